/* SPDX-License-Identifier: MIT */
/* Kalman folding: the update against an independent long-double
   computation, the row-major dposv convention, refusal of bad packets
   (accumulation unchanged bit for bit), the tracker's coverage, the
   information form and its merge, the mean and least squares as Kalman
   folds, innovations and the monitor, the fast path against the
   reference, and the accumulator descriptors. */
#include <float.h>
#include <stdint.h>

#include <lapacke.h>

#include "foldest.h"
#include "testutil.h"

enum { MAXD = 8 };

/* ------------------------------------------------------------ helpers */

/* A covariance-form filter with its own heap buffer (tests may allocate). */
typedef struct kf {
    fe_kalman k;
    double *mem;
    size_t len;
} kf;

static void kf_make(kf *f, size_t n, size_t bmax)
{
    f->len = fe_kalman_doubles(n, bmax);
    ck_assert_uint_gt(f->len, 0);
    f->mem = malloc(f->len * sizeof *f->mem);
    ck_assert_ptr_nonnull(f->mem);
    ck_assert_int_eq(fe_kalman_init(&f->k, n, bmax, f->mem, f->len), FE_OK);
}

static void kf_free(kf *f)
{
    free(f->mem);
}

typedef struct kinfo {
    fe_kalman_info s;
    double *mem;
} kinfo;

static void kinfo_make(kinfo *f, size_t n, size_t bmax)
{
    size_t len = fe_kalman_info_doubles(n, bmax);
    ck_assert_uint_gt(len, 0);
    f->mem = malloc(len * sizeof *f->mem);
    ck_assert_ptr_nonnull(f->mem);
    ck_assert_int_eq(fe_kalman_info_init(&f->s, n, bmax, f->mem, len), FE_OK);
}

/* Symmetric positive definite matrix: M M^T + shift I, M uniform(-1, 1). */
static void random_spd(fe_rng *r, size_t n, double shift, double *S)
{
    double M[MAXD * MAXD];
    for (size_t i = 0; i < n * n; i++)
        M[i] = 2.0 * fe_rng_uniform(r) - 1.0;
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j <= i; j++) {
            double s = i == j ? shift : 0.0;
            for (size_t k = 0; k < n; k++)
                s += M[i * n + k] * M[j * n + k];
            S[i * n + j] = S[j * n + i] = s;
        }
}

static void random_vec(fe_rng *r, size_t n, double scale, double *v)
{
    for (size_t i = 0; i < n; i++)
        v[i] = scale * fe_rng_normal(r);
}

/* max |a - b| / max(max |b|, tiny) */
static double rel_diff(const double *a, const double *b, size_t len)
{
    double d = 0.0, s = 1e-300;
    for (size_t i = 0; i < len; i++) {
        if (fabs(a[i] - b[i]) > d)
            d = fabs(a[i] - b[i]);
        if (fabs(b[i]) > s)
            s = fabs(b[i]);
    }
    return d / s;
}

/* The textbook update with an explicit inverse, in long double. */
static void ref_update(size_t n, size_t b, const double *x, const double *P,
                       const double *A, const double *z, const double *Z,
                       double *xo, double *Po)
{
    long double PAT[MAXD * MAXD], D[MAXD * MAXD], Di[MAXD * MAXD],
        K[MAXD * MAXD], nu[MAXD];
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < b; j++) {
            long double s = 0;
            for (size_t k = 0; k < n; k++)
                s += (long double)P[i * n + k] * A[j * n + k];
            PAT[i * b + j] = s;
        }
    for (size_t i = 0; i < b; i++) {
        long double s = z[i];
        for (size_t j = 0; j < b; j++) {
            long double t = Z[i * b + j];
            for (size_t k = 0; k < n; k++)
                t += (long double)A[i * n + k] * PAT[k * b + j];
            D[i * b + j] = t;
        }
        for (size_t k = 0; k < n; k++)
            s -= (long double)A[i * n + k] * x[k];
        nu[i] = s;
    }
    fe_test_inverse(b, D, Di);
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < b; j++) {
            long double s = 0;
            for (size_t k = 0; k < b; k++)
                s += PAT[i * b + k] * Di[k * b + j];
            K[i * b + j] = s;
        }
    for (size_t i = 0; i < n; i++) {
        long double s = x[i];
        for (size_t j = 0; j < b; j++)
            s += K[i * b + j] * nu[j];
        xo[i] = (double)s;
        for (size_t c = 0; c < n; c++) {
            long double t = P[i * n + c];
            for (size_t j = 0; j < b; j++)
                t -= K[i * b + j] * PAT[c * b + j];
            Po[i * n + c] = (double)t;
        }
    }
}

static int is_symmetric(const double *P, size_t n)
{
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < i; j++)
            if (P[i * n + j] != P[j * n + i])
                return 0;
    return 1;
}

/* Positive definite by a long-double Cholesky. */
static int is_pd(const double *P, size_t n)
{
    long double L[MAXD * MAXD];
    for (size_t j = 0; j < n; j++) {
        long double s = P[j * n + j];
        for (size_t k = 0; k < j; k++)
            s -= L[j * n + k] * L[j * n + k];
        if (!(s > 0))
            return 0;
        L[j * n + j] = sqrtl(s);
        for (size_t i = j + 1; i < n; i++) {
            long double t = P[i * n + j];
            for (size_t k = 0; k < j; k++)
                t -= L[i * n + k] * L[j * n + k];
            L[i * n + j] = t / L[j * n + j];
        }
    }
    return 1;
}

/* Assert that `got` rounds to `want` as printed with six significant digits. */
#define ASSERT_DIGITS(got, want)                                             \
    do {                                                                     \
        double g_ = (got), w_ = (want);                                      \
        double t_ = w_ == 0.0 ? 5e-7                                         \
                              : 0.5 * pow(10.0, floor(log10(fabs(w_))) - 5); \
        ck_assert_msg(fabs(g_ - w_) <= t_, "%s = %.10g, want %.6g (+- %.1g)", \
                      #got, g_, w_, t_);                                     \
    } while (0)

/* --------------------------------------------------- the 5x4 example */

static const double lsq_A[5][4] = {
    {1, 0, 0, 0}, {1, 1, 1, 1}, {1, -1, 1, -1}, {1, -2, 4, -8}, {1, 2, 4, 8}};
static const double lsq_z[5] = {-2.28442, -4.83168, -10.4601, 1.40488, -40.8079};

/* (A^T A + lambda I)^{-1} A^T z by row-major dposv (ldb = nrhs = 1). */
static void ridge(double lambda, double *x)
{
    double N[16] = {0};
    for (int i = 0; i < 4; i++) {
        x[i] = 0;
        for (int j = 0; j < 4; j++) {
            for (int r = 0; r < 5; r++)
                N[i * 4 + j] += lsq_A[r][i] * lsq_A[r][j];
        }
        N[i * 4 + i] += lambda;
        for (int r = 0; r < 5; r++)
            x[i] += lsq_A[r][i] * lsq_z[r];
    }
    ck_assert_int_eq(LAPACKE_dposv(LAPACK_ROW_MAJOR, 'L', 4, 1, N, 4, x, 1), 0);
}

START_TEST(least_squares_5x4)
{
    const double want_D[5] = {1001, 3002, 2669.55, 18030.5, 69.7966};
    const double want_x[4] = {-2.97423, 7.2624, -4.21051, -4.45378};
    const double want_P[16] = {0.485458, 0, -0.142778, 0,
                               0, 0.901908, 0, -0.235882,
                               -0.142778, 0, 0.0714031, 0,
                               0, -0.235882, 0, 0.0693839};
    const double want_ne[4] = {-2.97507, 7.27001, -4.21039, -4.4558};
    double ne[4], rg[4];
    const double one = 1.0;

    /* Normal equations: the unregularised answer. */
    ridge(0.0, ne);
    for (int i = 0; i < 4; i++)
        ASSERT_DIGITS(ne[i], want_ne[i]);
    ridge(1.0 / 1000.0, rg);

    for (int fast = 0; fast < 2; fast++) {
        kf f;
        kf_make(&f, 4, 1);
        ck_assert_int_eq(fe_kalman_set_prior_scaled(&f.k, NULL, 1000.0), FE_OK);
        for (int r = 0; r < 5; r++) {
            double D;
            fe_kalman_report rep = {0, 0, 0, NULL, NULL, &D};
            fe_kalman_obs o = {1, lsq_A[r], &lsq_z[r], &one};
            ck_assert_int_eq(fast ? fe_kalman_update_fast(&f.k, &o, &rep)
                                  : fe_kalman_update(&f.k, &o, &rep), FE_OK);
            ASSERT_DIGITS(D, want_D[r]);
            FE_ASSERT_REL(exp(rep.log_det_D), D, 1e-12);
        }
        for (int i = 0; i < 4; i++)
            ASSERT_DIGITS(f.k.x[i], want_x[i]);
        for (int i = 0; i < 16; i++)
            ASSERT_DIGITS(f.k.P[i], want_P[i]);
        /* The prior acts as regularisation: exactly the ridge solution. */
        for (int i = 0; i < 4; i++)
            ck_assert_msg(fabs(f.k.x[i] - rg[i]) <= 1e-10,
                          "fast=%d x[%d] = %.17g, ridge %.17g", fast, i,
                          f.k.x[i], rg[i]);
        ck_assert_uint_eq(f.k.count, 5);
        kf_free(&f);
    }
    /* The information form from zero information gives the normal
       equations; with the prior, the ridge solution. */
    for (int prior = 0; prior < 2; prior++) {
        kinfo s;
        kf f;
        kinfo_make(&s, 4, 1);
        kf_make(&f, 4, 1);
        if (prior)
            ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&s.s, NULL, 1000.0), FE_OK);
        for (int r = 0; r < 5; r++) {
            fe_kalman_obs o = {1, lsq_A[r], &lsq_z[r], &one};
            ck_assert_int_eq(fe_kalman_info_update(&s.s, &o), FE_OK);
        }
        ck_assert_int_eq(fe_kalman_info_to_kalman(&s.s, &f.k), FE_OK);
        for (int i = 0; i < 4; i++)
            ck_assert_msg(fabs(f.k.x[i] - (prior ? rg[i] : ne[i])) <= 1e-10,
                          "info prior=%d x[%d] = %.17g", prior, i, f.k.x[i]);
        free(s.mem);
        kf_free(&f);
    }
}
END_TEST

/* ------------------------------------------------------ the mean */

START_TEST(mean_is_a_kalman_filter)
{
    const double z[3] = {55, 89, 144};
    const double one = 1.0;
    fe_meanvar mv = FE_MEANVAR_EMPTY;
    kinfo s;
    kf f, c;
    kinfo_make(&s, 1, 1);
    kf_make(&f, 1, 1);
    kf_make(&c, 1, 1);
    /* Covariance form with a diffuse prior. */
    ck_assert_int_eq(fe_kalman_set_prior_scaled(&c.k, NULL, 1e12), FE_OK);
    for (int i = 0; i < 3; i++) {
        fe_kalman_obs o = {1, &one, &z[i], &one};
        ck_assert_int_eq(fe_kalman_info_update(&s.s, &o), FE_OK);
        ck_assert_int_eq(fe_kalman_update(&c.k, &o, NULL), FE_OK);
        ck_assert_int_eq(fe_meanvar_add(&mv, z[i]), FE_OK);
        /* After each observation, the information form is the mean. */
        ck_assert_int_eq(fe_kalman_info_to_kalman(&s.s, &f.k), FE_OK);
        FE_ASSERT_REL(f.k.x[0], fe_meanvar_mean(&mv), 1e-14);
        FE_ASSERT_REL(c.k.x[0], fe_meanvar_mean(&mv), 1e-9);
        FE_ASSERT_REL(f.k.P[0], 1.0 / (i + 1), 1e-14);
    }
    FE_ASSERT_REL(f.k.x[0], 96.0, 1e-14);
    FE_ASSERT_REL(c.k.x[0], 96.0, 1e-9);
    ck_assert_double_eq(fe_meanvar_mean(&mv), 96.0);
    free(s.mem);
    kf_free(&f);
    kf_free(&c);
}
END_TEST

/* ------------------------------------- the update against long double */

START_TEST(update_matches_textbook_for_b_ne_n)
{
    /* b < n, b = n - 1, b > n, and other n: the column-major solve with
       ldb = b and n + 1 right-hand sides must be indexed right. */
    const size_t cases[][2] = {{4, 1}, {4, 2}, {4, 3}, {4, 6}, {7, 2}, {2, 5}, {1, 3}};
    fe_rng r = fe_rng_seed(3);
    double worst = 0.0, worst_fast = 0.0;
    for (size_t t = 0; t < sizeof cases / sizeof cases[0]; t++) {
        size_t n = cases[t][0], b = cases[t][1];
        for (int rep = 0; rep < 8; rep++) {
            double P[MAXD * MAXD], x[MAXD], A[MAXD * MAXD], z[MAXD], Z[MAXD * MAXD];
            double xo[MAXD], Po[MAXD * MAXD];
            kf f, g;
            fe_kalman_obs o;
            kf_make(&f, n, b);
            kf_make(&g, n, b);
            random_spd(&r, n, 0.5, P);
            random_vec(&r, n, 2.0, x);
            random_vec(&r, b * n, 1.0, A);
            random_vec(&r, b, 3.0, z);
            random_spd(&r, b, 0.2, Z);
            o = (fe_kalman_obs){b, A, z, Z};
            ck_assert_int_eq(fe_kalman_set_prior(&f.k, x, P), FE_OK);
            ck_assert_int_eq(fe_kalman_set_prior(&g.k, x, P), FE_OK);
            ck_assert_int_eq(fe_kalman_update(&f.k, &o, NULL), FE_OK);
            ck_assert_int_eq(fe_kalman_update_fast(&g.k, &o, NULL), FE_OK);
            ref_update(n, b, x, P, A, z, Z, xo, Po);
            worst = fmax(worst, rel_diff(f.k.x, xo, n));
            worst = fmax(worst, rel_diff(f.k.P, Po, n * n));
            worst_fast = fmax(worst_fast, rel_diff(g.k.x, f.k.x, n));
            worst_fast = fmax(worst_fast, rel_diff(g.k.P, f.k.P, n * n));
            ck_assert(is_symmetric(f.k.P, n) && is_symmetric(g.k.P, n));
            kf_free(&f);
            kf_free(&g);
        }
    }
    ck_assert_msg(worst <= 1e-11, "reference vs long double: %.3g", worst);
    ck_assert_msg(worst_fast <= 1e-12, "fast vs reference: %.3g", worst_fast);
}
END_TEST

START_TEST(row_major_dposv_needs_ldb_nrhs)
{
    /* Beckman's row-major formulation: D [DiRes | DiAP] = [nu | A P] with
       the b x (n + 1) block row-major, so ldb = nrhs = n + 1 (not b, not n).
       It must agree with the library's column-major solve, and ldb = b is
       rejected by LAPACKE (argument 8) whenever b < n + 1. */
    const size_t cases[][2] = {{4, 1}, {4, 3}, {4, 6}, {3, 2}};
    fe_rng r = fe_rng_seed(8);
    for (size_t t = 0; t < sizeof cases / sizeof cases[0]; t++) {
        size_t n = cases[t][0], b = cases[t][1], m = n + 1;
        double P[MAXD * MAXD], x[MAXD], A[MAXD * MAXD], z[MAXD], Z[MAXD * MAXD];
        double PAT[MAXD * MAXD], D[MAXD * MAXD], D2[MAXD * MAXD], B[MAXD * (MAXD + 1)],
            B2[MAXD * (MAXD + 1)], xr[MAXD], Pr[MAXD * MAXD];
        lapack_int info;
        kf f;
        fe_kalman_obs o;
        random_spd(&r, n, 0.5, P);
        random_vec(&r, n, 1.0, x);
        random_vec(&r, b * n, 1.0, A);
        random_vec(&r, b, 1.0, z);
        random_spd(&r, b, 0.3, Z);
        for (size_t i = 0; i < n; i++)
            for (size_t j = 0; j < b; j++) {
                double s = 0;
                for (size_t k = 0; k < n; k++)
                    s += P[i * n + k] * A[j * n + k];
                PAT[i * b + j] = s;
            }
        for (size_t i = 0; i < b; i++) {
            double nu = z[i];
            for (size_t j = 0; j < b; j++) {
                double s = Z[i * b + j];
                for (size_t k = 0; k < n; k++)
                    s += A[i * n + k] * PAT[k * b + j];
                D[i * b + j] = s;
            }
            for (size_t k = 0; k < n; k++)
                nu -= A[i * n + k] * x[k];
            B[i * m] = nu;
            for (size_t j = 0; j < n; j++)          /* (A P)_{ij} */
                B[i * m + 1 + j] = PAT[j * b + i];
        }
        memcpy(D2, D, sizeof D);
        memcpy(B2, B, sizeof B);
        info = LAPACKE_dposv(LAPACK_ROW_MAJOR, 'L', (lapack_int)b, (lapack_int)m,
                             D, (lapack_int)b, B, (lapack_int)m);
        ck_assert_int_eq(info, 0);
        /* LAPACKE prints "Wrong parameter 8 in LAPACKE_dposv_work" here:
           that is the expected refusal. */
        if (b < m)
            ck_assert_int_eq(LAPACKE_dposv(LAPACK_ROW_MAJOR, 'L', (lapack_int)b,
                                           (lapack_int)m, D2, (lapack_int)b, B2,
                                           (lapack_int)b), -8);
        for (size_t i = 0; i < n; i++) {
            double s = x[i];
            for (size_t j = 0; j < b; j++)
                s += PAT[i * b + j] * B[j * m];
            xr[i] = s;
            for (size_t c = 0; c < n; c++) {
                double t2 = P[i * n + c];
                for (size_t j = 0; j < b; j++)
                    t2 -= PAT[i * b + j] * B[j * m + 1 + c];
                Pr[i * n + c] = t2;
            }
        }
        kf_make(&f, n, b);
        ck_assert_int_eq(fe_kalman_set_prior(&f.k, x, P), FE_OK);
        o = (fe_kalman_obs){b, A, z, Z};
        ck_assert_int_eq(fe_kalman_update(&f.k, &o, NULL), FE_OK);
        ck_assert_msg(rel_diff(f.k.x, xr, n) <= 1e-12, "x, n=%zu b=%zu", n, b);
        ck_assert_msg(rel_diff(f.k.P, Pr, n * n) <= 1e-12, "P, n=%zu b=%zu", n, b);
        kf_free(&f);
    }
}
END_TEST

/* --------------------------------------------------- bad packets */

/* Assert that the filter's memory and descriptor did not change. */
#define ASSERT_UNCHANGED(f, snap, desc)                                     \
    do {                                                                     \
        ck_assert_mem_eq((f).mem, (snap), ((f).k.n + (f).k.n * (f).k.n) * sizeof(double)); \
        ck_assert_mem_eq(&(f).k, &(desc), sizeof(fe_kalman));                \
    } while (0)

START_TEST(bad_packets_are_refused_and_nothing_changes)
{
    const double x0[3] = {1, 2, 3};
    const double A1[3] = {1, 0.5, -1}, A2[6] = {1, 0, 0, 0, 1, 0};
    const double z1 = 2.0, z2[2] = {1, 2}, zbad[2] = {1, NAN};
    const double Zneg = -5.0;
    const double Zind[4] = {1, 2, 2, 1};          /* indefinite */
    const double Z2[4] = {1, 0, 0, 1};
    double snap[3 + 9];
    fe_kalman desc;
    kf f;
    kf_make(&f, 3, 2);
    ck_assert_int_eq(fe_kalman_set_prior_scaled(&f.k, x0, 0.1), FE_OK);
    {   /* a few good packets first */
        fe_kalman_obs o = {1, A1, &z1, &Z2[0]};
        ck_assert_int_eq(fe_kalman_update(&f.k, &o, NULL), FE_OK);
    }
    memcpy(snap, f.mem, sizeof snap);
    desc = f.k;
    /* Each update: the reference, the fast one and Joseph's form. */
    for (int v = 0; v < 3; v++) {
        int (*upd)(fe_kalman *, const fe_kalman_obs *, fe_kalman_report *) =
            v == 1 ? fe_kalman_update_fast : v == 2 ? fe_kalman_update_joseph : fe_kalman_update;
        int fast = v == 1;
        fe_kalman_obs neg = {1, A1, &z1, &Zneg};          /* D = -5 + small < 0 */
        fe_kalman_obs ind = {2, A2, z2, Zind};            /* D indefinite */
        fe_kalman_obs nan = {2, A2, zbad, Z2};
        fe_kalman_obs big = {3, A2, z2, Z2};              /* b > bmax */
        fe_kalman_obs zero = {0, A2, z2, Z2};
        fe_kalman_obs null = {1, NULL, &z1, &Z2[0]};
        double D[4], w[2];
        fe_kalman_report rep = {0, 0, 0, NULL, w, D};
        ck_assert_int_eq(upd(&f.k, &neg, &rep), FE_ENOTPD);
        ASSERT_UNCHANGED(f, snap, desc);
        ck_assert_int_eq(upd(&f.k, &ind, NULL), FE_ENOTPD);
        ASSERT_UNCHANGED(f, snap, desc);
        ck_assert_int_eq(upd(&f.k, &nan, NULL), FE_ENONFINITE);
        ASSERT_UNCHANGED(f, snap, desc);
        ck_assert_int_eq(upd(&f.k, &big, NULL), FE_ESIZE);
        ASSERT_UNCHANGED(f, snap, desc);
        {   /* Scalar packets with a NaN or an infinity anywhere. */
            const double Anan[3] = {1, NAN, 0}, Ainf[3] = {INFINITY, 0, 0};
            const double one = 1.0, nanv = NAN, infv = INFINITY;
            fe_kalman_obs s1 = {1, Anan, &z1, &one}, s2 = {1, Ainf, &z1, &one},
                          s3 = {1, A1, &nanv, &one}, s4 = {1, A1, &infv, &one},
                          s5 = {1, A1, &z1, &nanv}, s6 = {1, A1, &z1, &infv};
            ck_assert_int_eq(upd(&f.k, &s1, NULL), FE_ENONFINITE);
            ck_assert_int_eq(upd(&f.k, &s2, NULL), FE_ENONFINITE);
            ck_assert_int_eq(upd(&f.k, &s3, NULL), FE_ENONFINITE);
            ck_assert_int_eq(upd(&f.k, &s4, NULL), FE_ENONFINITE);
            ck_assert_int_eq(upd(&f.k, &s5, NULL), FE_ENONFINITE);
            ck_assert_int_eq(upd(&f.k, &s6, NULL), FE_ENONFINITE);
            ASSERT_UNCHANGED(f, snap, desc);
        }
        {   /* An update whose result overflows is refused too. */
            const double huge = 1e300, tiny = 1e-300, Ahuge[3] = {1e-300, 0, 0};
            fe_kalman_obs ov = {1, Ahuge, &huge, &tiny};
            ck_assert_int_eq(upd(&f.k, &ov, NULL), FE_ENONFINITE);
            ASSERT_UNCHANGED(f, snap, desc);
        }
        if (fast) {   /* Z singular (D is not): refused at the boundary, */
            const double Zsing[4] = {1, 1, 1, 1}, Znear[4] = {1, 1 - 1e-6, 1 - 1e-6, 1};
            fe_kalman_obs sing = {2, A2, z2, Zsing}, near = {2, A2, z2, Znear};
            kf g;
            ck_assert_int_eq(upd(&f.k, &sing, NULL), FE_ENOTPD);
            ASSERT_UNCHANGED(f, snap, desc);
            /* and just inside it the packet is accepted, as the reference takes it. */
            kf_make(&g, 3, 2);
            ck_assert_int_eq(fe_kalman_copy(&g.k, &f.k), FE_OK);
            ck_assert_int_eq(upd(&g.k, &near, NULL), FE_OK);
            ck_assert_int_eq(fe_kalman_copy(&g.k, &f.k), FE_OK);
            ck_assert_int_eq(fe_kalman_update(&g.k, &sing, NULL), FE_OK);
            kf_free(&g);
        }
        ck_assert_int_eq(upd(&f.k, &zero, NULL), FE_EINVAL);
        ck_assert_int_eq(upd(&f.k, &null, NULL), FE_EINVAL);
        ck_assert_int_eq(upd(&f.k, NULL, NULL), FE_EINVAL);
        ASSERT_UNCHANGED(f, snap, desc);
    }
    {   /* A tracker step whose update fails after the predict ran. */
        const double Phi[9] = {1, 0.1, 0, 0, 1, 0.1, 0, 0, 1};
        const double Phibad[9] = {1, INFINITY, 0, 0, 1, 0, 0, 0, 1};
        fe_kalman_track_obs t = {{Phi, NULL, NULL, 0, NULL}, {1, A1, &z1, &Zneg}};
        ck_assert_int_eq(fe_kalman_track(&f.k, &t, NULL), FE_ENOTPD);
        ASSERT_UNCHANGED(f, snap, desc);
        ck_assert_int_eq(fe_kalman_track_fast(&f.k, &t, NULL), FE_ENOTPD);
        ASSERT_UNCHANGED(f, snap, desc);
        t.model.Phi = Phibad;
        t.obs.Z = &Z2[0];
        ck_assert_int_eq(fe_kalman_track(&f.k, &t, NULL), FE_ENONFINITE);
        ck_assert_int_eq(fe_kalman_predict(&f.k, &t.model), FE_ENONFINITE);
        ASSERT_UNCHANGED(f, snap, desc);
    }
    {   /* The information form refuses a Z that is not positive definite. */
        kinfo s;
        double before[3 + 9];
        fe_kalman_obs o = {2, A2, z2, Zind};
        fe_kalman_obs ok = {2, A2, z2, Z2};
        kinfo_make(&s, 3, 2);
        ck_assert_int_eq(fe_kalman_info_update(&s.s, &ok), FE_OK);
        memcpy(before, s.mem, sizeof before);
        ck_assert_int_eq(fe_kalman_info_update(&s.s, &o), FE_ENOTPD);
        ck_assert_mem_eq(s.mem, before, sizeof before);
        ck_assert_uint_eq(s.s.count, 1);
        /* Two measurements cannot determine three unknowns. */
        ck_assert_int_eq(fe_kalman_info_to_kalman(&s.s, &f.k), FE_ENOTPD);
        ASSERT_UNCHANGED(f, snap, desc);
        free(s.mem);
    }
    kf_free(&f);
}
END_TEST

START_TEST(sizes_and_arguments)
{
    double mem[64];
    fe_kalman k;
    fe_kalman_info s;
    ck_assert_uint_eq(fe_kalman_doubles(0, 1), 0);
    ck_assert_uint_eq(fe_kalman_doubles(1, 0), 0);
    ck_assert_uint_eq(fe_kalman_doubles(FE_KALMAN_MAX_DIM + 1, 1), 0);
    ck_assert_uint_gt(fe_kalman_doubles(4, 3), 4 + 16);
    ck_assert_int_eq(fe_kalman_init(&k, 4, 3, mem, fe_kalman_doubles(4, 3) - 1), FE_ESIZE);
    ck_assert_int_eq(fe_kalman_init(&k, 4, 3, NULL, 64), FE_EINVAL);
    ck_assert_int_eq(fe_kalman_init(&k, 2, 2, mem, 64), FE_OK);
    ck_assert_double_eq(k.x[0], 0.0);
    ck_assert_int_eq(fe_kalman_set_prior_scaled(&k, NULL, -1.0), FE_ENOTPD);
    ck_assert_int_eq(fe_kalman_set_prior_scaled(&k, NULL, NAN), FE_ENONFINITE);
    ck_assert_int_eq(fe_kalman_set_prior_scaled(NULL, NULL, 1.0), FE_EINVAL);
    ck_assert_int_eq(fe_kalman_set_prior_scaled(&k, NULL, 0.0), FE_OK); /* the edge: P = 0 */
    {   /* The prior in information form writes nothing past its memory. */
        enum { N = 3, PAD = 16 };
        size_t len = fe_kalman_info_doubles(N, 1);
        double *m = malloc((len + PAD) * sizeof *m), P0[N * N] = {4, 1, 0, 1, 3, 1, 0, 1, 2};
        const double x0[N] = {1, -2, 3};
        fe_kalman_info si;
        ck_assert_ptr_nonnull(m);
        for (size_t i = 0; i < len + PAD; i++)
            m[i] = -7.0;
        ck_assert_int_eq(fe_kalman_info_init(&si, N, 1, m, len), FE_OK);
        ck_assert_int_eq(fe_kalman_info_set_prior(&si, x0, P0), FE_OK);
        for (size_t i = len; i < len + PAD; i++)
            ck_assert_double_eq(m[i], -7.0);
        free(m);
    }
    ck_assert_int_eq(fe_kalman_info_init(&s, 4, 3, mem, fe_kalman_info_doubles(4, 3) - 1), FE_ESIZE);
    ck_assert_int_eq(fe_kalman_info_init(&s, 2, 2, mem, 64), FE_OK);
    {
        fe_kalman k3;
        double m3[64];
        ck_assert_int_eq(fe_kalman_init(&k3, 3, 1, m3, 64), FE_OK);
        ck_assert_int_eq(fe_kalman_copy(&k3, &k), FE_EMISMATCH);
    }
}
END_TEST

/* Issue 20: refusals at their edges, and the information form's prior and
   sums against direct calculations. */
START_TEST(edges_of_the_sizes_models_and_sums)
{
    /* Every bad dimension gives 0 doubles, each alone; the largest good
       one does not. */
    ck_assert_uint_eq(fe_kalman_info_doubles(0, 1), 0);
    ck_assert_uint_eq(fe_kalman_info_doubles(1, 0), 0);
    ck_assert_uint_eq(fe_kalman_info_doubles(FE_KALMAN_MAX_DIM + 1, 1), 0);
    ck_assert_uint_eq(fe_kalman_info_doubles(1, FE_KALMAN_MAX_DIM + 1), 0);
    ck_assert_uint_gt(fe_kalman_info_doubles(1, FE_KALMAN_MAX_DIM), 0);
    {   /* A packet larger than bmax, for the small kernels too. */
        kf f;
        const double A[4] = {1, 0, 0, 1}, z[2] = {1, 2}, Z[4] = {1, 0, 0, 1};
        fe_kalman_obs o = {2, A, z, Z};
        kf_make(&f, 2, 1);
        ck_assert_int_eq(fe_kalman_set_prior_scaled(&f.k, NULL, 1.0), FE_OK);
        ck_assert_int_eq(fe_kalman_update_fast(&f.k, &o, NULL), FE_ESIZE);
        ck_assert_int_eq(fe_kalman_update(&f.k, &o, NULL), FE_ESIZE);
        ck_assert_double_eq(f.k.x[0], 0.0);
        ck_assert_double_eq(f.k.P[0], 1.0);
        o.b = 1;                    /* at bmax: taken */
        ck_assert_int_eq(fe_kalman_update_fast(&f.k, &o, NULL), FE_OK);
        /* Scalar update from P = I, z = 1 on x0: x0 = 1/2, P00 = 1/2. */
        ck_assert_double_eq_tol(f.k.x[0], 0.5, 1e-15);
        ck_assert_double_eq_tol(f.k.P[0], 0.5, 1e-15);
        kf_free(&f);
    }
    {   /* A model with no control matrix ignores m and u (not read): the
           prediction is Phi x, Phi P Phi^T; a control matrix with a NaN
           input is refused and changes nothing. */
        kf f;
        const double Phi[4] = {1, 0.5, 0, 1}, x0[2] = {2, 4}, P0[4] = {1, 0, 0, 2};
        const double Gamma[2] = {0.5, 1}, ubad[1] = {NAN};
        fe_kalman_model nog = {Phi, NULL, NULL, 2, NULL};
        fe_kalman_model bad = {Phi, Gamma, ubad, 1, NULL};
        kf_make(&f, 2, 1);
        ck_assert_int_eq(fe_kalman_set_prior(&f.k, x0, P0), FE_OK);
        ck_assert_int_eq(fe_kalman_predict(&f.k, &bad), FE_ENONFINITE);
        ck_assert_double_eq(f.k.x[0], 2.0);
        ck_assert_double_eq(f.k.P[3], 2.0);
        /* A control matrix with m = 0 inputs is no control either: u is
           not needed (null), and the prediction is the same. */
        {
            fe_kalman_model none = {Phi, Gamma, NULL, 0, NULL};
            kf g;
            kf_make(&g, 2, 1);
            ck_assert_int_eq(fe_kalman_set_prior(&g.k, x0, P0), FE_OK);
            ck_assert_int_eq(fe_kalman_predict(&g.k, &none), FE_OK);
            ck_assert_double_eq_tol(g.k.x[0], 4.0, 1e-15);
            ck_assert_double_eq_tol(g.k.P[0], 1.5, 1e-15);
            kf_free(&g);
        }
        ck_assert_int_eq(fe_kalman_predict(&f.k, &nog), FE_OK);
        /* x = (2 + 0.5*4, 4); P = [[1 + 0.25*2, 0.5*2], [1, 2]]. */
        ck_assert_double_eq_tol(f.k.x[0], 4.0, 1e-15);
        ck_assert_double_eq_tol(f.k.x[1], 4.0, 1e-15);
        ck_assert_double_eq_tol(f.k.P[0], 1.5, 1e-15);
        ck_assert_double_eq_tol(f.k.P[1], 1.0, 1e-15);
        ck_assert_double_eq_tol(f.k.P[2], 1.0, 1e-15);
        ck_assert_double_eq_tol(f.k.P[3], 2.0, 1e-15);
        kf_free(&f);
    }
    {   /* The information prior in memory full of other numbers: Lambda is
           P0^{-1} (P0 Lambda = I, multiplied here) and eta solves
           P0 eta = x0. */
        enum { N = 3 };
        size_t len = fe_kalman_info_doubles(N, 2);
        double *m = malloc(len * sizeof *m), P0[N * N] = {4, 1, 0, 1, 3, 1, 0, 1, 2};
        const double x0[N] = {1, -2, 3};
        fe_kalman_info si;
        ck_assert_ptr_nonnull(m);
        for (size_t i = 0; i < len; i++)
            m[i] = -7.0;
        ck_assert_int_eq(fe_kalman_info_init(&si, N, 2, m, len), FE_OK);
        ck_assert_int_eq(fe_kalman_info_set_prior(&si, x0, P0), FE_OK);
        for (size_t i = 0; i < N; i++) {
            double e = 0.0;
            for (size_t j = 0; j < N; j++) {
                double s = 0.0;
                for (size_t k = 0; k < N; k++)
                    s += P0[i * N + k] * si.Lambda[k * N + j];
                ck_assert_double_eq_tol(s, i == j ? 1.0 : 0.0, 1e-14);
                e += P0[i * N + j] * si.eta[j];
            }
            ck_assert_double_eq_tol(e, x0[i], 1e-14);
        }
        free(m);
    }
    {   /* Merging sums at the edge of the doubles: 0.8e308 twice is
           1.6e308 (doubling is exact); 1e308 twice overflows and is
           refused, leaving s as it was. */
        kinfo a, b;
        kinfo_make(&a, 2, 1);
        kinfo_make(&b, 2, 1);
        ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&a.s, NULL, 1.0 / 0.8e308), FE_OK);
        ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&b.s, NULL, 1.0 / 0.8e308), FE_OK);
        {
            double l0 = a.s.Lambda[0];
            ck_assert_int_eq(fe_kalman_info_merge(&a.s, &b.s), FE_OK);
            ck_assert_double_eq(a.s.Lambda[0], 2.0 * l0);
            ck_assert(isfinite(a.s.Lambda[3]));
        }
        ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&a.s, NULL, 1e-308), FE_OK);
        ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&b.s, NULL, 1e-308), FE_OK);
        {
            double l0 = a.s.Lambda[0];
            ck_assert(isfinite(l0));
            ck_assert_int_eq(fe_kalman_info_merge(&a.s, &b.s), FE_ENONFINITE);
            ck_assert_double_eq(a.s.Lambda[0], l0);
            ck_assert_double_eq(a.s.Lambda[3], l0);
            ck_assert_double_eq(a.s.Lambda[1], 0.0);
        }
        free(a.mem);
        free(b.mem);
    }
    {   /* The scaled information prior: P0 = 2 I, x0 = (1, -4) gives
           Lambda = I / 2 and eta = x0 / 2; p0 = INFINITY zero information.
           A NaN p0 or an x0 not finite is a value not finite
           (FE_ENONFINITE, each alone, whatever the other is), p0 = 0 and
           below a prior that is not positive definite; each refusal leaves
           the prior as it was. */
        kinfo a;
        const double x0[2] = {1.0, -4.0}, want[4] = {0.5, 0.0, 0.0, 0.5};
        double bad[2] = {1.0, -4.0};
        kinfo_make(&a, 2, 1);
        ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&a.s, x0, 2.0), FE_OK);
        for (int i = 0; i < 4; i++)
            ck_assert_double_eq(a.s.Lambda[i], want[i]);
        ck_assert(a.s.eta[0] == 0.5 && a.s.eta[1] == -2.0);
        ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&a.s, NULL, NAN), FE_ENONFINITE);
        ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&a.s, x0, NAN), FE_ENONFINITE);
        for (int k = 0; k < 2; k++) {
            bad[1] = k == 0 ? NAN : -INFINITY;
            ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&a.s, bad, 1.0), FE_ENONFINITE);
            ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&a.s, bad, 0.0), FE_ENONFINITE);
        }
        ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&a.s, x0, 0.0), FE_ENOTPD);
        ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&a.s, x0, -1.0), FE_ENOTPD);
        for (int i = 0; i < 4; i++)
            ck_assert_double_eq(a.s.Lambda[i], want[i]);
        ck_assert(a.s.eta[0] == 0.5 && a.s.eta[1] == -2.0);
        ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&a.s, x0, INFINITY), FE_OK);
        for (int i = 0; i < 4; i++)
            ck_assert_double_eq(a.s.Lambda[i], 0.0);
        ck_assert(a.s.eta[0] == 0.0 && a.s.eta[1] == 0.0);
        /* x0 / p0 overflowing in either entry alone (1e300 / 1e-10) is
           refused, and the prior is the one before (p0 = infinity). */
        for (int k = 0; k < 2; k++) {
            bad[0] = k == 0 ? 1e300 : 1.0;
            bad[1] = k == 1 ? -1e300 : -4.0;
            ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&a.s, bad, 1e-10), FE_ENONFINITE);
            ck_assert(a.s.Lambda[0] == 0.0 && a.s.eta[0] == 0.0 && a.s.eta[1] == 0.0);
        }
        free(a.mem);
    }
}
END_TEST

/* --------------------------------------------------- symmetry, PD */

START_TEST(covariance_stays_exactly_symmetric)
{
    fe_rng r = fe_rng_seed(21);
    int rc = FE_OK, sym = 1, pd = 1;
    for (int fast = 0; fast < 2; fast++) {
        kf f;
        kf_make(&f, 5, 3);
        ck_assert_int_eq(fe_kalman_set_prior_scaled(&f.k, NULL, 100.0), FE_OK);
        for (int i = 0; i < 300; i++) {
            double A[15], z[3], Z[9];
            size_t b = 1 + (size_t)(i % 3);
            fe_kalman_obs o;
            random_vec(&r, b * 5, 1.0, A);
            random_vec(&r, b, 1.0, z);
            random_spd(&r, b, 0.01, Z);
            o = (fe_kalman_obs){b, A, z, Z};
            rc |= fast ? fe_kalman_update_fast(&f.k, &o, NULL)
                       : fe_kalman_update(&f.k, &o, NULL);
            sym &= is_symmetric(f.k.P, 5);
            pd &= is_pd(f.k.P, 5);
        }
        kf_free(&f);
    }
    ck_assert_int_eq(rc, FE_OK);
    ck_assert_msg(sym, "P lost exact symmetry");
    ck_assert_msg(pd, "P lost positive definiteness");
}
END_TEST

/* --------------------------------------------- fast path vs reference */

/* ------------------------------------------------ Joseph's form */

/* A vague prior P0 = p0 I against precise packets z = A x + v,
   v ~ N(0, zv I), with small integer A.  The reference is the information
   form P^{-1} = I/p0 + T/zv, T = sum A^T A (exact integers), inverted in
   closed form in long double with no subtraction: for n = 2,
   det = det(T)/zv^2 + tr(T)/(p0 zv) + 1/p0^2 with det(T) >= 0 an exact
   integer, and adj has no difference either. */
static void joseph_reference(size_t n, const long double *T, double p0, double zv,
                             long double *P)
{
    long double l0 = 1.0L / p0, z = zv;
    if (n == 1) {
        P[0] = 1.0L / (l0 + T[0] / z);
        return;
    }
    {
        long double detT = T[0] * T[3] - T[1] * T[2];
        long double det = detT / (z * z) + (T[0] + T[3]) * l0 / z + l0 * l0;
        P[0] = (l0 + T[3] / z) / det;
        P[3] = (l0 + T[0] / z) / det;
        P[1] = P[2] = -(T[1] / z) / det;
    }
}

START_TEST(joseph_form_against_long_double)
{
    /* Packet sequences: 1-D scalars; 2-D axis rows, then rotated rows;
       2-D full packets (b = 2).  Each row of `rows` is one measurement;
       `b` rows form a packet. */
    static const struct { size_t n, b, steps; double rows[12][2]; } seq[] = {
        {1, 1, 8, {{1}, {2}, {1}, {3}, {1}, {-1}, {2}, {1}}},
        {2, 1, 8, {{1, 0}, {0, 1}, {1, 1}, {1, -1}, {2, 1}, {0, 1}, {1, 3}, {1, 0}}},
        {2, 1, 6, {{0, 1}, {1, 0}, {0, 2}, {3, 0}, {1, 1}, {1, 2}}},
        {2, 2, 4, {{1, 0}, {0, 1}, {1, 1}, {1, -1}, {2, 1}, {1, 3}, {1, 0}, {0, 1}}},
        {2, 2, 3, {{1, 1}, {1, -1}, {1, 0}, {0, 1}, {2, 1}, {1, 3}}},
    };
    const double p0 = 1e10, zv = 1e-8;
    double worst = 0.0, standard_first = -1.0;

    for (size_t q = 0; q < sizeof seq / sizeof seq[0]; q++) {
        size_t n = seq[q].n, b = seq[q].b;
        kf f, g;
        long double T[4] = {0, 0, 0, 0}, Pref[4];
        fe_rng r = fe_rng_seed(900 + q);
        kf_make(&f, n, b);
        kf_make(&g, n, b);
        ck_assert_int_eq(fe_kalman_set_prior_scaled(&f.k, NULL, p0), FE_OK);
        ck_assert_int_eq(fe_kalman_set_prior_scaled(&g.k, NULL, p0), FE_OK);
        for (size_t t = 0; t < seq[q].steps; t++) {
            double A[4], z[2], Z[4] = {zv, 0, 0, zv};
            fe_kalman_obs o = {b, A, z, Z};
            for (size_t i = 0; i < b; i++) {
                for (size_t c = 0; c < n; c++)
                    A[i * n + c] = seq[q].rows[t * b + i][c];
                z[i] = 3.0 + fe_rng_normal(&r) * 1e-4;
            }
            if (b == 1)
                Z[0] = zv;
            else
                Z[0] = Z[3] = zv, Z[1] = Z[2] = 0.0;
            ck_assert_int_eq(fe_kalman_update_joseph(&f.k, &o, NULL), FE_OK);
            if (q == 0 && t == 0)
                ck_assert_int_eq(fe_kalman_update(&g.k, &o, NULL), FE_OK);
            for (size_t i = 0; i < b; i++)
                for (size_t c = 0; c < n; c++)
                    for (size_t e = 0; e < n; e++)
                        T[c * n + e] += (long double)A[i * n + c] * A[i * n + e];
            joseph_reference(n, T, p0, zv, Pref);
            /* Element by element: diagonal relative to itself,
               off-diagonal relative to sqrt(P_ii P_jj). */
            for (size_t c = 0; c < n; c++)
                for (size_t e = 0; e < n; e++) {
                    long double scale = sqrtl(Pref[c * n + c] * Pref[e * n + e]);
                    double err = (double)(fabsl(f.k.P[c * n + e] - Pref[c * n + e]) / scale);
                    ck_assert_msg(err <= 1e-6, "sequence %zu step %zu P[%zu][%zu] = %.17g, reference %.17Lg",
                                  q, t, c, e, f.k.P[c * n + e], Pref[c * n + e]);
                    worst = fmax(worst, err);
                }
            ck_assert(is_symmetric(f.k.P, n));
            if (q == 0 && t == 0)
                standard_first = g.k.P[0];
        }
        kf_free(&f);
        kf_free(&g);
    }
    /* The standard forms, for the record, after one step: the reference
       update is off by far more than the answer (a negative variance
       here), the fast path gives an exact 0. */
    ck_assert_double_gt(fabs(standard_first - 1e-8), 1e-8);
    {
        kf h;
        double A[1] = {1}, z[1] = {3}, Z[1] = {zv};
        fe_kalman_obs o = {1, A, z, Z};
        kf_make(&h, 1, 1);
        ck_assert_int_eq(fe_kalman_set_prior_scaled(&h.k, NULL, p0), FE_OK);
        ck_assert_int_eq(fe_kalman_update_fast(&h.k, &o, NULL), FE_OK);
        ck_assert_double_eq(h.k.P[0], 0.0);
        kf_free(&h);
    }
    fprintf(stderr, "Joseph form, P0 = 1e10 I, Z = 1e-8 I: worst relative error of P %.3g "
            "(standard form after one step: P = %g, fast path 0, want 1e-08)\n", worst, standard_first);
}
END_TEST

START_TEST(fast_path_equals_reference)
{
    fe_rng r = fe_rng_seed(77);
    double worst = 0.0, worst_rep = 0.0;
    int rc = FE_OK, same_b = 1;
    /* n = 10 runs the run-time-size path, the others the fixed-size kernels. */
    const size_t ns[5] = {1, 2, 4, 6, 10};
    for (int t = 0; t < 5; t++) {
        size_t n = ns[t];
        kf f, g;
        kf_make(&f, n, 4);
        kf_make(&g, n, 4);
        ck_assert_int_eq(fe_kalman_set_prior_scaled(&f.k, NULL, 10.0), FE_OK);
        ck_assert_int_eq(fe_kalman_set_prior_scaled(&g.k, NULL, 10.0), FE_OK);
        for (int i = 0; i < 60; i++) {
            double A[4 * 10], z[4], Z[16];
            double nu1[4], nu2[4], w1[4], w2[4], D1[16], D2[16];
            fe_kalman_report r1 = {0, 0, 0, nu1, w1, D1}, r2 = {0, 0, 0, nu2, w2, D2};
            size_t b = 1 + (size_t)(i % 4);
            fe_kalman_obs o;
            random_vec(&r, b * n, 1.0, A);
            random_vec(&r, b, 2.0, z);
            if (i % 2)
                random_spd(&r, b, 0.1, Z);
            else {      /* decorrelated: diagonal Z */
                memset(Z, 0, sizeof Z);
                for (size_t j = 0; j < b; j++)
                    Z[j * b + j] = 0.5 + fe_rng_uniform(&r);
            }
            o = (fe_kalman_obs){b, A, z, Z};
            rc |= fe_kalman_update(&f.k, &o, &r1);
            rc |= fe_kalman_update_fast(&g.k, &o, &r2);
            same_b &= r1.b == r2.b && r1.b == b;
            worst = fmax(worst, rel_diff(g.k.x, f.k.x, n));
            worst = fmax(worst, rel_diff(g.k.P, f.k.P, n * n));
            worst_rep = fmax(worst_rep, fabs(r2.nis - r1.nis) / fmax(1.0, r1.nis));
            worst_rep = fmax(worst_rep, fabs(r2.log_det_D - r1.log_det_D) / fmax(1.0, fabs(r1.log_det_D)));
            worst_rep = fmax(worst_rep, rel_diff(nu2, nu1, b));
            worst_rep = fmax(worst_rep, rel_diff(w2, w1, b));
            worst_rep = fmax(worst_rep, rel_diff(D2, D1, b * b));
        }
        kf_free(&f);
        kf_free(&g);
    }
    ck_assert_int_eq(rc, FE_OK);
    ck_assert(same_b);
    ck_assert_msg(worst <= 1e-12, "state: fast vs reference %.3g", worst);
    ck_assert_msg(worst_rep <= 1e-12, "report: fast vs reference %.3g", worst_rep);
}
END_TEST

START_TEST(report_is_the_innovation)
{
    /* nu = z - A x, NIS = nu^T D^{-1} nu = |w|^2, D = Z + A P A^T. */
    const double x0[2] = {1, -1}, P0[4] = {2, 0.5, 0.5, 1};
    const double A[4] = {1, 0, 1, 1}, z[2] = {2, 1}, Z[4] = {1, 0.2, 0.2, 0.5};
    double nu[2], w[2], D[4];
    fe_kalman_report rep = {0, 0, 0, nu, w, D};
    fe_kalman_obs o = {2, A, z, Z};
    kf f;
    double Dw[4], det, nis;
    kf_make(&f, 2, 2);
    ck_assert_int_eq(fe_kalman_set_prior(&f.k, x0, P0), FE_OK);
    ck_assert_int_eq(fe_kalman_update(&f.k, &o, &rep), FE_OK);
    FE_ASSERT_REL(nu[0], 1.0, 1e-15);
    FE_ASSERT_REL(nu[1], 1.0, 1e-15);
    /* A P A^T = [[2, 2.5], [2.5, 4]] */
    Dw[0] = 3.0; Dw[1] = 2.7; Dw[2] = 2.7; Dw[3] = 4.5;
    for (int i = 0; i < 4; i++)
        FE_ASSERT_REL(D[i], Dw[i], 1e-15);
    det = Dw[0] * Dw[3] - Dw[1] * Dw[2];
    nis = (Dw[3] - 2 * Dw[1] + Dw[0]) / det;   /* [1 1] D^{-1} [1 1]^T */
    FE_ASSERT_REL(rep.nis, nis, 1e-14);
    FE_ASSERT_REL(w[0] * w[0] + w[1] * w[1], nis, 1e-14);
    FE_ASSERT_REL(rep.log_det_D, log(det), 1e-14);
    ck_assert_uint_eq(rep.b, 2);
    kf_free(&f);
}
END_TEST

/* A scalar packet's report by each update, with each buffer asked for
   alone (the other two NULL) and all three at once: kalman.h says every
   buffer not NULL receives its value.  With x = (1, -1), P = [[2, 0.5],
   [0.5, 1]], a = (1, 1), z = 2 and Z = 1: P a = (2.5, 1.5), nu = z - a x
   = 2, D = Z + a P a^T = 5, whitened nu / sqrt(D), NIS nu^2 / D = 0.8,
   log det D = log 5; the state x + P a nu / D = (2, -0.4), and P minus
   (P a)(P a)^T / D = [[0.75, -0.25], [-0.25, 0.55]]. */
START_TEST(a_scalar_packet_reports_each_buffer_asked_for)
{
    typedef int update_fn(fe_kalman *, const fe_kalman_obs *, fe_kalman_report *);
    static update_fn *const update[3] = {fe_kalman_update, fe_kalman_update_joseph,
                                         fe_kalman_update_fast};
    const double x0[2] = {1, -1}, P0[4] = {2, 0.5, 0.5, 1};
    const double A[2] = {1, 1}, z[1] = {2}, Z[1] = {1};
    const double x1[2] = {2, -0.4}, P1[4] = {0.75, -0.25, -0.25, 0.55};
    fe_kalman_obs o = {1, A, z, Z};
    for (int u = 0; u < 3; u++)
        for (int ask = 0; ask < 4; ask++) {     /* nu, whitened, D alone; all */
            double nu = NAN, w = NAN, D = NAN;
            fe_kalman_report rep = {0, NAN, NAN, ask == 0 || ask == 3 ? &nu : NULL,
                                    ask == 1 || ask == 3 ? &w : NULL,
                                    ask == 2 || ask == 3 ? &D : NULL};
            kf f;
            kf_make(&f, 2, 1);
            ck_assert_int_eq(fe_kalman_set_prior(&f.k, x0, P0), FE_OK);
            ck_assert_int_eq(update[u](&f.k, &o, &rep), FE_OK);
            ck_assert_uint_eq(rep.b, 1);
            FE_ASSERT_REL(rep.nis, 0.8, 1e-15);
            FE_ASSERT_REL(rep.log_det_D, log(5.0), 1e-15);
            if (rep.innovation != NULL)
                FE_ASSERT_REL(nu, 2.0, 1e-15);
            if (rep.whitened != NULL)
                FE_ASSERT_REL(w, 2.0 / sqrt(5.0), 1e-15);
            if (rep.D != NULL)
                FE_ASSERT_REL(D, 5.0, 1e-15);
            for (int i = 0; i < 2; i++)
                FE_ASSERT_REL(f.k.x[i], x1[i], 1e-14);
            for (int i = 0; i < 4; i++)
                FE_ASSERT_REL(f.k.P[i], P1[i], 1e-14);
            kf_free(&f);
        }
}
END_TEST

/* --------------------------------------------------- the tracker */

/* The falling object of Kalman Folding 2, simulated with the model's own
   noise so that the filter's covariance is the truth's. */
typedef struct falling {
    double dt, g, sa, sz;
    double Phi[4], Gamma[2], Xi[4], u[1], A[2], Z[1];
} falling;

static void falling_init(falling *m, double sa, double sz)
{
    double dt = 0.1;
    m->dt = dt;
    m->g = -9.8;
    m->sa = sa;
    m->sz = sz;
    m->Phi[0] = 1; m->Phi[1] = dt; m->Phi[2] = 0; m->Phi[3] = 1;
    m->Gamma[0] = dt * dt / 2; m->Gamma[1] = dt;
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++)
            m->Xi[i * 2 + j] = sa * sa * m->Gamma[i] * m->Gamma[j];
    m->u[0] = m->g;
    m->A[0] = 1; m->A[1] = 0;
    m->Z[0] = sz * sz;
}

/* Advance the truth one step and observe it; returns z. */
static double falling_truth(const falling *m, fe_rng *r, double *s, double sz)
{
    double a = m->g + m->sa * fe_rng_normal(r);
    double p = s[0] + m->dt * s[1] + m->Gamma[0] * a;
    double v = s[1] + m->Gamma[1] * a;
    s[0] = p;
    s[1] = v;
    return p + sz * fe_rng_normal(r);
}

START_TEST(tracker_errors_within_two_sigma)
{
    int seeds = fe_test_quick() ? 30 : 200, steps = 100;
    long in_pos = 0, in_vel = 0, total = 0;
    int rc = FE_OK, spd = 1;
    double P0[4] = {4.0, 0, 0, 1.0};
    falling m;
    falling_init(&m, 0.5, 1.0);
    for (int seed = 0; seed < seeds; seed++) {
        fe_rng r = fe_rng_seed(1000 + (uint64_t)seed);
        double truth[2] = {1000.0, 0.0}, x0[2];
        kf f;
        kf_make(&f, 2, 1);
        /* The initial estimate is drawn from the prior, as the filter assumes. */
        x0[0] = truth[0] + 2.0 * fe_rng_normal(&r);
        x0[1] = truth[1] + 1.0 * fe_rng_normal(&r);
        ck_assert_int_eq(fe_kalman_set_prior(&f.k, x0, P0), FE_OK);
        for (int k = 0; k < steps; k++) {
            double z = falling_truth(&m, &r, truth, m.sz);
            fe_kalman_track_obs t = {{m.Phi, m.Gamma, m.u, 1, m.Xi},
                                     {1, m.A, &z, m.Z}};
            rc |= (seed % 2) ? fe_kalman_track_fast(&f.k, &t, NULL)
                             : fe_kalman_track(&f.k, &t, NULL);
            in_pos += fabs(f.k.x[0] - truth[0]) <= 2.0 * sqrt(f.k.P[0]);
            in_vel += fabs(f.k.x[1] - truth[1]) <= 2.0 * sqrt(f.k.P[3]);
            total++;
            spd &= f.k.P[1] == f.k.P[2] && f.k.P[0] > 0
                && f.k.P[0] * f.k.P[3] - f.k.P[1] * f.k.P[2] > 0;
        }
        kf_free(&f);
    }
    ck_assert_int_eq(rc, FE_OK);
    ck_assert_msg(spd, "covariance stopped being symmetric positive definite");
    ck_assert_msg(in_pos >= 0.90 * total, "position within 2 sigma: %ld of %ld", in_pos, total);
    ck_assert_msg(in_vel >= 0.90 * total, "speed within 2 sigma: %ld of %ld", in_vel, total);
    /* And not vacuously: the bounds are not absurdly wide (the 2-sigma
       coverage of a Gaussian is 95.4%; far above means a lying P). */
    ck_assert_msg(in_pos <= 0.99 * total && in_vel <= 0.99 * total,
                  "coverage suspiciously high: %ld, %ld of %ld", in_pos, in_vel, total);
}
END_TEST

START_TEST(tracker_fast_equals_reference)
{
    falling m;
    fe_rng r = fe_rng_seed(5);
    double truth[2] = {500, 10}, x0[2] = {505, 9};
    double worst = 0;
    kf f, g;
    falling_init(&m, 0.3, 2.0);
    kf_make(&f, 2, 1);
    kf_make(&g, 2, 1);
    ck_assert_int_eq(fe_kalman_set_prior_scaled(&f.k, x0, 25.0), FE_OK);
    ck_assert_int_eq(fe_kalman_set_prior_scaled(&g.k, x0, 25.0), FE_OK);
    for (int k = 0; k < 200; k++) {
        double z = falling_truth(&m, &r, truth, m.sz);
        fe_kalman_track_obs t = {{m.Phi, m.Gamma, m.u, 1, m.Xi}, {1, m.A, &z, m.Z}};
        ck_assert_int_eq(fe_kalman_track(&f.k, &t, NULL), FE_OK);
        ck_assert_int_eq(fe_kalman_track_fast(&g.k, &t, NULL), FE_OK);
        worst = fmax(worst, rel_diff(g.k.x, f.k.x, 2));
        worst = fmax(worst, rel_diff(g.k.P, f.k.P, 4));
    }
    ck_assert_msg(worst <= 1e-12, "fast tracker vs reference: %.3g", worst);
    /* Predict alone is predict-then-nothing: identity model keeps x. */
    {
        fe_kalman_model id = {NULL, NULL, NULL, 0, NULL};
        double x1 = f.k.x[0], p1 = f.k.P[0];
        uint64_t c = f.k.count;
        ck_assert_int_eq(fe_kalman_predict(&f.k, &id), FE_OK);
        ck_assert_double_eq(f.k.x[0], x1);
        ck_assert_double_eq(f.k.P[0], p1);
        ck_assert_uint_eq(f.k.count, c);
    }
    kf_free(&f);
    kf_free(&g);
}
END_TEST

/* --------------------------------------------------- information form */

enum { NPK = 30 };

static void make_packets(fe_rng *r, size_t n, double *A, double *z, double *Z,
                         size_t *b, fe_kalman_obs *o)
{
    for (int i = 0; i < NPK; i++) {
        b[i] = 1 + (size_t)(i % 3);
        random_vec(r, b[i] * n, 1.0, A + i * 3 * n);
        random_vec(r, b[i], 2.0, z + i * 3);
        random_spd(r, b[i], 0.2, Z + i * 9);
        o[i] = (fe_kalman_obs){b[i], A + i * 3 * n, z + i * 3, Z + i * 9};
    }
}

START_TEST(information_form_equals_covariance_form)
{
    enum { N = 4 };
    fe_rng r = fe_rng_seed(99);
    double A[NPK * 3 * N], z[NPK * 3], Z[NPK * 9], P0[N * N], x0[N];
    size_t b[NPK];
    fe_kalman_obs o[NPK];
    kf f, g;
    kinfo s;
    make_packets(&r, N, A, z, Z, b, o);
    random_spd(&r, N, 1.0, P0);
    random_vec(&r, N, 1.0, x0);
    kf_make(&f, N, 3);
    kf_make(&g, N, 3);
    kinfo_make(&s, N, 3);
    ck_assert_int_eq(fe_kalman_set_prior(&f.k, x0, P0), FE_OK);
    ck_assert_int_eq(fe_kalman_info_set_prior(&s.s, x0, P0), FE_OK);
    /* The prior alone converts back. */
    ck_assert_int_eq(fe_kalman_info_to_kalman(&s.s, &g.k), FE_OK);
    ck_assert_msg(rel_diff(g.k.P, P0, N * N) <= 1e-12, "prior P round trip");
    ck_assert_msg(rel_diff(g.k.x, x0, N) <= 1e-12, "prior x round trip");
    for (int i = 0; i < NPK; i++) {
        ck_assert_int_eq(fe_kalman_update(&f.k, &o[i], NULL), FE_OK);
        ck_assert_int_eq(fe_kalman_info_update(&s.s, &o[i]), FE_OK);
    }
    ck_assert(is_symmetric(s.s.Lambda, N));
    ck_assert_int_eq(fe_kalman_info_to_kalman(&s.s, &g.k), FE_OK);
    ck_assert_uint_eq(g.k.count, NPK);
    ck_assert_msg(rel_diff(g.k.x, f.k.x, N) <= 1e-10, "x: %.3g", rel_diff(g.k.x, f.k.x, N));
    ck_assert_msg(rel_diff(g.k.P, f.k.P, N * N) <= 1e-10, "P: %.3g", rel_diff(g.k.P, f.k.P, N * N));
    kf_free(&f);
    kf_free(&g);
    free(s.mem);
}
END_TEST

START_TEST(information_shards_merge_by_addition)
{
    enum { N = 3 };
    fe_rng r = fe_rng_seed(123);
    double A[NPK * 3 * N], z[NPK * 3], Z[NPK * 9];
    size_t b[NPK];
    fe_kalman_obs o[NPK];
    fe_accumulator acc = fe_kalman_info_accumulator();
    kinfo whole, prior;
    kf want, got;
    double worst = 0;
    make_packets(&r, N, A, z, Z, b, o);
    kinfo_make(&whole, N, 3);
    kinfo_make(&prior, N, 3);
    kf_make(&want, N, 3);
    kf_make(&got, N, 3);
    /* The prior is one more shard, counted once. */
    ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&prior.s, NULL, 50.0), FE_OK);
    ck_assert_int_eq(fe_copy(&acc, &whole.s, &prior.s), FE_OK);
    ck_assert_int_eq(fe_fold(&acc, &whole.s, o, NPK, NULL), FE_OK);
    ck_assert_int_eq(fe_kalman_info_to_kalman(&whole.s, &want.k), FE_OK);
    for (size_t c1 = 0; c1 <= NPK; c1 += 7)
        for (size_t c2 = c1; c2 <= NPK; c2 += 5) {
            kinfo a, bb, c;
            size_t done = 0;
            kinfo_make(&a, N, 3);
            kinfo_make(&bb, N, 3);
            kinfo_make(&c, N, 3);
            ck_assert_int_eq(fe_init(&acc, &a.s), FE_OK);
            ck_assert_int_eq(fe_fold(&acc, &a.s, o, c1, &done), FE_OK);
            ck_assert_uint_eq(done, c1);
            ck_assert_int_eq(fe_fold(&acc, &bb.s, o + c1, c2 - c1, NULL), FE_OK);
            ck_assert_int_eq(fe_fold(&acc, &c.s, o + c2, NPK - c2, NULL), FE_OK);
            /* (c + prior) + (a + b): any grouping, any order. */
            ck_assert_int_eq(fe_merge(&acc, &c.s, &prior.s), FE_OK);
            ck_assert_int_eq(fe_merge(&acc, &a.s, &bb.s), FE_OK);
            ck_assert_int_eq(fe_merge(&acc, &c.s, &a.s), FE_OK);
            ck_assert_uint_eq(c.s.count, NPK);
            ck_assert_int_eq(fe_kalman_info_to_kalman(&c.s, &got.k), FE_OK);
            worst = fmax(worst, rel_diff(got.k.x, want.k.x, N));
            worst = fmax(worst, rel_diff(got.k.P, want.k.P, N * N));
            free(a.mem);
            free(bb.mem);
            free(c.mem);
        }
    ck_assert_msg(worst <= 1e-12, "merged shards vs whole: %.3g", worst);
    {   /* Zero information is the identity, bit for bit. */
        kinfo e;
        double before[N + N * N];
        kinfo_make(&e, N, 3);
        memcpy(before, whole.mem, sizeof before);
        ck_assert_int_eq(fe_merge(&acc, &whole.s, &e.s), FE_OK);
        ck_assert_mem_eq(whole.mem, before, sizeof before);
        free(e.mem);
    }
    {   /* Merged with itself, an accumulation doubles: as merged with a copy. */
        kinfo self, copy;
        kinfo_make(&self, N, 3);
        kinfo_make(&copy, N, 3);
        ck_assert_int_eq(fe_copy(&acc, &self.s, &whole.s), FE_OK);
        ck_assert_int_eq(fe_copy(&acc, &copy.s, &whole.s), FE_OK);
        ck_assert_int_eq(fe_merge(&acc, &copy.s, &whole.s), FE_OK);
        ck_assert_int_eq(fe_kalman_info_merge(&self.s, &self.s), FE_OK);
        ck_assert_mem_eq(self.s.Lambda, copy.s.Lambda, N * N * sizeof(double));
        ck_assert_mem_eq(self.s.eta, copy.s.eta, N * sizeof(double));
        ck_assert_uint_eq(self.s.count, 2 * whole.s.count);
        for (size_t i = 0; i < N * N; i++)
            ck_assert_double_eq(self.s.Lambda[i], 2.0 * whole.s.Lambda[i]);
        free(self.mem);
        free(copy.mem);
    }
    {   /* Different dimensions do not merge, and nothing changes. */
        kinfo other;
        double before[N + N * N];
        kinfo_make(&other, N + 1, 1);
        memcpy(before, whole.mem, sizeof before);
        ck_assert_int_eq(fe_merge(&acc, &whole.s, &other.s), FE_EMISMATCH);
        ck_assert_mem_eq(whole.mem, before, sizeof before);
        free(other.mem);
    }
    free(whole.mem);
    free(prior.mem);
    kf_free(&want);
    kf_free(&got);
}
END_TEST

/* The workspace of the information form holds, besides (G, g), either a
   copy of Z and Z^{-1}[A | z] (b^2 + b (n + 1) doubles) or a copy of P0
   and [I | x0] (n^2 + n (n + 1)); a packet of bmax > n rows needs the
   first.  Laid out over exactly fe_kalman_info_doubles(n, bmax) doubles,
   with guard doubles after them, a packet of bmax rows folds to
   Lambda = A^T Z^{-1} A and eta = A^T Z^{-1} z (Z diagonal: sums of
   A_ij A_ik / Z_ii, every term exact), and not one guard is written. */
START_TEST(a_packet_wider_than_the_state_folds_within_the_information_buffer)
{
    enum { B = 4, GUARD = 64 };
    const double Zd[B] = {1.0, 2.0, 4.0, 8.0}, z[B] = {1.0, -2.0, 3.0, -4.0};
    for (size_t n = 1; n < B; n++) {
        size_t len = fe_kalman_info_doubles(n, B);
        double A[B * B], Z[B * B] = {0}, *mem;
        fe_kalman_info s;
        fe_kalman_obs o = {B, A, z, Z};
        ck_assert_uint_gt(len, 0);
        mem = malloc((len + GUARD) * sizeof *mem);
        ck_assert_ptr_nonnull(mem);
        for (size_t i = 0; i < GUARD; i++)
            mem[len + i] = 12345.0;
        for (size_t i = 0; i < B; i++) {
            Z[i * B + i] = Zd[i];
            for (size_t j = 0; j < n; j++)
                A[i * n + j] = (double)(i + 2 * j + 1) * (j % 2 ? -1.0 : 1.0);
        }
        ck_assert_int_eq(fe_kalman_info_init(&s, n, B, mem, len), FE_OK);
        ck_assert_int_eq(fe_kalman_info_update(&s, &o), FE_OK);
        for (size_t j = 0; j < n; j++) {
            double eta = 0.0;
            for (size_t i = 0; i < B; i++)
                eta += A[i * n + j] * z[i] / Zd[i];
            FE_ASSERT_REL(s.eta[j], eta, 1e-12);
            for (size_t k = 0; k < n; k++) {
                double lam = 0.0;
                for (size_t i = 0; i < B; i++)
                    lam += A[i * n + j] * A[i * n + k] / Zd[i];
                FE_ASSERT_REL(s.Lambda[j * n + k], lam, 1e-12);
            }
        }
        for (size_t i = 0; i < GUARD; i++)
            ck_assert_msg(mem[len + i] == 12345.0, "n = %zu: guard %zu written (%g)", n, i,
                          mem[len + i]);
        free(mem);
    }
}
END_TEST

/* --------------------------------------------------- accumulators */

START_TEST(accumulator_fold_equals_loop)
{
    enum { N = 4 };
    fe_rng r = fe_rng_seed(7);
    double A[NPK * 3 * N], z[NPK * 3], Z[NPK * 9], x0[N] = {1, 2, 3, 4};
    size_t b[NPK];
    fe_kalman_obs o[NPK];
    for (int fast = 0; fast < 2; fast++) {
        fe_kalman_config cfg = {x0, NULL, 10.0, fast};
        fe_accumulator acc = fe_kalman_accumulator(&cfg);
        kf f, g, h;
        size_t done = 0;
        make_packets(&r, N, A, z, Z, b, o);
        kf_make(&f, N, 3);
        kf_make(&g, N, 3);
        kf_make(&h, N, 3);
        /* Empty stream: the prior. */
        ck_assert_int_eq(fe_init(&acc, &f.k), FE_OK);
        ck_assert_int_eq(fe_fold(&acc, &f.k, o, 0, &done), FE_OK);
        ck_assert_uint_eq(done, 0);
        ck_assert_double_eq(f.k.x[2], 3.0);
        ck_assert_double_eq(f.k.P[5], 10.0);
        ck_assert_double_eq(f.k.P[1], 0.0);
        /* The fold equals the loop, bit for bit. */
        ck_assert_int_eq(fe_fold(&acc, &f.k, o, NPK, &done), FE_OK);
        ck_assert_uint_eq(done, NPK);
        ck_assert_int_eq(fe_kalman_set_prior_scaled(&g.k, x0, 10.0), FE_OK);
        for (int i = 0; i < NPK; i++)
            ck_assert_int_eq(fast ? fe_kalman_update_fast(&g.k, &o[i], NULL)
                                  : fe_kalman_update(&g.k, &o[i], NULL), FE_OK);
        ck_assert_mem_eq(f.k.x, g.k.x, N * sizeof(double));
        ck_assert_mem_eq(f.k.P, g.k.P, N * N * sizeof(double));
        /* Copies are deep; scans of a pointer-holding accumulation are refused. */
        ck_assert_int_eq(fe_copy(&acc, &h.k, &f.k), FE_OK);
        ck_assert_ptr_ne(h.k.x, f.k.x);
        ck_assert_mem_eq(h.k.P, f.k.P, N * N * sizeof(double));
        ck_assert_int_eq(fe_scan(&acc, &h.k, o, 1, h.mem, NULL), FE_ENOTSUP);
        ck_assert_int_eq(fe_merge(&acc, &h.k, &f.k), FE_ENOTSUP);
        /* A bad packet in the middle: fold stops exactly there. */
        {
            double Zbad = -1000.0;
            fe_kalman_obs bad[5];
            const double one = 1.0;
            const double a[4] = {1, 0, 0, 0};
            for (int i = 0; i < 5; i++)
                bad[i] = o[i];
            bad[3] = (fe_kalman_obs){1, a, &one, &Zbad};
            ck_assert_int_eq(fe_init(&acc, &h.k), FE_OK);
            ck_assert_int_eq(fe_fold(&acc, &h.k, bad, 5, &done), FE_ENOTPD);
            ck_assert_uint_eq(done, 3);
            ck_assert_uint_eq(h.k.count, 3);
        }
        kf_free(&f);
        kf_free(&g);
        kf_free(&h);
    }
    {   /* Without a configuration, fe_init has no prior to set. */
        fe_accumulator acc = fe_kalman_accumulator(NULL);
        kf f;
        kf_make(&f, 2, 1);
        ck_assert_int_eq(fe_init(&acc, &f.k), FE_ENOTSUP);
        kf_free(&f);
    }
}
END_TEST

START_TEST(track_accumulator_folds_a_tracker)
{
    enum { K = 50 };
    falling m;
    fe_rng r = fe_rng_seed(17);
    double truth[2] = {100, 0}, zs[K], x0[2] = {100, 0};
    fe_kalman_track_obs t[K];
    fe_kalman_config cfg = {x0, NULL, 1.0, 0};
    fe_accumulator acc = fe_kalman_track_accumulator(&cfg);
    kf f, g;
    falling_init(&m, 0.5, 1.0);
    for (int k = 0; k < K; k++) {
        zs[k] = falling_truth(&m, &r, truth, m.sz);
        t[k] = (fe_kalman_track_obs){{m.Phi, m.Gamma, m.u, 1, m.Xi}, {1, m.A, &zs[k], m.Z}};
    }
    kf_make(&f, 2, 1);
    kf_make(&g, 2, 1);
    ck_assert_int_eq(fe_init(&acc, &f.k), FE_OK);
    ck_assert_int_eq(fe_fold(&acc, &f.k, t, K, NULL), FE_OK);
    ck_assert_int_eq(fe_kalman_set_prior_scaled(&g.k, x0, 1.0), FE_OK);
    for (int k = 0; k < K; k++)
        ck_assert_int_eq(fe_kalman_track(&g.k, &t[k], NULL), FE_OK);
    ck_assert_mem_eq(f.k.x, g.k.x, 2 * sizeof(double));
    ck_assert_mem_eq(f.k.P, g.k.P, 4 * sizeof(double));
    /* The tracker followed the fall: about 100 - 9.8 * 5^2 / 2 at t = 5 s. */
    ck_assert_msg(fabs(f.k.x[0] - truth[0]) < 3.0, "tracker lost the object");
    kf_free(&f);
    kf_free(&g);
}
END_TEST

/* --------------------------------------------------- innovations */

/* Run the falling-object tracker for `steps`, the observation noise sd
   multiplied by `late_factor` from step `change` on (1-based), and the
   filter's gravity multiplied by `g_factor`; fold the reports into m. */
static void run_monitored(uint64_t seed, int steps, int change, double late_factor,
                          double g_factor, fe_kalman_monitor *mon)
{
    falling m, filt;
    fe_rng r = fe_rng_seed(seed);
    double truth[2] = {1000, 0};
    kf f;
    int rc = FE_OK;
    falling_init(&m, 0.5, 1.0);
    filt = m;
    filt.u[0] = m.g * g_factor;
    kf_make(&f, 2, 1);
    ck_assert_int_eq(fe_kalman_set_prior_scaled(&f.k, truth, 1.0), FE_OK);
    for (int k = 1; k <= steps; k++) {
        double sz = k >= change ? m.sz * late_factor : m.sz;
        double z = falling_truth(&m, &r, truth, sz), w;
        fe_kalman_report rep = {0, 0, 0, NULL, &w, NULL};
        fe_kalman_track_obs t = {{filt.Phi, filt.Gamma, filt.u, 1, filt.Xi},
                                 {1, filt.A, &z, filt.Z}};
        rc |= fe_kalman_track_fast(&f.k, &t, &rep);
        rc |= fe_kalman_monitor_add(mon, &rep);
    }
    ck_assert_int_eq(rc, FE_OK);
    kf_free(&f);
}

START_TEST(consistent_model_passes_the_monitor)
{
    fe_kalman_monitor mon;
    double lo, hi, mean;
    int steps = fe_test_quick() ? 1000 : 4000;
    ck_assert_int_eq(fe_kalman_monitor_init(&mon, NULL), FE_OK);
    ck_assert_int_eq(fe_kalman_monitor_nis_band(&mon, 0.99, &lo, &hi), FE_ETOOFEW);
    run_monitored(42, steps, steps + 1, 1.0, 1.0, &mon);
    ck_assert_uint_eq(mon.steps, (uint64_t)steps);
    ck_assert_int_eq(fe_kalman_monitor_nis_band(&mon, 0.99, &lo, &hi), FE_OK);
    mean = fe_kalman_monitor_mean_nis(&mon);
    ck_assert_msg(lo < 1.0 && 1.0 < hi && hi - lo < 0.3, "band [%g, %g]", lo, hi);
    ck_assert_msg(lo <= mean && mean <= hi, "mean NIS %g outside [%g, %g]", mean, lo, hi);
    for (size_t l = 1; l <= 4; l++) {
        uint64_t terms;
        double rho = fe_kalman_monitor_autocorr(&mon, l, &terms);
        ck_assert_uint_eq(terms, (uint64_t)steps - l);
        ck_assert_msg(fabs(rho) <= 4.0 / sqrt((double)terms),
                      "lag %zu autocorrelation %g on a right model", l, rho);
    }
    ck_assert_uint_eq(mon.alarms, 0);
    ck_assert_uint_eq(mon.alarm_step, 0);
}
END_TEST

START_TEST(monitor_says_when_consistency_is_lost)
{
    /* The sensor's noise triples at step 600: the mean NIS leaves its band
       and the CUSUM raises an alarm within a few steps, dating the onset
       close to 600.  Nothing before 600 alarms. */
    fe_kalman_monitor mon;
    double lo, hi;
    ck_assert_int_eq(fe_kalman_monitor_init(&mon, NULL), FE_OK);
    run_monitored(43, 1000, 600, 3.0, 1.0, &mon);
    ck_assert_int_eq(fe_kalman_monitor_nis_band(&mon, 0.99, &lo, &hi), FE_OK);
    ck_assert_msg(fe_kalman_monitor_mean_nis(&mon) > hi, "mean NIS %g not above %g",
                  fe_kalman_monitor_mean_nis(&mon), hi);
    ck_assert_int_eq(mon.alarm_side, +1);
    ck_assert_msg(mon.alarm_step >= 600 && mon.alarm_step <= 620,
                  "alarm at %llu", (unsigned long long)mon.alarm_step);
    ck_assert_msg(mon.onset_step >= 590 && mon.onset_step <= 605,
                  "onset at %llu", (unsigned long long)mon.onset_step);
    ck_assert_uint_gt(mon.alarms, 5);
}
END_TEST

START_TEST(monitor_sees_a_pessimistic_model)
{
    /* The sensor becomes four times more precise at step 600 and the
       filter does not know: the NIS shrinks, the lower CUSUM alarms. */
    fe_kalman_monitor mon;
    ck_assert_int_eq(fe_kalman_monitor_init(&mon, NULL), FE_OK);
    run_monitored(45, 1000, 600, 0.25, 1.0, &mon);
    ck_assert_int_eq(mon.alarm_side, -1);
    ck_assert_msg(mon.alarm_step >= 600 && mon.alarm_step <= 680,
                  "alarm at %llu", (unsigned long long)mon.alarm_step);
    ck_assert_msg(mon.onset_step >= 570 && mon.onset_step <= 610,
                  "onset at %llu", (unsigned long long)mon.onset_step);
}
END_TEST

START_TEST(wrong_dynamics_show_in_autocorrelation)
{
    /* The filter believes gravity is half what it is: the innovations
       carry a slowly varying bias, so they are strongly correlated. */
    fe_kalman_monitor mon;
    uint64_t terms;
    double rho;
    ck_assert_int_eq(fe_kalman_monitor_init(&mon, NULL), FE_OK);
    run_monitored(44, 1000, 2000, 1.0, 0.5, &mon);
    rho = fe_kalman_monitor_autocorr(&mon, 1, &terms);
    ck_assert_msg(rho > 10.0 / sqrt((double)terms), "lag-1 autocorrelation %g", rho);
    ck_assert_double_nan(fe_kalman_monitor_autocorr(&mon, 0, NULL));
    ck_assert_double_nan(fe_kalman_monitor_autocorr(&mon, 5, NULL));
}
END_TEST

START_TEST(monitor_scans_and_refuses)
{
    /* The monitor is a flat value: fe_scan gives the CUSUM at each step. */
    enum { K = 40 };
    fe_kalman_report reps[K];
    fe_kalman_monitor_params p = fe_kalman_monitor_default_params();
    fe_accumulator acc;
    fe_kalman_monitor m, out[K + 1], before;
    p.threshold = 5.0;
    acc = fe_kalman_monitor_accumulator(&p);
    for (int k = 0; k < K; k++)
        reps[k] = (fe_kalman_report){1, k < 20 ? 1.0 : 9.0, 0.0, NULL, NULL, NULL};
    ck_assert_int_eq(fe_init(&acc, &m), FE_OK);
    ck_assert_int_eq(fe_scan(&acc, &m, reps, K, out, NULL), FE_OK);
    ck_assert_double_eq(out[20].cusum_up, 0.0);   /* NIS 1 < the break-even */
    ck_assert_double_gt(out[21].cusum_up, 0.0);
    ck_assert_uint_eq(m.onset_step, 21);
    ck_assert_uint_gt(m.alarm_step, 21);
    ck_assert_double_eq(out[K].nis_sum, 20.0 + 9.0 * 20.0);
    before = m;
    {
        fe_kalman_report bad = {1, NAN, 0, NULL, NULL, NULL};
        fe_kalman_report neg = {1, -1.0, 0, NULL, NULL, NULL};
        fe_kalman_report nob = {0, 1.0, 0, NULL, NULL, NULL};
        /* A whitened innovation not finite in a component the monitor
           reads (the second of two), then in one it does not (the fifth
           of five: only FE_KALMAN_MONITOR_DIM = 4 are read). */
        double wh[5] = {0.5, NAN, 0.1, 0.2, INFINITY};
        fe_kalman_report badw = {2, 1.0, 0, NULL, wh, NULL};
        fe_kalman_report past = {5, 1.0, 0, NULL, wh, NULL};
        ck_assert_int_eq(fe_kalman_monitor_add(&m, &bad), FE_ENONFINITE);
        ck_assert_int_eq(fe_kalman_monitor_add(&m, &neg), FE_EINVAL);
        ck_assert_int_eq(fe_kalman_monitor_add(&m, &nob), FE_EINVAL);
        ck_assert_int_eq(fe_kalman_monitor_add(&m, &badw), FE_ENONFINITE);
        ck_assert_mem_eq(&m, &before, sizeof m);
        wh[1] = -0.3;
        ck_assert_int_eq(fe_kalman_monitor_add(&m, &past), FE_OK);
    }
    p.scale_down = 2.0;
    ck_assert_int_eq(fe_kalman_monitor_init(&m, &p), FE_EINVAL);
}
END_TEST

/* The two CUSUMs step by step against their formula (Page's recursion on
   the log-likelihood ratio of the NIS, chi-square on b degrees of
   freedom, scaled by lambda against 1): S <- max(0, S + llr), llr =
   -(b/2) ln lambda + (NIS/2)(1 - 1/lambda), lambda 3 up and 0.3 down,
   for reports of 1 to 3 dimensions and NIS from 0 to 12, under a
   threshold no sum reaches. */
START_TEST(cusums_follow_their_recursion)
{
    fe_kalman_monitor_params p = fe_kalman_monitor_default_params();
    fe_kalman_monitor m;
    double up = 0.0, down = 0.0, top_up = 0.0, top_down = 0.0;
    p.scale_up = 3.0;
    p.scale_down = 0.3;
    p.threshold = 1e9;
    ck_assert_int_eq(fe_kalman_monitor_init(&m, &p), FE_OK);
    for (int k = 0; k < 60; k++) {
        size_t b = 1 + (size_t)(k % 3);
        double nis = (double)((k * 7) % 13);
        fe_kalman_report r = {b, nis, 0.0, NULL, NULL, NULL};
        double lu = -0.5 * (double)b * log(3.0) + 0.5 * nis * (1.0 - 1.0 / 3.0);
        double ld = -0.5 * (double)b * log(0.3) + 0.5 * nis * (1.0 - 1.0 / 0.3);
        ck_assert_int_eq(fe_kalman_monitor_add(&m, &r), FE_OK);
        up = fmax(0.0, up + lu);
        down = fmax(0.0, down + ld);
        top_up = fmax(top_up, up);
        top_down = fmax(top_down, down);
        ck_assert_msg(fabs(m.cusum_up - up) <= 1e-12 * (1.0 + up), "step %d: up %.17g, want "
                      "%.17g", k, m.cusum_up, up);
        ck_assert_msg(fabs(m.cusum_down - down) <= 1e-12 * (1.0 + down), "step %d: down %.17g, "
                      "want %.17g", k, m.cusum_down, down);
    }
    ck_assert_double_gt(top_up, 1.0);            /* both sums moved */
    ck_assert_double_gt(top_down, 1.0);
    ck_assert_uint_eq(m.alarms, 0);
}
END_TEST

START_TEST(chi_square_quantiles)
{
    /* Tabulated values, six significant digits. */
    const double t[][3] = {{0.005, 10, 2.15586}, {0.025, 10, 3.24697},
                           {0.975, 10, 20.4832}, {0.995, 10, 25.1882},
                           {0.025, 100, 74.2219}, {0.975, 100, 129.561},
                           {0.95, 1, 3.84146},   {0.95, 3, 7.81473},
                           {0.005, 30, 13.7867}, {0.5, 2, 1.38629},
                           {0.05, 1, 0.00393214}};
    for (size_t i = 0; i < sizeof t / sizeof t[0]; i++)
        FE_ASSERT_REL(fe_chi2_quantile(t[i][0], t[i][1]), t[i][2], 5e-6);
    /* The median of chi-square(2) is 2 log 2 exactly. */
    FE_ASSERT_REL(fe_chi2_quantile(0.5, 2), 2.0 * log(2.0), 1e-13);
    ck_assert_double_nan(fe_chi2_quantile(0.0, 3));
    ck_assert_double_nan(fe_chi2_quantile(0.5, 0));
}
END_TEST

START_TEST(fast_update_refuses_a_singular_z_whose_whitened_row_is_infinite)
{
    /* One state, two observations of it (A = (1, 2)) with Z = [1 1; 1 1]:
       the Cholesky's second pivot is 1 - 1 = 0 and the second whitened
       row (2 - 1) / 0 infinite, not NaN; the fast update promises
       FE_ENOTPD for a Z that is not positive definite, with the filter
       unchanged (the reference update takes the packet: D = A P A^T + Z is
       positive definite). */
    kf f;
    const double x0 = 0.5, A[2] = {1, 2}, z[2] = {1, 3}, Z[4] = {1, 1, 1, 1};
    double snap[2];
    fe_kalman desc;
    fe_kalman_obs o = {2, A, z, Z};
    kf_make(&f, 1, 2);
    ck_assert_int_eq(fe_kalman_set_prior_scaled(&f.k, &x0, 4.0), FE_OK);
    memcpy(snap, f.mem, sizeof snap);
    desc = f.k;
    ck_assert_int_eq(fe_kalman_update_fast(&f.k, &o, NULL), FE_ENOTPD);
    ASSERT_UNCHANGED(f, snap, desc);
    ck_assert_int_eq(fe_kalman_update(&f.k, &o, NULL), FE_OK);
    kf_free(&f);
}
END_TEST

/* Issue 20: FE_KALMAN_MAX_DIM and the buffer length at their edges.  A
   state of FE_KALMAN_MAX_DIM is laid out over exactly fe_kalman_doubles
   (its x and P zeroed), one double less is FE_ESIZE, one dimension more
   sizes to 0 and is FE_ESIZE whatever the length; the same for bmax
   (a buffer never touched past x and P) and for the information form. */
START_TEST(the_largest_dimension_is_taken_and_one_more_refused)
{
    const size_t M = FE_KALMAN_MAX_DIM;
    size_t need = fe_kalman_doubles(M, 1), needb = fe_kalman_doubles(1, M);
    double *mem;
    fe_kalman k;
    fe_kalman_info s;
    ck_assert_uint_gt(need, M * M);
    ck_assert_uint_gt(needb, M * M);                /* D is bmax x bmax */
    ck_assert_uint_eq(fe_kalman_doubles(M + 1, 1), 0);
    ck_assert_uint_eq(fe_kalman_doubles(1, M + 1), 0);
    ck_assert_uint_gt(fe_kalman_info_doubles(M, 1), M * M);
    mem = malloc((need > needb ? need : needb) * sizeof *mem);
    ck_assert_ptr_nonnull(mem);
    mem[0] = mem[M + M * M - 1] = 7.0;
    ck_assert_int_eq(fe_kalman_init(&k, M, 1, mem, need - 1), FE_ESIZE);
    ck_assert_double_eq(mem[0], 7.0);
    ck_assert_int_eq(fe_kalman_init(&k, M, 1, mem, need), FE_OK);
    ck_assert_uint_eq(k.n, M);
    ck_assert_double_eq(mem[0], 0.0);
    ck_assert_double_eq(mem[M + M * M - 1], 0.0);   /* the last of P */
    ck_assert_int_eq(fe_kalman_init(&k, M + 1, 1, mem, need), FE_ESIZE);
    ck_assert_int_eq(fe_kalman_init(&k, 1, M, mem, needb - 1), FE_ESIZE);
    ck_assert_int_eq(fe_kalman_init(&k, 1, M, mem, needb), FE_OK);
    ck_assert_uint_eq(k.bmax, M);
    ck_assert_int_eq(fe_kalman_init(&k, 1, M + 1, mem, needb), FE_ESIZE);
    ck_assert_int_eq(fe_kalman_info_init(&s, 1, M, mem, fe_kalman_info_doubles(1, M) - 1),
                     FE_ESIZE);
    ck_assert_int_eq(fe_kalman_info_init(&s, 1, M, mem, fe_kalman_info_doubles(1, M)), FE_OK);
    ck_assert_int_eq(fe_kalman_info_init(&s, 1, M + 1, mem, needb), FE_ESIZE);
    free(mem);
}
END_TEST

/* Issue 20 (seed 10117's kalman:853): the information form's buffer is the
   layout kalman.org gives it, no more and no less: eta (n) and Lambda
   (n x n), the increment (G, g) of a packet (n x n + n), then room for
   the larger of a copy of Z with the b x (n + 1) block Z^{-1}[A | z]
   (b x b + b (n + 1)) and a copy of P0 with the n x (n + 1) block
   [I | x0] (n x n + n (n + 1)).  A buffer of exactly that many doubles
   takes a prior and a packet of bmax without a write past its end (the
   guard after it is left as it was), and one double less is FE_ESIZE. */
START_TEST(information_buffer_is_its_documented_layout)
{
    enum { PAD = 8 };
    static const size_t ns[] = {1, 2, 3, 5, 8}, bs[] = {1, 2, 4, 8};
    fe_rng rng = fe_rng_seed(10117);
    for (size_t i = 0; i < sizeof ns / sizeof *ns; i++)
        for (size_t j = 0; j < sizeof bs / sizeof *bs; j++) {
            const size_t n = ns[i], b = bs[j];
            const size_t packet = b * b + b * (n + 1), prior = n * n + n * (n + 1);
            const size_t len = n + n * n + (n * n + n) + (packet > prior ? packet : prior);
            double *m, P0[MAXD * MAXD], x0[MAXD], A[MAXD * MAXD], z[MAXD], Z[MAXD * MAXD];
            fe_kalman_info s;
            fe_kalman_obs o = {b, A, z, Z};
            ck_assert_msg(fe_kalman_info_doubles(n, b) == len, "n %zu, bmax %zu: %zu doubles, "
                          "the layout %zu", n, b, fe_kalman_info_doubles(n, b), len);
            m = malloc((len + PAD) * sizeof *m);
            ck_assert_ptr_nonnull(m);
            for (size_t k = 0; k < len + PAD; k++)
                m[k] = -7.0;
            ck_assert_int_eq(fe_kalman_info_init(&s, n, b, m, len - 1), FE_ESIZE);
            ck_assert_int_eq(fe_kalman_info_init(&s, n, b, m, len), FE_OK);
            random_spd(&rng, n, 1.0, P0);
            random_vec(&rng, n, 1.0, x0);
            ck_assert_int_eq(fe_kalman_info_set_prior(&s, x0, P0), FE_OK);
            for (size_t k = 0; k < b * n; k++)
                A[k] = fe_rng_normal(&rng);
            random_vec(&rng, b, 1.0, z);
            random_spd(&rng, b, 1.0, Z);
            ck_assert_int_eq(fe_kalman_info_update(&s, &o), FE_OK);
            ck_assert_uint_eq(s.count, 1);
            for (size_t k = len; k < len + PAD; k++)
                ck_assert_double_eq(m[k], -7.0);
            free(m);
        }
}
END_TEST

/* Issue 20: the packet size at bmax is folded and bmax + 1 refused with
   FE_ESIZE, the filter unchanged to the byte, by every update and
   tracker step, for a small state (fixed kernels) and one above them. */
START_TEST(a_packet_of_bmax_is_folded_and_one_more_refused_by_every_step)
{
    typedef int upd_fn(fe_kalman *, const fe_kalman_obs *, fe_kalman_report *);
    typedef int track_fn(fe_kalman *, const fe_kalman_track_obs *, fe_kalman_report *);
    upd_fn *const upd[3] = {fe_kalman_update, fe_kalman_update_fast, fe_kalman_update_joseph};
    track_fn *const trk[3] = {fe_kalman_track, fe_kalman_track_fast, fe_kalman_track_joseph};
    const size_t ns[2] = {2, 9};
    double A[3 * 9] = {0}, z[3] = {1, 2, 3}, Z[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    const double Z2[4] = {1, 0, 0, 1};
    for (int in = 0; in < 2; in++) {
        size_t n = ns[in];
        for (size_t i = 0; i < 3; i++)
            A[i * n + i % n] = 1.0;
        for (int v = 0; v < 6; v++) {
            kf f;
            fe_kalman desc;
            double *snap;
            fe_kalman_obs o = {3, A, z, Z};
            fe_kalman_track_obs to = {{NULL, NULL, NULL, 0, NULL}, o};
            kf_make(&f, n, 2);
            snap = malloc((n + n * n) * sizeof *snap);
            ck_assert_int_eq(fe_kalman_set_prior_scaled(&f.k, NULL, 1.0), FE_OK);
            memcpy(snap, f.mem, (n + n * n) * sizeof *snap);
            desc = f.k;
            ck_assert_int_eq(v < 3 ? upd[v](&f.k, &o, NULL) : trk[v - 3](&f.k, &to, NULL),
                             FE_ESIZE);
            ASSERT_UNCHANGED(f, snap, desc);
            o.b = to.obs.b = 2;                     /* at bmax */
            o.Z = to.obs.Z = Z2;
            ck_assert_int_eq(v < 3 ? upd[v](&f.k, &o, NULL) : trk[v - 3](&f.k, &to, NULL),
                             FE_OK);
            ck_assert_uint_eq(f.k.count, 1);
            /* x0 = 0, P = I, z_i = x_i + v, v ~ N(0, 1): x_i = z_i / 2. */
            ck_assert_double_eq_tol(f.k.x[0], 0.5, 1e-15);
            ck_assert_double_eq_tol(f.k.x[1], 1.0, 1e-15);
            ck_assert_double_eq_tol(f.k.P[0], 0.5, 1e-15);
            free(snap);
            kf_free(&f);
        }
        {
            kinfo s;
            double *copy;
            size_t len = fe_kalman_info_doubles(n, 2);
            fe_kalman_obs o = {3, A, z, Z};
            kinfo_make(&s, n, 2);
            copy = malloc(len * sizeof *copy);
            memcpy(copy, s.mem, len * sizeof *copy);
            ck_assert_int_eq(fe_kalman_info_update(&s.s, &o), FE_ESIZE);
            ck_assert_mem_eq(s.mem, copy, (n + n * n) * sizeof *copy);
            ck_assert_uint_eq(s.s.count, 0);
            o.b = 2;
            o.Z = Z2;
            ck_assert_int_eq(fe_kalman_info_update(&s.s, &o), FE_OK);
            ck_assert_double_eq(s.s.eta[1], 2.0);
            free(copy);
            free(s.mem);
        }
        memset(A, 0, sizeof A);
    }
}
END_TEST

/* Issue 20: the priors' variances at their edges: p0 = 0 is a covariance
   prior and the smallest negative double is FE_ENOTPD with the filter
   unchanged; the information prior needs p0 > 0, so 0 is refused and the
   smallest variance whose inverse is a double is taken. */
START_TEST(a_merge_that_overflows_in_any_one_sum_is_refused)
{
    /* Two information filters of 2 states, each holding 1e308 in one
       entry of Lambda or eta: the merge's sum, 2e308, overflows in that
       entry alone.  Each position in turn is refused with FE_ENONFINITE
       and the first filter left as it was; with 1e307 in the first
       (1.1e308) the same merge is taken. */
    for (size_t pos = 0; pos < 6; pos++)
        for (int fits = 0; fits < 2; fits++) {
            kinfo a, b;
            double snap_L[4], snap_e[2];
            double *ea, *eb;
            kinfo_make(&a, 2, 1);
            kinfo_make(&b, 2, 1);
            ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&a.s, NULL, 1.0), FE_OK);
            ea = pos < 4 ? &a.s.Lambda[pos] : &a.s.eta[pos - 4];
            eb = pos < 4 ? &b.s.Lambda[pos] : &b.s.eta[pos - 4];
            *ea = fits ? 1e307 : 1e308;
            *eb = 1e308;
            memcpy(snap_L, a.s.Lambda, sizeof snap_L);
            memcpy(snap_e, a.s.eta, sizeof snap_e);
            if (fits) {
                ck_assert_int_eq(fe_kalman_info_merge(&a.s, &b.s), FE_OK);
                ck_assert(isfinite(*ea));
            } else {
                ck_assert_int_eq(fe_kalman_info_merge(&a.s, &b.s), FE_ENONFINITE);
                ck_assert_mem_eq(a.s.Lambda, snap_L, sizeof snap_L);
                ck_assert_mem_eq(a.s.eta, snap_e, sizeof snap_e);
            }
            free(a.mem);
            free(b.mem);
        }
}
END_TEST

/* Issue 20: the information prior's covariance P0 is refused when any of
   its n^2 entries is not finite (FE_ENONFINITE, the accumulation as it
   was), even an entry of the lower triangle, which the Cholesky solve
   ('U') never reads and would otherwise pass over silently. */
START_TEST(an_information_prior_not_finite_in_any_entry_is_refused)
{
    enum { N = 3 };
    const double P0[N * N] = {4, 1, 0, 1, 3, 1, 0, 1, 2}, x0[N] = {1, -2, 3};
    const double bad[2] = {NAN, INFINITY};
    for (size_t pos = 0; pos < N * N; pos++)
        for (int b = 0; b < 2; b++) {
            kinfo s;
            double P[N * N], snap_L[N * N], snap_e[N];
            kinfo_make(&s, N, 1);
            ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&s.s, x0, 2.0), FE_OK);
            memcpy(snap_L, s.s.Lambda, sizeof snap_L);
            memcpy(snap_e, s.s.eta, sizeof snap_e);
            memcpy(P, P0, sizeof P);
            P[pos] = bad[b];
            ck_assert_msg(fe_kalman_info_set_prior(&s.s, x0, P) == FE_ENONFINITE,
                          "P0[%zu] = %g taken", pos, bad[b]);
            ck_assert_mem_eq(s.s.Lambda, snap_L, sizeof snap_L);
            ck_assert_mem_eq(s.s.eta, snap_e, sizeof snap_e);
            free(s.mem);
        }
}
END_TEST

/* Issue 20: the covariance form of an information accumulation whose
   state is not a double is refused, the filter unchanged.  Lambda =
   1e-300 I (a prior variance of 1e300) and eta = (1e10, 1): P = 1e300 I
   is finite, but x = P eta = (1e310, 1e300), its first entry past
   DBL_MAX. */
START_TEST(a_covariance_form_whose_state_overflows_is_refused)
{
    kinfo s;
    kf f;
    fe_kalman desc;
    double snap[2 + 4];
    const double x1[2] = {3.0, -1.0};
    kinfo_make(&s, 2, 1);
    kf_make(&f, 2, 1);
    ck_assert_int_eq(fe_kalman_set_prior_scaled(&f.k, x1, 5.0), FE_OK);
    memcpy(snap, f.mem, sizeof snap);
    desc = f.k;
    ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&s.s, NULL, 1e300), FE_OK);
    ck_assert_double_eq(s.s.Lambda[0], 1e-300);
    s.s.eta[0] = 1e10;
    s.s.eta[1] = 1.0;
    ck_assert(!isfinite(1e300 * 1e10));
    ck_assert_int_eq(fe_kalman_info_to_kalman(&s.s, &f.k), FE_ENONFINITE);
    ASSERT_UNCHANGED(f, snap, desc);
    /* With eta = (1e-10, 1) the state (1e290, 1e300) is a double, taken. */
    s.s.eta[0] = 1e-10;
    ck_assert_int_eq(fe_kalman_info_to_kalman(&s.s, &f.k), FE_OK);
    ck_assert_double_eq_tol(f.k.x[0], 1e290, 1e276);
    ck_assert_double_eq_tol(f.k.x[1], 1e300, 1e286);
    ck_assert_double_eq_tol(f.k.P[0], 1e300, 1e286);
    free(s.mem);
    kf_free(&f);
}
END_TEST

START_TEST(prior_variances_are_refused_just_below_their_edges)
{
    kf f;
    kinfo s;
    fe_kalman desc;
    double snap[2 + 4];
    kf_make(&f, 2, 1);
    ck_assert_int_eq(fe_kalman_set_prior_scaled(&f.k, NULL, 3.0), FE_OK);
    memcpy(snap, f.mem, sizeof snap);
    desc = f.k;
    ck_assert_int_eq(fe_kalman_set_prior_scaled(&f.k, NULL, -DBL_TRUE_MIN), FE_ENOTPD);
    ASSERT_UNCHANGED(f, snap, desc);
    ck_assert_int_eq(fe_kalman_set_prior_scaled(&f.k, NULL, 0.0), FE_OK);
    ck_assert_double_eq(f.k.P[0], 0.0);
    ck_assert_double_eq(f.k.P[3], 0.0);
    kf_free(&f);
    kinfo_make(&s, 2, 1);
    ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&s.s, NULL, 0.0), FE_ENOTPD);
    ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&s.s, NULL, -DBL_TRUE_MIN), FE_ENOTPD);
    ck_assert_double_eq(s.s.Lambda[0], 0.0);
    /* 1/p0 must be a double: the variance below the smallest whose
       inverse is one, and one whose x0/p0 overflows, are refused with the
       accumulation unchanged (they were once taken, as infinities). */
    {
        double pmin = nextafter(1.0 / DBL_MAX, 1.0), x0[2] = {1.0, 0.0}, big[2] = {0.0, 1e300};
        while (!isfinite(1.0 / pmin))
            pmin = nextafter(pmin, 1.0);
        ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&s.s, x0, 1.0), FE_OK);
        ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&s.s, NULL, nextafter(pmin, 0.0)),
                         FE_ENONFINITE);
        ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&s.s, big, 1e-10), FE_ENONFINITE);
        ck_assert_double_eq(s.s.Lambda[0], 1.0);
        ck_assert_double_eq(s.s.eta[0], 1.0);
        ck_assert_double_eq(s.s.eta[1], 0.0);
        ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&s.s, x0, pmin), FE_OK);
        ck_assert(isfinite(s.s.Lambda[0]) && s.s.Lambda[0] > 1e307);
        ck_assert_double_eq(s.s.Lambda[3], s.s.Lambda[0]);
        ck_assert_double_eq(s.s.eta[0], s.s.Lambda[0]);
    }
    ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&s.s, NULL, INFINITY), FE_OK);
    ck_assert_double_eq(s.s.Lambda[0], 0.0);       /* zero information */
    free(s.mem);
}
END_TEST

/* Issue 20: the monitor's parameters, band and reports at their edges:
   each open bound refused at its value and taken one double inside. */
START_TEST(monitor_ranges_are_refused_at_their_bounds_and_taken_just_inside)
{
    const fe_kalman_monitor_params d = fe_kalman_monitor_default_params();
    fe_kalman_monitor_params p;
    fe_kalman_monitor m, before;
    fe_kalman_report r = {1, 1.0, 0.0, NULL, NULL, NULL};
    double lo = -1, hi = -1;
    struct { int field; double bad, good; } cases[] = {
        {0, 1.0, 0}, {1, 1.0, 0}, {1, 0.0, DBL_TRUE_MIN}, {2, 0.0, DBL_TRUE_MIN},
    };
    cases[0].good = nextafter(1.0, 2.0);            /* scale_up > 1 */
    cases[1].good = nextafter(1.0, 0.0);            /* 0 < scale_down < 1 */
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        double *field[3] = {&p.scale_up, &p.scale_down, &p.threshold};
        p = d;
        *field[cases[i].field] = cases[i].bad;
        ck_assert_msg(fe_kalman_monitor_init(&m, &p) == FE_EINVAL, "case %zu", i);
        *field[cases[i].field] = cases[i].good;
        ck_assert_msg(fe_kalman_monitor_init(&m, &p) == FE_OK, "case %zu", i);
    }
    p = d;
    p.lags = FE_KALMAN_MONITOR_LAGS + 1;
    ck_assert_int_eq(fe_kalman_monitor_init(&m, &p), FE_EINVAL);
    p.lags = 0;
    ck_assert_int_eq(fe_kalman_monitor_init(&m, &p), FE_OK);
    p.lags = FE_KALMAN_MONITOR_LAGS;
    ck_assert_int_eq(fe_kalman_monitor_init(&m, &p), FE_OK);
    /* A report: NIS 0 is folded, the smallest negative one is not. */
    ck_assert_int_eq(fe_kalman_monitor_add(&m, &r), FE_OK);
    before = m;
    r.nis = -DBL_TRUE_MIN;
    ck_assert_int_eq(fe_kalman_monitor_add(&m, &r), FE_EINVAL);
    ck_assert_mem_eq(&m, &before, sizeof m);
    r.nis = 0.0;
    ck_assert_int_eq(fe_kalman_monitor_add(&m, &r), FE_OK);
    ck_assert_uint_eq(m.steps, 2);
    /* The band: prob in (0, 1). */
    ck_assert_int_eq(fe_kalman_monitor_nis_band(&m, 0.0, &lo, &hi), FE_EINVAL);
    ck_assert_int_eq(fe_kalman_monitor_nis_band(&m, 1.0, &lo, &hi), FE_EINVAL);
    ck_assert_double_eq(lo, -1.0);
    ck_assert_int_eq(fe_kalman_monitor_nis_band(&m, DBL_TRUE_MIN, &lo, &hi), FE_OK);
    ck_assert(isfinite(lo) && isfinite(hi) && lo <= hi);
    FE_ASSERT_REL(lo, hi, 1e-12);                   /* the median, both sides */
    /* The largest double below 1 is refused: (1 + prob)/2 rounds to 1
       (it was taken, with hi NaN); the next one down is taken. */
    lo = hi = -1.0;
    ck_assert_int_eq(fe_kalman_monitor_nis_band(&m, nextafter(1.0, 0.0), &lo, &hi), FE_EINVAL);
    ck_assert_double_eq(hi, -1.0);
    ck_assert_int_eq(fe_kalman_monitor_nis_band(&m, nextafter(nextafter(1.0, 0.0), 0.0), &lo,
                                                &hi), FE_OK);
    ck_assert(isfinite(lo) && isfinite(hi) && 0.0 <= lo && lo < hi);
    ck_assert_double_gt(hi, 30.0);                  /* chi2_2 / 2 beyond 1 - 2^-53 */
}
END_TEST

Suite *fe_kalman_suite(void)
{
    Suite *s = suite_create("kalman");
    TCase *t = tcase_create("core");
    tcase_set_timeout(t, 120);
    tcase_add_test(t, least_squares_5x4);
    tcase_add_test(t, fast_update_refuses_a_singular_z_whose_whitened_row_is_infinite);
    tcase_add_test(t, mean_is_a_kalman_filter);
    tcase_add_test(t, update_matches_textbook_for_b_ne_n);
    tcase_add_test(t, row_major_dposv_needs_ldb_nrhs);
    tcase_add_test(t, bad_packets_are_refused_and_nothing_changes);
    tcase_add_test(t, sizes_and_arguments);
    tcase_add_test(t, edges_of_the_sizes_models_and_sums);
    tcase_add_test(t, covariance_stays_exactly_symmetric);
    tcase_add_test(t, fast_path_equals_reference);
    tcase_add_test(t, joseph_form_against_long_double);
    tcase_add_test(t, report_is_the_innovation);
    tcase_add_test(t, a_scalar_packet_reports_each_buffer_asked_for);
    tcase_add_test(t, tracker_errors_within_two_sigma);
    tcase_add_test(t, tracker_fast_equals_reference);
    tcase_add_test(t, information_form_equals_covariance_form);
    tcase_add_test(t, information_shards_merge_by_addition);
    tcase_add_test(t, a_packet_wider_than_the_state_folds_within_the_information_buffer);
    tcase_add_test(t, accumulator_fold_equals_loop);
    tcase_add_test(t, track_accumulator_folds_a_tracker);
    tcase_add_test(t, consistent_model_passes_the_monitor);
    tcase_add_test(t, monitor_says_when_consistency_is_lost);
    tcase_add_test(t, monitor_sees_a_pessimistic_model);
    tcase_add_test(t, wrong_dynamics_show_in_autocorrelation);
    tcase_add_test(t, monitor_scans_and_refuses);
    tcase_add_test(t, cusums_follow_their_recursion);
    tcase_add_test(t, chi_square_quantiles);
    tcase_add_test(t, the_largest_dimension_is_taken_and_one_more_refused);
    tcase_add_test(t, information_buffer_is_its_documented_layout);
    tcase_add_test(t, a_packet_of_bmax_is_folded_and_one_more_refused_by_every_step);
    tcase_add_test(t, prior_variances_are_refused_just_below_their_edges);
    tcase_add_test(t, a_merge_that_overflows_in_any_one_sum_is_refused);
    tcase_add_test(t, an_information_prior_not_finite_in_any_entry_is_refused);
    tcase_add_test(t, a_covariance_form_whose_state_overflows_is_refused);
    tcase_add_test(t, monitor_ranges_are_refused_at_their_bounds_and_taken_just_inside);
    suite_add_tcase(s, t);
    return s;
}
