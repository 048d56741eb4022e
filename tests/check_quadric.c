/* SPDX-License-Identifier: MIT */
/* Moments of a three-axis stream: step equals block, merge of any split
   equals the whole (to 1e-12), re-centring, refusal leaves the accumulation
   unchanged, empty and one-sample streams, equal-area regions, coverage. */
#include <stdint.h>

#include "foldest.h"
#include "testutil.h"


/* Largest difference of two moment vectors, each moment relative to the
   scale N R^degree of its degree. */
static double moment_diff(const fe_quadric *a, const fe_quadric *b, double R)
{
    double worst = 0.0;
    for (int k = 0; k < FE_QUADRIC_MOMENTS; k++) {
        int e[3];
        fe_quadric_exponents(k, e);
        double scale = b->m[0] * pow(R, e[0] + e[1] + e[2]);
        worst = fmax(worst, fabs(a->m[k] - b->m[k]) / scale);
    }
    return worst;
}

static const double C0[3] = {100, -50, 30}, R0[3] = {400, 380, 420};

START_TEST(index_and_exponents_are_inverse)
{
    int bad = 0;
    for (int k = 0; k < FE_QUADRIC_MOMENTS; k++) {
        int e[3];
        fe_quadric_exponents(k, e);
        bad += fe_quadric_index(e[0], e[1], e[2]) != k;
    }
    ck_assert_int_eq(bad, 0);
    ck_assert_int_eq(fe_quadric_index(0, 0, 0), 0);
    ck_assert_int_eq(fe_quadric_index(0, 0, 2), 9);
    ck_assert_int_eq(fe_quadric_index(0, 0, 4), 34);
    ck_assert_int_eq(fe_quadric_index(3, 1, 1), -1);
}
END_TEST

START_TEST(empty_and_one_sample)
{
    const double x[3] = {3, -4, 5};
    fe_quadric q = FE_QUADRIC_EMPTY, e = FE_QUADRIC_EMPTY;
    ck_assert_uint_eq(fe_quadric_count(&q), 0);
    ck_assert_int_eq(fe_quadric_regions(&q), 0);
    ck_assert_double_eq(fe_quadric_coverage(&q), 0.0);
    /* A NULL accumulation reads as an empty one (quadric.h). */
    ck_assert_uint_eq(fe_quadric_count(NULL), 0);
    ck_assert_int_eq(fe_quadric_regions(NULL), 0);
    ck_assert_double_eq(fe_quadric_coverage(NULL), 0.0);
    ck_assert_int_eq(fe_quadric_add_many(&q, x, 0, NULL), FE_OK);
    ck_assert_mem_eq(&q, &e, sizeof q);
    ck_assert_int_eq(fe_quadric_add(&q, x), FE_OK);
    ck_assert_uint_eq(fe_quadric_count(&q), 1);
    /* The first sample is the reference: every moment but N is zero. */
    for (int k = 1; k < FE_QUADRIC_MOMENTS; k++)
        ck_assert_double_eq(q.m[k], 0.0);
    ck_assert_double_eq(q.ref[2], 5.0);
    ck_assert_double_eq(q.lo[1], -4.0);
    ck_assert_double_eq(q.hi[1], -4.0);
    /* The empty accumulation is the identity of merge, on both sides. */
    ck_assert_int_eq(fe_quadric_merge(&q, &e), FE_OK);
    ck_assert_uint_eq(fe_quadric_count(&q), 1);
    ck_assert_int_eq(fe_quadric_merge(&e, &q), FE_OK);
    ck_assert_mem_eq(&e, &q, sizeof q);
}
END_TEST

START_TEST(step_equals_block)
{
    enum { N = 5000 };
    static double x[3 * N];
    fe_quadric one = FE_QUADRIC_EMPTY, many = FE_QUADRIC_EMPTY;
    size_t done = 0;
    int rc = FE_OK;
    fe_test_ellipsoid_points(x, N, C0, R0, 2.0, 1);
    for (size_t i = 0; i < N && rc == FE_OK; i++)
        rc = fe_quadric_add(&one, x + 3 * i);
    ck_assert_int_eq(rc, FE_OK);
    ck_assert_int_eq(fe_quadric_add_many(&many, x, N, &done), FE_OK);
    ck_assert_uint_eq(done, N);
    ck_assert_double_le(moment_diff(&many, &one, 400.0), 1e-13);
    ck_assert_mem_eq(many.lo, one.lo, sizeof one.lo);
    ck_assert_mem_eq(many.hi, one.hi, sizeof one.hi);
    ck_assert_mem_eq(many.seen, one.seen, sizeof one.seen);
    ck_assert_int_eq(fe_quadric_regions(&many), 100);
}
END_TEST

/* Streams whose box keeps growing (Gaussian clouds, the first third
   folded one step at a time): a block that grows the box must leave the
   box and the recorded region sizes that one step at a time leaves, the
   samples before the growth marked at the smaller size, not all of them
   at the grown box's. */
START_TEST(step_equals_block_when_the_box_grows)
{
    enum { N = 3000 };
    static double x[3 * N];
    fe_rng g = fe_rng_seed(7);
    int differ = 0;
    for (int t = 0; t < 40; t++) {
        size_t n = 1 + (size_t)(fe_rng_uniform(&g) * (N - 1)), first = n / 3,
               done = 0;
        fe_quadric one = FE_QUADRIC_EMPTY, many = FE_QUADRIC_EMPTY;
        int rc = FE_OK;
        for (size_t i = 0; i < 3 * n; i++)
            x[i] = 1000.0 + 50.0 * fe_rng_normal(&g);
        for (size_t i = 0; i < n && rc == FE_OK; i++)
            rc = fe_quadric_add(&one, x + 3 * i);
        for (size_t i = 0; i < first && rc == FE_OK; i++)
            rc = fe_quadric_add(&many, x + 3 * i);
        ck_assert_int_eq(rc, FE_OK);
        ck_assert_int_eq(fe_quadric_add_many(&many, x + 3 * first, n - first,
                                             &done), FE_OK);
        ck_assert_uint_eq(done, n - first);
        ck_assert_double_le(moment_diff(&many, &one, 200.0), 1e-12);
        ck_assert_mem_eq(many.lo, one.lo, sizeof one.lo);
        ck_assert_mem_eq(many.hi, one.hi, sizeof one.hi);
        differ += memcmp(many.seen, one.seen, sizeof one.seen) != 0;
    }
    ck_assert_int_eq(differ, 0);
}
END_TEST

START_TEST(two_shards_equal_one)
{
    enum { N = 20000 };
    static double x[3 * N];
    fe_accumulator f = fe_quadric_accumulator(NULL);
    fe_quadric whole, a, b;
    fe_test_ellipsoid_points(x, N, C0, R0, 2.0, 2);
    ck_assert_int_eq(fe_init(&f, &whole), FE_OK);
    ck_assert_int_eq(fe_fold(&f, &whole, x, N, NULL), FE_OK);
    ck_assert_int_eq(fe_init(&f, &a), FE_OK);
    ck_assert_int_eq(fe_init(&f, &b), FE_OK);
    ck_assert_int_eq(fe_fold(&f, &a, x, 7919, NULL), FE_OK);
    ck_assert_int_eq(fe_fold(&f, &b, x + 3 * 7919, N - 7919, NULL), FE_OK);
    ck_assert(memcmp(a.ref, b.ref, sizeof a.ref) != 0); /* merge must re-centre */
    ck_assert_int_eq(fe_merge(&f, &a, &b), FE_OK);
    ck_assert_uint_eq(fe_quadric_count(&a), N);
    ck_assert_double_le(moment_diff(&a, &whole, 400.0), 1e-12);
    ck_assert_mem_eq(a.lo, whole.lo, sizeof a.lo);
    ck_assert_mem_eq(a.hi, whole.hi, sizeof a.hi);
    /* fe_quadric_compare: the merged shards against the whole; a known
       perturbation of a fourth moment; exact parts that differ. */
    {
        double apart = -1.0, s = 0.0;
        fe_quadric c = a;
        ck_assert_int_eq(fe_quadric_compare(&a, &whole, &apart), FE_OK);
        ck_assert_double_le(apart, 1e-12);
        ck_assert_double_ge(apart, 0.0);
        for (int j = 0; j < 3; j++)
            s = fmax(s, fmax(whole.hi[j] - whole.ref[j], whole.ref[j] - whole.lo[j]));
        c.m[fe_quadric_index(2, 1, 1)] += 1e-6 * N * s * s * s * s;
        ck_assert_int_eq(fe_quadric_compare(&c, &whole, &apart), FE_OK);
        FE_ASSERT_REL(apart, 1e-6, 1e-6);
        c = a;
        c.m[0] += 1.0;
        ck_assert_int_eq(fe_quadric_compare(&c, &whole, &apart), FE_EMISMATCH);
        c = a;
        c.hi[2] += 1.0;
        ck_assert_int_eq(fe_quadric_compare(&c, &whole, &apart), FE_EMISMATCH);
        ck_assert_int_eq(fe_quadric_compare(&b, &whole, &apart), FE_EMISMATCH);
        ck_assert_int_eq(fe_quadric_compare(NULL, &whole, &apart), FE_EINVAL);
        ck_assert_int_eq(fe_quadric_compare(&a, &whole, NULL), FE_EINVAL);
    }
}
END_TEST

START_TEST(merged_hemispheres_cover_the_sphere)
{
    /* The samples above the centre folded in one accumulation, those below
       in another: merged, they report what the whole reports: the count,
       the box (against the brute-force extremes), the moments, and every
       one of the 100 regions (every region holds a sample direction from
       the true centre, counted here), so coverage 1. */
    enum { N = 6000 };
    static double x[3 * N];
    fe_quadric up = FE_QUADRIC_EMPTY, down = FE_QUADRIC_EMPTY, whole = FE_QUADRIC_EMPTY;
    int seen[FE_QUADRIC_REGIONS] = {0}, count = 0;
    double lo[3], hi[3];
    fe_test_ellipsoid_points(x, N, C0, R0, 2.0, 12);
    for (int j = 0; j < 3; j++)
        lo[j] = hi[j] = x[j];
    for (size_t i = 0; i < N; i++) {
        double v[3] = {x[3 * i] - C0[0], x[3 * i + 1] - C0[1], x[3 * i + 2] - C0[2]};
        int r = fe_quadric_region(v);
        count += r >= 0 && !seen[r];
        if (r >= 0)
            seen[r] = 1;
        for (int j = 0; j < 3; j++) {
            lo[j] = fmin(lo[j], x[3 * i + j]);
            hi[j] = fmax(hi[j], x[3 * i + j]);
        }
        ck_assert_int_eq(fe_quadric_add(v[2] > 0.0 ? &up : &down, x + 3 * i), FE_OK);
    }
    ck_assert_int_eq(count, 100);
    ck_assert_int_eq(fe_quadric_add_many(&whole, x, N, NULL), FE_OK);
    ck_assert_double_lt(fe_quadric_coverage(&down), 1.0);    /* each half alone */
    ck_assert_double_lt(fe_quadric_coverage(&up), 1.0);
    ck_assert_int_eq(fe_quadric_merge(&up, &down), FE_OK);
    ck_assert_uint_eq(fe_quadric_count(&up), N);
    ck_assert_mem_eq(up.lo, lo, sizeof lo);
    ck_assert_mem_eq(up.hi, hi, sizeof hi);
    ck_assert_int_eq(fe_quadric_regions(&up), 100);
    FE_ASSERT_REL(fe_quadric_coverage(&up), 1.0, 0.0);
    ck_assert_int_eq(fe_quadric_regions(&whole), 100);
    {
        double apart = -1.0;
        ck_assert_int_eq(fe_quadric_recentre(&up, whole.ref), FE_OK);
        ck_assert_int_eq(fe_quadric_compare(&up, &whole, &apart), FE_OK);
        ck_assert_double_le(apart, 1e-12);
    }
}
END_TEST

START_TEST(merge_every_split_and_associativity)
{
    enum { N = 40 };
    double x[3 * N], worst = 0.0;
    fe_quadric whole = FE_QUADRIC_EMPTY, p = FE_QUADRIC_EMPTY,
               q = FE_QUADRIC_EMPTY, r = FE_QUADRIC_EMPTY, left, right;
    int bad = 0;
    fe_test_ellipsoid_points(x, N, C0, R0, 1.0, 3);
    ck_assert_int_eq(fe_quadric_add_many(&whole, x, N, NULL), FE_OK);
    for (size_t s = 0; s <= N; s++) {
        fe_quadric a = FE_QUADRIC_EMPTY, b = FE_QUADRIC_EMPTY;
        bad += fe_quadric_add_many(&a, x, s, NULL) != FE_OK;
        bad += fe_quadric_add_many(&b, x + 3 * s, N - s, NULL) != FE_OK;
        bad += fe_quadric_merge(&a, &b) != FE_OK;
        bad += fe_quadric_count(&a) != N;
        worst = fmax(worst, moment_diff(&a, &whole, 400.0));
    }
    ck_assert_int_eq(bad, 0);
    ck_assert_double_le(worst, 1e-12);
    fe_quadric_add_many(&p, x, 10, NULL);
    fe_quadric_add_many(&q, x + 30, 15, NULL);
    fe_quadric_add_many(&r, x + 75, 15, NULL);
    left = p;
    fe_quadric_merge(&left, &q);
    fe_quadric_merge(&left, &r);
    right = q;
    fe_quadric_merge(&right, &r);
    {
        fe_quadric t = p;
        fe_quadric_merge(&t, &right);
        right = t;
    }
    ck_assert_double_le(moment_diff(&left, &right, 400.0), 1e-13);
}
END_TEST

START_TEST(recentre_equals_accumulating_there)
{
    enum { N = 3000 };
    static double x[3 * N];
    const double there[3] = {90, -60, 40};
    fe_quadric a = FE_QUADRIC_EMPTY, b;
    fe_test_ellipsoid_points(x, N, C0, R0, 2.0, 4);
    ck_assert_int_eq(fe_quadric_add_many(&a, x, N, NULL), FE_OK);
    ck_assert_int_eq(fe_quadric_init(&b, there), FE_OK);
    ck_assert_int_eq(fe_quadric_add_many(&b, x, N, NULL), FE_OK);
    ck_assert_int_eq(fe_quadric_recentre(&a, there), FE_OK);
    ck_assert_mem_eq(a.ref, b.ref, sizeof a.ref);
    ck_assert_double_le(moment_diff(&a, &b, 400.0), 1e-12);
    /* A supplied reference survives a merge into an empty accumulation. */
    {
        fe_quadric c, d = FE_QUADRIC_EMPTY;
        fe_quadric_init(&c, there);
        fe_quadric_add_many(&d, x, N, NULL);
        ck_assert_int_eq(fe_quadric_merge(&c, &d), FE_OK);
        ck_assert_mem_eq(c.ref, there, sizeof c.ref);
        ck_assert_double_le(moment_diff(&c, &b, 400.0), 1e-12);
    }
}
END_TEST

START_TEST(bad_samples_leave_it_unchanged)
{
    enum { N = 1000, BAD = 613 };
    static double x[3 * N];
    const double nonfinite[3] = {NAN, INFINITY, -INFINITY};
    fe_test_ellipsoid_points(x, N, C0, R0, 2.0, 5);
    for (int t = 0; t < 3; t++) {
        fe_quadric q = FE_QUADRIC_EMPTY, before, slow = FE_QUADRIC_EMPTY;
        double bad[3] = {1, 2, 3};
        size_t done = 0;
        bad[t] = nonfinite[t];
        fe_quadric_add_many(&q, x, 100, NULL);
        before = q;
        ck_assert_int_eq(fe_quadric_add(&q, bad), FE_ENONFINITE);
        ck_assert_mem_eq(&q, &before, sizeof q);
        /* The block path stops exactly at the bad sample. */
        x[3 * BAD + t] = nonfinite[t];
        q = (fe_quadric)FE_QUADRIC_EMPTY;
        ck_assert_int_eq(fe_quadric_add_many(&q, x, N, &done), FE_ENONFINITE);
        ck_assert_uint_eq(done, BAD);
        for (size_t i = 0; i < BAD; i++)
            fe_quadric_add(&slow, x + 3 * i);
        ck_assert_double_le(moment_diff(&q, &slow, 400.0), 1e-13);
        x[3 * BAD + t] = 1.0;
    }
    /* An overflowing fourth power is refused too. */
    {
        fe_quadric q = FE_QUADRIC_EMPTY, before;
        const double huge[3] = {1e90, 0, 0};
        fe_quadric_add_many(&q, x, 10, NULL);
        before = q;
        ck_assert_int_eq(fe_quadric_add(&q, huge), FE_ENONFINITE);
        ck_assert_mem_eq(&q, &before, sizeof q);
        ck_assert_int_eq(fe_quadric_init(&q, nonfinite), FE_ENONFINITE);
        ck_assert_mem_eq(&q, &before, sizeof q);
        ck_assert_int_eq(fe_quadric_add(NULL, huge), FE_EINVAL);
    }
    /* A merge or a move whose binomial shift overflows is refused too. */
    {
        const double far[3] = {1e90, 0, 0};
        fe_quadric a = FE_QUADRIC_EMPTY, b, before;
        fe_quadric_add_many(&a, x, 10, NULL);
        fe_quadric_init(&b, far);
        ck_assert_int_eq(fe_quadric_add(&b, far), FE_OK);
        before = a;
        ck_assert_int_eq(fe_quadric_merge(&a, &b), FE_ENONFINITE);
        ck_assert_mem_eq(&a, &before, sizeof a);
        ck_assert_int_eq(fe_quadric_recentre(&a, far), FE_ENONFINITE);
        ck_assert_mem_eq(&a, &before, sizeof a);
    }
}
END_TEST

START_TEST(regions_have_equal_area)
{
    /* Uniform directions: each region should get 1% of them; with 10^5
       directions a region's count has standard deviation ~31. */
    size_t n = fe_test_quick() ? 20000 : 100000, count[100] = {0}, none = 0;
    fe_rng g = fe_rng_seed(6);
    double worst = 0.0, sd;
    for (size_t i = 0; i < n; i++) {
        double v[3] = {fe_rng_normal(&g), fe_rng_normal(&g), fe_rng_normal(&g)};
        int r = fe_quadric_region(v);
        if (r < 0)
            none++;
        else
            count[r]++;
    }
    ck_assert_uint_eq(none, 0);
    sd = sqrt(n * 0.01 * 0.99);
    for (int r = 0; r < 100; r++)
        worst = fmax(worst, fabs((double)count[r] - 0.01 * n) / sd);
    ck_assert_double_le(worst, 4.5);
    {
        const double up[3] = {0, 0, 1}, down[3] = {0, 0, -2}, east[3] = {1, 0.01, 0},
                     zero[3] = {0, 0, 0}, west[3] = {-1, -0.01, 0};
        ck_assert_int_eq(fe_quadric_region(up) / 10, 9);
        ck_assert_int_eq(fe_quadric_region(down) / 10, 0);
        ck_assert_int_eq(fe_quadric_region(east), 50);   /* band 5, sector 0 */
        ck_assert_int_eq(fe_quadric_region(west), 55);   /* sector 5: 180..216 */
        ck_assert_int_eq(fe_quadric_region(zero), -1);
    }
}
END_TEST

START_TEST(coverage_ignores_an_initial_rest_and_sees_a_hemisphere)
{
    enum { N = 4000, REST = 500 };
    static double x[3 * N], rest[3 * REST];
    fe_quadric q = FE_QUADRIC_EMPTY, h = FE_QUADRIC_EMPTY, h0 = FE_QUADRIC_EMPTY;
    fe_rng g = fe_rng_seed(7);
    int exact[100] = {0}, nexact = 0;
    /* A sensor at rest for 500 samples (noise only) at the top of its
       sphere: directions from the middle of the noise cluster point
       everywhere, but the box is then the size of the noise. */
    for (size_t i = 0; i < REST; i++)
        for (int j = 0; j < 3; j++)
            rest[3 * i + j] = C0[j] + (j == 2 ? R0[2] : 0.0) + 2.0 * fe_rng_normal(&g);
    fe_quadric_add_many(&h, rest, REST, NULL);
    ck_assert_int_ge(fe_quadric_regions(&h), 50);   /* the noise, alone */
    /* Then turned through the upper hemisphere only. */
    fe_test_ellipsoid_points(x, N, C0, R0, 2.0, 8);
    for (size_t i = 0; i < N; i++)
        if (x[3 * i + 2] < C0[2])
            x[3 * i + 2] = 2 * C0[2] - x[3 * i + 2];
    fe_quadric_add_many(&h, x, N, NULL);
    fe_quadric_add_many(&h0, x, N, NULL);
    /* The rest adds (almost) nothing to the estimate... */
    ck_assert_int_le(abs(fe_quadric_regions(&h) - fe_quadric_regions(&h0)), 3);
    /* ...which overstates a hemisphere, because the box's centre sits
       half-way up it (the fit's extents are what refuse such data); the
       exact count from the true centre is half the sphere. */
    ck_assert_int_gt(fe_quadric_regions(&h0), 60);
    for (size_t i = 0; i < N; i++) {
        double v[3] = {x[3 * i] - C0[0], x[3 * i + 1] - C0[1], x[3 * i + 2] - C0[2]};
        int r = fe_quadric_region(v);
        nexact += r >= 0 && !exact[r];
        if (r >= 0)
            exact[r] = 1;
    }
    ck_assert_int_eq(nexact, 50);
    /* The whole sphere. */
    fe_test_ellipsoid_points(x, N, C0, R0, 2.0, 9);
    fe_quadric_add_many(&q, rest, REST, NULL);
    fe_quadric_add_many(&q, x, N, NULL);
    ck_assert_int_eq(fe_quadric_regions(&q), 100);
    FE_ASSERT_REL(fe_quadric_coverage(&q), 1.0, 0.0);
}
END_TEST

START_TEST(block_extremes_in_the_tail_of_a_block)
{
    /* A box from two samples, then 13 samples inside it but for one,
       which leaves the box on one side of one axis: the eight-lane kernel
       takes samples 0-7 in lanes and 8-12 one at a time (the four-lane one
       0-11 and 12).  Each of the six sides, the sample leaving the box at
       each place in the block: the box must be the brute-force minimum and
       maximum of all 15 samples, and the moments those of one sample at a
       time. */
    enum { M = 13 };
    static const double corner[6] = {0, 0, 0, 10, 10, 10};
    int bad = 0;
    for (int side = 0; side < 6; side++)
        for (int at = 0; at < M; at++) {
            double x[3 * M], lo[3], hi[3];
            fe_quadric q = FE_QUADRIC_EMPTY, one = FE_QUADRIC_EMPTY;
            for (int i = 0; i < M; i++)
                for (int j = 0; j < 3; j++)
                    x[3 * i + j] = 1.0 + 0.5 * ((i * (j + 2)) % 17);    /* in (0, 10) */
            x[3 * at + side % 3] = side < 3 ? -4.0 - at : 14.0 + at;
            ck_assert_int_eq(fe_quadric_add_many(&q, corner, 2, NULL), FE_OK);
            ck_assert_int_eq(fe_quadric_add_many(&q, x, M, NULL), FE_OK);
            for (int j = 0; j < 3; j++) {
                lo[j] = 0.0;
                hi[j] = 10.0;
                for (int i = 0; i < M; i++) {
                    lo[j] = fmin(lo[j], x[3 * i + j]);
                    hi[j] = fmax(hi[j], x[3 * i + j]);
                }
                bad += q.lo[j] != lo[j] || q.hi[j] != hi[j];
            }
            fe_quadric_add(&one, corner);
            fe_quadric_add(&one, corner + 3);
            for (int i = 0; i < M; i++)
                fe_quadric_add(&one, x + 3 * i);
            bad += moment_diff(&q, &one, 30.0) > 1e-14;
            bad += memcmp(q.seen, one.seen, sizeof q.seen) != 0;
        }
    ck_assert_int_eq(bad, 0);
}
END_TEST

START_TEST(block_coverage_of_a_hemisphere_inside_the_box)
{
    /* The eight corners of a cube fix the box and its centre C0; then 300
       samples inside it on the half z > 0 of a sphere about C0, folded as
       one block.  They are all inside the box, so each is marked in the
       region of its direction from C0 at the box's full size: the regions
       counted must be those found here with fe_quadric_region (the
       corners, marked while the box grew, stay below half its size but
       for the last, which is in the upper half), and the marks those of
       one sample at a time. */
    enum { N = 300 };
    static double x[3 * N], cube[3 * 8];
    fe_quadric q = FE_QUADRIC_EMPTY, one = FE_QUADRIC_EMPTY;
    fe_rng g = fe_rng_seed(31);
    int seen[FE_QUADRIC_REGIONS] = {0}, count = 0;
    for (int k = 0; k < 8; k++) {
        double v[3] = {k & 1 ? 100.0 : -100.0, k & 2 ? 100.0 : -100.0, k & 4 ? 100.0 : -100.0};
        for (int j = 0; j < 3; j++)
            cube[3 * k + j] = C0[j] + v[j];
    }
    for (size_t i = 0; i < N; i++) {
        double v[3];
        fe_rng_unit_vector(&g, v);
        v[2] = fabs(v[2]);
        for (int j = 0; j < 3; j++)
            x[3 * i + j] = C0[j] + 90.0 * v[j];
        {
            int r = fe_quadric_region(v);
            count += r >= 0 && !seen[r];
            if (r >= 0)
                seen[r] = 1;
        }
    }
    fe_quadric_add_many(&q, cube, 8, NULL);
    ck_assert_int_eq(fe_quadric_add_many(&q, x, N, NULL), FE_OK);
    for (int k = 0; k < 8; k++)
        fe_quadric_add(&one, cube + 3 * k);
    for (size_t i = 0; i < N; i++)
        fe_quadric_add(&one, x + 3 * i);
    ck_assert_int_eq(fe_quadric_regions(&q), count);
    ck_assert_int_le(count, 50);                 /* the upper half of 100 */
    ck_assert_mem_eq(q.seen, one.seen, sizeof q.seen);
}
END_TEST

/* The coverage's threshold, at its edge: a region counts when it was
   visited while the box's largest half-width was at least half its final
   one, equality included (seed 9909's quadric:1905, >= made >).  Each
   sample's region is taken from the box's centre after it, the sizes
   worked by hand and exact in float. */
START_TEST(coverage_counts_a_region_seen_at_exactly_half_the_size)
{
    const double s[5][3] = {{-1, 0, 0}, {1, 0, 0}, {0, 0, 1}, {0, 0, -3}, {0, 0, -7}};
    const double px[3] = {1, 0, 0}, pz[3] = {0, 0, 1}, mz[3] = {0, 0, -1};
    fe_quadric q = FE_QUADRIC_EMPTY, p = FE_QUADRIC_EMPTY;
    /* Three different regions: +x, +z and -z. */
    ck_assert_int_ne(fe_quadric_region(px), fe_quadric_region(pz));
    ck_assert_int_ne(fe_quadric_region(px), fe_quadric_region(mz));
    ck_assert_int_ne(fe_quadric_region(pz), fe_quadric_region(mz));
    /* One sample, or the same one twice: a box of no extent, no direction,
       no region visited. */
    ck_assert_int_eq(fe_quadric_add(&p, s[1]), FE_OK);
    ck_assert_int_eq(fe_quadric_regions(&p), 0);
    ck_assert_int_eq(fe_quadric_add(&p, s[1]), FE_OK);
    ck_assert_int_eq(fe_quadric_regions(&p), 0);
    /* (-1, 0, 0): no extent.  (1, 0, 0): half-width 1, centre 0, +x seen
       at 1.  (0, 0, 1): z in [0, 1], still 1, centre (0, 0, 0.5), +z seen
       at 1. */
    for (int i = 0; i < 3; i++)
        ck_assert_int_eq(fe_quadric_add(&q, s[i]), FE_OK);
    ck_assert_int_eq(fe_quadric_regions(&q), 2);
    /* (0, 0, -3): z in [-3, 1], half-width 2, centre (0, 0, -1), -z seen
       at 2.  Half the final size is 1: +x and +z count, at exactly 1. */
    ck_assert_int_eq(fe_quadric_add(&q, s[3]), FE_OK);
    ck_assert_int_eq(fe_quadric_regions(&q), 3);
    /* (0, 0, -7): z in [-7, 1], half-width 4, -z seen at 4; half of it is
       2, and the regions seen at 1 no longer count. */
    ck_assert_int_eq(fe_quadric_add(&q, s[4]), FE_OK);
    ck_assert_int_eq(fe_quadric_regions(&q), 1);
}
END_TEST

/* The regions are counted from the box and the marks, whatever the
   moments hold: a stream whose first coordinates add up to the first
   sample's (its first moment about that reference, the first sample, is
   0) counts its regions like any other.  (0, 0, 0): no extent.  (2, 0, 0):
   x in [0, 2], half-width 1, centre (1, 0, 0), +x seen at 1.  (-2, 0, 0):
   x in [-2, 2], half-width 2, centre 0, -x seen at 2.  (0, 0, 2): z in
   [0, 2], still 2, centre (0, 0, 1), +z seen at 2.  Half the final size
   is 1: all three count; with the centre given as (0, 0, 0) the same. */
START_TEST(coverage_does_not_depend_on_the_first_moment)
{
    const double s[4][3] = {{0, 0, 0}, {2, 0, 0}, {-2, 0, 0}, {0, 0, 2}};
    const double px[3] = {1, 0, 0}, mx[3] = {-1, 0, 0}, pz[3] = {0, 0, 1};
    const double origin[3] = {0, 0, 0};
    fe_quadric q = FE_QUADRIC_EMPTY, c;
    ck_assert_int_ne(fe_quadric_region(px), fe_quadric_region(mx));
    ck_assert_int_ne(fe_quadric_region(px), fe_quadric_region(pz));
    ck_assert_int_ne(fe_quadric_region(mx), fe_quadric_region(pz));
    ck_assert_int_eq(fe_quadric_init(&c, origin), FE_OK);
    for (int i = 0; i < 4; i++) {
        ck_assert_int_eq(fe_quadric_add(&q, s[i]), FE_OK);
        ck_assert_int_eq(fe_quadric_add(&c, s[i]), FE_OK);
    }
    ck_assert_double_eq(q.m[1], 0.0);       /* x's first moment about (0, 0, 0) */
    ck_assert_double_eq(c.m[1], 0.0);
    ck_assert_uint_eq(fe_quadric_count(&q), 4);
    ck_assert_int_eq(fe_quadric_regions(&q), 3);
    ck_assert_int_eq(fe_quadric_regions(&c), 3);
    FE_ASSERT_REL(fe_quadric_coverage(&q), 0.03, 0.0);
}
END_TEST

START_TEST(compare_a_box_of_one_point_absolutely)
{
    /* One sample: the box has no extent, every moment's scale N s^d is
       zero, and a difference is reported as it is (0.5 here, under 1). */
    const double p[3] = {1, 2, 3};
    fe_quadric a = FE_QUADRIC_EMPTY, b = FE_QUADRIC_EMPTY;
    double apart = -1.0;
    fe_quadric_add(&a, p);
    fe_quadric_add(&b, p);
    ck_assert_int_eq(fe_quadric_compare(&a, &b, &apart), FE_OK);
    ck_assert_double_eq(apart, 0.0);
    a.m[1] = 0.5;
    ck_assert_int_eq(fe_quadric_compare(&a, &b, &apart), FE_OK);
    ck_assert_double_eq(apart, 0.5);
    a.m[1] = 0.0;
    a.m[34] = -0.25;
    ck_assert_int_eq(fe_quadric_compare(&a, &b, &apart), FE_OK);
    ck_assert_double_eq(apart, 0.25);
}
END_TEST

START_TEST(compare_is_the_largest_scaled_difference)
{
    /* Two samples 0.5 apart on x: N = 2, s = 0.5, so a moment of degree d
       has the scale 2 * 0.5^d (0.5 for d = 2, 0.25 for d = 3).  Moving
       the x^2 sum by 0.3 and the x^3 sum by 0.1: 0.3 / 0.5 = 0.6 and
       0.1 / 0.25 = 0.4; the largest, 0.6, whatever the order. */
    const double p[6] = {0, 0, 0, 0.5, 0, 0};
    fe_quadric a = FE_QUADRIC_EMPTY, b = FE_QUADRIC_EMPTY;
    double apart = -1.0;
    fe_quadric_add_many(&a, p, 2, NULL);
    fe_quadric_add_many(&b, p, 2, NULL);
    a.m[fe_quadric_index(2, 0, 0)] += 0.3;
    a.m[fe_quadric_index(3, 0, 0)] += 0.1;
    ck_assert_int_eq(fe_quadric_compare(&a, &b, &apart), FE_OK);
    FE_ASSERT_REL(apart, 0.6, 1e-14);
    a.m[fe_quadric_index(2, 0, 0)] -= 0.3;
    a.m[fe_quadric_index(3, 0, 0)] += 0.2;     /* now 0.3 / 0.25 */
    ck_assert_int_eq(fe_quadric_compare(&a, &b, &apart), FE_OK);
    FE_ASSERT_REL(apart, 1.2, 1e-14);
}
END_TEST

/* Single precision (the Cortex-M4F step).  Fits of a double and a float
   accumulation of the same samples, compared as fractions of the field:
   the largest of |offset difference| / R and R |matrix difference|. */
static double fits_apart(const fe_quadric *qd, const fe_quadric *qf, int model)
{
    fe_sphere_fit fd, ff;
    double worst = 0.0;
    ck_assert_int_eq(fe_sphere_fit_moments(qd, (fe_sphere_model)model, NULL, &fd), FE_OK);
    ck_assert_int_eq(fe_sphere_fit_moments(qf, (fe_sphere_model)model, NULL, &ff), FE_OK);
    for (int j = 0; j < 3; j++)
        worst = fmax(worst, fabs(fd.offset[j] - ff.offset[j]) / fd.radius);
    for (int j = 0; j < 9; j++)
        worst = fmax(worst, fabs(fd.matrix[j] - ff.matrix[j]) * fd.radius);
    return worst;
}

/* Round samples to float in place, so that a double and a float fold see
   the same numbers.  (Written as one loop: GCC 12's -O2 vectoriser drops
   the rounding of a round trip through a float[3] rebuilt per sample.) */
static void round_to_float(double *x, size_t n)
{
    for (size_t k = 0; k < n; k++)
        x[k] = (float)x[k];
}

/* The float step against the double step on a QMC5883L-like ellipsoid
   (offset five times the field, semi-axes 1 : 1.6 : 2.3, 1.5% noise):
   samples rounded to float first, so both fold the same numbers.  The
   float fold re-centres itself near the centre; the fits agree to 1e-5
   of the field, and the moments (moved to the double's reference) to
   float rounding. */
START_TEST(f32_step_agrees_with_the_double_step)
{
    enum { N = 20000 };
    static double x[3 * N];
    const double c[3] = {6000, 250, 3500}, r[3] = {700, 1100, 1600};
    fe_quadric qd = FE_QUADRIC_EMPTY, qf;
    fe_quadric_f32 f = FE_QUADRIC_F32_EMPTY;
    fe_test_ellipsoid_points(x, N, c, r, 15.0, 21);
    round_to_float(x, 3 * N);
    for (size_t i = 0; i < N; i++) {
        float xf[3] = {(float)x[3 * i], (float)x[3 * i + 1], (float)x[3 * i + 2]};
        ck_assert_int_eq(fe_quadric_f32_add(&f, xf), FE_OK);
        ck_assert_int_eq(fe_quadric_add(&qd, x + 3 * i), FE_OK);
    }
    ck_assert_uint_eq(f.n, N);
    ck_assert_uint_gt(f.recentres, 0);
    /* The reference ends within a tenth of the box's largest half-width
       (z's) of the mean, which is within 10 of the centre (its standard
       error is r / sqrt(3N) < 7): a reference 5 field-widths off would be
       6000 away. */
    for (int j = 0; j < 3; j++) {
        double mean = qd.ref[j] + qd.m[1 + j] / qd.m[0];
        ck_assert_double_le(fabs(f.ref[j] - mean), 0.1 * 0.5 * (qd.hi[2] - qd.lo[2]));
        ck_assert_double_le(fabs(f.ref[j] - c[j]), 0.1 * 0.5 * (qd.hi[2] - qd.lo[2]) + 10.0);
        ck_assert_double_eq(f.lo[j], qd.lo[j]);
        ck_assert_double_eq(f.hi[j], qd.hi[j]);
    }
    ck_assert_int_eq(fe_quadric_from_f32(&qf, &f), FE_OK);
    ck_assert_uint_eq(fe_quadric_count(&qf), N);
    ck_assert_int_eq(fe_quadric_recentre(&qd, qf.ref), FE_OK);
    ck_assert_double_le(moment_diff(&qf, &qd, 1600.0), 1e-5);
    ck_assert_double_le(fits_apart(&qd, &qf, FE_FIT_ELLIPSOID), 1e-5);
    ck_assert_double_le(fits_apart(&qd, &qf, FE_FIT_AXIAL), 1e-5);
    ck_assert_double_le(fits_apart(&qd, &qf, FE_FIT_SPHERE), 1e-5);
}
END_TEST

/* The binomial shift in float is exact where float arithmetic is: small
   integer samples, whose moments about integer points are integers below
   2^24, moved to another integer point equal the moments summed about it
   from the start (in double, exactly).  Then on real-sized data the step's
   moments, moved to an arbitrary point, equal the double moments summed
   about that point to float rounding. */
START_TEST(f32_recentre_is_exact)
{
    enum { N = 40 };
    const double from[3] = {3, -2, 5}, to[3] = {-4, 6, 1};
    const float tof[3] = {-4, 6, 1};
    fe_quadric a, b;
    fe_quadric_f32 f = FE_QUADRIC_F32_EMPTY;
    fe_rng g = fe_rng_seed(22);
    ck_assert_int_eq(fe_quadric_init(&a, from), FE_OK);
    ck_assert_int_eq(fe_quadric_init(&b, to), FE_OK);
    for (int i = 0; i < N; i++) {
        double x[3];
        for (int j = 0; j < 3; j++)
            x[j] = (double)(int)(fe_rng_uniform(&g) * 17.0) - 8.0;
        fe_quadric_add(&a, x);
        fe_quadric_add(&b, x);
    }
    /* The float state holding a's moments about `from`, exactly. */
    for (int k = 0; k < FE_QUADRIC_MOMENTS; k++) {
        f.m[k] = (float)a.m[k];
        ck_assert_double_eq(f.m[k], a.m[k]);
    }
    for (int j = 0; j < 3; j++) {
        f.ref[j] = (float)from[j];
        f.lo[j] = (float)a.lo[j];
        f.hi[j] = (float)a.hi[j];
    }
    f.n = N;
    f.flags = FE_QUADRIC_HAS_REF;
    ck_assert_int_eq(fe_quadric_f32_recentre(&f, tof), FE_OK);
    for (int k = 0; k < FE_QUADRIC_MOMENTS; k++)
        ck_assert_msg(f.m[k] == b.m[k], "moment %d: %.9g, want %.17g", k,
                      (double)f.m[k], b.m[k]);
    ck_assert_mem_eq(f.ref, tof, sizeof tof);
    /* Real-sized data, with the step's own re-centres on the way. */
    {
        enum { M = 3000 };
        static double x[3 * M];
        const double there[3] = {90, -60, 40};
        const float theref[3] = {90, -60, 40};
        fe_quadric_f32 h = FE_QUADRIC_F32_EMPTY;
        fe_quadric d, hq;
        fe_test_ellipsoid_points(x, M, C0, R0, 2.0, 23);
        round_to_float(x, 3 * M);
        ck_assert_int_eq(fe_quadric_init(&d, there), FE_OK);
        for (size_t i = 0; i < M; i++) {
            float xf[3] = {(float)x[3 * i], (float)x[3 * i + 1], (float)x[3 * i + 2]};
            ck_assert_int_eq(fe_quadric_f32_add(&h, xf), FE_OK);
            fe_quadric_add(&d, x + 3 * i);
        }
        ck_assert_uint_gt(h.recentres, 0);
        ck_assert_int_eq(fe_quadric_f32_recentre(&h, theref), FE_OK);
        ck_assert_int_eq(fe_quadric_from_f32(&hq, &h), FE_OK);
        ck_assert_mem_eq(hq.ref, there, sizeof there);
        ck_assert_double_le(moment_diff(&hq, &d, 400.0), 1e-6);
        ck_assert_double_gt(moment_diff(&hq, &d, 400.0), 0.0); /* float, not double */
    }
}
END_TEST

/* NaN, infinities, overflowing powers and a full count are refused and
   leave the float accumulation as it was; NULL is FE_EINVAL. */
START_TEST(f32_bad_samples_leave_it_unchanged)
{
    enum { N = 200 };
    static double x[3 * N];
    const float nonfinite[3] = {NAN, INFINITY, -INFINITY};
    fe_quadric_f32 q = FE_QUADRIC_F32_EMPTY, before;
    fe_quadric d;
    fe_test_ellipsoid_points(x, N, C0, R0, 2.0, 24);
    for (size_t i = 0; i < N; i++) {
        float xf[3] = {(float)x[3 * i], (float)x[3 * i + 1], (float)x[3 * i + 2]};
        ck_assert_int_eq(fe_quadric_f32_add(&q, xf), FE_OK);
    }
    for (int t = 0; t < 3; t++) {
        float bad[3] = {1, 2, 3};
        bad[t] = nonfinite[t];
        before = q;
        ck_assert_int_eq(fe_quadric_f32_add(&q, bad), FE_ENONFINITE);
        ck_assert_mem_eq(&q, &before, sizeof q);
        ck_assert_int_eq(fe_quadric_f32_recentre(&q, bad), FE_ENONFINITE);
        ck_assert_mem_eq(&q, &before, sizeof q);
        ck_assert_int_eq(fe_quadric_f32_init(&q, bad), FE_ENONFINITE);
        ck_assert_mem_eq(&q, &before, sizeof q);
    }
    {
        const float huge[3] = {1e12f, 0, 0};   /* (1e12)^4 overflows a float */
        before = q;
        ck_assert_int_eq(fe_quadric_f32_add(&q, huge), FE_ENONFINITE);
        ck_assert_mem_eq(&q, &before, sizeof q);
        ck_assert_int_eq(fe_quadric_f32_recentre(&q, huge), FE_ENONFINITE);
        ck_assert_mem_eq(&q, &before, sizeof q);
    }
    {
        const float one[3] = {1, 2, 3};
        fe_quadric_f32 full = q;
        full.n = UINT32_MAX;
        before = full;
        ck_assert_int_eq(fe_quadric_f32_add(&full, one), FE_ESIZE);
        ck_assert_mem_eq(&full, &before, sizeof full);
        /* One sample short of full is taken (issue 20: the edge from
           inside), and the count is then full. */
        full = q;
        full.n = UINT32_MAX - 1;
        ck_assert_int_eq(fe_quadric_f32_add(&full, one), FE_OK);
        ck_assert_uint_eq(full.n, UINT32_MAX);
        ck_assert_int_eq(fe_quadric_f32_add(&full, one), FE_ESIZE);
        ck_assert_int_eq(fe_quadric_f32_add(NULL, one), FE_EINVAL);
        ck_assert_int_eq(fe_quadric_f32_add(&q, NULL), FE_EINVAL);
        ck_assert_int_eq(fe_quadric_f32_recentre(NULL, one), FE_EINVAL);
        ck_assert_int_eq(fe_quadric_f32_init(NULL, NULL), FE_EINVAL);
        ck_assert_int_eq(fe_quadric_from_f32(NULL, &q), FE_EINVAL);
        ck_assert_int_eq(fe_quadric_from_f32(&d, NULL), FE_EINVAL);
    }
    /* Empty, and a supplied first reference. */
    {
        const float centre[3] = {100, -50, 30};
        fe_quadric_f32 e;
        ck_assert_int_eq(fe_quadric_f32_init(&e, NULL), FE_OK);
        ck_assert_int_eq(fe_quadric_from_f32(&d, &e), FE_OK);
        ck_assert_uint_eq(fe_quadric_count(&d), 0);
        ck_assert_int_eq(fe_quadric_f32_init(&e, centre), FE_OK);
        ck_assert_mem_eq(e.ref, centre, sizeof centre);
        ck_assert_uint_eq(e.flags, FE_QUADRIC_HAS_REF);
        ck_assert_int_eq(fe_quadric_f32_add(&e, centre), FE_OK);
        ck_assert_uint_eq(e.n, 1);
        ck_assert_double_eq(e.m[0], 1.0);
        for (int k = 1; k < FE_QUADRIC_MOMENTS; k++)
            ck_assert_double_eq(e.m[k], 0.0);
    }
}
END_TEST

START_TEST(state_size)
{
    /* The figure the prose promises and make size prints for the M4. */
    ck_assert_uint_eq(sizeof(fe_quadric), 760);
    /* The float state make size measures on the M4F (limit 300). */
    ck_assert_uint_eq(sizeof(fe_quadric_f32), 188);
}
END_TEST


/* Blocks in time: `all` is the plain fold, the blocks partition the stream
   in order (every block block_len long but the last, 8 to 16 of them),
   two halves split at a multiple of the block length merge into exactly
   the fold of the whole, and a refused sample changes nothing. */
START_TEST(blocks_partition_the_stream_and_merge_in_time)
{
    enum { N = 4096 + 77 };
    static double x[3 * N];
    static fe_quadric_blocks whole, a, b, before;
    const double c[3] = {10, -20, 5}, r[3] = {30, 45, 60};
    fe_quadric plain = FE_QUADRIC_EMPTY, sum = FE_QUADRIC_EMPTY;
    double apart, total = 0.0;
    fe_test_ellipsoid_points(x, N, c, r, 0.5, 4);
    ck_assert_int_eq(fe_quadric_blocks_init(&whole), FE_OK);
    for (size_t i = 0; i < N; i++) {
        ck_assert_int_eq(fe_quadric_blocks_add(&whole, x + 3 * i), FE_OK);
        ck_assert_int_eq(fe_quadric_add(&plain, x + 3 * i), FE_OK);
        if (i + 1 >= FE_QUADRIC_BLOCKS) {
            ck_assert_uint_ge(whole.nblocks, FE_QUADRIC_BLOCKS / 2);
            ck_assert_uint_le(whole.nblocks, FE_QUADRIC_BLOCKS);
        }
    }
    ck_assert_mem_eq(&whole.all, &plain, sizeof plain);
    /* 4173 samples in blocks of 512: 8 full and one of 77. */
    ck_assert_uint_eq(whole.block_len, 512);
    ck_assert_uint_eq(whole.nblocks, 9);
    for (uint32_t k = 0; k < whole.nblocks; k++) {
        double want = k + 1 < whole.nblocks ? 512.0 : 77.0;
        ck_assert_double_eq(whole.block[k].m[0], want);
        /* Block k holds samples 512 k ..: its extremes are theirs. */
        for (int j = 0; j < 3; j++) {
            double lo = INFINITY;
            for (size_t i = 512 * k; i < 512 * k + (size_t)want; i++)
                lo = fmin(lo, x[3 * i + j]);
            ck_assert_double_eq(whole.block[k].lo[j], lo);
        }
        ck_assert_int_eq(fe_quadric_merge(&sum, &whole.block[k]), FE_OK);
        total += whole.block[k].m[0];
    }
    ck_assert_double_eq(total, N);
    ck_assert_int_eq(fe_quadric_recentre(&sum, plain.ref), FE_OK);
    ck_assert_int_eq(fe_quadric_compare(&sum, &plain, &apart), FE_OK);
    ck_assert_double_le(apart, 1e-12);
    /* Halves at 2048: blocks of 128 each, merged into blocks of 512. */
    fe_quadric_blocks_init(&a);
    fe_quadric_blocks_init(&b);
    for (size_t i = 0; i < N; i++)
        ck_assert_int_eq(fe_quadric_blocks_add(i < 2048 ? &a : &b, x + 3 * i), FE_OK);
    ck_assert_int_eq(fe_quadric_blocks_merge(&a, &b), FE_OK);
    ck_assert_uint_eq(a.nblocks, whole.nblocks);
    ck_assert_uint_eq(a.block_len, whole.block_len);
    for (uint32_t k = 0; k < a.nblocks; k++) {
        fe_quadric moved = a.block[k];
        ck_assert_double_eq(moved.m[0], whole.block[k].m[0]);
        ck_assert_int_eq(fe_quadric_recentre(&moved, whole.block[k].ref), FE_OK);
        ck_assert_int_eq(fe_quadric_compare(&moved, &whole.block[k], &apart), FE_OK);
        ck_assert_double_le(apart, 1e-12);
    }
    /* Refused samples: nothing changes. */
    before = whole;
    {
        const double bad[3] = {NAN, 1, 2}, huge[3] = {1e300, 0, 0};
        ck_assert_int_eq(fe_quadric_blocks_add(&whole, bad), FE_ENONFINITE);
        ck_assert_int_ne(fe_quadric_blocks_add(&whole, huge), FE_OK);
    }
    ck_assert_mem_eq(&before, &whole, sizeof whole);
    ck_assert_int_eq(fe_quadric_blocks_add(NULL, x), FE_EINVAL);
    ck_assert_int_eq(fe_quadric_blocks_merge(&whole, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_quadric_blocks_init(NULL), FE_EINVAL);
}
END_TEST

/* Many samples at once, in runs of any length: the blocks, counts,
   extremes and coverage of one sample at a time, the moments to 1e-12;
   a refused sample stops it with exactly the samples before folded. */
START_TEST(blocks_add_many_is_the_step_repeated)
{
    enum { N = 20000 + 77 };
    static double x[3 * N];
    static fe_quadric_blocks one, many, upto;
    const double c[3] = {10, -20, 5}, r[3] = {30, 45, 60};
    static const size_t runs[] = {1, 7, 512, 3, 1000, 4096, 13};
    double apart;
    size_t done, i = 0, k = 0;
    fe_test_ellipsoid_points(x, N, c, r, 0.5, 4);
    fe_quadric_blocks_init(&one);
    fe_quadric_blocks_init(&many);
    for (size_t j = 0; j < N; j++)
        ck_assert_int_eq(fe_quadric_blocks_add(&one, x + 3 * j), FE_OK);
    while (i < N) {
        size_t m = runs[k++ % (sizeof runs / sizeof runs[0])];
        m = m < N - i ? m : N - i;
        ck_assert_int_eq(fe_quadric_blocks_add_many(&many, x + 3 * i, m, &done), FE_OK);
        ck_assert_uint_eq(done, m);
        i += m;
    }
    ck_assert_uint_eq(many.nblocks, one.nblocks);
    ck_assert_uint_eq(many.block_len, one.block_len);
    for (uint32_t b = 0; b <= many.nblocks; b++) {
        const fe_quadric *p = b < many.nblocks ? &many.block[b] : &many.all;
        const fe_quadric *q = b < many.nblocks ? &one.block[b] : &one.all;
        ck_assert_double_eq(p->m[0], q->m[0]);
        ck_assert_mem_eq(p->lo, q->lo, sizeof p->lo);
        ck_assert_mem_eq(p->hi, q->hi, sizeof p->hi);
        ck_assert_int_eq(fe_quadric_regions(p), fe_quadric_regions(q));
        ck_assert_int_eq(fe_quadric_compare(p, q, &apart), FE_OK);
        ck_assert_double_le(apart, 1e-12);
    }
    /* A sample whose fourth power overflows, at 3000: 3000 folded. */
    x[3 * 3000] = 1e300;
    fe_quadric_blocks_init(&many);
    fe_quadric_blocks_init(&upto);
    ck_assert_int_eq(fe_quadric_blocks_add_many(&many, x, N, &done), FE_ENONFINITE);
    ck_assert_uint_eq(done, 3000);
    ck_assert_int_eq(fe_quadric_blocks_add_many(&upto, x, 3000, NULL), FE_OK);
    ck_assert_mem_eq(&many, &upto, sizeof many);
    ck_assert_int_eq(fe_quadric_blocks_add_many(NULL, x, 1, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_quadric_blocks_add_many(&many, NULL, 1, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_quadric_blocks_add_many(&many, NULL, 0, &done), FE_OK);
    ck_assert_uint_eq(done, 0);
    /* The refused sample right after one or two good ones at the start
       of a run: those are folded and counted (quadric:2069 of CI's
       sample 23844 gave back the one good sample). */
    for (size_t k = 1; k <= 2; k++) {
        double y[9];
        memcpy(y, x, 3 * k * sizeof *y);
        y[3 * k] = 1e300;
        y[3 * k + 1] = y[3 * k + 2] = 0.0;
        fe_quadric_blocks_init(&many);
        fe_quadric_blocks_init(&upto);
        ck_assert_int_eq(fe_quadric_blocks_add_many(&many, y, k + 1, &done), FE_ENONFINITE);
        ck_assert_uint_eq(done, k);
        ck_assert_int_eq(fe_quadric_blocks_add_many(&upto, y, k, NULL), FE_OK);
        ck_assert_mem_eq(&many, &upto, sizeof many);
        ck_assert_double_eq(many.all.m[0], (double)k);
    }
    /* Every block full, so that the next sample halves them first: a run
       refused at its first sample leaves the accumulation as it was,
       unhalved, to the byte. */
    fe_quadric_blocks_init(&many);
    for (size_t i = 0; many.nblocks < FE_QUADRIC_BLOCKS
                       || many.block[many.nblocks - 1].m[0] < (double)many.block_len; i++)
        ck_assert_int_eq(fe_quadric_blocks_add(&many, x + 3 * (i % 3000)), FE_OK);
    memcpy(&upto, &many, sizeof upto);
    {
        double y[6] = {NAN, 0, 0, 1, 2, 3};
        ck_assert_int_eq(fe_quadric_blocks_add_many(&many, y, 2, &done), FE_ENONFINITE);
        ck_assert_uint_eq(done, 0);
        ck_assert_mem_eq(&many, &upto, sizeof many);
    }
    /* An all-zero struct is an empty accumulation (block_len 0 read as
       1): the same blocks as an initialised one. */
    memset(&many, 0, sizeof many);
    fe_quadric_blocks_init(&upto);
    ck_assert_int_eq(fe_quadric_blocks_add_many(&many, x, 2999, NULL), FE_OK);
    ck_assert_int_eq(fe_quadric_blocks_add_many(&upto, x, 2999, NULL), FE_OK);
    ck_assert_uint_eq(many.nblocks, upto.nblocks);
    ck_assert_uint_eq(many.block_len, upto.block_len);
    for (uint32_t b = 0; b < upto.nblocks; b++)
        ck_assert_double_eq(many.block[b].m[0], upto.block[b].m[0]);
}
END_TEST

/* fe_quadric_init refuses a NULL accumulation; a blocked merge whose
   binomial shift overflows (a reference at 1e90 against one near 0) is
   refused with `a` unchanged to the byte, and the same merge of b with a
   reference near a's is accepted. */
START_TEST(blocks_merge_overflow_and_init_null)
{
    const double far[3] = {1e90, 0, 0}, near[3] = {1, 0, 0}, centre[3] = {0, 0, 0};
    fe_quadric_blocks a, b, c, before;
    ck_assert_int_eq(fe_quadric_init(NULL, centre), FE_EINVAL);
    ck_assert_int_eq(fe_quadric_blocks_init(&a), FE_OK);
    ck_assert_int_eq(fe_quadric_blocks_init(&b), FE_OK);
    ck_assert_int_eq(fe_quadric_blocks_init(&c), FE_OK);
    for (int i = 0; i < 10; i++) {
        const double x[3] = {1.0 + 0.1 * i, 0.5, -0.25 * i};
        ck_assert_int_eq(fe_quadric_blocks_add(&a, x), FE_OK);
    }
    ck_assert_int_eq(fe_quadric_blocks_add(&b, far), FE_OK);
    ck_assert_int_eq(fe_quadric_blocks_add(&c, near), FE_OK);
    before = a;
    ck_assert_int_eq(fe_quadric_blocks_merge(&a, &b), FE_ENONFINITE);
    ck_assert_mem_eq(&a, &before, sizeof a);
    ck_assert_int_eq(fe_quadric_blocks_merge(NULL, &b), FE_EINVAL);
    ck_assert_int_eq(fe_quadric_blocks_merge(&a, &c), FE_OK);
    ck_assert(a.all.m[0] == 11.0);
}
END_TEST

Suite *fe_quadric_suite(void)
{
    Suite *s = suite_create("quadric");
    TCase *t = tcase_create("moments");
    tcase_set_timeout(t, 60);
    tcase_add_test(t, index_and_exponents_are_inverse);
    tcase_add_test(t, empty_and_one_sample);
    tcase_add_test(t, step_equals_block);
    tcase_add_test(t, step_equals_block_when_the_box_grows);
    tcase_add_test(t, two_shards_equal_one);
    tcase_add_test(t, blocks_partition_the_stream_and_merge_in_time);
    tcase_add_test(t, merge_every_split_and_associativity);
    tcase_add_test(t, merged_hemispheres_cover_the_sphere);
    tcase_add_test(t, recentre_equals_accumulating_there);
    tcase_add_test(t, bad_samples_leave_it_unchanged);
    tcase_add_test(t, regions_have_equal_area);
    tcase_add_test(t, coverage_ignores_an_initial_rest_and_sees_a_hemisphere);
    tcase_add_test(t, block_extremes_in_the_tail_of_a_block);
    tcase_add_test(t, block_coverage_of_a_hemisphere_inside_the_box);
    tcase_add_test(t, coverage_counts_a_region_seen_at_exactly_half_the_size);
    tcase_add_test(t, coverage_does_not_depend_on_the_first_moment);
    tcase_add_test(t, compare_a_box_of_one_point_absolutely);
    tcase_add_test(t, compare_is_the_largest_scaled_difference);
    tcase_add_test(t, state_size);
    tcase_add_test(t, blocks_add_many_is_the_step_repeated);
    tcase_add_test(t, f32_step_agrees_with_the_double_step);
    tcase_add_test(t, f32_recentre_is_exact);
    tcase_add_test(t, f32_bad_samples_leave_it_unchanged);
    tcase_add_test(t, blocks_merge_overflow_and_init_null);
    suite_add_tcase(s, t);
    return s;
}
