/* SPDX-License-Identifier: MIT */
/* Tangled from literate/catalog.org: do not edit; edit the .org and run make tangle. */
/* [[file:../literate/catalog.org::Catalog Includes][Catalog Includes]] */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "foldest/catalog.h"
#include "foldest/error.h"
/* Catalog Includes ends here */
/* [[file:../literate/catalog.org::Evaluate the built-in terms][Evaluate the built-in terms]] */
static double fe__kelvin(double t, int is_kelvin)
{
    return is_kelvin ? t : t + 273.15;
}

static double fe__bias(const fe_sample *s, const fe_catalog_scale *c, void *u)
{ (void)s; (void)c; (void)u; return 1.0; }
static double fe__drift(const fe_sample *s, const fe_catalog_scale *c, void *u)
{ (void)u; return s->t - c->t_first; }
static double fe__gain(const fe_sample *s, const fe_catalog_scale *c, void *u)
{ (void)c; (void)u; return s->sim; }
static double fe__delay(const fe_sample *s, const fe_catalog_scale *c, void *u)
{ (void)c; (void)u; return s->dsim; }
static double fe__viscous(const fe_sample *s, const fe_catalog_scale *c, void *u)
{ (void)c; (void)u; return s->velocity; }
static double fe__quadratic(const fe_sample *s, const fe_catalog_scale *c, void *u)
{ (void)c; (void)u; return s->velocity * fabs(s->velocity); }
static double fe__coulomb(const fe_sample *s, const fe_catalog_scale *c, void *u)
{
    (void)u;
    return c->vmax > 0.0 ? tanh(s->velocity / (0.002 * c->vmax)) : 0.0;
}
static double fe__linear(const fe_sample *s, const fe_catalog_scale *c, void *u)
{ (void)c; (void)u; return s->position; }
static double fe__cubic(const fe_sample *s, const fe_catalog_scale *c, void *u)
{ (void)c; (void)u; return s->position * s->position * s->position; }
static double fe__thermal(const fe_sample *s, const fe_catalog_scale *c, void *u)
{ (void)u; return s->temperature - c->temperature_first; }
static double fe__newton(const fe_sample *s, const fe_catalog_scale *c, void *u)
{
    (void)u;
    return fe__kelvin(s->temperature, c->temperature_kelvin)
           - fe__kelvin(s->ambient, c->ambient_kelvin);
}
static double fe__radiative(const fe_sample *s, const fe_catalog_scale *c, void *u)
{
    double t = fe__kelvin(s->temperature, c->temperature_kelvin);
    double a = fe__kelvin(s->ambient, c->ambient_kelvin);
    (void)u;
    return (t * t) * (t * t) - (a * a) * (a * a);
}
static double fe__input(const fe_sample *s, const fe_catalog_scale *c, void *u)
{ (void)c; (void)u; return s->input; }

static const fe_term fe__builtin[] = {
    {.name = "bias", .description = "constant sensor or actuator offset",
     .eval = fe__bias, .needs = 0},
    {.name = "drift", .description = "offset drifting with time",
     .eval = fe__drift, .needs = 0},
    {.name = "gain", .description = "scale-factor error",
     .eval = fe__gain, .needs = 0},
    {.name = "delay", .description = "time lag between simulation and recording",
     .eval = fe__delay, .needs = 0},
    {.name = "viscous_friction",
     .description = "force proportional to velocity (viscous damping, Stokes drag)",
     .eval = fe__viscous, .needs = FE_ROLE_VELOCITY},
    {.name = "quadratic_drag", .description = "aerodynamic (turbulent) drag",
     .eval = fe__quadratic, .needs = FE_ROLE_VELOCITY},
    {.name = "coulomb_friction", .description = "dry friction",
     .eval = fe__coulomb, .needs = FE_ROLE_VELOCITY},
    {.name = "linear_stiffness", .description = "missing spring or restoring force",
     .eval = fe__linear, .needs = FE_ROLE_POSITION},
    {.name = "cubic_stiffness", .description = "hardening or softening spring",
     .eval = fe__cubic, .needs = FE_ROLE_POSITION},
    {.name = "thermal_sensitivity", .description = "temperature coefficient",
     .eval = fe__thermal, .needs = FE_ROLE_TEMPERATURE},
    {.name = "newton_cooling", .description = "convective heat loss",
     .eval = fe__newton, .needs = FE_ROLE_TEMPERATURE | FE_ROLE_AMBIENT},
    {.name = "radiative_cooling", .description = "thermal radiation",
     .eval = fe__radiative, .needs = FE_ROLE_TEMPERATURE | FE_ROLE_AMBIENT},
    {.name = "input_gain", .description = "actuator gain error",
     .eval = fe__input, .needs = FE_ROLE_INPUT},
};

const fe_term *fe_catalog_builtin_terms(size_t *count)
{
    if (count != NULL)
        *count = sizeof fe__builtin / sizeof fe__builtin[0];
    return fe__builtin;
}
/* Evaluate the built-in terms ends here */
/* [[file:../literate/catalog.org::Probe the state][Probe the state]] */
static const char *const fe__probe_names[FE_CATALOG_VARS] = {
    NULL, NULL, NULL, "probe_position", "probe_velocity", "probe_temperature",
    "probe_ambient", "probe_input"};

static double fe__probe(const fe_term *k, const double *row)
{
    double x = row[k->var];
    return x >= k->lo && x < k->hi ? 1.0 : 0.0;
}

int fe_catalog_add_probes(fe_catalog *c, int var, double lo, double hi, size_t bins)
{
    if (c == NULL || var < FE_CATALOG_VAR_POSITION || var >= FE_CATALOG_VARS || bins < 2
        || bins > FE_CATALOG_MAX_BINS || !isfinite(lo) || !isfinite(hi) || !(lo < hi))
        return FE_EINVAL;
    if (c->count + bins - 1 > FE_DISCOVER_MAX_GROUPS)
        return FE_ESIZE;
    for (size_t k = 0; k + 1 < bins; k++) {
        fe_term *t = &c->terms[c->count++];
        memset(t, 0, sizeof *t);
        t->name = fe__probe_names[var];
        t->description = "a probe of the state: the indicator of one bin";
        t->probe = 1;
        t->var = var;
        t->lo = k == 0 ? -INFINITY : lo + (hi - lo) * (double)k / (double)bins;
        t->hi = lo + (hi - lo) * (double)(k + 1) / (double)bins;
    }
    return FE_OK;
}
/* Probe the state ends here */
/* [[file:../literate/catalog.org::Build and evaluate a catalog][Build and evaluate a catalog]] */
int fe_catalog_scale_add(fe_catalog_scale *scale, const fe_sample *s)
{
    if (scale == NULL || s == NULL)
        return FE_EINVAL;
    if (scale->n == 0) {
        scale->t_first = s->t;
        scale->temperature_first = s->temperature;
        scale->vmax = 0.0;
    }
    if (fabs(s->velocity) > scale->vmax)
        scale->vmax = fabs(s->velocity);
    scale->n++;
    return FE_OK;
}

int fe_catalog_init(fe_catalog *c, unsigned roles, const fe_catalog_scale *scale)
{
    size_t nb;
    const fe_term *b = fe_catalog_builtin_terms(&nb);
    if (c == NULL || scale == NULL)
        return FE_EINVAL;
    memset(c, 0, sizeof *c);
    c->roles = roles;
    c->scale = *scale;
    for (size_t i = 0; i < nb; i++)
        if ((b[i].needs & roles) == b[i].needs)
            c->terms[c->count++] = b[i];
    return FE_OK;
}

long fe_catalog_find(const fe_catalog *c, const char *name)
{
    for (size_t i = 0; c != NULL && name != NULL && i < c->count; i++)
        if (!c->terms[i].probe && strcmp(c->terms[i].name, name) == 0)
            return (long)i;
    return -1;
}

int fe_catalog_add(fe_catalog *c, const char *name, const char *description,
                   fe_term_fn *eval, void *user)
{
    if (c == NULL || name == NULL || eval == NULL || fe_catalog_find(c, name) >= 0)
        return FE_EINVAL;
    if (c->count >= FE_DISCOVER_MAX_GROUPS)
        return FE_ESIZE;
    c->terms[c->count].name = name;
    c->terms[c->count].description = description != NULL ? description : "user term";
    c->terms[c->count].eval = eval;
    c->terms[c->count].user = user;
    c->terms[c->count].needs = 0;
    c->terms[c->count].expr = NULL;
    c->count++;
    return FE_OK;
}

int fe_catalog_remove(fe_catalog *c, const char *name)
{
    long j = fe_catalog_find(c, name);
    if (j < 0)
        return FE_EINVAL;
    memmove(&c->terms[j], &c->terms[j + 1], (c->count - (size_t)j - 1) * sizeof c->terms[0]);
    c->count--;
    return FE_OK;
}

int fe_catalog_eval(const fe_catalog *c, const fe_sample *s, double *phi)
{
    double row[FE_CATALOG_VARS];
    if (c == NULL || s == NULL || phi == NULL)
        return FE_EINVAL;
    fe_catalog_row(s, row);
    for (size_t j = 0; j < c->count; j++) {
        const fe_term *k = &c->terms[j];
        if (k->expr != NULL) {
            int rc;
            if (k->expr->nvars > FE_CATALOG_VARS)
                return FE_EINVAL;
            rc = fe_expr_eval(k->expr, row, &phi[j]);
            if (rc != FE_OK)
                return rc;
        } else if (k->probe) {
            phi[j] = fe__probe(k, row);
        } else {
            phi[j] = k->eval(s, &c->scale, k->user);
        }
        if (!isfinite(phi[j]))
            return FE_ENONFINITE;
    }
    return FE_OK;
}

void fe_catalog_groups(const fe_catalog *c, fe_discover_group *groups)
{
    for (size_t j = 0; j < c->count; j++) {
        groups[j].name = c->terms[j].name;
        groups[j].first = j;
        groups[j].count = 1;
    }
}
/* Build and evaluate a catalog ends here */
/* [[file:../literate/catalog.org::Evaluate expression terms][Evaluate expression terms]] */
static const char *const fe__var_names[FE_CATALOG_VARS] = {
    "t", "sim", "dsim", "position", "velocity", "temperature", "ambient", "input"};

const char *const *fe_catalog_var_names(size_t *count)
{
    if (count != NULL)
        *count = FE_CATALOG_VARS;
    return fe__var_names;
}

int fe_catalog_add_expr(fe_catalog *c, const char *name, const char *description,
                        const fe_expr *e)
{
    size_t nb;
    const fe_term *b = fe_catalog_builtin_terms(&nb);
    if (c == NULL || name == NULL || e == NULL || fe_catalog_find(c, name) >= 0)
        return FE_EINVAL;
    for (size_t i = 0; i < nb; i++)
        if (strcmp(b[i].name, name) == 0)
            return FE_EINVAL;
    if (c->count >= FE_DISCOVER_MAX_GROUPS)
        return FE_ESIZE;
    memset(&c->terms[c->count], 0, sizeof c->terms[0]);
    c->terms[c->count].name = name;
    c->terms[c->count].description = description != NULL ? description : "user term";
    c->terms[c->count].expr = e;
    c->count++;
    return FE_OK;
}

void fe_catalog_row(const fe_sample *s, double *row)
{
    row[FE_CATALOG_VAR_T] = s->t;
    row[FE_CATALOG_VAR_SIM] = s->sim;
    row[FE_CATALOG_VAR_DSIM] = s->dsim;
    row[FE_CATALOG_VAR_POSITION] = s->position;
    row[FE_CATALOG_VAR_VELOCITY] = s->velocity;
    row[FE_CATALOG_VAR_TEMPERATURE] = s->temperature;
    row[FE_CATALOG_VAR_AMBIENT] = s->ambient;
    row[FE_CATALOG_VAR_INPUT] = s->input;
}

/* The sample a row stands for (real is not a variable: 0). */
static void fe__row_sample(const double *row, fe_sample *s)
{
    memset(s, 0, sizeof *s);
    s->t = row[FE_CATALOG_VAR_T];
    s->sim = row[FE_CATALOG_VAR_SIM];
    s->dsim = row[FE_CATALOG_VAR_DSIM];
    s->position = row[FE_CATALOG_VAR_POSITION];
    s->velocity = row[FE_CATALOG_VAR_VELOCITY];
    s->temperature = row[FE_CATALOG_VAR_TEMPERATURE];
    s->ambient = row[FE_CATALOG_VAR_AMBIENT];
    s->input = row[FE_CATALOG_VAR_INPUT];
}

size_t fe_catalog_work_doubles(size_t n)
{
    return n + fe_expr_work_doubles(n);
}

int fe_catalog_eval_rows(const fe_catalog *c, const double *rows, size_t ldv, size_t n,
                         double *phi, size_t ldphi, double *work, size_t *bad)
{
    int callbacks = 0;
    if (c == NULL || rows == NULL || phi == NULL || work == NULL || ldv < FE_CATALOG_VARS
        || ldphi < c->count)
        return FE_EINVAL;
    for (size_t j = 0; j < c->count; j++) {
        if (c->terms[j].expr != NULL && c->terms[j].expr->nvars > ldv)
            return FE_EINVAL;
        if (c->terms[j].expr == NULL && c->terms[j].eval == NULL && !c->terms[j].probe)
            return FE_EINVAL;
        callbacks |= c->terms[j].expr == NULL && !c->terms[j].probe;
    }
    /* The probes, straight from the rows. */
    for (size_t j = 0; j < c->count; j++)
        if (c->terms[j].probe)
            for (size_t t = 0; t < n; t++)
                phi[t * ldphi + j] = fe__probe(&c->terms[j], rows + t * ldv);
    /* The expression terms: a column each, then scattered into phi. */
    for (size_t j = 0; j < c->count; j++) {
        int rc;
        if (c->terms[j].expr == NULL)
            continue;
        rc = fe_expr_eval_rows(c->terms[j].expr, rows, ldv, n, work, work + n, NULL);
        if (rc != FE_OK && rc != FE_ENONFINITE)
            return rc;
        for (size_t t = 0; t < n; t++)
            phi[t * ldphi + j] = work[t];
    }
    /* The C terms, row by row. */
    for (size_t t = 0; t < n && callbacks; t++) {
        fe_sample s;
        fe__row_sample(rows + t * ldv, &s);
        for (size_t j = 0; j < c->count; j++)
            if (c->terms[j].expr == NULL && !c->terms[j].probe)
                phi[t * ldphi + j] = c->terms[j].eval(&s, &c->scale, c->terms[j].user);
    }
    for (size_t t = 0; t < n; t++)
        for (size_t j = 0; j < c->count; j++)
            if (!isfinite(phi[t * ldphi + j])) {
                if (bad != NULL)
                    *bad = t;
                return FE_ENONFINITE;
            }
    return FE_OK;
}
/* Evaluate expression terms ends here */
/* [[file:../literate/catalog.org::Read a coefficient in words][Read a coefficient in words]] */
int fe_catalog_explain(const char *name, double coef, double se, char *buf,
                       size_t len)
{
    if (buf == NULL || len == 0)
        return FE_EINVAL;
    if (name == NULL)
        name = "";
    if (strcmp(name, "bias") == 0)
        snprintf(buf, len, "constant offset of %.4g +/- %.2g (channel units)", coef, se);
    else if (strcmp(name, "drift") == 0)
        snprintf(buf, len, "offset drifting by %.4g +/- %.2g per time unit", coef, se);
    else if (strcmp(name, "gain") == 0)
        snprintf(buf, len, "scale-factor error: recording = (1 %+.4g) x simulation (%.3g%% +/- %.2g%%)",
                 coef, 100 * coef, 100 * se);
    else if (strcmp(name, "delay") == 0)
        snprintf(buf, len, "time lag: the recording lags the simulation by %.4g +/- %.2g time units",
                 -coef, se);
    else if (strcmp(name, "viscous_friction") == 0)
        snprintf(buf, len, "viscous damping: a = -b v with b = %.4g +/- %.2g (1/time)", -coef, se);
    else if (strcmp(name, "quadratic_drag") == 0) {
        int n = snprintf(buf, len, "quadratic drag: a = -k v|v| with k = %.4g +/- %.2g (1/length)",
                         -coef, se);
        double vt = -coef > 0 ? sqrt(9.80665 / -coef) : 0.0;
        /* No terminal speed for k <= 0, nor where g / k overflows. */
        if (-coef > 0 && isfinite(vt) && n > 0 && (size_t)n < len)
            snprintf(buf + n, len - (size_t)n,
                     "; terminal speed sqrt(g/k) = %.3g m/s for an acceleration in m/s^2", vt);
    } else if (strcmp(name, "coulomb_friction") == 0)
        snprintf(buf, len, "dry friction: a = -mu sign(v) with mu = %.4g +/- %.2g (channel units)",
                 -coef, se);
    else if (strcmp(name, "linear_stiffness") == 0)
        snprintf(buf, len, "missing spring: a = -kappa x with kappa = %.4g +/- %.2g (1/time^2)",
                 -coef, se);
    else if (strcmp(name, "cubic_stiffness") == 0)
        snprintf(buf, len, "cubic spring: a = -kappa3 x^3 with kappa3 = %.4g +/- %.2g (%s)",
                 -coef, se, -coef >= 0 ? "hardening" : "softening");
    else if (strcmp(name, "thermal_sensitivity") == 0)
        snprintf(buf, len, "temperature coefficient of %.4g +/- %.2g channel units per degree",
                 coef, se);
    else if (strcmp(name, "newton_cooling") == 0)
        snprintf(buf, len, "convective loss: %.4g +/- %.2g per degree of T - T_ambient", coef, se);
    else if (strcmp(name, "radiative_cooling") == 0)
        snprintf(buf, len, "radiative loss: %.4g +/- %.2g per K^4 of T^4 - T_ambient^4", coef, se);
    else if (strcmp(name, "input_gain") == 0)
        snprintf(buf, len, "actuator gain error: %.4g +/- %.2g per input unit", coef, se);
    else
        snprintf(buf, len, "coefficient %.4g +/- %.2g", coef, se);
    return FE_OK;
}
/* Read a coefficient in words ends here */
/* [[file:../literate/catalog.org::The three-axis terms][The three-axis terms]] */
int fe_catalog_axes_init(fe_catalog_axes *c, const double centre[3], int has_time, double t1,
                         int has_temperature, double temperature1)
{
    static const fe_discover_group all[FE_CATALOG_AXES_GROUPS] = {
        {"bias", 0, 1}, {"hard_iron", 1, 3}, {"axis_gain", 4, 2},
        {"cross_axis", 6, 3}, {"thermal_offset", 9, 3}, {"drift", 12, 1}};
    static const char *const words[FE_CATALOG_AXES_GROUPS] = {
        "a different radius", "an offset of the centre", "unequal per-axis scale",
        "soft iron or non-orthogonal axes", "an offset that moves with temperature",
        "a field or a gain drifting with time"};
    if (c == NULL || centre == NULL)
        return FE_EINVAL;
    if (!isfinite(centre[0]) || !isfinite(centre[1]) || !isfinite(centre[2])
        || (has_time && !isfinite(t1)) || (has_temperature && !isfinite(temperature1)))
        return FE_ENONFINITE;
    memset(c, 0, sizeof *c);
    memcpy(c->centre, centre, sizeof c->centre);
    c->t1 = has_time ? t1 : 0.0;
    c->temperature1 = has_temperature ? temperature1 : 0.0;
    for (size_t g = 0; g < FE_CATALOG_AXES_GROUPS; g++) {
        if ((g == 4 && !has_temperature) || (g == 5 && !has_time))
            continue;
        c->groups[c->ngroups] = all[g];
        c->description[c->ngroups++] = words[g];
    }
    return FE_OK;
}

int fe_catalog_axes_eval(const fe_catalog_axes *c, const double x[3], double t, double temp,
                         double *phi, double *radius)
{
    double d[3], len, u[3], dT;
    if (c == NULL || x == NULL || phi == NULL || radius == NULL)
        return FE_EINVAL;
    if (!isfinite(x[0]) || !isfinite(x[1]) || !isfinite(x[2]) || !isfinite(t)
        || !isfinite(temp))
        return FE_ENONFINITE;
    for (int i = 0; i < 3; i++)
        d[i] = x[i] - c->centre[i];
    len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(len > 0.0))
        return FE_ESINGULAR;
    if (!isfinite(len))
        return FE_ENONFINITE;
    for (int i = 0; i < 3; i++)
        u[i] = d[i] / len;
    dT = temp - c->temperature1;
    *radius = len;
    phi[0] = 1.0;
    phi[1] = u[0];
    phi[2] = u[1];
    phi[3] = u[2];
    phi[4] = u[0] * u[0];
    phi[5] = u[1] * u[1];
    phi[6] = u[0] * u[1];
    phi[7] = u[0] * u[2];
    phi[8] = u[1] * u[2];
    phi[9] = dT * u[0];
    phi[10] = dT * u[1];
    phi[11] = dT * u[2];
    phi[12] = t - c->t1;
    return FE_OK;
}
/* The three-axis terms ends here */
