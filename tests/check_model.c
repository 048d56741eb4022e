/* SPDX-License-Identifier: MIT */
/* A model as a callback: the mechanical rig of the synthetic generator
   written as a model f(t, x, v, u; theta) with three parameters (input
   gain, resonance frequency, damping ratio), its Jacobian analytic or by
   finite differences; discovery names the concealed effect with either,
   and the parameters absorb what they can. */
#include <float.h>
#include <stdint.h>

#include "foldest.h"
#include "testutil.h"

static const double two_pi = 6.283185307179586476925286766559;

/* a = g u - (2 pi f)^2 x - 2 zeta (2 pi f) v, theta = (g, f, zeta). */
static int rig_predict(const fe_sample *s, const double *th, double *y, void *user)
{
    double w = two_pi * th[1];
    (void)user;
    *y = th[0] * s->input - w * w * s->position - 2.0 * th[2] * w * s->velocity;
    return 0;
}

static int rig_jacobian(const fe_sample *s, const double *th, double *jac, void *user)
{
    double w = two_pi * th[1];
    (void)user;
    jac[0] = s->input;
    jac[1] = -2.0 * w * two_pi * s->position - 2.0 * th[2] * two_pi * s->velocity;
    jac[2] = -2.0 * w * s->velocity;
    return 0;
}

/* A user term: the sample's time, scaled by *user. */
static double time_term(const fe_sample *s, const fe_catalog_scale *scale, void *user)
{
    (void)scale;
    return *(const double *)user * s->t;
}

static int calls;
static int counting_predict(const fe_sample *s, const double *th, double *y, void *user)
{
    calls++;
    return rig_predict(s, th, y, user);
}

static int failing_predict(const fe_sample *s, const double *th, double *y, void *user)
{
    (void)s;
    (void)th;
    (void)user;
    *y = 0;
    return FE_ESTOPPED;
}

static const double theta0[3] = {1.0, 0.4, 0.15};

/* Fails only away from theta0: the finite-difference evaluations. */
static int failing_away_predict(const fe_sample *s, const double *th, double *y, void *user)
{
    (void)user;
    if (th[1] != theta0[1])
        return FE_ESTOPPED;
    return rig_predict(s, th, y, user);
}

static int failing_jacobian(const fe_sample *s, const double *th, double *jac, void *user)
{
    (void)s;
    (void)th;
    (void)user;
    jac[0] = jac[1] = jac[2] = 0.0;
    return FE_ESTOPPED;
}

static int nan_jacobian(const fe_sample *s, const double *th, double *jac, void *user)
{
    int rc = rig_jacobian(s, th, jac, user);
    jac[2] = NAN;
    return rc;
}
/* NaN in the first column, and infinity in the second. */
static int nan0_jacobian(const fe_sample *s, const double *th, double *jac, void *user)
{
    int rc = rig_jacobian(s, th, jac, user);
    jac[0] = NAN;
    return rc;
}

static int inf1_jacobian(const fe_sample *s, const double *th, double *jac, void *user)
{
    int rc = rig_jacobian(s, th, jac, user);
    jac[1] = -INFINITY;
    return rc;
}
static const char *const names[3] = {"input_gain_param", "frequency", "damping"};

typedef struct {
    fe_synth g;
    fe_catalog c;
    fe_model_acc a;
    double *storage, *work;
    size_t nwork;
    fe_discover_result *r;
} model_case;

/* Fold the synthetic case through the model (analytic Jacobian, central
   or forward differences) and select with bias as an extra base term. */
static void run_case(model_case *mc, const char *effect, uint64_t seed, int how)
{
    fe_synth_spec spec = fe_synth_default_spec(effect, seed);
    fe_model m = {3, theta0, names, rig_predict, NULL, 0, NULL, NULL};
    fe_discover_options o = fe_discover_default_options();
    fe_sample s;
    size_t nst, bias;
    int rc = FE_OK;
    if (how == 0)
        m.jacobian = rig_jacobian;
    m.forward = how == 2;
    spec.rows = 100000;
    ck_assert_int_eq(fe_synth_init(&mc->g, &spec), FE_OK);
    ck_assert_int_eq(fe_catalog_init(&mc->c, mc->g.roles, &mc->g.scale), FE_OK);
    nst = fe_model_acc_doubles(3, mc->c.count, 20);
    ck_assert_uint_gt(nst, 0);
    mc->storage = malloc(nst * sizeof *mc->storage);
    ck_assert_ptr_nonnull(mc->storage);
    ck_assert_int_eq(fe_model_acc_init(&mc->a, &m, &mc->c, 20, 70000, mc->storage, nst),
                     FE_OK);
    while (fe_synth_next(&mc->g, &s) == FE_OK)
        rc |= fe_model_add(&mc->a, &s);
    ck_assert_int_eq(rc, FE_OK);
    mc->r = malloc(sizeof *mc->r);
    ck_assert_ptr_nonnull(mc->r);
    ck_assert_int_eq(fe_model_select(&mc->a, NULL, mc->r, NULL, 0), FE_EINVAL); /* a row is held */
    ck_assert_int_eq(fe_model_break(&mc->a), FE_OK);
    ck_assert_uint_eq(mc->a.acc.n, spec.rows);
    mc->nwork = fe_model_workspace_doubles(&mc->a);
    mc->work = malloc(mc->nwork * sizeof *mc->work);
    ck_assert_ptr_nonnull(mc->work);
    bias = (size_t)fe_catalog_find(&mc->c, "bias");
    o.base = &bias;
    o.nbase = 1;
    ck_assert_int_eq(fe_model_select(&mc->a, &o, mc->r, mc->work, mc->nwork), FE_OK);
}

static void free_case(model_case *mc)
{
    free(mc->storage);
    free(mc->work);
    free(mc->r);
}

static long group_of(const model_case *mc, const char *term)
{
    return fe_catalog_find(&mc->c, term) + 3;
}

START_TEST(analytic_and_numerical_jacobians_discover_the_same)
{
    /* Concealed quadratic drag: all three Jacobians name it first, with
       coefficients within a small fraction of a standard error of each
       other, and the model's parameters stay at their true values. */
    static const char *const effects[] = {"quadratic_drag", "cubic_stiffness"};
    for (size_t e = 0; e < 2; e++) {
        model_case mc[3];
        long truth;
        for (int how = 0; how < 3; how++)
            run_case(&mc[how], effects[e], 3 + e, how);
        truth = group_of(&mc[0], effects[e]);
        for (int how = 0; how < 3; how++) {
            double th[3], se[3];
            ck_assert_uint_ge(mc[how].r->steps, 1);
            ck_assert_msg((long)mc[how].r->added[0] == truth, "%s: named %s (how %d)",
                          effects[e], fe_model_group_name(&mc[how].a, mc[how].r->added[0]), how);
            ck_assert_uint_eq(mc[how].r->steps, mc[0].r->steps);
            ck_assert_uint_eq(mc[how].r->ncols, mc[0].r->ncols);
            for (size_t s = 0; s < mc[0].r->steps; s++)
                ck_assert_uint_eq(mc[how].r->added[s], mc[0].r->added[s]);
            for (size_t j = 0; j < mc[0].r->ncols; j++) {
                double se0 = mc[0].r->stderr_[j];
                ck_assert_uint_eq(mc[how].r->cols[j], mc[0].r->cols[j]);
                /* central differences: 1e-11 relative; forward: 1e-7 */
                ck_assert_msg(fabs(mc[how].r->coef[j] - mc[0].r->coef[j])
                                  <= (how == 2 ? 1e-3 : 1e-6) * se0,
                              "column %zu: %.12g vs %.12g (se %.3g), how %d", j,
                              mc[how].r->coef[j], mc[0].r->coef[j], se0, how);
            }
            /* The named term has the sign of the truth (coverage of the
               truth by the intervals is tested over many seeds below). */
            for (size_t j = 0; j < mc[how].r->ncols; j++)
                if ((long)mc[how].r->cols[j] == truth)
                    ck_assert(mc[how].r->coef[j] * mc[how].g.coefficient > 0);
            /* The nominal parameters are the simulation's: the fit keeps them. */
            ck_assert_int_eq(fe_model_theta(&mc[how].a, mc[how].r, th, se), FE_OK);
            for (int i = 0; i < 3; i++)
                ck_assert_msg(fabs(th[i] - theta0[i]) <= 4.0 * se[i] && se[i] > 0,
                              "theta%d = %.6g +/- %.2g", i + 1, th[i], se[i]);
        }
        /* The parameters absorb the terms they span: input, position and
           velocity are redundant, and so is gain (the prediction itself). */
        {
            static const char *const spanned[] = {"input_gain", "linear_stiffness",
                                                  "viscous_friction", "gain"};
            for (size_t k = 0; k < 4; k++) {
                long gk = group_of(&mc[0], spanned[k]);
                int found = 0;
                for (size_t i = 0; i < mc[0].r->nranked[0]; i++)
                    if ((long)mc[0].r->ranking[0][i].group == gk) {
                        found = 1;
                        ck_assert_msg(mc[0].r->ranking[0][i].redundant, "%s not redundant",
                                      spanned[k]);
                    }
                ck_assert(found);
            }
        }
        for (int how = 0; how < 3; how++)
            free_case(&mc[how]);
    }
}
END_TEST

START_TEST(concealed_effects_are_found_through_the_model)
{
    /* The acceptance test of the engine, through a model: each effect the
       three parameters cannot imitate, over many seeds, is named first and
       its 95% interval covers the truth about as often as it should. */
    static const char *const effects[] = {"quadratic_drag", "coulomb_friction",
                                          "cubic_stiffness", "drift", "delay"};
    unsigned seeds = fe_test_quick() ? 1 : 10, runs = 0, first = 0, covered = 0;
    for (size_t e = 0; e < sizeof effects / sizeof effects[0]; e++)
        for (uint64_t seed = 1; seed <= seeds; seed++) {
            model_case mc;
            long truth;
            run_case(&mc, effects[e], 100 + seed, 0);
            truth = group_of(&mc, effects[e]);
            runs++;
            first += mc.r->steps > 0 && (long)mc.r->added[0] == truth;
            for (size_t j = 0; j < mc.r->ncols; j++)
                if ((long)mc.r->cols[j] == truth)
                    covered += fabs(mc.r->coef[j] - mc.g.coefficient)
                               <= mc.r->t_critical[j] * mc.r->stderr_[j];
            free_case(&mc);
        }
    fprintf(stderr, "model acceptance: named first %u/%u, 95%% interval covers truth %u/%u\n",
            first, runs, covered, runs);
    ck_assert_msg(first >= 0.9 * runs, "named first %u/%u", first, runs);
    ck_assert_msg(covered >= 0.85 * runs, "covered %u/%u", covered, runs);
}
END_TEST

START_TEST(a_right_model_discovers_nothing)
{
    unsigned found = 0, seeds = fe_test_quick() ? 2 : 10;
    for (uint64_t seed = 1; seed <= seeds; seed++) {
        model_case mc;
        run_case(&mc, "none", seed, 1);
        found += mc.r->steps > 0;
        free_case(&mc);
    }
    fprintf(stderr, "model: right model, false discoveries %u/%u\n", found, seeds);
    ck_assert_msg(found <= 1, "false discoveries %u/%u", found, seeds);
}
END_TEST

START_TEST(the_fold_is_its_rows)
{
    /* Every row folded as the text says, recomputed from the stored rows:
       the prediction y_i at theta0, the Jacobian columns, the catalog's
       terms of the row with sim = y_i and dsim the central difference of
       the predictions (one-sided at each end of a recording), and r =
       real - y_i; the block Gram matrices summed against the products of
       those rows.  Two recordings, 300 and 200 rows. */
    enum { N = 500, NB = 300, K = 4 };
    fe_synth_spec spec = fe_synth_default_spec("bias", 11);
    fe_model m = {3, theta0, names, rig_predict, rig_jacobian, 0, NULL, NULL};
    fe_synth g;
    fe_catalog c;
    fe_model_acc a;
    static fe_sample rows[N];
    static double y[N];
    double *st;
    size_t nst, M, dim;
    static long double want[FE_DISCOVER_MAX_COLUMNS + 1][FE_DISCOVER_MAX_COLUMNS + 1];
    spec.rows = N;
    ck_assert_int_eq(fe_synth_init(&g, &spec), FE_OK);
    ck_assert_int_eq(fe_catalog_init(&c, g.roles, &g.scale), FE_OK);
    ck_assert_int_ge(fe_catalog_find(&c, "delay"), 0);
    nst = fe_model_acc_doubles(3, c.count, K);
    st = malloc(nst * sizeof *st);
    ck_assert_ptr_nonnull(st);
    ck_assert_int_eq(fe_model_acc_init(&a, &m, &c, K, N, st, nst), FE_OK);
    for (size_t i = 0; i < N; i++) {
        ck_assert_int_eq(fe_synth_next(&g, &rows[i]), FE_OK);
        if (i == NB)
            ck_assert_int_eq(fe_model_break(&a), FE_OK);
        ck_assert_int_eq(fe_model_add(&a, &rows[i]), FE_OK);
        rig_predict(&rows[i], theta0, &y[i], NULL);
    }
    ck_assert_int_eq(fe_model_break(&a), FE_OK);
    M = 3 + c.count;
    dim = M + 1;
    memset(want, 0, sizeof want);
    for (size_t i = 0; i < N; i++) {
        size_t lo = i < NB ? 0 : NB, hi = i < NB ? NB - 1 : N - 1;
        size_t i0 = i > lo ? i - 1 : i, i1 = i < hi ? i + 1 : i;
        fe_sample row = rows[i];
        double z[FE_DISCOVER_MAX_COLUMNS + 1];
        row.sim = y[i];
        row.dsim = (y[i1] - y[i0]) / (rows[i1].t - rows[i0].t);
        rig_jacobian(&rows[i], theta0, z, NULL);
        ck_assert_int_eq(fe_catalog_eval(&c, &row, z + 3), FE_OK);
        z[M] = rows[i].real - y[i];
        for (size_t u = 0; u < dim; u++)
            for (size_t v = 0; v < dim; v++)
                want[u][v] += (long double)z[u] * z[v];
    }
    for (size_t u = 0; u < dim; u++)
        for (size_t v = u; v < dim; v++) {
            double got = 0.0;
            for (size_t k = 0; k < K; k++)
                got += a.acc.gram[k * dim * dim + u * dim + v];
            ck_assert_msg(fabs(got - (double)want[u][v])
                              <= 1e-10 * sqrt((double)(want[u][u] * want[v][v])) + 1e-300,
                          "gram[%zu][%zu] = %.17g, want %.17g", u, v, got, (double)want[u][v]);
        }
    free(st);
}
END_TEST

START_TEST(finite_difference_steps_and_calls)
{
    /* The step is eps^(1/3) max(|theta|, typical), exactly representable
       from theta; central differences call predict 2p + 1 times a row,
       forward p + 1. */
    fe_catalog_scale sc = {0};
    fe_catalog c;
    fe_model m = {3, theta0, NULL, counting_predict, NULL, 0, NULL, NULL};
    double typ[3] = {1.0, 10.0, 1e-3};
    fe_model_acc a;
    size_t nst;
    double *st;
    fe_sample s = {0};
    ck_assert_int_eq(fe_catalog_init(&c, FE_ROLE_POSITION | FE_ROLE_VELOCITY | FE_ROLE_INPUT,
                                     &sc), FE_OK);
    nst = fe_model_acc_doubles(3, c.count, 4);
    st = malloc(nst * sizeof *st);
    m.typical = typ;
    ck_assert_int_eq(fe_model_acc_init(&a, &m, &c, 4, 100, st, nst), FE_OK);
    FE_ASSERT_REL(a.step[0], cbrt(DBL_EPSILON), 1e-9);
    FE_ASSERT_REL(a.step[1], 10.0 * cbrt(DBL_EPSILON), 1e-9);
    FE_ASSERT_REL(a.step[2], 0.15 * cbrt(DBL_EPSILON), 1e-9);
    for (int i = 0; i < 3; i++)
        ck_assert(((theta0[i] + a.step[i]) - theta0[i]) == a.step[i]);
    ck_assert_str_eq(fe_model_group_name(&a, 1), "theta2");
    calls = 0;
    s.t = 0;
    s.input = 1;
    ck_assert_int_eq(fe_model_add(&a, &s), FE_OK);
    ck_assert_int_eq(calls, 7);
    m.forward = 1;
    ck_assert_int_eq(fe_model_acc_init(&a, &m, &c, 4, 100, st, nst), FE_OK);
    FE_ASSERT_REL(a.step[0], sqrt(DBL_EPSILON), 1e-9);
    calls = 0;
    ck_assert_int_eq(fe_model_add(&a, &s), FE_OK);
    ck_assert_int_eq(calls, 4);
    free(st);
}
END_TEST

/* fe_model_break's FE_ENONFINITE: the held row is folded with a
   one-sided difference of the simulation, here a step of 1 over 1e-310 of
   time, which overflows (the delay term carries it); the row is dropped
   and the recording ends.  Over 1e-150 the difference is finite and the
   row folds.  (The row before it, folded with the central difference
   across both neighbours, sees no step.) */
START_TEST(a_held_row_whose_difference_overflows_is_dropped)
{
    fe_catalog_scale sc = {0};
    fe_catalog c;
    fe_model m = {3, theta0, NULL, rig_predict, rig_jacobian, 0, NULL, NULL};
    fe_model_acc a;
    size_t nst;
    double *st;
    ck_assert_int_eq(fe_catalog_init(&c, FE_ROLE_POSITION | FE_ROLE_VELOCITY | FE_ROLE_INPUT,
                                     &sc), FE_OK);
    nst = fe_model_acc_doubles(3, c.count, 4);
    st = malloc(nst * sizeof *st);
    for (int k = 0; k < 2; k++) {
        fe_sample s = {0};
        double rows_before;
        ck_assert_int_eq(fe_model_acc_init(&a, &m, &c, 4, 100, st, nst), FE_OK);
        s.real = 0.3;
        for (int i = 0; i < 3; i++) {       /* the simulation 1.5, 0.5, 1.5 */
            s.t = i == 0 ? -1.0 : i == 1 ? 0.0 : k == 0 ? 1e-310 : 1e-150;
            s.input = i == 1 ? 0.5 : 1.5;
            ck_assert_int_eq(fe_model_add(&a, &s), FE_OK);
        }
        rows_before = a.acc.counts[0];
        ck_assert_int_eq(fe_model_break(&a), k == 0 ? FE_ENONFINITE : FE_OK);
        ck_assert_double_eq(a.acc.counts[0], rows_before + (k == 0 ? 0.0 : 1.0));
        ck_assert_int_eq(a.have_pend, 0);    /* no row held either way */
    }
    free(st);
}
END_TEST

START_TEST(refusals_leave_the_accumulation_unchanged)
{
    fe_catalog_scale sc = {0};
    fe_catalog c;
    fe_model m = {3, theta0, NULL, rig_predict, rig_jacobian, 0, NULL, NULL};
    fe_model bad = m;
    double nan_theta[3] = {1, NAN, 0};
    fe_model_acc a, before;
    size_t nst;
    double *st, *copy;
    fe_sample s = {0};
    ck_assert_int_eq(fe_catalog_init(&c, FE_ROLE_POSITION | FE_ROLE_VELOCITY | FE_ROLE_INPUT,
                                     &sc), FE_OK);
    ck_assert_uint_eq(fe_model_acc_doubles(0, c.count, 4), 0);
    ck_assert_uint_eq(fe_model_acc_doubles(FE_MODEL_MAX_PARAMS + 1, c.count, 4), 0);
    nst = fe_model_acc_doubles(3, c.count, 4);
    st = malloc(nst * sizeof *st);
    copy = malloc(nst * sizeof *st);
    bad.predict = NULL;
    ck_assert_int_eq(fe_model_acc_init(&a, &bad, &c, 4, 100, st, nst), FE_EINVAL);
    bad = m;
    bad.theta0 = nan_theta;
    ck_assert_int_eq(fe_model_acc_init(&a, &bad, &c, 4, 100, st, nst), FE_ENONFINITE);
    ck_assert_int_eq(fe_model_acc_init(&a, &m, &c, 4, 100, st, nst - 1), FE_ESIZE);
    ck_assert_int_eq(fe_model_acc_init(&a, &m, &c, 4, 100, st, nst), FE_OK);
    s.t = 1;
    s.input = 0.5;
    s.real = 0.3;
    ck_assert_int_eq(fe_model_add(&a, &s), FE_OK);
    s.t = 2;
    ck_assert_int_eq(fe_model_add(&a, &s), FE_OK);
    memcpy(&before, &a, sizeof a);
    memcpy(copy, st, nst * sizeof *st);
    s.t = 2;                                   /* time does not increase */
    ck_assert_int_eq(fe_model_add(&a, &s), FE_EINVAL);
    s.t = 3;
    s.real = NAN;
    ck_assert_int_eq(fe_model_add(&a, &s), FE_ENONFINITE);
    s.real = 0;
    s.velocity = INFINITY;                     /* the prediction is not finite */
    ck_assert_int_eq(fe_model_add(&a, &s), FE_ENONFINITE);
    s.velocity = 0;
    a.model.predict = failing_predict;         /* a callback says stop */
    ck_assert_int_eq(fe_model_add(&a, &s), FE_ESTOPPED);
    a.model.predict = rig_predict;
    ck_assert_mem_eq(&a, &before, sizeof a);
    ck_assert_mem_eq(st, copy, nst * sizeof *st);
    ck_assert_uint_eq(a.acc.n, 1);
    ck_assert_int_eq(fe_model_break(&a), FE_OK);
    ck_assert_uint_eq(a.acc.n, 2);
    free(st);
    free(copy);
}
END_TEST

/* fe_model_add's answer to s; a refusal must leave the accumulation a and
   its storage (nst doubles at st; copy has room for as many) as they
   were, byte for byte. */
static int add_unchanged_if_refused(fe_model_acc *a, const fe_sample *s, double *st,
                                    double *copy, size_t nst)
{
    fe_model_acc before = *a;
    int rc;
    memcpy(copy, st, nst * sizeof *st);
    rc = fe_model_add(a, s);
    if (rc != FE_OK) {
        ck_assert_mem_eq(a, &before, sizeof *a);
        ck_assert_mem_eq(st, copy, nst * sizeof *st);
    }
    return rc;
}

/* A time that is not finite is a value that is not finite (FE_ENONFINITE,
   the accumulation unchanged), with a finite recording and no term that
   reads the time (drift, t - t_first, would be refused in its stead): as
   the first row, where no time precedes it (NaN, +inf, -inf), and after a
   held row, where +inf would increase (a NaN or -inf there also fails the
   ordering, so it is left out). */
START_TEST(a_time_that_is_not_finite_is_refused_without_a_term_of_time)
{
    const double first[3] = {NAN, INFINITY, -INFINITY};
    fe_catalog_scale sc = {0};
    fe_catalog c;
    fe_model m = {3, theta0, NULL, rig_predict, rig_jacobian, 0, NULL, NULL};
    fe_model_acc a;
    size_t nst;
    double *st, *copy;
    fe_sample s = {0};
    ck_assert_int_eq(fe_catalog_init(&c, FE_ROLE_POSITION | FE_ROLE_VELOCITY | FE_ROLE_INPUT,
                                     &sc), FE_OK);
    ck_assert_int_eq(fe_catalog_remove(&c, "drift"), FE_OK);
    nst = fe_model_acc_doubles(3, c.count, 4);
    st = malloc(nst * sizeof *st);
    copy = malloc(nst * sizeof *st);
    ck_assert_ptr_nonnull(st);
    ck_assert_ptr_nonnull(copy);
    ck_assert_int_eq(fe_model_acc_init(&a, &m, &c, 4, 100, st, nst), FE_OK);
    s.input = 0.5;
    s.position = 0.25;
    s.velocity = -0.125;
    s.real = 0.3;                              /* finite: only the time is not */
    for (int i = 0; i < 3; i++) {
        s.t = first[i];
        ck_assert_msg(add_unchanged_if_refused(&a, &s, st, copy, nst) == FE_ENONFINITE,
                      "first row, t = %g", s.t);
    }
    s.t = 1.0;
    ck_assert_int_eq(fe_model_add(&a, &s), FE_OK);
    s.t = INFINITY;
    ck_assert_int_eq(add_unchanged_if_refused(&a, &s, st, copy, nst), FE_ENONFINITE);
    s.t = 2.0;                                 /* the recording goes on */
    ck_assert_int_eq(fe_model_add(&a, &s), FE_OK);
    ck_assert_int_eq(fe_model_break(&a), FE_OK);
    ck_assert_uint_eq(a.acc.n, 2);
    free(st);
    free(copy);
}
END_TEST

START_TEST(arguments_and_failing_callbacks)
{
    fe_catalog_scale sc = {0};
    fe_catalog c;
    fe_model m = {3, theta0, names, rig_predict, rig_jacobian, 0, NULL, NULL};
    fe_model bad = m;
    double zero_typical[3] = {1, 0, 1}, th[3], se[3], *st, *copy;
    fe_model_acc a, before;
    fe_discover_options o = fe_discover_default_options();
    fe_discover_result *r = malloc(sizeof *r);
    size_t nst, base[1], term;
    fe_sample s = {0};
    ck_assert_ptr_nonnull(r);
    ck_assert_int_eq(fe_catalog_init(&c, FE_ROLE_POSITION | FE_ROLE_VELOCITY | FE_ROLE_INPUT,
                                     &sc), FE_OK);
    nst = fe_model_acc_doubles(3, c.count, 4);
    ck_assert_uint_eq(fe_model_acc_doubles(3, FE_DISCOVER_MAX_COLUMNS, 4), 0);
    st = malloc(nst * sizeof *st);
    copy = malloc(nst * sizeof *st);
    ck_assert_int_eq(fe_model_acc_init(NULL, &m, &c, 4, 100, st, nst), FE_EINVAL);
    ck_assert_int_eq(fe_model_acc_init(&a, NULL, &c, 4, 100, st, nst), FE_EINVAL);
    ck_assert_int_eq(fe_model_acc_init(&a, &m, NULL, 4, 100, st, nst), FE_EINVAL);
    bad.theta0 = NULL;
    ck_assert_int_eq(fe_model_acc_init(&a, &bad, &c, 4, 100, st, nst), FE_EINVAL);
    bad = m;
    bad.p = 0;
    ck_assert_int_eq(fe_model_acc_init(&a, &bad, &c, 4, 100, st, nst), FE_EINVAL);
    bad.p = FE_MODEL_MAX_PARAMS + 1;
    ck_assert_int_eq(fe_model_acc_init(&a, &bad, &c, 4, 100, st, nst), FE_EINVAL);
    bad = m;
    bad.typical = zero_typical;
    ck_assert_int_eq(fe_model_acc_init(&a, &bad, &c, 4, 100, st, nst), FE_ENONFINITE);
    /* Names: given, or made. */
    ck_assert_int_eq(fe_model_acc_init(&a, &m, &c, 4, 100, st, nst), FE_OK);
    ck_assert_str_eq(fe_model_group_name(&a, 1), "frequency");
    ck_assert_ptr_null(fe_model_group_name(&a, a.ngroups));
    ck_assert_ptr_null(fe_model_group_name(NULL, 0));
    ck_assert_int_eq(fe_model_group_is_term(&a, 0, &term), 0);
    ck_assert_int_eq(fe_model_group_is_term(&a, 3, &term), 1);
    ck_assert_uint_eq(term, 0);
    ck_assert_int_eq(fe_model_group_is_term(&a, 3, NULL), 1);
    ck_assert_int_eq(fe_model_group_is_term(NULL, 3, &term), 0);
    /* The last group is a term; the one after it is no group. */
    ck_assert_int_eq(fe_model_group_is_term(&a, a.ngroups - 1, &term), 1);
    ck_assert_uint_eq(term, a.ngroups - 1 - a.model.p);
    term = 77;
    ck_assert_int_eq(fe_model_group_is_term(&a, a.ngroups, &term), 0);
    ck_assert_uint_eq(term, 77);
    bad = m;
    bad.names = NULL;
    ck_assert_int_eq(fe_model_acc_init(&a, &bad, &c, 4, 100, st, nst), FE_OK);
    ck_assert_str_eq(fe_model_group_name(&a, 1), "theta2");
    /* The widest model, p + terms = FE_DISCOVER_MAX_GROUPS groups (the
       position terms and user terms up to it): the last group is named,
       and the one after it, where groups[] has no entry, is out of range:
       NULL, as model.h says. */
    {
        fe_catalog wide;
        double one = 1.0, *stw;
        size_t nw;
        char tn[FE_DISCOVER_MAX_GROUPS][16];
        ck_assert_int_eq(fe_catalog_init(&wide, FE_ROLE_POSITION, &sc), FE_OK);
        for (size_t j = wide.count; 3 + j < FE_DISCOVER_MAX_GROUPS; j++) {
            snprintf(tn[j], sizeof tn[j], "w%zu", j);
            ck_assert_int_eq(fe_catalog_add(&wide, tn[j], "", time_term, &one), FE_OK);
        }
        ck_assert_uint_eq(3 + wide.count, FE_DISCOVER_MAX_GROUPS);
        nw = fe_model_acc_doubles(3, wide.count, 4);
        ck_assert_uint_gt(nw, 0);
        stw = malloc(nw * sizeof *stw);
        ck_assert_ptr_nonnull(stw);
        ck_assert_int_eq(fe_model_acc_init(&a, &m, &wide, 4, 100, stw, nw), FE_OK);
        ck_assert_uint_eq(a.ngroups, FE_DISCOVER_MAX_GROUPS);
        ck_assert_str_eq(fe_model_group_name(&a, FE_DISCOVER_MAX_GROUPS - 1),
                         tn[FE_DISCOVER_MAX_GROUPS - 4]);
        ck_assert_ptr_null(fe_model_group_name(&a, FE_DISCOVER_MAX_GROUPS));
        ck_assert_ptr_null(fe_model_group_name(&a, FE_DISCOVER_MAX_GROUPS + 1));
        free(stw);
    }
    /* Rows: failing and non-finite Jacobians, failing finite differences,
       NULL arguments; every refusal leaves the accumulation as it was. */
    ck_assert_int_eq(fe_model_acc_init(&a, &m, &c, 4, 100, st, nst), FE_OK);
    s.t = 1;
    s.input = 0.5;
    s.real = 0.3;
    ck_assert_int_eq(fe_model_add(&a, &s), FE_OK);
    memcpy(&before, &a, sizeof a);
    memcpy(copy, st, nst * sizeof *st);
    s.t = 2;
    a.model.jacobian = failing_jacobian;
    ck_assert_int_eq(fe_model_add(&a, &s), FE_ESTOPPED);
    a.model.jacobian = nan_jacobian;
    ck_assert_int_eq(fe_model_add(&a, &s), FE_ENONFINITE);
    a.model.jacobian = nan0_jacobian;
    ck_assert_int_eq(fe_model_add(&a, &s), FE_ENONFINITE);
    a.model.jacobian = inf1_jacobian;
    ck_assert_int_eq(fe_model_add(&a, &s), FE_ENONFINITE);
    a.model.jacobian = NULL;
    a.model.predict = failing_away_predict;
    ck_assert_int_eq(fe_model_add(&a, &s), FE_ESTOPPED);
    a.model.forward = 1;
    ck_assert_int_eq(fe_model_add(&a, &s), FE_ESTOPPED);
    a.model = before.model;
    ck_assert_int_eq(fe_model_add(NULL, &s), FE_EINVAL);
    ck_assert_int_eq(fe_model_add(&a, NULL), FE_EINVAL);
    ck_assert_mem_eq(&a, &before, sizeof a);
    ck_assert_mem_eq(st, copy, nst * sizeof *st);
    /* Selecting: NULLs, a held row, bad base terms. */
    for (int i = 2; i < 40; i++) {
        s.t = i;
        s.position = 0.01 * i * (i % 3);
        s.velocity = 0.02 * (i % 5);
        s.input = (i % 7) * 0.1;
        s.real = 0.1 * (i % 4);
        ck_assert_int_eq(fe_model_add(&a, &s), FE_OK);
    }
    {
        size_t nw = fe_model_workspace_doubles(&a);
        double *w = malloc(nw * sizeof *w);
        ck_assert_uint_eq(fe_model_workspace_doubles(NULL), 0);
        ck_assert_int_eq(fe_model_select(&a, NULL, r, w, nw), FE_EINVAL);   /* row held */
        ck_assert_int_eq(fe_model_break(NULL), FE_EINVAL);
        ck_assert_int_eq(fe_model_break(&a), FE_OK);
        ck_assert_int_eq(fe_model_select(NULL, NULL, r, w, nw), FE_EINVAL);
        ck_assert_int_eq(fe_model_select(&a, NULL, NULL, w, nw), FE_EINVAL);
        o.nbase = 1;
        o.base = NULL;
        ck_assert_int_eq(fe_model_select(&a, &o, r, w, nw), FE_EINVAL);
        base[0] = c.count;
        o.base = base;
        ck_assert_int_eq(fe_model_select(&a, &o, r, w, nw), FE_EINVAL);
        ck_assert_int_eq(fe_model_theta(NULL, r, th, se), FE_EINVAL);
        ck_assert_int_eq(fe_model_theta(&a, NULL, th, se), FE_EINVAL);
        ck_assert_int_eq(fe_model_theta(&a, r, NULL, se), FE_EINVAL);
        free(w);
    }
    /* The parameters read from a result written here: columns 0 and 2
       (parameters) and 3 (a catalog term) chosen, column 1 set aside.
       theta = theta0 + coef for 0 and 2, theta0 with se 0 for 1. */
    memset(r, 0, sizeof *r);
    r->ncols = 3;
    r->cols[0] = 2;
    r->cols[1] = 0;
    r->cols[2] = 3;
    r->coef[0] = -0.25;
    r->coef[1] = 0.5;
    r->coef[2] = 7.0;
    r->stderr_[0] = 0.2;
    r->stderr_[1] = 0.1;
    r->stderr_[2] = 3.0;
    se[0] = se[1] = se[2] = -1.0;
    ck_assert_int_eq(fe_model_theta(&a, r, th, se), FE_EUNDETERMINED);
    ck_assert(th[0] == theta0[0] + 0.5 && th[1] == theta0[1] && th[2] == theta0[2] - 0.25);
    ck_assert(se[0] == 0.1 && se[1] == 0.0 && se[2] == 0.2);
    r->cols[2] = 1;                     /* all three: determined */
    ck_assert_int_eq(fe_model_theta(&a, r, th, NULL), FE_OK);
    ck_assert(th[0] == theta0[0] + 0.5 && th[1] == theta0[1] + 7.0 && th[2] == theta0[2] - 0.25);
    /* p at its largest, FE_MODEL_MAX_PARAMS, is a model; one more is not. */
    {
        double th16[FE_MODEL_MAX_PARAMS] = {0}, *st16;
        size_t n16 = fe_model_acc_doubles(FE_MODEL_MAX_PARAMS, c.count, 4);
        ck_assert_uint_le(FE_MODEL_MAX_PARAMS + c.count, FE_DISCOVER_MAX_COLUMNS);
        ck_assert_uint_gt(n16, 0);
        ck_assert_uint_eq(fe_model_acc_doubles(FE_MODEL_MAX_PARAMS + 1, c.count, 4), 0);
        st16 = malloc(n16 * sizeof *st16);
        ck_assert_ptr_nonnull(st16);
        bad = m;
        bad.p = FE_MODEL_MAX_PARAMS;
        bad.theta0 = th16;
        bad.names = NULL;
        bad.jacobian = NULL;
        ck_assert_int_eq(fe_model_acc_init(&a, &bad, &c, 4, 100, st16, n16), FE_OK);
        ck_assert_uint_eq(a.ngroups, FE_MODEL_MAX_PARAMS + c.count);
        ck_assert_str_eq(fe_model_group_name(&a, FE_MODEL_MAX_PARAMS - 1), "theta16");
        bad.p = FE_MODEL_MAX_PARAMS + 1;
        ck_assert_int_eq(fe_model_acc_init(&a, &bad, &c, 4, 100, st16, n16), FE_EINVAL);
        free(st16);
    }
    free(st);
    free(copy);
    free(r);
}
END_TEST

/* A prediction that is NaN or infinite at one row only. */
static int nan_at_two_predict(const fe_sample *s, const double *th, double *y, void *user)
{
    int rc = rig_predict(s, th, y, user);
    if (s->t == 2.0)
        *y = s->input > 0 ? NAN : INFINITY;
    return rc;
}

/* A prediction not finite at its own row, with the Jacobian analytic
   (finite there) and by differences: the row is refused when it is
   added, with FE_ENONFINITE, and the accumulation is left as it was (a
   refusal only when the row is folded, one row later, would come too
   late to leave it so). */
START_TEST(non_finite_prediction_refused_at_its_row)
{
    fe_catalog_scale sc = {0};
    fe_catalog c;
    fe_model_acc a;
    fe_sample s = {0};
    size_t nst;
    double *st, *copy;
    ck_assert_int_eq(fe_catalog_init(&c, FE_ROLE_POSITION | FE_ROLE_VELOCITY | FE_ROLE_INPUT,
                                     &sc), FE_OK);
    nst = fe_model_acc_doubles(3, c.count, 4);
    st = malloc(nst * sizeof *st);
    copy = malloc(nst * sizeof *st);
    ck_assert_ptr_nonnull(st);
    ck_assert_ptr_nonnull(copy);
    for (int analytic = 0; analytic < 2; analytic++)
        for (int k = 0; k < 2; k++) {
            fe_model m = {3, theta0, names, nan_at_two_predict,
                          analytic ? rig_jacobian : NULL, 0, NULL, NULL};
            ck_assert_int_eq(fe_model_acc_init(&a, &m, &c, 4, 100, st, nst), FE_OK);
            s.t = 1;
            s.input = 0.5;
            s.position = 0.1;
            s.velocity = -0.2;
            s.real = 0.3;
            ck_assert_int_eq(fe_model_add(&a, &s), FE_OK);
            s.t = 2;
            s.input = k == 0 ? 0.5 : -0.5;      /* NaN, then infinity */
            ck_assert_msg(add_unchanged_if_refused(&a, &s, st, copy, nst) == FE_ENONFINITE,
                          "analytic %d, case %d", analytic, k);
            s.t = 3;
            ck_assert_int_eq(fe_model_add(&a, &s), FE_OK);
            ck_assert_int_eq(fe_model_break(&a), FE_OK);
            ck_assert_uint_eq(a.acc.n, 2);
        }
    free(st);
    free(copy);
}
END_TEST

/* Two parameters whose Jacobian columns are equal ((theta1 + theta2) t):
   the data cannot tell them apart, and fe_model_select says so with
   FE_ESINGULAR; the same rows with the columns t and t^2 are selected. */
static int sum_predict(const fe_sample *s, const double *th, double *y, void *user)
{
    *y = th[0] * s->t + th[1] * (*(const int *)user ? s->t * s->t : s->t);
    return 0;
}

static int sum_jacobian(const fe_sample *s, const double *th, double *jac, void *user)
{
    (void)th;
    jac[0] = s->t;
    jac[1] = *(const int *)user ? s->t * s->t : s->t;
    return 0;
}

START_TEST(collinear_parameters_are_singular)
{
    enum { N = 2000, K = 4 };
    static const double th0[2] = {0.5, 0.25};
    for (int apart = 0; apart < 2; apart++) {
        fe_synth_spec spec = fe_synth_default_spec("bias", 5);
        fe_model m = {2, th0, NULL, sum_predict, sum_jacobian, 0, NULL, NULL};
        fe_synth g;
        fe_catalog c;
        fe_model_acc a;
        fe_sample s;
        fe_discover_result *r = malloc(sizeof *r);
        double *st, *work;
        size_t nst, nwork;
        m.user = &apart;
        spec.rows = N;
        ck_assert_int_eq(fe_synth_init(&g, &spec), FE_OK);
        ck_assert_int_eq(fe_catalog_init(&c, g.roles, &g.scale), FE_OK);
        nst = fe_model_acc_doubles(2, c.count, K);
        st = malloc(nst * sizeof *st);
        ck_assert_int_eq(fe_model_acc_init(&a, &m, &c, K, N, st, nst), FE_OK);
        while (fe_synth_next(&g, &s) == FE_OK)
            ck_assert_int_eq(fe_model_add(&a, &s), FE_OK);
        ck_assert_int_eq(fe_model_break(&a), FE_OK);
        nwork = fe_model_workspace_doubles(&a);
        work = malloc(nwork * sizeof *work);
        ck_assert_int_eq(fe_model_select(&a, NULL, r, work, nwork),
                         apart ? FE_OK : FE_ESINGULAR);
        free(work);
        free(st);
        free(r);
    }
}
END_TEST

/* Issue 20: the columns of a model accumulation at their edge: p
   parameters and a catalog of FE_DISCOVER_MAX_COLUMNS - p terms are
   taken, one term more is refused (fe_model_acc_doubles 0, init
   FE_EINVAL), for p = 1 and p = FE_MODEL_MAX_PARAMS. */
START_TEST(parameters_and_terms_fill_the_columns_exactly)
{
    static char names[FE_DISCOVER_MAX_GROUPS][24];
    const size_t ps[2] = {1, FE_MODEL_MAX_PARAMS};
    double th[FE_MODEL_MAX_PARAMS] = {1.0};
    fe_catalog_scale scale = {0, 0, 0, 0, 0, 0};
    fe_expr e;
    ck_assert_int_eq(fe_expr_compile(&e, "t", fe_catalog_var_names(NULL), FE_CATALOG_VARS, NULL,
                                     NULL, 0), FE_OK);
    for (int k = 0; k < 2; k++) {
        size_t p = ps[k], terms = FE_DISCOVER_MAX_COLUMNS - p, n;
        fe_catalog c;
        fe_model m = {p, th, NULL, rig_predict, NULL, 0, NULL, NULL};
        fe_model_acc *a = malloc(sizeof *a);
        double *st;
        ck_assert_int_eq(fe_catalog_init(&c, 0, &scale), FE_OK);
        for (size_t i = 0; c.count < terms; i++) {
            snprintf(names[i], sizeof names[i], "u%zu", i);
            ck_assert_int_eq(fe_catalog_add_expr(&c, names[i], NULL, &e), FE_OK);
        }
        ck_assert_uint_eq(fe_model_acc_doubles(p, terms + 1, 4), 0);
        n = fe_model_acc_doubles(p, terms, 4);
        ck_assert_uint_gt(n, 0);
        st = malloc(n * sizeof *st);
        ck_assert_int_eq(fe_model_acc_init(a, &m, &c, 4, 100, st, n), FE_OK);
        ck_assert_uint_eq(a->ngroups, FE_DISCOVER_MAX_COLUMNS);
        ck_assert_int_eq(fe_catalog_add_expr(&c, "one_more", NULL, &e), FE_OK);
        ck_assert_int_eq(fe_model_acc_init(a, &m, &c, 4, 100, st, n), FE_EINVAL);
        free(st);
        free(a);
    }
}
END_TEST

Suite *fe_model_suite(void)
{
    Suite *s = suite_create("model");
    TCase *t = tcase_create("model");
    tcase_set_timeout(t, 600);
    tcase_add_test(t, finite_difference_steps_and_calls);
    tcase_add_test(t, the_fold_is_its_rows);
    tcase_add_test(t, refusals_leave_the_accumulation_unchanged);
    tcase_add_test(t, a_time_that_is_not_finite_is_refused_without_a_term_of_time);
    tcase_add_test(t, a_held_row_whose_difference_overflows_is_dropped);
    tcase_add_test(t, arguments_and_failing_callbacks);
    tcase_add_test(t, non_finite_prediction_refused_at_its_row);
    tcase_add_test(t, analytic_and_numerical_jacobians_discover_the_same);
    tcase_add_test(t, concealed_effects_are_found_through_the_model);
    tcase_add_test(t, a_right_model_discovers_nothing);
    tcase_add_test(t, collinear_parameters_are_singular);
    tcase_add_test(t, parameters_and_terms_fill_the_columns_exactly);
    suite_add_tcase(s, t);
    return s;
}
