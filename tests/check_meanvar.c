/* SPDX-License-Identifier: MIT */
/* Running mean and variance: the vectors of Kalman Folding, merge laws,
   streaming equals batch, precision, refusal of bad input. */
#include <float.h>
#include <stdint.h>

#include "foldest.h"
#include "testutil.h"

#include "../src/meanvar_private.h"

static const double ten[10] = {-0.178654, 0.828305, 0.0592247, -0.0121089,
                               -1.48014,  -0.315044, -0.324796, -0.676357,
                               0.16301,   -0.858164};

/* The mean of x[0..n-1] and the sum of squared deviations from it, in
   long double by two passes: the reference the folds are held to. */
static void reference_moments(const double *x, size_t n, long double *mean, long double *ss)
{
    long double sum = 0;
    for (size_t i = 0; i < n; i++)
        sum += x[i];
    *mean = sum / (long double)n;
    *ss = 0;
    for (size_t i = 0; i < n; i++)
        *ss += (x[i] - *mean) * (x[i] - *mean);
}

START_TEST(mean_of_three)
{
    const double z[3] = {55, 89, 144};
    fe_accumulator f = fe_meanvar_accumulator();
    fe_meanvar a = FE_MEANVAR_EMPTY;
    size_t done = 99;
    ck_assert_int_eq(fe_fold(&f, &a, z, 3, &done), FE_OK);
    ck_assert_uint_eq(done, 3);
    ck_assert_uint_eq(a.n, 3);
    ck_assert_double_eq(fe_meanvar_mean(&a), 96.0);
}
END_TEST

START_TEST(variance_scan_of_three)
{
    /* Kalman Folding: {0,0,0}, {0,55,1}, {578,72,2}, {2017,96,3} as
       (variance, mean, n). */
    const double z[3] = {55, 89, 144};
    const double want[4][3] = {{0, 0, 0}, {0, 55, 1}, {578, 72, 2}, {2017, 96, 3}};
    fe_accumulator f = fe_meanvar_accumulator();
    fe_meanvar a = FE_MEANVAR_EMPTY, out[4];
    ck_assert_int_eq(fe_scan(&f, &a, z, 3, out, NULL), FE_OK);
    for (int k = 0; k < 4; k++) {
        ck_assert_double_eq_tol(fe_meanvar_variance(&out[k]), want[k][0], 1e-12);
        ck_assert_double_eq_tol(fe_meanvar_mean(&out[k]), want[k][1], 1e-12);
        ck_assert_uint_eq(out[k].n, (uint64_t)want[k][2]);
    }
}
END_TEST

START_TEST(ten_values)
{
    fe_meanvar a = FE_MEANVAR_EMPTY, b = FE_MEANVAR_EMPTY;
    for (int i = 0; i < 10; i++)
        ck_assert_int_eq(fe_meanvar_add(&a, ten[i]), FE_OK);
    FE_ASSERT_REL(fe_meanvar_mean(&a), -0.27947242, 1e-12);
    FE_ASSERT_REL(fe_meanvar_variance(&a), 0.3951831517200817, 1e-12);
    /* The blocked path gives the same. */
    ck_assert_int_eq(fe_meanvar_add_many(&b, ten, 10, NULL), FE_OK);
    FE_ASSERT_REL(fe_meanvar_mean(&b), -0.27947242, 1e-12);
    FE_ASSERT_REL(fe_meanvar_variance(&b), 0.3951831517200817, 1e-12);
}
END_TEST

START_TEST(merge_every_split)
{
    fe_meanvar whole = FE_MEANVAR_EMPTY;
    ck_assert_int_eq(fe_meanvar_add_many(&whole, ten, 10, NULL), FE_OK);
    for (size_t s = 0; s <= 10; s++) {
        fe_meanvar left = FE_MEANVAR_EMPTY, right = FE_MEANVAR_EMPTY;
        for (size_t i = 0; i < s; i++)
            ck_assert_int_eq(fe_meanvar_add(&left, ten[i]), FE_OK);
        for (size_t i = s; i < 10; i++)
            ck_assert_int_eq(fe_meanvar_add(&right, ten[i]), FE_OK);
        ck_assert_int_eq(fe_meanvar_merge(&left, &right), FE_OK);
        ck_assert_uint_eq(left.n, 10);
        FE_ASSERT_REL(left.mean, whole.mean, 1e-12);
        FE_ASSERT_REL(left.m2, whole.m2, 1e-12);
    }
}
END_TEST

START_TEST(merge_through_accumulator_is_associative)
{
    fe_accumulator f = fe_meanvar_accumulator();
    fe_meanvar p = FE_MEANVAR_EMPTY, q = FE_MEANVAR_EMPTY, r = FE_MEANVAR_EMPTY;
    fe_meanvar left, right;
    ck_assert_int_eq(fe_fold(&f, &p, ten, 3, NULL), FE_OK);
    ck_assert_int_eq(fe_fold(&f, &q, ten + 3, 4, NULL), FE_OK);
    ck_assert_int_eq(fe_fold(&f, &r, ten + 7, 3, NULL), FE_OK);
    left = p;                                   /* (p + q) + r */
    ck_assert_int_eq(fe_merge(&f, &left, &q), FE_OK);
    ck_assert_int_eq(fe_merge(&f, &left, &r), FE_OK);
    right = q;                                  /* p + (q + r) */
    ck_assert_int_eq(fe_merge(&f, &right, &r), FE_OK);
    {
        fe_meanvar t = p;
        ck_assert_int_eq(fe_merge(&f, &t, &right), FE_OK);
        right = t;
    }
    FE_ASSERT_REL(left.mean, right.mean, 1e-14);
    FE_ASSERT_REL(left.m2, right.m2, 1e-14);
}
END_TEST

START_TEST(empty_and_single)
{
    fe_accumulator f = fe_meanvar_accumulator();
    fe_meanvar a = FE_MEANVAR_EMPTY, e = FE_MEANVAR_EMPTY;
    size_t done = 7;
    ck_assert_int_eq(fe_fold(&f, &a, ten, 0, &done), FE_OK);
    ck_assert_uint_eq(done, 0);
    ck_assert_uint_eq(a.n, 0);
    ck_assert_double_eq(fe_meanvar_mean(&a), 0.0);
    ck_assert_double_eq(fe_meanvar_variance(&a), 0.0);
    ck_assert_double_eq(fe_meanvar_population_variance(&a), 0.0);
    ck_assert_int_eq(fe_meanvar_add(&a, 3.5), FE_OK);
    ck_assert_double_eq(fe_meanvar_mean(&a), 3.5);
    ck_assert_double_eq(fe_meanvar_variance(&a), 0.0);
    /* The empty accumulation is the identity of merge, on both sides. */
    ck_assert_int_eq(fe_meanvar_merge(&a, &e), FE_OK);
    ck_assert_uint_eq(a.n, 1);
    ck_assert_double_eq(a.mean, 3.5);
    ck_assert_int_eq(fe_meanvar_merge(&e, &a), FE_OK);
    ck_assert_double_eq(e.mean, 3.5);
    /* Each missing argument alone, nothing changed. */
    ck_assert_int_eq(fe_meanvar_merge(NULL, &a), FE_EINVAL);
    ck_assert_int_eq(fe_meanvar_merge(&a, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_meanvar_add_many(NULL, ten, 10, &done), FE_EINVAL);
    ck_assert_uint_eq(done, 0);
    done = 7;
    ck_assert_int_eq(fe_meanvar_add_many(&a, NULL, 3, &done), FE_EINVAL);
    ck_assert_uint_eq(done, 0);
    ck_assert_int_eq(fe_meanvar_add_many(&a, NULL, 0, &done), FE_OK);
    ck_assert_uint_eq(a.n, 1);
    ck_assert_double_eq(a.mean, 3.5);
}
END_TEST

START_TEST(nonfinite_is_refused_and_nothing_changes)
{
    const double bad[3] = {NAN, INFINITY, -INFINITY};
    for (int i = 0; i < 3; i++) {
        fe_meanvar a = FE_MEANVAR_EMPTY, before;
        ck_assert_int_eq(fe_meanvar_add_many(&a, ten, 10, NULL), FE_OK);
        before = a;
        ck_assert_int_eq(fe_meanvar_add(&a, bad[i]), FE_ENONFINITE);
        ck_assert_mem_eq(&a, &before, sizeof a);
    }
    /* Overflow of the deviation is refused, too. */
    {
        fe_meanvar a = FE_MEANVAR_EMPTY, before;
        ck_assert_int_eq(fe_meanvar_add(&a, -DBL_MAX), FE_OK);
        before = a;
        ck_assert_int_eq(fe_meanvar_add(&a, DBL_MAX), FE_ENONFINITE);
        ck_assert_mem_eq(&a, &before, sizeof a);
    }
}
END_TEST

START_TEST(bulk_stops_exactly_at_the_bad_value)
{
    /* A NaN deep inside the second block: the blocked path must fold
       exactly what precedes it, like the one-by-one path. */
    enum { N = 2000, BAD = 777 };
    static double x[N];
    fe_rng r = fe_rng_seed(5);
    fe_meanvar fast = FE_MEANVAR_EMPTY, slow = FE_MEANVAR_EMPTY;
    fe_accumulator f = fe_meanvar_accumulator();
    size_t done = 0;
    for (int i = 0; i < N; i++)
        x[i] = 10.0 + fe_rng_normal(&r);
    x[BAD] = NAN;
    ck_assert_int_eq(fe_fold(&f, &fast, x, N, &done), FE_ENONFINITE);
    ck_assert_uint_eq(done, BAD);
    ck_assert_uint_eq(fast.n, BAD);
    for (int i = 0; i < BAD; i++)
        ck_assert_int_eq(fe_meanvar_add(&slow, x[i]), FE_OK);
    FE_ASSERT_REL(fast.mean, slow.mean, 1e-13);
    FE_ASSERT_REL(fast.m2, slow.m2, 1e-11);
    /* Resuming after the bad value folds the rest. */
    ck_assert_int_eq(fe_fold(&f, &fast, x + BAD + 1, N - BAD - 1, &done), FE_OK);
    ck_assert_uint_eq(fast.n, N - 1);
}
END_TEST

START_TEST(streaming_equals_batch)
{
    enum { N = 100003 };
    static double x[N];
    fe_rng r = fe_rng_seed(11);
    fe_meanvar fast = FE_MEANVAR_EMPTY, slow = FE_MEANVAR_EMPTY;
    long double ss, mean;
    int rc = FE_OK;
    for (int i = 0; i < N; i++)
        x[i] = 3.0 + 2.0 * fe_rng_normal(&r);
    reference_moments(x, N, &mean, &ss);
    ck_assert_int_eq(fe_meanvar_add_many(&fast, x, N, NULL), FE_OK);
    for (int i = 0; i < N; i++)
        rc |= fe_meanvar_add(&slow, x[i]);
    ck_assert_int_eq(rc, FE_OK);
    FE_ASSERT_REL(fast.mean, (double)mean, 1e-13);
    FE_ASSERT_REL(slow.mean, (double)mean, 1e-12);
    FE_ASSERT_REL(fe_meanvar_variance(&fast), (double)(ss / (N - 1)), 1e-12);
    FE_ASSERT_REL(fe_meanvar_variance(&slow), (double)(ss / (N - 1)), 1e-12);
}
END_TEST

/* The block kernels (the AVX2 or SSE2 registers where the processor has
   them, the loops otherwise) hold the same eight lanes and add them in the
   same order: a block folded by fe_meanvar_add_many into an empty
   accumulation has the bits of fe__meanvar_block_portable, the loops alone.
   The values mix magnitudes by position, so that another order of the
   squares' lanes rounds differently (the first pass's order is not seen:
   the correction takes out any error of the provisional mean); both agree
   with a long-double two-pass sum too.
   Where the library may fuse multiply-adds (-mfma), the kernels may round
   a square differently, and only the agreement is asserted. */
START_TEST(every_kernel_gives_the_loops_bits)
{
    static const size_t sizes[] = {1, 2, 7, 8, 9, 15, 16, 17, 63, 64, 65, 255, 511, 512};
    double x[512];
    fe_rng r = fe_rng_seed(2611);
    for (size_t i = 0; i < 512; i++)
        x[i] = 1e6 * (double)(i % 3) + (1.0 + 1e3 * (double)(i % 8)) * fe_rng_normal(&r);
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
        size_t m = sizes[k];
        fe_meanvar fast = FE_MEANVAR_EMPTY, loops = FE_MEANVAR_EMPTY, sse2 = FE_MEANVAR_EMPTY;
        long double ss, mean;
        reference_moments(x, m, &mean, &ss);
        ck_assert_int_eq(fe_meanvar_add_many(&fast, x, m, NULL), FE_OK);
        ck_assert_int_eq(fe__meanvar_block_portable(x, m, &loops), FE_OK);
        ck_assert_int_eq(fe__meanvar_block_sse2(x, m, &sse2), FE_OK);
        ck_assert_uint_eq(fast.n, m);
        ck_assert_uint_eq(loops.n, m);
        ck_assert_uint_eq(sse2.n, m);
#if !defined(__FMA__)
        ck_assert_msg(fast.mean == loops.mean && fast.m2 == loops.m2,
                      "m = %zu: kernel (%.17g, %.17g), loops (%.17g, %.17g)", m,
                      fast.mean, fast.m2, loops.mean, loops.m2);
        ck_assert_msg(sse2.mean == loops.mean && sse2.m2 == loops.m2,
                      "m = %zu: SSE2 (%.17g, %.17g), loops (%.17g, %.17g)", m,
                      sse2.mean, sse2.m2, loops.mean, loops.m2);
#endif
        FE_ASSERT_REL(fast.mean, (double)mean, 1e-15);
        FE_ASSERT_REL(loops.mean, (double)mean, 1e-15);
        FE_ASSERT_REL(sse2.mean, (double)mean, 1e-15);
        if (m > 1) {
            FE_ASSERT_REL(fast.m2, (double)ss, 1e-13);
            FE_ASSERT_REL(loops.m2, (double)ss, 1e-13);
            FE_ASSERT_REL(sse2.m2, (double)ss, 1e-13);
        }
    }
    x[9] = NAN;
    {
        fe_meanvar loops = {7, 1.0, 2.0};
        ck_assert_int_eq(fe__meanvar_block_portable(x, 16, &loops), FE_ENONFINITE);
        ck_assert(loops.n == 7 && loops.mean == 1.0 && loops.m2 == 2.0);
    }
}
END_TEST

START_TEST(precision_at_large_offset)
{
    /* 10^7 samples of 1e9 + N(0,1): variance to 1e-6 relative, where the
       sum-of-squares formula has no correct digit.  The reference is the
       two-pass formula in long double. */
    size_t n = fe_test_quick() ? 1000000 : 10000000;
    double *x = malloc(n * sizeof *x);
    fe_rng r = fe_rng_seed(2026);
    fe_meanvar fast = FE_MEANVAR_EMPTY, slow = FE_MEANVAR_EMPTY;
    long double sum = 0, ss = 0, mean, var;
    double naive_s = 0, naive_q = 0, naive;
    int rc = FE_OK;
    ck_assert_ptr_nonnull(x);
    for (size_t i = 0; i < n; i++) {
        x[i] = 1e9 + fe_rng_normal(&r);
        sum += x[i];
        naive_s += x[i];
        naive_q += x[i] * x[i];
    }
    mean = sum / (long double)n;
    for (size_t i = 0; i < n; i++)
        ss += (x[i] - mean) * (x[i] - mean);
    var = ss / (long double)(n - 1);
    ck_assert_int_eq(fe_meanvar_add_many(&fast, x, n, NULL), FE_OK);
    for (size_t i = 0; i < n; i++)
        rc |= fe_meanvar_add(&slow, x[i]);
    ck_assert_int_eq(rc, FE_OK);
    FE_ASSERT_REL(fe_meanvar_variance(&fast), (double)var, 1e-6);
    FE_ASSERT_REL(fe_meanvar_variance(&slow), (double)var, 1e-6);
    /* The textbook formula is off by far more than 1e-6: the test can fail. */
    naive = (naive_q - naive_s * naive_s / (double)n) / (double)(n - 1);
    ck_assert_msg(fabs(naive - (double)var) > 1e-3 * (double)var,
                  "naive formula unexpectedly accurate: %g vs %Lg", naive, var);
    free(x);
}
END_TEST

/* The block's correction, where the provisional mean is far off: 64
   values 2^52 + k, k = 7i mod 5 in 0 .. 4, whose sums (to 2^58) round to
   multiples of up to 64, so that the first pass's mean can miss by a
   whole unit where the spread is about 1.4.  The deviations from any
   double near 2^52 are exact integers, and so are their squares' sum,
   their sum c and c^2 / 64: the corrected two-pass sum of squares,
   sum d^2 - c^2 / 64, is exactly that of the k about their mean, worked
   here from the k alone (127 / 64 their mean).  Every kernel must give
   it to the bit; the uncorrected sum about a mean summed in order is
   off by more than a third of it (191 against 8255 / 64), so the
   correction is what is tested. */
START_TEST(correction_takes_out_a_provisional_mean_far_off)
{
    enum { M = 64 };
    const double big = 4503599627370496.0;      /* 2^52 */
    double x[M], kmean = 0.0, exact = 0.0, seq = 0.0, naive = 0.0;
    fe_meanvar fast = FE_MEANVAR_EMPTY, loops = FE_MEANVAR_EMPTY, sse2 = FE_MEANVAR_EMPTY;
    for (int i = 0; i < M; i++) {
        x[i] = big + (double)(7 * i % 5);
        kmean += (double)(7 * i % 5);
        seq += x[i];
    }
    kmean /= M;
    for (int i = 0; i < M; i++)
        exact += ((double)(7 * i % 5) - kmean) * ((double)(7 * i % 5) - kmean);
    for (int i = 0; i < M; i++)
        naive += (x[i] - seq / M) * (x[i] - seq / M);
    ck_assert_double_eq(kmean, 127.0 / 64.0);
    ck_assert_msg(fabs(naive - exact) > exact / 3.0,
                  "the provisional mean is not far off: %.17g vs %.17g", naive, exact);
    ck_assert_int_eq(fe_meanvar_add_many(&fast, x, M, NULL), FE_OK);
    ck_assert_int_eq(fe__meanvar_block_portable(x, M, &loops), FE_OK);
    ck_assert_int_eq(fe__meanvar_block_sse2(x, M, &sse2), FE_OK);
    ck_assert_double_eq(fast.m2, exact);
    ck_assert_double_eq(loops.m2, exact);
    ck_assert_double_eq(sse2.m2, exact);
    /* The mean, 2^52 + 127/64, to the nearest integer, the spacing there. */
    ck_assert_double_eq(fast.mean, big + 2.0);
    ck_assert_double_eq(loops.mean, big + 2.0);
    ck_assert_double_eq(sse2.mean, big + 2.0);
}
END_TEST

START_TEST(small_values_far_from_one)
{
    /* Values of 1e-6 + 1e-9 u (u uniform): the bulk path's mean and
       variance against the two-pass formula in long double, to 1e-10
       relative, for lengths that use the eight lanes, the tail, both and
       several blocks.  At this scale an error of order one in a block's
       first sum (which the corrected two-pass formula absorbs for values
       of order one) leaves no correct digit in the variance. */
    static const size_t sizes[] = {5, 8, 13, 512, 1000, 5003};
    static double x[5003];
    fe_rng r = fe_rng_seed(606);
    for (size_t i = 0; i < 5003; i++)
        x[i] = 1e-6 + 1e-9 * fe_rng_uniform(&r);
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
        size_t n = sizes[k];
        fe_meanvar a = FE_MEANVAR_EMPTY;
        long double ss, mean;
        reference_moments(x, n, &mean, &ss);
        ck_assert_int_eq(fe_meanvar_add_many(&a, x, n, NULL), FE_OK);
        ck_assert_uint_eq(a.n, n);
        FE_ASSERT_REL(a.mean, (double)mean, 1e-12);
        FE_ASSERT_REL(fe_meanvar_variance(&a), (double)(ss / (long double)(n - 1)), 1e-10);
    }
}
END_TEST

/* A merge whose squared difference of means overflows is refused, `a`
   unchanged; one a factor 2 inside (difference 1e154) is taken. */
START_TEST(merge_overflow_at_its_edge)
{
    fe_meanvar a = FE_MEANVAR_EMPTY, b = FE_MEANVAR_EMPTY, c = FE_MEANVAR_EMPTY, before;
    ck_assert_int_eq(fe_meanvar_add(&a, 0.0), FE_OK);
    ck_assert_int_eq(fe_meanvar_add(&b, 2e154), FE_OK);
    ck_assert_int_eq(fe_meanvar_add(&c, 1e154), FE_OK);
    before = a;
    ck_assert_int_eq(fe_meanvar_merge(&a, &b), FE_ENONFINITE);
    ck_assert_mem_eq(&a, &before, sizeof a);
    ck_assert_int_eq(fe_meanvar_merge(&a, &c), FE_OK);
    ck_assert_double_eq(fe_meanvar_mean(&a), 0.5e154);
}
END_TEST

Suite *fe_meanvar_suite(void)
{
    Suite *s = suite_create("meanvar");
    TCase *t = tcase_create("core");
    tcase_set_timeout(t, 120);
    tcase_add_test(t, mean_of_three);
    tcase_add_test(t, variance_scan_of_three);
    tcase_add_test(t, ten_values);
    tcase_add_test(t, merge_every_split);
    tcase_add_test(t, merge_through_accumulator_is_associative);
    tcase_add_test(t, empty_and_single);
    tcase_add_test(t, nonfinite_is_refused_and_nothing_changes);
    tcase_add_test(t, bulk_stops_exactly_at_the_bad_value);
    tcase_add_test(t, streaming_equals_batch);
    tcase_add_test(t, every_kernel_gives_the_loops_bits);
    tcase_add_test(t, precision_at_large_offset);
    tcase_add_test(t, small_values_far_from_one);
    tcase_add_test(t, correction_takes_out_a_provisional_mean_far_off);
    tcase_add_test(t, merge_overflow_at_its_edge);
    suite_add_tcase(s, t);
    return s;
}
