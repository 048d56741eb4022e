/* SPDX-License-Identifier: MIT */
/* Least squares by Kalman folding (Beckman, Kalman Folding part 1).

   Five observations of a cubic, z = x0 + x1 t + x2 t^2 + x3 t^3 + noise at
   t = 0, 1, -1, -2, 2, folded one row at a time into a static Kalman filter
   with prior x = 0, P = 1000 I and unit noise.  The fold never forms A^T A,
   yet ends at the ridge solution (A^T A + I/1000)^{-1} A^T z; the
   information form with zero information gives the plain normal equations,
   and two shards folded apart merge into the whole.

   Build against an installed foldest:
     cc kalman_lsq.c $(pkg-config --cflags --libs foldest) -o kalman_lsq */
#include <stdio.h>
#include <stdlib.h>

#include <foldest.h>

enum { N = 4, ROWS = 5 };

static const double A[ROWS][N] = {
    {1, 0, 0, 0}, {1, 1, 1, 1}, {1, -1, 1, -1}, {1, -2, 4, -8}, {1, 2, 4, 8}};
static const double z[ROWS] = {-2.28442, -4.83168, -10.4601, 1.40488, -40.8079};
static const double one = 1.0;

static void print_vector(const char *what, const double *x)
{
    printf("%-34s [%10.6g %10.6g %10.6g %10.6g]\n", what, x[0], x[1], x[2], x[3]);
}

static int fail(const char *what, int rc)
{
    fprintf(stderr, "kalman_lsq: %s: %s\n", what, fe_strerror(rc));
    return 1;
}

int main(void)
{
    size_t len = fe_kalman_doubles(N, 1), ilen = fe_kalman_info_doubles(N, 1);
    double *mem = malloc(len * sizeof *mem), *mem2 = malloc(len * sizeof *mem2);
    double *im[3];
    fe_kalman k, k2;
    fe_kalman_info s[3];
    fe_kalman_obs obs[ROWS];
    fe_kalman_config cfg = {NULL, NULL, 1000.0, 0};   /* x0 = 0, P0 = 1000 I */
    fe_accumulator kal = fe_kalman_accumulator(&cfg);
    fe_accumulator info = fe_kalman_info_accumulator();
    int rc;

    for (int i = 0; i < 3; i++)
        im[i] = malloc(ilen * sizeof *im[i]);
    if (mem == NULL || mem2 == NULL || im[0] == NULL || im[1] == NULL || im[2] == NULL)
        return fail("memory", FE_ENOMEM);
    if ((rc = fe_kalman_init(&k, N, 1, mem, len)) != FE_OK
        || (rc = fe_kalman_init(&k2, N, 1, mem2, len)) != FE_OK)
        return fail("init", rc);
    for (int r = 0; r < ROWS; r++)
        obs[r] = (fe_kalman_obs){1, A[r], &z[r], &one};

    /* 1. The fold, one row at a time, printing the Kalman denominator D. */
    printf("Kalman fold, x0 = 0, P0 = 1000 I, Z = 1:\n");
    if ((rc = fe_init(&kal, &k)) != FE_OK)
        return fail("prior", rc);
    for (int r = 0; r < ROWS; r++) {
        double D;
        fe_kalman_report rep = {0, 0, 0, NULL, NULL, &D};
        if ((rc = fe_kalman_update(&k, &obs[r], &rep)) != FE_OK)
            return fail("update", rc);
        printf("  row %d: D = %-10.6g innovation NIS = %.4g\n", r + 1, D, rep.nis);
    }
    print_vector("final x", k.x);
    printf("final P\n");
    for (int i = 0; i < N; i++)
        printf("  [%10.6f %10.6f %10.6f %10.6f]\n", k.P[i * N + 0], k.P[i * N + 1],
               k.P[i * N + 2], k.P[i * N + 3]);

    /* 2. The same through fe_fold, on the fast path. */
    cfg.fast = 1;
    if ((rc = fe_init(&kal, &k2)) != FE_OK || (rc = fe_fold(&kal, &k2, obs, ROWS, NULL)) != FE_OK)
        return fail("fast fold", rc);
    print_vector("fe_fold, fast path", k2.x);

    /* 3. Information form: zero information is ordinary least squares. */
    for (int i = 0; i < 3; i++)
        if ((rc = fe_kalman_info_init(&s[i], N, 1, im[i], ilen)) != FE_OK)
            return fail("info init", rc);
    if ((rc = fe_fold(&info, &s[0], obs, ROWS, NULL)) != FE_OK
        || (rc = fe_kalman_info_to_kalman(&s[0], &k2)) != FE_OK)
        return fail("normal equations", rc);
    print_vector("normal equations (no prior)", k2.x);

    /* 4. Two shards, folded apart, merged, plus the prior counted once. */
    if ((rc = fe_fold(&info, &s[1], obs, 2, NULL)) != FE_OK
        || (rc = fe_fold(&info, &s[2], obs + 2, ROWS - 2, NULL)) != FE_OK
        || (rc = fe_merge(&info, &s[1], &s[2])) != FE_OK
        || (rc = fe_kalman_info_set_prior_scaled(&s[2], NULL, 1000.0)) != FE_OK
        || (rc = fe_merge(&info, &s[1], &s[2])) != FE_OK
        || (rc = fe_kalman_info_to_kalman(&s[1], &k2)) != FE_OK)
        return fail("shards", rc);
    print_vector("shards {1,2} + {3,4,5} + prior", k2.x);
    {
        double worst = 0;
        for (int i = 0; i < N; i++) {
            double d = k2.x[i] > k.x[i] ? k2.x[i] - k.x[i] : k.x[i] - k2.x[i];
            worst = d > worst ? d : worst;
        }
        printf("largest difference from the Kalman fold: %.2g\n", worst);
    }
    free(mem);
    free(mem2);
    for (int i = 0; i < 3; i++)
        free(im[i]);
    return 0;
}
