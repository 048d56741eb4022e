/* SPDX-License-Identifier: MIT */
/* Locating a mismatch from a Kalman filter's innovations: a tracker whose
   constant-velocity model misses a drag switched on for one stretch of the
   run locates that stretch; with the right model nothing is located. */
#include <stdint.h>

#include "foldest.h"
#include "testutil.h"

enum { STEPS = 4000, BLOCKS = 20, ON = 1700, OFF = 2300 };

static const double dt = 0.1;

/* Track a cart moving at about 10 m/s with a position sensor (1 m noise)
   and a random acceleration (sa) the filter knows of; between steps ON and
   OFF the world adds a drag a = -c v|v| that the filter's model lacks.
   Folds the reports into `inn`. */
static void run_tracker(uint64_t seed, double c, fe_innovations *inn)
{
    const double sa = 0.05, sz = 1.0;
    const double Phi[4] = {1, dt, 0, 1};
    const double G[2] = {dt * dt / 2, dt};
    const double A[2] = {1, 0};
    const double Z[1] = {sz * sz};
    const double x0[2] = {0.0, 10.0}, P0[4] = {4.0, 0, 0, 1.0};
    double Xi[4], truth[2], mem[64], w, z;
    fe_kalman k;
    fe_rng rng = fe_rng_seed(seed);
    int rc = FE_OK;
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++)
            Xi[i * 2 + j] = sa * sa * G[i] * G[j];
    /* The truth starts where the prior says it may (within its spread). */
    truth[0] = x0[0] + 2.0 * fe_rng_normal(&rng);
    truth[1] = x0[1] + 1.0 * fe_rng_normal(&rng);
    ck_assert_int_eq(fe_kalman_init(&k, 2, 1, mem, sizeof mem / sizeof mem[0]), FE_OK);
    ck_assert_int_eq(fe_kalman_set_prior(&k, x0, P0), FE_OK);
    ck_assert_int_eq(fe_innovations_init(inn, BLOCKS, STEPS, 0), FE_OK);
    for (int s = 0; s < STEPS; s++) {
        fe_kalman_report rep = {0, 0, 0, NULL, &w, NULL};
        fe_kalman_track_obs o = {{Phi, NULL, NULL, 0, Xi}, {1, A, &z, Z}};
        double a = sa * fe_rng_normal(&rng);
        if (s >= ON && s < OFF)
            a -= c * truth[1] * fabs(truth[1]);
        truth[0] += dt * truth[1] + G[0] * a;
        truth[1] += G[1] * a;
        z = truth[0] + sz * fe_rng_normal(&rng);
        rc |= fe_kalman_track_fast(&k, &o, &rep);
        rc |= fe_innovations_add(inn, (s + 1) * dt, &rep);
    }
    ck_assert_int_eq(rc, FE_OK);
}

/* At most this many of `runs` runs, each with a chance of at most p,
   exceed it: p runs plus three binomial standard deviations. */
static double at_most(unsigned runs, double p)
{
    return p * runs + 3.0 * sqrt(runs * p * (1.0 - p));
}

START_TEST(a_missed_drag_is_located_where_it_acts)
{
    /* The drag acts from t_on to t_off.  In (nearly) every run one window
       covers it, up to a block at either end (a block half in the drag may
       or may not stand out); a window reaching further than a block beyond
       it is a chance finding, as rare as the level says. */
    const double t_on = (ON + 1) * dt, t_off = OFF * dt, blen = STEPS / BLOCKS * dt;
    unsigned runs = fe_test_quick() ? 4 : 50, covered = 0, beyond = 0;
    for (uint64_t seed = 1; seed <= runs; seed++) {
        fe_innovations inn;
        fe_located loc[8];
        size_t n;
        int cover = 0, out = 0;
        run_tracker(seed, 0.0005, &inn);
        ck_assert_int_eq(fe_innovations_locate(&inn, 0.05, loc, 8, &n), FE_OK);
        for (size_t i = 0; i < n && i < 8; i++) {
            ck_assert(loc[i].is_time);
            if (loc[i].t0 <= t_on + blen && loc[i].t1 >= t_off - blen) {
                cover = 1;
                ck_assert(loc[i].mean_nis > 1.0 && loc[i].lag1 > 0.0);
                ck_assert(loc[i].p_value < 0.05 / (2.0 * BLOCKS));
            }
            out |= loc[i].t0 < t_on - blen || loc[i].t1 > t_off + blen;
        }
        covered += cover;
        beyond += out;
    }
    fprintf(stderr, "locate: drag covered in %u/%u runs, windows beyond it in %u\n", covered,
            runs, beyond);
    ck_assert_msg(covered >= 0.9 * runs, "covered %u/%u", covered, runs);
    ck_assert_msg(beyond <= at_most(runs, 0.05), "beyond %u/%u", beyond, runs);
}
END_TEST

START_TEST(a_right_model_locates_nothing)
{
    /* Family-wise level 0.05: a run locates anything with a chance of at
       most 0.05 (the tests without Bonferroni's correction would locate
       something in most runs). */
    unsigned runs = fe_test_quick() ? 10 : 200, located = 0;
    for (uint64_t seed = 1; seed <= runs; seed++) {
        fe_innovations inn;
        fe_located loc[8];
        size_t n;
        run_tracker(1000 + seed, 0.0, &inn);
        ck_assert_int_eq(fe_innovations_locate(&inn, 0.05, loc, 8, &n), FE_OK);
        located += n > 0;
    }
    fprintf(stderr, "locate: right model, something located in %u/%u runs\n", located, runs);
    ck_assert_msg(located <= at_most(runs, 0.05), "located something in %u/%u runs", located,
                  runs);
}
END_TEST

START_TEST(block_statistics_match_a_direct_computation)
{
    /* The per-block sums are those of the reports, pairs do not cross a
       break, and the JSON record carries the command's keys. */
    fe_innovations inn;
    fe_rng rng = fe_rng_seed(4);
    double nis0 = 0, acf1 = 0, prev = 0, w;
    fe_located l;
    size_t n;
    char json[1024];
    ck_assert_int_eq(fe_innovations_init(&inn, 4, 40, 0), FE_OK);
    for (int i = 0; i < 40; i++) {
        fe_kalman_report r = {1, 0, 0, NULL, &w, NULL};
        w = fe_rng_normal(&rng);
        r.nis = w * w;
        if (i == 15)
            fe_innovations_break(&inn);
        ck_assert_int_eq(fe_innovations_add(&inn, i, &r), FE_OK);
        if (i < 10)
            nis0 += w * w;
        if (i >= 10 && i < 20 && i != 10 + 5)
            acf1 += w * prev;
        prev = w;
    }
    FE_ASSERT_REL(inn.block[0].nis, nis0, 1e-12);
    FE_ASSERT_REL(inn.block[1].acf, acf1, 1e-12);
    ck_assert_double_eq(inn.block[1].acf_terms, 9);    /* the pair across the break is not formed */
    ck_assert_int_eq(inn.block[1].pair, 0);
    ck_assert_int_eq(inn.block[1].pair1, 1);
    {
        fe_kalman_report r = {1, 1.0, 0, NULL, NULL, NULL};
        ck_assert_int_eq(fe_innovations_add(&inn, 41, &r), FE_ESIZE);
    }
    ck_assert_int_eq(fe_innovations_locate(&inn, 0.05, NULL, 0, &n), FE_OK);
    ck_assert_int_eq(fe_innovations_locate(&inn, 0.0, NULL, 0, &n), FE_EINVAL);
    memset(&l, 0, sizeof l);
    l.is_time = 1;
    l.test = "nis";
    l.t0 = 1.5;
    l.t1 = 2.5;
    l.n = 10;
    l.z = 5.0;
    l.t = INFINITY;
    ck_assert_int_eq(fe_located_json(&l, json, sizeof json), FE_OK);
    ck_assert_ptr_nonnull(strstr(json, "\"kind\": \"time\""));
    ck_assert_ptr_nonnull(strstr(json, "\"start\": 1.5"));
    ck_assert_ptr_nonnull(strstr(json, "\"test\": \"nis\""));
    ck_assert_ptr_nonnull(strstr(json, "\"acf_statistic\": null"));
    ck_assert_int_eq(fe_located_json(&l, json, 20), FE_ESIZE);
    /* Every figure of the record under its key, in %.10g. */
    l.p_value = 0.001;
    l.mean_nis = 1.25;
    l.lag1 = -0.5;
    ck_assert_int_eq(fe_located_json(&l, json, sizeof json), FE_OK);
    ck_assert_ptr_nonnull(strstr(json, "\"p_value\": 0.001"));
    ck_assert_ptr_nonnull(strstr(json, "\"nis_statistic\": 5"));
    ck_assert_ptr_nonnull(strstr(json, "\"mean_nis_per_dof\": 1.25"));
    ck_assert_ptr_nonnull(strstr(json, "\"lag1\": -0.5"));
    ck_assert_ptr_nonnull(strstr(json, "\"end\": 2.5"));
}
END_TEST

START_TEST(blocks_without_pairs_have_no_autocorrelation_test)
{
    /* A break before every report: no lag-one pair anywhere, so the
       autocorrelation test has nothing to say (p = 1) and the NIS of one
       per report (p = 0.44 for 10 on 10 degrees of freedom) locates
       nothing; the same reports with their pairs neither. */
    fe_innovations inn;
    size_t n = 9;
    double w = 1.0;
    for (int pairs = 0; pairs < 2; pairs++) {
        ck_assert_int_eq(fe_innovations_init(&inn, 4, 40, 0), FE_OK);
        for (int i = 0; i < 40; i++) {
            fe_kalman_report r = {1, 1.0, 0, NULL, &w, NULL};
            if (!pairs)
                fe_innovations_break(&inn);
            w = i % 2 ? 1.0 : -1.0;     /* alternating: lag one -1 when paired */
            ck_assert_int_eq(fe_innovations_add(&inn, i, &r), FE_OK);
        }
        for (int b = 0; b < 4; b++)
            ck_assert_double_eq(inn.block[b].acf_terms, pairs ? (b == 0 ? 9 : 10) : 0);
        ck_assert_int_eq(fe_innovations_locate(&inn, 0.05, NULL, 0, &n), FE_OK);
        if (!pairs)
            ck_assert_uint_eq(n, 0);
        else    /* rho = -1 over 9 or 10 pairs: z = -3 or -3.16, p < 0.05/8 */
            ck_assert_uint_ge(n, 1);
    }
}
END_TEST

START_TEST(merge_of_consecutive_parts_equals_whole)
{
    /* Reports of two dimensions (whitened vectors sometimes missing) with
       recording breaks, folded whole and in three parts cut at awkward
       places (one cut right at a break), merged: the same blocks. */
    enum { N = 997, K = 7 };
    const size_t cut1 = 200, cut2 = 613;
    fe_innovations whole, p[3];
    fe_rng rng = fe_rng_seed(21);
    int rc = FE_OK;
    ck_assert_int_eq(fe_innovations_init(&whole, K, N, 0), FE_OK);
    ck_assert_int_eq(fe_innovations_init(&p[0], K, N, 0), FE_OK);
    ck_assert_int_eq(fe_innovations_init(&p[1], K, N, cut1), FE_OK);
    ck_assert_int_eq(fe_innovations_init(&p[2], K, N, cut2), FE_OK);
    for (size_t i = 0; i < N; i++) {
        double w[2] = {fe_rng_normal(&rng), fe_rng_normal(&rng)};
        fe_kalman_report r = {2, w[0] * w[0] + w[1] * w[1], 0, NULL, i % 37 ? w : NULL, NULL};
        fe_innovations *part = &p[i < cut1 ? 0 : i < cut2 ? 1 : 2];
        if (i == 150 || i == cut2 || i == 800) {
            fe_innovations_break(&whole);
            fe_innovations_break(part);
        }
        rc |= fe_innovations_add(&whole, 0.5 * (double)i, &r);
        rc |= fe_innovations_add(part, 0.5 * (double)i, &r);
    }
    ck_assert_int_eq(rc, FE_OK);
    ck_assert_int_eq(fe_innovations_merge(&p[0], &p[2]), FE_EMISMATCH);
    ck_assert_int_eq(fe_innovations_merge(&p[1], &p[2]), FE_OK);
    ck_assert_int_eq(fe_innovations_merge(&p[0], &p[1]), FE_OK);
    ck_assert_uint_eq(p[0].n, N);
    ck_assert_int_eq(p[0].recording, whole.recording);
    ck_assert_int_eq(whole.recording, 3);
    for (size_t k = 0; k < K; k++) {
        const fe_innovation_block *x = &p[0].block[k], *y = &whole.block[k];
        ck_assert_double_eq(x->n, y->n);
        ck_assert_double_eq(x->acf_terms, y->acf_terms);
        ck_assert_double_eq(x->sq_terms, y->sq_terms);
        ck_assert_double_eq(x->t0, y->t0);
        ck_assert_double_eq(x->t1, y->t1);
        ck_assert_int_eq(x->pair, y->pair);
        ck_assert_int_eq(x->pair1, y->pair1);
        FE_ASSERT_REL(x->nis, y->nis, 1e-12);
        FE_ASSERT_REL(x->sq, y->sq, 1e-12);
        ck_assert_double_eq_tol(x->acf, y->acf, 1e-12 * y->sq);
    }
}
END_TEST

START_TEST(merge_into_an_empty_part_is_the_other_part)
{
    /* An empty first part (nothing folded) merged with a part that starts
       with a recording break: the same recordings and blocks as the part. */
    enum { N = 40, K = 4 };
    fe_innovations a, b;
    fe_rng rng = fe_rng_seed(5);
    ck_assert_int_eq(fe_innovations_init(&a, K, N, 0), FE_OK);
    ck_assert_int_eq(fe_innovations_init(&b, K, N, 0), FE_OK);
    for (size_t i = 0; i < N; i++) {
        double w = fe_rng_normal(&rng);
        fe_kalman_report r = {1, w * w, 0, NULL, &w, NULL};
        if (i == 0 || i == 25)
            fe_innovations_break(&b);
        ck_assert_int_eq(fe_innovations_add(&b, (double)i, &r), FE_OK);
    }
    ck_assert_int_eq(fe_innovations_merge(&a, &b), FE_OK);
    ck_assert_uint_eq(a.n, b.n);
    ck_assert_int_eq(a.recording, b.recording);
    for (size_t k = 0; k < K; k++) {
        ck_assert_int_eq(a.block[k].pair, b.block[k].pair);
        ck_assert_int_eq(a.block[k].pair1, b.block[k].pair1);
        ck_assert_double_eq(a.block[k].nis, b.block[k].nis);
    }
}
END_TEST

START_TEST(json_of_every_length_is_whole_or_refused)
{
    /* Every buffer shorter than the document is refused with FE_ESIZE and
       nothing written past it; the exact length (with its NUL) is enough. */
    fe_located l = {0};
    char full[1024], buf[1024 + 8];
    size_t need;
    l.pair = 0;
    l.pair1 = 1;
    l.t0 = 1.5;
    l.t1 = 2.5;
    l.n = 10;
    l.z = 3.25;
    l.t = -1.5;
    l.test = "nis";
    l.p_value = 0.001;
    l.mean_nis = 2.0;
    l.lag1 = 0.25;
    ck_assert_int_eq(fe_located_json(&l, full, sizeof full), FE_OK);
    need = strlen(full) + 1;
    for (size_t len = 1; len <= need; len++) {
        memset(buf, 'X', sizeof buf);
        ck_assert_int_eq(fe_located_json(&l, buf, len), len < need ? FE_ESIZE : FE_OK);
        for (size_t i = len; i < sizeof buf; i++)
            ck_assert_int_eq(buf[i], 'X');
    }
    ck_assert_str_eq(buf, full);
}
END_TEST

START_TEST(refusals_leave_the_accumulation_unchanged)
{
    fe_innovations inn, before;
    double w = 1.0, bad = NAN;
    fe_kalman_report r = {1, 1.0, 0, NULL, &w, NULL};
    ck_assert_int_eq(fe_innovations_init(&inn, 1, 100, 0), FE_ESIZE);
    ck_assert_int_eq(fe_innovations_init(&inn, 10, 19, 0), FE_ETOOFEW);
    ck_assert_int_eq(fe_innovations_init(&inn, 10, 100, 100), FE_ESIZE);
    ck_assert_int_eq(fe_innovations_init(&inn, 10, 100, 0), FE_OK);
    ck_assert_int_eq(fe_innovations_add(&inn, 0.0, &r), FE_OK);
    memcpy(&before, &inn, sizeof inn);
    r.whitened = &bad;
    ck_assert_int_eq(fe_innovations_add(&inn, 1.0, &r), FE_ENONFINITE);
    r.whitened = &w;
    r.nis = -1;
    ck_assert_int_eq(fe_innovations_add(&inn, 1.0, &r), FE_EINVAL);
    r.nis = 1;
    r.b = 0;
    ck_assert_int_eq(fe_innovations_add(&inn, 1.0, &r), FE_EINVAL);
    r.b = 1;
    ck_assert_int_eq(fe_innovations_add(&inn, NAN, &r), FE_ENONFINITE);
    ck_assert_mem_eq(&inn, &before, sizeof inn);
}
END_TEST

START_TEST(huge_values_are_refused_and_nothing_infinite_escapes)
{
    /* Finite reports whose squares or block sums overflow are refused with
       the accumulation unchanged (found by fuzz_steps), and what is located
       from reports near the top of the range is finite: windows pool
       running means, not sums. */
    fe_innovations inn, before;
    fe_located out[4];
    size_t nout = 0;
    double w[2] = {1e200, -1e200};
    fe_kalman_report r = {2, 1.0, 0, NULL, w, NULL};
    ck_assert_int_eq(fe_innovations_init(&inn, 2, 40, 0), FE_OK);
    memcpy(&before, &inn, sizeof inn);
    ck_assert_int_eq(fe_innovations_add(&inn, 0.0, &r), FE_ENONFINITE);
    ck_assert_mem_eq(&inn, &before, sizeof inn);
    w[0] = 1e150;
    w[1] = 1e-310;                      /* a denormal beside a huge value */
    r.nis = 1e308;
    for (int i = 0; i < 40; i++) {
        int rc = fe_innovations_add(&inn, (double)i, &r);
        ck_assert(rc == FE_OK || rc == FE_ENONFINITE);
        w[1] = -w[1];
    }
    ck_assert_int_eq(fe_innovations_locate(&inn, 0.05, out, 4, &nout), FE_OK);
    ck_assert_uint_ge(nout, 1);
    for (size_t i = 0; i < nout && i < 4; i++) {
        ck_assert(isfinite(out[i].mean_nis) && isfinite(out[i].lag1) && isfinite(out[i].z)
                  && isfinite(out[i].t) && isfinite(out[i].n));
        ck_assert(out[i].p_value >= 0.0 && out[i].p_value <= 1.0);
    }
}
END_TEST

START_TEST(arguments_merges_that_do_not_fit_and_json)
{
    fe_innovations a, b, before;
    fe_located out[4], one;
    double w = 1.0;
    fe_kalman_report r = {1, 1.0, 0, NULL, &w, NULL};
    size_t nout = 7;
    char buf[512], tiny[8];
    ck_assert_int_eq(fe_innovations_init(NULL, 4, 40, 0), FE_EINVAL);
    ck_assert_int_eq(fe_innovations_init(&a, FE_DISCOVER_MAX_BLOCKS + 1, 4000, 0), FE_ESIZE);
    ck_assert_int_eq(fe_innovations_init(&a, 4, 40, 0), FE_OK);
    ck_assert_int_eq(fe_innovations_add(NULL, 0.0, &r), FE_EINVAL);
    ck_assert_int_eq(fe_innovations_add(&a, 0.0, NULL), FE_EINVAL);
    fe_innovations_break(NULL);
    /* A part that ends is full: one report more is refused. */
    for (int i = 0; i < 40; i++)
        ck_assert_int_eq(fe_innovations_add(&a, (double)i, &r), FE_OK);
    memcpy(&before, &a, sizeof a);
    ck_assert_int_eq(fe_innovations_add(&a, 40.0, &r), FE_ESIZE);
    ck_assert_mem_eq(&a, &before, sizeof a);
    /* Merges: NULL, other shapes, parts that do not follow, an empty b. */
    ck_assert_int_eq(fe_innovations_init(&b, 4, 40, 0), FE_OK);
    ck_assert_int_eq(fe_innovations_merge(NULL, &b), FE_EINVAL);
    ck_assert_int_eq(fe_innovations_merge(&a, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_innovations_merge(&a, &b), FE_EMISMATCH);    /* b starts at 0 */
    ck_assert_int_eq(fe_innovations_init(&b, 5, 40, 0), FE_OK);
    ck_assert_int_eq(fe_innovations_merge(&a, &b), FE_EMISMATCH);
    ck_assert_mem_eq(&a, &before, sizeof a);
    ck_assert_int_eq(fe_innovations_init(&b, 4, 40, 0), FE_OK);
    ck_assert_int_eq(fe_innovations_init(&a, 4, 40, 0), FE_OK);
    ck_assert_int_eq(fe_innovations_merge(&a, &b), FE_OK);          /* both empty */
    ck_assert_uint_eq(a.n, 0);
    /* Locate: arguments; a block of zero NIS whose innovations alternate in
       sign is located by its autocorrelation with a finite NIS statistic. */
    ck_assert_int_eq(fe_innovations_locate(NULL, 0.05, out, 4, &nout), FE_EINVAL);
    ck_assert_int_eq(fe_innovations_locate(&a, 0.05, out, 4, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_innovations_locate(&a, 0.05, NULL, 4, &nout), FE_EINVAL);
    ck_assert_int_eq(fe_innovations_locate(&a, 0.0, out, 4, &nout), FE_EINVAL);
    ck_assert_int_eq(fe_innovations_locate(&a, 1.0, out, 4, &nout), FE_EINVAL);
    ck_assert_int_eq(fe_innovations_locate(&a, 0.05, NULL, 0, &nout), FE_OK);
    ck_assert_uint_eq(nout, 0);
    r.nis = 0.0;
    for (int i = 0; i < 40; i++) {
        w = i % 2 ? 1.0 : -1.0;
        ck_assert_int_eq(fe_innovations_add(&a, (double)i, &r), FE_OK);
    }
    ck_assert_int_eq(fe_innovations_locate(&a, 0.05, out, 0, &nout), FE_OK);
    ck_assert_uint_eq(nout, 1);                 /* counted, none written */
    ck_assert_int_eq(fe_innovations_locate(&a, 0.05, out, 4, &nout), FE_OK);
    ck_assert_uint_eq(nout, 1);
    ck_assert(isfinite(out[0].z) && isfinite(out[0].t) && out[0].lag1 < -0.9);
    ck_assert_str_eq(out[0].test, "innovation_acf");
    /* JSON: the keys, a buffer too small, NULLs. */
    ck_assert_int_eq(fe_located_json(&out[0], buf, sizeof buf), FE_OK);
    ck_assert_ptr_nonnull(strstr(buf, "\"test\": \"innovation_acf\""));
    ck_assert_ptr_nonnull(strstr(buf, "\"lag1\""));
    ck_assert_int_eq(buf[0], '{');
    ck_assert_int_eq(buf[strlen(buf) - 1], '}');
    ck_assert_int_eq(fe_located_json(&out[0], tiny, sizeof tiny), FE_ESIZE);
    ck_assert_int_eq(fe_located_json(NULL, buf, sizeof buf), FE_EINVAL);
    ck_assert_int_eq(fe_located_json(&out[0], NULL, sizeof buf), FE_EINVAL);
    one = out[0];
    one.mean_nis = INFINITY;                    /* written as null, not inf */
    ck_assert_int_eq(fe_located_json(&one, buf, sizeof buf), FE_OK);
    ck_assert_ptr_null(strstr(buf, "inf"));
}
END_TEST

Suite *fe_locate_suite(void)
{
    Suite *s = suite_create("locate");
    TCase *t = tcase_create("locate");
    tcase_set_timeout(t, 300);
    tcase_add_test(t, block_statistics_match_a_direct_computation);
    tcase_add_test(t, merge_of_consecutive_parts_equals_whole);
    tcase_add_test(t, refusals_leave_the_accumulation_unchanged);
    tcase_add_test(t, huge_values_are_refused_and_nothing_infinite_escapes);
    tcase_add_test(t, arguments_merges_that_do_not_fit_and_json);
    tcase_add_test(t, merge_into_an_empty_part_is_the_other_part);
    tcase_add_test(t, json_of_every_length_is_whole_or_refused);
    tcase_add_test(t, blocks_without_pairs_have_no_autocorrelation_test);
    tcase_add_test(t, a_missed_drag_is_located_where_it_acts);
    tcase_add_test(t, a_right_model_locates_nothing);
    suite_add_tcase(s, t);
    return s;
}
