/* SPDX-License-Identifier: MIT */
/* The normal-equation accumulator: streaming equals batch (LAPACK's dgels
   on the same rows), merge of every split equals the whole, sub-model
   solves equal refits, the Schur score equals the drop in RSS, refusal of
   bad rows, rank deficiency reported and never a NaN. */
#include <float.h>
#include <stdint.h>

#include <lapacke.h>

#include "foldest.h"
#include "testutil.h"

enum { M = 200, P = 6, D = P + 1 };

/* A reproducible problem: m rows of p regressors of different scales,
   r = J x_true + sd * noise; weights in [0.5, 2) when w != NULL. */
static void make_problem(uint64_t seed, size_t m, size_t p, double sd,
                         double *J, double *r, double *w)
{
    fe_rng g = fe_rng_seed(seed);
    for (size_t i = 0; i < m; i++) {
        double y = 0.0;
        for (size_t k = 0; k < p; k++) {
            double v = (1.0 + (double)k) * fe_rng_normal(&g) + 0.3 * (double)k;
            J[i * p + k] = v;
            y += (0.5 - 0.25 * (double)k) * v;
        }
        r[i] = y + sd * fe_rng_normal(&g);
        if (w != NULL)
            w[i] = 0.5 + 1.5 * fe_rng_uniform(&g);
    }
}

/* Batch reference: least squares on the columns cols[0..q-1] of J with
   dgels (QR), rows scaled by sqrt(w).  x[0..q-1] and the RSS. */
static double batch_fit(const double *J, const double *r, const double *w,
                        size_t m, size_t p, const size_t *cols, size_t q,
                        double *x)
{
    double *A = malloc(m * q * sizeof *A), *b = malloc(m * sizeof *b), rss = 0;
    for (size_t i = 0; i < m; i++) {
        double s = w != NULL ? sqrt(w[i]) : 1.0;
        for (size_t k = 0; k < q; k++)
            A[i * q + k] = s * J[i * p + cols[k]];
        b[i] = s * r[i];
    }
    ck_assert_int_eq(LAPACKE_dgels(LAPACK_ROW_MAJOR, 'N', (lapack_int)m,
                                   (lapack_int)q, 1, A, (lapack_int)q, b, 1), 0);
    for (size_t k = 0; k < q; k++)
        x[k] = b[k];
    for (size_t i = q; i < m; i++)
        rss += b[i] * b[i];
    free(A);
    free(b);
    return rss;
}

static double max_rel(const double *got, const double *want, size_t n)
{
    double e = 0.0, s = 0.0;
    for (size_t k = 0; k < n; k++)
        s = fmax(s, fabs(want[k]));
    for (size_t k = 0; k < n; k++)
        e = fmax(e, fabs(got[k] - want[k]) / s);
    return e;
}

static const size_t all_cols[P] = {0, 1, 2, 3, 4, 5};

START_TEST(streaming_equals_dgels)
{
    static double J[M * P], r[M], g[D * D], g2[D * D];
    double x[P], xb[P], rss, rssb, work[D * D];
    fe_lsq a, b;
    fe_accumulator f = fe_lsq_accumulator();
    fe_lsq_row rows[M];
    size_t done = 0;

    make_problem(1, M, P, 0.1, J, r, NULL);
    ck_assert_int_eq(fe_lsq_init(&a, P, g), FE_OK);
    for (size_t i = 0; i < M; i++)
        ck_assert_int_eq(fe_lsq_add(&a, J + i * P, r[i], 1.0), FE_OK);
    ck_assert_uint_eq(a.n, M);
    ck_assert_double_eq(a.wsum, (double)M);
    ck_assert_uint_ge(fe_lsq_solve_work(P), D * D);
    ck_assert_int_eq(fe_lsq_solve(&a, NULL, P, x, &rss, NULL, work), FE_OK);
    rssb = batch_fit(J, r, NULL, M, P, all_cols, P, xb);
    ck_assert_double_le(max_rel(x, xb, P), 1e-10);
    FE_ASSERT_REL(rss, rssb, 1e-10);

    /* The generic fold over fe_lsq_row gives the same, bit for bit. */
    for (size_t i = 0; i < M; i++)
        rows[i] = (fe_lsq_row){J + i * P, r[i], 1.0};
    ck_assert_int_eq(fe_lsq_init(&b, P, g2), FE_OK);
    ck_assert_int_eq(fe_fold(&f, &b, rows, M, &done), FE_OK);
    ck_assert_uint_eq(done, M);
    ck_assert_mem_eq(g, g2, sizeof g);
    /* The array form folds blocks with BLAS: equal up to rounding. */
    ck_assert_int_eq(fe_init(&f, &b), FE_OK);
    ck_assert_int_eq(fe_lsq_add_rows(&b, J, P, r, NULL, M, &done), FE_OK);
    ck_assert_uint_eq(done, M);
    ck_assert_uint_eq(b.n, M);
    ck_assert_double_eq(b.wsum, (double)M);
    for (size_t k = 0; k < D; k++)
        for (size_t l = k; l < D; l++)
            ck_assert_double_eq_tol(g2[k * D + l], g[k * D + l],
                                    1e-14 * sqrt(g[k * D + k] * g[l * D + l]));
    for (size_t k = 0; k < D; k++)
        for (size_t l = 0; l < k; l++)
            ck_assert_double_eq(g2[k * D + l], 0.0);    /* lower stays zero */
}
END_TEST

START_TEST(weighted_equals_scaled_dgels)
{
    static double J[M * P], r[M], w[M], g[D * D];
    double x[P], xb[P], rss, rssb, work[D * D], wsum = 0.0;
    fe_lsq a;

    make_problem(2, M, P, 0.2, J, r, w);
    ck_assert_int_eq(fe_lsq_init(&a, P, g), FE_OK);
    ck_assert_int_eq(fe_lsq_add_rows(&a, J, P, r, w, M, NULL), FE_OK);
    for (size_t i = 0; i < M; i++)
        wsum += w[i];
    FE_ASSERT_REL(a.wsum, wsum, 1e-14);
    ck_assert_int_eq(fe_lsq_solve(&a, NULL, P, x, &rss, NULL, work), FE_OK);
    rssb = batch_fit(J, r, w, M, P, all_cols, P, xb);
    ck_assert_double_le(max_rel(x, xb, P), 1e-10);
    FE_ASSERT_REL(rss, rssb, 1e-10);
}
END_TEST

START_TEST(merge_every_split_equals_the_whole)
{
    enum { N = 40 };
    static double J[N * P], r[N], w[N];
    double gw[D * D], gl[D * D], gr[D * D], ge[D * D], before[D * D];
    double err = 0.0;
    fe_lsq whole, left, right, empty;
    fe_accumulator f = fe_lsq_accumulator();
    int rc = FE_OK;

    make_problem(3, N, P, 0.5, J, r, w);
    fe_lsq_init(&whole, P, gw);
    ck_assert_int_eq(fe_lsq_add_rows(&whole, J, P, r, w, N, NULL), FE_OK);
    for (size_t s = 0; s <= N; s++) {
        fe_lsq_init(&left, P, gl);
        fe_lsq_init(&right, P, gr);
        rc |= fe_lsq_add_rows(&left, J, P, r, w, s, NULL);
        rc |= fe_lsq_add_rows(&right, J + s * P, P, r + s, w + s, N - s, NULL);
        rc |= fe_merge(&f, &left, &right);
        if (left.n != N)
            rc |= 1000;
        err = fmax(err, fabs(left.wsum - whole.wsum) / whole.wsum);
        for (size_t k = 0; k < D; k++)
            for (size_t l = k; l < D; l++) {
                double scale = sqrt(gw[k * D + k] * gw[l * D + l]);
                err = fmax(err, fabs(gl[k * D + l] - gw[k * D + l]) / scale);
            }
    }
    ck_assert_int_eq(rc, FE_OK);
    ck_assert_double_le(err, 1e-14);

    /* The empty accumulation is the identity of merge, bit for bit. */
    fe_lsq_init(&empty, P, ge);
    memcpy(before, gw, sizeof gw);
    ck_assert_int_eq(fe_lsq_merge(&whole, &empty), FE_OK);
    ck_assert_mem_eq(gw, before, sizeof gw);
    ck_assert_int_eq(fe_lsq_merge(&empty, &whole), FE_OK);
    ck_assert_mem_eq(ge, gw, sizeof gw);
    ck_assert_uint_eq(empty.n, whole.n);
}
END_TEST

START_TEST(merge_is_associative_and_checks_shapes)
{
    enum { N = 30 };
    static double J[N * P], r[N];
    double g1[D * D], g2[D * D], g3[D * D], gL[D * D], gR[D * D], gq[9], before[D * D];
    fe_lsq a1, a2, a3, L, R, q;

    make_problem(4, N, P, 0.5, J, r, NULL);
    fe_lsq_init(&a1, P, g1);
    fe_lsq_init(&a2, P, g2);
    fe_lsq_init(&a3, P, g3);
    fe_lsq_add_rows(&a1, J, P, r, NULL, 10, NULL);
    fe_lsq_add_rows(&a2, J + 10 * P, P, r + 10, NULL, 7, NULL);
    fe_lsq_add_rows(&a3, J + 17 * P, P, r + 17, NULL, 13, NULL);
    fe_lsq_init(&L, P, gL);
    fe_lsq_init(&R, P, gR);
    ck_assert_int_eq(fe_lsq_copy(&L, &a1), FE_OK);       /* (1 + 2) + 3 */
    fe_lsq_merge(&L, &a2);
    fe_lsq_merge(&L, &a3);
    ck_assert_int_eq(fe_lsq_copy(&R, &a2), FE_OK);       /* 1 + (2 + 3) */
    fe_lsq_merge(&R, &a3);
    fe_lsq_merge(&a1, &R);
    for (size_t k = 0; k < D; k++)
        for (size_t l = k; l < D; l++)
            ck_assert_double_eq_tol(gL[k * D + l], g1[k * D + l],
                                    1e-13 * sqrt(gL[k * D + k] * gL[l * D + l]));
    /* Different column counts do not merge or copy; nothing changes. */
    fe_lsq_init(&q, 2, gq);
    memcpy(before, gL, sizeof gL);
    ck_assert_int_eq(fe_lsq_merge(&L, &q), FE_EMISMATCH);
    ck_assert_int_eq(fe_lsq_copy(&L, &q), FE_EMISMATCH);
    ck_assert_mem_eq(gL, before, sizeof gL);
    ck_assert_int_eq(fe_lsq_merge(&L, &L), FE_EINVAL);
}
END_TEST

START_TEST(every_subset_solves_like_a_refit)
{
    static double J[M * P], r[M], w[M];
    double worst_x = 0.0, worst_rss = 0.0, worst_refit = 0.0;
    double g[D * D];
    fe_lsq a;
    int rc = FE_OK;

    make_problem(5, M, P, 0.3, J, r, w);
    fe_lsq_init(&a, P, g);
    ck_assert_int_eq(fe_lsq_add_rows(&a, J, P, r, w, M, NULL), FE_OK);
    for (unsigned mask = 1; mask < (1u << P); mask++) {
        size_t cols[P], q = 0;
        double x[P], xb[P], xr[P], rss, rssb, rssr, work[D * D];
        double sub_j[M * P], gs[D * D];
        fe_lsq s;
        for (size_t k = 0; k < P; k++)
            if (mask & (1u << k))
                cols[q++] = k;
        /* Solve from the one accumulation. */
        rc |= fe_lsq_solve(&a, cols, q, x, &rss, NULL, work);
        /* Against QR on the same columns. */
        rssb = batch_fit(J, r, w, M, P, cols, q, xb);
        worst_x = fmax(worst_x, max_rel(x, xb, q));
        worst_rss = fmax(worst_rss, fabs(rss - rssb) / rssb);
        /* Against a fresh accumulation of only those columns. */
        for (size_t i = 0; i < M; i++)
            for (size_t k = 0; k < q; k++)
                sub_j[i * q + k] = J[i * P + cols[k]];
        fe_lsq_init(&s, q, gs);
        rc |= fe_lsq_add_rows(&s, sub_j, q, r, w, M, NULL);
        rc |= fe_lsq_solve(&s, NULL, q, xr, &rssr, NULL, work);
        worst_refit = fmax(worst_refit, fmax(max_rel(x, xr, q), fabs(rss - rssr) / rssr));
    }
    ck_assert_int_eq(rc, FE_OK);
    ck_assert_double_le(worst_x, 1e-10);
    ck_assert_double_le(worst_rss, 1e-10);
    ck_assert_double_le(worst_refit, 1e-13);
}
END_TEST

START_TEST(score_is_the_drop_in_rss)
{
    static double J[M * P], r[M];
    double g[D * D];
    fe_lsq a;
    /* Bases of sizes 0..3; all columns as candidates (members of the base
       included: they must score 0). */
    const size_t bases[4][3] = {{0}, {2}, {1, 4}, {0, 3, 5}};
    const size_t sizes[4] = {0, 1, 2, 3};
    double worst = 0.0, worst_base = 0.0;
    int rc = FE_OK;

    make_problem(6, M, P, 0.3, J, r, NULL);
    fe_lsq_init(&a, P, g);
    ck_assert_int_eq(fe_lsq_add_rows(&a, J, P, r, NULL, M, NULL), FE_OK);
    for (size_t t = 0; t < 4; t++) {
        size_t qb = sizes[t];
        double score[P], schur[P], rssb, rss0 = 0, work[64];
        ck_assert_uint_le(fe_lsq_scores_work(qb, P), 64);
        rc |= fe_lsq_scores(&a, bases[t], qb, all_cols, P, score, schur, &rssb, work);
        if (qb > 0)
            rc |= fe_lsq_solve(&a, bases[t], qb, NULL, &rss0, NULL, work);
        else
            rss0 = fe_lsq_gram(&a, P, P);
        worst_base = fmax(worst_base, fabs(rssb - rss0) / rss0);
        for (size_t j = 0; j < P; j++) {
            size_t cols[4], in_base = 0;
            double rss1;
            for (size_t k = 0; k < qb; k++) {
                cols[k] = bases[t][k];
                in_base |= cols[k] == j;
            }
            if (in_base) {
                if (score[j] != 0.0)
                    rc |= 1000;
                continue;
            }
            cols[qb] = j;
            rc |= fe_lsq_solve(&a, cols, qb + 1, NULL, &rss1, NULL, work);
            worst = fmax(worst, fabs(score[j] - (rss0 - rss1)) / rss0);
        }
    }
    ck_assert_int_eq(rc, FE_OK);
    ck_assert_double_le(worst_base, 1e-12);
    ck_assert_double_le(worst, 1e-10);
}
END_TEST

START_TEST(covariance_is_sigma2_times_inverse)
{
    static double J[M * P], r[M];
    double g[D * D], x[P], rss, cov[P * P], work[D * D], A[P * P];
    double err = 0.0;
    fe_lsq a;

    make_problem(7, M, P, 0.3, J, r, NULL);
    fe_lsq_init(&a, P, g);
    fe_lsq_add_rows(&a, J, P, r, NULL, M, NULL);
    ck_assert_int_eq(fe_lsq_solve(&a, NULL, P, x, &rss, cov, work), FE_OK);
    /* J'J computed directly; cov * J'J / sigma^2 = I. */
    for (size_t k = 0; k < P; k++)
        for (size_t l = 0; l < P; l++) {
            double s = 0.0;
            for (size_t i = 0; i < M; i++)
                s += J[i * P + k] * J[i * P + l];
            A[k * P + l] = s;
        }
    for (size_t k = 0; k < P; k++)
        for (size_t l = 0; l < P; l++) {
            double s = 0.0;
            for (size_t i = 0; i < P; i++)
                s += cov[k * P + i] * A[i * P + l];
            s /= rss / (double)(M - P);
            err = fmax(err, fabs(s - (k == l ? 1.0 : 0.0)));
        }
    ck_assert_double_le(err, 1e-10);
    /* Symmetric, positive diagonal. */
    for (size_t k = 0; k < P; k++) {
        ck_assert_double_gt(cov[k * P + k], 0.0);
        for (size_t l = 0; l < k; l++)
            ck_assert_double_eq(cov[k * P + l], cov[l * P + k]);
    }
}
END_TEST

START_TEST(dependent_columns_are_singular_never_nan)
{
    enum { N = 50, Q = 4, DQ = Q + 1 };
    double J[N * Q], r[N], g[DQ * DQ], work[64], x[Q], cov[Q * Q], rss = -1.0;
    double score[Q], x0[Q];
    const size_t dep[2] = {1, 3}, one[1] = {1}, zero_col[1] = {2}, cand[Q] = {0, 1, 2, 3};
    fe_rng rng = fe_rng_seed(8);
    fe_lsq a;

    for (size_t i = 0; i < N; i++) {
        J[i * Q + 0] = fe_rng_normal(&rng);
        J[i * Q + 1] = fe_rng_normal(&rng);
        J[i * Q + 2] = 0.0;                      /* a zero column */
        J[i * Q + 3] = -3.0 * J[i * Q + 1];       /* a multiple of column 1 */
        r[i] = J[i * Q] + fe_rng_normal(&rng);
    }
    fe_lsq_init(&a, Q, g);
    ck_assert_int_eq(fe_lsq_add_rows(&a, J, Q, r, NULL, N, NULL), FE_OK);
    for (size_t k = 0; k < Q; k++)
        x[k] = x0[k] = 42.0;
    ck_assert_int_eq(fe_lsq_solve(&a, NULL, Q, x, &rss, cov, work), FE_ESINGULAR);
    ck_assert_int_eq(fe_lsq_solve(&a, dep, 2, x, &rss, cov, work), FE_ESINGULAR);
    ck_assert_int_eq(fe_lsq_solve(&a, zero_col, 1, x, &rss, cov, work), FE_ESINGULAR);
    ck_assert_mem_eq(x, x0, sizeof x);                /* nothing written */
    ck_assert_double_eq(rss, -1.0);
    ck_assert_int_eq(fe_lsq_scores(&a, dep, 2, cand, Q, score, NULL, NULL, work),
                     FE_ESINGULAR);
    /* Base {1}: column 3 is in its span, column 2 is zero: both score 0;
       column 0 carries the signal. */
    ck_assert_int_eq(fe_lsq_scores(&a, one, 1, cand, Q, score, NULL, &rss, work), FE_OK);
    ck_assert_double_eq(score[1], 0.0);
    ck_assert_double_eq(score[2], 0.0);
    ck_assert_double_eq(score[3], 0.0);
    ck_assert_double_gt(score[0], 0.0);
    ck_assert(isfinite(rss));
}
END_TEST

START_TEST(bad_rows_are_refused_and_nothing_changes)
{
    static double J[M * P], r[M];
    double g[D * D], gbefore[D * D], row[P];
    fe_lsq a, before;
    fe_accumulator f = fe_lsq_accumulator();
    fe_lsq_row rows[3];
    size_t done = 99;
    const double bad[3] = {NAN, INFINITY, -INFINITY};
    int codes = 0;

    make_problem(9, M, P, 0.1, J, r, NULL);
    fe_lsq_init(&a, P, g);
    fe_lsq_add_rows(&a, J, P, r, NULL, M, NULL);
    before = a;
    memcpy(gbefore, g, sizeof g);
    for (int b = 0; b < 3; b++) {
        for (size_t k = 0; k < P; k++) {
            memcpy(row, J, sizeof row);
            row[k] = bad[b];
            codes |= fe_lsq_add(&a, row, 1.0, 1.0) != FE_ENONFINITE;
        }
        codes |= fe_lsq_add(&a, J, bad[b], 1.0) != FE_ENONFINITE;
        codes |= fe_lsq_add(&a, J, 1.0, bad[b]) != FE_ENONFINITE;
    }
    ck_assert_int_eq(codes, 0);
    ck_assert_int_eq(fe_lsq_add(&a, J, 1.0, -1.0), FE_EINVAL);
    /* Finite but overflowing. */
    memcpy(row, J, sizeof row);
    row[2] = 1e200;
    ck_assert_int_eq(fe_lsq_add(&a, row, 1.0, 1.0), FE_ENONFINITE);
    ck_assert_int_eq(fe_lsq_add(&a, J, 1.0, DBL_MAX), FE_ENONFINITE);
    ck_assert_mem_eq(&a, &before, sizeof a);
    ck_assert_mem_eq(g, gbefore, sizeof g);

    /* The generic fold stops exactly at the bad row. */
    row[2] = NAN;
    rows[0] = (fe_lsq_row){J, r[0], 1.0};
    rows[1] = (fe_lsq_row){row, 1.0, 1.0};
    rows[2] = (fe_lsq_row){J + P, r[1], 1.0};
    ck_assert_int_eq(fe_fold(&f, &a, rows, 3, &done), FE_ENONFINITE);
    ck_assert_uint_eq(done, 1);
    ck_assert_uint_eq(a.n, M + 1);
}
END_TEST

/* The sparse step refuses what the dense one refuses, with the same codes,
   and both refuse a total weight beyond DBL_MAX / 4 at its edge. */
START_TEST(sparse_rows_are_refused_like_dense_rows)
{
    double g[3 * 3], gbefore[3 * 3];
    const double bad[3] = {NAN, INFINITY, -INFINITY}, zero[2] = {0, 0};
    const size_t idx[2] = {0, 1};
    const double val[2] = {1.0, 2.0};
    fe_lsq a, before;
    fe_lsq_init(&a, 2, g);
    ck_assert_int_eq(fe_lsq_add_sparse(&a, idx, val, 2, 1.0, 1.0), FE_OK);
    before = a;
    memcpy(gbefore, g, sizeof g);
    for (int b = 0; b < 3; b++) {
        double v[2] = {1.0, bad[b]};
        ck_assert_int_eq(fe_lsq_add_sparse(&a, idx, val, 2, 1.0, bad[b]), FE_ENONFINITE);
        ck_assert_int_eq(fe_lsq_add(&a, val, 1.0, bad[b]), FE_ENONFINITE);
        ck_assert_int_eq(fe_lsq_add_sparse(&a, idx, val, 2, bad[b], 1.0), FE_ENONFINITE);
        ck_assert_int_eq(fe_lsq_add_sparse(&a, idx, v, 2, 1.0, 1.0), FE_ENONFINITE);
    }
    ck_assert_int_eq(fe_lsq_add_sparse(&a, idx, val, 2, 1.0, -1.0), FE_EINVAL);
    ck_assert_mem_eq(&a, &before, sizeof a);
    ck_assert_mem_eq(g, gbefore, sizeof g);
    /* Rows of zeros weigh only in wsum: two of DBL_MAX / 8 reach the edge
       exactly and are taken; a third goes past it, by either step. */
    for (int sparse = 0; sparse < 2; sparse++) {
        fe_lsq_init(&a, 2, g);
        for (int k = 0; k < 2; k++)
            ck_assert_int_eq(sparse ? fe_lsq_add_sparse(&a, idx, zero, 2, 0.0, DBL_MAX / 8)
                                    : fe_lsq_add(&a, zero, 0.0, DBL_MAX / 8), FE_OK);
        ck_assert_double_eq(a.wsum, DBL_MAX / 4);
        before = a;
        ck_assert_int_eq(sparse ? fe_lsq_add_sparse(&a, idx, zero, 2, 0.0, DBL_MAX / 8)
                                : fe_lsq_add(&a, zero, 0.0, DBL_MAX / 8), FE_ENONFINITE);
        ck_assert_mem_eq(&a, &before, sizeof a);
    }
    /* A diagonal sum at the edge: rows (1, 0) and then rows (0, 0) with
       residual 1, each of weight DBL_MAX / 8, put w v^2 = DBL_MAX / 8 on
       one diagonal entry (a parameter's, then the residual's); two reach
       DBL_MAX / 4 exactly and are taken, a third goes past it.  The total
       weight stays at its own edge or under it, so the diagonal's test is
       the one that decides. */
    for (int sparse = 0; sparse < 2; sparse++)
        for (int on = 0; on < 2; on++) {
            const double one0[2] = {1.0, 0.0};
            const double *v = on == 0 ? one0 : zero;
            const double res = on == 0 ? 0.0 : 1.0;
            const size_t k = on == 0 ? 0 : 2;        /* g[k * 3 + k] */
            fe_lsq_init(&a, 2, g);
            for (int row = 0; row < 2; row++)
                ck_assert_int_eq(sparse ? fe_lsq_add_sparse(&a, idx, v, 2, res, DBL_MAX / 8)
                                        : fe_lsq_add(&a, v, res, DBL_MAX / 8), FE_OK);
            ck_assert_double_eq(g[k * 3 + k], DBL_MAX / 4);
            before = a;
            memcpy(gbefore, g, sizeof g);
            a.wsum = 0.0;                   /* only the diagonal at its edge */
            before.wsum = 0.0;
            ck_assert_int_eq(sparse ? fe_lsq_add_sparse(&a, idx, v, 2, res, DBL_MAX / 8)
                                    : fe_lsq_add(&a, v, res, DBL_MAX / 8), FE_ENONFINITE);
            ck_assert_mem_eq(&a, &before, sizeof a);
            ck_assert_mem_eq(g, gbefore, sizeof g);
        }
}
END_TEST

START_TEST(empty_single_and_bad_arguments)
{
    double g[4], work[16], x = 0, rss = 1, cov = 0;
    const double j = 2.0;
    const size_t cols2[2] = {0, 0}, col5[1] = {5};
    fe_lsq a;
    fe_accumulator f = fe_lsq_accumulator();
    double out[2 * sizeof(fe_lsq)];

    ck_assert_uint_eq(fe_lsq_storage(1), 4);
    ck_assert_int_eq(fe_lsq_init(&a, 1, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_init(&a, 1, g), FE_OK);
    ck_assert_int_eq(fe_lsq_solve(&a, NULL, 1, &x, &rss, NULL, work), FE_ETOOFEW);
    ck_assert_int_eq(fe_lsq_scores(&a, NULL, 0, NULL, 0, NULL, NULL, NULL, NULL), FE_ETOOFEW);
    /* One row: an exact fit. */
    ck_assert_int_eq(fe_lsq_add(&a, &j, 3.0, 1.0), FE_OK);
    ck_assert_int_eq(fe_lsq_solve(&a, NULL, 1, &x, &rss, NULL, work), FE_OK);
    ck_assert_double_eq_tol(x, 1.5, 1e-15);
    ck_assert_double_eq(rss, 0.0);
    ck_assert_int_eq(fe_lsq_solve(&a, NULL, 1, &x, &rss, &cov, work), FE_ETOOFEW);
    /* Bad column lists. */
    ck_assert_int_eq(fe_lsq_solve(&a, NULL, 0, &x, &rss, NULL, work), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_solve(&a, NULL, 2, &x, &rss, NULL, work), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_solve(&a, col5, 1, &x, &rss, NULL, work), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_solve(&a, cols2, 1, &x, &rss, NULL, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_scores(&a, col5, 1, NULL, 0, NULL, NULL, NULL, work), FE_EINVAL);
    /* fe_init resets; scans are not supported (the struct points to storage). */
    ck_assert_int_eq(fe_init(&f, &a), FE_OK);
    ck_assert_uint_eq(a.n, 0);
    ck_assert_double_eq(g[0] + g[1] + g[3], 0.0);
    ck_assert_int_eq(fe_scan(&f, &a, NULL, 0, out, NULL), FE_ENOTSUP);
}
END_TEST

/* Rows (1, 0 | 1), (1, 1 | 2), (1, 2 | 4): J'J = [3 3; 3 5], J'r = (7,
   10), r'r = 21, each exact.  Folded twice and merged, every sum doubles.
   A fold of m rows reads r[0 .. m) only, and an accumulation its own
   fe_lsq_storage(p) doubles only: the value after the rows is 1000 (its
   square would show in r'r), the doubles after each storage are NaN, and
   nothing changes. */
START_TEST(only_the_rows_and_storage_given_are_read)
{
    enum { TAIL = 8 };
    const double J[6] = {1, 0, 1, 1, 1, 2}, r[4] = {1, 2, 4, 1000};
    const double want[3][3] = {{6, 6, 14}, {6, 10, 20}, {14, 20, 42}};
    double ga[9 + TAIL], gb[9 + TAIL], x[2], rss, score, schur, rssb, work[16];
    const size_t base[1] = {0}, cand[1] = {1}, three[3] = {0, 1, 0};
    size_t done;
    fe_lsq a, b;
    for (int i = 0; i < 9 + TAIL; i++)
        ga[i] = gb[i] = NAN;
    ck_assert_uint_eq(fe_lsq_storage(2), 9);
    ck_assert_int_eq(fe_lsq_init(&a, 2, ga), FE_OK);
    ck_assert_int_eq(fe_lsq_init(&b, 2, gb), FE_OK);
    ck_assert_int_eq(fe_lsq_add_rows(&a, J, 2, r, NULL, 3, &done), FE_OK);
    ck_assert_uint_eq(done, 3);
    ck_assert_int_eq(fe_lsq_add_rows(&b, J, 2, r, NULL, 3, &done), FE_OK);
    ck_assert(fe_lsq_gram(&b, 2, 2) == 21.0 && fe_lsq_gram(&b, 0, 2) == 7.0
              && fe_lsq_gram(&b, 1, 1) == 5.0);
    ck_assert_int_eq(fe_lsq_merge(&a, &b), FE_OK);
    for (size_t k = 0; k < 3; k++)
        for (size_t l = 0; l < 3; l++)
            ck_assert_double_eq(fe_lsq_gram(&a, k, l), want[k][l]);
    ck_assert_uint_eq(a.n, 6);
    for (int i = 9; i < 9 + TAIL; i++)
        ck_assert(isnan(ga[i]) && isnan(gb[i]));
    /* [3 3; 3 5] x = (7, 10): x = (5/6, 3/2); rss = 2 (21 - 7 x1 - 10 x2) = 1/3. */
    ck_assert_int_eq(fe_lsq_solve(&a, NULL, 2, x, &rss, NULL, work), FE_OK);
    FE_ASSERT_REL(x[0], 5.0 / 6.0, 1e-14);
    FE_ASSERT_REL(x[1], 1.5, 1e-14);
    FE_ASSERT_REL(rss, 1.0 / 3.0, 1e-12);
    /* Column 1 added to column 0: s = 10 - 6 6 / 6 = 4, c = 20 - 6 14 / 6
       = 6, score c^2 / s = 9; the base's rss 42 - 14^2 / 6 = 28 / 3. */
    ck_assert_int_eq(fe_lsq_scores(&a, base, 1, cand, 1, &score, &schur, &rssb, work), FE_OK);
    FE_ASSERT_REL(score, 9.0, 1e-13);
    FE_ASSERT_REL(schur, 4.0, 1e-13);
    FE_ASSERT_REL(rssb, 28.0 / 3.0, 1e-13);
    FE_ASSERT_REL(rssb - score, rss, 1e-12);
    /* Candidates without a list or without scores, each alone; a base
       longer than p. */
    ck_assert_int_eq(fe_lsq_scores(&a, base, 1, NULL, 1, &score, NULL, NULL, work), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_scores(&a, base, 1, cand, 1, NULL, NULL, NULL, work), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_scores(&a, NULL, 0, NULL, 1, &score, NULL, NULL, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_scores(&a, three, 3, cand, 1, &score, NULL, NULL, work), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_scores(&a, NULL, 0, cand, 1, &score, NULL, NULL, NULL), FE_OK);
    ck_assert_double_eq(score, 20.0 * 20.0 / 10.0);     /* no base: G_jr^2 / G_jj */
}
END_TEST

START_TEST(exact_fit_has_zero_rss)
{
    enum { N = 30, Q = 3 };
    double J[N * Q], r[N], g[(Q + 1) * (Q + 1)], work[16], x[Q], rss = -1.0;
    const double xt[Q] = {1.0, -2.0, 0.5};
    fe_rng rng = fe_rng_seed(10);
    fe_lsq a;

    for (size_t i = 0; i < N; i++) {
        r[i] = 0.0;
        for (size_t k = 0; k < Q; k++) {
            J[i * Q + k] = fe_rng_normal(&rng);
            r[i] += xt[k] * J[i * Q + k];
        }
    }
    fe_lsq_init(&a, Q, g);
    fe_lsq_add_rows(&a, J, Q, r, NULL, N, NULL);
    ck_assert_int_eq(fe_lsq_solve(&a, NULL, Q, x, &rss, NULL, work), FE_OK);
    ck_assert_double_le(max_rel(x, xt, Q), 1e-13);
    /* G resolves an RSS only to about eps * r'r (lsq.org, "Cholesky, and
       the residual sum of squares"): never negative, and that small. */
    ck_assert_double_ge(rss, 0.0);
    ck_assert_double_le(rss, 16 * DBL_EPSILON * fe_lsq_gram(&a, Q, Q));
}
END_TEST

START_TEST(sparse_rows_equal_dense_rows)
{
    enum { Q = 9, DQ = Q + 1 };
    double gs[DQ * DQ], gd[DQ * DQ], row[Q], before[DQ * DQ];
    const size_t idx[3] = {7, 2, 4}, rep[2] = {3, 3}, out[1] = {Q};
    fe_rng rng = fe_rng_seed(11);
    fe_lsq s, d, s0;
    int rc = FE_OK;

    fe_lsq_init(&s, Q, gs);
    fe_lsq_init(&d, Q, gd);
    for (int i = 0; i < 50; i++) {
        double val[3], r = fe_rng_normal(&rng), w = 0.5 + fe_rng_uniform(&rng);
        memset(row, 0, sizeof row);
        for (int t = 0; t < 3; t++)
            row[idx[t]] = val[t] = fe_rng_normal(&rng);
        rc |= fe_lsq_add_sparse(&s, idx, val, 3, r, w);
        rc |= fe_lsq_add(&d, row, r, w);
    }
    ck_assert_int_eq(rc, FE_OK);
    /* The same products in the same order: equal bit for bit. */
    ck_assert_mem_eq(gs, gd, sizeof gs);
    ck_assert_uint_eq(s.n, d.n);
    /* Refusals leave it unchanged. */
    s0 = s;
    memcpy(before, gs, sizeof gs);
    ck_assert_int_eq(fe_lsq_add_sparse(&s, rep, row, 2, 1.0, 1.0), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_add_sparse(&s, out, row, 1, 1.0, 1.0), FE_EINVAL);
    row[0] = NAN;
    ck_assert_int_eq(fe_lsq_add_sparse(&s, idx, row, 3, 1.0, 1.0), FE_ENONFINITE);
    row[0] = 1e300;
    ck_assert_int_eq(fe_lsq_add_sparse(&s, idx, row, 3, 1.0, 1.0), FE_ENONFINITE);
    ck_assert_mem_eq(gs, before, sizeof gs);
    ck_assert_mem_eq(&s, &s0, sizeof s);
}
END_TEST

START_TEST(blocked_rows_stop_exactly_at_the_bad_row)
{
    /* A NaN deep inside the third block of 256: the blocked fold must
       fold exactly the rows before it, like the row-by-row fold. */
    enum { N = 1000, BAD = 600, Q = 5, DQ = Q + 1 };
    static double J[N * Q], r[N];
    double gf[DQ * DQ], gs[DQ * DQ], err = 0.0;
    fe_rng rng = fe_rng_seed(12);
    fe_lsq fast, slow;
    size_t done = 0;
    int rc = FE_OK;

    for (size_t i = 0; i < N * Q; i++)
        J[i] = fe_rng_normal(&rng);
    for (size_t i = 0; i < N; i++)
        r[i] = fe_rng_normal(&rng);
    J[BAD * Q + 3] = NAN;
    fe_lsq_init(&fast, Q, gf);
    fe_lsq_init(&slow, Q, gs);
    ck_assert_int_eq(fe_lsq_add_rows(&fast, J, Q, r, NULL, N, &done), FE_ENONFINITE);
    ck_assert_uint_eq(done, BAD);
    ck_assert_uint_eq(fast.n, BAD);
    for (size_t i = 0; i < BAD; i++)
        rc |= fe_lsq_add(&slow, J + i * Q, r[i], 1.0);
    ck_assert_int_eq(rc, FE_OK);
    for (size_t k = 0; k < DQ * DQ; k++)
        err = fmax(err, fabs(gf[k] - gs[k]));
    ck_assert_double_le(err, 1e-12 * gs[0]);
    /* An overflow inside a block is refused the same way. */
    J[BAD * Q + 3] = 1e300;
    fe_lsq_reset(&fast);
    ck_assert_int_eq(fe_lsq_add_rows(&fast, J, Q, r, NULL, N, &done), FE_ENONFINITE);
    ck_assert_uint_eq(done, BAD);
    /* And in the response alone: a NaN, then a value whose square
       overflows, with every regressor finite. */
    J[BAD * Q + 3] = 0.5;
    for (int b = 0; b < 2; b++) {
        double keep = r[BAD];
        r[BAD] = b == 0 ? NAN : 1e300;
        fe_lsq_reset(&fast);
        ck_assert_int_eq(fe_lsq_add_rows(&fast, J, Q, r, NULL, N, &done), FE_ENONFINITE);
        ck_assert_uint_eq(done, BAD);
        ck_assert_uint_eq(fast.n, BAD);
        r[BAD] = keep;
    }
}
END_TEST

/* The residual's sum of squares at its edge in an unweighted block: with
   every regressor 0 and residuals 2^510 (squares 2^1020, exact), three
   rows sum to 3 2^1020 = 1.5 2^1021, under DBL_MAX / 4 = 2^1022 - 2^969;
   a fourth would make 2^1022, past it (a finite double, but beyond the
   bound of lsq.org).  In one call of four rows the block is refused and
   the row-by-row fold takes three: FE_ENONFINITE, *done = 3, G_rr = 3
   2^1020.  A fifth row passed alone to the same accumulation is refused
   with nothing changed.  The suite's residual refusals in a block were a
   NaN and 1e300, whose square is not finite, so a test that looked at
   the wrong entry of G, or subtracted, still refused them; seed 10223's
   neighbours of lsq:121 did that (lsq:118 to 120, and 122, which tied the
   residual's test to the total weight's). */
START_TEST(a_blocked_residual_sum_past_its_edge_is_refused)
{
    const double r = 0x1p510, J[4] = {0.0, 0.0, 0.0, 0.0}, rs[4] = {r, r, r, r};
    double g[2 * 2], gbefore[2 * 2];
    fe_lsq a, before;
    size_t done = 99;
    ck_assert_double_eq(r * r, 0x1p1020);
    ck_assert(3.0 * 0x1p1020 <= DBL_MAX / 4);
    ck_assert(!(4.0 * 0x1p1020 <= DBL_MAX / 4));
    fe_lsq_init(&a, 1, g);
    ck_assert_int_eq(fe_lsq_add_rows(&a, J, 1, rs, NULL, 4, &done), FE_ENONFINITE);
    ck_assert_uint_eq(done, 3);
    ck_assert_uint_eq(a.n, 3);
    ck_assert_double_eq(a.wsum, 3.0);
    ck_assert_double_eq(g[3], 3.0 * 0x1p1020);
    before = a;
    memcpy(gbefore, g, sizeof g);
    ck_assert_int_eq(fe_lsq_add_rows(&a, J, 1, rs, NULL, 1, &done), FE_ENONFINITE);
    ck_assert_uint_eq(done, 0);
    ck_assert_mem_eq(&a, &before, sizeof a);
    ck_assert_mem_eq(g, gbefore, sizeof g);
}
END_TEST

/* fe_lsq_add_rows' refusals at their edges: one row needs no stride
   (ldj 0 and p - 1 are taken for m = 1), two rows need ldj >= p (p - 1
   refused, p taken); null arguments are refused with nothing folded, and
   a null J is fine when p = 0; a negative weight is refused as by
   fe_lsq_add, after the rows before it. */
START_TEST(add_rows_arguments_at_their_edges)
{
    enum { Q = 3 };
    double g[(Q + 1) * (Q + 1)], g0[1], J[2 * Q] = {1, 2, 3, 4, 5, 6}, r[2] = {1, 2},
           w[2] = {1, -1};
    fe_lsq a, e;
    size_t done = 9;
    ck_assert_int_eq(fe_lsq_init(&a, Q, g), FE_OK);
    ck_assert_int_eq(fe_lsq_add_rows(&a, J, 0, r, NULL, 1, &done), FE_OK);
    ck_assert_uint_eq(done, 1);
    ck_assert_int_eq(fe_lsq_add_rows(&a, J, Q - 1, r, NULL, 1, &done), FE_OK);
    ck_assert_int_eq(fe_lsq_add_rows(&a, J, Q - 1, r, NULL, 2, &done), FE_EINVAL);
    ck_assert_uint_eq(done, 0);
    ck_assert_int_eq(fe_lsq_add_rows(&a, J, Q, r, NULL, 2, &done), FE_OK);
    ck_assert_uint_eq(done, 2);
    ck_assert_uint_eq(a.n, 4);
    /* (1, 2, 3) three times and (4, 5, 6) once: G_00 = 3 + 16. */
    ck_assert_double_eq(g[0], 19.0);
    ck_assert_int_eq(fe_lsq_add_rows(NULL, J, Q, r, NULL, 2, &done), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_add_rows(&a, NULL, Q, r, NULL, 2, &done), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_add_rows(&a, J, Q, NULL, NULL, 2, &done), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_add_rows(&a, NULL, Q, NULL, NULL, 0, &done), FE_OK);
    ck_assert_uint_eq(done, 0);
    ck_assert_uint_eq(a.n, 4);
    ck_assert_int_eq(fe_lsq_init(&e, 0, g0), FE_OK);
    ck_assert_int_eq(fe_lsq_add_rows(&e, NULL, 0, r, NULL, 2, &done), FE_OK);
    ck_assert_double_eq(g0[0], 5.0);
    ck_assert_int_eq(fe_lsq_add_rows(&a, J, Q, r, w, 2, &done), FE_EINVAL);
    ck_assert_uint_eq(done, 1);
    ck_assert_uint_eq(a.n, 5);
}
END_TEST

/* A merge whose diagonal sum would pass DBL_MAX / 4 (the room the
   library keeps for the solve) is refused with `a` unchanged; one that
   reaches it exactly is taken. */
START_TEST(merge_overflow_at_its_edge)
{
    double ga[16], gb[16], keep[16];
    const double j[3] = {1, 0, 0};
    fe_lsq a, b;
    ck_assert_int_eq(fe_lsq_init(&a, 3, ga), FE_OK);
    ck_assert_int_eq(fe_lsq_init(&b, 3, gb), FE_OK);
    ck_assert_int_eq(fe_lsq_add(&a, j, 0.0, DBL_MAX / 8), FE_OK);
    ck_assert_int_eq(fe_lsq_add(&b, j, 0.0, DBL_MAX / 8), FE_OK);
    ck_assert_int_eq(fe_lsq_merge(&a, &b), FE_OK);
    ck_assert_double_eq(ga[0], DBL_MAX / 4);
    memcpy(keep, ga, sizeof ga);
    ck_assert_int_eq(fe_lsq_merge(&a, &b), FE_ENONFINITE);
    ck_assert_mem_eq(ga, keep, sizeof ga);
    ck_assert_uint_eq(a.n, 2);
}
END_TEST

/* Issue 20: the step's weight, the column indices, the covariance's row
   count and the rank test at their edges.  A weight of 0 is a row that
   counts in n and adds nothing; -DBL_TRUE_MIN is refused, unchanged.
   Column p - 1 is a column and p is not, in every list; q = p columns
   solve, p + 1 do not.  The covariance needs n > q: n = q is FE_ETOOFEW,
   n = q + 1 gives rss / (n - q) A^{-1}. */
START_TEST(weights_indices_and_counts_at_their_edges)
{
    enum { Q = 3, DQ = Q + 1 };
    double g[DQ * DQ], gb[DQ * DQ], x[Q + 1], rss, cov[Q * Q], work[64], score[1];
    const double j[Q] = {1, 2, 3}, val[1] = {2.0};
    const size_t last[1] = {Q - 1}, past[1] = {Q}, all[Q + 1] = {0, 1, 2, 3};
    fe_lsq a, before;
    ck_assert_int_eq(fe_lsq_init(&a, Q, g), FE_OK);
    ck_assert_int_eq(fe_lsq_add(&a, j, 1.0, 1.0), FE_OK);
    before = a;
    memcpy(gb, g, sizeof g);
    ck_assert_int_eq(fe_lsq_add(&a, j, 1.0, -DBL_TRUE_MIN), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_add_sparse(&a, last, val, 1, 1.0, -DBL_TRUE_MIN), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_add_sparse(&a, past, val, 1, 1.0, 1.0), FE_EINVAL);
    /* One entry (nnz = 1) without its index or its value, or both, or an
       accumulation without storage: refused, nothing read or changed. */
    ck_assert_int_eq(fe_lsq_add_sparse(&a, NULL, val, 1, 1.0, 1.0), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_add_sparse(&a, last, NULL, 1, 1.0, 1.0), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_add_sparse(&a, NULL, NULL, 1, 1.0, 1.0), FE_EINVAL);
    {
        fe_lsq nog = a;
        nog.g = NULL;
        ck_assert_int_eq(fe_lsq_add_sparse(&nog, last, val, 1, 1.0, 1.0), FE_EINVAL);
        ck_assert_uint_eq(nog.n, 1);
    }
    ck_assert_mem_eq(&a, &before, sizeof a);
    ck_assert_mem_eq(g, gb, sizeof g);
    ck_assert_int_eq(fe_lsq_add(&a, j, 1.0, 0.0), FE_OK);
    ck_assert_uint_eq(a.n, 2);
    ck_assert_double_eq(a.wsum, 1.0);
    ck_assert_mem_eq(g, gb, sizeof g);              /* nothing added */
    /* A sparse row takes every weight from 0 up, as a dense one: 0 is
       counted and adds nothing; 1/2 and the double just below 1 add w v^2,
       w v r and w r^2 (v = 2, r = 1: each sum exact in binary). */
    ck_assert_int_eq(fe_lsq_add_sparse(&a, last, val, 1, 1.0, 0.0), FE_OK);
    ck_assert_uint_eq(a.n, 3);
    ck_assert_double_eq(a.wsum, 1.0);
    ck_assert_mem_eq(g, gb, sizeof g);              /* nothing added */
    ck_assert_int_eq(fe_lsq_add_sparse(&a, last, val, 1, 1.0, 0.5), FE_OK);
    ck_assert_uint_eq(a.n, 4);
    ck_assert_double_eq(a.wsum, 1.5);
    ck_assert_double_eq(fe_lsq_gram(&a, Q - 1, Q - 1), 9.0 + 2.0);
    ck_assert_double_eq(fe_lsq_gram(&a, Q - 1, Q), 3.0 + 1.0);
    ck_assert_double_eq(fe_lsq_gram(&a, Q, Q), 1.0 + 0.5);
    ck_assert_double_eq(fe_lsq_gram(&a, 0, Q - 1), 3.0);
    /* No entries (nnz = 0, neither array read): the response alone,
       w r^2 = 9/2 in G[p][p]. */
    ck_assert_int_eq(fe_lsq_reset(&a), FE_OK);
    ck_assert_int_eq(fe_lsq_add_sparse(&a, NULL, NULL, 0, 3.0, 0.5), FE_OK);
    ck_assert_uint_eq(a.n, 1);
    ck_assert_double_eq(a.wsum, 0.5);
    ck_assert_double_eq(fe_lsq_gram(&a, Q, Q), 4.5);
    for (size_t k = 0; k < Q; k++)
        for (size_t l = 0; l <= Q; l++)
            ck_assert_double_eq(fe_lsq_gram(&a, k, l), 0.0);
    ck_assert_int_eq(fe_lsq_reset(&a), FE_OK);     /* alone: its sums exact */
    ck_assert_int_eq(fe_lsq_add_sparse(&a, last, val, 1, 1.0, 1.0 - 0x1p-53), FE_OK);
    ck_assert_uint_eq(a.n, 1);
    ck_assert_double_eq(a.wsum, 1.0 - 0x1p-53);
    ck_assert_double_eq(fe_lsq_gram(&a, Q - 1, Q - 1), 4.0 - 0x1p-51);
    ck_assert_double_eq(fe_lsq_gram(&a, Q - 1, Q), 2.0 - 0x1p-52);
    ck_assert_double_eq(fe_lsq_gram(&a, Q, Q), 1.0 - 0x1p-53);
    ck_assert_double_eq(fe_lsq_gram(&a, 0, 0), 0.0);
    /* Back to the row (1 2 3 | 1) with weights 1 and 0, then the sparse (0 0 2 | 1). */
    ck_assert_int_eq(fe_lsq_reset(&a), FE_OK);
    ck_assert_int_eq(fe_lsq_add(&a, j, 1.0, 1.0), FE_OK);
    ck_assert_int_eq(fe_lsq_add(&a, j, 1.0, 0.0), FE_OK);
    ck_assert_int_eq(fe_lsq_add_sparse(&a, last, val, 1, 1.0, 1.0), FE_OK);
    ck_assert_double_eq(fe_lsq_gram(&a, Q - 1, Q - 1), 9.0 + 4.0);
    ck_assert_double_eq(fe_lsq_gram(&a, Q - 1, Q), 3.0 + 2.0);
    ck_assert_int_eq(fe_lsq_solve(&a, past, 1, x, &rss, NULL, work), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_solve(&a, all, Q + 1, x, &rss, NULL, work), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_solve(&a, NULL, Q + 1, x, &rss, NULL, work), FE_EINVAL);
    /* Rows (1 2 3 | 1) and (0 0 2 | 1) alone (n = 2): column 2 fits with
       x = 5/13, rss = 2 - 25/13 = 1/13, variance rss / (2 - 1) / 13;
       columns 0 and 2 (q = n = 2) fit exactly, without a covariance
       until a third row comes. */
    ck_assert_int_eq(fe_lsq_reset(&a), FE_OK);
    ck_assert_int_eq(fe_lsq_add(&a, j, 1.0, 1.0), FE_OK);
    ck_assert_int_eq(fe_lsq_add_sparse(&a, last, val, 1, 1.0, 1.0), FE_OK);
    ck_assert_int_eq(fe_lsq_solve(&a, last, 1, x, &rss, cov, work), FE_OK);
    ck_assert_double_eq_tol(x[0], 5.0 / 13.0, 1e-15);
    ck_assert_double_eq_tol(rss, 1.0 / 13.0, 1e-15);
    ck_assert_double_eq_tol(cov[0], 1.0 / 169.0, 1e-16);
    {
        const size_t two[2] = {0, 2};
        double c2[4] = {-1, -1, -1, -1};
        ck_assert_int_eq(fe_lsq_solve(&a, two, 2, x, &rss, c2, work), FE_ETOOFEW);
        ck_assert_double_eq(c2[0], -1.0);
        ck_assert_int_eq(fe_lsq_solve(&a, two, 2, x, &rss, NULL, work), FE_OK);
        ck_assert_double_eq_tol(rss, 0.0, 1e-14);
        ck_assert_int_eq(fe_lsq_add(&a, j, 0.0, 1.0), FE_OK);
        ck_assert_int_eq(fe_lsq_solve(&a, two, 2, x, &rss, c2, work), FE_OK);
        ck_assert(isfinite(c2[0]) && c2[0] > 0.0);
    }
    ck_assert_int_eq(fe_lsq_scores(&a, past, 1, last, 1, score, NULL, NULL, work), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_scores(&a, last, 1, past, 1, score, NULL, NULL, work), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_scores(&a, NULL, 0, last, 1, score, NULL, NULL, work), FE_OK);
    ck_assert_double_gt(score[0], 0.0);
}
END_TEST

/* Issue 20: FE_LSQ_RANK_TOL at its edge.  Rows (1 1 | 1) and (0 d | 1):
   column 1's part unexplained by column 0 is d^2 / (1 + d^2) of its norm,
   so d^2 = 1.5e-12 passes the rank test and d^2 = 0.5e-12 does not, in
   the solve, as a base of the scores, and as a candidate (which then
   scores 0, and 1 = c^2 / s with c = d, s = d^2 above the edge). */
START_TEST(rank_test_at_its_edge)
{
    for (int c = 0; c < 2; c++) {
        double d2 = c == 0 ? 1.5e-12 : 0.5e-12, d = sqrt(d2), g[9], x[2], rss, work[64];
        double score[1] = {-1};
        const double r0[2] = {1.0, 1.0}, r1[2] = {0.0, d};
        const size_t zero[1] = {0}, one[1] = {1}, both[2] = {0, 1};
        fe_lsq a;
        ck_assert_int_eq(fe_lsq_init(&a, 2, g), FE_OK);
        ck_assert_int_eq(fe_lsq_add(&a, r0, 1.0, 1.0), FE_OK);
        ck_assert_int_eq(fe_lsq_add(&a, r1, 1.0, 1.0), FE_OK);
        ck_assert_int_eq(fe_lsq_solve(&a, NULL, 2, x, &rss, NULL, work),
                         c == 0 ? FE_OK : FE_ESINGULAR);
        ck_assert_int_eq(fe_lsq_scores(&a, both, 2, NULL, 0, NULL, NULL, &rss, work),
                         c == 0 ? FE_OK : FE_ESINGULAR);
        ck_assert_int_eq(fe_lsq_scores(&a, zero, 1, one, 1, score, NULL, NULL, work), FE_OK);
        if (c == 0) {
            ck_assert_double_eq_tol(x[1], 1.0 / d, 1e-3 / d);
            ck_assert_double_eq_tol(score[0], 1.0, 1e-3);
        } else {
            ck_assert_double_eq(score[0], 0.0);
        }
    }
}
END_TEST

Suite *fe_lsq_suite(void)
{
    Suite *s = suite_create("lsq");
    TCase *t = tcase_create("normal equations");
    tcase_set_timeout(t, 120);
    tcase_add_test(t, streaming_equals_dgels);
    tcase_add_test(t, weighted_equals_scaled_dgels);
    tcase_add_test(t, merge_every_split_equals_the_whole);
    tcase_add_test(t, merge_is_associative_and_checks_shapes);
    tcase_add_test(t, every_subset_solves_like_a_refit);
    tcase_add_test(t, score_is_the_drop_in_rss);
    tcase_add_test(t, covariance_is_sigma2_times_inverse);
    tcase_add_test(t, dependent_columns_are_singular_never_nan);
    tcase_add_test(t, bad_rows_are_refused_and_nothing_changes);
    tcase_add_test(t, sparse_rows_are_refused_like_dense_rows);
    tcase_add_test(t, empty_single_and_bad_arguments);
    tcase_add_test(t, only_the_rows_and_storage_given_are_read);
    tcase_add_test(t, exact_fit_has_zero_rss);
    tcase_add_test(t, sparse_rows_equal_dense_rows);
    tcase_add_test(t, blocked_rows_stop_exactly_at_the_bad_row);
    tcase_add_test(t, a_blocked_residual_sum_past_its_edge_is_refused);
    tcase_add_test(t, add_rows_arguments_at_their_edges);
    tcase_add_test(t, merge_overflow_at_its_edge);
    tcase_add_test(t, weights_indices_and_counts_at_their_edges);
    tcase_add_test(t, rank_test_at_its_edge);
    suite_add_tcase(s, t);
    return s;
}
