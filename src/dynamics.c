/* SPDX-License-Identifier: MIT */
/* Tangled from literate/dynamics.org: do not edit; edit the .org and run make tangle. */
/* [[file:../literate/dynamics.org::Dynamics Includes][Dynamics Includes]] */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "foldest/dynamics.h"
#include "foldest/error.h"
/* Dynamics Includes ends here */
/* [[file:../literate/dynamics.org::The state of a sample][The state of a sample]] */
/* Variable i of sample s for order K: 0 state, 1 rate, 2 input, 3 ambient. */
static double fe__var(const fe_sample *s, size_t order, int i)
{
    switch (i) {
    case 0: return order == 2 ? s->position : s->temperature;
    case 1: return order == 2 ? s->velocity : 0.0;
    case 2: return s->input;
    default: return s->ambient;
    }
}

/* The state variable x^(i) of s, for moving it. */
static double *fe__state(fe_sample *s, size_t order, size_t i)
{
    return order == 2 ? (i == 0 ? &s->position : &s->velocity) : &s->temperature;
}

static int fe__order_ok(size_t order)
{
    return order == 1 || order == 2;
}
/* The state of a sample ends here */
/* [[file:../literate/dynamics.org::Finite-difference Jacobian][Finite-difference Jacobian]] */
int fe_dynamics_jacobian_fd(fe_dynamics_fn *f, void *user, size_t order, const fe_sample *s,
                            double *a)
{
    double out[FE_DYNAMICS_MAX_ORDER];
    if (f == NULL || s == NULL || a == NULL || !fe__order_ok(order))
        return FE_EINVAL;
    for (size_t i = 0; i < order; i++) {
        fe_sample p = *s, m = *s;
        double *xp = fe__state(&p, order, i), *xm = fe__state(&m, order, i);
        double h = 1e-6 * (fabs(*xp) + 1.0), fp, fm;
        int rc;
        if (!isfinite(*xp))
            return FE_ENONFINITE;
        *xp += h;
        *xm -= h;
        if ((rc = f(&p, &fp, user)) != 0 || (rc = f(&m, &fm, user)) != 0)
            return rc;
        out[i] = (fp - fm) / (*xp - *xm);
        if (!isfinite(out[i]))
            return FE_ENONFINITE;
    }
    memcpy(a, out, order * sizeof *a);
    return FE_OK;
}
/* Finite-difference Jacobian ends here */
/* [[file:../literate/dynamics.org::The span of the variables][The span of the variables]] */
int fe_dynamics_span_init(fe_dynamics_span *sp, size_t order)
{
    if (sp == NULL || !fe__order_ok(order))
        return FE_EINVAL;
    memset(sp, 0, sizeof *sp);
    sp->order = order;
    return FE_OK;
}

int fe_dynamics_span_add(fe_dynamics_span *sp, const fe_sample *s)
{
    double v[FE_DYNAMICS_VARS];
    if (sp == NULL || s == NULL || !fe__order_ok(sp->order))
        return FE_EINVAL;
    for (int i = 0; i < FE_DYNAMICS_VARS; i++)
        if (!isfinite(v[i] = fe__var(s, sp->order, i)))
            return FE_ENONFINITE;
    for (int i = 0; i < FE_DYNAMICS_VARS; i++) {
        sp->lo[i] = sp->n == 0 || v[i] < sp->lo[i] ? v[i] : sp->lo[i];
        sp->hi[i] = sp->n == 0 || v[i] > sp->hi[i] ? v[i] : sp->hi[i];
    }
    sp->n += 1.0;
    return FE_OK;
}
/* The span of the variables ends here */
/* [[file:../literate/dynamics.org::The basis][The basis]] */
/* The basis at the scaled variables x[0..3]; d[0], d[1] (may be NULL)
   receive each function's derivative in x[0] and x[1]; wn (may be NULL:
   the row's own) the scaled input at the rows before and after.  Returns
   the number of functions. */
static size_t fe__basis(size_t order, const double *x, const double *wn, double *f, double *d0,
                        double *d1)
{
    double p = x[0], v = x[1], w = x[2], b = x[3];
    double wa = wn != NULL ? wn[0] : w, wb = wn != NULL ? wn[1] : w;
    double zero[FE_DYNAMICS_BASIS];
    if (d0 == NULL)
        d0 = zero;
    if (d1 == NULL)
        d1 = zero;
    memset(d0, 0, FE_DYNAMICS_BASIS * sizeof *d0);
    memset(d1, 0, FE_DYNAMICS_BASIS * sizeof *d1);
    if (order == 2) {
        double p2 = p * p;
        f[0] = 1.0;
        f[1] = p, d0[1] = 1.0;
        f[2] = v, d1[2] = 1.0;
        f[3] = w;
        f[4] = p2, d0[4] = 2.0 * p;
        f[5] = p2 * p, d0[5] = 3.0 * p2;
        f[6] = v * fabs(v), d1[6] = 2.0 * fabs(v);
        f[7] = v * v * v, d1[7] = 3.0 * v * v;
        f[8] = p2 * p2 * p, d0[8] = 5.0 * p2 * p2;
        f[9] = p * v, d0[9] = v, d1[9] = p;
        f[10] = wa;
        f[11] = wb;
        return 12;
    }
    f[0] = 1.0;
    f[1] = p, d0[1] = 1.0;
    f[2] = w;
    f[3] = b;
    f[4] = p * p, d0[4] = 2.0 * p;
    f[5] = p * p * p, d0[5] = 3.0 * p * p;
    f[6] = b * b;
    f[7] = p * b, d0[7] = b;
    f[8] = p * p * p * p, d0[8] = 4.0 * p * p * p;
    f[9] = wa;
    f[10] = wb;
    return 11;
}

static void fe__scaled(const double *centre, const double *scale, const fe_sample *s,
                       size_t order, double *x)
{
    for (int i = 0; i < FE_DYNAMICS_VARS; i++)
        x[i] = (fe__var(s, order, i) - centre[i]) / scale[i];
}
/* The basis ends here */
/* [[file:../literate/dynamics.org::The identification fold][The identification fold]] */
int fe_dynamics_ident_init(fe_dynamics_ident *id, const fe_dynamics_span *sp)
{
    if (id == NULL || sp == NULL || !fe__order_ok(sp->order))
        return FE_EINVAL;
    if (sp->n < 1)
        return FE_ETOOFEW;
    memset(id, 0, sizeof *id);
    id->order = sp->order;
    for (int i = 0; i < FE_DYNAMICS_VARS; i++) {
        double half = 0.5 * (sp->hi[i] - sp->lo[i]);
        id->centre[i] = 0.5 * (sp->hi[i] + sp->lo[i]);
        id->scale[i] = half > 1e-12 * (fabs(id->centre[i]) + 1e-300) ? half : 1.0;
    }
    return FE_OK;
}

/* The three-point first derivative at the middle of (t0, t1, t2). */
static double fe__d3(double t0, double t1, double t2, double y0, double y1, double y2)
{
    double h0 = t1 - t0, h1 = t2 - t1;
    return (h0 * h0 * y2 - h1 * h1 * y0 + (h1 * h1 - h0 * h0) * y1) / (h0 * h1 * (h0 + h1));
}

/* The three-point second derivative at the middle of (t0, t1, t2). */
static double fe__dd3(double t0, double t1, double t2, double y0, double y1, double y2)
{
    double h0 = t1 - t0, h1 = t2 - t1;
    return 2.0 * ((y2 - y1) / h1 - (y1 - y0) / h0) / (h0 + h1);
}

int fe_dynamics_ident_add(fe_dynamics_ident *id, const fe_sample *s)
{
    const size_t dim = FE_DYNAMICS_BASIS + 1;
    size_t K;
    if (id == NULL || s == NULL || !fe__order_ok(id->order))
        return FE_EINVAL;
    K = id->order;
    if (!isfinite(s->t))
        return FE_ENONFINITE;
    for (int i = 0; i < FE_DYNAMICS_VARS; i++)
        if (!isfinite(fe__var(s, K, i)))
            return FE_ENONFINITE;
    if (id->nwin > 0 && !(s->t > id->win[id->nwin - 1].t))
        return FE_EINVAL;
    if (id->nwin == 2) {
        /* The middle row's K-th derivative of the state (the second
           difference of the position for K = 2, the three-point derivative
           of the temperature for K = 1), and its basis. */
        const fe_sample *a = &id->win[0], *b = &id->win[1];
        double x[FE_DYNAMICS_VARS], row[FE_DYNAMICS_BASIS + 1] = {0};
        double y = K == 2 ? fe__dd3(a->t, b->t, s->t, fe__var(a, K, 0), fe__var(b, K, 0),
                                    fe__var(s, K, 0))
                          : fe__d3(a->t, b->t, s->t, fe__var(a, K, 0), fe__var(b, K, 0),
                                   fe__var(s, K, 0));
        size_t nb;
        double wn[2] = {(a->input - id->centre[2]) / id->scale[2],
                        (s->input - id->centre[2]) / id->scale[2]};
        fe__scaled(id->centre, id->scale, b, K, x);
        nb = fe__basis(K, x, wn, row, NULL, NULL);
        row[FE_DYNAMICS_BASIS] = y;
        if (!isfinite(y))
            return FE_ENONFINITE;
        (void)nb;
        for (size_t i = 0; i < dim; i++)
            for (size_t j = i; j < dim; j++)
                id->gram[i * dim + j] += row[i] * row[j];
        id->n += 1.0;
        id->win[0] = id->win[1];
        id->win[1] = *s;
    } else
        id->win[id->nwin++] = *s;
    return FE_OK;
}

void fe_dynamics_ident_break(fe_dynamics_ident *id)
{
    if (id != NULL)
        id->nwin = 0;
}

int fe_dynamics_ident_merge(fe_dynamics_ident *a, const fe_dynamics_ident *b)
{
    if (a == NULL || b == NULL)
        return FE_EINVAL;
    if (a->order != b->order)
        return FE_EMISMATCH;
    for (int i = 0; i < FE_DYNAMICS_VARS; i++)
        if (a->centre[i] != b->centre[i] || a->scale[i] != b->scale[i])
            return FE_EMISMATCH;
    for (size_t i = 0; i < sizeof a->gram / sizeof a->gram[0]; i++)
        a->gram[i] += b->gram[i];
    a->n += b->n;
    a->nwin = b->nwin;
    memcpy(a->win, b->win, sizeof a->win);
    return FE_OK;
}
/* The identification fold ends here */
/* [[file:../literate/dynamics.org::Solve the identification][Solve the identification]] */
int fe_dynamics_ident_solve(const fe_dynamics_ident *id, fe_dynamics_fit *fit)
{
    const size_t dim = FE_DYNAMICS_BASIS + 1, y = FE_DYNAMICS_BASIS;
    double R[FE_DYNAMICS_BASIS][FE_DYNAMICS_BASIS] = {{0}}, d[FE_DYNAMICS_BASIS];
    double x0[FE_DYNAMICS_VARS] = {0}, f[FE_DYNAMICS_BASIS], rss, var;
    size_t keep[FE_DYNAMICS_BASIS], q = 0, nb;
    const double *G;
    if (id == NULL || fit == NULL || !fe__order_ok(id->order))
        return FE_EINVAL;
    nb = fe__basis(id->order, x0, NULL, f, NULL, NULL);
    if (id->n < 2.0 * (double)nb)
        return FE_ETOOFEW;
    G = id->gram;
    for (size_t k = 0; k < nb; k++) {
        double c[FE_DYNAMICS_BASIS], piv = G[k * dim + k];
        for (size_t i = 0; i < q; i++) {    /* R^T c = G_Sk */
            double v = G[keep[i] * dim + k];
            for (size_t l = 0; l < i; l++)
                v -= R[l][i] * c[l];
            c[i] = v / R[i][i];
            piv -= c[i] * c[i];
        }
        if (!(G[k * dim + k] > 0.0) || !(piv > 1e-10 * G[k * dim + k]))
            continue;
        for (size_t i = 0; i < q; i++)
            R[i][q] = c[i];
        R[q][q] = sqrt(piv);
        keep[q++] = k;
    }
    if (q == 0)
        return FE_ETOOFEW;
    rss = G[y * dim + y];
    for (size_t i = 0; i < q; i++) {        /* R^T d = G_Sy */
        double v = G[keep[i] * dim + y];
        for (size_t l = 0; l < i; l++)
            v -= R[l][i] * d[l];
        d[i] = v / R[i][i];
        rss -= d[i] * d[i];
    }
    memset(fit, 0, sizeof *fit);
    for (size_t i = q; i-- > 0;) {          /* R beta = d */
        double v = d[i];
        for (size_t l = i + 1; l < q; l++)
            v -= R[i][l] * fit->coef[keep[l]];
        fit->coef[keep[i]] = v / R[i][i];
        fit->used[keep[i]] = 1;
    }
    fit->order = id->order;
    memcpy(fit->centre, id->centre, sizeof fit->centre);
    memcpy(fit->scale, id->scale, sizeof fit->scale);
    fit->nused = q;
    fit->n = id->n;
    rss = rss > 0.0 ? rss : 0.0;
    fit->rms = sqrt(rss / id->n);
    var = G[y * dim + y] - G[0 * dim + y] * G[0 * dim + y] / id->n;
    fit->r2 = var > 0.0 ? 1.0 - rss / var : 1.0;
    return FE_OK;
}

int fe_dynamics_fit_eval(const fe_sample *s, double *deriv, void *user)
{
    const fe_dynamics_fit *fit = user;
    double x[FE_DYNAMICS_VARS], f[FE_DYNAMICS_BASIS], v = 0.0;
    size_t nb;
    if (s == NULL || deriv == NULL || fit == NULL || !fe__order_ok(fit->order))
        return FE_EINVAL;
    fe__scaled(fit->centre, fit->scale, s, fit->order, x);
    nb = fe__basis(fit->order, x, NULL, f, NULL, NULL);
    for (size_t k = 0; k < nb; k++)
        v += fit->coef[k] * f[k];
    if (!isfinite(v))
        return FE_ENONFINITE;
    *deriv = v;
    return FE_OK;
}

int fe_dynamics_fit_jacobian(const fe_sample *s, double *a, void *user)
{
    const fe_dynamics_fit *fit = user;
    double x[FE_DYNAMICS_VARS], f[FE_DYNAMICS_BASIS], d0[FE_DYNAMICS_BASIS],
        d1[FE_DYNAMICS_BASIS], a0 = 0.0, a1 = 0.0;
    size_t nb;
    if (s == NULL || a == NULL || fit == NULL || !fe__order_ok(fit->order))
        return FE_EINVAL;
    fe__scaled(fit->centre, fit->scale, s, fit->order, x);
    nb = fe__basis(fit->order, x, NULL, f, d0, d1);
    for (size_t k = 0; k < nb; k++) {
        a0 += fit->coef[k] * d0[k];
        a1 += fit->coef[k] * d1[k];
    }
    a0 /= fit->scale[0];
    a1 /= fit->scale[1];
    if (!isfinite(a0) || !isfinite(a1))
        return FE_ENONFINITE;
    a[0] = a0;
    if (fit->order == 2)
        a[1] = a1;
    return FE_OK;
}
/* Solve the identification ends here */
/* [[file:../literate/dynamics.org::The Runge-Kutta map of a substep][The Runge-Kutta map of a substep]] */
/* dz/dtau at fraction l of the row step, Jacobian interpolated between
   a0 (the last row's) and a1 (this row's). */
static void fe__deriv(size_t K, const double *a0, const double *a1, double l, const double *z,
                      double f, double *dz)
{
    double j0 = a0[0] + l * (a1[0] - a0[0]);
    if (K == 1) {
        dz[0] = j0 * z[0] + f;
        dz[1] = 0.0;
    } else {
        double j1 = a0[1] + l * (a1[1] - a0[1]);
        dz[0] = z[1];
        dz[1] = j0 * z[0] + j1 * z[1] + f;
    }
}

/* One RK4 step of length h from fraction l0 to l1 for state z and forcing
   f0 at l0, f1 at l1 (linear between), into z. */
static void fe__rk4(size_t K, const double *a0, const double *a1, double l0, double l1, double h,
                    double *z, double f0, double f1)
{
    double lm = 0.5 * (l0 + l1), fm = 0.5 * (f0 + f1), k1[2], k2[2], k3[2], k4[2], y[2];
    fe__deriv(K, a0, a1, l0, z, f0, k1);
    y[0] = z[0] + 0.5 * h * k1[0], y[1] = z[1] + 0.5 * h * k1[1];
    fe__deriv(K, a0, a1, lm, y, fm, k2);
    y[0] = z[0] + 0.5 * h * k2[0], y[1] = z[1] + 0.5 * h * k2[1];
    fe__deriv(K, a0, a1, lm, y, fm, k3);
    y[0] = z[0] + h * k3[0], y[1] = z[1] + h * k3[1];
    fe__deriv(K, a0, a1, l1, y, f1, k4);
    for (int i = 0; i < 2; i++)
        z[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
}

/* The affine map of that step: z' = P z + q0 f0 + q1 f1. */
static void fe__rk4_map(size_t K, const double *a0, const double *a1, double l0, double l1,
                        double h, double P[2][2], double *q0, double *q1)
{
    double e0[2] = {1.0, 0.0}, e1[2] = {0.0, 1.0}, u0[2] = {0.0, 0.0}, u1[2] = {0.0, 0.0};
    fe__rk4(K, a0, a1, l0, l1, h, e0, 0.0, 0.0);
    fe__rk4(K, a0, a1, l0, l1, h, e1, 0.0, 0.0);
    fe__rk4(K, a0, a1, l0, l1, h, u0, 1.0, 0.0);
    fe__rk4(K, a0, a1, l0, l1, h, u1, 0.0, 1.0);
    P[0][0] = e0[0], P[1][0] = e0[1], P[0][1] = e1[0], P[1][1] = e1[1];
    q0[0] = u0[0], q0[1] = u0[1], q1[0] = u1[0], q1[1] = u1[1];
}
/* The Runge-Kutta map of a substep ends here */
/* [[file:../literate/dynamics.org::Integrate the signatures][Integrate the signatures]] */
int fe_dynamics_sens_init(fe_dynamics_sens *sn, size_t order, size_t m)
{
    if (sn == NULL || !fe__order_ok(order))
        return FE_EINVAL;
    if (m > FE_DISCOVER_MAX_COLUMNS)
        return FE_ESIZE;
    memset(sn, 0, sizeof *sn);
    sn->order = order;
    sn->m = m;
    return FE_OK;
}

void fe_dynamics_sens_restart(fe_dynamics_sens *sn)
{
    if (sn != NULL) {
        sn->started = 0;
        memset(sn->z, 0, sizeof sn->z);
    }
}

/* The substeps of a row step of length h: enough that h lambda / n is at
   most 0.2, lambda the fastest rate of the Jacobian at either end. */
static size_t fe__substeps(size_t order, const double *a0, const double *a1, double h)
{
    double l0 = order == 2 ? sqrt(fabs(a0[0])) + fabs(a0[1]) : fabs(a0[0]);
    double l1 = order == 2 ? sqrt(fabs(a1[0])) + fabs(a1[1]) : fabs(a1[0]);
    double n = ceil(h * (l0 > l1 ? l0 : l1) / 0.2);
    return n < 1.0 ? 1 : n > FE_DYNAMICS_MAX_SUBSTEPS ? FE_DYNAMICS_MAX_SUBSTEPS : (size_t)n;
}

int fe_dynamics_sens_step(fe_dynamics_sens *sn, double t, const double *a, const double *phi,
                          double *y, double *rate)
{
    size_t K, m, nsub;
    double z[FE_DISCOVER_MAX_COLUMNS][FE_DYNAMICS_MAX_ORDER], h;
    if (sn == NULL || a == NULL || (phi == NULL && sn->m > 0) || (y == NULL && sn->m > 0)
        || !fe__order_ok(sn->order))
        return FE_EINVAL;
    K = sn->order;
    m = sn->m;
    if (!isfinite(t))
        return FE_ENONFINITE;
    for (size_t i = 0; i < K; i++)
        if (!isfinite(a[i]))
            return FE_ENONFINITE;
    for (size_t j = 0; j < m; j++)
        if (!isfinite(phi[j]))
            return FE_ENONFINITE;
    if (!sn->started) {
        memset(z, 0, sizeof z);
    } else {
        if (!(t > sn->t))
            return FE_EINVAL;
        h = t - sn->t;
        nsub = fe__substeps(K, sn->a, a, h);
        memcpy(z, sn->z, sizeof z);
        h /= (double)nsub;
        for (size_t k = 0; k < nsub; k++) {
            double l0 = (double)k / (double)nsub, l1 = (double)(k + 1) / (double)nsub;
            double P[2][2], q0[2], q1[2];
            fe__rk4_map(K, sn->a, a, l0, l1, h, P, q0, q1);
            for (size_t j = 0; j < m; j++) {
                double f0 = sn->phi[j] + l0 * (phi[j] - sn->phi[j]);
                double f1 = sn->phi[j] + l1 * (phi[j] - sn->phi[j]);
                double s0 = z[j][0], s1 = K == 2 ? z[j][1] : 0.0;
                z[j][0] = P[0][0] * s0 + P[0][1] * s1 + q0[0] * f0 + q1[0] * f1;
                if (K == 2)
                    z[j][1] = P[1][0] * s0 + P[1][1] * s1 + q0[1] * f0 + q1[1] * f1;
            }
        }
        for (size_t j = 0; j < m; j++)
            if (!isfinite(z[j][0]) || !isfinite(z[j][K - 1]))
                return FE_ENONFINITE;
    }
    memcpy(sn->z, z, sizeof z);
    memcpy(sn->a, a, K * sizeof *a);
    if (m > 0)
        memcpy(sn->phi, phi, m * sizeof *phi);
    sn->t = t;
    sn->started = 1;
    for (size_t j = 0; j < m; j++) {
        y[j] = z[j][0];
        if (rate != NULL)
            rate[j] = K == 2 ? z[j][1] : a[0] * z[j][0] + phi[j];
    }
    return FE_OK;
}
/* Integrate the signatures ends here */
/* [[file:../literate/dynamics.org::Integrate the deviation][Integrate the deviation]] */
int fe_dynamics_deviation_init(fe_dynamics_deviation *dv, size_t order)
{
    if (dv == NULL || !fe__order_ok(order))
        return FE_EINVAL;
    memset(dv, 0, sizeof *dv);
    dv->order = order;
    return FE_OK;
}

void fe_dynamics_deviation_restart(fe_dynamics_deviation *dv)
{
    if (dv != NULL) {
        dv->started = 0;
        memset(dv->d, 0, sizeof dv->d);
    }
}

/* The sample at fraction l between a and b, moved by the deviation d. */
static fe_sample fe__between(const fe_sample *a, const fe_sample *b, double l)
{
    fe_sample m;
    m.t = a->t + l * (b->t - a->t);
    m.real = a->real + l * (b->real - a->real);
    m.sim = a->sim + l * (b->sim - a->sim);
    m.dsim = a->dsim + l * (b->dsim - a->dsim);
    m.position = a->position + l * (b->position - a->position);
    m.velocity = a->velocity + l * (b->velocity - a->velocity);
    m.temperature = a->temperature + l * (b->temperature - a->temperature);
    m.ambient = a->ambient + l * (b->ambient - a->ambient);
    m.input = a->input + l * (b->input - a->input);
    return m;
}

/* d(delta)/dt at fraction l of the row step, deviation z. */
static int fe__dev_deriv(const fe_dynamics_deviation *dv, const fe_sample *b, double l,
                         const double *z, fe_dynamics_fn *f, void *fu, fe_dynamics_fn *force,
                         void *gu, double *dz)
{
    size_t K = dv->order;
    fe_sample on = fe__between(&dv->prev, b, l), off = on;
    double f0, f1, g;
    int rc;
    *fe__state(&off, K, 0) += z[0];
    if (K == 2)
        off.velocity += z[1];
    if ((rc = f(&on, &f0, fu)) != 0 || (rc = f(&off, &f1, fu)) != 0
        || (rc = force(&off, &g, gu)) != 0)
        return rc;
    if (K == 2) {
        dz[0] = z[1];
        dz[1] = f1 - f0 + g;
    } else {
        dz[0] = f1 - f0 + g;
        dz[1] = 0.0;
    }
    return FE_OK;
}

int fe_dynamics_deviation_step(fe_dynamics_deviation *dv, const fe_sample *s, const double *a,
                               fe_dynamics_fn *f, void *fuser, fe_dynamics_fn *force,
                               void *forceuser, double *d)
{
    size_t K, nsub;
    double z[2] = {0.0, 0.0}, h;
    if (dv == NULL || s == NULL || a == NULL || f == NULL || force == NULL || d == NULL
        || !fe__order_ok(dv->order))
        return FE_EINVAL;
    K = dv->order;
    if (!isfinite(s->t) || !isfinite(a[0]) || (K == 2 && !isfinite(a[1])))
        return FE_ENONFINITE;
    if (dv->started) {
        int rc;
        if (!(s->t > dv->prev.t))
            return FE_EINVAL;
        memcpy(z, dv->d, sizeof z);
        nsub = fe__substeps(K, dv->a, a, s->t - dv->prev.t);
        h = (s->t - dv->prev.t) / (double)nsub;
        for (size_t k = 0; k < nsub; k++) {
            double l0 = (double)k / (double)nsub, l1 = (double)(k + 1) / (double)nsub;
            double lm = 0.5 * (l0 + l1), k1[2], k2[2], k3[2], k4[2], y[2];
            if ((rc = fe__dev_deriv(dv, s, l0, z, f, fuser, force, forceuser, k1)) != 0)
                return rc;
            y[0] = z[0] + 0.5 * h * k1[0], y[1] = z[1] + 0.5 * h * k1[1];
            if ((rc = fe__dev_deriv(dv, s, lm, y, f, fuser, force, forceuser, k2)) != 0)
                return rc;
            y[0] = z[0] + 0.5 * h * k2[0], y[1] = z[1] + 0.5 * h * k2[1];
            if ((rc = fe__dev_deriv(dv, s, lm, y, f, fuser, force, forceuser, k3)) != 0)
                return rc;
            y[0] = z[0] + h * k3[0], y[1] = z[1] + h * k3[1];
            if ((rc = fe__dev_deriv(dv, s, l1, y, f, fuser, force, forceuser, k4)) != 0)
                return rc;
            for (int i = 0; i < 2; i++)
                z[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        if (!isfinite(z[0]) || !isfinite(z[1]))
            return FE_ENONFINITE;
    }
    memcpy(dv->d, z, sizeof dv->d);
    memcpy(dv->a, a, K * sizeof *a);
    dv->prev = *s;
    dv->started = 1;
    memcpy(d, z, K * sizeof *d);
    return FE_OK;
}
/* Integrate the deviation ends here */
/* [[file:../literate/dynamics.org::The catalog of a dynamics analysis][The catalog of a dynamics analysis]] */
static double fe__offset(const fe_sample *s, const fe_catalog_scale *c, void *u)
{
    (void)s;
    (void)c;
    (void)u;
    return 1.0;
}

int fe_dynamics_catalog_init(fe_catalog *c, size_t order, unsigned roles,
                             const fe_catalog_scale *scale)
{
    fe_catalog all;
    int rc;
    if (c == NULL || scale == NULL || !fe__order_ok(order))
        return FE_EINVAL;
    if ((rc = fe_catalog_init(&all, roles, scale)) != FE_OK)
        return rc;
    *c = all;
    c->count = 0;
    c->terms[c->count].name = "offset";
    c->terms[c->count].description = "constant offset of the measured channel";
    c->terms[c->count].eval = fe__offset;
    c->terms[c->count].user = NULL;
    c->terms[c->count].needs = 0;
    c->terms[c->count].expr = NULL;
    c->count++;
    for (size_t j = 0; j < all.count; j++)
        if (strcmp(all.terms[j].name, "gain") != 0 && strcmp(all.terms[j].name, "delay") != 0)
            c->terms[c->count++] = all.terms[j];
    return FE_OK;
}
/* The catalog of a dynamics analysis ends here */
/* [[file:../literate/dynamics.org::Dynamics coefficients in words][Dynamics coefficients in words]] */
int fe_dynamics_explain(const char *name, size_t order, double coef, double se, char *buf,
                        size_t len)
{
    const char *d = order == 2 ? "d2x/dt2" : "dT/dt";
    if (buf == NULL || len == 0)
        return FE_EINVAL;
    if (order == 0)
        return fe_catalog_explain(name, coef, se, buf, len);
    if (!fe__order_ok(order))
        return FE_EINVAL;
    if (name == NULL)
        name = "";
    if (strcmp(name, "offset") == 0)
        snprintf(buf, len, "the measurement reads %.4g +/- %.2g (channel units) high", coef, se);
    else if (strcmp(name, "bias") == 0)
        snprintf(buf, len, "a constant %s: %s gains %.4g +/- %.2g",
                 order == 2 ? "force per mass" : "heat rate per capacity", d, coef, se);
    else if (strcmp(name, "drift") == 0)
        snprintf(buf, len, "%s gains c (t - t1) with c = %.4g +/- %.2g per time unit", d, coef,
                 se);
    else if (strcmp(name, "viscous_friction") == 0)
        snprintf(buf, len, "viscous damping: %s gains -c v with c = %.4g +/- %.2g (1/time)", d,
                 -coef, se);
    else if (strcmp(name, "quadratic_drag") == 0)
        snprintf(buf, len, "quadratic drag: %s gains -k v|v| with k = %.4g +/- %.2g (1/length)",
                 d, -coef, se);
    else if (strcmp(name, "coulomb_friction") == 0)
        snprintf(buf, len, "dry friction: %s gains -mu sign(v) with mu = %.4g +/- %.2g "
                           "(length/time^2)", d, -coef, se);
    else if (strcmp(name, "linear_stiffness") == 0)
        snprintf(buf, len, "missing spring: %s gains -kappa x with kappa = %.4g +/- %.2g "
                           "(1/time^2)", d, -coef, se);
    else if (strcmp(name, "cubic_stiffness") == 0)
        snprintf(buf, len, "cubic spring: %s gains -kappa3 x^3 with kappa3 = %.4g +/- %.2g (%s)",
                 d, -coef, se, -coef >= 0 ? "hardening" : "softening");
    else if (strcmp(name, "newton_cooling") == 0)
        snprintf(buf, len, "convective loss: %s gains -h (T - T_ambient) with h = %.4g +/- %.2g "
                           "(1/time)", d, -coef, se);
    else if (strcmp(name, "radiative_cooling") == 0)
        snprintf(buf, len, "radiative loss: %s gains -e (T^4 - T_ambient^4) with e = %.4g +/- "
                           "%.2g (1/(K^3 time))", d, -coef, se);
    else if (strcmp(name, "thermal_sensitivity") == 0)
        snprintf(buf, len, "%s gains c (T - T1) with c = %.4g +/- %.2g (1/time)", d, coef, se);
    else if (strcmp(name, "input_gain") == 0)
        snprintf(buf, len, "actuator gain error: %s gains %.4g +/- %.2g per input unit", d, coef,
                 se);
    else
        snprintf(buf, len, "%s gains %.4g +/- %.2g times the term", d, coef, se);
    return FE_OK;
}
/* Dynamics coefficients in words ends here */
