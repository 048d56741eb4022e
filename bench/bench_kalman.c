/* SPDX-License-Identifier: MIT */
/* Kalman update at n = 4, for packets of b = 1 and b = 3 measurements,
   in one run (b = 3 twice: a full Z, and a diagonal Z, i.e. decorrelated
   measurements):
     - the reference path, fe_kalman_update (CBLAS + one LAPACKE_dposv),
     - the fast path, fe_kalman_update_fast (decorrelate, scalar updates),
     - a hand-written fixed-size update (arrays of 4 and 16 doubles, no
       checks, no atomicity, no report): the floor a library can approach.
   Each path folds the same stream of packets from the same prior.  Prints
   ns per update, the ratio fast / hand-written (goal <= 1.5), and the
   agreement of the fast path and the baseline with the reference. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bench.h"
#include "foldest.h"

enum { N = 4, M = 4096 };

/* One packet stream: b rows of A, b values, a b x b covariance. */
typedef struct stream {
    size_t b;
    int diagonal;       /* Z diagonal: decorrelated measurements */
    double A[M][3 * N];
    double z[M][3];
    double Z[M][9];
    fe_kalman_obs obs[M];
} stream;

static void make_stream(stream *s, size_t b, int diagonal, uint64_t seed)
{
    fe_rng r = fe_rng_seed(seed);
    s->b = b;
    s->diagonal = diagonal;
    for (int k = 0; k < M; k++) {
        double L[9] = {0};
        for (size_t i = 0; i < b * N; i++)
            s->A[k][i] = 2.0 * fe_rng_uniform(&r) - 1.0;
        for (size_t i = 0; i < b; i++)
            s->z[k][i] = 3.0 * fe_rng_normal(&r);
        /* Z = L L^T with a random lower triangular L, well conditioned. */
        for (size_t i = 0; i < b; i++) {
            for (size_t j = 0; j < i; j++)
                L[i * b + j] = diagonal ? 0.0 : 0.3 * (2.0 * fe_rng_uniform(&r) - 1.0);
            L[i * b + i] = 0.5 + fe_rng_uniform(&r);
        }
        for (size_t i = 0; i < b; i++)
            for (size_t j = 0; j < b; j++) {
                double t = 0;
                for (size_t e = 0; e < b; e++)
                    t += L[i * b + e] * L[j * b + e];
                s->Z[k][i * b + j] = t;
            }
        s->obs[k] = (fe_kalman_obs){b, s->A[k], s->z[k], s->Z[k]};
    }
}

/* ---------------------------------------------- hand-written baselines */

/* b = 1: the scalar update written out for n = 4. */
static inline void hand_update1(double x[N], double P[N * N], const double a[N],
                                double z, double Z)
{
    double g[N], d = Z, res = z, inv;
    for (int i = 0; i < N; i++) {
        g[i] = P[i * N + 0] * a[0] + P[i * N + 1] * a[1] + P[i * N + 2] * a[2]
             + P[i * N + 3] * a[3];
        d += a[i] * g[i];
        res -= a[i] * x[i];
    }
    inv = 1.0 / d;
    for (int i = 0; i < N; i++)
        x[i] += g[i] * (res * inv);
    for (int i = 0; i < N; i++)
        for (int j = i; j < N; j++)
            P[i * N + j] = P[j * N + i] = P[i * N + j] - g[i] * g[j] * inv;
}

/* b = 3: the batch update written out: D by hand, its Cholesky, the gain
   K^T = D^{-1} (P A^T)^T by two triangular solves. */
static inline void hand_update3(double x[N], double P[N * N], const double A[3 * N],
                                const double z[3], const double Z[9])
{
    double PAT[N][3], D[3][3], L[3][3], il[3], nu[3], KT[3][N], y[3][N + 1];
    for (int i = 0; i < N; i++)
        for (int j = 0; j < 3; j++)
            PAT[i][j] = P[i * N + 0] * A[j * N + 0] + P[i * N + 1] * A[j * N + 1]
                      + P[i * N + 2] * A[j * N + 2] + P[i * N + 3] * A[j * N + 3];
    for (int i = 0; i < 3; i++) {
        nu[i] = z[i] - (A[i * N + 0] * x[0] + A[i * N + 1] * x[1]
                        + A[i * N + 2] * x[2] + A[i * N + 3] * x[3]);
        for (int j = 0; j <= i; j++)
            D[i][j] = Z[i * 3 + j] + A[i * N + 0] * PAT[0][j] + A[i * N + 1] * PAT[1][j]
                    + A[i * N + 2] * PAT[2][j] + A[i * N + 3] * PAT[3][j];
    }
    /* Cholesky D = L L^T with the reciprocals of the diagonal kept. */
    L[0][0] = sqrt(D[0][0]);
    il[0] = 1.0 / L[0][0];
    L[1][0] = D[1][0] * il[0];
    L[2][0] = D[2][0] * il[0];
    L[1][1] = sqrt(D[1][1] - L[1][0] * L[1][0]);
    il[1] = 1.0 / L[1][1];
    L[2][1] = (D[2][1] - L[2][0] * L[1][0]) * il[1];
    L[2][2] = sqrt(D[2][2] - L[2][0] * L[2][0] - L[2][1] * L[2][1]);
    il[2] = 1.0 / L[2][2];
    /* Right-hand sides: the columns of (P A^T)^T and nu. */
    for (int c = 0; c <= N; c++) {
        double r0 = c < N ? PAT[c][0] : nu[0];
        double r1 = c < N ? PAT[c][1] : nu[1];
        double r2 = c < N ? PAT[c][2] : nu[2];
        double y0 = r0 * il[0];
        double y1 = (r1 - L[1][0] * y0) * il[1];
        double y2 = (r2 - L[2][0] * y0 - L[2][1] * y1) * il[2];
        y2 = y2 * il[2];
        y1 = (y1 - L[2][1] * y2) * il[1];
        y0 = (y0 - L[1][0] * y1 - L[2][0] * y2) * il[0];
        y[0][c] = y0;
        y[1][c] = y1;
        y[2][c] = y2;
    }
    for (int j = 0; j < 3; j++)
        for (int c = 0; c < N; c++)
            KT[j][c] = y[j][c];
    for (int i = 0; i < N; i++)
        x[i] += PAT[i][0] * y[0][N] + PAT[i][1] * y[1][N] + PAT[i][2] * y[2][N];
    for (int i = 0; i < N; i++)
        for (int j = i; j < N; j++)
            P[i * N + j] = P[j * N + i] = P[i * N + j]
                - (PAT[i][0] * KT[0][j] + PAT[i][1] * KT[1][j] + PAT[i][2] * KT[2][j]);
}

/* ---------------------------------------------------------- the runs */

static double *filter_mem;
static fe_kalman filter;

static void reset(void)
{
    static const double x0[N] = {0, 0, 0, 0};
    if (fe_kalman_set_prior_scaled(&filter, x0, 100.0) != FE_OK) {
        fprintf(stderr, "bench_kalman: prior refused\n");
        exit(1);
    }
}

static void run_library(const stream *s, long updates, int fast)
{
    reset();
    for (long k = 0; k < updates; k++) {
        int rc = fast ? fe_kalman_update_fast(&filter, &s->obs[k % M], NULL)
                      : fe_kalman_update(&filter, &s->obs[k % M], NULL);
        if (rc != FE_OK) {
            fprintf(stderr, "bench_kalman: update refused: %s\n", fe_strerror(rc));
            exit(1);
        }
    }
}

static void run_hand(const stream *s, long updates, double x[N], double P[N * N])
{
    memset(x, 0, N * sizeof *x);
    memset(P, 0, N * N * sizeof *P);
    for (int i = 0; i < N; i++)
        P[i * N + i] = 100.0;
    for (long k = 0; k < updates; k++) {
        const stream *t = s;
        int j = (int)(k % M);
        if (t->b == 1)
            hand_update1(x, P, t->A[j], t->z[j][0], t->Z[j][0]);
        else
            hand_update3(x, P, t->A[j], t->z[j], t->Z[j]);
    }
}

static double rel(const double *a, const double *b, size_t len)
{
    double d = 0, s = 1e-300;
    for (size_t i = 0; i < len; i++) {
        d = fmax(d, fabs(a[i] - b[i]));
        s = fmax(s, fabs(b[i]));
    }
    return d / s;
}

/* Best time per update of each path over `rounds` short runs, the three
   paths interleaved so that a busy machine slows them alike. */
static void time_paths(const stream *s, long chunk, long chunk_ref, int rounds,
                       double *t_ref, double *t_fast, double *t_hand)
{
    double xh[N], Ph[N * N];
    *t_ref = *t_fast = *t_hand = 1e300;
    for (int r = 0; r < rounds; r++) {
        double t0 = fe_bench_now(), t1, t2, t3;
        run_library(s, chunk_ref, 0);
        t1 = fe_bench_now();
        run_library(s, chunk, 1);
        t2 = fe_bench_now();
        run_hand(s, chunk, xh, Ph);
        t3 = fe_bench_now();
        fe_bench_keep(xh[0] + Ph[0]);
        *t_ref = fmin(*t_ref, (t1 - t0) / (double)chunk_ref);
        *t_fast = fmin(*t_fast, (t2 - t1) / (double)chunk);
        *t_hand = fmin(*t_hand, (t3 - t2) / (double)chunk);
    }
    *t_ref *= 1e9;
    *t_fast *= 1e9;
    *t_hand *= 1e9;
}

int main(int argc, char **argv)
{
    int rounds = argc > 1 ? atoi(argv[1]) : 200;
    long chunk = 20000, chunk_ref = 2000, n_agree = 100000;
    static stream s1, s3, s3d;
    stream *streams[3] = {&s1, &s3, &s3d};
    double worst_goal = 0.0;
    int ok = 1;
    size_t len = fe_kalman_doubles(N, 3);

    filter_mem = malloc(len * sizeof *filter_mem);
    if (rounds < 1 || filter_mem == NULL
        || fe_kalman_init(&filter, N, 3, filter_mem, len) != FE_OK) {
        fprintf(stderr, "bench_kalman: cannot set up the filter\n");
        return 1;
    }
    make_stream(&s1, 1, 0, 1);
    make_stream(&s3, 3, 0, 3);
    make_stream(&s3d, 3, 1, 4);
    printf("Kalman update, n = %d (ns per update: best of %d interleaved runs of %ld updates,"
           " %ld for the reference); machine busy %.0f%% before the run (other processes'"
           " share of the cores)\n", N, rounds, chunk, chunk_ref, 100 * fe_bench_busy_fraction());
    for (int t = 0; t < 3; t++) {
        const stream *s = streams[t];
        double t_ref, t_fast, t_hand, xr[N], Pr[N * N], xf[N], Pf[N * N], xh[N], Ph[N * N];
        double agree_fast, agree_hand;
        time_paths(s, chunk, chunk_ref, rounds, &t_ref, &t_fast, &t_hand);
        /* Agreement after n_agree updates from the same prior. */
        run_library(s, n_agree, 0);
        memcpy(xr, filter.x, sizeof xr);
        memcpy(Pr, filter.P, sizeof Pr);
        run_library(s, n_agree, 1);
        memcpy(xf, filter.x, sizeof xf);
        memcpy(Pf, filter.P, sizeof Pf);
        run_hand(s, n_agree, xh, Ph);
        agree_fast = fmax(rel(xf, xr, N), rel(Pf, Pr, N * N));
        agree_hand = fmax(rel(xh, xr, N), rel(Ph, Pr, N * N));
        printf("  b = %zu (%s Z)\n", s->b,
               s->b == 1 ? "scalar" : s->diagonal ? "diagonal" : "full");
        printf("    reference (CBLAS + LAPACKE_dposv)   %8.1f\n", t_ref);
        printf("    fast path (decorrelate + scalar)    %8.1f\n", t_fast);
        printf("    hand-written fixed-size baseline    %8.1f\n", t_hand);
        printf("    ratios: fast/hand %.2f (goal <= 1.5), reference/fast %.1f\n",
               t_fast / t_hand, t_ref / t_fast);
        printf("    agreement with the reference after %ld updates: fast %.1e,"
               " hand-written %.1e (goal <= 1e-12)\n", n_agree, agree_fast, agree_hand);
        worst_goal = fmax(worst_goal, t_fast / t_hand);
        ok &= agree_fast <= 1e-12;
    }
    printf("  worst fast/hand ratio %.2f: goal %s\n", worst_goal,
           worst_goal <= 1.5 ? "met" : "NOT met");
    free(filter_mem);
    return ok ? 0 : 1;
}
