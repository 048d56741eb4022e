/* SPDX-License-Identifier: MIT */
/* gen_dyn: one case of the dynamics (output-error) acceptance suite of
   `foldest discover --order K`, drawn independently of foldest.

   A simulation runs open loop from the same input and initial state as the
   real system; the real system has one or two extra terms in its K-th time
   derivative (K = 2: x'' of a position or angle; K = 1: T' of a
   temperature), or an effect outside the catalog, so the two trajectories
   drift apart.  Both are integrated here by RK4 with several substeps a
   sample, the effect inside the dynamics.  Like gen.c, this program links
   and includes nothing of foldest: its own random numbers, rigs, noise
   processes, clocks, terms (from the conventions of README.md), and its
   own identifiability check (the output signature dx/dtheta of every term
   by finite differences of full runs, fitted with a sensor offset by a GLS
   with the true noise spectrum).  See tests/accept/README.md.

     gen_dyn --list                             every case: NAME FAMILY
     gen_dyn --case NAME --seed S --out DIR     writes DIR/real.csv, DIR/sim.csv,
                                                DIR/truth.json; prints on stdout the
                                                arguments of `foldest` that analyse it
                                                (with --order K, without --json)
     gen_dyn ... --quiet-noise                  the noise divided by 10^6: the fit
                                                must return the coefficients closely
     gen_dyn ... --substeps N                   RK4 substeps a simulation step
                                                (default 4): a check of the integration
     gen_dyn ... --verbose                      the number of integrations, on stderr

   Exit status: 0, 2 usage, 4 input/output. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "common.h"

/* ------------------------------------------------------------------ macros */

#define PI 3.14159265358979323846
#define MAXT 2          /* hidden terms in one case, at most */
#define MAXCOL 8        /* columns of one regression, at most */
#define Z_MIN 8.0       /* design |z| of every hidden term under the true GLS */
#define DELTA_MIN 10.0  /* design RSS gap to the closest competitor, in innovation variances */
#define PART_MIN 1.0    /* max |x_real - x_sim| in noise sds: drawn in [PART_MIN, PART_MAX] */
#define PART_MAX 10.0
#define HOLDOUT 0.2     /* discover's default: identifiability is judged on the rest */
#define ATTEMPTS 6      /* draws of one case before it is kept as not identifiable */

enum { T_BIAS, T_DRIFT, T_VISC, T_QUAD, T_COUL, T_LIN, T_CUB, T_THERM, T_NEWTON, T_RAD,
       T_INPUT, NTERMS };
enum { RIG_CART, RIG_MSD, RIG_SHAKER, RIG_PEND, RIG_THERMAL, NRIGS };
enum { O_NONE, O_BACKLASH, O_DEADZONE, O_COGGING, O_SATURATION };

#define MECH ((1u << RIG_CART) | (1u << RIG_MSD) | (1u << RIG_SHAKER) | (1u << RIG_PEND))
#define THERM (1u << RIG_THERMAL)

/* ------------------------------------------------------------------ data */

static const char *const term_name[NTERMS] = {
    "bias", "drift", "viscous_friction", "quadratic_drag", "coulomb_friction",
    "linear_stiffness", "cubic_stiffness", "thermal_sensitivity", "newton_cooling",
    "radiative_cooling", "input_gain"};

static const char *const rig_name[NRIGS] = {"cart", "msd_force", "msd_shaker", "pendulum",
                                            "thermal"};

static const char *const outside_name[] = {"", "backlash", "dead_zone", "cogging", "saturation"};

static const char *const noise_name[] = {"white", "ar1_0.5", "ar1_0.8", "ar1_0.95",
                                         "ar2_resonant", "pink_1.0", "white+walk"};
#define NNOISE 7

/* Clocks: the mechanical rigs use milliseconds where the thermal rig uses minutes. */
static const char *const clock_name[] = {"seconds", "epoch_seconds", "milliseconds",
                                         "minutes", "jitter_dropouts", "jitter_dropouts_epoch"};
#define NCLOCK 6

static const long lengths[] = {300, 1000, 3000, 10000, 20000};
#define NLEN 5

/* The candidate terms of each kind of rig: the competitors of the check. */
static const int mech_terms[] = {T_BIAS, T_DRIFT, T_VISC, T_QUAD, T_COUL, T_LIN, T_CUB, T_INPUT};
static const int therm_terms[] = {T_BIAS, T_DRIFT, T_THERM, T_NEWTON, T_RAD, T_INPUT};

/* A case: name, family, the rigs it may use, its hidden terms (nt = -2:
   two drawn by seed from the rig's pool), an outside effect. */
typedef struct {
    const char *name, *family;
    unsigned rigs;
    int nt, t[MAXT];
    int outside;
} dcase;

static const dcase cases[] = {
    {"hidden_viscous_friction", "hidden", MECH, 1, {T_VISC}, O_NONE},
    {"hidden_quadratic_drag", "hidden", MECH, 1, {T_QUAD}, O_NONE},
    {"hidden_coulomb_friction", "hidden", MECH, 1, {T_COUL}, O_NONE},
    {"hidden_linear_stiffness", "hidden", MECH, 1, {T_LIN}, O_NONE},
    {"hidden_cubic_stiffness", "hidden", MECH, 1, {T_CUB}, O_NONE},
    {"hidden_input_gain", "hidden", MECH | THERM, 1, {T_INPUT}, O_NONE},
    {"hidden_bias", "hidden", MECH | THERM, 1, {T_BIAS}, O_NONE},
    {"hidden_newton_cooling", "hidden", THERM, 1, {T_NEWTON}, O_NONE},
    {"hidden_radiative_cooling", "hidden", THERM, 1, {T_RAD}, O_NONE},
    {"multi_mechanical", "multi", MECH, -2, {0}, O_NONE},
    {"multi_thermal", "multi", THERM, -2, {0}, O_NONE},
    {"null_cart", "null", 1u << RIG_CART, 0, {0}, O_NONE},
    {"null_msd_force", "null", 1u << RIG_MSD, 0, {0}, O_NONE},
    {"null_msd_shaker", "null", 1u << RIG_SHAKER, 0, {0}, O_NONE},
    {"null_pendulum", "null", 1u << RIG_PEND, 0, {0}, O_NONE},
    {"null_thermal", "null", THERM, 0, {0}, O_NONE},
    {"outside_backlash", "outside", (1u << RIG_MSD) | (1u << RIG_SHAKER), 0, {0}, O_BACKLASH},
    {"outside_dead_zone", "outside", (1u << RIG_CART) | (1u << RIG_MSD) | (1u << RIG_PEND) | THERM,
     0, {0}, O_DEADZONE},
    {"outside_cogging", "outside", (1u << RIG_CART) | (1u << RIG_PEND), 0, {0}, O_COGGING},
    {"outside_saturation", "outside", (1u << RIG_CART) | (1u << RIG_MSD) | (1u << RIG_PEND) | THERM,
     0, {0}, O_SATURATION},
};
#define NCASES (sizeof cases / sizeof cases[0])

/* One draw: clocks, rig, exogenous signals, the simulation. */
typedef struct {
    int rig, order, noise_type, clock, kelvin, hold, sub, hot;
    long n, m, nu;             /* recording rows, simulation rows, union grid points */
    double dt, hs, csec;       /* recording step, simulation step (s); s per time-column unit */
    double *tau_r, *tcol_r;    /* recording: seconds from start; time column */
    double *tau_s, *tcol_s;    /* simulation grid */
    double *tu;                /* union of both grids, seconds */
    long *s_at, *r_at;         /* simulation row / recording row at a union point, or -1 */
    double *u_s, *amb_s;       /* input and ambient samples on the simulation grid */
    double inv_m, c_m, k_m, w2, G, tau_th; /* rig parameters */
    double x0, v0, vmax, T1;
    double *xs, *vs;           /* simulation at its rows */
    double *xsr;               /* simulation at the recording's rows (exact, same integration) */
    double *noise, sigma;
} draw;

/* The real system's departure from the simulation. */
typedef struct {
    int nt, t[MAXT];
    double a[MAXT];            /* coefficients, per second^K */
    const double *u_real;      /* the input the real actuator delivers (samples), or NULL */
    double cog, cog_period;    /* cogging: cog sin(2 pi x / period) in the K-th derivative */
} effect;

/* ------------------------------------------------------------------ random numbers */







static int gauss_have;
static double gauss_spare;

static double gauss(void)
{
    double u, v;
    if (gauss_have) {
        gauss_have = 0;
        return gauss_spare;
    }
    u = unif();
    v = unif();
    gauss_spare = sqrt(-2.0 * log(u)) * sin(2.0 * PI * v);
    gauss_have = 1;
    return sqrt(-2.0 * log(u)) * cos(2.0 * PI * v);
}


/* ------------------------------------------------------------------ small helpers */

static void *alloc(long n, size_t size)
{
    void *p = calloc((size_t)(n > 0 ? n : 1), size);
    if (p == NULL) {
        fprintf(stderr, "gen_dyn: out of memory\n");
        exit(4);
    }
    return p;
}

static double *vec(long n) { return alloc(n, sizeof(double)); }





static double maxdiff_of(const double *x, const double *y, long n)
{
    double m = 0;
    for (long i = 0; i < n; i++)
        m = fabs(x[i] - y[i]) > m ? fabs(x[i] - y[i]) : m;
    return m;
}


/* ------------------------------------------------------------------ least squares */


/* ------------------------------------------------------------------ noise */

static void noise_acf(int type, long n, int p, double *r)
{
    memset(r, 0, (size_t)(p + 1) * sizeof *r);
    if (type == 0) {
        r[0] = 1;
    } else if (type <= 3) {
        static const double phis[] = {0, 0.5, 0.8, 0.95};
        for (int h = 0; h <= p; h++)
            r[h] = pow(phis[type], h);
    } else if (type == 4) {
        double a1 = 2 * 0.9 * cos(0.3), a2 = -0.81;
        r[0] = 1;
        if (p >= 1)
            r[1] = a1 / (1 - a2);
        for (int h = 2; h <= p; h++)
            r[h] = a1 * r[h - 1] + a2 * r[h - 2];
    } else if (type == 5) {
        /* 1/f: 16 AR(1) processes with log-spaced time constants up to 4n,
           weights tau^0, plus a 10 % white floor */
        double tot = 0, ph[16];
        for (int k = 0; k < 16; k++) {
            ph[k] = exp(-1.0 / exp(log(4.0 * (double)n) * k / 15.0));
            tot += 1.0;
        }
        for (int k = 0; k < 16; k++)
            for (int h = 0; h <= p; h++)
                r[h] += 0.9 / tot * pow(ph[k], h);
        r[0] += 0.1;
    } else {
        /* white plus a random walk with increments 1/sqrt(n): approximated
           for the design GLS by a stationary AR(1) of time constant n */
        double phi = 1.0 - 1.0 / (double)n, q2 = 1.0 / (double)n;
        for (int h = 0; h <= p; h++)
            r[h] = q2 / (1 - phi * phi) * pow(phi, h);
        r[0] += 1.0;
    }
}

static void noise_draw(int type, long n, double *x)
{
    if (type == 0) {
        for (long i = 0; i < n; i++)
            x[i] = gauss();
    } else if (type <= 3) {
        static const double phis[] = {0, 0.5, 0.8, 0.95};
        double phi = phis[type], c = sqrt(1 - phi * phi), v = gauss();
        for (long i = 0; i < n; i++) {
            x[i] = v;
            v = phi * v + c * gauss();
        }
    } else if (type == 4) {
        double a1 = 2 * 0.9 * cos(0.3), a2 = -0.81, v1 = 0, v2 = 0;
        for (long i = -2000; i < n; i++) {
            double v = a1 * v1 + a2 * v2 + gauss();
            v2 = v1;
            v1 = v;
            if (i >= 0)
                x[i] = v;
        }
    } else if (type == 5) {
        double w2 = 0.9 / 16.0, ph[16], st[16];
        for (int k = 0; k < 16; k++) {
            ph[k] = exp(-1.0 / exp(log(4.0 * (double)n) * k / 15.0));
            st[k] = sqrt(w2) * gauss();
        }
        for (long i = 0; i < n; i++) {
            double v = sqrt(0.1) * gauss();
            for (int k = 0; k < 16; k++) {
                v += st[k];
                st[k] = ph[k] * st[k] + sqrt(w2 * (1 - ph[k] * ph[k])) * gauss();
            }
            x[i] = v;
        }
    } else {
        double w = 0, q = 1.0 / sqrt((double)n);
        for (long i = 0; i < n; i++) {
            x[i] = gauss() + w;
            w += q * gauss();
        }
    }
}



/* ------------------------------------------------------------------ clocks */

static double epoch0;

static double time_value(int clock, double tau)
{
    switch (clock) {
    case 1: case 5: return epoch0 + tau;
    case 2: return tau * 1000.0;
    case 3: return tau / 60.0;
    default: return tau;
    }
}

static double seconds_per_unit(int clock)
{
    return clock == 2 ? 1e-3 : clock == 3 ? 60.0 : 1.0;
}

static const char *time_column(int clock)
{
    switch (clock) {
    case 1: case 5: return "unix_time";
    case 2: return "t_ms";
    case 3: return "t_min";
    default: return "time";
    }
}

/* The recording's times (jittered with dropouts for the irregular clocks),
   the simulation's grid (the recording's own times when regular, else a
   regular grid of a quarter of the nominal step over the recording: the
   simulation interpolated linearly onto the recording is then within
   sim_interp_error_sd of the truth, written in truth.json), and their
   union, on which both systems are integrated. */
static void make_clock(draw *d)
{
    long n = d->n, i, j, q;
    epoch0 = floor(unif2(1.69e9, 1.72e9));
    d->tau_r = vec(n);
    d->tcol_r = vec(n);
    if (d->clock < 4) {
        for (i = 0; i < n; i++)
            d->tau_r[i] = (double)i * d->dt;
        d->m = n;
        d->hs = d->dt;
        d->tau_s = vec(n);
        d->tcol_s = vec(n);
        for (i = 0; i < n; i++) {
            d->tau_s[i] = d->tau_r[i];
            d->tcol_s[i] = d->tcol_r[i] = time_value(d->clock, d->tau_r[i]);
        }
    } else {
        /* jitter of +-35 % of a step, 3 % of rows dropped at random and one
           contiguous dropout of 2 % of the rows */
        long blk = n / 50 + 1, start = (long)(unif() * (double)n * 0.8) + n / 10, k = 0;
        for (j = 0; k < n; j++) {
            if (j >= start && j < start + blk)
                continue;
            if (unif() < 0.03)
                continue;
            d->tau_r[k++] = ((double)j + unif2(-0.35, 0.35)) * d->dt;
        }
        {
            double t0 = d->tau_r[0];
            for (i = 0; i < n; i++)
                d->tau_r[i] -= t0;
        }
        for (i = 0; i < n; i++)
            d->tcol_r[i] = time_value(d->clock, d->tau_r[i]);
        d->hs = 0.25 * d->dt;
        d->m = (long)(d->tau_r[n - 1] / d->hs) + 3;
        d->tau_s = vec(d->m);
        d->tcol_s = vec(d->m);
        for (i = 0; i < d->m; i++) {
            d->tau_s[i] = (double)i * d->hs;
            d->tcol_s[i] = time_value(d->clock, d->tau_s[i]);
        }
        d->tcol_s[0] = d->tcol_r[0];
    }
    d->tu = vec(n + d->m);
    d->s_at = alloc(n + d->m, sizeof(long));
    d->r_at = alloc(n + d->m, sizeof(long));
    for (i = j = q = 0; i < d->m || j < n; q++) {
        double ts = i < d->m ? d->tau_s[i] : INFINITY, tr = j < n ? d->tau_r[j] : INFINITY;
        double t = ts < tr ? ts : tr;
        d->tu[q] = t;
        d->s_at[q] = d->r_at[q] = -1;
        if (ts - t <= 1e-9 * d->hs)
            d->s_at[q] = i++;
        if (tr - t <= 1e-9 * d->hs)
            d->r_at[q] = j++;
    }
    d->nu = q;
}

/* ------------------------------------------------------------------ signals */

/* A multi-sine with three components (cycles over the record between 2 and
   n/40) at seconds t. */
typedef struct { double A[3], w[3], p[3]; } multisine;

static multisine multisine_draw(double D, long n)
{
    multisine m;
    double cmax = (double)n / 40.0 > 4 ? (double)n / 40.0 : 4;
    for (int k = 0; k < 3; k++) {
        m.A[k] = unif2(0.3, 1.0) / (k + 1);
        m.w[k] = 2 * PI * logunif(2.0, cmax) / D;
        m.p[k] = unif2(0, 2 * PI);
    }
    return m;
}

static double multisine_eval(const multisine *m, double t)
{
    double x = 0;
    for (int k = 0; k < 3; k++)
        x += m->A[k] * sin(m->w[k] * t + m->p[k]);
    return x;
}

/* Random levels switched at 8 to 32 random instants, with short ramps. */

static steps steps_draw(double D, double lo, double hi, double ramp)
{
    steps s;
    s.k = 8 + (int)(unif() * 24);
    for (int i = 0; i < s.k; i++)
        s.edge[i] = D * ((double)i + unif2(0.6, 1.4)) / (double)(s.k + 1);
    for (int i = 0; i <= s.k; i++)
        s.level[i] = unif2(lo, hi);
    s.ramp = ramp;
    return s;
}


/* ------------------------------------------------------------------ dynamics */

/* A catalog term at a state (x, v per second, u, ta, t seconds from the
   start), from README.md's conventions, in the columns' units: velocity as
   written, in units per time-column unit (v x seconds per unit), drift in
   the time column's unit from the first row, coulomb with 0.002 max|v| of
   the simulation's velocity column at the recording's rows, radiative in
   kelvin. */
static double term_at(const draw *d, int k, double x, double v, double u, double ta, double t)
{
    switch (k) {
    case T_BIAS: return 1.0;
    case T_DRIFT: return t / d->csec;
    case T_VISC: return v * d->csec;
    case T_QUAD: return v * d->csec * fabs(v * d->csec);
    case T_COUL: return tanh(v * d->csec / (0.002 * d->vmax));
    case T_LIN: return x;
    case T_CUB: return x * x * x;
    case T_THERM: return x - d->T1;
    case T_NEWTON: return x - ta;
    case T_RAD: {
        double TK = d->kelvin ? x : x + 273.15, TaK = d->kelvin ? ta : ta + 273.15;
        return TK * TK * TK * TK - TaK * TaK * TaK * TaK;
    }
    default: return u;
    }
}

/* The exogenous signals over one simulation interval, from its start ts:
   the commanded input (the column), the input the actuator delivers, the
   ambient; each a value at ts and a slope (0 for a held input). */
typedef struct { double ts, uc, ucs, u, us, ta, tas; } segment;

static void segment_at(const draw *d, const effect *e, long js, segment *g)
{
    double h = d->tau_s[js + 1] - d->tau_s[js];
    const double *ur = e->u_real != NULL ? e->u_real : d->u_s;
    g->ts = d->tau_s[js];
    g->uc = d->u_s[js];
    g->ucs = d->hold ? (d->u_s[js + 1] - d->u_s[js]) / h : 0.0;
    g->u = ur[js];
    g->us = d->hold ? (ur[js + 1] - ur[js]) / h : 0.0;
    g->ta = d->amb_s != NULL ? d->amb_s[js] : 0.0;
    g->tas = d->amb_s != NULL ? (d->amb_s[js + 1] - d->amb_s[js]) / h : 0.0;
}

/* The K-th derivative of the state s (x, v for the mechanical rigs; T for
   the thermal one) at t seconds, with effect e, in segment g. */
static void deriv(const draw *d, const effect *e, const segment *g, double t, const double *s, double *ds)
{
    double dt = t - g->ts, uc = g->uc + dt * g->ucs, u = g->u + dt * g->us, ta = g->ta + dt * g->tas;
    double extra = 0;
    for (int j = 0; j < e->nt; j++)
        extra += e->a[j] * term_at(d, e->t[j], s[0], d->order == 2 ? s[1] : 0.0, uc, ta, t);
    if (e->cog != 0)
        extra += e->cog * sin(2 * PI * s[0] / e->cog_period);
    switch (d->rig) {
    case RIG_CART:
        ds[0] = s[1];
        ds[1] = u * d->inv_m - d->c_m * s[1] + extra;
        break;
    case RIG_MSD:
        ds[0] = s[1];
        ds[1] = u * d->inv_m - d->c_m * s[1] - d->k_m * s[0] + extra;
        break;
    case RIG_SHAKER:
        /* base excitation: the input is the base's position (linear hold,
           its slope the base's velocity) */
        ds[0] = s[1];
        ds[1] = -d->c_m * (s[1] - g->us) - d->k_m * (s[0] - u) + extra;
        break;
    case RIG_PEND:
        ds[0] = s[1];
        ds[1] = u * d->inv_m - d->c_m * s[1] - d->w2 * sin(s[0]) + extra;
        break;
    default:
        ds[0] = (d->G * u - (s[0] - ta)) / d->tau_th + extra;
    }
}

static long runs_done;   /* integrations, reported by --verbose */

/* Integrate from the initial state over the union grid, RK4 with substeps
   of at most 1/d->sub of the recording's nominal step; the state written
   at the recording's rows (xr) and at the simulation's (xs, vs; NULL: not
   wanted).  Returns 0, or -1 when the trajectory is not finite. */
static int integrate(const draw *d, const effect *e, double *xr, double *xs, double *vs)
{
    double s[2] = {d->x0, d->v0};
    int dim = d->order;
    long js = 0;
    segment g;
    runs_done++;
    segment_at(d, e, 0, &g);
    for (long q = 0; q < d->nu; q++) {
        if (q > 0) {
            double t = d->tu[q - 1], T = d->tu[q] - t, h;
            int ns = (int)ceil(T / (d->dt / d->sub) - 1e-6);
            ns = ns < 1 ? 1 : ns;
            h = T / ns;
            if (js + 2 < d->m && d->tau_s[js + 1] <= t + 1e-9 * d->hs) {
                while (js + 2 < d->m && d->tau_s[js + 1] <= t + 1e-9 * d->hs)
                    js++;
                segment_at(d, e, js, &g);
            }
            for (int k = 0; k < ns; k++, t += h) {
                double k1[2], k2[2], k3[2], k4[2], z[2];
                deriv(d, e, &g, t, s, k1);
                for (int c = 0; c < dim; c++)
                    z[c] = s[c] + h / 2 * k1[c];
                deriv(d, e, &g, t + h / 2, z, k2);
                for (int c = 0; c < dim; c++)
                    z[c] = s[c] + h / 2 * k2[c];
                deriv(d, e, &g, t + h / 2, z, k3);
                for (int c = 0; c < dim; c++)
                    z[c] = s[c] + h * k3[c];
                deriv(d, e, &g, t + h, z, k4);
                for (int c = 0; c < dim; c++)
                    s[c] += h / 6 * (k1[c] + 2 * k2[c] + 2 * k3[c] + k4[c]);
            }
            if (!isfinite(s[0]) || !isfinite(s[1]))
                return -1;
        }
        if (d->s_at[q] >= 0) {
            if (xs != NULL)
                xs[d->s_at[q]] = s[0];
            if (vs != NULL)
                vs[d->s_at[q]] = s[1];
        }
        if (d->r_at[q] >= 0 && xr != NULL)
            xr[d->r_at[q]] = s[0];
    }
    return 0;
}

static const effect no_effect = {0, {0}, {0}, NULL, 0, 1};

/* ------------------------------------------------------------------ rigs */

/* The rig's parameters, input (and ambient) samples and the simulation. */
static void make_rig(draw *d)
{
    long m = d->m, i;
    double D = d->tau_r[d->n - 1] + d->dt, cmax = (double)d->n / 40.0, w0;
    multisine ms = multisine_draw(D, d->n);
    steps st;
    cmax = cmax < 6 ? 6 : cmax;
    w0 = 2 * PI * logunif(3.0, cmax < 200 ? cmax : 200) / D;
    d->u_s = vec(m);
    d->xs = vec(m);
    d->vs = vec(m);
    d->xsr = vec(d->n);
    d->hold = d->rig == RIG_SHAKER ? 1 : unif() < 0.5;
    d->x0 = d->v0 = 0;
    if (d->rig == RIG_THERMAL) {
        /* T' = (G P - (T - Ta)) / tau: a heated body, heater power P in W,
           an ambient with a daily-like swing and a trend; the heater's
           full power raises the body 30 to 400 K (200 to 600 K when the
           hidden term is radiation) */
        double Pmax = logunif(5, 200), dT = d->hot ? unif2(200, 600) : logunif(30, 400), ta0 = unif2(15, 30),
               ta_amp = unif2(2, 8), ta_w = 2 * PI * unif2(1.0, 4.0) / D, ta_p = unif2(0, 2 * PI),
               ta_tr = unif2(-5, 5) / D;
        d->order = 1;
        d->kelvin = unif() < 0.5;
        d->amb_s = vec(m);
        d->G = dT / Pmax;
        d->tau_th = D / unif2(10, 40);
        st = steps_draw(D, 0.0, Pmax, 2 * d->dt);
        for (i = 0; i < m; i++) {
            double t = d->tau_s[i];
            d->u_s[i] = clampd(steps_eval(&st, t) + 0.1 * Pmax * multisine_eval(&ms, t), 0, Pmax);
            d->amb_s[i] = ta0 + (d->kelvin ? 273.15 : 0) + ta_amp * sin(ta_w * t + ta_p) + ta_tr * t;
        }
        d->x0 = d->amb_s[0] + d->G * d->u_s[0];
        integrate(d, &no_effect, d->xsr, d->xs, NULL);
        return;
    }
    d->order = 2;
    st = steps_draw(D, -1.0, 1.0, 2 * d->dt);
    for (i = 0; i < m; i++)
        d->u_s[i] = 0.5 * steps_eval(&st, d->tau_s[i]) + multisine_eval(&ms, d->tau_s[i]);
    switch (d->rig) {
    case RIG_CART:
        /* m x'' = F - c x': a cart pushed by a force, light viscous drag */
        d->inv_m = 1.0 / logunif(0.1, 10.0);
        d->c_m = logunif(3, 30) / D;
        break;
    case RIG_MSD:
        /* m x'' = F - c x' - k x */
        d->inv_m = 1.0 / logunif(0.1, 10.0);
        d->k_m = w0 * w0;
        d->c_m = 2 * unif2(0.02, 0.3) * w0;
        break;
    case RIG_SHAKER:
        /* m x'' = -c (x' - y') - k (x - y), y the base (the shaker's table) */
        d->k_m = w0 * w0;
        d->c_m = 2 * unif2(0.02, 0.3) * w0;
        break;
    default:
        /* J th'' = tau - b th' - m g l sin th: a pendulum driven by a torque */
        d->inv_m = 1.0 / logunif(0.01, 1.0);
        d->w2 = w0 * w0;
        d->c_m = 2 * unif2(0.02, 0.3) * w0;
        for (i = 0; i < m; i++)
            d->u_s[i] *= d->w2 / d->inv_m;
    }
    if (d->rig == RIG_PEND) {
        /* the torque scaled (damped fixed point) so that the swing reaches
           a drawn angle between 0.5 and 2.5 rad: sin is far from linear */
        double target = unif2(0.5, 2.5), ls0 = 0, lr0 = 0, ls = 0, slope = 1;
        for (int it = 0; it < 8; it++) {
            double r, lr;
            integrate(d, &no_effect, d->xsr, d->xs, d->vs);
            r = maxabs_of(d->xs, m);
            if (!(r > 0) || !isfinite(r) || fabs(r / target - 1) < 0.05)
                break;
            lr = log(r);
            if (it > 0 && ls != ls0)
                slope = clampd((lr - lr0) / (ls - ls0), 0.3, 3.0);
            ls0 = ls;
            lr0 = lr;
            ls += (log(target) - lr) / slope;
            for (i = 0; i < m; i++)
                d->u_s[i] *= exp(ls - ls0);
        }
    } else {
        /* linear: the input scaled to a drawn amplitude of motion */
        double amp = logunif(0.01, 1.0), r;
        integrate(d, &no_effect, d->xsr, d->xs, d->vs);
        r = amp / (maxabs_of(d->xs, m) + 1e-300);
        for (i = 0; i < m; i++)
            d->u_s[i] *= r;
        if (d->rig == RIG_SHAKER)
            d->x0 = d->u_s[0];
    }
    if (integrate(d, &no_effect, d->xsr, d->xs, d->vs) != 0) {
        fprintf(stderr, "gen_dyn: the simulation diverged\n");
        exit(4);
    }
}

/* ------------------------------------------------------------------ the draw */

static int pick_rig(unsigned mask, long seed, uint64_t h)
{
    int allowed[NRIGS], na = 0;
    for (int r = 0; r < NRIGS; r++)
        if (mask & (1u << r))
            allowed[na++] = r;
    return allowed[(uint64_t)(seed + (long)(h >> 24) % na) % (uint64_t)na];
}

static void make_draw(draw *d, const dcase *cs, long seed, int attempt, uint64_t h, int sub)
{
    memset(d, 0, sizeof *d);
    gauss_have = 0;
    rng_seed(h ^ ((uint64_t)seed * 0x9E3779B97F4A7C15ULL) ^ ((uint64_t)attempt << 48));
    d->sub = sub;
    d->hot = cs->nt == 1 && cs->t[0] == T_RAD;  /* radiation told from convection: a hot body */
    /* the design axes vary with the seed, each at its own pace */
    d->rig = pick_rig(cs->rigs, seed, h);
    d->noise_type = (int)(((uint64_t)seed * 3 + h % NNOISE) % NNOISE);
    d->clock = (int)(((uint64_t)seed * 5 + (h >> 8) % NCLOCK) % NCLOCK);
    if (d->clock == 3 && d->rig != RIG_THERMAL)
        d->clock = 2;  /* minutes are for the thermal rig; the others get milliseconds */
    d->csec = seconds_per_unit(d->clock);
    d->n = lengths[((uint64_t)seed * 2 + (h >> 16) % NLEN) % NLEN];
    d->dt = d->rig == RIG_THERMAL ? logunif(1.0, 10.0) : logunif(0.001, 0.02);
    make_clock(d);
    make_rig(d);
    d->vmax = d->order == 2 ? maxabs_of(d->vs, d->n) : 1.0;
    {   /* the simulation's velocity at the recording's rows, for coulomb's scale */
        double *vr = vec(d->n);
        long j = 0;
        for (long i = 0; i < d->n; i++) {
            while (j + 2 < d->m && d->tau_s[j + 1] <= d->tau_r[i])
                j++;
            vr[i] = d->vs[j] + (d->tau_r[i] - d->tau_s[j]) / (d->tau_s[j + 1] - d->tau_s[j])
                                   * (d->vs[j + 1] - d->vs[j]);
        }
        if (d->order == 2)
            d->vmax = maxabs_of(vr, d->n) * d->csec;   /* in the column's unit */
        free(vr);
    }
    d->T1 = d->x0;
    d->noise = vec(d->n);
    {
        double sd;
        noise_draw(d->noise_type, d->n, d->noise);
        sd = sd_of(d->noise, d->n);
        d->sigma = sd_of(d->xsr, d->n) * logunif(0.001, 0.02);
        for (long i = 0; i < d->n; i++)
            d->noise[i] *= d->sigma / sd;
    }
}

static void free_draw(draw *d)
{
    free(d->tau_r); free(d->tcol_r); free(d->tau_s); free(d->tcol_s); free(d->tu);
    free(d->s_at); free(d->r_at); free(d->u_s); free(d->amb_s); free(d->xs); free(d->vs);
    free(d->xsr); free(d->noise);
}

/* ------------------------------------------------------------------ signatures, identifiability */

/* The output signature dx/da of term k about the simulation (a = 0), at the
   recording's rows: a forward difference of two full runs, the step
   rescaled until the perturbation is 1e-9 to 1e-5 of the trajectory's range. */
static void signature(const draw *d, int k, double range, double *sig)
{
    effect e = no_effect;
    double *xr = vec(d->n), h, D = d->tau_r[d->n - 1] + d->dt, mx = 0, resp;
    for (long i = 0; i < d->m; i++)   /* the term's size along the simulation */
        mx = fmax(mx, fabs(term_at(d, k, d->xs[i], d->order == 2 ? d->vs[i] : 0, d->u_s[i],
                                   d->amb_s != NULL ? d->amb_s[i] : 0, d->tau_s[i])));
    /* the rig's response to a unit constant push, roughly: a first step */
    resp = d->rig == RIG_CART ? D * D : d->rig == RIG_MSD || d->rig == RIG_SHAKER ? 1.0 / d->k_m
         : d->rig == RIG_PEND ? 1.0 / d->w2 : d->tau_th;
    h = 1e-7 * range / ((mx > 0 ? mx : 1) * resp);
    e.nt = 1;
    e.t[0] = k;
    for (int it = 0; it < 4; it++) {
        double r;
        e.a[0] = h;
        integrate(d, &e, xr, NULL, NULL);
        r = maxdiff_of(xr, d->xsr, d->n) / range;
        if (r > 1e-9 && r < 1e-5)
            break;
        h *= 1e-7 / (r > 1e-300 ? r : 1e-300);
    }
    for (long i = 0; i < d->n; i++)
        sig[i] = (xr[i] - d->xsr[i]) / h;
    free(xr);
}

typedef struct {
    double z[MAXT], coef_hat[MAXT];
    double delta;          /* RSS gap to the closest competitor, in innovation variances */
    int competitor;
} design;

/* GLS with the true noise spectrum on the rows discover fits: the offset
   and the hidden terms' signatures, then every competitor's signature in
   place of each hidden one. */
static design design_check(double *w1, double *const *wsig, const int *cand, int nc, const double *wy,
                           long nw, const int *tr, int nt)
{
    design g;
    double *cols[MAXCOL], coef[MAXCOL], se[MAXCOL], rss, s2;
    int k = 0;
    memset(&g, 0, sizeof g);
    g.delta = INFINITY;
    g.competitor = -1;
    cols[k++] = w1;
    for (int j = 0; j < nt; j++)
        cols[k++] = wsig[tr[j]];
    rss = lsq(cols, k, wy, nw, coef, se);
    if (rss < 0) {
        for (int j = 0; j < nt; j++)
            g.z[j] = g.coef_hat[j] = 0;
        g.delta = 0;
        return g;
    }
    s2 = rss / (double)(nw - k);
    for (int j = 0; j < nt; j++) {
        g.z[j] = coef[1 + j] / se[1 + j];
        g.coef_hat[j] = coef[1 + j];
    }
    for (int j = 0; j < nt; j++)
        for (int ci = 0; ci < nc; ci++) {
            int c = cand[ci], skip = wsig[c] == NULL;
            double r2;
            for (int l = 0; l < nt; l++)
                skip |= tr[l] == c;
            if (skip)
                continue;
            cols[1 + j] = wsig[c];
            r2 = lsq(cols, k, wy, nw, coef, se);
            cols[1 + j] = wsig[tr[j]];
            if (r2 < 0)
                r2 = rss;
            if ((r2 - rss) / s2 < g.delta) {
                g.delta = (r2 - rss) / s2;
                g.competitor = c;
            }
        }
    return g;
}

/* The check on the linear prediction of the departure at parting pt:
   lam Sum wgt_j sig_j (lam set so that its largest value is pt noise sds)
   plus the offset and the noise; competitors cand[0 .. nc). */
static design lin_check(const draw *d, double pt, double *const *sig, double *const *wsig, const int *tr,
                        int nt, const double *wgt, const int *cand, int nc, double offset,
                        const double *ar, int p, long nf, double *w1, double *tmp, double *wy,
                        double *lam)
{
    long n = d->n;
    for (long i = 0; i < n; i++) {
        tmp[i] = 0;
        for (int j = 0; j < nt; j++)
            tmp[i] += wgt[j] * sig[tr[j]][i];
    }
    *lam = pt * d->sigma / (maxabs_of(tmp, n) + 1e-300);
    for (long i = 0; i < nf; i++)
        tmp[i] = *lam * tmp[i] + offset + d->noise[i];
    whiten(ar, p, tmp, wy, nf);
    return design_check(w1, wsig, cand, nc, wy, nf - p, tr, nt);
}

/* ------------------------------------------------------------------ outside the catalog */

/* The input the real actuator delivers, from the commanded samples. */
static void outside_input(const draw *d, int what, double par, double *ur)
{
    double out = d->u_s[0];
    for (long i = 0; i < d->m; i++) {
        double u = d->u_s[i];
        if (what == O_DEADZONE)
            /* mechanical: the classic dead zone; the heater: no power below par */
            ur[i] = d->rig == RIG_THERMAL ? (u < par ? 0 : u)
                                          : (fabs(u) <= par ? 0 : u - (u > 0 ? par : -par));
        else if (what == O_SATURATION)
            ur[i] = clampd(u, -par, par);
        else {   /* backlash (play par) between the command and the actuator */
            if (u - out > par / 2)
                out = u - par / 2;
            else if (out - u > par / 2)
                out = u + par / 2;
            ur[i] = out;
        }
    }
}

/* The real trajectory with outside effect `what` of parameter par. */
static int outside_run(const draw *d, int what, double par, double *ur, double period, double *xr)
{
    effect e = no_effect;
    if (what == O_COGGING) {
        e.cog = par;
        e.cog_period = period;
    } else {
        outside_input(d, what, par, ur);
        e.u_real = ur;
    }
    return integrate(d, &e, xr, NULL, NULL);
}

/* ------------------------------------------------------------------ output */

static FILE *open_out(const char *dir, const char *file)
{
    char path[4096];
    FILE *f;
    snprintf(path, sizeof path, "%s/%s", dir, file);
    f = fopen(path, "w");
    if (f == NULL) {
        fprintf(stderr, "gen_dyn: %s: %s\n", path, strerror(errno));
        exit(4);
    }
    return f;
}

static void close_out(FILE *f)
{
    if (ferror(f) || fclose(f) != 0) {
        fprintf(stderr, "gen_dyn: write error\n");
        exit(4);
    }
}

/* Column names: channel (= the position or temperature role), velocity,
   input, ambient. */
static const char *col_x(const draw *d)
{
    return d->rig == RIG_THERMAL ? (d->kelvin ? "T_K" : "T") : d->rig == RIG_PEND ? "angle" : "x";
}
static const char *col_v(const draw *d) { return d->rig == RIG_PEND ? "omega" : "v"; }
static const char *col_u(const draw *d)
{
    return d->rig == RIG_THERMAL ? "P" : d->rig == RIG_PEND ? "torque" : d->rig == RIG_SHAKER ? "base" : "F";
}
static const char *col_amb(const draw *d) { return d->kelvin ? "Ta_K" : "Ta"; }

/* ------------------------------------------------------------------ main */

static int usage(void)
{
    fprintf(stderr, "usage: gen_dyn --list | gen_dyn --case NAME --seed S --out DIR [--quiet-noise] "
                    "[--substeps N] [--verbose]\n");
    return 2;
}

int main(int argc, char **argv)
{
    const char *cname = NULL, *out = NULL;
    long seed = -1, n = 0, nf, nw;
    const dcase *cs = NULL;
    draw d;
    int tr[MAXT], nt = 0, identifiable = 1, attempts, quiet = 0, sub = 4, bumps = 0, verbose = 0;
    double a[MAXT] = {0}, offset = 0, parting = 0, part_target = 0, inflation = 0, lin_err = 0;
    double opar = 0, opar_rel = 0, operiod = 0, range = 0, interp_err = 0;
    double *xr = NULL;
    design g;
    uint64_t h;
    FILE *f;

    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--list") == 0) {
            for (size_t c = 0; c < NCASES; c++)
                printf("%s %s\n", cases[c].name, cases[c].family);
            return 0;
        } else if (strcmp(argv[i], "--case") == 0 && i + 1 < argc) {
            cname = argv[++i];
        } else if (strcmp(argv[i], "--seed") == 0 && i + 1 < argc) {
            seed = strtol(argv[++i], NULL, 10);
        } else if (strcmp(argv[i], "--out") == 0 && i + 1 < argc) {
            out = argv[++i];
        } else if (strcmp(argv[i], "--substeps") == 0 && i + 1 < argc) {
            sub = (int)strtol(argv[++i], NULL, 10);
        } else if (strcmp(argv[i], "--quiet-noise") == 0) {
            quiet = 1;
        } else if (strcmp(argv[i], "--verbose") == 0) {
            verbose = 1;
        } else {
            return usage();
        }
    }
    if (cname == NULL || out == NULL || seed < 0 || sub < 1 || sub > 1000)
        return usage();
    for (size_t c = 0; c < NCASES; c++)
        if (strcmp(cases[c].name, cname) == 0)
            cs = &cases[c];
    if (cs == NULL) {
        fprintf(stderr, "gen_dyn: unknown case %s (gen_dyn --list)\n", cname);
        return 2;
    }
    if (mkdir(out, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "gen_dyn: %s: %s\n", out, strerror(errno));
        return 4;
    }
    h = hash_str(cname);
    memset(&g, 0, sizeof g);
    g.delta = INFINITY;
    g.competitor = -1;

    for (attempts = 1;; attempts++) {
        const int *cand;
        int nc, p, ok = 0, hopeless = 0;
        double *sig[NTERMS] = {0}, *wsig[NTERMS] = {0}, *w1, *ones, *wy, *tmp, ar[64], acf[64];
        double wgt[MAXT], lam;
        make_draw(&d, cs, seed, attempts, h, sub);
        if (verbose)
            fprintf(stderr, "gen_dyn: attempt %d, %ld integrations after the simulation\n", attempts, runs_done);
        n = d.n;
        nf = n - (long)floor(HOLDOUT * (double)n + 0.5);
        range = maxabs_of(d.xsr, n);
        {
            double lo = INFINITY, hi = -INFINITY;
            for (long i = 0; i < n; i++) {
                lo = fmin(lo, d.xsr[i]);
                hi = fmax(hi, d.xsr[i]);
            }
            range = hi - lo;
        }
        xr = vec(n);
        offset = unif() < 0.25 ? 0.0 : unif2(-3, 3) * d.sigma;
        part_target = unif2(PART_MIN, PART_MAX);

        /* Choose the hidden terms. */
        cand = d.order == 2 ? mech_terms : therm_terms;
        nc = d.order == 2 ? 8 : 6;
        nt = 0;
        if (cs->nt == -2) {
            static const int mp[] = {T_VISC, T_QUAD, T_COUL, T_LIN, T_CUB, T_INPUT, T_BIAS};
            static const int tp[] = {T_NEWTON, T_RAD, T_INPUT, T_BIAS};
            const int *pool = d.order == 2 ? mp : tp;
            int np = d.order == 2 ? 7 : 4;
            while (nt < 2) {
                int c = pool[(int)(unif() * np)];
                if (nt == 0 || tr[0] != c)
                    tr[nt++] = c;
            }
        } else {
            for (int j = 0; j < cs->nt; j++)
                tr[nt++] = cs->t[j];
        }

        if (cs->outside != O_NONE) {
            /* the effect's parameter bisected (cogging: scaled) to the drawn parting */
            double *ur = vec(d.m), umax = maxabs_of(d.u_s, d.m), lo, hi, par = 0;
            double ulo = INFINITY, uhi = -INFINITY;
            for (long i = 0; i < d.m; i++) {
                ulo = fmin(ulo, d.u_s[i]);
                uhi = fmax(uhi, d.u_s[i]);
            }
            if (cs->outside == O_COGGING) {
                double A = 1e-3 * range * pow(2 * PI / (d.tau_r[n - 1] + d.dt), 2);
                operiod = range / unif2(5, 20);
                for (int it = 0; it < 6; it++) {
                    outside_run(&d, O_COGGING, A, ur, operiod, xr);
                    parting = maxdiff_of(xr, d.xsr, n) / d.sigma;
                    if (fabs(parting / part_target - 1) < 0.01 || !(parting > 0))
                        break;
                    A *= part_target / parting;
                }
                par = A;
            } else {
                /* parting grows with the dead zone and the play, falls with
                   the saturation level */
                int rising = cs->outside != O_SATURATION;
                lo = cs->outside == O_SATURATION ? 0.05 * umax : 0;
                hi = cs->outside == O_DEADZONE ? 0.9 * umax
                     : cs->outside == O_BACKLASH ? 0.5 * (uhi - ulo) : umax;
                for (int it = 0; it < 40; it++) {
                    par = 0.5 * (lo + hi);
                    outside_run(&d, cs->outside, par, ur, 0, xr);
                    parting = maxdiff_of(xr, d.xsr, n) / d.sigma;
                    if (fabs(parting / part_target - 1) < 0.01)
                        break;
                    if ((parting < part_target) == rising)
                        lo = par;
                    else
                        hi = par;
                }
            }
            opar = par;
            opar_rel = cs->outside == O_COGGING ? 0 : par / (cs->outside == O_BACKLASH ? uhi - ulo : umax);
            free(ur);
            nt = 0;
            break;
        }
        if (nt == 0) {
            memcpy(xr, d.xsr, (size_t)n * sizeof *xr);
            parting = 0;
            break;
        }

        /* The true noise's whitening filter. */
        p = nf / 5 < 30 ? (int)(nf / 5) : 30;
        nw = nf - p;
        noise_acf(d.noise_type, n, p, acf);
        levinson(acf, p, ar);
        ones = vec(nf);
        w1 = vec(nf);
        wy = vec(nf);
        tmp = vec(n);
        for (long i = 0; i < nf; i++)
            ones[i] = 1;
        whiten(ar, p, ones, w1, nf);
        /* The hidden terms' signatures about the simulation; relative sizes
           of their partings, signs (friction and cooling dissipate, the rest
           either way). */
        for (int j = 0; j < nt; j++) {
            int k = tr[j];
            double s = k == T_VISC || k == T_QUAD || k == T_COUL || k == T_NEWTON || k == T_RAD
                           ? -1.0 : sgn_rand();
            sig[k] = vec(n);
            signature(&d, k, range, sig[k]);
            wsig[k] = vec(nf);
            whiten(ar, p, sig[k], wsig[k], nf);
            wgt[j] = s * (nt > 1 ? logunif(0.5, 2.0) : 1.0) / (maxabs_of(sig[k], n) + 1e-300);
        }
        /* The best case first (the largest parting, linear prediction): a
           draw that fails it is redrawn before the competitors' signatures
           are all computed. */
        hopeless = 0;
        g = lin_check(&d, PART_MAX, sig, wsig, tr, nt, wgt, NULL, 0, offset, ar, p, nf, w1, tmp, wy, &lam);
        for (int j = 0; j < nt; j++)
            hopeless |= fabs(g.z[j]) < Z_MIN;
        for (int ci = 0; ci < nc && !(hopeless && attempts < ATTEMPTS); ci++) {
            int c = cand[ci];
            if (sig[c] != NULL)
                continue;
            sig[c] = vec(n);
            signature(&d, c, range, sig[c]);
            wsig[c] = vec(nf);
            whiten(ar, p, sig[c], wsig[c], nf);
            g = lin_check(&d, PART_MAX, sig, wsig, tr, nt, wgt, &c, 1, offset, ar, p, nf, w1, tmp, wy,
                          &lam);
            hopeless |= g.delta < DELTA_MIN;
        }
        if (verbose)
            fprintf(stderr, "gen_dyn: %ld integrations after the signatures%s\n", runs_done,
                    hopeless ? " (hopeless)" : "");
        if (hopeless && attempts < ATTEMPTS)
            goto next_attempt;
        hopeless = 0;
        hopeless = 0;
        for (bumps = 0;; bumps++) {
            /* the coefficients scaled on the linear prediction; the check
               first on it (cheap), then the full nonlinear runs scaled to
               the target parting and the check on them */
            effect e = no_effect;
            int lin_ok;
            g = lin_check(&d, part_target, sig, wsig, tr, nt, wgt, cand, nc, offset, ar, p, nf, w1, tmp,
                          wy, &lam);
            lin_ok = g.delta >= DELTA_MIN;
            for (int j = 0; j < nt; j++)
                lin_ok &= fabs(g.z[j]) >= Z_MIN;
            if (!lin_ok && part_target < PART_MAX) {
                part_target = fmin(PART_MAX, part_target * 1.3);
                continue;
            }
            if (!lin_ok && attempts < ATTEMPTS) {
                hopeless = 1;   /* redrawn without the nonlinear runs */
                break;
            }
            e.nt = nt;
            for (int j = 0; j < nt; j++)
                e.t[j] = tr[j];
            for (int it = 0; it < 6; it++) {
                for (int j = 0; j < nt; j++)
                    e.a[j] = a[j] = lam * wgt[j];
                if (integrate(&d, &e, xr, NULL, NULL) != 0) {
                    parting = INFINITY;
                    break;
                }
                parting = maxdiff_of(xr, d.xsr, n) / d.sigma;
                if (fabs(parting / part_target - 1) < 0.02)
                    break;
                lam *= part_target / parting;
            }
            if (!isfinite(parting))
                break;
            for (long i = 0; i < nf; i++)
                tmp[i] = xr[i] + offset + d.noise[i] - d.xsr[i];
            whiten(ar, p, tmp, wy, nf);
            g = design_check(w1, wsig, cand, nc, wy, nw, tr, nt);
            ok = g.delta >= DELTA_MIN;
            for (int j = 0; j < nt; j++)
                ok &= fabs(g.z[j]) >= Z_MIN;
            if (ok || part_target >= PART_MAX)
                break;
            part_target = fmin(PART_MAX, part_target * 1.3);
        }
        if (!hopeless && isfinite(parting)) {
            /* how far one linearisation about the simulation is from the
               truth: least squares of the noise-free departure on the
               offset and the true signatures (all rows) */
            double *cols[MAXCOL], coef[MAXCOL], se[MAXCOL];
            for (long i = 0; i < n; i++)
                tmp[i] = xr[i] - d.xsr[i];
            free(ones);
            cols[0] = ones = vec(n);
            for (long i = 0; i < n; i++)
                ones[i] = 1;
            for (int j = 0; j < nt; j++)
                cols[1 + j] = sig[tr[j]];
            lin_err = 0;
            if (lsq(cols, 1 + nt, tmp, n, coef, se) >= 0)
                for (int j = 0; j < nt; j++)
                    lin_err = fmax(lin_err, fabs(coef[1 + j] / a[j] - 1));
        }
    next_attempt:
        for (int k = 0; k < NTERMS; k++) {
            free(sig[k]);
            free(wsig[k]);
        }
        free(ones);
        free(w1);
        free(wy);
        free(tmp);
        if (!hopeless && isfinite(parting) && (ok || attempts >= ATTEMPTS)) {
            identifiable = ok;
            break;
        }
        free(xr);
        free_draw(&d);
        if (attempts >= 3 * ATTEMPTS) {
            fprintf(stderr, "gen_dyn: %s seed %ld: no finite draw\n", cname, seed);
            return 4;
        }
    }

    /* The recording: the real trajectory, the sensor's offset, the noise. */
    {
        double *nv = vec(n);
        for (long i = 0; i < n; i++)
            nv[i] = d.noise[i] + xr[i] - d.xsr[i];
        inflation = rms_of(nv, n) / rms_of(d.noise, n) - 1.0;
        free(nv);
    }
    {   /* the error of the simulation interpolated linearly onto the recording */
        long j = 0;
        for (long i = 0; i < n; i++) {
            double lam;
            while (j + 2 < d.m && d.tau_s[j + 1] <= d.tau_r[i])
                j++;
            lam = (d.tau_r[i] - d.tau_s[j]) / (d.tau_s[j + 1] - d.tau_s[j]);
            interp_err = fmax(interp_err, fabs(d.xs[j] + lam * (d.xs[j + 1] - d.xs[j]) - d.xsr[i]));
        }
        interp_err /= d.sigma;
    }
    if (quiet)
        for (long i = 0; i < n; i++)
            d.noise[i] *= 1e-6;

    f = open_out(out, "sim.csv");
    if (d.order == 2)
        fprintf(f, "%s,%s,%s,%s\n", time_column(d.clock), col_x(&d), col_v(&d), col_u(&d));
    else
        fprintf(f, "%s,%s,%s,%s\n", time_column(d.clock), col_x(&d), col_amb(&d), col_u(&d));
    for (long i = 0; i < d.m; i++)
        fprintf(f, "%.17g,%.17g,%.17g,%.17g\n", d.tcol_s[i], d.xs[i],
                d.order == 2 ? d.vs[i] * d.csec : d.amb_s[i], d.u_s[i]);
    close_out(f);
    f = open_out(out, "real.csv");
    fprintf(f, "%s,%s\n", time_column(d.clock), col_x(&d));
    for (long i = 0; i < n; i++)
        fprintf(f, "%.17g,%.17g\n", d.tcol_r[i], xr[i] + offset + d.noise[i]);
    close_out(f);

    /* The truth: coefficients in the K-th derivative per unit term, with
       time in the time column's unit, velocity and drift in that unit too
       (coefficient_per_s: the same with every time in seconds, e.g. -c/m
       in 1/s for viscous friction). */
    f = open_out(out, "truth.json");
    fprintf(f, "{\"case\": \"%s\", \"family\": \"%s\", \"seed\": %ld, \"rig\": \"%s\", \"order\": %d, "
               "\"noise\": \"%s\", \"clock\": \"%s\", \"rows\": %ld, \"sim_rows\": %ld, "
               "\"dt_s\": %.6g, \"input_hold\": \"%s\", \"substeps\": %d, \"sigma\": %.9g, "
               "\"offset\": %.9g, \"range\": %.9g, \"rig_parameters\": {\"inv_m\": %.17g, "
               "\"c_m\": %.17g, \"k_m\": %.17g, \"w2\": %.17g, \"G\": %.17g, \"tau_th\": %.17g, "
               "\"x0\": %.17g, \"v0\": %.17g, \"vmax\": %.17g, \"kelvin\": %d}, \"truth\": [",
            cs->name, cs->family, seed, rig_name[d.rig], d.order, noise_name[d.noise_type],
            clock_name[d.clock], n, d.m, d.dt, d.hold ? "linear" : "zoh", d.sub, d.sigma, offset,
            range, d.inv_m, d.c_m, d.k_m, d.w2, d.G, d.tau_th, d.x0, d.v0, d.vmax, d.kelvin);
    for (int j = 0; j < nt; j++)
        fprintf(f, "%s{\"name\": \"%s\", \"coefficient\": %.12g, \"coefficient_per_s\": %.12g, "
                   "\"design_z\": %.4g}",
                j ? ", " : "", term_name[tr[j]], a[j] * pow(d.csec, d.order),
                a[j] * (tr[j] == T_VISC ? d.csec : tr[j] == T_QUAD ? d.csec * d.csec
                        : tr[j] == T_DRIFT ? 1.0 / d.csec : 1.0), g.z[j]);
    fprintf(f, "], \"identifiable\": %s, \"attempts\": %d, \"bumps\": %d, \"parting\": %.4g, "
               "\"rms_inflation\": %.4g, \"linearisation_error\": %.3g, \"sim_interp_error_sd\": %.3g, ",
            nt == 0 || identifiable ? "true" : "false", attempts, bumps, parting, inflation,
            nt ? lin_err : 0.0, interp_err);
    if (nt > 0 && g.competitor >= 0)
        fprintf(f, "\"competitor\": \"%s\", \"competitor_delta\": %.4g, ", term_name[g.competitor],
                g.delta);
    else
        fprintf(f, "\"competitor\": null, \"competitor_delta\": null, ");
    if (cs->outside != O_NONE)
        fprintf(f, "\"outside\": \"%s\", \"outside_parameter\": %.17g, \"outside_parameter_rel\": %.4g, "
                   "\"outside_period\": %.17g}\n",
                outside_name[cs->outside], opar, opar_rel, operiod);
    else
        fprintf(f, "\"outside\": null}\n");
    close_out(f);

    printf("discover --real %s/real.csv --sim %s/sim.csv --channel %s --time %s --role %s=%s", out, out,
           col_x(&d), time_column(d.clock), col_x(&d), d.order == 2 ? "position" : "temperature");
    if (d.order == 2)
        printf(" --role %s=velocity", col_v(&d));
    else
        printf(" --role %s=ambient", col_amb(&d));
    printf(" --role %s=input --order %d\n", col_u(&d), d.order);
    if (verbose)
        fprintf(stderr, "gen_dyn: %ld integrations, %ld union points\n", runs_done, d.nu);
    free(xr);
    free_draw(&d);
    return 0;
}
