/* SPDX-License-Identifier: MIT */
/* Tangled from literate/model.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/model.org::Model Declarations][Model Declarations]] */
#ifndef FOLDEST_MODEL_H
#define FOLDEST_MODEL_H

#include <stddef.h>
#include <stdint.h>

#include "foldest/catalog.h"
#include "foldest/discover.h"

#ifdef __cplusplus
extern "C" {
#endif

enum {
    FE_MODEL_MAX_PARAMS = 16    /* parameters theta of one model */
};

/* The prediction y = f(t, state; theta) at one row: s->t and the state
   fields of s (position .. input) are the row's; s->real, s->sim and
   s->dsim must not be read.  Return 0 on success; any other value stops
   the step and is returned by it. */
typedef int fe_model_predict_fn(const fe_sample *s, const double *theta,
                                double *y, void *user);

/* The Jacobian jac[i] = d f / d theta_i at (s, theta), i < p.  Return as
   fe_model_predict_fn. */
typedef int fe_model_jacobian_fn(const fe_sample *s, const double *theta,
                                 double *jac, void *user);

/* A model.  Only `p`, `theta0` and `predict` are required. */
typedef struct fe_model {
    size_t p;                       /* parameters, 1..FE_MODEL_MAX_PARAMS */
    const double *theta0;           /* nominal parameters, p */
    const char *const *names;       /* p names (NULL: "theta1", "theta2", ...) */
    fe_model_predict_fn *predict;
    fe_model_jacobian_fn *jacobian; /* NULL: finite differences */
    int forward;                    /* finite differences: 0 central, 1 forward */
    const double *typical;          /* p typical magnitudes for the steps
                                       (NULL: 1 each) */
    void *user;                     /* passed to the callbacks */
} fe_model;

/* The accumulation: the engine's, whose columns are the p Jacobian
   columns then the catalog's terms, and the one row held back for the
   central difference of the prediction.  A flat struct; its storage is
   the caller's, as for fe_discover_acc. */
typedef struct fe_model_acc {
    fe_model model;                 /* copy; theta0 and typical point below */
    const fe_catalog *catalog;      /* must outlive the accumulation */
    fe_discover_acc acc;
    double theta0[FE_MODEL_MAX_PARAMS];
    double typical[FE_MODEL_MAX_PARAMS];
    double step[FE_MODEL_MAX_PARAMS];   /* finite-difference steps used */
    fe_discover_group groups[FE_DISCOVER_MAX_GROUPS];
    size_t ngroups;                 /* p + catalog terms */
    int have_pend, have_before;
    fe_sample pend;                 /* the held row; pend.sim = prediction */
    double pend_jac[FE_MODEL_MAX_PARAMS];
    double before_t, before_y;      /* the row before it, for d(sim)/dt */
} fe_model_acc;

/* fe_model_acc_doubles: storage for a model of p parameters, a catalog of
   `terms` terms and K = blocks time blocks (0 when p + terms exceeds
   FE_DISCOVER_MAX_COLUMNS or p is 0 or above FE_MODEL_MAX_PARAMS). */
size_t fe_model_acc_doubles(size_t p, size_t terms, size_t blocks);

/* fe_model_acc_init: an empty accumulation for model `m` and catalog `c`
   over caller storage; rows [0, fit_rows) are fitted and the rest held
   out, as fe_discover_acc_init.  The model is copied (its callbacks and
   user pointer are kept); `c` is kept by pointer.  Errors: FE_EINVAL (NULL,
   no predict, p out of range, p + c->count above FE_DISCOVER_MAX_COLUMNS),
   FE_ENONFINITE (theta0 or typical not finite,
   a typical value not positive), and those of fe_discover_acc_init. */
int fe_model_acc_init(fe_model_acc *a, const fe_model *m, const fe_catalog *c,
                      size_t blocks, uint64_t fit_rows, double *storage,
                      size_t storage_doubles);

/* fe_model_add: one row: s->t, s->real (the recording) and the state
   fields; s->sim and s->dsim are ignored (the prediction replaces them).
   Times must increase within a recording (FE_EINVAL otherwise).  Evaluates
   the prediction and its Jacobian at theta0, and folds the previous row.
   Errors: FE_EINVAL, FE_ENONFINITE (a value, the prediction, a Jacobian
   entry or a term is not finite), a callback's nonzero return; on any
   error the accumulation is unchanged.  No allocation; cost O(p) callback
   calls plus O((p + terms)^2). */
int fe_model_add(fe_model_acc *a, const fe_sample *s);

/* fe_model_break: the recording ended (the last one too): fold the held
   row with a one-sided difference, and form no lag product across.  Must
   be called before fe_model_select.  Errors: FE_EINVAL; FE_ENONFINITE (the
   held row's terms are not finite: it is dropped). */
int fe_model_break(fe_model_acc *a);

/* fe_model_workspace_doubles: scratch for fe_model_select. */
size_t fe_model_workspace_doubles(const fe_model_acc *a);

/* fe_model_select: discovery with the model's parameters as base terms.
   Groups 0..p-1 of the result are the parameters, group p + j is catalog
   term j.  In `options` (NULL: defaults), `base` lists catalog term
   indices that are also always in the model (e.g. bias); the parameters
   are added to them.  Errors: FE_EINVAL (a row still held: call
   fe_model_break), and those of fe_discover_select (FE_ESINGULAR when
   the Jacobian's columns are collinear: a parameter the data cannot
   determine). */
int fe_model_select(const fe_model_acc *a, const fe_discover_options *options,
                    fe_discover_result *result, double *work,
                    size_t work_doubles);

/* fe_model_group_name: the name of group g of a result (a parameter's or
   a term's); NULL when g is out of range. */
const char *fe_model_group_name(const fe_model_acc *a, size_t g);

/* fe_model_group_is_term: nonzero when group g is a catalog term (and
   *term receives its catalog index), 0 for a parameter. */
int fe_model_group_is_term(const fe_model_acc *a, size_t g, size_t *term);

/* fe_model_theta: the parameters the fit prefers, theta0 + delta (one
   Gauss-Newton step taken with the discovered terms in the model), and
   their batch-means standard errors (se may be NULL).  FE_EINVAL on NULL;
   FE_EUNDETERMINED when the selection set a parameter's column aside as
   redundant (the data cannot determine it): that one keeps theta0 and
   se 0, the others are filled as usual.  Every number written is finite. */
int fe_model_theta(const fe_model_acc *a, const fe_discover_result *r,
                   double *theta, double *se);

#ifdef __cplusplus
}
#endif

#endif /* FOLDEST_MODEL_H */
/* Model Declarations ends here */
