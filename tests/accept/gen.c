/* SPDX-License-Identifier: MIT */
/* gen: one case of the acceptance suite of `foldest discover`, drawn
   independently of foldest.

   This program links and includes nothing of foldest: its own random
   numbers (splitmix64 seeding xoshiro256**, Box-Muller normals), its own
   rigs, noise processes, time columns, its own evaluation of the catalog's
   terms (from the conventions written in README.md, not from the library's
   code) and its own check that the hidden terms are identifiable (a GLS with
   the true noise spectrum).  See tests/accept/README.md.

     gen --list                                 every case: NAME FAMILY
     gen --case NAME --seed S --out DIR         writes DIR/real.csv, DIR/sim.csv,
                                                DIR/truth.json; prints on stdout the
                                                arguments of `foldest` that analyse it
                                                (without --json)
     gen ... --quiet-noise                      the same with the noise divided by 10^6:
                                                a check that the terms follow README.md's
                                                conventions (the fit must return the truth)

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
#define NTERMS 13
#define MAXT 3          /* hidden terms in one case, at most */
#define MAXCOL 20       /* columns of one regression, at most */
#define Z_MIN 8.0       /* design |z| of every hidden term under the true GLS */
#define DELTA_MIN 10.0  /* design RSS gap to the closest competitor, in innovation variances */
#define PEAK_MAX 0.3    /* visible part of the hidden effect, noise sds per sample */
#define HOLDOUT 0.2     /* discover's default: identifiability is judged on the rest */

enum { ROLE_POS, ROLE_VEL, ROLE_TEMP, ROLE_AMB, ROLE_INPUT, NROLES };
enum { RIG_MECH, RIG_THERMAL, RIG_GENERIC };
enum { T_BIAS, T_DRIFT, T_GAIN, T_DELAY, T_VISC, T_QUAD, T_COUL, T_LIN, T_CUB,
       T_THERM, T_NEWTON, T_RAD, T_INPUT };

/* ------------------------------------------------------------------ data */

static const char *const term_name[NTERMS] = {
    "bias", "drift", "gain", "delay", "viscous_friction", "quadratic_drag",
    "coulomb_friction", "linear_stiffness", "cubic_stiffness", "thermal_sensitivity",
    "newton_cooling", "radiative_cooling", "input_gain"};

static const char *const role_name[NROLES] = {"position", "velocity", "temperature",
                                              "ambient", "input"};

static const char *const noise_name[] = {"white", "ar1_0.3", "ar1_0.6", "ar1_0.9",
                                         "ar1_0.95", "ar2_resonant", "pink_0.5",
                                         "pink_1.0", "pink_1.5", "white+walk"};
#define NNOISE 10

static const char *const clock_name[] = {"seconds", "epoch_seconds", "minutes",
                                         "milliseconds", "jitter_dropouts",
                                         "jitter_dropouts_epoch"};
#define NCLOCK 6

static const long lengths[] = {150, 500, 2000, 10000, 50000};
#define NLEN 5

/* A case: its name, family, rig (-1: chosen by seed), hidden terms. */
typedef struct {
    const char *name, *family;
    int rig;            /* RIG_*, or -1: by seed among the rigs that have the terms */
    int nt;             /* hidden terms; -1: two or three drawn by seed */
    int t[MAXT];
    int pair;           /* for pair cases: the near-collinear rival, else -1 */
    const char *outside;/* effect outside the catalog, or NULL */
} acase;

static const acase cases[] = {
    {"hidden_bias", "hidden", -1, 1, {T_BIAS}, -1, NULL},
    {"hidden_drift", "hidden", -1, 1, {T_DRIFT}, -1, NULL},
    {"hidden_gain", "hidden", -1, 1, {T_GAIN}, -1, NULL},
    {"hidden_delay", "hidden", -1, 1, {T_DELAY}, -1, NULL},
    {"hidden_viscous_friction", "hidden", RIG_MECH, 1, {T_VISC}, -1, NULL},
    {"hidden_quadratic_drag", "hidden", RIG_MECH, 1, {T_QUAD}, -1, NULL},
    {"hidden_coulomb_friction", "hidden", RIG_MECH, 1, {T_COUL}, -1, NULL},
    {"hidden_linear_stiffness", "hidden", RIG_MECH, 1, {T_LIN}, -1, NULL},
    {"hidden_cubic_stiffness", "hidden", RIG_MECH, 1, {T_CUB}, -1, NULL},
    {"hidden_thermal_sensitivity", "hidden", -1, 1, {T_THERM}, -1, NULL},
    {"hidden_newton_cooling", "hidden", RIG_THERMAL, 1, {T_NEWTON}, -1, NULL},
    {"hidden_radiative_cooling", "hidden", RIG_THERMAL, 1, {T_RAD}, -1, NULL},
    {"hidden_input_gain", "hidden", -1, 1, {T_INPUT}, -1, NULL},
    {"pair_viscous_not_quadratic", "pair", RIG_MECH, 1, {T_VISC}, T_QUAD, NULL},
    {"pair_quadratic_not_viscous", "pair", RIG_MECH, 1, {T_QUAD}, T_VISC, NULL},
    {"pair_coulomb_not_viscous", "pair", RIG_MECH, 1, {T_COUL}, T_VISC, NULL},
    {"pair_newton_not_radiative", "pair", RIG_THERMAL, 1, {T_NEWTON}, T_RAD, NULL},
    {"pair_radiative_not_newton", "pair", RIG_THERMAL, 1, {T_RAD}, T_NEWTON, NULL},
    {"pair_thermal_not_newton", "pair", RIG_THERMAL, 1, {T_THERM}, T_NEWTON, NULL},
    {"pair_gain_not_input_gain", "pair", RIG_MECH, 1, {T_GAIN}, T_INPUT, NULL},
    {"pair_input_gain_not_gain", "pair", RIG_MECH, 1, {T_INPUT}, T_GAIN, NULL},
    {"pair_bias_not_drift", "pair", -1, 1, {T_BIAS}, T_DRIFT, NULL},
    {"pair_drift_not_bias", "pair", -1, 1, {T_DRIFT}, T_BIAS, NULL},
    {"multi_two", "multi", -1, 2, {0}, -1, NULL},
    {"multi_three", "multi", -1, 3, {0}, -1, NULL},
    {"null_mechanical", "null", RIG_MECH, 0, {0}, -1, NULL},
    {"null_thermal", "null", RIG_THERMAL, 0, {0}, -1, NULL},
    {"null_generic", "null", RIG_GENERIC, 0, {0}, -1, NULL},
    {"outside_cogging", "outside", RIG_MECH, 0, {0}, -1, "cogging"},
    {"outside_clipping", "outside", -1, 0, {0}, -1, "clipping"},
    {"outside_saturation", "outside", RIG_MECH, 0, {0}, -1, "saturation"},
    {"outside_burst", "outside", -1, 0, {0}, -1, "burst"},
    {"outside_ambient_cycling", "outside", RIG_THERMAL, 0, {0}, -1, "ambient_cycling"},
    {"outside_gain_drift", "outside", -1, 0, {0}, -1, "gain_drift"},
};
#define NCASES (sizeof cases / sizeof cases[0])

/* The generator's state for one draw. */
typedef struct {
    int rig, noise_type, clock, kelvin;
    long n, m;                 /* recording rows, simulation rows */
    double dt;                 /* nominal recording step, seconds */
    double *tau_r, *tcol_r;    /* recording: seconds from start; time column */
    double *tau_s, *tcol_s;    /* simulation grid */
    double *s_s, *role_s[NROLES]; /* simulation columns */
    int has_role[NROLES];
    double *s_i, *ds_i, *role_i[NROLES]; /* simulation at the recording's rows */
    double *phi[NTERMS];       /* catalog terms at the recording's rows */
    int avail[NTERMS];
    double *noise, sigma;
    double *y;                 /* recording's channel */
    /* rig parameters kept for outside effects */
    double mass, damp, stiff;
    double heat_gain, gain2, tau_th, tau_sensor, tau_b;
} draw;

/* ------------------------------------------------------------------ random numbers */







static double gauss(void)
{
    static int have;
    static double spare;
    double u, v;
    if (have) {
        have = 0;
        return spare;
    }
    u = unif();
    v = unif();
    spare = sqrt(-2.0 * log(u)) * sin(2.0 * PI * v);
    have = 1;
    return sqrt(-2.0 * log(u)) * cos(2.0 * PI * v);
}


/* ------------------------------------------------------------------ small helpers */

static double *vec(long n)
{
    double *p = calloc((size_t)(n > 0 ? n : 1), sizeof *p);
    if (p == NULL) {
        fprintf(stderr, "gen: out of memory\n");
        exit(4);
    }
    return p;
}






/* ------------------------------------------------------------------ least squares */


/* ------------------------------------------------------------------ noise */

/* Autocovariance r[0..p] of the unit-scale process of noise type `type`
   with n rows, as generated below (before the final rescaling). */
static void noise_acf(int type, long n, int p, double *r)
{
    memset(r, 0, (size_t)(p + 1) * sizeof *r);
    if (type == 0) {
        r[0] = 1;
    } else if (type <= 4) {
        static const double phis[] = {0, 0.3, 0.6, 0.9, 0.95};
        for (int h = 0; h <= p; h++)
            r[h] = pow(phis[type], h);
    } else if (type == 5) {
        double a1 = 2 * 0.9 * cos(0.3), a2 = -0.81;
        r[0] = 1;
        if (p >= 1)
            r[1] = a1 / (1 - a2);
        for (int h = 2; h <= p; h++)
            r[h] = a1 * r[h - 1] + a2 * r[h - 2];
    } else if (type <= 8) {
        double alpha = type == 6 ? 0.5 : type == 7 ? 1.0 : 1.5, tot = 0;
        const int K = 16;
        double w2[16], ph[16];
        for (int k = 0; k < K; k++) {
            double tau = exp(log(4.0 * (double)n) * k / (K - 1));
            ph[k] = exp(-1.0 / tau);
            w2[k] = pow(tau, alpha - 1.0);
            tot += w2[k];
        }
        for (int k = 0; k < K; k++)
            for (int h = 0; h <= p; h++)
                r[h] += 0.9 * w2[k] / tot * pow(ph[k], h);
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

/* Draw n samples of noise type `type` (unit scale, as in noise_acf). */
static void noise_draw(int type, long n, double *x)
{
    if (type == 0) {
        for (long i = 0; i < n; i++)
            x[i] = gauss();
    } else if (type <= 4) {
        static const double phis[] = {0, 0.3, 0.6, 0.9, 0.95};
        double phi = phis[type], c = sqrt(1 - phi * phi), v = gauss();
        for (long i = 0; i < n; i++) {
            x[i] = v;
            v = phi * v + c * gauss();
        }
    } else if (type == 5) {
        double a1 = 2 * 0.9 * cos(0.3), a2 = -0.81, v1 = 0, v2 = 0;
        for (long i = -2000; i < n; i++) {
            double v = a1 * v1 + a2 * v2 + gauss();
            v2 = v1;
            v1 = v;
            if (i >= 0)
                x[i] = v;
        }
    } else if (type <= 8) {
        double alpha = type == 6 ? 0.5 : type == 7 ? 1.0 : 1.5, tot = 0;
        const int K = 16;
        double w2[16], ph[16], st[16];
        for (int k = 0; k < K; k++) {
            double tau = exp(log(4.0 * (double)n) * k / (K - 1));
            ph[k] = exp(-1.0 / tau);
            w2[k] = pow(tau, alpha - 1.0);
            tot += w2[k];
        }
        for (int k = 0; k < K; k++) {
            w2[k] = 0.9 * w2[k] / tot;
            st[k] = sqrt(w2[k]) * gauss();
        }
        for (long i = 0; i < n; i++) {
            double v = sqrt(0.1) * gauss();
            for (int k = 0; k < K; k++) {
                v += st[k];
                st[k] = ph[k] * st[k] + sqrt(w2[k] * (1 - ph[k] * ph[k])) * gauss();
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



/* ------------------------------------------------------------------ time columns */

static double epoch0;

static double time_value(int clock, double tau)
{
    switch (clock) {
    case 1: case 5: return epoch0 + tau;
    case 2: return tau / 60.0;
    case 3: return tau * 1000.0;
    default: return tau;
    }
}

static const char *time_column(int clock)
{
    switch (clock) {
    case 1: case 5: return "unix_time";
    case 2: return "t_min";
    case 3: return "t_ms";
    default: return "time";
    }
}

/* The recording's times (jittered with dropouts for the irregular clocks)
   and the simulation's grid: the recording's own times when regular, else
   a regular grid of half the nominal step over the recording. */
static void make_clock(draw *d)
{
    long n = d->n, i, j;
    epoch0 = floor(unif2(1.69e9, 1.72e9));
    d->tau_r = vec(n);
    d->tcol_r = vec(n);
    if (d->clock < 4) {
        for (i = 0; i < n; i++)
            d->tau_r[i] = (double)i * d->dt;
        d->m = n;
        d->tau_s = vec(n);
        d->tcol_s = vec(n);
        for (i = 0; i < n; i++) {
            d->tau_s[i] = d->tau_r[i];
            d->tcol_s[i] = d->tcol_r[i] = time_value(d->clock, d->tau_r[i]);
        }
        return;
    }
    {
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
        d->m = (long)(d->tau_r[n - 1] / (0.5 * d->dt)) + 3;
        d->tau_s = vec(d->m);
        d->tcol_s = vec(d->m);
        for (i = 0; i < d->m; i++) {
            d->tau_s[i] = (double)i * 0.5 * d->dt;
            d->tcol_s[i] = time_value(d->clock, d->tau_s[i]);
        }
        d->tcol_s[0] = d->tcol_r[0];
    }
}

/* ------------------------------------------------------------------ rigs */

/* A multi-sine with three components (cycles over the record between 2 and
   n/40), its first and second derivatives, at seconds tau. */
typedef struct { double A[3], w[3], p[3], x0; } multisine;

static multisine multisine_draw(double amp, double D, long n, double offset)
{
    multisine m;
    double cmax = (double)n / 40.0 > 4 ? (double)n / 40.0 : 4;
    for (int k = 0; k < 3; k++) {
        m.A[k] = amp * unif2(0.3, 1.0) / (k + 1);
        m.w[k] = 2 * PI * logunif(2.0, cmax) / D;
        m.p[k] = unif2(0, 2 * PI);
    }
    m.x0 = offset;
    return m;
}

static void multisine_eval(const multisine *m, double t, double *x, double *v, double *a)
{
    *x = m->x0;
    *v = *a = 0;
    for (int k = 0; k < 3; k++) {
        double ph = m->w[k] * t + m->p[k];
        *x += m->A[k] * sin(ph);
        *v += m->A[k] * m->w[k] * cos(ph);
        *a -= m->A[k] * m->w[k] * m->w[k] * sin(ph);
    }
}

/* Piecewise-constant levels with linear ramps (a heater, a switched input). */

static steps steps_draw(double D, double lo, double hi)
{
    steps s;
    s.k = 8 + (int)(unif() * 24);
    for (int i = 0; i < s.k; i++)
        s.edge[i] = D * ((double)i + unif2(0.6, 1.4)) / (double)(s.k + 1);
    for (int i = 0; i <= s.k; i++)
        s.level[i] = unif2(lo, hi);
    s.ramp = D / 100.0;
    return s;
}


/* Thermal rig: a body A (the temperature column) heated by u (the input
   column) loses heat to the ambient: A' = (G u - (A - Ta)) / tau_th.  The
   channel is the temperature of a second node B coupled to A and to the
   ambient, with a heater of its own that the simulation models but gives no
   role: B' = (A - B) / tau_ab + (Ta - B + G2 u2) / tau_b.  Without u2, A
   would be a combination of B, dB/dt and Ta, and thermal_sensitivity a
   near-copy of delay.  Integrated by RK4 with four substeps per simulation
   step; cyc_amp adds an on/off square wave to the ambient the simulation
   knows (the ambient-cycling case's real system). */
typedef struct { steps heat, heat2; double ta0, ta_amp, ta_w, ta_p, ta_trend; } thermal_in;

static double ambient_at(const thermal_in *in, double t)
{
    return in->ta0 + in->ta_amp * sin(in->ta_w * t + in->ta_p) + in->ta_trend * t;
}

static void thermal_deriv(const draw *d, const thermal_in *in, double t, const double *x,
                          double cyc_amp, double cyc_period, double *k)
{
    double amb = ambient_at(in, t), u = steps_eval(&in->heat, t);
    if (cyc_amp != 0 && fmod(t, cyc_period) < 0.5 * cyc_period)
        amb += cyc_amp;
    k[0] = (d->heat_gain * u - (x[0] - amb)) / d->tau_th;
    k[1] = (x[0] - x[1]) / d->tau_sensor + (amb - x[1] + d->gain2 * steps_eval(&in->heat2, t)) / d->tau_b;
}

static void thermal_run(const draw *d, const thermal_in *in, const double *tau, long m,
                        double cyc_amp, double cyc_period, double *T, double *Ts)
{
    double x[2];
    x[0] = x[1] = ambient_at(in, tau[0]);
    for (long i = 0; i < m; i++) {
        if (i > 0) {
            double h = (tau[i] - tau[i - 1]) / 4.0, t = tau[i - 1];
            for (int sub = 0; sub < 4; sub++, t += h) {
                double k1[2], k2[2], k3[2], k4[2], z[2];
                thermal_deriv(d, in, t, x, cyc_amp, cyc_period, k1);
                for (int c = 0; c < 2; c++)
                    z[c] = x[c] + h / 2 * k1[c];
                thermal_deriv(d, in, t + h / 2, z, cyc_amp, cyc_period, k2);
                for (int c = 0; c < 2; c++)
                    z[c] = x[c] + h / 2 * k2[c];
                thermal_deriv(d, in, t + h / 2, z, cyc_amp, cyc_period, k3);
                for (int c = 0; c < 2; c++)
                    z[c] = x[c] + h * k3[c];
                thermal_deriv(d, in, t + h, z, cyc_amp, cyc_period, k4);
                for (int c = 0; c < 2; c++)
                    x[c] += h / 6 * (k1[c] + 2 * k2[c] + 2 * k3[c] + k4[c]);
            }
        }
        T[i] = x[0];
        Ts[i] = x[1];
    }
}

static multisine rig_ms;
static thermal_in rig_th;

/* Fill the simulation's columns of the rig on its grid. */
static void make_rig(draw *d, int pair_rival)
{
    long m = d->m, i;
    double D = d->tau_r[d->n - 1] + d->dt;
    d->s_s = vec(m);
    for (int r = 0; r < NROLES; r++) {
        d->role_s[r] = vec(m);
        d->has_role[r] = 0;
    }
    if (d->rig == RIG_MECH) {
        /* m x" + c x' + k x = u, u random steps plus a multi-sine, integrated
           by RK4 (four substeps a step) and scaled to a drawn amplitude: a
           sinusoidal x alone would make x a multiple of its second
           derivative (stiffness a copy of gain) and v of the third
           (viscous friction a copy of delay). */
        double amp = logunif(0.01, 10.0), cmax = (double)d->n / 40.0 > 6 ? (double)d->n / 40.0 : 6;
        double w0 = 2 * PI * logunif(3.0, cmax < 200 ? cmax : 200) / D, zeta = unif2(0.05, 0.5);
        double frac = pair_rival == T_INPUT || pair_rival == T_GAIN ? 0.15 : 1.0, sc, x[2] = {0, 0};
        steps st = steps_draw(D, -1.0, 1.0);
        d->has_role[ROLE_POS] = d->has_role[ROLE_VEL] = d->has_role[ROLE_INPUT] = 1;
        rig_ms = multisine_draw(1.0, D, d->n, 0.0);
        d->mass = logunif(0.1, 10.0);
        /* damping and stiffness small against inertia when gain and
           input_gain must be told apart */
        d->damp = 2 * zeta * w0 * d->mass * frac;
        d->stiff = w0 * w0 * d->mass * frac;
        for (i = 0; i < m; i++) {
            double xx, vv, aa, u;
            if (i > 0) {
                double h = (d->tau_s[i] - d->tau_s[i - 1]) / 4.0, t = d->tau_s[i - 1];
                for (int sub = 0; sub < 4; sub++, t += h) {
                    double k[4][2], z[2], tt[4] = {t, t + h / 2, t + h / 2, t + h};
                    for (int q = 0; q < 4; q++) {
                        double f = q == 0 ? 0 : q == 3 ? h : h / 2;
                        z[0] = x[0] + (q ? f * k[q - 1][0] : 0);
                        z[1] = x[1] + (q ? f * k[q - 1][1] : 0);
                        multisine_eval(&rig_ms, tt[q], &xx, &vv, &aa);
                        u = d->stiff / frac * (steps_eval(&st, tt[q]) + 0.5 * xx);
                        k[q][0] = z[1];
                        k[q][1] = (u - d->damp * z[1] - d->stiff * z[0]) / d->mass;
                    }
                    x[0] += h / 6 * (k[0][0] + 2 * k[1][0] + 2 * k[2][0] + k[3][0]);
                    x[1] += h / 6 * (k[0][1] + 2 * k[1][1] + 2 * k[2][1] + k[3][1]);
                }
            }
            multisine_eval(&rig_ms, d->tau_s[i], &xx, &vv, &aa);
            u = d->stiff / frac * (steps_eval(&st, d->tau_s[i]) + 0.5 * xx);
            d->role_s[ROLE_POS][i] = x[0];
            d->role_s[ROLE_VEL][i] = x[1];
            d->role_s[ROLE_INPUT][i] = u;
            d->s_s[i] = (u - d->damp * x[1] - d->stiff * x[0]) / d->mass;
        }
        /* scale the (linear) rig to the drawn amplitude of motion */
        sc = amp / (maxabs_of(d->role_s[ROLE_POS], m) + 1e-300);
        for (i = 0; i < m; i++) {
            d->role_s[ROLE_POS][i] *= sc;
            d->role_s[ROLE_VEL][i] *= sc;
            d->role_s[ROLE_INPUT][i] *= sc;
            d->s_s[i] *= sc;
        }
    } else if (d->rig == RIG_THERMAL) {
        double dT = pair_rival == T_RAD || pair_rival == T_NEWTON ? unif2(80, 250) : unif2(10, 200);
        d->has_role[ROLE_TEMP] = d->has_role[ROLE_AMB] = d->has_role[ROLE_INPUT] = 1;
        d->kelvin = unif() < 0.5;
        rig_th.heat = steps_draw(D, 0.0, 1.0);
        rig_th.ta0 = unif2(15, 30) + (d->kelvin ? 273.15 : 0.0);
        rig_th.ta_amp = unif2(5, 15);
        rig_th.ta_w = 2 * PI * unif2(1.0, 4.0) / D;
        rig_th.ta_p = unif2(0, 2 * PI);
        rig_th.ta_trend = unif2(-5, 5) / D;
        d->heat_gain = dT;
        d->tau_th = D / unif2(20, 60);
        d->tau_sensor = d->tau_th / unif2(1, 4);
        d->tau_b = d->tau_th / unif2(0.5, 2);
        d->gain2 = dT * unif2(0.3, 1.0);
        rig_th.heat2 = steps_draw(D, 0.0, 1.0);
        thermal_run(d, &rig_th, d->tau_s, m, 0, 1, d->role_s[ROLE_TEMP], d->s_s);
        for (i = 0; i < m; i++) {
            d->role_s[ROLE_AMB][i] = ambient_at(&rig_th, d->tau_s[i]);
            d->role_s[ROLE_INPUT][i] = steps_eval(&rig_th.heat, d->tau_s[i]);
        }
    } else {
        double amp = logunif(1e-3, 1e3);
        multisine ms = multisine_draw(amp, D, d->n, amp * unif2(0.5, 5.0));
        steps st = steps_draw(D, -amp, amp);
        double tb0 = unif2(15, 40), tba = unif2(3, 15), tbw = 2 * PI * unif2(0.3, 1.5) / D,
               tbp = unif2(0, 2 * PI);
        d->has_role[ROLE_TEMP] = 1;
        for (i = 0; i < m; i++) {
            double x, v, a, t = d->tau_s[i];
            multisine_eval(&ms, t, &x, &v, &a);
            d->s_s[i] = x + 0.5 * steps_eval(&st, t);
            d->role_s[ROLE_TEMP][i] = tb0 + tba * sin(tbw * t + tbp) + 0.3 * tba * t / D;
        }
    }
}

/* ------------------------------------------------------------------ the simulation at the recording's rows */

/* As README.md states the convention: linear interpolation of the
   simulation onto the recording's times; d(sim)/dt by central differences
   at the simulation's rows (one-sided at its ends), interpolated the same
   way; the terms evaluated on those values. */
static void align_and_terms(draw *d)
{
    long n = d->n, m = d->m, j = 0;
    double *ds = vec(m), vmax = 0, t1, T1 = 0;
    for (long i = 0; i < m; i++) {
        long a = i > 0 ? i - 1 : i, b = i < m - 1 ? i + 1 : i;
        ds[i] = (d->s_s[b] - d->s_s[a]) / (d->tcol_s[b] - d->tcol_s[a]);
    }
    d->s_i = vec(n);
    d->ds_i = vec(n);
    for (int r = 0; r < NROLES; r++)
        d->role_i[r] = vec(n);
    for (long i = 0; i < n; i++) {
        double t = d->tcol_r[i];
        while (j + 1 < m && d->tcol_s[j + 1] <= t)
            j++;
        if (t == d->tcol_s[j] || j + 1 >= m) {
            d->s_i[i] = d->s_s[j];
            d->ds_i[i] = ds[j];
            for (int r = 0; r < NROLES; r++)
                d->role_i[r][i] = d->role_s[r][j];
        } else {
            double lam = (t - d->tcol_s[j]) / (d->tcol_s[j + 1] - d->tcol_s[j]);
            d->s_i[i] = d->s_s[j] + lam * (d->s_s[j + 1] - d->s_s[j]);
            d->ds_i[i] = ds[j] + lam * (ds[j + 1] - ds[j]);
            for (int r = 0; r < NROLES; r++)
                d->role_i[r][i] = d->role_s[r][j] + lam * (d->role_s[r][j + 1] - d->role_s[r][j]);
        }
    }
    free(ds);
    for (long i = 0; i < n; i++)
        vmax = fabs(d->role_i[ROLE_VEL][i]) > vmax ? fabs(d->role_i[ROLE_VEL][i]) : vmax;
    t1 = d->tcol_r[0];
    T1 = d->role_i[ROLE_TEMP][0];
    for (int k = 0; k < NTERMS; k++)
        d->phi[k] = vec(n);
    for (long i = 0; i < n; i++) {
        double x = d->role_i[ROLE_POS][i], v = d->role_i[ROLE_VEL][i];
        double T = d->role_i[ROLE_TEMP][i], Ta = d->role_i[ROLE_AMB][i];
        double TK = d->kelvin ? T : T + 273.15, TaK = d->kelvin ? Ta : Ta + 273.15;
        d->phi[T_BIAS][i] = 1.0;
        d->phi[T_DRIFT][i] = d->tcol_r[i] - t1;
        d->phi[T_GAIN][i] = d->s_i[i];
        d->phi[T_DELAY][i] = d->ds_i[i];
        d->phi[T_VISC][i] = v;
        d->phi[T_QUAD][i] = v * fabs(v);
        d->phi[T_COUL][i] = vmax > 0 ? tanh(v / (0.002 * vmax)) : 0.0;
        d->phi[T_LIN][i] = x;
        d->phi[T_CUB][i] = x * x * x;
        d->phi[T_THERM][i] = T - T1;
        d->phi[T_NEWTON][i] = TK - TaK;
        d->phi[T_RAD][i] = (TK * TK) * (TK * TK) - (TaK * TaK) * (TaK * TaK);
        d->phi[T_INPUT][i] = d->role_i[ROLE_INPUT][i];
    }
    for (int k = 0; k < NTERMS; k++)
        d->avail[k] = 1;
    d->avail[T_VISC] = d->avail[T_QUAD] = d->avail[T_COUL] = d->has_role[ROLE_VEL];
    d->avail[T_LIN] = d->avail[T_CUB] = d->has_role[ROLE_POS];
    d->avail[T_THERM] = d->has_role[ROLE_TEMP];
    d->avail[T_NEWTON] = d->avail[T_RAD] = d->has_role[ROLE_TEMP] && d->has_role[ROLE_AMB];
    d->avail[T_INPUT] = d->has_role[ROLE_INPUT];
}

/* ------------------------------------------------------------------ identifiability by design */

typedef struct {
    double z[MAXT], coef_hat[MAXT];
    double delta;           /* RSS gap to the closest competitor, in noise variances */
    int competitor;
} design;

/* GLS with the true noise spectrum (AR(p) whitening from Levinson-Durbin on
   the generator's own autocovariance) on the rows discover fits: the hidden
   terms with the base, then every competitor in place of each hidden term. */
static design design_check(const draw *d, double *const *wphi, const double *wy, long nf,
                           const int *base, int nb, const int *tr, int nt)
{
    design g;
    double *cols[MAXCOL], coef[MAXCOL], se[MAXCOL], rss, s2;
    int k = 0;
    g.delta = INFINITY;
    g.competitor = -1;
    for (int b = 0; b < nb; b++)
        cols[k++] = wphi[base[b]];
    for (int j = 0; j < nt; j++)
        cols[k++] = wphi[tr[j]];
    rss = lsq(cols, k, wy, nf, coef, se);
    if (rss < 0) {
        for (int j = 0; j < nt; j++)
            g.z[j] = g.coef_hat[j] = 0;
        g.delta = 0;
        return g;
    }
    s2 = rss / (double)(nf - k);
    for (int j = 0; j < nt; j++) {
        g.z[j] = coef[nb + j] / se[nb + j];
        g.coef_hat[j] = coef[nb + j];
    }
    for (int j = 0; j < nt; j++)
        for (int c = 0; c < NTERMS; c++) {
            int skip = !d->avail[c];
            double r2;
            for (int b = 0; b < nb; b++)
                skip |= base[b] == c;
            for (int l = 0; l < nt; l++)
                skip |= tr[l] == c;
            if (skip)
                continue;
            cols[nb + j] = wphi[c];
            r2 = lsq(cols, k, wy, nf, coef, se);
            cols[nb + j] = wphi[tr[j]];
            if (r2 < 0)
                r2 = rss;   /* the competitor is collinear with the base: no rival */
            if ((r2 - rss) / s2 < g.delta) {
                g.delta = (r2 - rss) / s2;
                g.competitor = c;
            }
        }
    return g;
}

/* ------------------------------------------------------------------ output */

static FILE *open_out(const char *dir, const char *file)
{
    char path[4096];
    FILE *f;
    snprintf(path, sizeof path, "%s/%s", dir, file);
    f = fopen(path, "w");
    if (f == NULL) {
        fprintf(stderr, "gen: %s: %s\n", path, strerror(errno));
        exit(4);
    }
    return f;
}

static void close_out(FILE *f)
{
    if (ferror(f) || fclose(f) != 0) {
        fprintf(stderr, "gen: write error\n");
        exit(4);
    }
}

static const char *channel_name(int rig)
{
    return rig == RIG_MECH ? "acc" : rig == RIG_THERMAL ? "T_sensor" : "pressure";
}

static const char *role_column(const draw *d, int r)
{
    static const char *const mech[NROLES] = {"pos", "vel", "", "", "force"};
    static const char *const th[NROLES] = {"", "", "T_body", "T_amb", "heater"};
    static const char *const thk[NROLES] = {"", "", "T_body_K", "T_amb_K", "heater"};
    static const char *const gen[NROLES] = {"", "", "T_board", "", ""};
    if (d->rig == RIG_MECH)
        return mech[r];
    if (d->rig == RIG_THERMAL)
        return d->kelvin ? thk[r] : th[r];
    return gen[r];
}

/* ------------------------------------------------------------------ the draw */

/* The part of eff (n rows) that the base terms do not absorb (ordinary
   least squares over all rows), written into vis. */
static void visible_part(draw *d, const int *base, int nb, const double *eff, double *vis)
{
    double *cols[MAXCOL], coef[MAXCOL], se[MAXCOL];
    memcpy(vis, eff, (size_t)d->n * sizeof *vis);
    if (nb == 0)
        return;
    for (int b = 0; b < nb; b++)
        cols[b] = d->phi[base[b]];
    if (lsq(cols, nb, eff, d->n, coef, se) < 0)
        return;
    for (long i = 0; i < d->n; i++)
        for (int b = 0; b < nb; b++)
            vis[i] -= coef[b] * d->phi[base[b]][i];
}

/* The recording's time, the rig and the terms for one attempt of a case. */
static void make_draw(draw *d, const acase *cs, long seed, int attempt, uint64_t h)
{
    memset(d, 0, sizeof *d);
    rng_seed(h ^ ((uint64_t)seed * 0x9E3779B97F4A7C15ULL) ^ ((uint64_t)attempt << 48));
    /* the design axes vary with the seed, each at its own pace */
    d->noise_type = (int)(((uint64_t)seed * 7 + h % 10) % NNOISE);
    d->clock = (int)(((uint64_t)seed * 5 + (h >> 8) % NCLOCK) % NCLOCK);
    d->n = lengths[((uint64_t)seed * 3 + (h >> 16) % NLEN) % NLEN];
    if (cs->rig >= 0)
        d->rig = cs->rig;
    else if (cs->nt == 1 && cs->t[0] == T_THERM)
        d->rig = seed % 2 ? RIG_THERMAL : RIG_GENERIC;
    else if (cs->nt == 1 && cs->t[0] == T_INPUT)
        d->rig = seed % 2 ? RIG_THERMAL : RIG_MECH;
    else if (cs->nt != 1 && cs->outside == NULL)
        d->rig = seed % 2 ? RIG_THERMAL : RIG_MECH;
    else
        d->rig = (int)(seed % 3);
    d->dt = d->rig == RIG_THERMAL ? logunif(0.1, 10.0) : logunif(0.001, 0.1);
    make_clock(d);
    make_rig(d, cs->pair);
    align_and_terms(d);
    d->noise = vec(d->n);
    {
        double sd;
        noise_draw(d->noise_type, d->n, d->noise);
        sd = sd_of(d->noise, d->n);
        d->sigma = sd_of(d->s_i, d->n) * logunif(0.01, 0.1);
        for (long i = 0; i < d->n; i++)
            d->noise[i] *= d->sigma / sd;
    }
    d->y = vec(d->n);
}

static void free_draw(draw *d)
{
    free(d->tau_r); free(d->tcol_r); free(d->tau_s); free(d->tcol_s);
    free(d->s_s); free(d->s_i); free(d->ds_i); free(d->noise); free(d->y);
    for (int r = 0; r < NROLES; r++) {
        free(d->role_s[r]);
        free(d->role_i[r]);
    }
    for (int k = 0; k < NTERMS; k++)
        free(d->phi[k]);
}

/* The cogging effect as a term a user could write (foldest discover
   --term): its period in position and its true coefficient, for the
   user-term run of tests/accept/user_terms.py. */
static double cogging_period, cogging_coefficient;

/* An effect outside the catalog, added to (or, for clipping, applied to)
   the recording's channel.  Returns its RMS in noise sds. */
static double outside_effect(draw *d, const char *what)
{
    long n = d->n;
    double *e = vec(n), target = unif2(0.7, 1.5) * d->sigma, r;
    double D = d->tau_r[n - 1] + d->dt;
    if (strcmp(what, "cogging") == 0) {
        double lo = INFINITY, hi = -INFINITY, period;
        for (long i = 0; i < n; i++) {
            lo = fmin(lo, d->role_i[ROLE_POS][i]);
            hi = fmax(hi, d->role_i[ROLE_POS][i]);
        }
        period = (hi - lo) / unif2(8, 20);
        cogging_period = period;
        for (long i = 0; i < n; i++)
            e[i] = sin(2 * PI * d->role_i[ROLE_POS][i] / period);
    } else if (strcmp(what, "saturation") == 0) {
        /* the real actuator delivers at most L: the level is bisected so that
           the missing force has the target RMS (L at least 30 % of the peak) */
        double umax = maxabs_of(d->role_i[ROLE_INPUT], n), lo = 0.3 * umax, hi = umax;
        for (int it = 0; it < 60; it++) {
            double L = 0.5 * (lo + hi);
            for (long i = 0; i < n; i++) {
                double u = d->role_i[ROLE_INPUT][i];
                e[i] = (clampd(u, -L, L) - u) / d->mass;
            }
            if (rms_of(e, n) > target)
                lo = L;
            else
                hi = L;
        }
        for (long i = 0; i < n; i++)
            d->y[i] += e[i];
        r = rms_of(e, n) / d->sigma;
        free(e);
        return r;
    } else if (strcmp(what, "burst") == 0) {
        double c = D * unif2(0.15, 0.85), w = D / unif2(10, 30), per = 8 * d->dt;
        for (long i = 0; i < n; i++) {
            double x = (d->tau_r[i] - c) / w;
            e[i] = fabs(x) < 0.5 ? 3.0 * d->sigma * 0.5 * (1 + cos(2 * PI * x))
                                       * sin(2 * PI * d->tau_r[i] / per)
                                 : 0.0;
        }
        for (long i = 0; i < n; i++)
            d->y[i] += e[i];
        r = rms_of(e, n) / d->sigma;
        free(e);
        return r;
    } else if (strcmp(what, "ambient_cycling") == 0) {
        /* the room's heating switches on and off; the simulation's ambient
           column does not know it */
        double *T = vec(d->m), *Ts = vec(d->m), per = D / unif2(4, 10);
        long j = 0;
        thermal_run(d, &rig_th, d->tau_s, d->m, 1.0, per, T, Ts);
        for (long i = 0; i < n; i++) {
            while (j + 1 < d->m && d->tau_s[j + 1] <= d->tau_r[i])
                j++;
            if (j + 1 >= d->m || d->tau_r[i] == d->tau_s[j]) {
                e[i] = Ts[j] - d->s_s[j];
            } else {
                double lam = (d->tau_r[i] - d->tau_s[j]) / (d->tau_s[j + 1] - d->tau_s[j]);
                e[i] = (1 - lam) * (Ts[j] - d->s_s[j]) + lam * (Ts[j + 1] - d->s_s[j + 1]);
            }
        }
        free(T);
        free(Ts);
    } else if (strcmp(what, "gain_drift") == 0) {
        double P = D / unif2(1.5, 3), ph = unif2(0, 2 * PI);
        for (long i = 0; i < n; i++)
            e[i] = sin(2 * PI * d->tau_r[i] / P + ph) * d->s_i[i];
    } else if (strcmp(what, "clipping") == 0) {
        /* the recorder saturates: 4 % of rows at each end are clipped */
        double *srt = vec(n), lo, hi;
        memcpy(srt, d->y, (size_t)n * sizeof *srt);
        {   /* Shell sort of the values, for the two quantiles */
            long gap;
            for (gap = n / 2; gap > 0; gap /= 2)
                for (long i = gap; i < n; i++)
                    for (long k = i; k >= gap && srt[k - gap] > srt[k]; k -= gap) {
                        double t = srt[k];
                        srt[k] = srt[k - gap];
                        srt[k - gap] = t;
                    }
        }
        lo = srt[(long)(0.04 * (double)n)];
        hi = srt[(long)(0.96 * (double)n)];
        for (long i = 0; i < n; i++) {
            e[i] = clampd(d->y[i], lo, hi) - d->y[i];
            d->y[i] += e[i];
        }
        free(srt);
        r = rms_of(e, n) / d->sigma;
        free(e);
        return r;
    }
    {
        double s = rms_of(e, n);
        for (long i = 0; i < n; i++)
            d->y[i] += e[i] * (s > 0 ? target / s : 0);
        cogging_coefficient = s > 0 ? target / s : 0;
    }
    free(e);
    return target / d->sigma;
}

/* ------------------------------------------------------------------ main */

static int usage(void)
{
    fprintf(stderr, "usage: gen --list | gen --case NAME --seed S --out DIR [--quiet-noise]\n");
    return 2;
}

int main(int argc, char **argv)
{
    const char *cname = NULL, *out = NULL;
    long seed = -1, n, nf, nw;
    const acase *cs = NULL;
    draw d;
    int base[3], nb = 0, tr[MAXT], nt = 0, identifiable = 1, attempts = 0, at_limit = 0, bumps = 0;
    int quiet = 0;
    double a[MAXT] = {0}, nuis[3] = {0}, peak = 0, inflation = 0, outside_rms = 0;
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
        } else if (strcmp(argv[i], "--quiet-noise") == 0) {
            quiet = 1;
        } else {
            return usage();
        }
    }
    if (cname == NULL || out == NULL || seed < 0)
        return usage();
    for (size_t c = 0; c < NCASES; c++)
        if (strcmp(cases[c].name, cname) == 0)
            cs = &cases[c];
    if (cs == NULL) {
        fprintf(stderr, "gen: unknown case %s (gen --list)\n", cname);
        return 2;
    }
    if (mkdir(out, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "gen: %s: %s\n", out, strerror(errno));
        return 4;
    }
    h = hash_str(cname);
    memset(&g, 0, sizeof g);
    g.delta = INFINITY;
    g.competitor = -1;

    for (attempts = 1;; attempts++) {
        double *wphi[NTERMS] = {0}, *wy, *eff, *vis, *tmp, ar[64], acf[64], sig_e;
        int p, ok = 0;
        make_draw(&d, cs, seed, attempts, h);
        n = d.n;
        nf = n - (long)floor(HOLDOUT * (double)n + 0.5);

        /* Choose the hidden terms. */
        nt = 0;
        if (strcmp(cs->family, "multi") == 0) {
            static const int mech[] = {T_DRIFT, T_DELAY, T_VISC, T_QUAD, T_COUL, T_LIN, T_CUB, T_INPUT};
            static const int th[] = {T_DRIFT, T_DELAY, T_THERM, T_NEWTON, T_RAD, T_INPUT};
            const int *pool = d.rig == RIG_MECH ? mech : th;
            int np = d.rig == RIG_MECH ? 8 : 6, want = strcmp(cs->name, "multi_two") == 0 ? 2 : 3;
            while (nt < want) {
                int c = pool[(int)(unif() * np)], dup = 0;
                for (int j = 0; j < nt; j++)
                    dup |= tr[j] == c;
                if (!dup)
                    tr[nt++] = c;
            }
        } else {
            for (int j = 0; j < cs->nt; j++)
                tr[nt++] = cs->t[j];
        }
        /* The base: bias and gain, less a hidden term or its rival. */
        nb = 0;
        {
            static const int def[2] = {T_BIAS, T_GAIN};
            for (int b = 0; b < 2; b++) {
                int out_of_base = cs->pair == def[b];
                for (int j = 0; j < nt; j++)
                    out_of_base |= tr[j] == def[b];
                if (!out_of_base)
                    base[nb++] = def[b];
            }
        }
        /* The base's own true parameters: an offset and a scale error. */
        for (int b = 0; b < nb; b++)
            nuis[b] = base[b] == T_BIAS ? unif2(-3, 3) * d.sigma : unif2(-0.02, 0.02);
        for (long i = 0; i < n; i++) {
            d.y[i] = d.s_i[i] + d.noise[i];
            for (int b = 0; b < nb; b++)
                d.y[i] += nuis[b] * d.phi[base[b]][i];
        }
        if (nt == 0) {
            if (cs->outside != NULL)
                outside_rms = outside_effect(&d, cs->outside);
            break;
        }

        /* The true noise's whitening filter: AR(p) by Levinson-Durbin. */
        p = nf / 5 < 30 ? (int)(nf / 5) : 30;
        nw = nf - p;
        noise_acf(d.noise_type, n, p, acf);
        levinson(acf, p, ar);
        for (int k = 0; k < NTERMS; k++)
            if (d.avail[k]) {
                wphi[k] = vec(nf);
                whiten(ar, p, d.phi[k], wphi[k], nf);
            }
        wy = vec(nf);
        eff = vec(n);
        vis = vec(n);
        tmp = vec(nf);
        whiten(ar, p, d.noise, tmp, nf);
        sig_e = sd_of(tmp, nw);

        /* A first amplitude: the design |z| drawn in [8, 14]. */
        for (int j = 0; j < nt; j++) {
            double *cols[MAXCOL], coef[MAXCOL], se[MAXCOL], rn = 0;
            int k = 0;
            for (int b = 0; b < nb; b++)
                cols[k++] = wphi[base[b]];
            for (int l = 0; l < nt; l++)
                if (l != j)
                    cols[k++] = wphi[tr[l]];
            memcpy(tmp, wphi[tr[j]], (size_t)nw * sizeof *tmp);
            if (k > 0 && lsq(cols, k, tmp, nw, coef, se) >= 0)
                for (long i = 0; i < nw; i++)
                    for (int l = 0; l < k; l++)
                        tmp[i] -= coef[l] * cols[l][i];
            rn = 0;
            for (long i = 0; i < nw; i++)
                rn += tmp[i] * tmp[i];
            rn = sqrt(rn);
            a[j] = sgn_rand() * unif2(8, 14) * sig_e / (rn > 0 ? rn : 1e-300);
        }
        /* Raise the amplitude until the realized true-GLS |z| >= 8 and the
           closest competitor is clearly worse, within the concealment limit. */
        for (bumps = 0; bumps < 12; bumps++) {
            at_limit = 0;
            for (long i = 0; i < n; i++) {
                eff[i] = 0;
                for (int j = 0; j < nt; j++)
                    eff[i] += a[j] * d.phi[tr[j]][i];
            }
            visible_part(&d, base, nb, eff, vis);
            peak = maxabs_of(vis, n) / d.sigma;
            if (peak > PEAK_MAX) {
                for (int j = 0; j < nt; j++)
                    a[j] *= PEAK_MAX / peak;
                for (long i = 0; i < n; i++) {
                    eff[i] *= PEAK_MAX / peak;
                    vis[i] *= PEAK_MAX / peak;
                }
                peak = PEAK_MAX;
                at_limit = 1;
            }
            for (long i = 0; i < nf; i++)
                tmp[i] = d.y[i] - d.s_i[i] + eff[i];
            whiten(ar, p, tmp, wy, nf);
            g = design_check(&d, wphi, wy, nw, base, nb, tr, nt);
            ok = g.delta >= DELTA_MIN;
            for (int j = 0; j < nt; j++)
                ok &= fabs(g.z[j]) >= Z_MIN;
            if (ok || at_limit)
                break;
            for (int j = 0; j < nt; j++)
                a[j] *= 1.3;
        }
        {
            double *nv = vec(n);
            for (long i = 0; i < n; i++)
                nv[i] = d.noise[i] + vis[i];
            inflation = rms_of(nv, n) / rms_of(d.noise, n) - 1.0;
            free(nv);
        }
        for (long i = 0; i < n; i++)
            d.y[i] += eff[i];
        for (int k = 0; k < NTERMS; k++)
            free(wphi[k]);
        free(wy);
        free(eff);
        free(vis);
        free(tmp);
        if (ok || attempts >= 6) {
            identifiable = ok;
            break;
        }
        free_draw(&d);
    }

    /* The self-check of the term conventions: the noise divided by 10^6. */
    if (quiet)
        for (long i = 0; i < d.n; i++)
            d.y[i] -= d.noise[i] * (1.0 - 1e-6);

    /* Write the pair. */
    f = open_out(out, "sim.csv");
    fprintf(f, "%s,%s", time_column(d.clock), channel_name(d.rig));
    for (int r = 0; r < NROLES; r++)
        if (d.has_role[r])
            fprintf(f, ",%s", role_column(&d, r));
    fputc('\n', f);
    for (long i = 0; i < d.m; i++) {
        fprintf(f, "%.17g,%.17g", d.tcol_s[i], d.s_s[i]);
        for (int r = 0; r < NROLES; r++)
            if (d.has_role[r])
                fprintf(f, ",%.17g", d.role_s[r][i]);
        fputc('\n', f);
    }
    close_out(f);
    f = open_out(out, "real.csv");
    fprintf(f, "%s,%s\n", time_column(d.clock), channel_name(d.rig));
    for (long i = 0; i < d.n; i++)
        fprintf(f, "%.17g,%.17g\n", d.tcol_r[i], d.y[i]);
    close_out(f);

    /* Write the truth. */
    f = open_out(out, "truth.json");
    fprintf(f, "{\"case\": \"%s\", \"family\": \"%s\", \"seed\": %ld, \"rig\": \"%s\", "
               "\"noise\": \"%s\", \"clock\": \"%s\", \"rows\": %ld, \"sigma\": %.9g, \"base\": [",
            cs->name, cs->family, seed,
            d.rig == RIG_MECH ? "mechanical" : d.rig == RIG_THERMAL ? "thermal" : "generic",
            noise_name[d.noise_type], clock_name[d.clock], d.n, d.sigma);
    for (int b = 0; b < nb; b++)
        fprintf(f, "%s\"%s\"", b ? ", " : "", term_name[base[b]]);
    fprintf(f, "], \"base_true\": [");
    for (int b = 0; b < nb; b++)
        fprintf(f, "%s%.9g", b ? ", " : "", nuis[b]);
    fprintf(f, "], \"truth\": [");
    for (int j = 0; j < nt; j++)
        fprintf(f, "%s{\"name\": \"%s\", \"coefficient\": %.12g, \"design_z\": %.4g}", j ? ", " : "",
                term_name[tr[j]], a[j], g.z[j]);
    fprintf(f, "], \"identifiable\": %s, \"attempts\": %d, \"at_limit\": %s, "
               "\"peak_visible_sd\": %.4g, \"rms_inflation\": %.4g, ",
            nt == 0 || identifiable ? "true" : "false", attempts, at_limit ? "true" : "false",
            nt ? peak : 0.0, nt ? inflation : 0.0);
    if (nt > 0 && g.competitor >= 0)
        fprintf(f, "\"competitor\": \"%s\", \"competitor_delta\": %.4g, ", term_name[g.competitor],
                g.delta);
    else
        fprintf(f, "\"competitor\": null, \"competitor_delta\": null, ");
    if (cs->pair >= 0)
        fprintf(f, "\"rival\": \"%s\", ", term_name[cs->pair]);
    if (cs->outside != NULL && strcmp(cs->outside, "cogging") == 0)
        fprintf(f, "\"outside\": \"%s\", \"outside_rms_sd\": %.4g, \"outside_term\": "
                   "{\"expression\": \"sin(2*pi*position/%.17g)\", \"coefficient\": %.12g}}\n",
                cs->outside, outside_rms, cogging_period, cogging_coefficient);
    else if (cs->outside != NULL)
        fprintf(f, "\"outside\": \"%s\", \"outside_rms_sd\": %.4g}\n", cs->outside, outside_rms);
    else
        fprintf(f, "\"outside\": null}\n");
    close_out(f);

    /* The command that analyses it. */
    printf("discover --real %s/real.csv --sim %s/sim.csv --channel %s --time %s", out, out,
           channel_name(d.rig), time_column(d.clock));
    for (int r = 0; r < NROLES; r++)
        if (d.has_role[r])
            printf(" --role %s=%s", role_column(&d, r), role_name[r]);
    if (nb > 0) {
        printf(" --base ");
        for (int b = 0; b < nb; b++)
            printf("%s%s", b ? "," : "", term_name[base[b]]);
    }
    printf("\n");
    free_draw(&d);
    return 0;
}
