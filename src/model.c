/* SPDX-License-Identifier: MIT */
/* Tangled from literate/model.org: do not edit; edit the .org and run make tangle. */
/* [[file:../literate/model.org::Model Includes][Model Includes]] */
#include <float.h>
#include <math.h>
#include <string.h>

#include "foldest/error.h"
#include "foldest/model.h"

static const char *const fe__theta_names[FE_MODEL_MAX_PARAMS] = {
    "theta1", "theta2", "theta3", "theta4", "theta5", "theta6", "theta7", "theta8",
    "theta9", "theta10", "theta11", "theta12", "theta13", "theta14", "theta15", "theta16",
};
/* Model Includes ends here */
/* [[file:../literate/model.org::Set up a model accumulation][Set up a model accumulation]] */
size_t fe_model_acc_doubles(size_t p, size_t terms, size_t blocks)
{
    if (p == 0 || p > FE_MODEL_MAX_PARAMS || p + terms > FE_DISCOVER_MAX_COLUMNS)
        return 0;
    return fe_discover_acc_doubles(p + terms, blocks);
}

int fe_model_acc_init(fe_model_acc *a, const fe_model *m, const fe_catalog *c,
                      size_t blocks, uint64_t fit_rows, double *storage,
                      size_t storage_doubles)
{
    size_t p;
    int rc;
    if (a == NULL || m == NULL || c == NULL || m->predict == NULL || m->theta0 == NULL)
        return FE_EINVAL;
    p = m->p;
    if (p == 0 || p > FE_MODEL_MAX_PARAMS || p + c->count > FE_DISCOVER_MAX_COLUMNS)
        return FE_EINVAL;
    for (size_t i = 0; i < p; i++)
        if (!isfinite(m->theta0[i])
            || (m->typical != NULL && !(isfinite(m->typical[i]) && m->typical[i] > 0.0)))
            return FE_ENONFINITE;
    memset(a, 0, sizeof *a);            /* padding too: the state is all defined */
    rc = fe_discover_acc_init(&a->acc, p + c->count, blocks, fit_rows, 0, storage,
                              storage_doubles);
    if (rc != FE_OK)
        return rc;
    a->model.p = p;
    a->model.names = m->names;
    a->model.predict = m->predict;
    a->model.jacobian = m->jacobian;
    a->model.forward = m->forward;
    a->model.user = m->user;
    a->catalog = c;
    for (size_t i = 0; i < p; i++) {
        double th = m->theta0[i], tau = m->typical != NULL ? m->typical[i] : 1.0;
        double h = (m->forward ? sqrt(DBL_EPSILON) : cbrt(DBL_EPSILON))
                   * (fabs(th) > tau ? fabs(th) : tau);
        volatile double moved = th + h;     /* the step floating point takes */
        a->theta0[i] = th;
        a->typical[i] = tau;
        a->step[i] = moved - th;
    }
    a->model.theta0 = a->theta0;
    a->model.typical = a->typical;
    a->ngroups = p + c->count;
    for (size_t i = 0; i < p; i++) {
        a->groups[i].name = m->names != NULL && m->names[i] != NULL ? m->names[i]
                                                                    : fe__theta_names[i];
        a->groups[i].first = i;
        a->groups[i].count = 1;
    }
    for (size_t j = 0; j < c->count; j++) {
        a->groups[p + j].name = c->terms[j].name;
        a->groups[p + j].first = p + j;
        a->groups[p + j].count = 1;
    }
    return FE_OK;
}
/* Set up a model accumulation ends here */
/* [[file:../literate/model.org::Predict and differentiate][Predict and differentiate]] */
static int fe__model_eval(const fe_model_acc *a, const fe_sample *s, double *y,
                          double *jac)
{
    const fe_model *m = &a->model;
    double th[FE_MODEL_MAX_PARAMS];
    int rc = m->predict(s, a->theta0, y, m->user);
    if (rc != 0)
        return rc;
    if (!isfinite(*y))
        return FE_ENONFINITE;
    if (m->jacobian != NULL) {
        rc = m->jacobian(s, a->theta0, jac, m->user);
        if (rc != 0)
            return rc;
    } else {
        memcpy(th, a->theta0, m->p * sizeof *th);
        for (size_t i = 0; i < m->p; i++) {
            double h = a->step[i], up, down = *y;
            th[i] = a->theta0[i] + h;
            rc = m->predict(s, th, &up, m->user);
            if (rc == 0 && !m->forward) {
                th[i] = a->theta0[i] - h;
                rc = m->predict(s, th, &down, m->user);
            }
            th[i] = a->theta0[i];
            if (rc != 0)
                return rc;
            jac[i] = (up - down) / (m->forward ? h : 2.0 * h);
        }
    }
    for (size_t i = 0; i < m->p; i++)
        if (!isfinite(jac[i]))
            return FE_ENONFINITE;
    return FE_OK;
}
/* Predict and differentiate ends here */
/* [[file:../literate/model.org::Fold the held row][Fold the held row]] */
static int fe__model_fold_pend(fe_model_acc *a, int has_next, double next_t,
                               double next_y)
{
    fe_sample s = a->pend;
    double phi[FE_DISCOVER_MAX_COLUMNS];
    double t0 = a->have_before ? a->before_t : s.t, y0 = a->have_before ? a->before_y : s.sim;
    double t1 = has_next ? next_t : s.t, y1 = has_next ? next_y : s.sim;
    size_t p = a->model.p;
    int rc;
    s.dsim = t1 > t0 ? (y1 - y0) / (t1 - t0) : 0.0;
    memcpy(phi, a->pend_jac, p * sizeof *phi);
    rc = fe_catalog_eval(a->catalog, &s, phi + p);
    if (rc != FE_OK)
        return rc;
    return fe_discover_add(&a->acc, phi, s.real - s.sim);
}
/* Fold the held row ends here */
/* [[file:../literate/model.org::Add a row, end a recording][Add a row, end a recording]] */
int fe_model_add(fe_model_acc *a, const fe_sample *s)
{
    double y, jac[FE_MODEL_MAX_PARAMS], phi[FE_DISCOVER_MAX_COLUMNS];
    fe_sample row;
    int rc;
    if (a == NULL || s == NULL || a->catalog == NULL)
        return FE_EINVAL;
    if (!isfinite(s->t) || !isfinite(s->real))
        return FE_ENONFINITE;
    if (a->have_pend && !(s->t > a->pend.t))
        return FE_EINVAL;
    rc = fe__model_eval(a, s, &y, jac);
    if (rc != FE_OK)
        return rc;
    row = *s;
    row.sim = y;
    row.dsim = 0.0;
    rc = fe_catalog_eval(a->catalog, &row, phi);
    if (rc != FE_OK)
        return rc;
    if (!isfinite(row.real - y))
        return FE_ENONFINITE;
    if (a->have_pend) {
        rc = fe__model_fold_pend(a, 1, row.t, y);
        if (rc != FE_OK)
            return rc;
        a->before_t = a->pend.t;
        a->before_y = a->pend.sim;
        a->have_before = 1;
    }
    a->pend = row;
    memcpy(a->pend_jac, jac, a->model.p * sizeof *jac);
    a->have_pend = 1;
    return FE_OK;
}

int fe_model_break(fe_model_acc *a)
{
    int rc = FE_OK;
    if (a == NULL)
        return FE_EINVAL;
    if (a->have_pend)
        rc = fe__model_fold_pend(a, 0, 0.0, 0.0);
    a->have_pend = 0;
    a->have_before = 0;
    fe_discover_break(&a->acc);
    return rc;
}
/* Add a row, end a recording ends here */
/* [[file:../literate/model.org::Select and read the result][Select and read the result]] */
size_t fe_model_workspace_doubles(const fe_model_acc *a)
{
    return a != NULL ? fe_discover_workspace_doubles(a->acc.m, a->acc.blocks) : 0;
}

int fe_model_select(const fe_model_acc *a, const fe_discover_options *options,
                    fe_discover_result *result, double *work,
                    size_t work_doubles)
{
    fe_discover_options o = options != NULL ? *options : fe_discover_default_options();
    size_t base[FE_DISCOVER_MAX_GROUPS], nbase = 0, p;
    if (a == NULL || result == NULL || a->catalog == NULL || a->have_pend)
        return FE_EINVAL;
    p = a->model.p;
    if (o.nbase > 0 && o.base == NULL)
        return FE_EINVAL;
    for (size_t i = 0; i < p; i++)
        base[nbase++] = i;
    for (size_t i = 0; i < o.nbase; i++) {
        if (o.base[i] >= a->catalog->count || nbase >= FE_DISCOVER_MAX_GROUPS)
            return FE_EINVAL;
        base[nbase++] = p + o.base[i];
    }
    o.base = base;
    o.nbase = nbase;
    return fe_discover_select(&a->acc, a->groups, a->ngroups, &o, result, work,
                              work_doubles);
}

const char *fe_model_group_name(const fe_model_acc *a, size_t g)
{
    return a != NULL && g < a->ngroups ? a->groups[g].name : NULL;
}

int fe_model_group_is_term(const fe_model_acc *a, size_t g, size_t *term)
{
    if (a == NULL || g < a->model.p || g >= a->ngroups)
        return 0;
    if (term != NULL)
        *term = g - a->model.p;
    return 1;
}

int fe_model_theta(const fe_model_acc *a, const fe_discover_result *r,
                   double *theta, double *se)
{
    int rc = FE_OK;
    if (a == NULL || r == NULL || theta == NULL)
        return FE_EINVAL;
    for (size_t i = 0; i < a->model.p; i++) {
        int found = 0;
        theta[i] = a->theta0[i];
        if (se != NULL)
            se[i] = 0.0;
        for (size_t j = 0; j < r->ncols; j++)
            if (r->cols[j] == i) {
                theta[i] += r->coef[j];
                if (se != NULL)
                    se[i] = r->stderr_[j];
                found = 1;
            }
        if (!found)             /* set aside: the data cannot determine it */
            rc = FE_EUNDETERMINED;
    }
    return rc;
}
/* Select and read the result ends here */
