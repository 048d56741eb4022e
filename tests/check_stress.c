/* SPDX-License-Identifier: MIT */
/* Numerical stress: ill-conditioned and degenerate data.  Planar and
   collinear samples, a sphere of radius 1 at 1e8 from the origin, radii
   1e-8 and 1e8, denormal values, near-singular Kalman denominators,
   rank-deficient least squares, Levenberg-Marquardt from absurd starts.
   Each returns a correct answer or a named error; no NaN or infinity is
   ever returned in a result; after an error the accumulation is unchanged
   (compared byte for byte). */
#include <float.h>

#include "foldest.h"
#include "testutil.h"

static int all_finite(const double *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

/* Every number a fit returns is finite, whether it was accepted or not. */
static void assert_fit_finite(const fe_sphere_fit *f)
{
    ck_assert_msg(all_finite(f->offset, 3) && all_finite(f->matrix, 9) && isfinite(f->radius)
                  && all_finite(f->axes, 3) && all_finite(f->params, FE_SPHERE_MAX_PARAMS)
                  && all_finite(f->se, FE_SPHERE_MAX_PARAMS)
                  && all_finite(f->cov, FE_SPHERE_MAX_PARAMS * FE_SPHERE_MAX_PARAMS)
                  && isfinite(f->rss) && isfinite(f->rms_percent) && isfinite(f->coverage)
                  && isfinite(f->planarity),
                  "a non-finite number in a fit (refusal %s)", fe_sphere_refusal_string(f->refusal));
}

/* Samples on a sphere of centre c and radius r (noise relative to r). */
static void sphere_points(double *x, size_t n, const double c[3], double r, double noise,
                          uint64_t seed)
{
    const double rr[3] = {r, r, r};
    fe_test_ellipsoid_points(x, n, c, rr, noise * r, seed);
}

static int fit_all_three_ways(const double *x, size_t n, fe_sphere_model model,
                              fe_sphere_fit *f)
{
    fe_quadric q;
    fe_sphere_fit s;
    int rc, rs;
    ck_assert_int_eq(fe_quadric_init(&q, NULL), FE_OK);
    for (size_t i = 0; i < n; i++)
        ck_assert_int_eq(fe_quadric_add(&q, x + 3 * i), FE_OK);
    rc = fe_sphere_fit_moments(&q, model, NULL, f);
    assert_fit_finite(f);
    rs = fe_sphere_fit_stored(x, n, model, NULL, &s);
    assert_fit_finite(&s);
    ck_assert_msg(rs == rc, "moments say %s, stored samples %s", fe_strerror(rc), fe_strerror(rs));
    if (rc == FE_OK)
        for (int j = 0; j < 3; j++)
            FE_ASSERT_REL(s.offset[j] - f->offset[j] + f->radius, f->radius, 1e-6);
    return rc;
}

START_TEST(planar_and_collinear_samples_are_refused_by_name)
{
    enum { N = 400 };
    static double x[3 * N];
    fe_rng g = fe_rng_seed(3);
    for (int m = 0; m < 3; m++) {
        fe_sphere_fit f;
        /* A circle in the plane z = 7 (planar). */
        for (size_t i = 0; i < N; i++) {
            double a = 6.283185307179586 * fe_rng_uniform(&g);
            x[3 * i] = 100 + 50 * cos(a);
            x[3 * i + 1] = -20 + 50 * sin(a);
            x[3 * i + 2] = 7;
        }
        ck_assert_int_ne(fit_all_three_ways(x, N, (fe_sphere_model)m, &f), FE_OK);
        ck_assert_int_eq(f.refusal, FE_SPHERE_PLANAR);
        /* Points on a line. */
        for (size_t i = 0; i < N; i++) {
            double t = fe_rng_normal(&g);
            x[3 * i] = 1 + t;
            x[3 * i + 1] = 2 + 2 * t;
            x[3 * i + 2] = 3 - t;
        }
        ck_assert_int_ne(fit_all_three_ways(x, N, (fe_sphere_model)m, &f), FE_OK);
        ck_assert_int_eq(f.refusal, FE_SPHERE_PLANAR);
        /* One point repeated. */
        for (size_t i = 0; i < N; i++)
            x[3 * i] = 5, x[3 * i + 1] = 6, x[3 * i + 2] = 7;
        ck_assert_int_ne(fit_all_three_ways(x, N, (fe_sphere_model)m, &f), FE_OK);
        ck_assert_int_ne(f.refusal, FE_SPHERE_ACCEPTED);
    }
}
END_TEST

START_TEST(sphere_far_from_the_origin_and_at_extreme_scales)
{
    enum { N = 2000 };
    static double x[3 * N];
    /* centre offset, radius: 1e8 with radius 1; radii 1e-8 and 1e8; both. */
    const double cases[][4] = {
        {1e8, -1e8, 1e8, 1.0}, {0, 0, 0, 1e-8}, {0, 0, 0, 1e8}, {3e-8, -1e-8, 2e-8, 1e-8},
        {1e10, 2e10, -3e10, 1e8}, {1e3, 1e3, 1e3, 1e-3},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        fe_sphere_fit f;
        int rc;
        sphere_points(x, N, cases[k], cases[k][3], 1e-4, 11 + k);
        rc = fit_all_three_ways(x, N, FE_FIT_SPHERE, &f);
        ck_assert_msg(rc == FE_OK, "case %zu: %s (%s)", k, fe_strerror(rc),
                      fe_sphere_refusal_string(f.refusal));
        FE_ASSERT_REL(f.radius, cases[k][3], 1e-4);
        for (int j = 0; j < 3; j++)     /* the centre to 1e-4 of the radius */
            ck_assert_msg(fabs(f.offset[j] - cases[k][j]) <= 1e-4 * cases[k][3],
                          "case %zu axis %d: centre %.17g, want %.17g", k, j, f.offset[j],
                          cases[k][j]);
        rc = fit_all_three_ways(x, N, FE_FIT_ELLIPSOID, &f);
        ck_assert_msg(rc == FE_OK, "case %zu ellipsoid: %s (%s)", k, fe_strerror(rc),
                      fe_sphere_refusal_string(f.refusal));
        FE_ASSERT_REL(f.radius, cases[k][3], 1e-3);
    }
}
END_TEST

START_TEST(exact_data_converges)
{
    /* Samples with no noise but the rounding of printing them with four
       decimals: the cost streamed from the moments is at its noise floor,
       where steps of 1e-14 "raise" it.  The fit must end converged (it
       used to end FE_SPHERE_NO_CONVERGENCE for the axial model). */
    enum { N = 100 };
    double x[3 * N];
    fe_rng g = fe_rng_seed(5);
    for (int m = 0; m < 3; m++) {
        fe_sphere_fit f;
        for (size_t i = 0; i < N; i++) {
            double v[3];
            char text[96];
            fe_rng_unit_vector(&g, v);
            snprintf(text, sizeof text, "%.4f %.4f %.4f", 20 + 400 * v[0], -10 + 380 * v[1],
                     5 + 420 * v[2]);
            ck_assert_int_eq(sscanf(text, "%lf %lf %lf", &x[3 * i], &x[3 * i + 1], &x[3 * i + 2]), 3);
        }
        ck_assert_msg(fit_all_three_ways(x, N, (fe_sphere_model)m, &f) == FE_OK || m == 0,
                      "%s: %s", fe_sphere_model_name(m), fe_sphere_refusal_string(f.refusal));
        if (m > 0) {
            ck_assert_double_eq_tol(f.offset[0], 20, 1e-3);
            ck_assert_double_eq_tol(f.offset[1], -10, 1e-3);
            ck_assert_double_eq_tol(f.offset[2], 5, 1e-3);
        }
    }
}
END_TEST

START_TEST(denormals_and_extremes_in_the_moment_fold)
{
    fe_meanvar a = FE_MEANVAR_EMPTY, before;
    fe_quadric q, qb;
    const double tiny = 4.9406564584124654e-324, sub = 2.2250738585072009e-310;
    const double values[] = {tiny, -tiny, sub, 0.0, -0.0, DBL_MIN, sub, tiny};
    for (size_t i = 0; i < sizeof values / sizeof values[0]; i++)
        ck_assert_int_eq(fe_meanvar_add(&a, values[i]), FE_OK);
    ck_assert(isfinite(fe_meanvar_mean(&a)) && fe_meanvar_variance(&a) >= 0.0);
    ck_assert(fabs(fe_meanvar_mean(&a)) <= DBL_MIN);
    /* Values whose squares overflow: refused, accumulation unchanged. */
    ck_assert_int_eq(fe_meanvar_add(&a, 1e150), FE_OK);      /* squares 1e300: fine */
    before = a;
    ck_assert_int_eq(fe_meanvar_add(&a, -1.7e308), FE_ENONFINITE);
    ck_assert_mem_eq(&a, &before, sizeof a);
    /* Moments of denormal samples: the fold accepts them and the fit
       refuses to call them a sphere, by name, with finite numbers. */
    ck_assert_int_eq(fe_quadric_init(&q, NULL), FE_OK);
    for (int i = 0; i < 50; i++) {
        double x[3] = {sub * (i % 3), tiny * (i % 5), -sub * (i % 7)};
        ck_assert_int_eq(fe_quadric_add(&q, x), FE_OK);
    }
    ck_assert(all_finite(q.m, FE_QUADRIC_MOMENTS));
    {
        fe_sphere_fit f;
        int rc = fe_sphere_fit_moments(&q, FE_FIT_SPHERE, NULL, &f);
        assert_fit_finite(&f);
        if (rc != FE_OK)
            ck_assert_msg(f.refusal != FE_SPHERE_ACCEPTED, "%s without a refusal", fe_strerror(rc));
    }
    /* A sample whose fourth powers overflow: refused, unchanged. */
    qb = q;
    {
        double x[3] = {1e100, 0, 0};
        ck_assert_int_eq(fe_quadric_add(&q, x), FE_ENONFINITE);
        ck_assert_mem_eq(&q, &qb, sizeof q);
    }
}
END_TEST

/* One Kalman update with prior variance p0 and noise Z on a scalar state
   observed with gain A: finite results or a named error, state unchanged. */
static void kalman_case(double p0, double A, double Z, int fast)
{
    double mem[64], snap[2], nu, w, D;
    fe_kalman k;
    fe_kalman_obs o;
    fe_kalman_report r = {0, 0, 0, &nu, &w, &D};
    double z = 1.0;
    int rc;
    ck_assert_int_eq(fe_kalman_init(&k, 1, 1, mem, 64), FE_OK);
    rc = fe_kalman_set_prior_scaled(&k, NULL, p0);
    if (rc != FE_OK)
        return;
    o.b = 1;
    o.A = &A;
    o.z = &z;
    o.Z = &Z;
    snap[0] = k.x[0];
    snap[1] = k.P[0];
    rc = fast ? fe_kalman_update_fast(&k, &o, &r) : fe_kalman_update(&k, &o, &r);
    if (rc == FE_OK) {
        ck_assert_msg(isfinite(k.x[0]) && isfinite(k.P[0]) && k.P[0] >= 0.0,
                      "p0 %g A %g Z %g fast %d: x %g P %g", p0, A, Z, fast, k.x[0], k.P[0]);
        ck_assert_msg(isfinite(r.nis) && r.nis >= 0.0 && isfinite(r.log_det_D),
                      "p0 %g A %g Z %g fast %d: nis %g log det D %g", p0, A, Z, fast, r.nis,
                      r.log_det_D);
        ck_assert_uint_eq(k.count, 1);
    } else {
        ck_assert_msg(rc == FE_ENOTPD || rc == FE_ENONFINITE, "p0 %g A %g Z %g: %s", p0, A, Z,
                      fe_strerror(rc));
        ck_assert(memcmp(&snap[0], k.x, sizeof(double)) == 0);
        ck_assert(memcmp(&snap[1], k.P, sizeof(double)) == 0);
        ck_assert_uint_eq(k.count, 0);
    }
}

START_TEST(near_singular_kalman_denominators)
{
    const double p0s[] = {0.0, 5e-324, 1e-300, 1.0, 1e300};
    const double As[] = {0.0, 5e-324, 1e-160, 1.0, 1e160, 1e300};
    const double Zs[] = {0.0, -1e-300, 5e-324, 1e-300, 1e-16, 1.0, 1e300};
    for (size_t i = 0; i < sizeof p0s / sizeof *p0s; i++)
        for (size_t j = 0; j < sizeof As / sizeof *As; j++)
            for (size_t l = 0; l < sizeof Zs / sizeof *Zs; l++)
                for (int fast = 0; fast < 2; fast++)
                    kalman_case(p0s[i], As[j], Zs[l], fast);
    /* The singular cases: no noise and no prior uncertainty. */
    {
        double mem[64], A = 1, z = 2, Z = 0, nu, w, D;
        fe_kalman k;
        fe_kalman_obs o = {1, &A, &z, &Z};
        fe_kalman_report r = {0, 0, 0, &nu, &w, &D};
        ck_assert_int_eq(fe_kalman_init(&k, 1, 1, mem, 64), FE_OK);
        ck_assert_int_eq(fe_kalman_set_prior_scaled(&k, NULL, 0.0), FE_OK);
        ck_assert_int_eq(fe_kalman_update(&k, &o, &r), FE_ENOTPD);
        ck_assert_int_eq(fe_kalman_update_fast(&k, &o, &r), FE_ENOTPD);
    }
}
END_TEST

START_TEST(rank_deficient_least_squares)
{
    enum { P = 4 };
    double g[(P + 1) * (P + 1)], x[P], work[(P + 1) * (P + 1)], rss = -1, score[P];
    size_t base[1] = {0}, cand[P] = {0, 1, 2, 3};
    double sw[64];
    fe_lsq a;
    fe_rng rng = fe_rng_seed(9);
    ck_assert_int_eq(fe_lsq_init(&a, P, g), FE_OK);
    /* Column 2 = column 0 + column 1; column 3 = 1e8 + tiny noise. */
    for (int i = 0; i < 200; i++) {
        double u = fe_rng_normal(&rng), v = fe_rng_normal(&rng);
        double j[P] = {u, v, u + v, 1e8 + 1e-9 * fe_rng_normal(&rng)};
        ck_assert_int_eq(fe_lsq_add(&a, j, 2 * u - v, 1.0), FE_OK);
    }
    for (int i = 0; i < P; i++)
        x[i] = 12345.0;
    ck_assert_int_eq(fe_lsq_solve(&a, NULL, 3, x, &rss, NULL, work), FE_ESINGULAR);
    ck_assert(x[0] == 12345.0 && rss == -1);   /* nothing written */
    {
        size_t cols[2] = {0, 1};
        ck_assert_int_eq(fe_lsq_solve(&a, cols, 2, x, &rss, NULL, work), FE_OK);
        FE_ASSERT_REL(x[0], 2.0, 1e-9);
        FE_ASSERT_REL(x[1], -1.0, 1e-9);
        /* Exact data: the residual is rounding, relative to r'r. */
        ck_assert(rss >= 0 && rss <= 1e-12 * fe_lsq_gram(&a, P, P));
    }
    /* Scores: the dependent candidate scores 0, the others are finite. */
    {
        size_t b2[2] = {0, 1};
        ck_assert_int_eq(fe_lsq_scores(&a, b2, 2, cand, P, score, NULL, NULL, sw), FE_OK);
        ck_assert(all_finite(score, P));
        ck_assert(score[2] == 0.0);
    }
    ck_assert_int_eq(fe_lsq_scores(&a, base, 1, cand, P, score, NULL, NULL, sw), FE_OK);
    ck_assert(all_finite(score, P));
    /* Schur: a local block that the rows do not determine. */
    {
        double mem[256], sx[8], swk[64], jg[1], jl[2];
        fe_schur s;
        ck_assert_int_eq(fe_schur_init(&s, 1, 2, 2, mem), FE_OK);
        for (int i = 0; i < 50; i++) {
            jg[0] = fe_rng_normal(&rng);
            jl[0] = fe_rng_normal(&rng);
            jl[1] = 3 * jl[0];                  /* rank one block */
            ck_assert_int_eq(fe_schur_add(&s, jg, (size_t)(i % 2), jl, 1.0, 1.0), FE_OK);
        }
        ck_assert_int_eq(fe_schur_solve(&s, 0.0, sx, NULL, swk), FE_ESINGULAR);
        /* Damping makes it solvable, and the answer is finite. */
        ck_assert_int_eq(fe_schur_solve(&s, 1e-3, sx, NULL, swk), FE_OK);
        ck_assert(all_finite(sx, 5));
    }
}
END_TEST

/* y = a exp(b t) at t = 0..1: residuals and Jacobian. */
static int expfit(const double *x, fe_lm_sink *sink, void *ctx)
{
    (void)ctx;
    for (int i = 0; i <= 20; i++) {
        double t = i / 20.0, e = exp(x[1] * t), y = 2.0 * exp(-1.5 * t);
        double jg[2] = {e, x[0] * t * e};
        int rc = fe_lm_emit(sink, x[0] * e - y, 1.0, jg, FE_SCHUR_NONE, NULL);
        if (rc != FE_OK)
            return rc;
    }
    return FE_OK;
}

START_TEST(levenberg_marquardt_from_absurd_starts)
{
    const fe_lm_problem prob = {2, 0, 0, expfit, NULL};
    const double starts[][2] = {
        {1.0, 1.0}, {1e8, -1e8}, {-1e12, 3.0}, {0.0, 700.0}, {1e-300, 1e-300},
        {1e300, 1.0}, {0.0, 0.0}, {NAN, 1.0}, {INFINITY, 0.0},
    };
    double work[64];
    ck_assert_uint_le(fe_lm_work(&prob, FE_LM_DENSE), 64);
    for (size_t k = 0; k < sizeof starts / sizeof starts[0]; k++) {
        double x[2] = {starts[k][0], starts[k][1]};
        fe_lm_result res;
        int rc = fe_lm_solve(&prob, FE_LM_DENSE, NULL, x, work, NULL, NULL, &res);
        if (rc == FE_OK) {
            /* Converged: to the answer, or at least to a finite point. */
            ck_assert(all_finite(x, 2) && isfinite(res.cost));
            if (res.cost < 1e-12) {
                FE_ASSERT_REL(x[0], 2.0, 1e-6);
                FE_ASSERT_REL(x[1], -1.5, 1e-6);
            }
        } else {
            ck_assert_msg(rc == FE_ENOCONV || rc == FE_ENONFINITE || rc == FE_EINVAL,
                          "start %zu: %s", k, fe_strerror(rc));
            if (rc == FE_ENONFINITE && !all_finite(starts[k], 2))
                continue;               /* refused at the start: x is the caller's */
            ck_assert_msg(all_finite(x, 2), "start %zu: x = %g, %g after %s", k, x[0], x[1],
                          fe_strerror(rc));
        }
    }
    /* From a reasonable start it reaches the answer. */
    {
        double x[2] = {1.0, 0.0};
        ck_assert_int_eq(fe_lm_solve(&prob, FE_LM_DENSE, NULL, x, work, NULL, NULL, NULL), FE_OK);
        FE_ASSERT_REL(x[0], 2.0, 1e-8);
        FE_ASSERT_REL(x[1], -1.5, 1e-8);
    }
}
END_TEST

START_TEST(overflowing_rows_are_refused_whole)
{
    /* Finite values whose products overflow (found by the fuzzer): the row
       is refused and not one double of the accumulation changes; large
       values whose products are finite take the careful path and count. */
    enum { M = 2, K = 4, CAP = 8192 };
    static double mem[CAP], snap[CAP];
    double phi[M];
    size_t nd = fe_discover_acc_doubles(M, K);
    fe_discover_acc a, as;
    ck_assert_uint_le(nd, CAP);
    ck_assert_int_eq(fe_discover_acc_init(&a, M, K, 100, 0, mem, nd), FE_OK);
    phi[0] = 1.0, phi[1] = 2.0;
    ck_assert_int_eq(fe_discover_add(&a, phi, 0.5), FE_OK);
    phi[0] = 1e120, phi[1] = -3e110;                    /* squares 1e240: fine */
    ck_assert_int_eq(fe_discover_add(&a, phi, 1e105), FE_OK);
    ck_assert(all_finite(mem, nd));
    memcpy(snap, mem, nd * sizeof *mem);
    as = a;
    phi[0] = 1e200;                                     /* square overflows */
    ck_assert_int_eq(fe_discover_add(&a, phi, 1.0), FE_ENONFINITE);
    ck_assert_mem_eq(mem, snap, nd * sizeof *mem);
    ck_assert_mem_eq(&a, &as, sizeof a);
    /* The caller drops the row and carries on. */
    phi[0] = 3.0, phi[1] = 4.0;
    ck_assert_int_eq(fe_discover_add(&a, phi, 1.0), FE_OK);
    ck_assert(all_finite(mem, nd));
    ck_assert_uint_eq(a.n, 3);
}
END_TEST

Suite *fe_stress_suite(void)
{
    Suite *s = suite_create("stress");
    TCase *t = tcase_create("numerical");
    tcase_set_timeout(t, 60);
    tcase_add_test(t, planar_and_collinear_samples_are_refused_by_name);
    tcase_add_test(t, sphere_far_from_the_origin_and_at_extreme_scales);
    tcase_add_test(t, exact_data_converges);
    tcase_add_test(t, denormals_and_extremes_in_the_moment_fold);
    tcase_add_test(t, near_singular_kalman_denominators);
    tcase_add_test(t, rank_deficient_least_squares);
    tcase_add_test(t, levenberg_marquardt_from_absurd_starts);
    tcase_add_test(t, overflowing_rows_are_refused_whole);
    suite_add_tcase(s, t);
    return s;
}
