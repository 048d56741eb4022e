/* SPDX-License-Identifier: MIT */
/* Arrow-shaped least squares: the Schur elimination equals the dense solve
   (and QR) of the same rows, damped or not; merge of every split equals the
   whole; bad rows are refused and nothing changes; singular blocks are
   reported, never NaN. */
#include <float.h>
#include <stdint.h>

#include <lapacke.h>

#include "foldest.h"
#include "testutil.h"

enum { NG = 4, NL = 3, NB = 6, NP = NG + NB * NL, ROWS = NB * 9 + 5 };

/* Rows of an arrow problem: block i % (NB+1) (the last value means a
   global-only row), Jacobian entries of different scales. */
struct rows {
    double jg[ROWS][NG], jl[ROWS][NL], r[ROWS], w[ROWS];
    size_t block[ROWS];
};

static void make_rows(uint64_t seed, struct rows *R)
{
    fe_rng g = fe_rng_seed(seed);
    for (size_t i = 0; i < ROWS; i++) {
        R->block[i] = i % (NB + 1) == NB ? FE_SCHUR_NONE : i % (NB + 1);
        for (size_t k = 0; k < NG; k++)
            R->jg[i][k] = (1.0 + (double)k) * fe_rng_normal(&g);
        for (size_t k = 0; k < NL; k++)
            R->jl[i][k] = R->block[i] == FE_SCHUR_NONE ? 0.0 : 0.5 * fe_rng_normal(&g) + 0.1;
        R->r[i] = fe_rng_normal(&g);
        R->w[i] = 0.5 + fe_rng_uniform(&g);
    }
}

/* The dense row of row i, in the full parameter vector. */
static void dense_row(const struct rows *R, size_t i, double *j)
{
    memset(j, 0, NP * sizeof *j);
    memcpy(j, R->jg[i], NG * sizeof *j);
    if (R->block[i] != FE_SCHUR_NONE)
        memcpy(j + NG + R->block[i] * NL, R->jl[i], NL * sizeof *j);
}

static double max_abs_diff(const double *a, const double *b, size_t n, double *scale)
{
    double e = 0.0, s = 0.0;
    for (size_t k = 0; k < n; k++) {
        e = fmax(e, fabs(a[k] - b[k]));
        s = fmax(s, fabs(b[k]));
    }
    *scale = s;
    return e;
}

START_TEST(elimination_equals_dense_and_qr)
{
    static struct rows R;
    static double st[NG * NG + 64 + NB * (NL * NL + NL + NL * NG) + 64];
    static double gd[(NP + 1) * (NP + 1)], wd[(NP + 1) * (NP + 1)];
    static double A[ROWS * NP], b[ROWS];
    double x[NP], xd[NP], work[256], rss, rssd, rssq = 0.0, scale;
    fe_schur a;
    fe_lsq d;

    make_rows(1, &R);
    ck_assert_uint_le(fe_schur_storage(NG, NL, NB), sizeof st / sizeof st[0]);
    ck_assert_uint_le(fe_schur_solve_work(NG, NL), 256);
    ck_assert_int_eq(fe_schur_init(&a, NG, NL, NB, st), FE_OK);
    ck_assert_int_eq(fe_lsq_init(&d, NP, gd), FE_OK);
    for (size_t i = 0; i < ROWS; i++) {
        double j[NP];
        ck_assert_int_eq(fe_schur_add(&a, R.jg[i], R.block[i], R.jl[i], R.r[i], R.w[i]), FE_OK);
        dense_row(&R, i, j);
        ck_assert_int_eq(fe_lsq_add(&d, j, R.r[i], R.w[i]), FE_OK);
        for (size_t k = 0; k < NP; k++)
            A[i * NP + k] = sqrt(R.w[i]) * j[k];
        b[i] = sqrt(R.w[i]) * R.r[i];
    }
    ck_assert_int_eq(fe_schur_solve(&a, 0.0, x, &rss, work), FE_OK);
    ck_assert_int_eq(fe_lsq_solve(&d, NULL, NP, xd, &rssd, NULL, wd), FE_OK);
    ck_assert_double_le(max_abs_diff(x, xd, NP, &scale), 1e-10 * scale);
    FE_ASSERT_REL(rss, rssd, 1e-10);
    /* And QR on the rows themselves. */
    ck_assert_int_eq(LAPACKE_dgels(LAPACK_ROW_MAJOR, 'N', ROWS, NP, 1, A, NP, b, 1), 0);
    for (size_t i = NP; i < ROWS; i++)
        rssq += b[i] * b[i];
    ck_assert_double_le(max_abs_diff(x, b, NP, &scale), 1e-10 * scale);
    FE_ASSERT_REL(rss, rssq, 1e-10);
}
END_TEST

START_TEST(damped_elimination_equals_damped_dense)
{
    static struct rows R;
    static double st[2048], gd[(NP + 1) * (NP + 1)];
    static double M[NP * NP];
    double x[NP], rhs[NP], work[256], scale;
    const double lambdas[3] = {1e-6, 0.3, 50.0};
    fe_schur a;
    fe_lsq d;

    make_rows(2, &R);
    fe_schur_init(&a, NG, NL, NB, st);
    fe_lsq_init(&d, NP, gd);
    for (size_t i = 0; i < ROWS; i++) {
        double j[NP];
        fe_schur_add(&a, R.jg[i], R.block[i], R.jl[i], R.r[i], R.w[i]);
        dense_row(&R, i, j);
        fe_lsq_add(&d, j, R.r[i], R.w[i]);
    }
    for (int t = 0; t < 3; t++) {
        double lam = lambdas[t];
        for (size_t k = 0; k < NP; k++) {
            for (size_t l = 0; l < NP; l++)
                M[k * NP + l] = fe_lsq_gram(&d, k, l);
            M[k * NP + k] *= 1.0 + lam;
            rhs[k] = fe_lsq_gram(&d, k, NP);
        }
        ck_assert_int_eq(LAPACKE_dposv(LAPACK_ROW_MAJOR, 'U', NP, 1, M, NP, rhs, 1), 0);
        ck_assert_int_eq(fe_schur_solve(&a, lam, x, NULL, work), FE_OK);
        ck_assert_double_le(max_abs_diff(x, rhs, NP, &scale), 1e-11 * scale);
    }
}
END_TEST

START_TEST(merge_every_split_equals_the_whole)
{
    static struct rows R;
    enum { S = 2048 };
    static double sw[S], sl[S], sr[S];
    fe_schur whole, left, right;
    fe_accumulator f = fe_schur_accumulator();
    size_t n = fe_schur_storage(NG, NL, NB);
    double err = 0.0, big = 0.0;
    int rc = FE_OK;

    make_rows(3, &R);
    fe_schur_init(&whole, NG, NL, NB, sw);
    for (size_t i = 0; i < ROWS; i++)
        rc |= fe_schur_add(&whole, R.jg[i], R.block[i], R.jl[i], R.r[i], R.w[i]);
    for (size_t k = 0; k < n; k++)
        big = fmax(big, fabs(sw[k]));
    for (size_t s = 0; s <= ROWS; s++) {
        fe_schur_init(&left, NG, NL, NB, sl);
        fe_schur_init(&right, NG, NL, NB, sr);
        for (size_t i = 0; i < ROWS; i++) {
            fe_schur_row row = {R.jg[i], R.block[i], R.jl[i], R.r[i], R.w[i]};
            rc |= fe_step(&f, i < s ? &left : &right, &row);
        }
        rc |= fe_merge(&f, &left, &right);
        if (left.global.n != ROWS)
            rc |= 1000;
        for (size_t k = 0; k < n; k++)
            err = fmax(err, fabs(sl[k] - sw[k]));
    }
    ck_assert_int_eq(rc, FE_OK);
    ck_assert_double_le(err, 1e-13 * big);
}
END_TEST

START_TEST(bad_rows_are_refused_and_nothing_changes)
{
    static struct rows R;
    static double st[2048], before[2048];
    fe_schur a, a0;
    size_t n = fe_schur_storage(NG, NL, NB);
    double jg[NG], jl[NL];
    int wrong = 0;

    make_rows(4, &R);
    fe_schur_init(&a, NG, NL, NB, st);
    for (size_t i = 0; i < ROWS; i++)
        fe_schur_add(&a, R.jg[i], R.block[i], R.jl[i], R.r[i], R.w[i]);
    a0 = a;
    memcpy(before, st, n * sizeof *st);
    for (size_t k = 0; k < NG + NL; k++) {
        memcpy(jg, R.jg[0], sizeof jg);
        memcpy(jl, R.jl[0], sizeof jl);
        if (k < NG)
            jg[k] = NAN;
        else
            jl[k - NG] = INFINITY;
        wrong |= fe_schur_add(&a, jg, 2, jl, 1.0, 1.0) != FE_ENONFINITE;
    }
    wrong |= fe_schur_add(&a, R.jg[0], 2, R.jl[0], NAN, 1.0) != FE_ENONFINITE;
    wrong |= fe_schur_add(&a, R.jg[0], 2, R.jl[0], 1.0, INFINITY) != FE_ENONFINITE;
    wrong |= fe_schur_add(&a, R.jg[0], 2, R.jl[0], 1.0, -1.0) != FE_EINVAL;
    wrong |= fe_schur_add(&a, R.jg[0], NB, R.jl[0], 1.0, 1.0) != FE_EINVAL;
    wrong |= fe_schur_add(&a, R.jg[0], 1, NULL, 1.0, 1.0) != FE_EINVAL;
    memcpy(jl, R.jl[0], sizeof jl);
    jl[1] = 1e200;                                  /* finite, overflows V */
    wrong |= fe_schur_add(&a, R.jg[0], 3, jl, 1.0, 1.0) != FE_ENONFINITE;
    memcpy(jg, R.jg[0], sizeof jg);
    jg[0] = 1e200;                                  /* finite, overflows U */
    wrong |= fe_schur_add(&a, jg, 3, R.jl[0], 1.0, 1.0) != FE_ENONFINITE;
    ck_assert_int_eq(wrong, 0);
    ck_assert_mem_eq(&a, &a0, sizeof a);
    ck_assert_mem_eq(st, before, n * sizeof *st);
}
END_TEST

START_TEST(underdetermined_blocks_are_singular_never_nan)
{
    enum { B = 2 };
    double st[256], x[NG + B * NL], work[256], rss = -1.0;
    const double jl[NL] = {1.0, 2.0, 3.0}, jg1[NG] = {0.5, -1.0, 0.25, 2.0};
    fe_rng g = fe_rng_seed(5);
    fe_schur a;

    fe_schur_init(&a, NG, NL, B, st);
    ck_assert_int_eq(fe_schur_solve(&a, 0.0, x, &rss, work), FE_ETOOFEW);
    /* Block 0 is seen often, block 1 only once: V_1 has rank 1. */
    for (int i = 0; i < 40; i++) {
        double jg[NG], j0[NL];
        for (size_t k = 0; k < NG; k++)
            jg[k] = fe_rng_normal(&g);
        for (size_t k = 0; k < NL; k++)
            j0[k] = fe_rng_normal(&g);
        ck_assert_int_eq(fe_schur_add(&a, jg, 0, j0, fe_rng_normal(&g), 1.0), FE_OK);
    }
    ck_assert_int_eq(fe_schur_add(&a, jg1, 1, jl, 1.0, 1.0), FE_OK);
    ck_assert_int_eq(fe_schur_solve(&a, 0.0, x, &rss, work), FE_ESINGULAR);
    ck_assert_double_eq(rss, -1.0);
    /* Damping makes the system definite; the step is finite. */
    ck_assert_int_eq(fe_schur_solve(&a, 1e-3, x, &rss, work), FE_OK);
    for (size_t k = 0; k < NG + B * NL; k++)
        ck_assert(isfinite(x[k]));
    ck_assert_int_eq(fe_schur_solve(&a, -1.0, x, &rss, work), FE_EINVAL);
    ck_assert_int_eq(fe_schur_solve(&a, NAN, x, &rss, work), FE_EINVAL);
}
END_TEST

START_TEST(shapes_and_degenerate_dimensions)
{
    double s1[256], s2[256], work[64], x[8], rss;
    fe_schur a, b;
    const double jl[2] = {1.0, 0.5}, jl2[2] = {-0.3, 2.0};

    ck_assert_int_eq(fe_schur_init(&a, 0, 0, 3, s1), FE_EINVAL);
    ck_assert_int_eq(fe_schur_init(&a, 1, 2, 2, NULL), FE_EINVAL);
    fe_schur_init(&a, 1, 2, 2, s1);
    fe_schur_init(&b, 2, 2, 2, s2);
    ck_assert_int_eq(fe_schur_merge(&a, &b), FE_EMISMATCH);
    ck_assert_int_eq(fe_schur_copy(&a, &b), FE_EMISMATCH);
    ck_assert_int_eq(fe_schur_merge(&a, &a), FE_EINVAL);
    /* The same global count, so that the global sums alone would merge:
       another local count, or another number of blocks, is another shape
       too, refused with a left as it was. */
    {
        static const size_t other[2][3] = {{1, 3, 2}, {1, 2, 3}};
        const double jg = 1.0, jl3[3] = {-0.3, 2.0, 0.7};   /* up to 3 locals */
        double s1before[256];
        const size_t used = fe_schur_storage(1, 2, 2);  /* what a writes */
        for (int c = 0; c < 2; c++) {
            fe_schur_init(&a, 1, 2, 2, s1);
            ck_assert_int_eq(fe_schur_add(&a, &jg, 0, jl, 1.0, 1.0), FE_OK);
            fe_schur_init(&b, other[c][0], other[c][1], other[c][2], s2);
            ck_assert_int_eq(fe_schur_add(&b, &jg, 1, jl3, 2.0, 1.0), FE_OK);
            ck_assert_uint_le(used, 256);
            memcpy(s1before, s1, used * sizeof *s1);
            ck_assert_int_eq(fe_schur_merge(&a, &b), FE_EMISMATCH);
            ck_assert_int_eq(fe_schur_copy(&a, &b), FE_EMISMATCH);
            ck_assert_mem_eq(s1, s1before, used * sizeof *s1);
            ck_assert_uint_eq(a.nl, 2);
            ck_assert_uint_eq(a.nb, 2);
        }
    }
    /* No global parameters: independent blocks, each solved alone. */
    fe_schur_init(&a, 0, 2, 2, s1);
    ck_assert_int_eq(fe_schur_add(&a, NULL, 0, jl, 1.0, 1.0), FE_OK);
    ck_assert_int_eq(fe_schur_add(&a, NULL, 0, jl2, 2.0, 1.0), FE_OK);
    ck_assert_int_eq(fe_schur_add(&a, NULL, 1, jl, 3.0, 1.0), FE_OK);
    ck_assert_int_eq(fe_schur_add(&a, NULL, 1, jl2, 4.0, 1.0), FE_OK);
    ck_assert_uint_le(fe_schur_solve_work(0, 2), 64);
    ck_assert_int_eq(fe_schur_solve(&a, 0.0, x, &rss, work), FE_OK);
    /* [1 .5; -.3 2] x = [1 2] and [3 4]: exact fits. */
    ck_assert_double_eq_tol(x[0] * 1.0 + x[1] * 0.5, 1.0, 1e-13);
    ck_assert_double_eq_tol(-0.3 * x[0] + 2.0 * x[1], 2.0, 1e-13);
    ck_assert_double_eq_tol(x[2] * 1.0 + x[3] * 0.5, 3.0, 1e-13);
    ck_assert_double_eq_tol(-0.3 * x[2] + 2.0 * x[3], 4.0, 1e-13);
    ck_assert_double_le(rss, 64 * DBL_EPSILON * 30.0);   /* r'r = 30 */
}
END_TEST

START_TEST(merge_refuses_an_overflow_in_any_local_diagonal)
{
    /* One global and two local parameters in one block: each part holds
       V_11 = 2.5e307 (the largest diagonal either may hold is DBL_MAX / 4,
       4.49e307), whose sum would pass it; V_00 = 1 stays small. */
    static double sa[256], sb[256], before[256];
    fe_schur a, b, a0;
    size_t n = fe_schur_storage(1, 2, 1);
    const double jg[1] = {0.0}, jl[2] = {1.0, 5e153};
    ck_assert_uint_le(n, 256);
    ck_assert_int_eq(fe_schur_init(&a, 1, 2, 1, sa), FE_OK);
    ck_assert_int_eq(fe_schur_init(&b, 1, 2, 1, sb), FE_OK);
    ck_assert_int_eq(fe_schur_add(&a, jg, 0, jl, 0.0, 1.0), FE_OK);
    ck_assert_int_eq(fe_schur_add(&b, jg, 0, jl, 0.0, 1.0), FE_OK);
    a0 = a;
    memcpy(before, sa, n * sizeof *sa);
    ck_assert_int_eq(fe_schur_merge(&a, &b), FE_ENONFINITE);
    ck_assert_mem_eq(&a, &a0, sizeof a);
    ck_assert_mem_eq(sa, before, n * sizeof *sa);
    /* At 2e307 each, the sum 4e307 is kept. */
    {
        const double small[2] = {1.0, sqrt(2e307)};
        ck_assert_int_eq(fe_schur_init(&a, 1, 2, 1, sa), FE_OK);
        ck_assert_int_eq(fe_schur_init(&b, 1, 2, 1, sb), FE_OK);
        ck_assert_int_eq(fe_schur_add(&a, jg, 0, small, 0.0, 1.0), FE_OK);
        ck_assert_int_eq(fe_schur_add(&b, jg, 0, small, 0.0, 1.0), FE_OK);
        ck_assert_int_eq(fe_schur_merge(&a, &b), FE_OK);
    }
}
END_TEST

/* The rank test at its edge, on 2 x 2 systems whose small pivot is known
   in closed form: rows (1, 1) and (0, delta) give the Gram [[1, 1], [1,
   1 + delta^2]], whose second pivot is delta^2, delta^2 / (1 + delta^2) of
   its diagonal.  FE_LSQ_RANK_TOL is 1e-12: a pivot of 1.5e-12 of its
   diagonal is kept (and x is the exact solution), one of 0.5e-12 is
   singular; first as the global parameter's reduced pivot (one global,
   one local), then inside a block (two locals). */
START_TEST(rank_test_at_its_edge)
{
    double st[256], work[256], x[3], rss;
    ck_assert_uint_le(fe_schur_storage(1, 2, 1), 256);
    ck_assert_uint_le(fe_schur_solve_work(1, 2), 256);
    for (int c = 0; c < 4; c++) {
        double d2 = c % 2 == 0 ? 1.5e-12 : 0.5e-12, delta = sqrt(d2);
        int want = c % 2 == 0 ? FE_OK : FE_ESINGULAR;
        fe_schur a;
        if (c < 2) {
            /* Global x_g, local x_l: x_g + x_l = 1, delta x_l = 0. */
            const double g1 = 1.0, l1 = 1.0, g2 = 0.0, l2 = delta;
            ck_assert_int_eq(fe_schur_init(&a, 1, 1, 1, st), FE_OK);
            ck_assert_int_eq(fe_schur_add(&a, &g1, 0, &l1, 1.0, 1.0), FE_OK);
            ck_assert_int_eq(fe_schur_add(&a, &g2, 0, &l2, 0.0, 1.0), FE_OK);
            ck_assert_msg(fe_schur_solve(&a, 0.0, x, &rss, work) == want, "global, %g", d2);
            if (want == FE_OK) {
                ck_assert_double_eq_tol(x[0], 1.0, 1e-3);
                ck_assert_double_eq_tol(x[1], 0.0, 1e-3);
            }
        } else {
            /* A global row x_g = 2 apart; in the block x1 + x2 = 1,
               delta x2 = 0. */
            const double g0 = 1.0, z = 0.0, l1[2] = {1.0, 1.0}, l2[2] = {0.0, delta};
            ck_assert_int_eq(fe_schur_init(&a, 1, 2, 1, st), FE_OK);
            ck_assert_int_eq(fe_schur_add(&a, &g0, FE_SCHUR_NONE, NULL, 2.0, 1.0), FE_OK);
            ck_assert_int_eq(fe_schur_add(&a, &z, 0, l1, 1.0, 1.0), FE_OK);
            ck_assert_int_eq(fe_schur_add(&a, &z, 0, l2, 0.0, 1.0), FE_OK);
            ck_assert_msg(fe_schur_solve(&a, 0.0, x, &rss, work) == want, "block, %g", d2);
            if (want == FE_OK) {
                ck_assert_double_eq_tol(x[0], 2.0, 1e-9);
                ck_assert_double_eq_tol(x[1], 1.0, 1e-3);
                ck_assert_double_eq_tol(x[2], 0.0, 1e-3);
            }
        }
    }
}
END_TEST

/* Issue 20: the row's weight and block index and the damping at their
   edges: weight 0 and block nb - 1 are taken, -DBL_TRUE_MIN and block nb
   refused with the accumulation unchanged; lambda 0 solves and
   -DBL_TRUE_MIN is refused. */
START_TEST(weights_blocks_and_damping_at_their_edges)
{
    double st[64], copy[64], x[3], work[64], rss;
    const double jg[1] = {1.0}, jl[1] = {1.0};
    fe_schur a, before;
    size_t n;
    ck_assert_int_eq(fe_schur_init(&a, 1, 1, 2, st), FE_OK);
    n = fe_schur_storage(1, 1, 2);
    ck_assert_uint_le(n, 64);
    ck_assert_int_eq(fe_schur_add(&a, jg, FE_SCHUR_NONE, NULL, 2.0, 1.0), FE_OK);
    before = a;
    memcpy(copy, st, n * sizeof *st);
    ck_assert_int_eq(fe_schur_add(&a, jg, 2, jl, 1.0, 1.0), FE_EINVAL);
    ck_assert_int_eq(fe_schur_add(&a, jg, 1, jl, 1.0, -DBL_TRUE_MIN), FE_EINVAL);
    ck_assert_mem_eq(&a, &before, sizeof a);
    ck_assert_mem_eq(st, copy, n * sizeof *st);
    ck_assert_int_eq(fe_schur_add(&a, jg, 1, jl, 5.0, 0.0), FE_OK);
    ck_assert_uint_eq(a.global.n, 2);
    ck_assert_mem_eq(st, copy, n * sizeof *st);     /* weight 0 adds nothing */
    ck_assert_int_eq(fe_schur_add(&a, jg, 0, jl, 3.0, 1.0), FE_OK);
    ck_assert_int_eq(fe_schur_add(&a, NULL, 0, jl, 1.0, 1.0), FE_EINVAL);
    {   /* x_g = 2 and x_g + x_0 = 3, block 1 free: fix it with a row. */
        const double z[1] = {0.0};
        ck_assert_int_eq(fe_schur_add(&a, z, 1, jl, 4.0, 1.0), FE_OK);
    }
    ck_assert_int_eq(fe_schur_solve(&a, -DBL_TRUE_MIN, x, &rss, work), FE_EINVAL);
    ck_assert_int_eq(fe_schur_solve(&a, 0.0, x, &rss, work), FE_OK);
    ck_assert_double_eq_tol(x[0], 2.0, 1e-14);
    ck_assert_double_eq_tol(x[1], 1.0, 1e-14);
    ck_assert_double_eq_tol(x[2], 4.0, 1e-14);
    ck_assert_double_eq_tol(rss, 0.0, 1e-13);
}
END_TEST

/* A missing accumulator, and one bound to no storage (all zeros, as a
   static one starts), are refused with FE_EINVAL, each by itself, before
   any row is read (CI's sample of seed 40756: schur:39, the first || of
   the check made &&, which let the unbound one through to its storage). */
START_TEST(add_refuses_a_missing_or_unbound_accumulator)
{
    const double jg[1] = {1.0}, jl[1] = {1.0};
    fe_schur z;
    memset(&z, 0, sizeof z);
    z.ng = 1;
    z.nl = 1;
    z.nb = 2;
    ck_assert_int_eq(fe_schur_add(NULL, jg, FE_SCHUR_NONE, NULL, 1.0, 1.0), FE_EINVAL);
    ck_assert_int_eq(fe_schur_add(&z, jg, FE_SCHUR_NONE, NULL, 1.0, 1.0), FE_EINVAL);
    ck_assert_int_eq(fe_schur_add(&z, jg, 0, jl, 1.0, 1.0), FE_EINVAL);
    ck_assert_ptr_null(z.blk);
}
END_TEST

/* Issue 20: a damped diagonal A_kk (1 + lambda) that overflows is
   refused with FE_ESINGULAR, in a block and in the reduced system, with
   the rest of the system harmless.  A_kk = 2^1020 (one row of 2^510,
   within the DBL_MAX / 4 a diagonal may hold): at lambda = 15 - 2^-49
   (the double below 15) the damped diagonal is (16 - 2^-49) 2^1020 =
   DBL_MAX exactly and the system is solved; at lambda = 15 it is 2^1024,
   infinite.  Block case: a global row x_g = 2 and a block row 2^510 x_l
   = 0, so x_g = 2 / (1 + lambda) and x_l = 0.  Reduced case: a global
   row 2^510 x_g = 0 and a block row x_l = 3: x_g = 0, x_l = 3 / (1 +
   lambda). */
START_TEST(a_damped_diagonal_that_overflows_is_singular)
{
    double st[64], work[64], x[2], rss;
    const double big = ldexp(1.0, 510), one = 1.0, zero = 0.0;
    const double below = nextafter(15.0, 0.0);
    ck_assert_uint_le(fe_schur_storage(1, 1, 1), 64);
    ck_assert_uint_le(fe_schur_solve_work(1, 1), 64);
    ck_assert_double_eq(below, 15.0 - ldexp(1.0, -49));
    ck_assert_double_eq((1.0 + below) * ldexp(1.0, 1020), DBL_MAX);
    for (int where = 0; where < 2; where++) {
        fe_schur a;
        ck_assert_int_eq(fe_schur_init(&a, 1, 1, 1, st), FE_OK);
        if (where == 0) {           /* the block's diagonal */
            ck_assert_int_eq(fe_schur_add(&a, &one, FE_SCHUR_NONE, NULL, 2.0, 1.0), FE_OK);
            ck_assert_int_eq(fe_schur_add(&a, &zero, 0, &big, 0.0, 1.0), FE_OK);
        } else {                    /* the reduced system's */
            ck_assert_int_eq(fe_schur_add(&a, &big, FE_SCHUR_NONE, NULL, 0.0, 1.0), FE_OK);
            ck_assert_int_eq(fe_schur_add(&a, &zero, 0, &one, 3.0, 1.0), FE_OK);
        }
        ck_assert_int_eq(fe_schur_solve(&a, below, x, &rss, work), FE_OK);
        if (where == 0) {
            ck_assert_double_eq_tol(x[0], 2.0 / 16.0, 1e-15);
            ck_assert_double_eq(x[1], 0.0);
        } else {
            ck_assert_double_eq(x[0], 0.0);
            ck_assert_double_eq_tol(x[1], 3.0 / 16.0, 1e-15);
        }
        ck_assert_int_eq(fe_schur_solve(&a, 15.0, x, &rss, work), FE_ESINGULAR);
    }
}
END_TEST

Suite *fe_schur_suite(void)
{
    Suite *s = suite_create("schur");
    TCase *t = tcase_create("arrow");
    tcase_set_timeout(t, 120);
    tcase_add_test(t, merge_refuses_an_overflow_in_any_local_diagonal);
    tcase_add_test(t, weights_blocks_and_damping_at_their_edges);
    tcase_add_test(t, add_refuses_a_missing_or_unbound_accumulator);
    tcase_add_test(t, elimination_equals_dense_and_qr);
    tcase_add_test(t, damped_elimination_equals_damped_dense);
    tcase_add_test(t, merge_every_split_equals_the_whole);
    tcase_add_test(t, bad_rows_are_refused_and_nothing_changes);
    tcase_add_test(t, underdetermined_blocks_are_singular_never_nan);
    tcase_add_test(t, shapes_and_degenerate_dimensions);
    tcase_add_test(t, rank_test_at_its_edge);
    tcase_add_test(t, a_damped_diagonal_that_overflows_is_singular);
    suite_add_tcase(s, t);
    return s;
}
