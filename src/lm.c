/* SPDX-License-Identifier: MIT */
/* Tangled from literate/lm.org: do not edit; edit the .org and run make tangle. */
/* [[file:../literate/lm.org::Levenberg-Marquardt Includes][Levenberg-Marquardt Includes]] */
#include <float.h>
#include <math.h>
#include <string.h>

#include <lapacke.h>

#include "foldest/error.h"
#include "foldest/lm.h"

/* A dense row with at most this many nonzeros is folded as a sparse row
   from stack arrays; a longer one as a full row. */
enum { FE__LM_SPARSE_MAX = 64 };

/* Damping beyond this means the problem cannot be made to descend. */
#define FE__LM_LAMBDA_MAX 1e16

/* Relative size of the rounding in a computed cost. */
#define FE__LM_COST_NOISE (64 * DBL_EPSILON)

/* A step whose gain ratio exceeds this is tried further along its line,
   at most this many times its length. */
#define FE__LM_LINE_RHO 0.25
#define FE__LM_EXTEND_MAX 64.0
/* Levenberg-Marquardt Includes ends here */
/* [[file:../literate/lm.org::The sink][The sink]] */
struct fe_lm_sink {
    const fe_lm_problem *prob;
    int want_j;
    fe_lsq *dense;          /* dense path, or NULL */
    fe_schur *schur;        /* Schur path, or NULL */
    double *row;            /* dense path: a zeroed row of p doubles */
    double cost;            /* sum of w f^2 (halved by the solver) */
    uint64_t n;
    int rc;                 /* first error */
};

int fe_lm_wants_jacobian(const fe_lm_sink *s)
{
    return s != NULL && s->want_j;
}

/* Fold one row into the dense accumulation: sparse when it is short. */
static int fe__lm_emit_dense(fe_lm_sink *s, double f, double w,
                             const double *jg, size_t block, const double *jl)
{
    const fe_lm_problem *p = s->prob;
    size_t idx[FE__LM_SPARSE_MAX], nnz = 0, k, base;
    double val[FE__LM_SPARSE_MAX];
    int rc;

    base = block != FE_SCHUR_NONE ? p->ng + block * p->nl : 0;
    if (p->ng + (block != FE_SCHUR_NONE ? p->nl : 0) <= FE__LM_SPARSE_MAX) {
        for (k = 0; k < p->ng; k++)
            if (jg[k] != 0.0) {
                idx[nnz] = k;
                val[nnz++] = jg[k];
            }
        if (block != FE_SCHUR_NONE)
            for (k = 0; k < p->nl; k++)
                if (jl[k] != 0.0) {
                    idx[nnz] = base + k;
                    val[nnz++] = jl[k];
                }
        return fe_lsq_add_sparse(s->dense, idx, val, nnz, -f, w);
    }
    if (p->ng > 0)              /* memcpy from NULL is undefined even for 0 bytes */
        memcpy(s->row, jg, p->ng * sizeof *jg);
    if (block != FE_SCHUR_NONE)
        memcpy(s->row + base, jl, p->nl * sizeof *jl);
    rc = fe_lsq_add(s->dense, s->row, -f, w);
    memset(s->row, 0, p->ng * sizeof *jg);
    if (block != FE_SCHUR_NONE)
        memset(s->row + base, 0, p->nl * sizeof *jl);
    return rc;
}

int fe_lm_emit(fe_lm_sink *s, double f, double w, const double *jg,
               size_t block, const double *jl)
{
    const fe_lm_problem *p;
    int rc = FE_OK;

    if (s == NULL)
        return FE_EINVAL;
    p = s->prob;
    if (!isfinite(f) || !isfinite(w))
        rc = FE_ENONFINITE;
    else if (w < 0.0 || (block != FE_SCHUR_NONE && (p->nl == 0 || block >= p->nb)))
        rc = FE_EINVAL;
    else if (s->want_j && ((jg == NULL && p->ng > 0)
                           || (block != FE_SCHUR_NONE && jl == NULL)))
        rc = FE_EINVAL;
    else if (s->want_j && s->dense != NULL)
        rc = fe__lm_emit_dense(s, f, w, jg, block, jl);
    else if (s->want_j)
        rc = fe_schur_add(s->schur, jg, block, jl, -f, w);
    if (rc == FE_OK) {
        s->cost += w * f * f;
        s->n++;
        if (!isfinite(s->cost))
            rc = FE_ENONFINITE;
    }
    if (rc != FE_OK && s->rc == FE_OK)
        s->rc = rc;
    return rc;
}
/* The sink ends here */
/* [[file:../literate/lm.org::Evaluate the model at a point][Evaluate the model at a point]] */
/* Evaluate at x; with want_j, refold the normal equations.  *cost gets
   (1/2) sum w f^2. */
static int fe__lm_eval(fe_lm_sink *s, const double *x, int want_j,
                       double *cost)
{
    int rc;
    s->want_j = want_j;
    s->cost = 0.0;
    s->n = 0;
    s->rc = FE_OK;
    if (want_j) {
        rc = s->dense != NULL ? fe_lsq_reset(s->dense) : fe_schur_reset(s->schur);
        if (rc != FE_OK)
            return rc;
    }
    rc = s->prob->model(x, s, s->prob->ctx);
    if (rc == FE_OK)
        rc = s->rc;
    if (rc == FE_OK && s->n == 0)
        rc = FE_ETOOFEW;
    *cost = 0.5 * s->cost;
    return rc;
}
/* Evaluate the model at a point ends here */
/* [[file:../literate/lm.org::Solve the damped normal equations][Solve the damped normal equations]] */
/* b_k and A_kk for parameter k. */
static void fe__lm_b_diag(const fe_lm_sink *s, size_t k, double *b, double *a)
{
    const fe_lm_problem *p = s->prob;
    if (s->dense != NULL) {
        size_t n = s->dense->p;
        *b = fe_lsq_gram(s->dense, k, n);
        *a = fe_lsq_gram(s->dense, k, k);
    } else if (k < p->ng) {
        *b = fe_lsq_gram(&s->schur->global, k, p->ng);
        *a = fe_lsq_gram(&s->schur->global, k, k);
    } else {
        size_t blk = (k - p->ng) / p->nl, l = (k - p->ng) % p->nl;
        const double *V = s->schur->blk + blk * fe_schur_block_size(p->ng, p->nl);
        *a = V[l * p->nl + l];
        *b = V[p->nl * p->nl + l];
    }
}

static int fe__lm_dense_step(const fe_lsq *a, double lambda, double *F,
                             double *h)
{
    size_t n = a->p, d = n + 1, k, l;
    lapack_int info;

    for (k = 0; k < n; k++) {
        for (l = k; l < n; l++)
            F[k * n + l] = a->g[k * d + l];
        F[k * n + k] *= 1.0 + lambda;
        h[k] = a->g[k * d + n];
        if (!(F[k * n + k] > 0.0))
            return FE_ESINGULAR;
    }
    info = LAPACKE_dpotrf(LAPACK_COL_MAJOR, 'L', (lapack_int)n, F, (lapack_int)n);
    if (info < 0)
        return FE_EINTERNAL;
    if (info > 0)
        return FE_ESINGULAR;
    for (k = 0; k < n; k++)
        if (!(F[k * n + k] * F[k * n + k]
              > FE_LSQ_RANK_TOL * a->g[k * d + k] * (1.0 + lambda)))
            return FE_ESINGULAR;
    info = LAPACKE_dpotrs(LAPACK_COL_MAJOR, 'L', (lapack_int)n, 1, F,
                          (lapack_int)n, h, (lapack_int)n);
    if (info != 0)
        return FE_EINTERNAL;
    for (k = 0; k < n; k++)
        if (!isfinite(h[k]))
            return FE_ESINGULAR;
    return FE_OK;
}
/* Solve the damped normal equations ends here */
/* [[file:../literate/lm.org::Extend a step along its line][Extend a step along its line]] */
/* xt = x + h has cost *trial_cost; try x + t* h with t* the minimum of
   the parabola through the cost at 0 (value cost, slope -slope) and at 1.
   On success xt and *trial_cost describe the new point and t* is
   returned; otherwise xt is x + h again and 1 is returned.  *evaluated
   says whether the model was evaluated (not when t* is 1 or undefined). */
static double fe__lm_extend(fe_lm_sink *s, const double *x, const double *h,
                            double *xt, double cost, double slope,
                            double *trial_cost, int *evaluated)
{
    size_t p = s->prob->ng + s->prob->nb * s->prob->nl, k;
    double c = *trial_cost - cost + slope, t, ext_cost = 0.0;
    int rc;

    *evaluated = 0;
    if (!(c > 0.0) || !(slope > 0.0))
        return 1.0;
    t = fmin(slope / (2.0 * c), FE__LM_EXTEND_MAX);
    if (!(t > 0.0) || t == 1.0)
        return 1.0;
    for (k = 0; k < p; k++)
        xt[k] = x[k] + t * h[k];
    *evaluated = 1;
    rc = fe__lm_eval(s, xt, 0, &ext_cost);
    if (rc == FE_OK && ext_cost < *trial_cost) {
        *trial_cost = ext_cost;
        return t;
    }
    for (k = 0; k < p; k++)
        xt[k] = x[k] + h[k];
    return 1.0;
}
/* Extend a step along its line ends here */
/* [[file:../literate/lm.org::Search along the last two steps][Search along the last two steps]] */
/* x has cost *cost and its normal equations folded; d = x - (the point
   two accepted steps back).  Move x to the best of x + d and x + t* d
   when that lowers the cost, refolding the normal equations there.
   xt is scratch.  Returns FE_OK or the model's error at the new x. */
static int fe__lm_accelerate(fe_lm_sink *s, double *x, const double *d,
                             double *xt, double *cost, fe_lm_result *res)
{
    size_t p = s->prob->ng + s->prob->nb * s->prob->nl, k;
    double slope = 0.0, c1 = 0.0, ct = 0.0, c, t;
    int rc;

    for (k = 0; k < p; k++) {
        double b, a;
        fe__lm_b_diag(s, k, &b, &a);
        slope += b * d[k];
    }
    if (!(slope > 0.0))
        return FE_OK;
    /* The cost at x + d, and the parabola's minimum. */
    for (k = 0; k < p; k++)
        xt[k] = x[k] + d[k];
    rc = fe__lm_eval(s, xt, 0, &c1);
    res->evaluations++;
    if (rc != FE_OK)
        return FE_OK;
    c = c1 - *cost + slope;
    t = c > 0.0 ? fmin(slope / (2.0 * c), FE__LM_EXTEND_MAX) : FE__LM_EXTEND_MAX;
    if (t != 1.0) {
        for (k = 0; k < p; k++)
            xt[k] = x[k] + t * d[k];
        rc = fe__lm_eval(s, xt, 0, &ct);
        res->evaluations++;
        if (rc != FE_OK || !(ct < c1)) {
            t = 1.0;
            ct = c1;
        }
    } else {
        ct = c1;
    }
    if (!(ct < *cost))
        return FE_OK;
    /* Move, and refold the normal equations there. */
    for (k = 0; k < p; k++)
        x[k] += t * d[k];
    rc = fe__lm_eval(s, x, 1, cost);
    res->evaluations++;
    res->accelerated++;
    return rc;
}
/* Search along the last two steps ends here */
/* [[file:../literate/lm.org::Iterate Levenberg-Marquardt][Iterate Levenberg-Marquardt]] */
fe_lm_params fe_lm_default_params(void)
{
    fe_lm_params p = {100, 1e-3, 1e-12, 0.0, 0.0, 1e-12, 1e-10};
    return p;
}

size_t fe_lm_work(const fe_lm_problem *prob, int method)
{
    size_t p;
    if (prob == NULL)
        return 0;
    p = prob->ng + prob->nb * prob->nl;
    if (method == FE_LM_DENSE)
        return fe_lsq_storage(p) + p * p + 4 * p;
    if (method == FE_LM_SCHUR)
        return fe_schur_storage(prob->ng, prob->nl, prob->nb)
               + fe_schur_solve_work(prob->ng, prob->nl) + 3 * p;
    return 0;
}

static double fe__lm_norm(const double *v, size_t n)
{
    double s = 0.0;
    for (size_t k = 0; k < n; k++)
        s += v[k] * v[k];
    return sqrt(s);
}

int fe_lm_solve(const fe_lm_problem *prob, int method,
                const fe_lm_params *params, double *x, double *work,
                fe_lm_report_fn *report, void *report_ctx,
                fe_lm_result *result)
{
    fe_lm_params par = params != NULL ? *params : fe_lm_default_params();
    fe_lm_result res = {0, 0, 0, 0.0, 0.0, FE_LM_RUNNING, 0, 0};
    fe_lm_problem pr;
    fe_lm_sink s;
    fe_lsq dense;
    fe_schur schur;
    double *solve_work, *xt, *h, *xa, cost = 0.0, lambda, nu = 2.0;
    size_t p, k;
    int rc, it, have_xa = 0;

    if (prob == NULL || prob->model == NULL || x == NULL || work == NULL
        || (method != FE_LM_DENSE && method != FE_LM_SCHUR)
        || par.max_iter < 0 || !(par.lambda0 > 0.0) || !isfinite(par.lambda0)
        || !(par.xtol >= 0.0) || !(par.gtol >= 0.0) || !(par.ftol >= 0.0)
        || !(par.rtol >= 0.0) || !(par.lambda_min >= 0.0)
        || !(par.lambda_min <= par.lambda0))
        return FE_EINVAL;
    pr = *prob;
    if (pr.nl == 0)
        pr.nb = 0;
    p = pr.ng + pr.nb * pr.nl;
    if (p == 0)
        return FE_EINVAL;

    /* Lay out the workspace. */
    memset(&s, 0, sizeof s);
    s.prob = &pr;
    if (method == FE_LM_DENSE) {
        rc = fe_lsq_init(&dense, p, work);
        solve_work = work + fe_lsq_storage(p);
        s.row = solve_work + p * p;
        xt = s.row + p;
        memset(s.row, 0, p * sizeof *s.row);
        s.dense = &dense;
    } else {
        rc = fe_schur_init(&schur, pr.ng, pr.nl, pr.nb, work);
        solve_work = work + fe_schur_storage(pr.ng, pr.nl, pr.nb);
        xt = solve_work + fe_schur_solve_work(pr.ng, pr.nl);
        s.schur = &schur;
    }
    h = xt + p;
    xa = h + p;
    if (rc != FE_OK)
        return rc;

    /* The starting point, with its normal equations. */
    rc = fe__lm_eval(&s, x, 1, &cost);
    res.evaluations++;
    res.initial_cost = res.cost = cost;
    if (rc != FE_OK) {
        if (result != NULL)
            *result = res;
        return rc;
    }
    lambda = par.lambda0;

    for (it = 1; res.stop == FE_LM_RUNNING; it++) {
        fe_lm_iteration row = {it, cost, 0.0, 0.0, lambda, 0.0, 0};
        double gmax = 0.0, pred = 0.0, slope = 0.0, trial_cost = 0.0, hn, rho, noise;
        int trial_rc, rtol_pending = 0;

        /* Converged already? */
        for (k = 0; k < p; k++) {
            double b, a;
            fe__lm_b_diag(&s, k, &b, &a);
            gmax = fmax(gmax, fabs(b));
        }
        if (cost <= par.ftol) {
            res.stop = FE_LM_FTOL;
            break;
        }
        if (gmax <= par.gtol) {
            res.stop = FE_LM_GTOL;
            break;
        }
        if (it > par.max_iter) {
            res.stop = FE_LM_MAXITER;
            break;
        }

        /* Solve (A + lambda diag A) h = b. */
        rc = method == FE_LM_DENSE
                 ? fe__lm_dense_step(&dense, lambda, solve_work, h)
                 : fe_schur_solve(&schur, lambda, h, NULL, solve_work);
        if (rc == FE_ESINGULAR) {
            lambda *= nu;
            nu *= 2.0;
        } else if (rc != FE_OK) {
            break;
        } else {
            hn = fe__lm_norm(h, p);
            row.step = hn;
            if (hn <= par.xtol * (fe__lm_norm(x, p) + par.xtol)) {
                res.stop = FE_LM_XTOL;
                break;
            }
            /* Predicted reduction: (1/2) h'(b + lambda diag(A) h); the
               slope of the cost along h is -b'h. */
            for (k = 0; k < p; k++) {
                double b, a;
                fe__lm_b_diag(&s, k, &b, &a);
                pred += h[k] * (b + lambda * a * h[k]);
                slope += h[k] * b;
                xt[k] = x[k] + h[k];
            }
            pred *= 0.5;
            trial_rc = fe__lm_eval(&s, xt, 0, &trial_cost);
            res.evaluations++;
            rho = trial_rc == FE_OK && pred > 0.0 ? (cost - trial_cost) / pred
                                                   : -1.0;
            row.ratio = rho;
            /* A step the model underrates may go further along its line. */
            if (trial_rc == FE_OK && rho > 0.0 && fabs(rho - 1.0) > FE__LM_LINE_RHO) {
                int evaluated;
                double t = fe__lm_extend(&s, x, h, xt, cost, slope, &trial_cost, &evaluated);
                res.evaluations += evaluated;
                row.step *= t;
                res.extended += t != 1.0;
            }
            row.change = trial_rc == FE_OK ? cost - trial_cost : 0.0;
            /* A reduction below the rounding of the cost cannot be judged:
               take the step unless it is measurably worse. */
            noise = FE__LM_COST_NOISE * cost;
            if (trial_rc == FE_OK && pred <= noise && trial_cost <= cost + noise)
                rho = 1.0;
            /* Relative change of the cost negligible, predicted and
                   actual (MINPACK's test): this step is the last. */
            rtol_pending = trial_rc == FE_OK && rho > 0.0
                           && pred <= par.rtol * cost
                           && fabs(cost - trial_cost) <= par.rtol * cost;
            if (trial_rc == FE_OK && rho > 0.0) {
                double t = 2.0 * rho - 1.0;
                int accel = have_xa;
                /* Take the step; remember where it started. */
                for (k = 0; k < p; k++)
                    h[k] = xt[k] - xa[k];
                memcpy(xa, x, p * sizeof *x);
                have_xa = 1;
                memcpy(x, xt, p * sizeof *x);
                rc = fe__lm_eval(&s, x, 1, &cost);
                res.evaluations++;
                if (rc == FE_OK && accel)
                    rc = fe__lm_accelerate(&s, x, h, xt, &cost, &res);
                if (rc != FE_OK)
                    break;
                lambda = fmax(par.lambda_min,
                              lambda * fmax(1.0 / 3.0, 1.0 - t * t * t));
                nu = 2.0;
                row.accepted = 1;
                res.accepted++;
            } else {
                lambda *= nu;
                nu *= 2.0;
            }
        }
        rc = FE_OK;
        row.cost = cost;
        res.cost = cost;
        res.iterations = it;
        if (report != NULL && report(&row, report_ctx) != 0)
            res.stop = FE_LM_STOPPED;
        if (res.stop == FE_LM_RUNNING && rtol_pending)
            res.stop = FE_LM_RTOL;
        if (res.stop == FE_LM_RUNNING && lambda > FE__LM_LAMBDA_MAX)
            res.stop = FE_LM_STUCK;
    }
    res.cost = cost;
    if (result != NULL)
        *result = res;
    if (rc != FE_OK)
        return rc;
    switch (res.stop) {
    case FE_LM_STOPPED:
        return FE_ESTOPPED;
    case FE_LM_MAXITER:
    case FE_LM_STUCK:
        return FE_ENOCONV;
    default:
        return FE_OK;
    }
}
/* Iterate Levenberg-Marquardt ends here */
