/* SPDX-License-Identifier: MIT */
/* Tangled from literate/dynamics.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/dynamics.org::Dynamics Declarations][Dynamics Declarations]] */
#ifndef FOLDEST_DYNAMICS_H
#define FOLDEST_DYNAMICS_H

#include <stddef.h>

#include "foldest/catalog.h"
#include "foldest/discover.h"

#ifdef __cplusplus
extern "C" {
#endif

enum {
    FE_DYNAMICS_MAX_ORDER = 2,      /* K: the derivative an effect enters */
    FE_DYNAMICS_BASIS = 12,         /* functions the simulation is fitted on */
    FE_DYNAMICS_VARS = 4,           /* state, rate, input, ambient */
    FE_DYNAMICS_MAX_SUBSTEPS = 256, /* substeps of one row step */
    FE_DYNAMICS_OFFSET = 0          /* the term of a dynamics catalog that
                                       enters the measurement, not the motion */
};

/* The state of order K read from a sample: K = 2, position and velocity;
   K = 1, temperature.  Functions below take an order and refuse others
   with FE_EINVAL. */

/* A simulation's dynamics, x^(K) = f(sample): *deriv receives the K-th
   derivative of the state at s (its time, state fields, input, ambient).
   Return 0 on success; any other value is passed back. */
typedef int fe_dynamics_fn(const fe_sample *s, double *deriv, void *user);

/* The Jacobian of such dynamics: a[i] = d f / d x^(i), i < K, at s.
   Return as fe_dynamics_fn. */
typedef int fe_dynamics_jacobian_fn(const fe_sample *s, double *a, void *user);

/* fe_dynamics_jacobian_fd: a[i] by central differences of f, the state
   variable i moved by 1e-6 (|x| + 1) either way.  Errors: FE_EINVAL,
   FE_ENONFINITE (a value not finite), or f's own nonzero return. */
int fe_dynamics_jacobian_fd(fe_dynamics_fn *f, void *user, size_t order, const fe_sample *s,
                            double *a);

/* The range of each variable over the record (state, rate, input,
   ambient), found by a first pass: the basis is scaled by it. */
typedef struct fe_dynamics_span {
    size_t order;
    double n;
    double lo[FE_DYNAMICS_VARS], hi[FE_DYNAMICS_VARS];
} fe_dynamics_span;

/* fe_dynamics_span_init, _add: an empty span of order K; one sample into
   it.  FE_EINVAL (NULL, order not 1 or 2), FE_ENONFINITE (a value not
   finite: the span is unchanged). */
int fe_dynamics_span_init(fe_dynamics_span *sp, size_t order);
int fe_dynamics_span_add(fe_dynamics_span *sp, const fe_sample *s);

/* The fold that identifies the simulation's dynamics from its own rows:
   the normal equations of the K-th derivative (three-point differences)
   on the basis.  A flat struct: copy it, merge it. */
typedef struct fe_dynamics_ident {
    size_t order;
    double centre[FE_DYNAMICS_VARS], scale[FE_DYNAMICS_VARS];
    double gram[(FE_DYNAMICS_BASIS + 1) * (FE_DYNAMICS_BASIS + 1)];
    double n;                       /* rows folded */
    size_t nwin;                    /* rows waiting for their successor */
    fe_sample win[2];               /* ... oldest first */
} fe_dynamics_ident;

/* fe_dynamics_ident_init: an empty fold scaled by the span `sp` (at
   least one row).  FE_EINVAL, FE_ETOOFEW (an empty span). */
int fe_dynamics_ident_init(fe_dynamics_ident *id, const fe_dynamics_span *sp);

/* fe_dynamics_ident_add: the next simulated row of a recording.  Times
   must increase (FE_EINVAL); FE_ENONFINITE for values not finite.  On an
   error the fold is unchanged.  A row is folded once its successor is
   known; the first and last row of every recording are not. */
int fe_dynamics_ident_add(fe_dynamics_ident *id, const fe_sample *s);

/* fe_dynamics_ident_break: the recording ended; the next row begins
   another. */
void fe_dynamics_ident_break(fe_dynamics_ident *id);

/* fe_dynamics_ident_merge: a <- a (+) b, for parts cut at recording
   boundaries (rows whose differences would straddle a cut are lost).
   FE_EMISMATCH when the orders or scalings differ. */
int fe_dynamics_ident_merge(fe_dynamics_ident *a, const fe_dynamics_ident *b);

/* The identified dynamics: f = sum of coef[k] basis_k over the basis
   functions kept. */
typedef struct fe_dynamics_fit {
    size_t order;
    double centre[FE_DYNAMICS_VARS], scale[FE_DYNAMICS_VARS];
    double coef[FE_DYNAMICS_BASIS];
    unsigned char used[FE_DYNAMICS_BASIS];
    size_t nused;
    double n;                       /* rows fitted */
    double rms;                     /* of the fit's residual */
    double r2;                      /* 1 - residual / response variance */
} fe_dynamics_fit;

/* fe_dynamics_ident_solve: the fit.  Errors: FE_EINVAL, FE_ETOOFEW
   (fewer rows than twice the basis). */
int fe_dynamics_ident_solve(const fe_dynamics_ident *id, fe_dynamics_fit *fit);

/* fe_dynamics_fit_jacobian: the fit's Jacobian at s, an
   fe_dynamics_jacobian_fn with user = the fit. */
int fe_dynamics_fit_jacobian(const fe_sample *s, double *a, void *user);

/* fe_dynamics_fit_eval: the fit's value, an fe_dynamics_fn. */
int fe_dynamics_fit_eval(const fe_sample *s, double *deriv, void *user);

/* The signatures of m forcings: each one's response through the
   linearised dynamics from zero at the recording's start.  Flat. */
typedef struct fe_dynamics_sens {
    size_t order, m;
    int started;
    double t, a[FE_DYNAMICS_MAX_ORDER];         /* the last row's */
    double phi[FE_DISCOVER_MAX_COLUMNS];
    double z[FE_DISCOVER_MAX_COLUMNS][FE_DYNAMICS_MAX_ORDER];
} fe_dynamics_sens;

/* fe_dynamics_sens_init: m forcings (at most FE_DISCOVER_MAX_COLUMNS)
   through dynamics of order K.  FE_EINVAL, FE_ESIZE. */
int fe_dynamics_sens_init(fe_dynamics_sens *sn, size_t order, size_t m);

/* fe_dynamics_sens_restart: a new recording: the responses start again
   from zero at its first row. */
void fe_dynamics_sens_restart(fe_dynamics_sens *sn);

/* fe_dynamics_sens_step: the row at time t, with the Jacobian a[0 .. K)
   and the forcings phi[0 .. m): the signatures y[0 .. m) at t and their
   rates (may be NULL).  The first row of a recording gives zeros.
   Errors: FE_EINVAL (NULL, t not after the last row), FE_ENONFINITE (an
   input or a response not finite); the state is then unchanged.  No
   allocation; about 8 m multiply-adds a substep. */
int fe_dynamics_sens_step(fe_dynamics_sens *sn, double t, const double *a, const double *phi,
                          double *y, double *rate);

/* The deviation of the real trajectory from the simulated one when the
   forcing `force` (e.g. the discovered terms times their coefficients) is
   added to the dynamics f: delta^(K) = f(sim + delta) - f(sim) +
   force(sim + delta), from zero at the recording's first row.  Flat. */
typedef struct fe_dynamics_deviation {
    size_t order;
    int started;
    fe_sample prev;                             /* the last row, as given */
    double a[FE_DYNAMICS_MAX_ORDER];            /* its Jacobian (for substeps) */
    double d[FE_DYNAMICS_MAX_ORDER];            /* delta and its rate there */
} fe_dynamics_deviation;

/* fe_dynamics_deviation_init, _restart: an empty integrator of order K;
   a new recording.  FE_EINVAL. */
int fe_dynamics_deviation_init(fe_dynamics_deviation *dv, size_t order);
void fe_dynamics_deviation_restart(fe_dynamics_deviation *dv);

/* fe_dynamics_deviation_step: the row s (the simulation's states), with
   the Jacobian a[0 .. K) there (it sets the substeps, as for the
   signatures): delta and its rate at s into d[0 .. K).  Between rows every
   field of the sample is taken linear in time and the deviation advances
   by fourth-order Runge-Kutta.  Errors: FE_EINVAL (NULL, time not after
   the last row's), FE_ENONFINITE, or a callback's nonzero return; the
   state is then unchanged.  Cost: per substep 8 calls of f and 4 of
   force. */
int fe_dynamics_deviation_step(fe_dynamics_deviation *dv, const fe_sample *s, const double *a,
                               fe_dynamics_fn *f, void *fuser, fe_dynamics_fn *force,
                               void *forceuser, double *d);

/* fe_dynamics_catalog_init: the catalog of order K for these roles: the
   sensor's offset first (FE_DYNAMICS_OFFSET, which enters the
   measurement), then the catalog's terms that can act on the motion
   (bias as a constant force, drift, the frictions, springs, heat losses,
   input gain; not gain or delay, which describe the measurement).
   Errors as fe_catalog_init; FE_EINVAL for an order not 1 or 2. */
int fe_dynamics_catalog_init(fe_catalog *c, size_t order, unsigned roles,
                             const fe_catalog_scale *scale);

/* fe_dynamics_explain: term `name`'s coefficient in words, in the
   convention of the K-th derivative ("viscous damping: d2x/dt2 gains -c v
   with c = ..."); as fe_catalog_explain for order 0. */
int fe_dynamics_explain(const char *name, size_t order, double coef, double stderr_,
                        char *buf, size_t len);

#ifdef __cplusplus
}
#endif

#endif /* FOLDEST_DYNAMICS_H */
/* Dynamics Declarations ends here */
