/* SPDX-License-Identifier: MIT */
/* The synthetic recordings' refusals, each at its edge: equal, just
   inside, just outside (their statistics are checked by the discovery and
   model suites, which fold them). */
#include <float.h>

#include "foldest.h"
#include "foldest/synth.h"
#include "testutil.h"

START_TEST(spec_refusals_at_their_edges)
{
    fe_synth g;
    fe_synth_spec s = fe_synth_default_spec("quadratic_drag", 3);
    ck_assert_int_eq(fe_synth_init(&g, &s), FE_OK);
    s.rows = 100;                           /* the fewest rows taken */
    ck_assert_int_eq(fe_synth_init(&g, &s), FE_OK);
    s.rows = 99;
    ck_assert_int_eq(fe_synth_init(&g, &s), FE_ETOOFEW);
    s = fe_synth_default_spec("quadratic_drag", 3);
    s.noise_sd = 0.0;
    ck_assert_int_eq(fe_synth_init(&g, &s), FE_EINVAL);
    s.noise_sd = 1e-300;
    ck_assert_int_eq(fe_synth_init(&g, &s), FE_OK);
    s = fe_synth_default_spec("quadratic_drag", 3);
    s.noise_rho = 1.0;
    ck_assert_int_eq(fe_synth_init(&g, &s), FE_EINVAL);
    s.noise_rho = 0.999;
    ck_assert_int_eq(fe_synth_init(&g, &s), FE_OK);
    s.noise_rho = 0.0;
    ck_assert_int_eq(fe_synth_init(&g, &s), FE_OK);
    s.noise_rho = -1e-9;
    ck_assert_int_eq(fe_synth_init(&g, &s), FE_EINVAL);
    s.noise_rho = NAN;
    ck_assert_int_eq(fe_synth_init(&g, &s), FE_EINVAL);
    s = fe_synth_default_spec("quadratic_drag", 3);
    s.effect = NULL;
    ck_assert_int_eq(fe_synth_init(&g, &s), FE_EINVAL);
    ck_assert_int_eq(fe_synth_init(NULL, &s), FE_EINVAL);
    /* A valid spec without a generator, and no spec. */
    s = fe_synth_default_spec("quadratic_drag", 3);
    ck_assert_int_eq(fe_synth_init(NULL, &s), FE_EINVAL);
    ck_assert_int_eq(fe_synth_init(&g, NULL), FE_EINVAL);
    /* The rig of each order: order 2 is the cart, with no temperature for
       a thermal effect; order 1 the stand, with no velocity for a
       friction; order 0 takes either; no order above 2.  Both have an
       input (the cart's force, the stand's heater) for input_gain. */
    {
        static const struct { const char *effect; size_t order; int rc; } rig[] = {
            {"newton_cooling", 2, FE_EINVAL}, {"newton_cooling", 1, FE_OK},
            {"newton_cooling", 0, FE_OK}, {"thermal_sensitivity", 2, FE_EINVAL},
            {"none_thermal", 2, FE_EINVAL}, {"none_thermal", 1, FE_OK},
            {"viscous_friction", 2, FE_OK}, {"viscous_friction", 1, FE_EINVAL},
            {"viscous_friction", 0, FE_OK}, {"viscous_friction", 3, FE_EINVAL},
            {"input_gain", 1, FE_OK}, {"input_gain", 2, FE_OK},
            /* gain and delay are not forcings (synth.h): refused at order
               1 and 2, taken at order 0 (seed 10223's synth:300 let
               order 1 through). */
            {"gain", 1, FE_EINVAL}, {"gain", 2, FE_EINVAL}, {"gain", 0, FE_OK},
            {"delay", 1, FE_EINVAL}, {"delay", 2, FE_EINVAL}, {"delay", 0, FE_OK},
        };
        for (size_t i = 0; i < sizeof rig / sizeof rig[0]; i++) {
            s = fe_synth_default_spec(rig[i].effect, 3);
            s.rows = 100;
            s.order = rig[i].order;
            ck_assert_msg(fe_synth_init(&g, &s) == rig[i].rc, "%s, order %zu", rig[i].effect,
                          rig[i].order);
        }
    }
    /* The parting of an integrated effect (order 1 and 2) must be
       positive: 0, -DBL_TRUE_MIN and NaN are refused, DBL_TRUE_MIN, 1/2
       and 1 taken; the coefficient is proportional to it, so 1/2 gives
       exactly half of 1's (a halving, exact in binary).  Order 0 does
       not read it. */
    {
        static const struct { const char *effect; size_t order; } rig[] = {
            {"newton_cooling", 1}, {"viscous_friction", 2},
        };
        for (size_t i = 0; i < sizeof rig / sizeof rig[0]; i++) {
            double one;
            s = fe_synth_default_spec(rig[i].effect, 3);
            s.rows = 100;
            s.order = rig[i].order;
            s.parting = 0.0;
            ck_assert_int_eq(fe_synth_init(&g, &s), FE_EINVAL);
            s.parting = -DBL_TRUE_MIN;
            ck_assert_int_eq(fe_synth_init(&g, &s), FE_EINVAL);
            s.parting = NAN;
            ck_assert_int_eq(fe_synth_init(&g, &s), FE_EINVAL);
            s.parting = DBL_TRUE_MIN;
            ck_assert_int_eq(fe_synth_init(&g, &s), FE_OK);
            s.parting = 1.0;
            ck_assert_int_eq(fe_synth_init(&g, &s), FE_OK);
            one = g.coefficient;
            ck_assert(isfinite(one) && one != 0.0);
            s.parting = 0.5;
            ck_assert_int_eq(fe_synth_init(&g, &s), FE_OK);
            ck_assert_double_eq(g.coefficient, 0.5 * one);
            s.order = 0;
            s.parting = 0.0;
            ck_assert_int_eq(fe_synth_init(&g, &s), FE_OK);
        }
    }
}
END_TEST

/* The input's three phases are drawn from the seed, each in [0, 2 pi):
   another seed draws three others. */
START_TEST(every_phase_comes_from_the_seed)
{
    fe_synth g, h;
    fe_synth_spec s = fe_synth_default_spec("quadratic_drag", 3);
    ck_assert_int_eq(fe_synth_init(&g, &s), FE_OK);
    s.seed = 4;
    ck_assert_int_eq(fe_synth_init(&h, &s), FE_OK);
    for (int i = 0; i < 3; i++) {
        ck_assert(g.phase[i] >= 0.0 && g.phase[i] < 2.0 * 3.14159265358979324);
        ck_assert(h.phase[i] >= 0.0 && h.phase[i] < 2.0 * 3.14159265358979324);
        ck_assert_double_ne(g.phase[i], h.phase[i]);
    }
}
END_TEST

START_TEST(rows_carry_the_central_difference_of_sim)
{
    /* dsim of row i is (sim[i+1] - sim[i-1]) / (t[i+1] - t[i-1]), one-sided
       at the ends (literate/synth.org), recomputed from the rows: on each
       rig, with and without an effect folded into the motion. */
    enum { N = 150 };
    static const struct { const char *effect; size_t order; } cases[] = {
        {"none", 0}, {"none_thermal", 0}, {"viscous_friction", 2}, {"newton_cooling", 1},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        fe_synth g;
        fe_synth_spec spec = fe_synth_default_spec(cases[c].effect, 5);
        fe_sample row[N], end;
        spec.rows = N;
        spec.order = cases[c].order;
        ck_assert_int_eq(fe_synth_init(&g, &spec), FE_OK);
        for (size_t i = 0; i < N; i++)
            ck_assert_int_eq(fe_synth_next(&g, &row[i]), FE_OK);
        ck_assert_int_eq(fe_synth_next(&g, &end), FE_END);
        for (size_t i = 0; i < N; i++) {
            size_t a = i > 0 ? i - 1 : 0, b = i + 1 < N ? i + 1 : N - 1;
            double want = (row[b].sim - row[a].sim) / (row[b].t - row[a].t);
            ck_assert_msg(fabs(row[i].dsim - want) <= 1e-12 * (fabs(want) + 1.0),
                          "%s row %zu: dsim %.17g, want %.17g", cases[c].effect, i, row[i].dsim,
                          want);
        }
        /* The noise's sd: noise_sd, in 0.1 % of the channel's span (the
           simulated channel over all the rows) when order > 0. */
        {
            double lo = row[0].sim, hi = row[0].sim;
            for (size_t i = 1; i < N; i++) {
                lo = fmin(lo, row[i].sim);
                hi = fmax(hi, row[i].sim);
            }
            if (cases[c].order > 0)
                FE_ASSERT_REL(g.sigma, spec.noise_sd * 1e-3 * (hi - lo), 1e-12);
            else
                ck_assert_double_eq(g.sigma, spec.noise_sd);
        }
    }
}
END_TEST

START_TEST(thermal_rig_follows_its_equations)
{
    /* The thermal rig as literate/synth.org states it, recomputed here row
       by row: ambient 20 + 25 sin(2 pi t / (T / 2.3) + 0.3) over the
       recording's length T; the heater 60 for the first 300 s of every
       600 s; the temperature starts at the ambient and relaxes towards
       ambient + heater with tau = 20 s (explicit Euler, the documented
       step); the load (sim - 2) is an Ornstein-Uhlenbeck process of time
       constant 5 s and unit spread, so load[i+1] = phi load[i] + e with
       phi = 1 - dt/5 and var(e) = 2 dt / 5.  phi and var(e) are estimated
       by least squares over 10^6 rows and held to four standard errors
       (SE(phi) = sqrt(var(e) / sum load^2), SE(var) = var sqrt(2 / N)):
       a time constant of 6 s moves phi by dt/30, about ten standard
       errors, and var(e) by a sixth. */
    enum { N = 1000000 };
    fe_synth g;
    fe_synth_spec spec = fe_synth_default_spec("none_thermal", 11);
    fe_sample s;
    double dt, total, temp = 0.0, sxy = 0.0, sxx = 0.0, worst = 0.0;
    double *load = malloc(N * sizeof *load);
    ck_assert_ptr_nonnull(load);
    spec.rows = N;
    ck_assert_int_eq(fe_synth_init(&g, &spec), FE_OK);
    ck_assert_int_eq(g.thermal, 1);
    dt = g.dt;
    ck_assert_double_gt(dt, 0.0);
    total = (double)N * dt;
    for (size_t i = 0; i < N; i++) {
        double t = (double)i * dt;
        double amb = 20.0 + 25.0 * sin(2.0 * 3.14159265358979323846 * t / (total / 2.3) + 0.3);
        double heat = fmod(t, 600.0) < 300.0 ? 60.0 : 0.0;
        ck_assert_int_eq(fe_synth_next(&g, &s), FE_OK);
        if (i == 0)
            temp = amb;
        worst = fmax(worst, fabs(s.t - t));
        worst = fmax(worst, fabs(s.ambient - amb) / 45.0);
        worst = fmax(worst, fabs(s.temperature - temp) / 100.0);
        temp += (amb + heat - temp) * dt / 20.0;
        load[i] = s.sim - 2.0;
    }
    ck_assert_int_eq(fe_synth_next(&g, &s), FE_END);
    ck_assert_msg(worst < 1e-9, "time, ambient or temperature off the equations by %.3g", worst);
    for (size_t i = 0; i + 1 < N; i++) {
        sxy += load[i] * load[i + 1];
        sxx += load[i] * load[i];
    }
    {
        double phi = sxy / sxx, ve = 0.0, want_phi = 1.0 - dt / 5.0, want_ve = 2.0 * dt / 5.0;
        for (size_t i = 0; i + 1 < N; i++) {
            double e = load[i + 1] - phi * load[i];
            ve += e * e;
        }
        ve /= (double)(N - 2);
        ck_assert_msg(fabs(phi - want_phi) < 4.0 * sqrt(want_ve / sxx),
                      "phi %.6f, want %.6f (SE %.2g)", phi, want_phi, sqrt(want_ve / sxx));
        ck_assert_msg(fabs(ve - want_ve) < 4.0 * want_ve * sqrt(2.0 / N),
                      "var(e) %.6g, want %.6g", ve, want_ve);
    }
    free(load);
}
END_TEST

START_TEST(mechanical_rig_follows_its_equations)
{
    /* The mechanical rig as literate/synth.org states it, recomputed here
       row by row from the seeded phases phi_0..2: the input
       u = min(t / 10, 1) (0.85 + 0.15 sin(2 pi t / (T / 3.3) + phi_2))
           (sin(2 pi 0.17 t + phi_0) + 1.5 sin(2 pi 0.83 t + phi_1))
       over the recording's length T, and the cart
       a = u - w0^2 x - 2 zeta w0 v, w0 = 2 pi 0.4, zeta = 0.15, advanced
       by semi-implicit Euler (v += a dt, then x += v dt), the channel sim
       being a; position and velocity are the state before the step. */
    enum { N = 6000 };
    const double two_pi = 6.283185307179586476925286766559;
    const double w0 = two_pi * 0.4, zeta = 0.15;
    fe_synth g;
    fe_synth_spec spec = fe_synth_default_spec("quadratic_drag", 5);
    fe_sample s;
    double dt, total, x = 0.0, v = 0.0, worst = 0.0, umax = 0.0;
    spec.rows = N;
    ck_assert_int_eq(fe_synth_init(&g, &spec), FE_OK);
    ck_assert_int_eq(g.thermal, 0);
    dt = g.dt;
    ck_assert_double_eq_tol(dt, 0.01, 1e-15);
    total = (double)N * dt;
    for (size_t i = 0; i < N; i++) {
        double t = (double)i * dt;
        double u = (t < 10.0 ? t / 10.0 : 1.0)
                   * (0.85 + 0.15 * sin(two_pi * t / (total / 3.3) + g.phase[2]))
                   * (sin(two_pi * 0.17 * t + g.phase[0])
                      + 1.5 * sin(two_pi * 0.83 * t + g.phase[1]));
        double a = u - w0 * w0 * x - 2.0 * zeta * w0 * v;
        ck_assert_int_eq(fe_synth_next(&g, &s), FE_OK);
        worst = fmax(worst, fabs(s.t - t));
        worst = fmax(worst, fabs(s.input - u));
        worst = fmax(worst, fabs(s.position - x));
        worst = fmax(worst, fabs(s.velocity - v));
        worst = fmax(worst, fabs(s.sim - a));
        umax = fmax(umax, fabs(u));
        v += a * dt;
        x += v * dt;
    }
    ck_assert_msg(worst < 1e-9, "time, input or cart off the equations by %.3g", worst);
    ck_assert_double_gt(umax, 1.0);
    /* The phases differ and lie in [0, 2 pi). */
    for (int k = 0; k < 3; k++) {
        ck_assert_double_ge(g.phase[k], 0.0);
        ck_assert_double_lt(g.phase[k], two_pi);
    }
}
END_TEST

START_TEST(noise_is_its_ar1_recursion)
{
    /* With no effect, real - sim is the noise alone: the AR(1) recursion
       of literate/synth.org started stationary at the first row,
       e_0 = sigma z_0, e_i = rho e_{i-1} + sqrt(1 - rho^2) sigma z_i, the
       z_i drawn in turn from the noise generator (seeded 2 seed + 2);
       each rig, two values of rho; rewound, the same rows again. */
    static const struct { const char *effect; double rho; } cases[] = {
        {"none", 0.5}, {"none", 0.9}, {"none_thermal", 0.5}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        fe_synth g;
        fe_synth_spec spec = fe_synth_default_spec(cases[c].effect, 13);
        fe_rng z = fe_rng_seed(13 * 2 + 2);
        fe_sample s;
        double e = 0.0, worst = 0.0, first = 0.0;
        spec.rows = 2000;
        spec.noise_rho = cases[c].rho;
        spec.noise_sd = 0.7;
        ck_assert_int_eq(fe_synth_init(&g, &spec), FE_OK);
        ck_assert_double_eq(g.coefficient, 0.0);
        for (size_t i = 0; i < spec.rows; i++) {
            double zi = fe_rng_normal(&z);
            e = i == 0 ? 0.7 * zi : cases[c].rho * e + sqrt(1.0 - cases[c].rho * cases[c].rho) * 0.7 * zi;
            ck_assert_int_eq(fe_synth_next(&g, &s), FE_OK);
            worst = fmax(worst, fabs((s.real - s.sim) - e));
            if (i == 0)
                first = s.real;
        }
        ck_assert_msg(worst < 1e-12, "%s rho %g: noise off its recursion by %.3g",
                      cases[c].effect, cases[c].rho, worst);
        fe_synth_rewind(&g);
        ck_assert_int_eq(fe_synth_next(&g, &s), FE_OK);
        ck_assert_double_eq(s.real, first);
    }
}
END_TEST

START_TEST(order_one_integrates_the_effect_into_the_stands_temperature)
{
    /* Order 1 (synth.h, literate/synth.org): the effect enters the real
       stand's dT/dt and is integrated into its motion; real is that
       stand's temperature plus the noise.  Recomputed here row by row: the
       real stand starts at the ambient and steps by explicit Euler,
       T_r += ((T_a + P - T_r) / tau + c phi) dt with tau = 20 s, the
       heater P = 60 for the first 300 s of every 600 s, and
       newton_cooling's phi = T_r - T_a; the noise is the AR(1) recursion
       of noise_is_its_ar1_recursion with sigma = g.sigma.  c is the
       coefficient whose static response to the largest forcing is
       `parting` noise sds, negative (cooling opposes excess heat):
       -parting sigma / (tau max |T - T_a|), the maximum over the
       simulated stand's rows.  The effect added to the channel instead
       (sim + c phi + noise, as for order 0) misses the integrated trace,
       which parts from the simulated stand by more than one sigma. */
    enum { N = 20000 };
    const double tau = 20.0, rho = 0.5;
    fe_synth g;
    fe_synth_spec spec = fe_synth_default_spec("newton_cooling", 3);
    fe_rng z = fe_rng_seed(3 * 2 + 2);
    fe_sample *row = malloc(N * sizeof *row);
    double maxphi = 0.0, c, tr, e = 0.0, worst = 0.0, parted = 0.0;
    ck_assert_ptr_nonnull(row);
    spec.rows = N;
    spec.order = 1;
    spec.noise_rho = rho;
    ck_assert_int_eq(fe_synth_init(&g, &spec), FE_OK);
    ck_assert_int_eq(g.thermal, 1);
    for (size_t i = 0; i < N; i++) {
        ck_assert_int_eq(fe_synth_next(&g, &row[i]), FE_OK);
        maxphi = fmax(maxphi, fabs(row[i].temperature - row[i].ambient));
    }
    ck_assert_double_gt(maxphi, 0.0);
    c = -spec.parting * g.sigma / (tau * maxphi);
    FE_ASSERT_REL(g.coefficient, c, 1e-12);
    tr = row[0].ambient;
    for (size_t i = 0; i < N; i++) {
        double zi = fe_rng_normal(&z), heat = fmod(row[i].t, 600.0) < 300.0 ? 60.0 : 0.0;
        e = i == 0 ? g.sigma * zi : rho * e + sqrt(1.0 - rho * rho) * g.sigma * zi;
        worst = fmax(worst, fabs(row[i].real - e - tr));
        parted = fmax(parted, fabs(tr - row[i].temperature));
        tr += ((row[i].ambient + heat - tr) / tau + c * (tr - row[i].ambient)) * g.dt;
    }
    ck_assert_msg(worst < 1e-9 * g.sigma, "real off the integrated stand by %.3g sigma",
                  worst / g.sigma);
    ck_assert_msg(parted > g.sigma, "the stand parts by only %.3g sigma", parted / g.sigma);
    free(row);
}
END_TEST

Suite *fe_synth_suite(void)
{
    Suite *s = suite_create("synth");
    TCase *t = tcase_create("core");
    tcase_set_timeout(t, 60);           /* 10^6 rows: about 1 s, more on a busy machine */
    tcase_add_test(t, spec_refusals_at_their_edges);
    tcase_add_test(t, thermal_rig_follows_its_equations);
    tcase_add_test(t, mechanical_rig_follows_its_equations);
    tcase_add_test(t, noise_is_its_ar1_recursion);
    tcase_add_test(t, order_one_integrates_the_effect_into_the_stands_temperature);
    tcase_add_test(t, every_phase_comes_from_the_seed);
    tcase_add_test(t, rows_carry_the_central_difference_of_sim);
    suite_add_tcase(s, t);
    return s;
}
