/* SPDX-License-Identifier: MIT */
/* Multi-session magnetometer calibration with the Schur complement.

   A magnetometer reads m = A u + o + noise, where u is the (unit) field
   in the sensor frame, A the soft-iron matrix and o the hard-iron offset.
   The soft iron belongs to the sensor and its mounting; the offset moves
   when the magnetised things near it move (another battery, a different
   board, a new session).  So recordings from several sessions share the
   calibration matrix S = A^{-1} (symmetric: the rotation part of A cannot
   be seen from magnitudes) and each has its own offset o_s:

       residual = |S (m - o_s)| - 1.

   The 6 entries of S are the global parameters, each session's offset a
   local block of 3: an arrow-shaped least-squares problem solved by
   Levenberg-Marquardt with the Schur complement: fe_sessions_fit
   (sessions.h).

   1. Synthetic sessions with known truth.
   2. Real recordings (../shared/data, or FOLDEST_DATA), skipped when absent:
      a QMC5883L recorded twice ("filtered" and "noisy", different centres),
      and one recording of another magnetometer cut in halves (one session:
      the halves should need no separate offsets).

   Build against an installed foldest:
     cc magcal_sessions.c $(pkg-config --cflags --libs foldest) -lm -o magcal_sessions */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <foldest.h>

static int magcal_fit(const fe_sessions *c, double *x, fe_lm_result *res)
{
    double *w = malloc(fe_sessions_work(c) * sizeof *w);
    int rc;
    if (w == NULL)
        return FE_ENOMEM;
    rc = fe_sessions_fit(c, x, w, res);
    free(w);
    return rc;
}

/* ------------------------------------------------------------ synthetic */

static int synthetic(void)
{
    enum { NS = 4, PER = 400 };
    const double A[3][3] = {{1.3, 0.2, -0.1}, {0.2, 0.8, 0.15}, {-0.1, 0.15, 1.1}};
    const double off[NS][3] = {{0.3, -0.2, 0.5}, {1.5, 0.1, -0.4}, {-0.7, 0.9, 0.2}, {0.0, -1.2, 0.8}};
    static double m[NS][PER * 3];
    double x[6 + 3 * NS], S[3][3], worst = 0.0;
    fe_sessions c = {NS, {0}, {0}, 0};
    fe_rng g = fe_rng_seed(5);
    fe_lm_result res;
    int rc;

    for (int b = 0; b < NS; b++) {
        for (int i = 0; i < PER; i++) {
            double u[3], n;
            for (int k = 0; k < 3; k++)
                u[k] = fe_rng_normal(&g);
            n = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
            for (int k = 0; k < 3; k++)
                m[b][3 * i + k] = off[b][k] + 0.005 * fe_rng_normal(&g)
                                  + (A[k][0] * u[0] + A[k][1] * u[1] + A[k][2] * u[2]) / n;
        }
        c.m[b] = m[b];
        c.n[b] = PER;
    }
    rc = magcal_fit(&c, x, &res);
    printf("1. synthetic: %d sessions of %d readings, noise 0.005 (field = 1)\n", NS, PER);
    printf("   %s after %d iterations, cost %.4e -> %.4e\n", fe_strerror(rc), res.iterations,
           res.initial_cost, res.cost);
    for (int b = 0; b < NS; b++)
        printf("   session %d offset (%7.4f %7.4f %7.4f), truth (%7.4f %7.4f %7.4f)\n", b,
               x[6 + 3 * b], x[7 + 3 * b], x[8 + 3 * b], off[b][0], off[b][1], off[b][2]);
    fe_sessions_matrix(x, S);
    for (int k = 0; k < 3; k++)
        for (int l = 0; l < 3; l++) {
            double sa = S[k][0] * A[0][l] + S[k][1] * A[1][l] + S[k][2] * A[2][l];
            worst = fmax(worst, fabs(sa - (k == l ? 1.0 : 0.0)));
        }
    printf("   S A = I to %.1e\n\n", worst);
    return rc == FE_OK ? 0 : 1;
}

/* ------------------------------------------------------------ real data */

/* Read columns [col, col+3) of a CSV, skipping lines that do not parse and
   the first `skip` rows that do. */
static double *read_csv3(const char *path, int col, size_t skip, size_t *n)
{
    FILE *f = fopen(path, "r");
    char line[512];
    size_t cap = 1024, k = 0, row = 0;
    double *m = malloc(cap * 3 * sizeof *m);
    if (f == NULL || m == NULL) {
        if (f != NULL)
            fclose(f);
        free(m);
        return NULL;
    }
    while (fgets(line, sizeof line, f) != NULL) {
        double v[6];
        int got = sscanf(line, "%lf,%lf,%lf,%lf,%lf,%lf", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5]);
        if (got < col + 3 || row++ < skip)
            continue;
        if (k == cap) {
            double *bigger = realloc(m, 2 * cap * 3 * sizeof *m);
            if (bigger == NULL)
                break;
            m = bigger;
            cap *= 2;
        }
        memcpy(m + 3 * k, v + col, 3 * sizeof *m);
        k++;
    }
    fclose(f);
    *n = k;
    return m;
}

/* Fit two sessions three ways and print the comparison; return the
   distance between the two sessions' offsets (shared S). */
static double compare(const char *title, const char *unit, const double *m1, size_t n1,
                    const double *m2, size_t n2)
{
    fe_sessions joint = {2, {m1, m2}, {n1, n2}, 0}, common = joint, one;
    double xj[12], xc[9], xs[9], rms_sep[2], rms_j[2], rms_c[2], rssj = 0, rssc = 0, F;
    fe_lm_result r;
    int rc;

    common.one_offset = 1;
    printf("\n%s (%zu + %zu readings)\n", title, n1, n2);
    rc = magcal_fit(&joint, xj, &r);
    printf("   shared S, one offset per session: %s after %d iterations\n", fe_strerror(rc),
           r.iterations);
    for (int b = 0; b < 2; b++) {
        one = (fe_sessions){1, {joint.m[b]}, {joint.n[b]}, 0};
        magcal_fit(&one, xs, &r);
        rms_sep[b] = fe_sessions_rms(&one, xs, 0);
        rms_j[b] = fe_sessions_rms(&joint, xj, (size_t)b);
        printf("   session %d offset (%.4g, %.4g, %.4g) %s; alone: (%.4g, %.4g, %.4g)\n", b + 1,
               xj[6 + 3 * b], xj[7 + 3 * b], xj[8 + 3 * b], unit, xs[6], xs[7], xs[8]);
    }
    magcal_fit(&common, xc, &r);
    for (int b = 0; b < 2; b++) {
        rms_c[b] = fe_sessions_rms(&common, xc, (size_t)b);
        rssj += (double)joint.n[b] * rms_j[b] * rms_j[b];
        rssc += (double)joint.n[b] * rms_c[b] * rms_c[b];
    }
    F = (rssc - rssj) / 3.0 / (rssj / ((double)(n1 + n2) - 12.0));
    printf("   radial RMS (fraction of the field)   session 1   session 2\n");
    printf("     each session alone (9 + 9 params)    %.4f      %.4f\n", rms_sep[0], rms_sep[1]);
    printf("     shared S, own offsets (6 + 3 + 3)    %.4f      %.4f\n", rms_j[0], rms_j[1]);
    printf("     shared S and offset (6 + 3)          %.4f      %.4f\n", rms_c[0], rms_c[1]);
    printf("   F statistic of the per-session offsets: %.1f (its 1e-6 quantile is about 10.2 for\n"
           "   independent residuals; these are not: hand-held recordings misfit slowly)\n", F);
    return sqrt((xj[6] - xj[9]) * (xj[6] - xj[9]) + (xj[7] - xj[10]) * (xj[7] - xj[10])
                + (xj[8] - xj[11]) * (xj[8] - xj[11]));
}

int main(void)
{
    const char *dir = getenv("FOLDEST_DATA");
    char path[4096];
    double *m1, *m2;
    size_t n1 = 0, n2 = 0;
    int status = synthetic();

    if (dir == NULL || *dir == '\0')
        dir = "../shared/data";
    printf("2. real recordings from %s\n", dir);
    snprintf(path, sizeof path, "%s/qmc5883l_tomisuarez/filtered_raw_data.csv", dir);
    m1 = read_csv3(path, 0, 3000, &n1);          /* the first 60 s are static */
    snprintf(path, sizeof path, "%s/qmc5883l_tomisuarez/noisy_raw_data.csv", dir);
    m2 = read_csv3(path, 0, 3000, &n2);
    if (m1 != NULL && m2 != NULL && n1 > 100 && n2 > 100) {
        double between, half1, half2;
        between = compare("   QMC5883L, two recordings as two sessions", "counts", m1, n1, m2, n2);
        printf("   control: each recording cut in halves\n");
        half1 = compare("   QMC5883L filtered, halves", "counts", m1, n1 / 2, m1 + 3 * (n1 / 2), n1 - n1 / 2);
        half2 = compare("   QMC5883L noisy, halves", "counts", m2, n2 / 2, m2 + 3 * (n2 / 2), n2 - n2 / 2);
        printf("   offsets differ by %.1f counts between the recordings, by %.1f and %.1f between\n"
               "   the halves of each: the recordings have different hard iron\n\n",
               between, half1, half2);
    } else {
        printf("   SKIP: QMC5883L recordings not found under %s (set FOLDEST_DATA)\n", dir);
    }
    free(m1);
    free(m2);

    snprintf(path, sizeof path, "%s/ck_explorer_accmag/acc_mag_log.csv", dir);
    m1 = read_csv3(path, 3, 0, &n1);             /* columns mx, my, mz (gauss) */
    if (m1 != NULL && n1 > 200)
        printf("   offsets of the halves differ by %.4f G\n",
               compare("   CK-Explorer magnetometer, one recording cut in halves", "G", m1, n1 / 2,
                       m1 + 3 * (n1 / 2), n1 - n1 / 2));
    else
        printf("   SKIP: CK-Explorer recording not found under %s\n", dir);
    free(m1);
    return status;
}
