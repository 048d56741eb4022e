/* SPDX-License-Identifier: MIT */
/* The fold core: fold, scan, merge, copy and the product of accumulators,
   with a toy accumulator whose behaviour the tests control. */
#include "foldest.h"
#include "testutil.h"

/* A counting accumulator that refuses negative observations. */
typedef struct { long count; double sum; } toy_acc;

static int toy_step(void *acc, const void *obs, void *ctx)
{
    toy_acc *a = acc;
    double z = *(const double *)obs;
    (void)ctx;
    if (z < 0)
        return FE_EINVAL;
    a->count++;
    a->sum += z;
    return FE_OK;
}

static int toy_merge(void *acc, const void *other, void *ctx)
{
    toy_acc *a = acc;
    const toy_acc *b = other;
    (void)ctx;
    a->count += b->count;
    a->sum += b->sum;
    return FE_OK;
}

static fe_accumulator toy(void)
{
    fe_accumulator f = {0};
    f.name = "toy";
    f.acc_size = sizeof(toy_acc);
    f.obs_size = sizeof(double);
    f.step = toy_step;
    f.merge = toy_merge;
    return f;
}

START_TEST(fold_stops_at_refusal)
{
    const double z[5] = {1, 2, -3, 4, 5};
    fe_accumulator f = toy();
    toy_acc a;
    size_t done = 99;
    ck_assert_int_eq(fe_init(&f, &a), FE_OK);
    ck_assert_int_eq(a.count, 0);
    ck_assert_int_eq(fe_fold(&f, &a, z, 5, &done), FE_EINVAL);
    ck_assert_uint_eq(done, 2);
    ck_assert_int_eq(a.count, 2);
    ck_assert_double_eq(a.sum, 3.0);
    ck_assert_int_eq(fe_fold(&f, &a, z + 3, 2, &done), FE_OK);
    ck_assert_int_eq(a.count, 4);
}
END_TEST

START_TEST(argument_errors)
{
    const double z[1] = {1};
    fe_accumulator f = toy(), broken = toy();
    toy_acc a = {0, 0};
    broken.step = NULL;
    ck_assert_int_eq(fe_fold(NULL, &a, z, 1, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_fold(&f, NULL, z, 1, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_fold(&f, &a, NULL, 1, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_fold(&f, &a, NULL, 0, NULL), FE_OK);
    ck_assert_int_eq(fe_fold(&broken, &a, z, 1, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_step(&f, &a, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_init(&f, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_scan(&f, &a, z, 1, NULL, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_scan_visit(&f, &a, z, 1, NULL, NULL, NULL), FE_EINVAL);
    ck_assert_int_eq(a.count, 0);
    /* A merge and a copy refuse each bad argument alone, the accumulation
       untouched: no accumulator, one without a step, no accumulation, no
       other. */
    {
        toy_acc b = {3, 4.0}, c = {5, 6.0};
        ck_assert_int_eq(fe_merge(NULL, &a, &b), FE_EINVAL);
        ck_assert_int_eq(fe_merge(&broken, &a, &b), FE_EINVAL);
        ck_assert_int_eq(fe_merge(&f, NULL, &b), FE_EINVAL);
        ck_assert_int_eq(fe_merge(&f, &a, NULL), FE_EINVAL);
        ck_assert(a.count == 0 && a.sum == 0.0);
        ck_assert_int_eq(fe_copy(NULL, &c, &b), FE_EINVAL);
        ck_assert_int_eq(fe_copy(&broken, &c, &b), FE_EINVAL);
        ck_assert_int_eq(fe_copy(&f, NULL, &b), FE_EINVAL);
        ck_assert_int_eq(fe_copy(&f, &c, NULL), FE_EINVAL);
        ck_assert(c.count == 5 && c.sum == 6.0);
        ck_assert_int_eq(fe_merge(&f, &c, &b), FE_OK);
        ck_assert(c.count == 8 && c.sum == 10.0);
    }
    /* A refused fold reports that it folded nothing, whatever *done held. */
    {
        size_t done = 99;
        ck_assert_int_eq(fe_fold(NULL, &a, z, 1, &done), FE_EINVAL);
        ck_assert_uint_eq(done, 0);
        done = 99;
        ck_assert_int_eq(fe_fold(&f, &a, NULL, 1, &done), FE_EINVAL);
        ck_assert_uint_eq(done, 0);
    }
}
END_TEST

START_TEST(merge_unsupported_and_copy)
{
    fe_accumulator f = toy();
    toy_acc a = {1, 2}, b = {3, 4}, c;
    f.merge = NULL;
    ck_assert_int_eq(fe_merge(&f, &a, &b), FE_ENOTSUP);
    ck_assert_int_eq(a.count, 1);
    ck_assert_int_eq(fe_copy(&f, &c, &b), FE_OK);
    ck_assert_int_eq(c.count, 3);
    ck_assert_double_eq(c.sum, 4.0);
}
END_TEST

static int stop_at_two(const void *acc, size_t index, void *ctx)
{
    size_t *seen = ctx;
    (void)acc;
    *seen = index;
    return index == 2 ? FE_ESTOPPED : FE_OK;
}

START_TEST(scan_visit_can_stop)
{
    const double z[4] = {1, 1, 1, 1};
    fe_accumulator f = toy();
    toy_acc a = {0, 0};
    size_t seen = 0, done = 0;
    ck_assert_int_eq(fe_scan_visit(&f, &a, z, 4, stop_at_two, &seen, &done), FE_ESTOPPED);
    ck_assert_uint_eq(seen, 2);
    ck_assert_uint_eq(done, 2);
    ck_assert_int_eq(a.count, 2);
}
END_TEST

START_TEST(scan_writes_every_accumulation)
{
    const double z[3] = {1, 2, -1};
    fe_accumulator f = toy();
    toy_acc a = {0, 0}, out[4];
    size_t done = 0;
    memset(out, 0xff, sizeof out);
    ck_assert_int_eq(fe_scan(&f, &a, z, 3, out, &done), FE_EINVAL);
    ck_assert_uint_eq(done, 2);
    ck_assert_int_eq(out[0].count, 0);
    ck_assert_int_eq(out[1].count, 1);
    ck_assert_double_eq(out[2].sum, 3.0);
}
END_TEST

/* The product: mean/variance of field `x`, a toy over field `y`. */
typedef struct { double x, y; } pair;

START_TEST(product_runs_side_by_side)
{
    const pair z[4] = {{1, 10}, {2, 20}, {3, 30}, {4, 40}};
    fe_accumulator mv = fe_meanvar_accumulator(), t = toy(), prod;
    const fe_product_part parts[2] = {{&mv, offsetof(pair, x)}, {&t, offsetof(pair, y)}};
    const fe_product spec = {parts, 2};
    fe_meanvar m, m_spare;
    toy_acc ta, ta_spare;
    void *accs[2] = {&m, &ta}, *spare[2] = {&m_spare, &ta_spare};
    fe_product_acc a = {accs, spare};
    ck_assert_int_eq(fe_product_accumulator(&prod, &spec, sizeof(pair)), FE_OK);
    ck_assert(prod.merge != NULL);
    ck_assert_int_eq(fe_init(&prod, &a), FE_OK);
    ck_assert_int_eq(fe_fold(&prod, &a, z, 4, NULL), FE_OK);
    ck_assert_double_eq(fe_meanvar_mean(&m), 2.5);
    ck_assert_int_eq(ta.count, 4);
    ck_assert_double_eq(ta.sum, 100.0);
}
END_TEST

START_TEST(product_rolls_back_a_partial_step)
{
    /* The second component refuses y < 0 after the first accepted x:
       the first must be restored. */
    const pair good = {1, 1}, bad = {5, -1};
    fe_accumulator mv = fe_meanvar_accumulator(), t = toy(), prod;
    const fe_product_part parts[2] = {{&mv, offsetof(pair, x)}, {&t, offsetof(pair, y)}};
    const fe_product spec = {parts, 2};
    fe_meanvar m, m_spare, m_before;
    toy_acc ta, ta_spare, ta_before;
    void *accs[2] = {&m, &ta}, *spare[2] = {&m_spare, &ta_spare};
    fe_product_acc a = {accs, spare};
    ck_assert_int_eq(fe_product_accumulator(&prod, &spec, sizeof(pair)), FE_OK);
    ck_assert_int_eq(fe_init(&prod, &a), FE_OK);
    ck_assert_int_eq(fe_step(&prod, &a, &good), FE_OK);
    m_before = m;
    ta_before = ta;
    ck_assert_int_eq(fe_step(&prod, &a, &bad), FE_EINVAL);
    ck_assert_mem_eq(&m, &m_before, sizeof m);
    ck_assert_mem_eq(&ta, &ta_before, sizeof ta);
}
END_TEST

START_TEST(product_merges_component_wise)
{
    const pair z[6] = {{1, 1}, {2, 2}, {3, 3}, {4, 4}, {5, 5}, {6, 6}};
    fe_accumulator mv = fe_meanvar_accumulator(), t = toy(), prod;
    const fe_product_part parts[2] = {{&mv, 0}, {&t, sizeof(double)}};
    const fe_product spec = {parts, 2};
    fe_meanvar m1, s1, m2, s2, mw, sw;
    toy_acc t1, u1, t2, u2, tw, uw;
    void *a1[2] = {&m1, &t1}, *b1[2] = {&s1, &u1};
    void *a2[2] = {&m2, &t2}, *b2[2] = {&s2, &u2};
    void *aw[2] = {&mw, &tw}, *bw[2] = {&sw, &uw};
    fe_product_acc p1 = {a1, b1}, p2 = {a2, b2}, pw = {aw, bw};
    ck_assert_int_eq(fe_product_accumulator(&prod, &spec, sizeof(pair)), FE_OK);
    fe_init(&prod, &p1);
    fe_init(&prod, &p2);
    fe_init(&prod, &pw);
    ck_assert_int_eq(fe_fold(&prod, &p1, z, 2, NULL), FE_OK);
    ck_assert_int_eq(fe_fold(&prod, &p2, z + 2, 4, NULL), FE_OK);
    ck_assert_int_eq(fe_fold(&prod, &pw, z, 6, NULL), FE_OK);
    ck_assert_int_eq(fe_merge(&prod, &p1, &p2), FE_OK);
    FE_ASSERT_REL(m1.mean, mw.mean, 1e-15);
    FE_ASSERT_REL(m1.m2, mw.m2, 1e-14);
    ck_assert_int_eq(t1.count, tw.count);
    ck_assert_double_eq(t1.sum, tw.sum);
    /* A copy of the product copies every part, the last one too. */
    ck_assert_int_eq(fe_init(&prod, &p2), FE_OK);
    ck_assert_int_eq(fe_copy(&prod, &p2, &pw), FE_OK);
    ck_assert_mem_eq(&m2, &mw, sizeof m2);
    ck_assert_int_eq(t2.count, tw.count);
    ck_assert_double_eq(t2.sum, tw.sum);
    /* A component that cannot merge makes the product not merge. */
    {
        fe_accumulator nomerge = toy(), p;
        const fe_product_part q[1] = {{&nomerge, 0}};
        const fe_product sq = {q, 1};
        nomerge.merge = NULL;
        ck_assert_int_eq(fe_product_accumulator(&p, &sq, sizeof(double)), FE_OK);
        ck_assert(p.merge == NULL);
    }
}
END_TEST

/* A toy whose copy fails from an accumulation with a negative count (a
   component that cannot copy, for the product's rollback). */
static int toy_copy_or_fail(void *dst, const void *src, void *ctx)
{
    const toy_acc *b = src;
    (void)ctx;
    if (b->count < 0)
        return FE_ENOTSUP;
    *(toy_acc *)dst = *b;
    return FE_OK;
}

START_TEST(product_merge_rolls_back_when_a_copy_fails)
{
    /* Part 0 merges, part 1's copy to its spare fails: the product's
       merge is refused, part 0 is restored and part 1 untouched. */
    fe_accumulator t0 = toy(), t1 = toy(), prod;
    const fe_product_part parts[2] = {{&t0, 0}, {&t1, sizeof(double)}};
    const fe_product spec = {parts, 2};
    toy_acc a0 = {2, 3.0}, a1 = {-1, 7.0}, s0 = {0, 0}, s1 = {5, 5.0};
    toy_acc b0 = {4, 10.0}, b1 = {1, 1.0}, c0 = {0, 0}, c1 = {0, 0};
    void *aa[2] = {&a0, &a1}, *as[2] = {&s0, &s1}, *ba[2] = {&b0, &b1}, *bs[2] = {&c0, &c1};
    fe_product_acc pa = {aa, as}, pb = {ba, bs};
    t1.copy = toy_copy_or_fail;
    ck_assert_int_eq(fe_product_accumulator(&prod, &spec, 2 * sizeof(double)), FE_OK);
    ck_assert_int_eq(fe_merge(&prod, &pa, &pb), FE_ENOTSUP);
    ck_assert_int_eq(a0.count, 2);
    ck_assert_double_eq(a0.sum, 3.0);
    ck_assert_int_eq(a1.count, -1);
    ck_assert_double_eq(a1.sum, 7.0);
}
END_TEST

/* A product's copy refuses with the status of the first part whose copy
   refuses, and copies no part after it: part 0's copy refuses an
   accumulation with a negative count, so the product's copy returns
   FE_ENOTSUP with both destinations as they were to the byte; with that
   count set right, the same copy copies both parts (issue 20: seed
   9303's fold:174, a part's refusal to copy ignored). */
START_TEST(product_copy_refuses_with_the_first_part_that_refuses)
{
    fe_accumulator t0 = toy(), t1 = toy(), prod;
    const fe_product_part parts[2] = {{&t0, 0}, {&t1, sizeof(double)}};
    const fe_product spec = {parts, 2};
    toy_acc s0 = {-1, 7.0}, s1 = {3, 6.0}, d0 = {9, 9.0}, d1 = {8, 8.0};
    toy_acc x0 = {0, 0}, x1 = {0, 0}, y0 = {0, 0}, y1 = {0, 0};
    const toy_acc d0_was = d0, d1_was = d1, s0_was = s0, s1_was = s1;
    void *sa[2] = {&s0, &s1}, *sx[2] = {&x0, &x1}, *da[2] = {&d0, &d1}, *dx[2] = {&y0, &y1};
    fe_product_acc ps = {sa, sx}, pd = {da, dx};
    t0.copy = toy_copy_or_fail;
    ck_assert_int_eq(fe_product_accumulator(&prod, &spec, 2 * sizeof(double)), FE_OK);
    ck_assert_int_eq(fe_copy(&prod, &pd, &ps), FE_ENOTSUP);
    ck_assert_mem_eq(&d0, &d0_was, sizeof d0);
    ck_assert_mem_eq(&d1, &d1_was, sizeof d1);
    ck_assert_mem_eq(&s0, &s0_was, sizeof s0);
    ck_assert_mem_eq(&s1, &s1_was, sizeof s1);
    s0.count = 2;
    ck_assert_int_eq(fe_copy(&prod, &pd, &ps), FE_OK);
    ck_assert_int_eq(d0.count, 2);
    ck_assert_double_eq(d0.sum, 7.0);
    ck_assert_int_eq(d1.count, 3);
    ck_assert_double_eq(d1.sum, 6.0);
}
END_TEST

START_TEST(product_rejects_bad_layout)
{
    fe_accumulator mv = fe_meanvar_accumulator(), prod;
    const fe_product_part parts[1] = {{&mv, 4}};
    const fe_product spec = {parts, 1};
    /* A double at offset 4 does not fit in 8 bytes, nor in 11 (the edge,
       issue 20): it needs 12. */
    ck_assert_int_eq(fe_product_accumulator(&prod, &spec, 8), FE_EINVAL);
    ck_assert_int_eq(fe_product_accumulator(&prod, &spec, 11), FE_EINVAL);
    ck_assert_int_eq(fe_product_accumulator(&prod, &spec, 12), FE_OK);
    ck_assert_uint_eq(prod.obs_size, 12);
    ck_assert_int_eq(fe_product_accumulator(NULL, &spec, 12), FE_EINVAL);
    /* Each argument refused alone: a NULL spec, an observation of no
       bytes, parts missing for a non-zero count. */
    ck_assert_int_eq(fe_product_accumulator(&prod, NULL, 12), FE_EINVAL);
    ck_assert_int_eq(fe_product_accumulator(&prod, &spec, 0), FE_EINVAL);
    {
        const fe_product none = {NULL, 1}, empty = {NULL, 0};
        ck_assert_int_eq(fe_product_accumulator(&prod, &none, 12), FE_EINVAL);
        ck_assert_int_eq(fe_product_accumulator(&prod, &empty, 12), FE_OK);
    }
    /* A part starting past the observation (whose size would then wrap),
       and parts that cannot fold, each at a place that fits. */
    {
        fe_accumulator nostep = mv, nosize = mv, noobs = mv;
        const fe_product_part past[1] = {{&mv, 13}}, nullacc[1] = {{NULL, 0}};
        const fe_product_part bad[3][1] = {{{&nostep, 0}}, {{&nosize, 0}}, {{&noobs, 0}}};
        const fe_product sp = {past, 1}, sn = {nullacc, 1};
        nostep.step = NULL;
        nosize.acc_size = 0;
        noobs.obs_size = 0;
        ck_assert_int_eq(fe_product_accumulator(&prod, &sp, 12), FE_EINVAL);
        ck_assert_int_eq(fe_product_accumulator(&prod, &sn, 12), FE_EINVAL);
        for (int i = 0; i < 3; i++) {
            const fe_product sb = {bad[i], 1};
            ck_assert_int_eq(fe_product_accumulator(&prod, &sb, 12), FE_EINVAL);
        }
    }
    /* Every part is checked, not only the first: the second one ending
       exactly at the end of the observation fits, one byte further not. */
    {
        fe_accumulator t = toy(), nomerge = toy();
        const fe_product_part two[2] = {{&mv, 0}, {&t, 8}};
        const fe_product s2 = {two, 2};
        const fe_product_part late[2] = {{&t, 0}, {&nomerge, 8}};
        const fe_product s3 = {late, 2};
        ck_assert_int_eq(fe_product_accumulator(&prod, &s2, 16), FE_OK);
        ck_assert(prod.merge != NULL);
        ck_assert_int_eq(fe_product_accumulator(&prod, &s2, 15), FE_EINVAL);
        nomerge.merge = NULL;
        ck_assert_int_eq(fe_product_accumulator(&prod, &s3, 16), FE_OK);
        ck_assert(prod.merge == NULL);
    }
}
END_TEST

Suite *fe_fold_suite(void)
{
    Suite *s = suite_create("fold");
    TCase *t = tcase_create("core");
    tcase_add_test(t, fold_stops_at_refusal);
    tcase_add_test(t, argument_errors);
    tcase_add_test(t, merge_unsupported_and_copy);
    tcase_add_test(t, scan_visit_can_stop);
    tcase_add_test(t, scan_writes_every_accumulation);
    tcase_add_test(t, product_runs_side_by_side);
    tcase_add_test(t, product_rolls_back_a_partial_step);
    tcase_add_test(t, product_merges_component_wise);
    tcase_add_test(t, product_merge_rolls_back_when_a_copy_fails);
    tcase_add_test(t, product_copy_refuses_with_the_first_part_that_refuses);
    tcase_add_test(t, product_rejects_bad_layout);
    suite_add_tcase(s, t);
    return s;
}
