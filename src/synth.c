/* SPDX-License-Identifier: MIT */
/* Tangled from literate/synth.org: do not edit; edit the .org and run make tangle. */
/* [[file:../literate/synth.org::Synthetic Includes][Synthetic Includes]] */
#include <math.h>
#include <string.h>

#include "foldest/error.h"
#include "foldest/synth.h"

static const double fe__two_pi = 6.283185307179586476925286766559;
static const double fe__w0 = 6.283185307179586476925286766559 * 0.4;  /* the cart's */
static const double fe__tau = 20.0;                                    /* the stand's */

struct fe_synth;
static double fe__synth_term(const struct fe_synth *g, const fe_sample *s);
/* Synthetic Includes ends here */
/* [[file:../literate/synth.org::Effects and rigs][Effects and rigs]] */
static const char *const fe__synth_effects[] = {
    "bias", "drift", "gain", "delay", "viscous_friction", "quadratic_drag",
    "coulomb_friction", "linear_stiffness", "cubic_stiffness",
    "thermal_sensitivity", "newton_cooling", "radiative_cooling", "input_gain",
    "none", "none_thermal",
};

const char *const *fe_synth_effects(size_t *count)
{
    if (count != NULL)
        *count = sizeof fe__synth_effects / sizeof fe__synth_effects[0];
    return fe__synth_effects;
}

static int fe__synth_is_thermal(const char *effect)
{
    return strcmp(effect, "thermal_sensitivity") == 0
           || strcmp(effect, "newton_cooling") == 0
           || strcmp(effect, "radiative_cooling") == 0
           || strcmp(effect, "none_thermal") == 0;
}

static double fe__synth_sign(const char *effect)
{
    static const char *const opposing[] = {
        "viscous_friction", "quadratic_drag", "coulomb_friction",
        "linear_stiffness", "cubic_stiffness", "newton_cooling",
        "radiative_cooling",
    };
    for (size_t i = 0; i < sizeof opposing / sizeof opposing[0]; i++)
        if (strcmp(effect, opposing[i]) == 0)
            return -1.0;
    return 1.0;
}

fe_synth_spec fe_synth_default_spec(const char *effect, uint64_t seed)
{
    fe_synth_spec s = {effect, seed, 200000, 1.0, 0.5, 0.3, 0, 3.0};
    return s;
}
/* Effects and rigs ends here */
/* [[file:../literate/synth.org::Advance the simulated experiment][Advance the simulated experiment]] */
static void fe__synth_reset(fe_synth *g)
{
    fe_rng r = fe_rng_seed(g->spec.seed * 7 + 3);
    for (int i = 0; i < 3; i++)
        g->phase[i] = fe__two_pi * fe_rng_uniform(&r);
    g->physics = fe_rng_seed(g->spec.seed * 2 + 1);
    g->noise = fe_rng_seed(g->spec.seed * 2 + 2);
    g->row = 0;
    g->x = g->v = g->xr = g->vr = 0.0;
    g->temp = g->tempr = 20.0;
    g->load = 0.0;
    g->e = g->sigma * fe_rng_normal(&g->noise);
}

/* The simulation's row i (real not yet set). */
static void fe__synth_physics(fe_synth *g, size_t i, fe_sample *s)
{
    double t = (double)i * g->dt, total = (double)g->spec.rows * g->dt;
    memset(s, 0, sizeof *s);
    s->t = t;
    if (!g->thermal) {
        const double w0 = fe__w0, zeta = 0.15;
        const double *ph = g->phase;
        double u, a;
        u = (t < 10.0 ? t / 10.0 : 1.0)         /* a soft start */
            * (0.85 + 0.15 * sin(fe__two_pi * t / (total / 3.3) + ph[2]))
            * (1.0 * sin(fe__two_pi * 0.17 * t + ph[0]) + 1.5 * sin(fe__two_pi * 0.83 * t + ph[1]));
        a = u - w0 * w0 * g->x - 2.0 * zeta * w0 * g->v;
        s->input = u;
        s->position = g->x;
        s->velocity = g->v;
        s->sim = g->spec.order == 2 ? g->x : a;
        g->v += a * g->dt;              /* semi-implicit Euler */
        g->x += g->v * g->dt;
        if (g->spec.order == 2) {       /* the real cart, with the effect */
            fe_sample r = *s;
            r.position = g->xr;
            r.velocity = g->vr;
            s->real = g->xr;
            g->vr += (u - w0 * w0 * g->xr - 2.0 * zeta * w0 * g->vr
                      + g->coefficient * fe__synth_term(g, &r)) * g->dt;
            g->xr += g->vr * g->dt;
        }
    } else {
        double tau = fe__tau, ambient, power;
        ambient = 20.0 + 25.0 * sin(fe__two_pi * t / (total / 2.3) + 0.3);
        power = fmod(t, 600.0) < 300.0 ? 60.0 : 0.0;   /* heater on half the time */
        if (i == 0)
            g->temp = g->tempr = ambient;
        s->temperature = g->temp;
        s->ambient = ambient;
        if (g->spec.order == 1) {       /* the real stand, with the effect */
            fe_sample r;
            s->input = power;           /* the heater is a column here */
            r = *s;
            r.temperature = g->tempr;
            s->real = g->tempr;
            g->tempr += ((ambient + power - g->tempr) / tau
                         + g->coefficient * fe__synth_term(g, &r)) * g->dt;
        }
        /* load: Ornstein-Uhlenbeck, time constant 5 s, unit spread */
        g->load += -g->load * g->dt / 5.0 + sqrt(2.0 * g->dt / 5.0) * fe_rng_normal(&g->physics);
        s->sim = g->spec.order == 1 ? g->temp : 2.0 + g->load;
        g->temp += (ambient + power - g->temp) * g->dt / tau;
    }
}
/* Advance the simulated experiment ends here */
/* [[file:../literate/synth.org::Produce rows with the effect and the noise][Produce rows with the effect and the noise]] */
static void fe__synth_derivative(fe_synth *g, size_t i)
{
    const fe_sample *a = i > 0 ? &g->prev : &g->cur;
    const fe_sample *b = i + 1 < g->spec.rows ? &g->next : &g->cur;
    g->cur.dsim = b->t > a->t ? (b->sim - a->sim) / (b->t - a->t) : 0.0;
}

/* Step to row i: cur becomes row i, next row i + 1. */
static void fe__synth_advance(fe_synth *g)
{
    if (g->row == 0) {
        fe__synth_physics(g, 0, &g->cur);
        if (g->spec.rows > 1)
            fe__synth_physics(g, 1, &g->next);
    } else {
        g->prev = g->cur;
        g->cur = g->next;
        if (g->row + 1 < g->spec.rows)
            fe__synth_physics(g, g->row + 1, &g->next);
    }
    fe__synth_derivative(g, g->row);
}

static double fe__synth_term(const fe_synth *g, const fe_sample *s)
{
    const fe_term *terms;
    if (g->effect < 0)
        return 0.0;
    terms = fe_catalog_builtin_terms(NULL);
    return terms[g->effect].eval(s, &g->scale, NULL);
}

int fe_synth_init(fe_synth *g, const fe_synth_spec *spec)
{
    size_t nb;
    const fe_term *terms = fe_catalog_builtin_terms(&nb);
    double maxphi = 0.0, lo = 0.0, hi = 0.0;
    if (g == NULL || spec == NULL || spec->effect == NULL)
        return FE_EINVAL;
    if (spec->rows < 100)
        return FE_ETOOFEW;
    if (!(spec->noise_sd > 0.0) || !(spec->noise_rho >= 0.0) || !(spec->noise_rho < 1.0))
        return FE_EINVAL;
    memset(g, 0, sizeof *g);
    g->spec = *spec;
    if (spec->order > 2 || (spec->order > 0 && !(spec->parting > 0.0))
        || (spec->order > 0 && (strcmp(spec->effect, "gain") == 0
                                || strcmp(spec->effect, "delay") == 0))
        || (spec->order == 2 && fe__synth_is_thermal(spec->effect)))
        return FE_EINVAL;
    g->thermal = fe__synth_is_thermal(spec->effect) || spec->order == 1;
    g->dt = g->thermal ? 0.05 : 0.01;
    g->roles = g->thermal ? FE_ROLE_TEMPERATURE | FE_ROLE_AMBIENT
                          : FE_ROLE_POSITION | FE_ROLE_VELOCITY | FE_ROLE_INPUT;
    if (spec->order == 1)
        g->roles |= FE_ROLE_INPUT;      /* the heater's power */
    g->effect = -1;
    if (strncmp(spec->effect, "none", 4) != 0) {
        for (size_t i = 0; i < nb; i++)
            if (strcmp(terms[i].name, spec->effect) == 0)
                g->effect = (long)i;
        if (g->effect < 0 || (terms[g->effect].needs & g->roles) != terms[g->effect].needs)
            return FE_EINVAL;
    }
    /* First pass: the scale discovery will see, and the term's largest
       size.  Only coulomb_friction depends on the largest speed, which the
       pass is still finding; its largest size is tanh(500) = 1. */
    g->sigma = spec->noise_sd;
    fe__synth_reset(g);
    for (g->row = 0; g->row < spec->rows; g->row++) {
        double phi;
        fe__synth_advance(g);
        fe_catalog_scale_add(&g->scale, &g->cur);
        phi = fabs(fe__synth_term(g, &g->cur));
        if (phi > maxphi)
            maxphi = phi;
        lo = g->row == 0 || g->cur.sim < lo ? g->cur.sim : lo;
        hi = g->row == 0 || g->cur.sim > hi ? g->cur.sim : hi;
    }
    if (spec->order > 0)                    /* a sensor reading to 0.1 % of the span */
        g->sigma = spec->noise_sd * 1e-3 * (hi - lo);
    if (g->effect >= 0 && strcmp(spec->effect, "coulomb_friction") == 0)
        maxphi = tanh(500.0);
    g->coefficient = maxphi > 0.0
        ? fe__synth_sign(spec->effect) * spec->effect_size * spec->noise_sd / maxphi : 0.0;
    if (spec->order > 0 && maxphi > 0.0)    /* the static response: / w0^2, x tau */
        g->coefficient = fe__synth_sign(spec->effect) * spec->parting * g->sigma / maxphi
                         * (spec->order == 2 ? fe__w0 * fe__w0 : 1.0 / fe__tau);
    fe__synth_reset(g);
    return FE_OK;
}

int fe_synth_next(fe_synth *g, fe_sample *s)
{
    double rho = g->spec.noise_rho;
    if (g->row >= g->spec.rows)
        return FE_END;
    fe__synth_advance(g);
    if (g->row > 0)
        g->e = rho * g->e + sqrt(1.0 - rho * rho) * g->sigma * fe_rng_normal(&g->noise);
    *s = g->cur;
    s->real = g->spec.order > 0 ? g->cur.real + g->e
                                : s->sim + g->coefficient * fe__synth_term(g, s) + g->e;
    g->row++;
    return FE_OK;
}

void fe_synth_rewind(fe_synth *g)
{
    fe__synth_reset(g);
}

size_t fe_synth_base(const fe_synth *g, const fe_catalog *c, size_t *base)
{
    static const char *const names[] = {"bias", "gain"};
    size_t n = 0;
    const char *hidden = g->effect >= 0 ? fe_catalog_builtin_terms(NULL)[g->effect].name : "";
    for (size_t i = 0; i < 2; i++) {
        long j = fe_catalog_find(c, names[i]);
        if (j >= 0 && strcmp(names[i], hidden) != 0)
            base[n++] = (size_t)j;
    }
    return n;
}
/* Produce rows with the effect and the noise ends here */
