/* SPDX-License-Identifier: MIT */
/* The catalog: every built-in term evaluated against its documented
   formula, the scale's first pass, user terms, and every coefficient read in
   words (the sign conventions of catalog.org). */
#include "foldest.h"
#include "testutil.h"

static double user_term(const fe_sample *s, const fe_catalog_scale *c, void *u)
{
    (void)c;
    return *(const double *)u * s->t;
}

START_TEST(every_builtin_term_is_its_formula)
{
    fe_catalog_scale scale = {0, 0, 0, 0, 0, 0};
    fe_catalog c;
    fe_sample first = {2.0, 0, 0, 0, 0.5, 1.0, 20.0, 15.0, 0.25};
    fe_sample s = {5.0, 1.0, 3.0, -0.5, 2.0, -4.0, 30.0, 10.0, 7.0};
    double phi[FE_DISCOVER_MAX_GROUPS];
    size_t n;
    const fe_term *b = fe_catalog_builtin_terms(&n);
    ck_assert_uint_eq(n, 13);
    ck_assert_int_eq(fe_catalog_scale_add(&scale, &first), FE_OK);
    ck_assert_int_eq(fe_catalog_scale_add(&scale, &s), FE_OK);
    ck_assert_int_eq(fe_catalog_scale_add(NULL, &s), FE_EINVAL);
    ck_assert_uint_eq(scale.n, 2);
    ck_assert(scale.t_first == 2.0 && scale.temperature_first == 20.0 && scale.vmax == 4.0);
    ck_assert_int_eq(fe_catalog_init(&c, FE_ROLE_POSITION | FE_ROLE_VELOCITY | FE_ROLE_TEMPERATURE
                                         | FE_ROLE_AMBIENT | FE_ROLE_INPUT, &scale), FE_OK);
    ck_assert_uint_eq(c.count, n);
    ck_assert_int_eq(fe_catalog_eval(&c, &s, phi), FE_OK);
    {
        const double tk = 30.0 + 273.15, ak = 10.0 + 273.15;
        const struct { const char *name; double want; } w[] = {
            {"bias", 1.0}, {"drift", 3.0}, {"gain", 3.0}, {"delay", -0.5},
            {"viscous_friction", -4.0}, {"quadratic_drag", -16.0},
            {"coulomb_friction", tanh(-4.0 / (0.002 * 4.0))}, {"linear_stiffness", 2.0},
            {"cubic_stiffness", 8.0}, {"thermal_sensitivity", 10.0}, {"newton_cooling", 20.0},
            {"radiative_cooling", tk * tk * tk * tk - ak * ak * ak * ak}, {"input_gain", 7.0},
        };
        for (size_t i = 0; i < sizeof w / sizeof w[0]; i++) {
            long j = fe_catalog_find(&c, w[i].name);
            ck_assert_msg(j >= 0, "%s missing", w[i].name);
            ck_assert_str_eq(b[j].name, w[i].name);
            FE_ASSERT_REL(phi[j], w[i].want, 1e-12);
        }
    }
    /* Temperatures already in kelvin are not shifted. */
    scale.temperature_kelvin = scale.ambient_kelvin = 1;
    ck_assert_int_eq(fe_catalog_init(&c, FE_ROLE_TEMPERATURE | FE_ROLE_AMBIENT, &scale), FE_OK);
    ck_assert_int_eq(fe_catalog_eval(&c, &s, phi), FE_OK);
    FE_ASSERT_REL(phi[fe_catalog_find(&c, "radiative_cooling")], 30.0 * 30 * 30 * 30 - 1e4, 1e-12);
    /* Only the terms whose roles are present. */
    ck_assert_int_eq(fe_catalog_init(&c, 0, &scale), FE_OK);
    ck_assert_int_eq(fe_catalog_find(&c, "quadratic_drag"), -1);
    ck_assert_int_ge(fe_catalog_find(&c, "bias"), 0);
    ck_assert_int_eq(fe_catalog_init(NULL, 0, &scale), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_eval(NULL, &s, phi), FE_EINVAL);
}
END_TEST

START_TEST(user_terms_and_a_full_catalog)
{
    fe_catalog_scale scale = {0, 0, 0, 0, 0, 0};
    fe_catalog c;
    double k = 3.0, phi[FE_DISCOVER_MAX_GROUPS];
    fe_sample s = {2.0, 0, 0, 0, 0, 0, 0, 0, 0};
    fe_discover_group g[FE_DISCOVER_MAX_GROUPS];
    char name[FE_DISCOVER_MAX_GROUPS][16];
    ck_assert_int_eq(fe_catalog_init(&c, 0, &scale), FE_OK);
    ck_assert_int_eq(fe_catalog_add(&c, "bias", "again", user_term, &k), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_add(&c, "u", "user", NULL, &k), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_add(&c, "u", "user", user_term, &k), FE_OK);
    ck_assert_int_eq(fe_catalog_eval(&c, &s, phi), FE_OK);
    ck_assert(phi[fe_catalog_find(&c, "u")] == 6.0);
    k = NAN;
    ck_assert_int_eq(fe_catalog_eval(&c, &s, phi), FE_ENONFINITE);
    k = 1.0;
    for (size_t i = c.count; i < FE_DISCOVER_MAX_GROUPS; i++) {
        snprintf(name[i], sizeof name[i], "t%zu", i);
        ck_assert_int_eq(fe_catalog_add(&c, name[i], "", user_term, &k), FE_OK);
    }
    ck_assert_int_eq(fe_catalog_add(&c, "one_more", "", user_term, &k), FE_ESIZE);
    fe_catalog_groups(&c, g);
    ck_assert_str_eq(g[FE_DISCOVER_MAX_GROUPS - 1].name, name[FE_DISCOVER_MAX_GROUPS - 1]);
    ck_assert_uint_eq(g[5].first, 5);
    ck_assert_uint_eq(g[5].count, 1);
}
END_TEST

/* A built-in term's name stays reserved after the term is removed from
   the catalog: an expression term may not take it (catalog.h: "a name
   already present or of a built-in term"), whichever built-in it is, the
   table's first ("bias") and last too.  The names are the documented
   thirteen, written out here, not read from the table. */
START_TEST(a_removed_builtin_keeps_its_name)
{
    static const char *const names[] = {
        "bias", "drift", "gain", "delay", "viscous_friction", "quadratic_drag",
        "coulomb_friction", "linear_stiffness", "cubic_stiffness", "thermal_sensitivity",
        "newton_cooling", "radiative_cooling", "input_gain"};
    const size_t nn = sizeof names / sizeof names[0];
    const unsigned all = FE_ROLE_POSITION | FE_ROLE_VELOCITY | FE_ROLE_TEMPERATURE
                         | FE_ROLE_AMBIENT | FE_ROLE_INPUT;
    fe_catalog_scale scale = {0, 0, 0, 0, 0, 0};
    fe_catalog c;
    fe_expr e;
    size_t nv, col = 0;
    const char *const *vn = fe_catalog_var_names(&nv);
    ck_assert_int_eq(fe_expr_compile(&e, "2*t", vn, nv, &col, NULL, 0), FE_OK);
    scale.vmax = 1.0;
    for (size_t i = 0; i < nn; i++) {
        ck_assert_int_eq(fe_catalog_init(&c, all, &scale), FE_OK);
        ck_assert_uint_eq(c.count, nn);
        ck_assert_int_eq(fe_catalog_remove(&c, names[i]), FE_OK);
        ck_assert_int_eq(fe_catalog_find(&c, names[i]), -1);
        ck_assert_msg(fe_catalog_add_expr(&c, names[i], "mine", &e) == FE_EINVAL,
                      "%s taken by an expression term", names[i]);
        ck_assert_uint_eq(c.count, nn - 1);
        ck_assert_int_eq(fe_catalog_find(&c, names[i]), -1);
        /* A name of no built-in is taken, in the place the other left. */
        ck_assert_int_eq(fe_catalog_add_expr(&c, "mine", NULL, &e), FE_OK);
        ck_assert_int_eq(fe_catalog_find(&c, "mine"), (long)nn - 1);
    }
}
END_TEST

/* A term given by expression is a term like the others: it evaluates to
   its formula, from a sample or from a row with the caller's own columns,
   a panel equals its rows, and its refusals leave the catalog as it was. */
START_TEST(expression_terms_through_the_catalog)
{
    fe_catalog_scale scale = {0, 0, 0, 0, 0, 0};
    fe_catalog c;
    fe_expr drag, load, bad;
    size_t nv, col = 0, bad_row = 99;
    const char *const *vn = fe_catalog_var_names(&nv);
    const char *names[FE_CATALOG_VARS + 1];
    enum { N = 7, LDV = FE_CATALOG_VARS + 1 };
    double rows[N * LDV], phi[N * 16], one[16], work[64 * N];
    fe_sample s[N];
    ck_assert_uint_eq(nv, FE_CATALOG_VARS);
    ck_assert_str_eq(vn[FE_CATALOG_VAR_VELOCITY], "velocity");
    for (size_t i = 0; i < nv; i++)
        names[i] = vn[i];
    names[nv] = "load [N]";
    ck_assert_int_eq(fe_expr_compile(&drag, "velocity*abs(velocity)", names, nv, &col, NULL, 0),
                     FE_OK);
    ck_assert_int_eq(fe_expr_compile(&load, "2*`load [N]` + t", names, nv + 1, &col, NULL, 0),
                     FE_OK);
    ck_assert_int_eq(fe_expr_compile(&bad, "log(position)", names, nv, &col, NULL, 0), FE_OK);
    scale.vmax = 1.0;
    ck_assert_int_eq(fe_catalog_init(&c, FE_ROLE_VELOCITY, &scale), FE_OK);
    /* Refusals: a built-in's name (present or not), a name twice, NULLs. */
    ck_assert_int_eq(fe_catalog_add_expr(&c, "quadratic_drag", "", &drag), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_add_expr(&c, "cubic_stiffness", "", &drag), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_add_expr(&c, "mine", "", NULL), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_add_expr(NULL, "mine", "", &drag), FE_EINVAL);
    ck_assert_uint_eq(c.count, 7);
    ck_assert_int_eq(fe_catalog_add_expr(&c, "my_drag", "drag, mine", &drag), FE_OK);
    ck_assert_int_eq(fe_catalog_add_expr(&c, "my_drag", "again", &load), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_add_expr(&c, "load", NULL, &load), FE_OK);
    ck_assert_str_eq(c.terms[fe_catalog_find(&c, "my_drag")].description, "drag, mine");
    ck_assert_str_eq(c.terms[fe_catalog_find(&c, "load")].description, "user term");
    for (size_t t = 0; t < N; t++) {
        memset(&s[t], 0, sizeof s[t]);
        s[t].t = 0.5 * (double)t;
        s[t].sim = 1.0 + (double)t;
        s[t].velocity = -1.5 + 0.5 * (double)t;
        s[t].position = 1.0;
        fe_catalog_row(&s[t], rows + t * LDV);
        ck_assert(rows[t * LDV + FE_CATALOG_VAR_VELOCITY] == s[t].velocity);
        rows[t * LDV + FE_CATALOG_VARS] = 10.0 * (double)t;      /* load [N] */
    }
    /* A panel: every term equals its formula, the built-in ones too. */
    ck_assert_uint_ge(sizeof work / sizeof work[0], fe_catalog_work_doubles(N));
    ck_assert_int_eq(fe_catalog_eval_rows(&c, rows, LDV, N, phi, 16, work, &bad_row), FE_OK);
    for (size_t t = 0; t < N; t++) {
        double v = s[t].velocity;
        ck_assert(phi[t * 16 + (size_t)fe_catalog_find(&c, "my_drag")] == v * fabs(v));
        ck_assert(phi[t * 16 + (size_t)fe_catalog_find(&c, "quadratic_drag")] == v * fabs(v));
        ck_assert(phi[t * 16 + (size_t)fe_catalog_find(&c, "gain")] == s[t].sim);
        ck_assert(phi[t * 16 + (size_t)fe_catalog_find(&c, "load")] == 20.0 * (double)t + s[t].t);
    }
    /* One sample: the same, for terms that read only the sample; a term
       that reads the caller's column cannot be evaluated from a sample. */
    ck_assert_int_eq(fe_catalog_eval(&c, &s[2], one), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_remove(&c, "load"), FE_OK);
    ck_assert_int_eq(fe_catalog_remove(&c, "load"), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_find(&c, "my_drag"), 7);        /* order kept */
    ck_assert_int_eq(fe_catalog_eval(&c, &s[2], one), FE_OK);
    ck_assert(one[7] == s[2].velocity * fabs(s[2].velocity));
    /* Rows too short for an expression, phi too narrow: refused. */
    ck_assert_int_eq(fe_catalog_add_expr(&c, "load", NULL, &load), FE_OK);
    for (size_t i = 0; i < N * 16; i++)
        phi[i] = 12345.0;
    ck_assert_int_eq(fe_catalog_eval_rows(&c, rows, FE_CATALOG_VARS, N, phi, 16, work, NULL),
                     FE_EINVAL);
    /* Refused before anything is written: not even the expression terms
       ahead of "load" (seed 9915's catalog:254, the check of what each
       expression reads left to fe_expr_eval_rows, which refuses "load"
       only after the terms before it are in phi). */
    for (size_t i = 0; i < N * 16; i++)
        ck_assert_msg(phi[i] == 12345.0, "phi[%zu] = %g written", i, phi[i]);
    ck_assert_int_eq(fe_catalog_eval_rows(&c, rows, LDV, N, phi, 3, work, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_eval_rows(&c, rows, LDV, N, phi, 16, NULL, NULL), FE_EINVAL);
    /* A term not finite on row 4 (log of a negative position): that row
       is named, and the panel's values are complete (row 6 too). */
    ck_assert_int_eq(fe_catalog_add_expr(&c, "logx", "", &bad), FE_OK);
    rows[4 * LDV + FE_CATALOG_VAR_POSITION] = -1.0;
    for (size_t i = 0; i < N * 16; i++)
        phi[i] = 12345.0;
    ck_assert_int_eq(fe_catalog_eval_rows(&c, rows, LDV, N, phi, 16, work, &bad_row),
                     FE_ENONFINITE);
    ck_assert_uint_eq(bad_row, 4);
    ck_assert(isnan(phi[4 * 16 + (size_t)fe_catalog_find(&c, "logx")]));
    ck_assert(phi[6 * 16 + (size_t)fe_catalog_find(&c, "logx")] == 0.0);
    ck_assert(phi[6 * 16 + (size_t)fe_catalog_find(&c, "bias")] == 1.0);
}
END_TEST

START_TEST(probes_are_bins_of_a_state_variable)
{
    /* fe_catalog_add_probes on velocity over [-2, 2] in 4 bins: three
       probes, [-inf, -1), [-1, 0), [0, 1); the last bin [1, inf) is left
       out.  Values at the edges (lower edge in, upper edge out), the same
       through fe_catalog_eval and fe_catalog_eval_rows, invisible to
       fe_catalog_find, and every refusal at its edge, all or none. */
    fe_catalog_scale scale = {0, 0, 0, 0, 0, 0};
    fe_catalog c;
    const double v[] = {-5.0, -1.0 - 1e-12, -1.0, -1e-300, 0.0, 0.999, 1.0, 2.0, 7.0};
    const double want[][3] = {{1, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 1, 0}, {0, 0, 1},
                              {0, 0, 1}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    const size_t nv = sizeof v / sizeof v[0];
    double rows[9 * FE_CATALOG_VARS] = {0}, phi[9 * FE_DISCOVER_MAX_GROUPS];
    double work[512];
    size_t n0;
    ck_assert_int_eq(fe_catalog_init(&c, FE_ROLE_VELOCITY, &scale), FE_OK);
    n0 = c.count;
    ck_assert_int_eq(fe_catalog_add_probes(&c, FE_CATALOG_VAR_VELOCITY, -2.0, 2.0, 4), FE_OK);
    ck_assert_uint_eq(c.count, n0 + 3);
    ck_assert_int_eq(fe_catalog_find(&c, "probe_velocity"), -1);
    ck_assert_str_eq(c.terms[n0].name, "probe_velocity");
    ck_assert(c.terms[n0].probe && c.terms[n0].var == FE_CATALOG_VAR_VELOCITY);
    ck_assert(isinf(c.terms[n0].lo) && c.terms[n0].lo < 0 && c.terms[n0].hi == -1.0);
    ck_assert(c.terms[n0 + 2].lo == 0.0 && c.terms[n0 + 2].hi == 1.0);
    ck_assert_uint_ge(sizeof work / sizeof work[0], fe_catalog_work_doubles(nv));
    for (size_t i = 0; i < nv; i++) {
        fe_sample s = {0};
        double one[FE_DISCOVER_MAX_GROUPS];
        s.velocity = v[i];
        rows[i * FE_CATALOG_VARS + FE_CATALOG_VAR_VELOCITY] = v[i];
        ck_assert_int_eq(fe_catalog_eval(&c, &s, one), FE_OK);
        for (size_t k = 0; k < 3; k++)
            ck_assert_msg(one[n0 + k] == want[i][k], "v = %g, probe %zu: %g", v[i], k,
                          one[n0 + k]);
    }
    ck_assert_int_eq(fe_catalog_eval_rows(&c, rows, FE_CATALOG_VARS, nv, phi,
                                          FE_DISCOVER_MAX_GROUPS, work, NULL), FE_OK);
    for (size_t i = 0; i < nv; i++)
        for (size_t k = 0; k < 3; k++)
            ck_assert(phi[i * FE_DISCOVER_MAX_GROUPS + n0 + k] == want[i][k]);
    /* Refusals, the catalog unchanged by each. */
    ck_assert_int_eq(fe_catalog_add_probes(NULL, FE_CATALOG_VAR_VELOCITY, 0, 1, 4), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_add_probes(&c, FE_CATALOG_VAR_DSIM, 0, 1, 4), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_add_probes(&c, FE_CATALOG_VARS, 0, 1, 4), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_add_probes(&c, FE_CATALOG_VAR_INPUT, 0, 1, 1), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_add_probes(&c, FE_CATALOG_VAR_INPUT, 0, 1, FE_CATALOG_MAX_BINS + 1),
                     FE_EINVAL);
    ck_assert_int_eq(fe_catalog_add_probes(&c, FE_CATALOG_VAR_INPUT, 1, 1, 4), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_add_probes(&c, FE_CATALOG_VAR_INPUT, 2, 1, 4), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_add_probes(&c, FE_CATALOG_VAR_INPUT, NAN, 1, 4), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_add_probes(&c, FE_CATALOG_VAR_INPUT, 0, INFINITY, 4), FE_EINVAL);
    ck_assert_uint_eq(c.count, n0 + 3);
    /* The edges that are taken: two bins (one probe), and the most bins. */
    ck_assert_int_eq(fe_catalog_add_probes(&c, FE_CATALOG_VAR_POSITION, 0, 1, 2), FE_OK);
    ck_assert_uint_eq(c.count, n0 + 4);
    ck_assert_int_eq(fe_catalog_add_probes(&c, FE_CATALOG_VAR_INPUT, 0, 1, FE_CATALOG_MAX_BINS),
                     FE_OK);
    ck_assert_uint_eq(c.count, n0 + 4 + FE_CATALOG_MAX_BINS - 1);
    /* Full: exactly enough room is taken, one probe too many is refused
       and nothing is added. */
    {
        size_t room = FE_DISCOVER_MAX_GROUPS - c.count;
        ck_assert_int_eq(fe_catalog_add_probes(&c, FE_CATALOG_VAR_AMBIENT, 0, 1, room + 2),
                         room + 2 > FE_CATALOG_MAX_BINS ? FE_EINVAL : FE_ESIZE);
        while (c.count + FE_CATALOG_MAX_BINS - 1 <= FE_DISCOVER_MAX_GROUPS)
            ck_assert_int_eq(fe_catalog_add_probes(&c, FE_CATALOG_VAR_AMBIENT, 0, 1,
                                                   FE_CATALOG_MAX_BINS), FE_OK);
        room = FE_DISCOVER_MAX_GROUPS - c.count;
        ck_assert_int_eq(fe_catalog_add_probes(&c, FE_CATALOG_VAR_AMBIENT, 0, 1, room + 2),
                         FE_ESIZE);
        ck_assert_uint_eq(c.count, FE_DISCOVER_MAX_GROUPS - room);
        ck_assert_int_eq(fe_catalog_add_probes(&c, FE_CATALOG_VAR_AMBIENT, 0, 1, room + 1),
                         FE_OK);
        ck_assert_uint_eq(c.count, FE_DISCOVER_MAX_GROUPS);
    }
}
END_TEST

START_TEST(every_coefficient_in_words)
{
    const struct { const char *name; double coef; const char *words; } w[] = {
        {"bias", 0.5, "constant offset of 0.5"},
        {"drift", -0.01, "drifting by -0.01"},
        {"gain", 0.02, "(1 +0.02) x simulation"},
        {"delay", -0.03, "lags the simulation by 0.03"},
        {"viscous_friction", -0.2, "b = 0.2"},
        {"quadratic_drag", -0.02, "terminal speed sqrt(g/k) = 22.1 m/s"},
        {"coulomb_friction", -0.3, "mu = 0.3"},
        {"linear_stiffness", -4, "kappa = 4"},
        {"cubic_stiffness", -2, "hardening"},
        {"cubic_stiffness", 2, "softening"},
        {"cubic_stiffness", -0.5, "hardening"}, /* either side of 0, within 1 of it */
        {"cubic_stiffness", 0.5, "softening"},
        {"thermal_sensitivity", 0.7, "0.7 +/- 0.1 channel units per degree"},
        {"newton_cooling", -0.05, "convective loss: -0.05"},
        {"radiative_cooling", -1e-9, "per K^4"},
        {"input_gain", 0.1, "per input unit"},
        {"someone_elses", 1.5, "coefficient 1.5 +/- 0.1"},
        {NULL, 1.5, "coefficient 1.5"},
    };
    char buf[256];
    for (size_t i = 0; i < sizeof w / sizeof w[0]; i++) {
        ck_assert_int_eq(fe_catalog_explain(w[i].name, w[i].coef, 0.1, buf, sizeof buf), FE_OK);
        ck_assert_msg(strstr(buf, w[i].words) != NULL, "%s: \"%s\" lacks \"%s\"",
                      w[i].name ? w[i].name : "(null)", buf, w[i].words);
    }
    ck_assert_int_eq(fe_catalog_explain("bias", 1, 0.1, NULL, 10), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_explain("bias", 1, 0.1, buf, 0), FE_EINVAL);
    /* A short buffer is truncated, never overrun. */
    buf[8] = 'X';
    ck_assert_int_eq(fe_catalog_explain("quadratic_drag", -0.02, 0.01, buf, 8), FE_OK);
    ck_assert_uint_eq(strlen(buf), 7);
    ck_assert(buf[8] == 'X');
}
END_TEST


/* The terminal speed of quadratic drag is told only for k = -coef > 0:
   not at coef 0 or -0 (k not positive: sqrt(g/0) would be infinite), nor
   for a positive coef, the smallest too (sqrt of a negative number).  A
   buffer too short for the first sentence is truncated, and no byte past
   its length is written. */
START_TEST(quadratic_drag_in_words_at_its_edges)
{
    const struct { double coef; int terminal; } w[] = {
        {0.0, 0}, {-0.0, 0}, {DBL_TRUE_MIN, 0}, {0.02, 0}, {-8, 1}, {-0.02, 1},
        /* g / k overflows below k = 9.80665 / DBL_MAX: no speed of inf m/s */
        {-DBL_TRUE_MIN, 0}, {-1e-308, 0}, {-1e-307, 1},
    };
    char buf[256];
    for (size_t i = 0; i < sizeof w / sizeof w[0]; i++) {
        ck_assert_int_eq(fe_catalog_explain("quadratic_drag", w[i].coef, 0.1, buf, sizeof buf),
                         FE_OK);
        ck_assert_msg(strncmp(buf, "quadratic drag: a = -k v|v| with k = ", 37) == 0, "%s", buf);
        ck_assert_msg((strstr(buf, "terminal") != NULL) == w[i].terminal, "%g: %s", w[i].coef,
                      buf);
    }
    /* k = 8: sqrt(9.80665 / 8) = sqrt(1.22583125) = 1.1072 (1.1072^2 =
       1.22589). */
    ck_assert_int_eq(fe_catalog_explain("quadratic_drag", -8, 0.1, buf, sizeof buf), FE_OK);
    ck_assert_msg(strstr(buf, "sqrt(g/k) = 1.11 m/s") != NULL, "%s", buf);
    /* Truncated at 8, 37 and 60 bytes: each byte past the length untouched. */
    const size_t lens[] = {8, 37, 60};
    for (size_t i = 0; i < 3; i++) {
        memset(buf, 'X', sizeof buf);
        ck_assert_int_eq(fe_catalog_explain("quadratic_drag", -0.02, 0.01, buf, lens[i]), FE_OK);
        ck_assert_uint_eq(strlen(buf), lens[i] - 1);
        for (size_t j = lens[i]; j < sizeof buf; j++)
            ck_assert_msg(buf[j] == 'X', "length %zu: byte %zu written", lens[i], j);
    }
}
END_TEST

START_TEST(three_axis_terms_are_their_formulas)
{
    /* A sample at distance 5 from the centre in direction (0.6, 0, 0.8),
       temperature 3 above the first, time 7 after the first. */
    const double b[3] = {10, -20, 30}, x[3] = {13, -20, 34};
    const double want[FE_CATALOG_AXES_COLUMNS] = {1, 0.6, 0, 0.8, 0.36, 0, 0, 0.48, 0,
                                                  1.8, 0, 2.4, 7};
    double phi[FE_CATALOG_AXES_COLUMNS], r;
    fe_catalog_axes c;
    ck_assert_int_eq(fe_catalog_axes_init(&c, b, 1, 100.0, 1, 20.0), FE_OK);
    ck_assert_int_eq(fe_catalog_axes_eval(&c, x, 107.0, 23.0, phi, &r), FE_OK);
    ck_assert_double_eq_tol(r, 5.0, 1e-14);
    for (int j = 0; j < FE_CATALOG_AXES_COLUMNS; j++)
        ck_assert_double_eq_tol(phi[j], want[j], 1e-14);
    /* The groups cover the columns once each, in order. */
    ck_assert_uint_eq(c.ngroups, 6);
    {
        size_t next = 0;
        for (size_t g = 0; g < c.ngroups; g++) {
            ck_assert_uint_eq(c.groups[g].first, next);
            next += c.groups[g].count;
        }
        ck_assert_uint_eq(next, FE_CATALOG_AXES_COLUMNS);
    }
    /* Without a temperature the drift is the fifth group, and its words
       are a drift's, not a temperature's. */
    ck_assert_int_eq(fe_catalog_axes_init(&c, b, 1, 100.0, 0, NAN), FE_OK);
    ck_assert_uint_eq(c.ngroups, 5);
    ck_assert_str_eq(c.groups[4].name, "drift");
    ck_assert_uint_eq(c.groups[4].first, 12);
    ck_assert_str_eq(c.description[4], "a field or a gain drifting with time");
    ck_assert_int_eq(fe_catalog_axes_init(&c, b, 0, NAN, 0, NAN), FE_OK);
    ck_assert_uint_eq(c.ngroups, 4);
    ck_assert_str_eq(c.groups[3].name, "cross_axis");
    /* Refusals. */
    ck_assert_int_eq(fe_catalog_axes_eval(&c, b, 0, 0, phi, &r), FE_ESINGULAR);
    {
        double far[3] = {1e200, 1e200, 0}, nan3[3] = {0, NAN, 0}, bad[3] = {0, 0, INFINITY};
        ck_assert_int_eq(fe_catalog_axes_eval(&c, far, 0, 0, phi, &r), FE_ENONFINITE);
        ck_assert_int_eq(fe_catalog_axes_eval(&c, nan3, 0, 0, phi, &r), FE_ENONFINITE);
        ck_assert_int_eq(fe_catalog_axes_eval(&c, x, NAN, 0, phi, &r), FE_ENONFINITE);
        ck_assert_int_eq(fe_catalog_axes_eval(&c, x, 0, NAN, phi, &r), FE_ENONFINITE);
        /* A NaN in each coordinate alone (its length is NaN too, which the
           singular test would otherwise take). */
        for (int i = 0; i < 3; i++) {
            double y[3] = {x[0], x[1], x[2]};
            y[i] = NAN;
            ck_assert_int_eq(fe_catalog_axes_eval(&c, y, 0, 0, phi, &r), FE_ENONFINITE);
        }
        ck_assert_int_eq(fe_catalog_axes_init(&c, bad, 0, 0, 0, 0), FE_ENONFINITE);
        ck_assert_int_eq(fe_catalog_axes_init(&c, b, 1, NAN, 0, 0), FE_ENONFINITE);
        ck_assert_int_eq(fe_catalog_axes_init(&c, b, 0, 0, 1, INFINITY), FE_ENONFINITE);
    }
    ck_assert_int_eq(fe_catalog_axes_init(NULL, b, 0, 0, 0, 0), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_axes_eval(&c, x, 0, 0, NULL, &r), FE_EINVAL);
}
END_TEST

START_TEST(three_axis_gain_is_read_from_its_coefficients)
{
    /* y = (I + E)(x - b) on a sphere of radius R, E symmetric with diagonal
       (0.02, -0.01, 0) and 0.015 between x and y: |y| = R (1 + u'Eu) + O(E^2),
       and u'Eu = 0.02 u_x^2 - 0.01 u_y^2 + 0.03 u_x u_y exactly in the
       columns bias, axis_gain and the first of cross_axis: least squares of
       the radial residual on them reads E back, to second order. */
    const double b[3] = {1, 2, 3}, R = 50.0;
    double g[64], coef[4], cov[16], work[256], rss;
    fe_lsq l;
    fe_catalog_axes cat;
    ck_assert_uint_le(fe_lsq_storage(4), 64);
    ck_assert_uint_le(fe_lsq_solve_work(4), 256);
    ck_assert_int_eq(fe_catalog_axes_init(&cat, b, 0, 0, 0, 0), FE_OK);
    fe_lsq_init(&l, 4, g);
    for (int i = 0; i < 2000; i++) {
        double z = 1.0 - 2.0 * (i + 0.5) / 2000, a = 2.399963 * i, s = sqrt(1 - z * z);
        double u[3] = {s * cos(a), s * sin(a), z}, y[3], phi[FE_CATALOG_AXES_COLUMNS], r;
        y[0] = b[0] + R * (1.02 * u[0] + 0.015 * u[1]);
        y[1] = b[1] + R * (0.015 * u[0] + 0.99 * u[1]);
        y[2] = b[2] + R * u[2];
        ck_assert_int_eq(fe_catalog_axes_eval(&cat, y, 0, 0, phi, &r), FE_OK);
        {
            double row[4] = {phi[0], phi[4], phi[5], phi[6]};
            ck_assert_int_eq(fe_lsq_add(&l, row, r - R, 1.0), FE_OK);
        }
    }
    ck_assert_int_eq(fe_lsq_solve(&l, NULL, 4, coef, &rss, cov, work), FE_OK);
    ck_assert_double_eq_tol(coef[0] / R, 0.0, 1e-3);
    ck_assert_double_eq_tol(coef[1] / R, 0.02, 1e-3);
    ck_assert_double_eq_tol(coef[2] / R, -0.01, 1e-3);
    ck_assert_double_eq_tol(coef[3] / R, 0.03, 1e-3);
}
END_TEST

/* Each coordinate of the centre alone not finite (NaN, then +-infinity):
   refused, and the catalog is left as it was; the used t1 and temperature
   at their boundary too: refused when used, ignored when not. */
START_TEST(three_axis_centre_refused_in_each_coordinate)
{
    const double b[3] = {10, -20, 30};
    const double bads[3] = {NAN, INFINITY, -INFINITY};
    fe_catalog_axes c, before;
    ck_assert_int_eq(fe_catalog_axes_init(&c, b, 1, 100.0, 1, 20.0), FE_OK);
    memcpy(&before, &c, sizeof c);
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++) {
            double y[3] = {b[0], b[1], b[2]};
            y[i] = bads[k];
            ck_assert_msg(fe_catalog_axes_init(&c, y, 0, 0, 0, 0) == FE_ENONFINITE,
                          "coordinate %d, value %g", i, bads[k]);
            ck_assert_int_eq(memcmp(&c, &before, sizeof c), 0);
        }
    ck_assert_int_eq(fe_catalog_axes_init(&c, NULL, 0, 0, 0, 0), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_axes_init(&c, b, 0, 0, 1, NAN), FE_ENONFINITE);
    ck_assert_int_eq(fe_catalog_axes_init(&c, b, 1, -INFINITY, 0, 0), FE_ENONFINITE);
    ck_assert_int_eq(memcmp(&c, &before, sizeof c), 0);
    ck_assert_int_eq(fe_catalog_axes_init(&c, b, 0, NAN, 0, INFINITY), FE_OK);
    ck_assert_uint_eq(c.ngroups, 4);
    ck_assert_double_eq(c.centre[0], 10.0);
    ck_assert_double_eq(c.centre[1], -20.0);
    ck_assert_double_eq(c.centre[2], 30.0);
}
END_TEST

/* The first pass's scale: the first time and temperature are the first
   sample's, vmax the largest |velocity| wherever it comes (here in the
   middle, negative), n the samples; and a panel with a term that has
   neither an expression, a function nor a probe is refused. */
START_TEST(scale_is_the_first_sample_and_the_largest_speed)
{
    fe_catalog_scale scale = {0, 0, 0, 0, 0, 0};
    const double v[5] = {0.5, -1.0, -7.5, 3.0, 0.25};
    fe_catalog c;
    double rows[2 * FE_CATALOG_VARS] = {0}, phi[2 * 32], work[64];
    for (int i = 0; i < 5; i++) {
        fe_sample s = {0};
        s.t = 10.0 + i;
        s.temperature = 30.0 - i;
        s.velocity = v[i];
        ck_assert_int_eq(fe_catalog_scale_add(&scale, &s), FE_OK);
    }
    ck_assert_uint_eq(scale.n, 5);
    ck_assert_double_eq(scale.t_first, 10.0);
    ck_assert_double_eq(scale.temperature_first, 30.0);
    ck_assert_double_eq(scale.vmax, 7.5);
    ck_assert_int_eq(fe_catalog_scale_add(&scale, NULL), FE_EINVAL);
    ck_assert_uint_eq(scale.n, 5);
    /* A new pass (n = 0) starts again from its first sample. */
    scale.n = 0;
    {
        fe_sample s = {0};
        s.t = 3.0;
        s.temperature = 4.0;
        s.velocity = -0.5;
        ck_assert_int_eq(fe_catalog_scale_add(&scale, &s), FE_OK);
        ck_assert_double_eq(scale.t_first, 3.0);
        ck_assert_double_eq(scale.temperature_first, 4.0);
        ck_assert_double_eq(scale.vmax, 0.5);
    }
    ck_assert_int_eq(fe_catalog_init(&c, FE_ROLE_VELOCITY, &scale), FE_OK);
    ck_assert_uint_le(c.count, 32);
    ck_assert_uint_le(fe_catalog_work_doubles(2), 64);
    ck_assert_int_eq(fe_catalog_eval_rows(&c, rows, FE_CATALOG_VARS, 2, phi, 32, work, NULL),
                     FE_OK);
    {
        long j = fe_catalog_find(&c, "quadratic_drag");
        ck_assert_int_ge(j, 0);
        ck_assert_ptr_null(c.terms[j].expr);
        ck_assert_int_eq(c.terms[j].probe, 0);
        c.terms[j].eval = NULL;
        ck_assert_int_eq(fe_catalog_eval_rows(&c, rows, FE_CATALOG_VARS, 2, phi, 32, work, NULL),
                         FE_EINVAL);
    }
}
END_TEST

/* Issue 20: fe_catalog_eval_rows' strides at their edges: ldphi equal to
   the number of terms is enough and one less refused, as is a row stride
   of FE_CATALOG_VARS and one less (phi untouched when refused). */
START_TEST(row_and_term_strides_at_their_edges)
{
    fe_catalog_scale scale = {0, 0, 0, 0, 0, 0};
    fe_catalog c;
    fe_sample s;
    double rows[2 * FE_CATALOG_VARS], *phi, work[64];
    size_t nt;
    memset(&s, 0, sizeof s);
    s.velocity = 2.0;
    s.sim = 3.0;
    ck_assert_int_eq(fe_catalog_init(&c, FE_ROLE_VELOCITY, &scale), FE_OK);
    nt = c.count;
    ck_assert_uint_gt(nt, 1);
    fe_catalog_row(&s, rows);
    fe_catalog_row(&s, rows + FE_CATALOG_VARS);
    ck_assert_uint_ge(sizeof work / sizeof work[0], fe_catalog_work_doubles(2));
    phi = malloc(2 * nt * sizeof *phi);
    ck_assert_ptr_nonnull(phi);
    for (size_t i = 0; i < 2 * nt; i++)
        phi[i] = -7.0;
    ck_assert_int_eq(fe_catalog_eval_rows(&c, rows, FE_CATALOG_VARS, 2, phi, nt - 1, work, NULL),
                     FE_EINVAL);
    ck_assert_int_eq(fe_catalog_eval_rows(&c, rows, FE_CATALOG_VARS - 1, 2, phi, nt, work, NULL),
                     FE_EINVAL);
    for (size_t i = 0; i < 2 * nt; i++)
        ck_assert_double_eq(phi[i], -7.0);
    ck_assert_int_eq(fe_catalog_eval_rows(&c, rows, FE_CATALOG_VARS, 2, phi, nt, work, NULL),
                     FE_OK);
    ck_assert_double_eq(phi[(size_t)fe_catalog_find(&c, "gain")], 3.0);
    ck_assert_double_eq(phi[nt + (size_t)fe_catalog_find(&c, "quadratic_drag")], 4.0);
    free(phi);
}
END_TEST

/* Each pointer argument of each catalog function null alone, the others
   valid: FE_EINVAL, and nothing written (seed 10301's catalog:176, two
   of the three null checks of fe_catalog_eval joined by && instead of ||:
   the only null tested was the catalog's, with sample and output given). */
START_TEST(each_null_argument_is_refused_alone)
{
    enum { N = 2 };
    fe_catalog_scale scale = {0, 0, 0, 0, 0, 0};
    fe_catalog c;
    fe_catalog_axes ax;
    fe_sample s = {5.0, 1.0, 3.0, -0.5, 2.0, -4.0, 30.0, 10.0, 7.0};
    double phi[N * FE_DISCOVER_MAX_GROUPS], rows[N * FE_CATALOG_VARS], r = 0;
    double k = 3.0, *work = malloc(fe_catalog_work_doubles(N) * sizeof *work);
    const double b[3] = {10, -20, 30}, x[3] = {13, -20, 34};
    size_t nv, col = 0, count;
    const char *const *vn = fe_catalog_var_names(&nv);
    fe_expr e;
    ck_assert_ptr_nonnull(work);
    ck_assert_int_eq(fe_expr_compile(&e, "2*t", vn, nv, &col, NULL, 0), FE_OK);
    ck_assert_int_eq(fe_catalog_scale_add(&scale, &s), FE_OK);
    ck_assert_int_eq(fe_catalog_scale_add(&scale, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_scale_add(NULL, &s), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_init(&c, FE_ROLE_POSITION | FE_ROLE_VELOCITY, &scale), FE_OK);
    ck_assert_int_eq(fe_catalog_init(NULL, 0, &scale), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_init(&c, 0, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_init(&c, FE_ROLE_POSITION | FE_ROLE_VELOCITY, &scale), FE_OK);
    count = c.count;
    /* Adding a term: catalog, name, function or expression null. */
    ck_assert_int_eq(fe_catalog_add(NULL, "u", "user", user_term, &k), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_add(&c, NULL, "user", user_term, &k), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_add(&c, "u", "user", NULL, &k), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_add_expr(NULL, "v", "", &e), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_add_expr(&c, NULL, "", &e), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_add_expr(&c, "v", "", NULL), FE_EINVAL);
    ck_assert_uint_eq(c.count, count);
    ck_assert_int_eq(fe_catalog_add(&c, "u", "user", user_term, &k), FE_OK);
    ck_assert_int_eq(fe_catalog_add_expr(&c, "v", "", &e), FE_OK);
    count = c.count;
    /* One sample: catalog, sample or output null; phi untouched. */
    for (size_t j = 0; j < count; j++)
        phi[j] = -7.0;
    ck_assert_int_eq(fe_catalog_eval(NULL, &s, phi), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_eval(&c, NULL, phi), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_eval(&c, &s, NULL), FE_EINVAL);
    for (size_t j = 0; j < count; j++)
        ck_assert_double_eq(phi[j], -7.0);
    ck_assert_int_eq(fe_catalog_eval(&c, &s, phi), FE_OK);
    ck_assert_double_eq(phi[count - 2], 3.0 * s.t);
    ck_assert_double_eq(phi[count - 1], 2.0 * s.t);
    /* Rows: catalog, rows, output or workspace null; phi untouched. */
    fe_catalog_row(&s, rows);
    fe_catalog_row(&s, rows + FE_CATALOG_VARS);
    for (size_t j = 0; j < N * count; j++)
        phi[j] = -7.0;
    ck_assert_int_eq(fe_catalog_eval_rows(NULL, rows, FE_CATALOG_VARS, N, phi, count, work, NULL),
                     FE_EINVAL);
    ck_assert_int_eq(fe_catalog_eval_rows(&c, NULL, FE_CATALOG_VARS, N, phi, count, work, NULL),
                     FE_EINVAL);
    ck_assert_int_eq(fe_catalog_eval_rows(&c, rows, FE_CATALOG_VARS, N, NULL, count, work, NULL),
                     FE_EINVAL);
    ck_assert_int_eq(fe_catalog_eval_rows(&c, rows, FE_CATALOG_VARS, N, phi, count, NULL, NULL),
                     FE_EINVAL);
    for (size_t j = 0; j < N * count; j++)
        ck_assert_double_eq(phi[j], -7.0);
    ck_assert_int_eq(fe_catalog_eval_rows(&c, rows, FE_CATALOG_VARS, N, phi, count, work, NULL),
                     FE_OK);
    ck_assert_double_eq(phi[2 * count - 2], 3.0 * s.t);
    /* Probes: catalog null. */
    ck_assert_int_eq(fe_catalog_add_probes(NULL, FE_CATALOG_VAR_VELOCITY, 0, 1, 4), FE_EINVAL);
    /* Three axes: catalog, centre, sample, output or radius null. */
    ck_assert_int_eq(fe_catalog_axes_init(NULL, b, 0, 0, 0, 0), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_axes_init(&ax, NULL, 0, 0, 0, 0), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_axes_init(&ax, b, 0, 0, 0, 0), FE_OK);
    for (size_t j = 0; j < FE_CATALOG_AXES_COLUMNS; j++)
        phi[j] = -7.0;
    ck_assert_int_eq(fe_catalog_axes_eval(NULL, x, 0, 0, phi, &r), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_axes_eval(&ax, NULL, 0, 0, phi, &r), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_axes_eval(&ax, x, 0, 0, NULL, &r), FE_EINVAL);
    ck_assert_int_eq(fe_catalog_axes_eval(&ax, x, 0, 0, phi, NULL), FE_EINVAL);
    for (size_t j = 0; j < FE_CATALOG_AXES_COLUMNS; j++)
        ck_assert_double_eq(phi[j], -7.0);
    ck_assert_double_eq(r, 0.0);
    ck_assert_int_eq(fe_catalog_axes_eval(&ax, x, 0, 0, phi, &r), FE_OK);
    ck_assert_double_eq_tol(r, 5.0, 1e-14);   /* |(3, 0, 4)| */
    free(work);
}
END_TEST

Suite *fe_catalog_suite(void)
{
    Suite *s = suite_create("catalog");
    TCase *t = tcase_create("terms");
    tcase_add_test(t, every_builtin_term_is_its_formula);
    tcase_add_test(t, user_terms_and_a_full_catalog);
    tcase_add_test(t, expression_terms_through_the_catalog);
    tcase_add_test(t, a_removed_builtin_keeps_its_name);
    tcase_add_test(t, probes_are_bins_of_a_state_variable);
    tcase_add_test(t, every_coefficient_in_words);
    tcase_add_test(t, quadratic_drag_in_words_at_its_edges);
    tcase_add_test(t, three_axis_terms_are_their_formulas);
    tcase_add_test(t, three_axis_gain_is_read_from_its_coefficients);
    tcase_add_test(t, three_axis_centre_refused_in_each_coordinate);
    tcase_add_test(t, scale_is_the_first_sample_and_the_largest_speed);
    tcase_add_test(t, row_and_term_strides_at_their_edges);
    tcase_add_test(t, each_null_argument_is_refused_alone);
    suite_add_tcase(s, t);
    return s;
}
