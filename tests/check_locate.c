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
            ck_assert_int_eq(loc[i].region, FE_REGION_TIME);
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
    l.region = FE_REGION_TIME;
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

/* A window of two hit blocks reports the largest of their NIS
   statistics, whichever block holds it.  Four blocks of two reports of one
   degree of freedom each (dof 2 a block, where the chi-square upper tail
   is exp(-x/2) exactly): NIS 1 + 1 in the first and last (p = e^-1, no
   hit), 30 + 30 and 20 + 20 in the middle two, in either order (p =
   e^-30 and e^-20, both below 0.05 / 8).  The window's z is the normal
   quantile of e^-30, the root of erfc(z / sqrt 2) / 2 = e^-30 (to
   fe_normal_quantile's documented 1.2e-9), its p-value e^-30,
   its pooled NIS per degree of freedom (60 + 40) / 4 = 25. */
START_TEST(a_window_reports_its_largest_nis_statistic)
{
    /* z30, the root of erfc(z / sqrt 2) / 2 = e^-30, by bisection on
       libm's erfc (7.36; e^-20's is 5.88). */
    double lo = 0, hi = 40, z30;
    for (int i = 0; i < 200; i++) {
        double mid = 0.5 * (lo + hi);
        if (0.5 * erfc(mid / sqrt(2.0)) > exp(-30.0))
            lo = mid;
        else
            hi = mid;
    }
    z30 = 0.5 * (lo + hi);
    ck_assert(z30 > 7.35 && z30 < 7.36);
    for (int order = 0; order < 2; order++) {
        const double per[4] = {1, order ? 20 : 30, order ? 30 : 20, 1};
        fe_innovations inn;
        fe_located out[2];
        size_t n = 9;
        ck_assert_int_eq(fe_innovations_init(&inn, 4, 8, 0), FE_OK);
        for (int i = 0; i < 8; i++) {
            fe_kalman_report r = {1, per[i / 2], 0, NULL, NULL, NULL};
            ck_assert_int_eq(fe_innovations_add(&inn, i, &r), FE_OK);
        }
        ck_assert_int_eq(fe_innovations_locate(&inn, 0.05, out, 2, &n), FE_OK);
        ck_assert_uint_eq(n, 1);
        ck_assert_double_eq(out[0].t0, 2);
        ck_assert_double_eq(out[0].t1, 5);
        ck_assert_double_eq(out[0].n, 4);
        ck_assert_str_eq(out[0].test, "nis");
        FE_ASSERT_REL(out[0].p_value, exp(-30.0), 1e-9);
        FE_ASSERT_REL(out[0].z, z30, 1.2e-9);   /* fe_normal_quantile's bound */
        FE_ASSERT_REL(out[0].mean_nis, 25.0, 1e-12);
    }
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

/* A window the NIS locates in blocks without a lag-one pair carries no
   autocorrelation figure: its t and lag1 are 0, not a default of 1.  Four
   blocks of 10 scalar reports of +-3 (NIS 9 each), a break before every
   report (no pairs; with the whitened vector, then without it: no squares
   either).  Each block's NIS is 90 on 10 degrees of freedom, whose upper
   tail is, for an even number 2m of degrees of freedom,
   e^{-x/2} sum_{k<m} (x/2)^k / k!: p = e^{-45} (1 + 45 + 45^2/2 + 45^3/6
   + 45^4/24), about 5e-15, far below 0.05 / 8.  Every window found says
   "nis" with that p-value, z its upper normal quantile to the 1.2e-9 of
   fe_normal_quantile (the root of 0.5 erfc(z / sqrt 2) = p by Newton's
   method on the logarithm), the mean NIS 9, and t and lag1 exactly 0
   (issue 20: seed 9303's locate:244, z_acf starting at 1 for a block
   without pairs). */
START_TEST(a_window_without_pairs_has_no_autocorrelation_figure)
{
    const double h = 45.0;
    const double p = exp(-h) * (1.0 + h + h * h / 2.0 + h * h * h / 6.0 + h * h * h * h / 24.0);
    double z = 8.0;
    for (int it = 0; it < 60; it++) {
        double q = 0.5 * erfc(z / sqrt(2.0)), phi = exp(-z * z / 2.0) / sqrt(2.0 * acos(-1.0));
        z += (log(q) - log(p)) * q / phi;      /* d log q / dz = -phi / q */
    }
    FE_ASSERT_REL(0.5 * erfc(z / sqrt(2.0)), p, 1e-13);
    for (int whitened = 1; whitened >= 0; whitened--) {
        fe_innovations inn;
        fe_located loc[4];
        size_t n = 0;
        double w = 3.0;
        ck_assert_int_eq(fe_innovations_init(&inn, 4, 40, 0), FE_OK);
        for (int i = 0; i < 40; i++) {
            fe_kalman_report r = {1, 9.0, 0, NULL, whitened ? &w : NULL, NULL};
            fe_innovations_break(&inn);
            w = i % 2 ? 3.0 : -3.0;
            ck_assert_int_eq(fe_innovations_add(&inn, i, &r), FE_OK);
        }
        for (int b = 0; b < 4; b++) {
            ck_assert_double_eq(inn.block[b].acf_terms, 0);
            ck_assert_double_eq(inn.block[b].sq_terms, whitened ? 10 : 0);
            ck_assert_double_eq(inn.block[b].nis, 90.0);
        }
        ck_assert_int_eq(fe_innovations_locate(&inn, 0.05, loc, 4, &n), FE_OK);
        ck_assert_uint_ge(n, 1);
        ck_assert_uint_le(n, 4);
        for (size_t i = 0; i < n; i++) {
            ck_assert_str_eq(loc[i].test, "nis");
            FE_ASSERT_REL(loc[i].p_value, p, 1e-10);
            FE_ASSERT_REL(loc[i].z, z, 1.2e-9);
            ck_assert_double_eq(loc[i].mean_nis, 9.0);
            ck_assert_double_eq(loc[i].t, 0.0);
            ck_assert_double_eq(loc[i].lag1, 0.0);
        }
    }
}
END_TEST

/* The lag-one test of a block is the mean product over the mean square:
   four blocks of 10 scalar reports of +-1, alternating, each block cut by
   breaks at its start and middle, so that it holds 8 pairs (each -1) and
   10 squares (each 1): rho = (-8 / 8) / (10 / 10) = -1, z = rho sqrt(8).
   The window found carries that statistic. */
START_TEST(the_lag_one_statistic_is_a_mean_product_over_a_mean_square)
{
    fe_innovations inn;
    fe_located loc[4];
    size_t n = 0;
    double w = 1.0;
    ck_assert_int_eq(fe_innovations_init(&inn, 4, 40, 0), FE_OK);
    for (int i = 0; i < 40; i++) {
        fe_kalman_report r = {1, 1.0, 0, NULL, &w, NULL};
        if (i % 5 == 0)
            fe_innovations_break(&inn);
        w = i % 2 ? 1.0 : -1.0;
        ck_assert_int_eq(fe_innovations_add(&inn, i, &r), FE_OK);
    }
    for (int b = 0; b < 4; b++) {
        ck_assert_double_eq(inn.block[b].acf_terms, 8);
        ck_assert_double_eq(inn.block[b].sq_terms, 10);
    }
    ck_assert_int_eq(fe_innovations_locate(&inn, 0.05, loc, 4, &n), FE_OK);
    ck_assert_uint_ge(n, 1);
    ck_assert_double_eq_tol(loc[0].t, -sqrt(8.0), 1e-12);
}
END_TEST

START_TEST(merge_of_consecutive_parts_equals_whole)
{
    /* Reports of one, two, four and six dimensions (whitened vectors
       sometimes missing; six is past the FE_KALMAN_MONITOR_DIM = 4 used)
       with recording breaks, folded whole and in three parts cut at
       awkward places (one cut right at a break), merged: the same blocks,
       the pairs across the cuts included. */
    enum { N = 997, K = 7 };
    static const size_t dims[] = {1, 2, 4, 6};
    const size_t cut1 = 200, cut2 = 613;
    for (size_t d = 0; d < sizeof dims / sizeof *dims; d++) {
        fe_innovations whole, p[3];
        fe_rng rng = fe_rng_seed(21);
        int rc = FE_OK;
        ck_assert_int_eq(fe_innovations_init(&whole, K, N, 0), FE_OK);
        ck_assert_int_eq(fe_innovations_init(&p[0], K, N, 0), FE_OK);
        ck_assert_int_eq(fe_innovations_init(&p[1], K, N, cut1), FE_OK);
        ck_assert_int_eq(fe_innovations_init(&p[2], K, N, cut2), FE_OK);
        for (size_t i = 0; i < N; i++) {
            double w[6], nis = 0.0;
            for (size_t c = 0; c < dims[d]; c++) {
                w[c] = fe_rng_normal(&rng);
                nis += w[c] * w[c];
            }
            fe_kalman_report r = {dims[d], nis, 0, NULL, i % 37 ? w : NULL, NULL};
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
        {
            /* An empty part between them changes nothing, to the byte:
               not the row before the cut, nor the recording count. */
            fe_innovations empty, before;
            memcpy(&before, &p[0], sizeof before);
            ck_assert_int_eq(fe_innovations_init(&empty, K, N, cut1), FE_OK);
            ck_assert_int_eq(fe_innovations_merge(&p[0], &empty), FE_OK);
            ck_assert_mem_eq(&p[0], &before, sizeof before);
        }
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
            ck_assert_msg(fabs(x->acf - y->acf) <= 1e-12 * y->sq, "dim %zu block %zu: acf %.17g, "
                          "whole %.17g", dims[d], k, x->acf, y->acf);
        }
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
       nothing written past it, and holds then the header's "truncated
       prefix": the document's first len - 1 bytes and the NUL; the exact
       length (with its NUL) is enough.  A time window (NIS figures) and a
       speed band (residual figures): every piece of both branches is cut
       somewhere. */
    fe_located l[2];
    memset(l, 0, sizeof l);
    l[0].pair = 0;
    l[0].pair1 = 1;
    l[0].t0 = 1.5;
    l[0].t1 = 2.5;
    l[0].n = 10;
    l[0].z = 3.25;
    l[0].t = -1.5;
    l[0].test = "nis";
    l[0].p_value = 0.001;
    l[0].mean_nis = 2.0;
    l[0].lag1 = 0.25;
    l[1].region = FE_REGION_SPEED;
    l[1].lo = 0.25;
    l[1].hi = 0.75;
    l[1].n = 31;
    l[1].z = -0.5;
    l[1].t = 4.125;
    l[1].test = "residual_mean";
    l[1].p_value = 3e-7;
    l[1].mean_before = 0.0625;
    l[1].mean_after = -0.015625;
    l[1].ms_ratio_before = 1.75;
    l[1].ms_ratio_after = 1.0078125;
    for (int k = 0; k < 2; k++) {
        char full[1024], buf[1024 + 8];
        size_t need;
        ck_assert_int_eq(fe_located_json(&l[k], full, sizeof full), FE_OK);
        need = strlen(full) + 1;
        for (size_t len = 1; len <= need; len++) {
            memset(buf, 'X', sizeof buf);
            ck_assert_int_eq(fe_located_json(&l[k], buf, len), len < need ? FE_ESIZE : FE_OK);
            for (size_t i = len; i < sizeof buf; i++)
                ck_assert_int_eq(buf[i], 'X');
            ck_assert_uint_eq(strlen(buf), len - 1);
            ck_assert_int_eq(memcmp(buf, full, len - 1), 0);
        }
        ck_assert_str_eq(buf, full);
    }
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

START_TEST(a_lag_one_sum_that_overflows_is_refused)
{
    /* Four scalar reports in two blocks (rows 0, 1 | 2, 3), whitened
       0, a = 1.3e154 | x1 = 1.1e154, x2.  Block 1's squares, 1.21e308 +
       x2^2, and every single product are doubles; its lag-one sum a x1 +
       x1 x2 = 1.43e308 + 1.1e154 x2 is one for x2 = -6e153 (7.7e307) and
       not for x2 = +6e153 (2.09e308 > DBL_MAX = 1.80e308): that report is
       refused, the accumulation unchanged. */
    for (int sign = -1; sign <= 1; sign += 2) {
        fe_innovations inn, before;
        const double w[4] = {0.0, 1.3e154, 1.1e154, sign * 6e153};
        double one[1];
        fe_kalman_report r = {1, 1.0, 0, NULL, one, NULL};
        ck_assert_int_eq(fe_innovations_init(&inn, 2, 4, 0), FE_OK);
        for (int i = 0; i < 3; i++) {
            one[0] = w[i];
            ck_assert_int_eq(fe_innovations_add(&inn, (double)i, &r), FE_OK);
        }
        ck_assert(inn.block[1].acf == 1.3e154 * 1.1e154);
        memcpy(&before, &inn, sizeof inn);
        one[0] = w[3];
        if (sign < 0) {
            ck_assert_int_eq(fe_innovations_add(&inn, 3.0, &r), FE_OK);
            ck_assert(inn.block[1].acf == 1.3e154 * 1.1e154 + 1.1e154 * -6e153);
            ck_assert(inn.block[1].sq == 1.1e154 * 1.1e154 + 6e153 * 6e153);
        } else {
            ck_assert_int_eq(fe_innovations_add(&inn, 3.0, &r), FE_ENONFINITE);
            ck_assert_mem_eq(&inn, &before, sizeof inn);
        }
    }
}
END_TEST

START_TEST(a_block_sum_of_squares_that_overflows_is_refused)
{
    /* Two scalar reports in block 0 (rows 0, 1 of four in two blocks),
       whitened w and w.  Each square is a double; for w = 1e154 the
       block's sum of squares 1e308 + 1e308 is not (DBL_MAX = 1.80e308),
       and the second report is refused, the accumulation unchanged, while
       its lag-one product (1e308, the first row had none) and its NIS fit.
       For w = 9e153 the sum 1.62e308 is a double and is taken.  Seed
       10223's locate:86 tested bk->sq - sq, which cannot overflow. */
    for (int big = 0; big <= 1; big++) {
        fe_innovations inn, before;
        double w = big ? 1e154 : 9e153;
        fe_kalman_report r = {1, 1.0, 0, NULL, &w, NULL};
        ck_assert_int_eq(fe_innovations_init(&inn, 2, 4, 0), FE_OK);
        ck_assert_int_eq(fe_innovations_add(&inn, 0.0, &r), FE_OK);
        ck_assert(inn.block[0].sq == w * w);
        memcpy(&before, &inn, sizeof inn);
        if (big) {
            ck_assert_int_eq(fe_innovations_add(&inn, 1.0, &r), FE_ENONFINITE);
            ck_assert_mem_eq(&inn, &before, sizeof inn);
        } else {
            ck_assert_int_eq(fe_innovations_add(&inn, 1.0, &r), FE_OK);
            ck_assert(inn.block[0].sq == w * w + w * w);
            ck_assert(inn.block[0].acf == w * w);
            ck_assert(inn.block[0].n == 2.0);
        }
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


/* ---------------------------------------------------------------- residual map */

enum { MAP_ROWS = 600, MAP_BLOCKS = 10, MAP_FIT = 480 };

/* Row i of three recordings (breaks before rows 200 and 350): time, a
   state that crosses zero, and residuals before and after. */
static void map_row(int i, fe_sample *s, double *before, double *after)
{
    memset(s, 0, sizeof *s);
    s->t = 0.01 * i + (i >= 200 ? 100 : 0) + (i >= 350 ? 100 : 0);
    s->position = sin(0.05 * i);
    s->velocity = i % 37 == 0 ? 0.0 : cos(0.031 * i) * 2.0;
    s->temperature = 20.0 + 5.0 * sin(0.007 * i);
    *before = 0.3 * sin(1.7 * i) + (s->velocity < 0 ? 0.2 : 0.0);
    *after = 0.3 * sin(1.7 * i);
}

static const double map_lo[3] = {-1.0, -2.0, 15.0}, map_hi[3] = {1.0, 2.0, 25.0};
static const unsigned map_roles = FE_ROLE_POSITION | FE_ROLE_VELOCITY | FE_ROLE_TEMPERATURE;

/* Fold rows [from, to) into m (a part starting at row `from`). */
static void map_fold(fe_residual_map *m, int from, int to)
{
    ck_assert_int_eq(fe_residual_map_init(m, MAP_BLOCKS, MAP_FIT, (uint64_t)from, map_roles,
                                          map_lo, map_hi), FE_OK);
    for (int i = from; i < to; i++) {
        fe_sample s;
        double b, a;
        map_row(i, &s, &b, &a);
        if (i > from && (i == 200 || i == 350))
            fe_residual_map_break(m);
        if (i == from && (i == 200 || i == 350))
            fe_residual_map_break(m);
        ck_assert_int_eq(fe_residual_map_add(m, &s, b, a), FE_OK);
    }
}

START_TEST(residual_map_cells_equal_sums_over_the_rows)
{
    /* Every block, region and bin against a direct sum over the rows that
       belong to it by definition (block floor(i K / fit), the held-out rows
       in block K; regions of fitted rows only; bins of every row). */
    fe_residual_map m;
    double blk[MAP_BLOCKS + 1][3] = {{0}}, neg[3] = {0}, zero[3] = {0}, tb[4][3] = {{0}};
    double sb[4] = {0}, pb[FE_RESIDUAL_BINS] = {0};
    map_fold(&m, 0, MAP_ROWS);
    ck_assert_uint_eq(m.nregions, 13);
    for (int i = 0; i < MAP_ROWS; i++) {
        fe_sample s;
        double b, a, u;
        int k = i < MAP_FIT ? i * MAP_BLOCKS / MAP_FIT : MAP_BLOCKS, band;
        map_row(i, &s, &b, &a);
        blk[k][0] += 1;
        blk[k][1] += b;
        blk[k][2] += a * a;
        u = (s.position + 1.0) / 2.0 * FE_RESIDUAL_BINS;
        pb[u >= FE_RESIDUAL_BINS ? FE_RESIDUAL_BINS - 1 : (int)u] += 1;
        if (i >= MAP_FIT)
            continue;
        if (s.velocity < 0) {
            neg[0] += 1;
            neg[1] += b;
            neg[2] += b * b;
        }
        if (s.velocity == 0) {
            zero[0] += 1;
            zero[1] += a;
        }
        if (s.velocity != 0) {
            band = (int)(fabs(s.velocity) / 2.0 * 4);
            sb[band > 3 ? 3 : band] += 1;
        }
        band = (int)((s.temperature - 15.0) / 10.0 * 4);
        tb[band > 3 ? 3 : band][0] += 1;
        tb[band > 3 ? 3 : band][1] += b * b;
    }
    for (int k = 0; k <= MAP_BLOCKS; k++) {
        ck_assert_double_eq(m.block[k].n, blk[k][0]);
        ck_assert_double_eq_tol(m.block[k].sum0, blk[k][1], 1e-12);
        ck_assert_double_eq_tol(m.block[k].sq1, blk[k][2], 1e-12);
    }
    ck_assert_int_eq(m.region[0], FE_REGION_VELOCITY_NEGATIVE);
    ck_assert_double_eq(m.cell[0].n, neg[0]);
    ck_assert_double_eq_tol(m.cell[0].sum0, neg[1], 1e-12);
    ck_assert_double_eq_tol(m.cell[0].sq0, neg[2], 1e-12);
    ck_assert_int_eq(m.region[2], FE_REGION_VELOCITY_ZERO);
    ck_assert_double_eq(m.cell[2].n, zero[0]);
    ck_assert_double_eq_tol(m.cell[2].sum1, zero[1], 1e-12);
    for (int b = 0; b < 4; b++) {
        ck_assert_int_eq(m.region[3 + b], FE_REGION_SPEED);
        ck_assert_double_eq_tol(m.region_lo[3 + b], 0.5 * b, 1e-15);
        ck_assert_double_eq(m.cell[3 + b].n, sb[b]);
        ck_assert_int_eq(m.region[9 + b], FE_REGION_TEMPERATURE);
        ck_assert_double_eq_tol(m.region_hi[9 + b], 15.0 + 2.5 * (b + 1), 1e-12);
        ck_assert_double_eq(m.cell[9 + b].n, tb[b][0]);
        ck_assert_double_eq_tol(m.cell[9 + b].sq0, tb[b][1], 1e-12);
    }
    for (int j = 0; j < FE_RESIDUAL_BINS; j++)
        ck_assert_double_eq(m.bin[0][j].n, pb[j]);
    /* The recordings of the blocks: block 3 (rows 144..191) is in the
       first, block 4 (rows 192..239) runs from the first into the second. */
    ck_assert_int_eq(m.block[3].pair1, 0);
    ck_assert_int_eq(m.block[4].pair, 0);
    ck_assert_int_eq(m.block[4].pair1, 1);
    ck_assert_int_eq(m.block[MAP_BLOCKS].pair1, 2);
}
END_TEST

/* The most cells one row can join.  A range of no width is one band
   (residual_map_refusals_at_their_edges): its four bands are one and the
   same interval, and a row lies in each of them.  With the velocity's
   range [0, 0] (rows that stood still) and a row moving at 0.25, outside
   it (a value outside joins the band at the range's end), and a constant
   temperature, the row lies in the velocity's positive half, in all four
   speed bands, in the position's positive half and in all four
   temperature bands: ten regions of thirteen (one of the velocity's
   three, one of the position's two, every band), and with its time block
   and its three bins, fourteen cells, each holding it once. */
START_TEST(a_row_joins_every_region_it_lies_in)
{
    fe_residual_map m;
    fe_sample s = {0};
    const double lo[3] = {-1.0, 0.0, 10.0}, hi[3] = {1.0, 0.0, 10.0};
    double regions = 0.0, bins = 0.0, blocks = 0.0;
    ck_assert_int_eq(fe_residual_map_init(&m, 4, 40, 0, map_roles, lo, hi), FE_OK);
    ck_assert_uint_eq(m.nregions, FE_RESIDUAL_REGIONS);
    s.t = 3.0;
    s.position = 0.5;
    s.velocity = 0.25;
    s.temperature = 10.0;
    ck_assert_int_eq(fe_residual_map_add(&m, &s, 0.75, -0.5), FE_OK);
    for (size_t g = 0; g < m.nregions; g++) {
        int in = m.region[g] == FE_REGION_VELOCITY_POSITIVE || m.region[g] == FE_REGION_SPEED
                 || m.region[g] == FE_REGION_POSITION_POSITIVE
                 || m.region[g] == FE_REGION_TEMPERATURE;
        ck_assert_double_eq(m.cell[g].n, in ? 1.0 : 0.0);
        if (in) {
            ck_assert_double_eq(m.cell[g].sum0, 0.75);
            ck_assert_double_eq(m.cell[g].sq1, 0.25);
            ck_assert_double_eq(m.cell[g].t0, 3.0);
        }
        regions += m.cell[g].n;
    }
    ck_assert_double_eq(regions, 10.0);
    ck_assert_double_eq(m.block[0].n, 1.0);
    ck_assert_double_eq(m.block[0].sum1, -0.5);
    for (size_t k = 0; k <= m.blocks; k++)
        blocks += m.block[k].n;
    ck_assert_double_eq(blocks, 1.0);
    ck_assert_double_eq(m.bin[0][30].n, 1.0);      /* (0.5 + 1) / 2 of 40 bins */
    ck_assert_double_eq(m.bin[0][30].sum_at, 0.5);
    ck_assert_double_eq(m.bin[1][0].n, 1.0);       /* the range's one band: its first */
    ck_assert_double_eq(m.bin[1][0].sum_at, 0.25);
    ck_assert_double_eq(m.bin[2][0].n, 1.0);
    ck_assert_double_eq(m.bin[2][0].sum_at, 10.0);
    for (int v = 0; v < 3; v++)
        for (int j = 0; j < FE_RESIDUAL_BINS; j++)
            bins += m.bin[v][j].n;
    ck_assert_double_eq(bins, 3.0);
    ck_assert_uint_eq(m.n, 1);
}
END_TEST

START_TEST(a_part_numbers_its_recordings_from_zero)
{
    /* Seed 10117's locate:764 and its neighbours: the recordings of a part
       are numbered from 0 (locate.h), and a break starts the next one.
       A break before the part's first row starts no recording of its own:
       the whole stream folded after such a break has every block, region
       and bin of the fold without it, to the byte, and the same recording
       count; only first_linked says that the first row does not follow a
       previous part.  A part cut at the break before row 200 numbers that
       recording 0 and ends in recording 1 (rows 350 on); merged into an
       empty part it is that part.  A part of rows 199 on has one row of
       the first recording before the break: its recordings are the whole
       stream's, so its blocks after the first (rows 240 on) are the
       whole's to the byte, and it ends in recording 2. */
    fe_residual_map whole, lead, part, empty;
    map_fold(&whole, 0, MAP_ROWS);
    ck_assert_int_eq(fe_residual_map_init(&lead, MAP_BLOCKS, MAP_FIT, 0, map_roles, map_lo,
                                          map_hi), FE_OK);
    fe_residual_map_break(&lead);
    for (int i = 0; i < MAP_ROWS; i++) {
        fe_sample s;
        double b, a;
        map_row(i, &s, &b, &a);
        if (i == 200 || i == 350)
            fe_residual_map_break(&lead);
        ck_assert_int_eq(fe_residual_map_add(&lead, &s, b, a), FE_OK);
    }
    ck_assert_int_eq(whole.first_linked, 1);
    ck_assert_int_eq(lead.first_linked, 0);
    ck_assert_int_eq(whole.recording, 2);
    ck_assert_int_eq(lead.recording, 2);
    ck_assert_int_eq(lead.block[0].pair, 0);
    ck_assert_mem_eq(lead.block, whole.block, sizeof whole.block);
    ck_assert_mem_eq(lead.cell, whole.cell, sizeof whole.cell);
    ck_assert_mem_eq(lead.bin, whole.bin, sizeof whole.bin);
    map_fold(&part, 200, MAP_ROWS);                 /* a break before its row 200 */
    ck_assert_int_eq(part.first_linked, 0);
    ck_assert_int_eq(part.recording, 1);
    ck_assert_int_eq(part.block[200 * MAP_BLOCKS / MAP_FIT].pair, 0);
    ck_assert_int_eq(part.block[MAP_BLOCKS].pair1, 1);
    ck_assert_int_eq(fe_residual_map_init(&empty, MAP_BLOCKS, MAP_FIT, 200, map_roles, map_lo,
                                          map_hi), FE_OK);
    ck_assert_int_eq(fe_residual_map_merge(&empty, &part), FE_OK);
    ck_assert_int_eq(empty.recording, part.recording);
    ck_assert_mem_eq(empty.block, part.block, sizeof part.block);
    map_fold(&part, 199, MAP_ROWS);                 /* one row, then the break */
    ck_assert_int_eq(part.first_linked, 1);
    ck_assert_int_eq(part.recording, 2);
    ck_assert_int_eq(part.block[4].pair, 0);        /* rows 199 .. 239 */
    ck_assert_int_eq(part.block[4].pair1, 1);
    ck_assert_mem_eq(&part.block[5], &whole.block[5], (MAP_BLOCKS - 4) * sizeof *whole.block);
}
END_TEST

START_TEST(residual_map_merge_of_parts_equals_whole)
{
    /* Cut anywhere (inside a recording, at a break, next to one, in the
       held-out rows): the merged map equals the whole fold in every cell,
       recordings included. */
    static const int cuts[][2] = {{1, 599}, {200, 350}, {199, 351}, {480, 481}, {57, 520}};
    fe_residual_map whole;
    map_fold(&whole, 0, MAP_ROWS);
    for (size_t c = 0; c < sizeof cuts / sizeof cuts[0]; c++) {
        fe_residual_map p0, p1, p2;
        map_fold(&p0, 0, cuts[c][0]);
        map_fold(&p1, cuts[c][0], cuts[c][1]);
        map_fold(&p2, cuts[c][1], MAP_ROWS);
        ck_assert_int_eq(fe_residual_map_merge(&p1, &p2), FE_OK);
        ck_assert_int_eq(fe_residual_map_merge(&p0, &p1), FE_OK);
        ck_assert_uint_eq(p0.n, whole.n);
        ck_assert_int_eq(p0.recording, whole.recording);
        for (size_t k = 0; k <= MAP_BLOCKS; k++) {
            const fe_residual_cell *x = &p0.block[k], *y = &whole.block[k];
            ck_assert_double_eq(x->n, y->n);
            ck_assert_double_eq_tol(x->sum0, y->sum0, 1e-12);
            ck_assert_double_eq_tol(x->sq0, y->sq0, 1e-12);
            ck_assert_double_eq_tol(x->sum1, y->sum1, 1e-12);
            ck_assert_double_eq_tol(x->sq1, y->sq1, 1e-12);
            ck_assert_double_eq(x->t0, y->t0);
            ck_assert_double_eq(x->t1, y->t1);
            ck_assert_int_eq(x->pair, y->pair);
            ck_assert_int_eq(x->pair1, y->pair1);
        }
        for (size_t g = 0; g < whole.nregions; g++) {
            ck_assert_double_eq(p0.cell[g].n, whole.cell[g].n);
            ck_assert_double_eq_tol(p0.cell[g].sq0, whole.cell[g].sq0, 1e-12);
            ck_assert_int_eq(p0.cell[g].pair, whole.cell[g].pair);
            ck_assert_int_eq(p0.cell[g].pair1, whole.cell[g].pair1);
        }
        for (int v = 0; v < 3; v++)
            for (size_t j = 0; j < FE_RESIDUAL_BINS; j++) {
                ck_assert_double_eq(p0.bin[v][j].n, whole.bin[v][j].n);
                ck_assert_double_eq_tol(p0.bin[v][j].sum1, whole.bin[v][j].sum1, 1e-12);
            }
    }
    {
        /* Parts out of order, or cut from other ranges, do not merge. */
        fe_residual_map a, b, keep;
        double lo2[3] = {-1.0, -2.0, 14.0};
        map_fold(&a, 0, 100);
        map_fold(&b, 101, 200);
        memcpy(&keep, &a, sizeof a);
        ck_assert_int_eq(fe_residual_map_merge(&a, &b), FE_EMISMATCH);
        ck_assert_int_eq(fe_residual_map_init(&b, MAP_BLOCKS, MAP_FIT, 100, map_roles, lo2,
                                              map_hi), FE_OK);
        ck_assert_int_eq(fe_residual_map_merge(&a, &b), FE_EMISMATCH);
        ck_assert_mem_eq(&a, &keep, sizeof a);
        /* Each end of each range alone: a part cut from other ranges. */
        for (int v = 0; v < 3; v++)
            for (int end = 0; end < 2; end++) {
                double l[3], h[3];
                memcpy(l, map_lo, sizeof l);
                memcpy(h, map_hi, sizeof h);
                if (end == 0)
                    l[v] -= 0.5;
                else
                    h[v] += 0.5;
                ck_assert_int_eq(fe_residual_map_init(&b, MAP_BLOCKS, MAP_FIT, 100, map_roles,
                                                      l, h), FE_OK);
                ck_assert_msg(fe_residual_map_merge(&a, &b) == FE_EMISMATCH, "v %d end %d", v,
                              end);
                ck_assert_mem_eq(&a, &keep, sizeof a);
            }
        ck_assert_int_eq(fe_residual_map_init(&b, MAP_BLOCKS, MAP_FIT, 100, map_roles, map_lo,
                                              map_hi), FE_OK);
        ck_assert_int_eq(fe_residual_map_merge(&a, &b), FE_OK);     /* the same: an empty part */
        ck_assert_mem_eq(&a, &keep, sizeof a);
        ck_assert_int_eq(fe_residual_map_merge(NULL, &b), FE_EINVAL);
    }
}
END_TEST

/* A map of white noise (fixed seed), with `step` added to the residual
   before in fitted rows [from, to) and `vstep` where v < 0. */
static void map_noise(fe_residual_map *m, double step, int from, int to, double vstep)
{
    fe_rng rng = fe_rng_seed(11);
    const unsigned roles = FE_ROLE_VELOCITY;
    const double lo[3] = {0, -1, 0}, hi[3] = {0, 1, 0};
    ck_assert_int_eq(fe_residual_map_init(m, 20, 4000, 0, roles, lo, hi), FE_OK);
    for (int i = 0; i < 5000; i++) {
        fe_sample s = {0};
        double e = fe_rng_normal(&rng), b = e;
        s.t = i;
        s.velocity = sin(0.01 * i);
        if (i >= from && i < to)
            b += step;
        if (s.velocity < 0)
            b += vstep;
        ck_assert_int_eq(fe_residual_map_add(m, &s, b, e), FE_OK);
    }
}

START_TEST(residual_map_locates_a_window_and_a_region)
{
    fe_residual_map m;
    fe_located loc[8];
    size_t n;
    /* Nothing in white noise: every statistic below the Bonferroni bound
       (27 places, two statistics: 3.11 at 0.05); here the largest is far
       below it. */
    map_noise(&m, 0.0, 0, 0, 0.0);
    ck_assert_int_eq(fe_residual_map_locate(&m, 1.0, 0.05, loc, 8, &n), FE_OK);
    ck_assert_uint_eq(n, 0);
    ck_assert_double_lt(fe_residual_map_largest_after(&m, 1.0), -fe_normal_quantile(0.05 / 54));
    /* A step of 0.6 sd over rows 1000..1399 (blocks 5 to 6, 200 rows each):
       one window, exactly those blocks, t = 0.6 sqrt(200) = 8.5 each. */
    map_noise(&m, 0.6, 1000, 1400, 0.0);
    ck_assert_int_eq(fe_residual_map_locate(&m, 1.0, 0.05, loc, 8, &n), FE_OK);
    ck_assert_uint_eq(n, 1);
    ck_assert_int_eq(loc[0].region, FE_REGION_TIME);
    ck_assert_double_eq(loc[0].t0, 1000);
    ck_assert_double_eq(loc[0].t1, 1399);
    ck_assert_double_eq(loc[0].n, 400);
    ck_assert_str_eq(loc[0].test, "residual_mean");
    ck_assert_double_gt(loc[0].t, 6.0);
    ck_assert_double_lt(fabs(loc[0].mean_after), 0.2);
    {
        /* The window's pooled figures against the rows themselves: the
           same noise stream, with the step, over rows 1000 .. 1399. */
        fe_rng rng = fe_rng_seed(11);
        double before = 0.0, after = 0.0, sq = 0.0;
        for (int i = 0; i < 1400; i++) {
            double e = fe_rng_normal(&rng);
            if (i >= 1000) {
                before += e + 0.6;
                after += e;
                sq += (e + 0.6) * (e + 0.6);
            }
        }
        FE_ASSERT_REL(loc[0].mean_before, before / 400.0, 1e-12);
        FE_ASSERT_REL(loc[0].mean_after, after / 400.0, 1e-12);
        {
            /* its mean square over the median block's */
            double ms[20], med;
            for (int k = 0; k < 20; k++)
                ms[k] = m.block[k].sq0 / m.block[k].n;
            for (int i = 1; i < 20; i++)        /* insertion sort */
                for (int j = i; j > 0 && ms[j - 1] > ms[j]; j--) {
                    double x = ms[j];
                    ms[j] = ms[j - 1];
                    ms[j - 1] = x;
                }
            med = 0.5 * (ms[9] + ms[10]);
            FE_ASSERT_REL(loc[0].ms_ratio_before, sq / 400.0 / med, 1e-12);
        }
    }
    {
        /* The window's statistics, the larger of its two blocks' (5 and
           6), from the rows: each block's mean square ms_k and mean over
           its 200 rows, the median of the twenty ms_k, and z_k = (ms_k /
           med - 1) / sqrt(2 / 200), t_k = mean_k / sqrt(med / 200). */
        fe_rng rng = fe_rng_seed(11);
        double msk[20] = {0}, mean[20] = {0}, srt[20], med, z[2], t[2];
        for (int i = 0; i < 4000; i++) {
            double b = fe_rng_normal(&rng) + (i >= 1000 && i < 1400 ? 0.6 : 0.0);
            msk[i / 200] += b * b / 200.0;
            mean[i / 200] += b / 200.0;
        }
        memcpy(srt, msk, sizeof srt);
        for (int i = 1; i < 20; i++)
            for (int j = i; j > 0 && srt[j - 1] > srt[j]; j--) {
                double x = srt[j];
                srt[j] = srt[j - 1];
                srt[j - 1] = x;
            }
        med = 0.5 * (srt[9] + srt[10]);
        for (int k = 0; k < 2; k++) {
            z[k] = (msk[5 + k] / med - 1.0) / sqrt(2.0 / 200.0);
            t[k] = mean[5 + k] / sqrt(med / 200.0);
        }
        FE_ASSERT_REL(loc[0].z, z[0] > z[1] ? z[0] : z[1], 1e-10);
        FE_ASSERT_REL(loc[0].t, fabs(t[0]) > fabs(t[1]) ? t[0] : t[1], 1e-10);
        FE_ASSERT_REL(loc[0].p_value, erfc(fabs(loc[0].t) / sqrt(2.0)), 1e-12);
    }
    /* Worth a twentieth of a row each (a strongly coloured noise), the same step
       is no longer out of line in time: t falls by sqrt(20), below 2.5. */
    ck_assert_int_eq(fe_residual_map_locate(&m, 0.05, 0.05, loc, 8, &n), FE_OK);
    for (size_t i = 0; i < n && i < 8; i++)
        ck_assert_int_ne(loc[i].region, FE_REGION_TIME);
    /* A shift where v < 0: that region and its complement v > 0. */
    map_noise(&m, 0.0, 0, 0, 0.3);
    ck_assert_int_eq(fe_residual_map_locate(&m, 1.0, 0.05, loc, 8, &n), FE_OK);
    ck_assert_uint_ge(n, 1);
    {
        int found = 0;
        char words[64];
        for (size_t i = 0; i < n && i < 8; i++)
            if (loc[i].region == FE_REGION_VELOCITY_NEGATIVE) {
                /* its statistics from the map's sums: the region's mean
                   against the fitted rows' mean, its mean square against
                   theirs, each row worth one */
                double n = 0, sum = 0, sq = 0;
                const fe_residual_cell *c = &m.cell[0];
                for (int k = 0; k < 20; k++) {
                    n += m.block[k].n;
                    sum += m.block[k].sum0;
                    sq += m.block[k].sq0;
                }
                FE_ASSERT_REL(loc[i].t, (c->sum0 / c->n - sum / n) / sqrt(sq / n / c->n), 1e-12);
                FE_ASSERT_REL(loc[i].z, (c->sq0 / c->n / (sq / n) - 1.0) / sqrt(2.0 / c->n),
                              1e-12);
                found = 1;
                ck_assert_double_gt(loc[i].t, 0);
                ck_assert_int_eq(fe_region_describe(&loc[i], words, sizeof words), FE_OK);
                ck_assert_str_eq(words, "v < 0");
                ck_assert_str_eq(fe_region_variable(loc[i].region), "velocity");
            }
        ck_assert(found);
    }
    ck_assert_int_eq(fe_residual_map_locate(&m, 0.0, 0.05, loc, 8, &n), FE_EINVAL);
    ck_assert_int_eq(fe_residual_map_locate(&m, 1.5, 0.05, loc, 8, &n), FE_EINVAL);
    ck_assert_int_eq(fe_residual_map_locate(&m, 1.0, 1.0, loc, 8, &n), FE_EINVAL);
    ck_assert_int_eq(fe_residual_map_locate(&m, 1.0, 0.05, NULL, 8, &n), FE_EINVAL);
    /* Each of the other arguments alone: no map, no count, alpha 0 and
       NaN, worth NaN; no room and no array is a valid question. */
    ck_assert_int_eq(fe_residual_map_locate(NULL, 1.0, 0.05, loc, 8, &n), FE_EINVAL);
    ck_assert_int_eq(fe_residual_map_locate(&m, 1.0, 0.05, loc, 8, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_residual_map_locate(&m, 1.0, 0.0, loc, 8, &n), FE_EINVAL);
    ck_assert_int_eq(fe_residual_map_locate(&m, 1.0, NAN, loc, 8, &n), FE_EINVAL);
    ck_assert_int_eq(fe_residual_map_locate(&m, NAN, 0.05, loc, 8, &n), FE_EINVAL);
    ck_assert_int_eq(fe_residual_map_locate(&m, 1.0, 0.05, NULL, 0, &n), FE_OK);
}
END_TEST

START_TEST(the_largest_statistic_after_the_terms_looks_at_the_regions)
{
    /* 40 rows in 4 blocks, the velocity alternating +-0.5 and the
       residual after the terms its sign: every block has mean 0 and mean
       square 1, so their statistics are 0, and the regions v > 0 and
       v < 0 hold 20 rows of mean +-1, t = +-sqrt(20 w) (the speed bands
       hold every row and are not tested).  The largest statistic is the
       regions'.  The statistics are ratios: the same residuals a thousand
       times smaller (`small`, a sum of squares of 4e-5) give the same. */
    fe_residual_map m, small;
    const double lo[3] = {0, -1, 0}, hi[3] = {0, 1, 0};
    ck_assert_int_eq(fe_residual_map_init(&m, 4, 40, 0, FE_ROLE_VELOCITY, lo, hi), FE_OK);
    ck_assert_int_eq(fe_residual_map_init(&small, 4, 40, 0, FE_ROLE_VELOCITY, lo, hi), FE_OK);
    ck_assert_uint_ge(m.nregions, 2);
    for (int i = 0; i < 40; i++) {
        fe_sample s = {0};
        double e = i % 2 ? 1.0 : -1.0;
        s.t = i;
        s.velocity = 0.5 * e;
        ck_assert_int_eq(fe_residual_map_add(&m, &s, e, e), FE_OK);
        ck_assert_int_eq(fe_residual_map_add(&small, &s, 1e-3 * e, 1e-3 * e), FE_OK);
    }
    for (int k = 0; k < 3; k++) {
        double w = k == 0 ? 1.0 : k == 1 ? 0.5 : 0.05;
        ck_assert_double_eq_tol(fe_residual_map_largest_after(&m, w), sqrt(20.0 * w), 1e-12);
    }
    ck_assert_double_eq_tol(fe_residual_map_largest_after(&small, 1.0), sqrt(20.0), 1e-9);
    /* The four speed bands split 0 .. vmax (here 1) in quarters. */
    {
        int band = 0;
        for (size_t g = 0; g < m.nregions; g++)
            if (m.region[g] == FE_REGION_SPEED) {
                ck_assert_double_eq(m.region_lo[g], band / 4.0);
                ck_assert_double_eq(m.region_hi[g], (band + 1) / 4.0);
                band++;
            }
        ck_assert_int_eq(band, 4);
    }
}
END_TEST

/* The four speed bands split 0 .. vmax in quarters, vmax the larger of
   |lo| and |hi| of the velocity's range, at either end: [-4, 1] and
   [-1, 4] both give vmax = 4 and the bands [0, 1], [1, 2], [2, 3],
   [3, 4].  The position's and temperature's ranges given beside it (not
   in the roles) play no part.  Seed 10223's locate:528 compared the
   temperature's lo (0 then) with |hi[1]| and took vmax = 1 for [-4, 1];
   the suite's velocity ranges were all symmetric. */
START_TEST(the_speed_bands_reach_the_faster_end_of_either_sign)
{
    for (int neg = 0; neg <= 1; neg++) {
        fe_residual_map m;
        const double lo[3] = {-9.0, neg ? -4.0 : -1.0, 50.0};
        const double hi[3] = {9.0, neg ? 1.0 : 4.0, 60.0};
        int band = 0;
        ck_assert_int_eq(fe_residual_map_init(&m, 4, 40, 0, FE_ROLE_VELOCITY, lo, hi), FE_OK);
        ck_assert_double_eq(m.vmax, 4.0);
        for (size_t g = 0; g < m.nregions; g++)
            if (m.region[g] == FE_REGION_SPEED) {
                ck_assert_double_eq(m.region_lo[g], (double)band);
                ck_assert_double_eq(m.region_hi[g], (double)(band + 1));
                band++;
            }
        ck_assert_int_eq(band, 4);
    }
}
END_TEST

/* A cell is tested from 2 rows: rows 0 .. 37 at v = +0.5 with residuals
   -1, +1, ... (mean 0) and rows 38, 39 at v = -0.5 with residual +1.
   All 40 rows: mean 0.05, mean square 1, so every z is 0; the region
   v < 0 (2 rows, mean 1) has t = 0.95 sqrt(2 w), larger than block 3's
   (0.2 - 0.05) sqrt(10 w) and the region v > 0's 0.05 sqrt(38 w).  With
   only row 39 at v = -0.5 the region of one row is not tested, v > 0
   (39 rows, more than all but 2) neither, and the blocks' means are 0:
   the largest statistic is 0. */
START_TEST(cells_of_two_rows_are_tested_and_of_one_not)
{
    const double lo[3] = {0, -1, 0}, hi[3] = {0, 1, 0}, w = 0.5;
    for (int two = 1; two >= 0; two--) {
        fe_residual_map m;
        ck_assert_int_eq(fe_residual_map_init(&m, 4, 40, 0, FE_ROLE_VELOCITY, lo, hi), FE_OK);
        for (int i = 0; i < 40; i++) {
            fe_sample s = {0};
            int apart = i >= (two ? 38 : 39);
            double e = apart ? 1.0 : i % 2 ? 1.0 : -1.0;
            s.t = i;
            s.velocity = apart ? -0.5 : 0.5;
            ck_assert_int_eq(fe_residual_map_add(&m, &s, e, e), FE_OK);
        }
        ck_assert_double_eq_tol(fe_residual_map_largest_after(&m, w),
                                two ? 0.95 * sqrt(2.0 * w) : 0.0, 1e-12);
    }
}
END_TEST

/* A caller's own cell (the header exposes fe_residual_cell_add for a
   plot's blocks): three rows, the sums worked by hand, all exact in binary;
   the first row's time and recording kept, the last row's taken.  A NULL
   cell is ignored, as fe_innovations_break(NULL) is (seed 9909's
   locate:600: the guard forced off). */
START_TEST(a_cell_of_the_callers_own_sums_its_rows)
{
    fe_residual_cell c, before;
    memset(&c, 0, sizeof c);
    fe_residual_cell_add(&c, 2.0, 0, 1.0, -0.5);
    fe_residual_cell_add(&c, 3.5, 1, -2.0, 0.25);
    fe_residual_cell_add(&c, 5.0, 1, 3.0, 1.0);
    ck_assert_double_eq(c.n, 3.0);
    ck_assert_double_eq(c.t0, 2.0);
    ck_assert_int_eq(c.pair, 0);
    ck_assert_double_eq(c.t1, 5.0);
    ck_assert_int_eq(c.pair1, 1);
    ck_assert_double_eq(c.sum_at, 10.5);        /* 2 + 3.5 + 5 */
    ck_assert_double_eq(c.sum0, 2.0);           /* 1 - 2 + 3 */
    ck_assert_double_eq(c.sq0, 14.0);           /* 1 + 4 + 9 */
    ck_assert_double_eq(c.sum1, 0.75);          /* -0.5 + 0.25 + 1 */
    ck_assert_double_eq(c.sq1, 1.3125);         /* 0.25 + 0.0625 + 1 */
    memcpy(&before, &c, sizeof c);
    fe_residual_cell_add(NULL, 7.0, 2, 1.0, 1.0);
    ck_assert_mem_eq(&c, &before, sizeof c);
}
END_TEST

START_TEST(residual_map_statistics_by_hand)
{
    /* Two blocks of 10 rows with known sums: the statistics of the
       residual map's tests computed from their formulas. */
    fe_residual_map m;
    fe_located loc[4];
    size_t n;
    const double lo[3] = {0}, hi[3] = {0};
    ck_assert_int_eq(fe_residual_map_init(&m, 3, 30, 0, 0, lo, hi), FE_OK);
    for (int i = 0; i < 30; i++) {
        fe_sample s = {0};
        double e = i % 2 ? 1.0 : -1.0;
        s.t = i;
        if (i >= 20)
            e = i % 2 ? 6.0 : -2.0;     /* block 2: mean 2, mean square 20 */
        ck_assert_int_eq(fe_residual_map_add(&m, &s, e, e), FE_OK);
    }
    /* Mean squares 1, 1, 20: median 1.  Block 2: z = (20 - 1) / sqrt(2 /
       (10 w)), t = 2 / sqrt(1 / (10 w)); with w = 0.5, z = 42.49, t = 4.47,
       both above the bound for 3 places at 0.05 (2.394). */
    ck_assert_int_eq(fe_residual_map_locate(&m, 0.5, 0.05, loc, 4, &n), FE_OK);
    ck_assert_uint_eq(n, 1);
    ck_assert_double_eq_tol(loc[0].z, 19.0 / sqrt(2.0 / 5.0), 1e-12);
    ck_assert_double_eq_tol(loc[0].t, 2.0 / sqrt(1.0 / 5.0), 1e-12);
    ck_assert_double_eq_tol(loc[0].ms_ratio_before, 20.0, 1e-12);
    ck_assert_double_eq_tol(loc[0].p_value, 0.5 * erfc(loc[0].z / sqrt(2.0)), 1e-300);
    /* After the terms, against all 30 rows: mean 2/3, mean square 22/3.
       Block 2: t = (2 - 2/3) / sqrt((22/3) / (10 w)), z = (20 / (22/3) - 1)
       / sqrt(2 / (10 w)); blocks 0 and 1: t = (0 - 2/3) / ..., z = (3/22 -
       1) / ...; the largest is block 2's z. */
    {
        double w = 0.5, ms = 22.0 / 3.0;
        double z2 = (20.0 / ms - 1.0) / sqrt(2.0 / (10 * w));
        ck_assert_double_eq_tol(fe_residual_map_largest_after(&m, w), z2, 1e-12);
        /* At w = 0.01 every statistic is under 1 (block 2's z 0.386, its
           t 0.156), and the largest is still block 2's z. */
        w = 0.01;
        z2 = (20.0 / ms - 1.0) / sqrt(2.0 / (10 * w));
        ck_assert_double_lt(z2, 0.5);
        ck_assert_double_eq_tol(fe_residual_map_largest_after(&m, w), z2, 1e-12);
    }
    /* The bound is two-sided Bonferroni over the 3 places: block 2's z =
       19 sqrt(5 w) crosses b = -Phi^-1(0.05 / 6) at w = (b / 19)^2 / 5
       (its t, 0.15 b there, does not count). */
    {
        double b = -fe_normal_quantile(0.05 / 6.0), w = b * b / (19.0 * 19.0) / 5.0;
        ck_assert_int_eq(fe_residual_map_locate(&m, w * 1.001, 0.05, loc, 4, &n), FE_OK);
        ck_assert_uint_eq(n, 1);
        ck_assert_int_eq(fe_residual_map_locate(&m, w * 0.999, 0.05, loc, 4, &n), FE_OK);
        ck_assert_uint_eq(n, 0);
    }
}
END_TEST

/* Two rows of one time block (of a map of 10 blocks over 20 rows that
   carry a temperature in [lo, hi]), at temperatures temp0 and temp1, each
   with residual `before`: the first is taken, the second refused with
   FE_ENONFINITE and the map left as it was. */
static void second_row_refused(double lo, double hi, double temp0, double temp1, double before)
{
    fe_residual_map m, keep;
    fe_sample s = {0};
    double l[3] = {0, 0, lo}, h[3] = {1, 1, hi};
    ck_assert_int_eq(fe_residual_map_init(&m, 10, 20, 0, FE_ROLE_TEMPERATURE, l, h), FE_OK);
    s.temperature = temp0;
    ck_assert_int_eq(fe_residual_map_add(&m, &s, before, 0.5), FE_OK);
    memcpy(&keep, &m, sizeof m);
    s.t = 1.0;
    s.temperature = temp1;
    ck_assert_int_eq(fe_residual_map_add(&m, &s, before, 0.5), FE_ENONFINITE);
    ck_assert_mem_eq(&m, &keep, sizeof m);
}

START_TEST(residual_map_refusals_at_their_edges)
{
    fe_residual_map m, keep;
    fe_sample s = {0};
    double lo[3] = {0, -1, 10}, hi[3] = {1, 1, 20};
    const unsigned all = FE_ROLE_POSITION | FE_ROLE_VELOCITY | FE_ROLE_TEMPERATURE;
    ck_assert_int_eq(fe_residual_map_init(NULL, 2, 4, 0, 0, lo, hi), FE_EINVAL);
    ck_assert_int_eq(fe_residual_map_init(&m, 1, 100, 0, 0, lo, hi), FE_ESIZE);
    ck_assert_int_eq(fe_residual_map_init(&m, FE_DISCOVER_MAX_BLOCKS + 1, 1000, 0, 0, lo, hi),
                     FE_ESIZE);
    ck_assert_int_eq(fe_residual_map_init(&m, FE_DISCOVER_MAX_BLOCKS, 1000, 0, 0, lo, hi),
                     FE_OK);
    ck_assert_int_eq(fe_residual_map_init(&m, 10, 19, 0, 0, lo, hi), FE_ETOOFEW);
    ck_assert_int_eq(fe_residual_map_init(&m, 10, 20, 0, 0, lo, hi), FE_OK);
    ck_assert_int_eq(fe_residual_map_init(&m, 10, 20, 0, all, NULL, hi), FE_EINVAL);
    hi[2] = 9.0;                        /* lo > hi */
    ck_assert_int_eq(fe_residual_map_init(&m, 10, 20, 0, all, lo, hi), FE_EINVAL);
    /* ... but a variable the rows do not carry is not read */
    ck_assert_int_eq(fe_residual_map_init(&m, 10, 20, 0, FE_ROLE_VELOCITY, lo, hi), FE_OK);
    hi[2] = 10.0;                       /* lo == hi: one band */
    ck_assert_int_eq(fe_residual_map_init(&m, 10, 20, 0, all, lo, hi), FE_OK);
    lo[0] = NAN;
    ck_assert_int_eq(fe_residual_map_init(&m, 10, 20, 0, all, lo, hi), FE_ENONFINITE);
    lo[0] = 0;
    ck_assert_int_eq(fe_residual_map_init(&m, 10, 20, 0, all, lo, hi), FE_OK);
    s.temperature = 10;
    ck_assert_int_eq(fe_residual_map_add(&m, &s, 1.0, 0.5), FE_OK);
    memcpy(&keep, &m, sizeof m);
    ck_assert_int_eq(fe_residual_map_add(&m, &s, NAN, 0.5), FE_ENONFINITE);
    ck_assert_int_eq(fe_residual_map_add(&m, &s, 1.0, INFINITY), FE_ENONFINITE);
    ck_assert_int_eq(fe_residual_map_add(&m, &s, 1e200, 0.5), FE_ENONFINITE);
    s.velocity = NAN;
    ck_assert_int_eq(fe_residual_map_add(&m, &s, 1.0, 0.5), FE_ENONFINITE);
    s.velocity = 0;
    s.t = INFINITY;
    ck_assert_int_eq(fe_residual_map_add(&m, &s, 1.0, 0.5), FE_ENONFINITE);
    ck_assert_int_eq(fe_residual_map_add(NULL, &s, 1.0, 0.5), FE_EINVAL);
    ck_assert_mem_eq(&m, &keep, sizeof m);
    /* A sum past the largest double in a cell other than the time block:
       the temperature bin's sum of temperatures, 1.6e308 twice, while the
       block's sums (of times and residuals) stay small.  Every cell the
       row would enter is checked, not only the first. */
    second_row_refused(1e308, 1.7e308, 1.6e308, 1.6e308, 1.0);
    /* And in the time block alone: two rows of one block, in different
       temperature bins and regions, whose residuals' squares (1.21e308
       each) add up past the largest double only in the block. */
    second_row_refused(0.0, 10.0, 1.0, 9.0, 1.1e154);
    ck_assert_double_eq(fe_residual_map_largest_after(NULL, 1.0), 0.0);
    ck_assert_int_eq(fe_residual_map_init(&m, 10, 20, 0, 0, lo, hi), FE_OK);
    ck_assert_double_eq(fe_residual_map_largest_after(&m, 1.0), 0.0);   /* empty */
}
END_TEST

START_TEST(verdict_and_row_worth)
{
    fe_residual_map m;
    fe_discover_result *r = calloc(1, sizeof *r);
    fe_discover_noise nz;
    ck_assert_ptr_nonnull(r);
    map_noise(&m, 0.0, 0, 0, 0.0);
    /* What a row is worth: n_eff / n, over R when a long range was found,
       clamped to [1e-6, 1]. */
    memset(&nz, 0, sizeof nz);
    nz.n_eff = 250;
    ck_assert_double_eq_tol(fe_discover_row_worth(&nz, 1000), 0.25, 1e-15);
    nz.long_range = 1;
    nz.block_ratio = 5;
    ck_assert_double_eq_tol(fe_discover_row_worth(&nz, 1000), 0.05, 1e-15);
    nz.n_eff = 2000;
    nz.long_range = 0;
    ck_assert_double_eq(fe_discover_row_worth(&nz, 1000), 1.0);
    nz.n_eff = 1e-9;
    ck_assert_double_eq(fe_discover_row_worth(&nz, 1000), 1e-6);
    ck_assert_double_eq(fe_discover_row_worth(NULL, 1000), 1.0);
    /* The verdicts. */
    r->steps = 0;
    ck_assert_int_eq(fe_discover_verdict(r, &m, 0, 0.05), FE_VERDICT_NO_MISMATCH);
    ck_assert_int_eq(fe_discover_verdict(r, &m, 1, 0.05), FE_VERDICT_UNEXPLAINED);
    r->steps = 1;
    r->final.n = 4000;
    r->noise.kind = FE_DISCOVER_NOISE_AR;
    r->noise.n_eff = 4000;
    r->noise.portmanteau_p = 0.000999;
    ck_assert_int_eq(fe_discover_verdict(r, &m, 1, 0.05), FE_VERDICT_NOT_WHITE);
    r->noise.portmanteau_p = 0.001;
    ck_assert_int_eq(fe_discover_verdict(r, &m, 1, 0.05), FE_VERDICT_EXPLAINED);
    /* Probes of the state: one that stands out below alpha leaves a
       function of the state unexplained; at alpha, untested (NaN), or
       with none tested, it does not; without a term named, no probe
       makes a mismatch. */
    r->probes_tested = 7;
    r->probe_p = 0.0499;
    ck_assert_int_eq(fe_discover_verdict(r, &m, 1, 0.05), FE_VERDICT_STATE_LEFT);
    r->probe_p = 0.05;
    ck_assert_int_eq(fe_discover_verdict(r, &m, 1, 0.05), FE_VERDICT_EXPLAINED);
    r->probe_p = NAN;
    ck_assert_int_eq(fe_discover_verdict(r, &m, 1, 0.05), FE_VERDICT_EXPLAINED);
    r->probes_tested = 0;
    r->probe_p = 0.0;
    ck_assert_int_eq(fe_discover_verdict(r, &m, 1, 0.05), FE_VERDICT_EXPLAINED);
    r->probes_tested = 7;
    r->steps = 0;
    ck_assert_int_eq(fe_discover_verdict(r, &m, 0, 0.05), FE_VERDICT_NO_MISMATCH);
    r->steps = 1;
    r->probe_p = 0.0499;                    /* the whiteness test comes first */
    r->noise.portmanteau_p = 0.000999;
    ck_assert_int_eq(fe_discover_verdict(r, &m, 1, 0.05), FE_VERDICT_NOT_WHITE);
    r->probes_tested = 0;
    /* Held-out rows predicted worse with the terms than without: not
       explained; equal, or nothing held out (NaN), explained. */
    r->noise.portmanteau_p = 0.5;
    r->baseline.heldout_rms = 2.0;
    r->final.heldout_n = 100;
    r->final.heldout_rms = nextafter(2.0, 3.0);
    ck_assert_int_eq(fe_discover_verdict(r, &m, 1, 0.05), FE_VERDICT_HELDOUT_WORSE);
    ck_assert_int_eq(fe_discover_heldout_worse(r), 1);
    ck_assert_int_eq(fe_discover_heldout_worse(NULL), 0);
    r->final.heldout_rms = 2.0;
    ck_assert_int_eq(fe_discover_verdict(r, &m, 1, 0.05), FE_VERDICT_EXPLAINED);
    ck_assert_int_eq(fe_discover_heldout_worse(r), 0);
    r->final.heldout_rms = 3.0;
    r->probes_tested = 7;                   /* a probe comes first */
    ck_assert_int_eq(fe_discover_verdict(r, &m, 1, 0.05), FE_VERDICT_STATE_LEFT);
    r->probes_tested = 0;
    r->final.heldout_n = 0;
    r->final.heldout_rms = NAN;
    r->baseline.heldout_rms = NAN;
    ck_assert_int_eq(fe_discover_verdict(r, &m, 1, 0.05), FE_VERDICT_EXPLAINED);
    ck_assert_str_eq(fe_verdict_text(FE_VERDICT_HELDOUT_WORSE),
                     "mismatch not explained by the catalog");
    ck_assert_ptr_nonnull(strstr(fe_verdict_why(FE_VERDICT_HELDOUT_WORSE), "held out"));
    r->noise.portmanteau_p = 0.000999;
    ck_assert_str_eq(fe_verdict_text(FE_VERDICT_STATE_LEFT),
                     "mismatch not explained by the catalog");
    ck_assert_ptr_nonnull(strstr(fe_verdict_why(FE_VERDICT_STATE_LEFT), "function of the state"));
    r->noise.kind = FE_DISCOVER_NOISE_BATCH;
    r->noise.portmanteau_p = 0.0;
    ck_assert_int_eq(fe_discover_verdict(r, &m, 1, 0.05), FE_VERDICT_EXPLAINED);
    /* A residual after the terms that still has the step: out of line. */
    {
        fe_residual_map s;
        fe_rng rng = fe_rng_seed(3);
        const double lo[3] = {0}, hi[3] = {0};
        ck_assert_int_eq(fe_residual_map_init(&s, 20, 4000, 0, 0, lo, hi), FE_OK);
        for (int i = 0; i < 4000; i++) {
            fe_sample x = {0};
            double e = fe_rng_normal(&rng) + (i >= 2000 && i < 2200 ? 0.6 : 0.0);
            x.t = i;
            ck_assert_int_eq(fe_residual_map_add(&s, &x, e, e), FE_OK);
        }
        ck_assert_int_eq(fe_discover_verdict(r, &s, 1, 0.05), FE_VERDICT_OUT_OF_LINE);
        /* ... unless the noise model says the rows are worth a tenth each */
        r->noise.n_eff = 400;
        ck_assert_int_eq(fe_discover_verdict(r, &s, 1, 0.05), FE_VERDICT_EXPLAINED);
    }
    ck_assert_str_eq(fe_verdict_text(FE_VERDICT_EXPLAINED), "mismatch explained");
    ck_assert_str_eq(fe_verdict_text(FE_VERDICT_NO_MISMATCH), "no significant mismatch");
    ck_assert_str_eq(fe_verdict_text(FE_VERDICT_OUT_OF_LINE),
                     "mismatch not explained by the catalog");
    ck_assert_ptr_null(fe_verdict_why(FE_VERDICT_EXPLAINED));
    ck_assert_ptr_nonnull(strstr(fe_verdict_why(FE_VERDICT_NOT_WHITE), "not white"));
    ck_assert_int_eq(fe_discover_verdict(NULL, &m, 1, 0.05), FE_VERDICT_NO_MISMATCH);
    free(r);
}
END_TEST

START_TEST(located_regions_in_json_and_words)
{
    fe_located l;
    char json[1024], words[64];
    memset(&l, 0, sizeof l);
    l.region = FE_REGION_SPEED;
    l.lo = 0.5;
    l.hi = 1;
    l.n = 120;
    l.z = 1.0;
    l.t = -4.25;
    l.test = "residual_mean";
    l.p_value = 2.1e-5;
    l.mean_before = 0.1;
    l.mean_after = 0.1 + 0.2;           /* 0.30000000000000004: 17 digits */
    ck_assert_int_eq(fe_region_describe(&l, words, sizeof words), FE_OK);
    ck_assert_str_eq(words, "|v| 0.5 to 1");
    ck_assert_int_eq(fe_region_describe(&l, words, 5), FE_ESIZE);
    /* A buffer of one byte holds only the empty string: too small, and
       terminated; one of none is not written. */
    words[0] = 'x';
    ck_assert_int_eq(fe_region_describe(&l, words, 1), FE_ESIZE);
    ck_assert_int_eq(words[0], '\0');
    words[0] = 'x';
    ck_assert_int_ne(fe_region_describe(&l, words, 0), FE_OK);
    ck_assert_int_eq(words[0], 'x');
    ck_assert_int_eq(fe_region_describe(&l, words, 13), FE_OK);   /* 12 characters and NUL */
    ck_assert_str_eq(words, "|v| 0.5 to 1");
    ck_assert_int_eq(fe_region_describe(&l, words, 12), FE_ESIZE);
    ck_assert_int_eq(fe_located_json(&l, json, sizeof json), FE_OK);
    ck_assert_ptr_nonnull(strstr(json, "{\"kind\": \"state\", \"variable\": \"speed\", "
                                       "\"region\": \"|v| 0.5 to 1\", \"rows\": 120, "
                                       "\"statistic\": -4.25, \"test\": \"residual_mean\", "
                                       "\"p_value\": 2.1e-05"));
    ck_assert_ptr_nonnull(strstr(json, "\"mean_residual_after\": 0.30000000000000004"));
    ck_assert_ptr_null(strstr(json, "nis"));
    l.region = FE_REGION_TEMPERATURE;
    l.lo = 20;
    l.hi = 22.5;
    ck_assert_int_eq(fe_region_describe(&l, words, sizeof words), FE_OK);
    ck_assert_str_eq(words, "20 to 22.5");
    ck_assert_str_eq(fe_region_variable(FE_REGION_POSITION_POSITIVE), "position");
    ck_assert_str_eq(fe_region_variable((fe_region)99), "");
}
END_TEST

START_TEST(a_region_of_two_rows_is_tested_of_one_is_not)
{
    /* The residual map tests a region of at least 2 rows: 60 rows in 3
       blocks, velocity +-0.5 with residual +-1, except rows at velocity 0
       with residual 8.  Two such rows (10 and 41): the region v = 0 has
       n = 2, sum 16, sum of squares 128, against all rows' mean 16/60 and
       mean square 186/60; with worth 1, t = (8 - 16/60) / sqrt((186/60) /
       2) and z = (64 / (186/60) - 1) / sqrt(2 / 2), both far above the
       bound for 3 + 7 places.  One such row (10): the region has n = 1
       and is not tested. */
    const double lo[3] = {0, -0.5, 0}, hi[3] = {0, 0.5, 0};
    for (int two = 0; two < 2; two++) {
        fe_residual_map m;
        fe_located loc[16];
        size_t n, found = 0;
        ck_assert_int_eq(fe_residual_map_init(&m, 3, 60, 0, FE_ROLE_VELOCITY, lo, hi), FE_OK);
        ck_assert_uint_eq(m.nregions, 7);
        for (int i = 0; i < 60; i++) {
            fe_sample s = {0};
            int zero = i == 10 || (two && i == 41);
            double e = zero ? 8.0 : i % 2 ? 1.0 : -1.0;
            if (!two && i == 41)
                e = 1.0;
            s.t = i;
            s.velocity = zero ? 0.0 : i % 2 ? 0.5 : -0.5;
            ck_assert_int_eq(fe_residual_map_add(&m, &s, e, e), FE_OK);
        }
        ck_assert_int_eq(fe_residual_map_locate(&m, 1.0, 0.05, loc, 16, &n), FE_OK);
        ck_assert_uint_le(n, 16);
        for (size_t i = 0; i < n; i++) {
            double all_sum, msall, ws;
            if (loc[i].region != FE_REGION_VELOCITY_ZERO)
                continue;
            found++;
            ck_assert_double_eq(loc[i].n, 2.0);
            all_sum = 16.0;
            msall = (58.0 + 128.0) / 60.0;
            ws = 2.0;
            ck_assert_double_eq_tol(loc[i].t, (8.0 - all_sum / 60.0) / sqrt(msall / ws), 1e-12);
            ck_assert_double_eq_tol(loc[i].z, (64.0 / msall - 1.0) / sqrt(2.0 / ws), 1e-12);
            ck_assert_double_eq_tol(loc[i].mean_before, 8.0, 1e-15);
        }
        /* lo and hi are a band's bounds, and 0 for every other place. */
        for (size_t i = 0; i < n; i++)
            if (loc[i].region != FE_REGION_SPEED && loc[i].region != FE_REGION_TEMPERATURE) {
                ck_assert_double_eq(loc[i].lo, 0.0);
                ck_assert_double_eq(loc[i].hi, 0.0);
            }
        ck_assert_uint_eq(found, two ? 1 : 0);
    }
}
END_TEST

/* Issue 20: the innovation fold's shape and reports, and both locates'
   levels, at their edges: FE_DISCOVER_MAX_BLOCKS blocks, 2 reports a
   block and the last report as row0 are taken; a NIS of 0 is folded and
   -DBL_TRUE_MIN refused unchanged; alpha one double inside (0, 1) and
   worth 1 and DBL_TRUE_MIN are taken, worth one double above 1 refused. */
START_TEST(shapes_reports_and_levels_at_their_edges)
{
    fe_innovations inn, before;
    fe_residual_map m;
    fe_located out[8];
    fe_sample s = {0};
    double w = 1.0;
    const double lo[3] = {0, -1, 0}, hi[3] = {1, 1, 1};
    fe_kalman_report r = {1, 0.0, 0, NULL, &w, NULL};
    size_t n = 99;
    ck_assert_int_eq(fe_innovations_init(&inn, FE_DISCOVER_MAX_BLOCKS,
                                         2 * FE_DISCOVER_MAX_BLOCKS - 1, 0), FE_ETOOFEW);
    ck_assert_int_eq(fe_innovations_init(&inn, FE_DISCOVER_MAX_BLOCKS,
                                         2 * FE_DISCOVER_MAX_BLOCKS, 0), FE_OK);
    ck_assert_int_eq(fe_innovations_init(&inn, 2, 4, 0), FE_OK);
    ck_assert_int_eq(fe_innovations_init(&inn, 10, 20, 0), FE_OK);
    ck_assert_int_eq(fe_innovations_init(&inn, 10, 20, 20), FE_ESIZE);
    ck_assert_int_eq(fe_innovations_init(&inn, 10, 20, 19), FE_OK);   /* the last report */
    ck_assert_int_eq(fe_innovations_add(&inn, 0.0, &r), FE_OK);      /* NIS 0 */
    ck_assert_uint_eq(inn.n, 1);
    ck_assert_int_eq(fe_innovations_add(&inn, 1.0, &r), FE_ESIZE);   /* past the total */
    ck_assert_int_eq(fe_innovations_init(&inn, 2, 40, 0), FE_OK);
    for (int i = 0; i < 40; i++) {
        r.nis = i == 5 ? 40.0 : 1.0;
        ck_assert_int_eq(fe_innovations_add(&inn, (double)i, &r), FE_OK);
        if (i == 0) {
            before = inn;
            r.nis = -DBL_TRUE_MIN;
            ck_assert_int_eq(fe_innovations_add(&inn, 0.5, &r), FE_EINVAL);
            ck_assert_mem_eq(&inn, &before, sizeof inn);
        }
    }
    ck_assert_int_eq(fe_innovations_locate(&inn, DBL_TRUE_MIN, out, 8, &n), FE_OK);
    ck_assert_uint_eq(n, 0);                        /* nothing at so strict a level */
    ck_assert_int_eq(fe_innovations_locate(&inn, nextafter(1.0, 0.0), out, 8, &n), FE_OK);
    ck_assert_uint_ge(n, 1);                        /* the block with NIS 40 */
    ck_assert_int_eq(fe_residual_map_init(&m, 2, 4, 0, FE_ROLE_VELOCITY, lo, hi), FE_OK);
    for (int i = 0; i < 4; i++) {
        s.t = i;
        s.velocity = i % 2 ? 0.5 : -0.5;
        ck_assert_int_eq(fe_residual_map_add(&m, &s, i % 2 ? 1.0 : -1.0, 0.0), FE_OK);
    }
    ck_assert_int_eq(fe_residual_map_locate(&m, nextafter(1.0, 2.0), 0.05, out, 8, &n),
                     FE_EINVAL);
    ck_assert_int_eq(fe_residual_map_locate(&m, 1.0, 0.05, out, 8, &n), FE_OK);
    ck_assert_int_eq(fe_residual_map_locate(&m, DBL_TRUE_MIN, 0.05, out, 8, &n), FE_OK);
    ck_assert_uint_eq(n, 0);                        /* rows worth nothing locate nothing */
    ck_assert_int_eq(fe_residual_map_locate(&m, 1.0, DBL_TRUE_MIN, out, 8, &n), FE_OK);
    ck_assert_int_eq(fe_residual_map_locate(&m, 1.0, nextafter(1.0, 0.0), out, 8, &n), FE_OK);
}
END_TEST

Suite *fe_locate_suite(void)
{
    Suite *s = suite_create("locate");
    TCase *t = tcase_create("locate");
    tcase_set_timeout(t, 300);
    tcase_add_test(t, block_statistics_match_a_direct_computation);
    tcase_add_test(t, a_window_reports_its_largest_nis_statistic);
    tcase_add_test(t, the_largest_statistic_after_the_terms_looks_at_the_regions);
    tcase_add_test(t, cells_of_two_rows_are_tested_and_of_one_not);
    tcase_add_test(t, merge_of_consecutive_parts_equals_whole);
    tcase_add_test(t, a_row_joins_every_region_it_lies_in);
    tcase_add_test(t, the_lag_one_statistic_is_a_mean_product_over_a_mean_square);
    tcase_add_test(t, a_window_without_pairs_has_no_autocorrelation_figure);
    tcase_add_test(t, refusals_leave_the_accumulation_unchanged);
    tcase_add_test(t, huge_values_are_refused_and_nothing_infinite_escapes);
    tcase_add_test(t, a_lag_one_sum_that_overflows_is_refused);
    tcase_add_test(t, a_block_sum_of_squares_that_overflows_is_refused);
    tcase_add_test(t, the_speed_bands_reach_the_faster_end_of_either_sign);
    tcase_add_test(t, arguments_merges_that_do_not_fit_and_json);
    tcase_add_test(t, merge_into_an_empty_part_is_the_other_part);
    tcase_add_test(t, json_of_every_length_is_whole_or_refused);
    tcase_add_test(t, blocks_without_pairs_have_no_autocorrelation_test);
    tcase_add_test(t, a_missed_drag_is_located_where_it_acts);
    tcase_add_test(t, a_right_model_locates_nothing);
    tcase_add_test(t, residual_map_cells_equal_sums_over_the_rows);
    tcase_add_test(t, residual_map_merge_of_parts_equals_whole);
    tcase_add_test(t, a_part_numbers_its_recordings_from_zero);
    tcase_add_test(t, residual_map_locates_a_window_and_a_region);
    tcase_add_test(t, residual_map_statistics_by_hand);
    tcase_add_test(t, a_cell_of_the_callers_own_sums_its_rows);
    tcase_add_test(t, residual_map_refusals_at_their_edges);
    tcase_add_test(t, verdict_and_row_worth);
    tcase_add_test(t, located_regions_in_json_and_words);
    tcase_add_test(t, a_region_of_two_rows_is_tested_of_one_is_not);
    tcase_add_test(t, shapes_reports_and_levels_at_their_edges);
    suite_add_tcase(s, t);
    return s;
}
