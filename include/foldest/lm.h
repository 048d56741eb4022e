/* SPDX-License-Identifier: MIT */
/* Tangled from literate/lm.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/lm.org::Levenberg-Marquardt Declarations][Levenberg-Marquardt Declarations]] */
#ifndef FOLDEST_LM_H
#define FOLDEST_LM_H

#include <stddef.h>
#include <stdint.h>

#include "foldest/schur.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Where a model sends its residuals; owned by the solver. */
typedef struct fe_lm_sink fe_lm_sink;

/* A model: at the parameters x (ng globals, then nb blocks of nl), call
   fe_lm_emit once per residual, and return FE_OK or an error code (which
   stops the solver and is returned by it).  Must not modify ctx. */
typedef int fe_lm_model_fn(const double *x, fe_lm_sink *sink, void *ctx);

/* fe_lm_emit: one residual f with weight w >= 0, and its gradient: jg[ng]
   with respect to the globals, and jl[nl] with respect to block `block`
   (FE_SCHUR_NONE: the residual depends on no block; jl is then unused).
   jg and jl may be NULL when fe_lm_wants_jacobian(sink) is 0.  Returns
   FE_ENONFINITE, FE_EINVAL (block out of range) or FE_OK; the sink also
   remembers the first error, so the solver sees it even if the model does
   not pass it on. */
int fe_lm_emit(fe_lm_sink *sink, double f, double w, const double *jg,
               size_t block, const double *jl);

/* fe_lm_wants_jacobian: 0 when only the cost is wanted. */
int fe_lm_wants_jacobian(const fe_lm_sink *sink);

/* A problem: sizes and the model.  The parameter vector holds the ng
   globals, then block b's nl locals at ng + b*nl.  nl = 0 (or nb = 0) is a
   problem without blocks. */
typedef struct fe_lm_problem {
    size_t ng, nl, nb;
    fe_lm_model_fn *model;
    void *ctx;
} fe_lm_problem;

/* How the damped normal equations are solved. */
enum fe_lm_method {
    FE_LM_DENSE = 0,    /* one p x p Cholesky: O(p^2) memory, O(p^3) time */
    FE_LM_SCHUR = 1     /* eliminate the blocks: linear in nb */
};

/* Why the iteration stopped. */
enum fe_lm_stop {
    FE_LM_RUNNING = 0,
    FE_LM_FTOL,         /* cost <= ftol */
    FE_LM_XTOL,         /* negligible step */
    FE_LM_GTOL,         /* negligible gradient */
    FE_LM_MAXITER,      /* max_iter reached (FE_ENOCONV) */
    FE_LM_STOPPED,      /* the report callback asked to stop */
    FE_LM_STUCK,        /* damping grew without bound (FE_ENOCONV) */
    FE_LM_RTOL          /* negligible relative change of the cost */
};

typedef struct fe_lm_params {
    int max_iter;       /* iterations, taken or not (default 100) */
    double lambda0;     /* initial Marquardt damping (default 1e-3) */
    double xtol;        /* negligible step, relative (default 1e-12) */
    double gtol;        /* negligible max |J'Wf| (default 0) */
    double ftol;        /* cost low enough (default 0) */
    double rtol;        /* negligible relative change of the cost: an
                           accepted step whose actual and predicted
                           reductions are both <= rtol * cost ends the
                           iteration (default 1e-12; 0: never) */
    double lambda_min;  /* floor on the damping (default 1e-10) */
} fe_lm_params;

/* fe_lm_default_params: the defaults above. */
fe_lm_params fe_lm_default_params(void);

/* One row of the iteration table. */
typedef struct fe_lm_iteration {
    int iteration;      /* 1, 2, ... */
    double cost;        /* cost after the iteration */
    double change;      /* cost before minus cost at the trial point */
    double step;        /* |h| (0 when the damped system was singular) */
    double lambda;      /* damping the step was solved with */
    double ratio;       /* gain ratio rho */
    int accepted;       /* 1 when the step was taken */
} fe_lm_iteration;

/* Called after every iteration; a nonzero return stops the solver. */
typedef int fe_lm_report_fn(const fe_lm_iteration *it, void *ctx);

typedef struct fe_lm_result {
    int iterations;     /* iterations made (rows reported); the final
                           test that finds a negligible step is not one */
    int accepted;       /* steps taken */
    int evaluations;    /* model evaluations */
    double initial_cost;
    double cost;        /* at the returned x */
    int stop;           /* an enum fe_lm_stop */
    int extended;       /* steps taken further along their line */
    int accelerated;    /* steps followed by a search along the last two */
} fe_lm_result;

/* fe_lm_work: doubles of workspace fe_lm_solve needs.  With p = ng+nb*nl:
   dense (p+1)^2 + p^2 + 4p; Schur fe_schur_storage(ng, nl, nb) +
   fe_schur_solve_work(ng, nl) + 3p.  0 for an unknown method. */
size_t fe_lm_work(const fe_lm_problem *prob, int method);

/* fe_lm_solve: minimise (1/2) sum w f^2 from x (updated in place: on
   return the best point found).  `params` NULL: defaults.  `report` may be
   NULL.  `result` (if not NULL) receives the counts and costs.  `work`
   holds fe_lm_work(prob, method) doubles; nothing is allocated.
   Returns FE_OK on convergence (ftol, xtol or gtol), FE_ENOCONV (max_iter,
   or the damping grew without bound), FE_ESTOPPED, FE_EINVAL (bad sizes
   or method; params with max_iter < 0, lambda0 not finite and positive,
   a tolerance or lambda_min negative, or lambda_min > lambda0; max_iter
   0 makes no iteration), FE_ETOOFEW (the model emitted no residual), or the
   model's error at the starting point (e.g. FE_ENONFINITE).  A trial
   point where the model fails is treated as a rejected step. */
int fe_lm_solve(const fe_lm_problem *prob, int method,
                const fe_lm_params *params, double *x, double *work,
                fe_lm_report_fn *report, void *report_ctx,
                fe_lm_result *result);

#ifdef __cplusplus
}
#endif

#endif /* FOLDEST_LM_H */
/* Levenberg-Marquardt Declarations ends here */
