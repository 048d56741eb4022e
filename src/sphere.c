/* SPDX-License-Identifier: MIT */
/* Tangled from literate/sphere.org: do not edit; edit the .org and run make tangle. */
/* [[file:../literate/sphere.org::Sphere Fit Includes][Sphere Fit Includes]] */
#include <float.h>
#include <math.h>
#include <string.h>

#include <cblas.h>
#include <lapacke.h>

#include "foldest/error.h"
#include "foldest/sphere.h"

enum { FE__P = FE_SPHERE_MAX_PARAMS };
/* Sphere Fit Includes ends here */
/* [[file:../literate/sphere.org::Name models and refusals][Name models and refusals]] */
static const char *const fe__sphere_models[3] = {"sphere", "axial", "ellipsoid"};

const char *fe_sphere_model_name(int model)
{
    return model >= 0 && model < 3 ? fe__sphere_models[model] : NULL;
}

int fe_sphere_model_parse(const char *name, fe_sphere_model *model)
{
    for (int k = 0; name != NULL && model != NULL && k < 3; k++)
        if (strcmp(name, fe__sphere_models[k]) == 0) {
            *model = (fe_sphere_model)k;
            return FE_OK;
        }
    return FE_EINVAL;
}

const char *fe_sphere_refusal_string(int refusal)
{
    switch (refusal) {
    case FE_SPHERE_ACCEPTED:
        return "accepted";
    case FE_SPHERE_TOO_FEW:
        return "too few samples: no more than the model has parameters";
    case FE_SPHERE_PLANAR:
        return "the samples lie near a plane: rotate the sensor about more than one axis";
    case FE_SPHERE_HEMISPHERE:
        return "the samples cover one side of the sphere only: the centre is not determined";
    case FE_SPHERE_COVERAGE:
        return "the samples cover too little of the sphere";
    case FE_SPHERE_NOT_PD:
        return "the fitted quadric is not an ellipsoid (not positive definite)";
    case FE_SPHERE_DEGENERATE:
        return "a fitted scale is zero";
    case FE_SPHERE_SINGULAR:
        return "the Gauss-Newton matrix is not positive definite: the data do not determine the parameters";
    case FE_SPHERE_NO_CONVERGENCE:
        return "the iteration did not converge";
    case FE_SPHERE_UNBOUNDED:
        return "the best fit grows without bound into a plane: the samples are far from this model (try the ellipsoid)";
    default:
        return "unknown refusal";
    }
}

fe_sphere_options fe_sphere_default_options(void)
{
    fe_sphere_options o;
    memset(&o, 0, sizeof o);
    o.max_iterations = 100;
    o.xtol = 1e-11;
    o.min_planarity = 1e-3;
    o.min_extent = 0.5;
    o.min_coverage = 0.0;
    return o;
}

static int fe__sphere_nparams(int model)
{
    static const int p[3] = {4, 6, 9};
    return model >= 0 && model < 3 ? p[model] : 0;
}
/* Name models and refusals ends here */
/* [[file:../literate/sphere.org::Sphere Fit Private Data][Sphere Fit Private Data]] */
typedef struct fe__sphere_problem {
    int model, p;
    double c[3], sigma;         /* frame: u = (x - c) / sigma */
    double phi[100];            /* (iii): Phi, row-major */
    const double *xyz;          /* (i), (ii): the samples */
    size_t n;
    double *work;               /* (i): J^T (p x n) then r (n) */
    int (*build)(const struct fe__sphere_problem *pr, const double *beta,
                 double *cost, double *H, double *g);
} fe__sphere_problem;

/* Entry e of the six: its row and column. */
static const int fe__sphere_jk[6][2] = {{0,0},{0,1},{0,2},{1,1},{1,2},{2,2}};

static void fe__sphere_unpack(int model, const double *beta, double d[3],
                              double a[6], double P[9 * FE__P])
{
    int p = fe__sphere_nparams(model);
    memset(P, 0, 9 * FE__P * sizeof *P);
    for (int j = 0; j < 3; j++) {
        d[j] = beta[j];
        P[j * FE__P + j] = 1.0;
    }
    memset(a, 0, 6 * sizeof *a);
    if (model == FE_FIT_ELLIPSOID) {
        for (int e = 0; e < 6; e++) {
            a[e] = beta[3 + e];
            P[(3 + e) * FE__P + 3 + e] = 1.0;
        }
        return;
    }
    for (int j = 0; j < 3; j++) {
        int e = j == 0 ? 0 : j == 1 ? 3 : 5;       /* A_jj */
        int k = model == FE_FIT_SPHERE ? 3 : 3 + j;  /* its scale */
        double s = beta[k];
        a[e] = 1.0 / (s * s);
        P[(3 + e) * FE__P + k] = -2.0 / (s * s * s);
    }
    (void)p;
}

static double fe__sphere_aij(const double a[6], int i, int j)
{
    static const int e[3][3] = {{0, 1, 2}, {1, 3, 4}, {2, 4, 5}};
    return a[e[i][j]];
}
/* Sphere Fit Private Data ends here */
/* [[file:../literate/sphere.org::Compute the coefficients and their derivatives][Compute the coefficients and their derivatives]] */
static void fe__sphere_theta(int model, const double *beta, double theta[10],
                             double T[10 * FE__P])
{
    double d[3], a[6], P[9 * FE__P], G[10 * 9], ad[3];
    int p = fe__sphere_nparams(model);

    fe__sphere_unpack(model, beta, d, a, P);
    for (int i = 0; i < 3; i++)
        ad[i] = fe__sphere_aij(a, i, 0) * d[0] + fe__sphere_aij(a, i, 1) * d[1]
              + fe__sphere_aij(a, i, 2) * d[2];
    theta[0] = 1.0 - (d[0] * ad[0] + d[1] * ad[1] + d[2] * ad[2]);
    for (int i = 0; i < 3; i++)
        theta[1 + i] = 2.0 * ad[i];
    for (int e = 0; e < 6; e++)
        theta[4 + e] = (fe__sphere_jk[e][0] == fe__sphere_jk[e][1] ? -1.0 : -2.0) * a[e];
    if (T == NULL)
        return;
    memset(G, 0, sizeof G);
    for (int k = 0; k < 3; k++) {
        G[0 * 9 + k] = -2.0 * ad[k];
        for (int i = 0; i < 3; i++)
            G[(1 + i) * 9 + k] = 2.0 * fe__sphere_aij(a, i, k);
    }
    for (int e = 0; e < 6; e++) {
        int j = fe__sphere_jk[e][0], k = fe__sphere_jk[e][1];
        G[0 * 9 + 3 + e] = -(j == k ? 1.0 : 2.0) * d[j] * d[k];
        for (int i = 0; i < 3; i++)
            G[(1 + i) * 9 + 3 + e] = j == k ? 2.0 * (i == j) * d[j]
                                            : 2.0 * ((i == j) * d[k] + (i == k) * d[j]);
        G[(4 + e) * 9 + 3 + e] = j == k ? -1.0 : -2.0;
    }
    for (int r = 0; r < 10; r++)
        for (int c = 0; c < p; c++) {
            double s = 0.0;
            for (int m = 0; m < 9; m++)
                s += G[r * 9 + m] * P[m * FE__P + c];
            T[r * FE__P + c] = s;
        }
}
/* Compute the coefficients and their derivatives ends here */
/* [[file:../literate/sphere.org::Build the normal equations from the moments][Build the normal equations from the moments]] */
static int fe__sphere_build_moments(const fe__sphere_problem *pr,
                                    const double *beta, double *cost,
                                    double *H, double *g)
{
    double theta[10], T[10 * FE__P], v[10], W[10 * FE__P], s;
    int p = pr->p;

    fe__sphere_theta(pr->model, beta, theta, H != NULL ? T : NULL);
    for (int r = 0; r < 10; r++) {
        s = 0.0;
        for (int c = 0; c < 10; c++)
            s += pr->phi[r * 10 + c] * theta[c];
        v[r] = s;
    }
    s = 0.0;
    for (int r = 0; r < 10; r++)
        s += theta[r] * v[r];
    *cost = s;
    if (H == NULL)
        return FE_OK;
    for (int k = 0; k < p; k++) {
        s = 0.0;
        for (int r = 0; r < 10; r++)
            s += T[r * FE__P + k] * v[r];
        g[k] = s;
    }
    for (int r = 0; r < 10; r++)
        for (int k = 0; k < p; k++) {
            s = 0.0;
            for (int c = 0; c < 10; c++)
                s += pr->phi[r * 10 + c] * T[c * FE__P + k];
            W[r * FE__P + k] = s;
        }
    for (int k = 0; k < p; k++)
        for (int l = k; l < p; l++) {
            s = 0.0;
            for (int r = 0; r < 10; r++)
                s += T[r * FE__P + k] * W[r * FE__P + l];
            H[k * p + l] = H[l * p + k] = s;
        }
    return FE_OK;
}
/* Build the normal equations from the moments ends here */
/* [[file:../literate/sphere.org::Compute one sample's residual and Jacobian][Compute one sample's residual and Jacobian]] */
static double fe__sphere_point(const fe__sphere_problem *pr, const double *x,
                               const double d[3], const double a[6],
                               const double *P, double *J)
{
    double w[3], aw[3], q = 0.0, dr[9];
    for (int j = 0; j < 3; j++)
        w[j] = (x[j] - pr->c[j]) / pr->sigma - d[j];
    for (int i = 0; i < 3; i++) {
        aw[i] = fe__sphere_aij(a, i, 0) * w[0] + fe__sphere_aij(a, i, 1) * w[1]
              + fe__sphere_aij(a, i, 2) * w[2];
        q += w[i] * aw[i];
    }
    if (J != NULL) {
        for (int i = 0; i < 3; i++)
            dr[i] = 2.0 * aw[i];
        for (int e = 0; e < 6; e++) {
            int j = fe__sphere_jk[e][0], k = fe__sphere_jk[e][1];
            dr[3 + e] = -(j == k ? 1.0 : 2.0) * w[j] * w[k];
        }
        for (int c = 0; c < pr->p; c++) {
            double s = 0.0;
            for (int m = 0; m < 9; m++)
                s += dr[m] * P[m * FE__P + c];
            J[c] = s;
        }
    }
    return 1.0 - q;
}
/* Compute one sample's residual and Jacobian ends here */
/* [[file:../literate/sphere.org::Accumulate the normal equations over stored samples][Accumulate the normal equations over stored samples]] */
static int fe__sphere_build_stored(const fe__sphere_problem *pr,
                                   const double *beta, double *cost,
                                   double *H, double *g)
{
    double d[3], a[6], P[9 * FE__P], J[FE__P] = {0}, s = 0.0;
    int p = pr->p;

    fe__sphere_unpack(pr->model, beta, d, a, P);
    if (H != NULL) {
        memset(H, 0, (size_t)(p * p) * sizeof *H);
        memset(g, 0, (size_t)p * sizeof *g);
    }
    for (size_t i = 0; i < pr->n; i++) {
        double r = fe__sphere_point(pr, pr->xyz + 3 * i, d, a, P,
                                    H != NULL ? J : NULL);
        s += r * r;
        if (H == NULL)
            continue;
        for (int k = 0; k < p; k++) {
            g[k] += J[k] * r;
            for (int l = k; l < p; l++)
                H[k * p + l] += J[k] * J[l];
        }
    }
    if (H != NULL)
        for (int k = 0; k < p; k++)
            for (int l = 0; l < k; l++)
                H[k * p + l] = H[l * p + k];
    *cost = s;
    return FE_OK;
}
/* Accumulate the normal equations over stored samples ends here */
/* [[file:../literate/sphere.org::Materialise the Jacobian and form the normal equations][Materialise the Jacobian and form the normal equations]] */
static int fe__sphere_build_naive(const fe__sphere_problem *pr,
                                  const double *beta, double *cost,
                                  double *H, double *g)
{
    double d[3], a[6], P[9 * FE__P];
    int p = pr->p;
    double *jt = pr->work, *r = pr->work + (size_t)p * pr->n;

    fe__sphere_unpack(pr->model, beta, d, a, P);
    for (size_t i = 0; i < pr->n; i++)
        r[i] = fe__sphere_point(pr, pr->xyz + 3 * i, d, a, P, jt + (size_t)p * i);
    *cost = cblas_ddot((int)pr->n, r, 1, r, 1);
    if (H == NULL)
        return FE_OK;
    cblas_dsyrk(CblasColMajor, CblasUpper, CblasNoTrans, p, (int)pr->n, 1.0,
                jt, p, 0.0, H, p);
    for (int k = 0; k < p; k++)
        for (int l = 0; l < k; l++)
            H[l * p + k] = H[k * p + l];     /* lower from upper */
    cblas_dgemv(CblasColMajor, CblasNoTrans, p, (int)pr->n, 1.0, jt, p, r, 1,
                0.0, g, 1);
    return FE_OK;
}
/* Materialise the Jacobian and form the normal equations ends here */
/* [[file:../literate/sphere.org::Solve a symmetric positive definite system][Solve a symmetric positive definite system]] */
/* A x = b for SPD A (n x n, overwritten), b overwritten by x (nrhs
   columns, column-major).  FE_ENOTPD when A is not positive definite. */
static int fe__sphere_posv(int n, int nrhs, double *A, double *b)
{
    lapack_int info = LAPACKE_dposv(LAPACK_COL_MAJOR, 'U', n, nrhs, A, n, b, n);
    if (info > 0)
        return FE_ENOTPD;
    return info < 0 ? FE_EINTERNAL : FE_OK;
}
/* Solve a symmetric positive definite system ends here */
/* [[file:../literate/sphere.org::Iterate Gauss-Newton with Levenberg-Marquardt damping][Iterate Gauss-Newton with Levenberg-Marquardt damping]] */
/* The decrease of S the linear model predicts for `step`:
   -2 g.step - step' H step (H: upper triangle used). */
static double fe__sphere_predicted(int p, const double *g, const double *H,
                                   const double *step)
{
    double gs = 0.0, hs = 0.0;
    for (int k = 0; k < p; k++) {
        gs += g[k] * step[k];
        hs += H[k * p + k] * step[k] * step[k];
        for (int l = k + 1; l < p; l++)
            hs += 2.0 * H[k * p + l] * step[k] * step[l];
    }
    return -2.0 * gs - hs;
}

static int fe__sphere_iterate(const fe__sphere_problem *pr,
                              const fe_sphere_options *opt, double *beta,
                              double *cost, double *H, int *iterations,
                              int *refusal)
{
    int p = pr->p;
    double g[FE__P], A[FE__P * FE__P], step[FE__P], trial[FE__P];
    double Ht[FE__P * FE__P], gt[FE__P], St, lambda = 0.0;
    int rc;

    rc = pr->build(pr, beta, cost, H, g);
    if (rc != FE_OK)
        return rc;
    for (int it = 1; it <= opt->max_iterations; it++) {
        double smax = 0.0, bmax = 0.0;
        int accepted, converged;
        fe_sphere_iteration trace;

        memcpy(A, H, (size_t)(p * p) * sizeof *A);
        for (int k = 0; k < p; k++) {
            A[k * p + k] += lambda * H[k * p + k];
            step[k] = -g[k];
        }
        rc = fe__sphere_posv(p, 1, A, step);
        if (rc != FE_OK) {
            *refusal = rc == FE_ENOTPD ? FE_SPHERE_SINGULAR : *refusal;
            *iterations = it;
            return rc;
        }
        for (int k = 0; k < p; k++) {
            trial[k] = beta[k] + step[k];
            smax = fmax(smax, fabs(step[k]));
            bmax = fmax(bmax, fabs(beta[k]));
        }
        rc = pr->build(pr, trial, &St, Ht, gt);
        if (rc != FE_OK)
            return rc;
        accepted = isfinite(St) && St <= *cost * (1.0 + 1e-10);
        converged = lambda <= 1e-2
                    && (smax <= opt->xtol * (1.0 + bmax)
                        || fe__sphere_predicted(p, g, H, step)
                           <= 16.0 * DBL_EPSILON * fmax((double)pr->n, 1.0));
        if (accepted) {
            memcpy(beta, trial, (size_t)p * sizeof *beta);
            memcpy(H, Ht, (size_t)(p * p) * sizeof *H);
            memcpy(g, gt, (size_t)p * sizeof *g);
            *cost = St;
        }
        *iterations = it;
        if (opt->trace != NULL) {
            trace.iteration = it;
            trace.cost = *cost;
            trace.trial_cost = St;
            trace.lambda = lambda;
            trace.step = smax;
            trace.accepted = accepted;
            trace.nparams = p;
            trace.params = beta;
            if (opt->trace(&trace, opt->trace_ctx) != 0)
                return FE_ESTOPPED;
        }
        if (converged)
            return FE_OK;
        if (bmax > 1e4) {       /* radius or centre 10^4 box sizes away */
            *refusal = FE_SPHERE_UNBOUNDED;
            return FE_EUNDETERMINED;
        }
        if (accepted)
            lambda = lambda > 1e-6 ? lambda / 10.0 : 0.0;
        else
            lambda = lambda == 0.0 ? 1e-4 : 10.0 * lambda;
        if (lambda > 1e16)
            break;
    }
    *refusal = FE_SPHERE_NO_CONVERGENCE;
    return FE_ENOCONV;
}
/* Iterate Gauss-Newton with Levenberg-Marquardt damping ends here */
/* [[file:../literate/sphere.org::Compute the eigenvalues of a symmetric 3x3 matrix][Compute the eigenvalues of a symmetric 3x3 matrix]] */
/* Eigenvalues (ascending) and, if V is not NULL, eigenvectors (columns
   of the column-major V) of the symmetric S (row-major 3x3). */
static int fe__sphere_eig3(const double S[9], double w[3], double *V)
{
    double a[9], work[64];
    lapack_int info;
    memcpy(a, S, sizeof a);
    info = LAPACKE_dsyev_work(LAPACK_COL_MAJOR, V != NULL ? 'V' : 'N', 'U', 3,
                              a, 3, w, work, 64);
    if (info != 0)
        return info < 0 ? FE_EINTERNAL : FE_ENOCONV;
    if (V != NULL)
        memcpy(V, a, sizeof a);
    return FE_OK;
}
/* Compute the eigenvalues of a symmetric 3x3 matrix ends here */
/* [[file:../literate/sphere.org::Set up the frame and check the data][Set up the frame and check the data]] */
/* The moments mu of q in the frame u = (x - c) / sigma, and Phi from
   them: entry (k, l) is the moment of alpha_k + alpha_l. */
static int fe__sphere_phi(const fe_quadric *q, const double c[3], double sigma,
                          double phi[100], double mu[FE_QUADRIC_MOMENTS])
{
    fe_quadric moved = *q;
    int rc = fe_quadric_recentre(&moved, c);
    if (rc != FE_OK)
        return rc;
    for (int k = 0; k < FE_QUADRIC_MOMENTS; k++) {
        int e[3];
        fe_quadric_exponents(k, e);
        mu[k] = moved.m[k] / pow(sigma, e[0] + e[1] + e[2]);
    }
    for (int k = 0; k < 10; k++)
        for (int l = 0; l < 10; l++) {
            int ek[3], el[3];
            fe_quadric_exponents(k, ek);
            fe_quadric_exponents(l, el);
            phi[k * 10 + l] = mu[fe_quadric_index(ek[0] + el[0], ek[1] + el[1], ek[2] + el[2])];
        }
    return FE_OK;
}

/* Fill the frame of pr from q, the measured figures of fit, and the
   initial beta; refuse data that cannot determine the model. */
static int fe__sphere_setup(const fe_quadric *q, fe_sphere_model model,
                            const fe_sphere_options *opt,
                            fe__sphere_problem *pr, fe_sphere_fit *fit,
                            double *beta)
{
    double h[3], mu[FE_QUADRIC_MOMENTS], C[9], w[3], n;
    int rc;

    memset(fit, 0, sizeof *fit);
    memset(pr, 0, sizeof *pr);
    if (model < FE_FIT_SPHERE || model > FE_FIT_ELLIPSOID)
        return FE_EINVAL;
    fit->model = model;
    fit->nparams = pr->p = fe__sphere_nparams(model);
    pr->model = model;
    fit->n = fe_quadric_count(q);
    fit->coverage = fe_quadric_coverage(q);
    n = q->m[0];
    if (n <= pr->p) {
        fit->refusal = FE_SPHERE_TOO_FEW;
        return FE_ETOOFEW;
    }
    pr->sigma = 0.0;
    for (int j = 0; j < 3; j++) {
        pr->c[j] = 0.5 * (q->lo[j] + q->hi[j]);
        h[j] = 0.5 * (q->hi[j] - q->lo[j]);
        pr->sigma += h[j] / 3.0;
    }
    memcpy(fit->frame_centre, pr->c, sizeof pr->c);
    fit->frame_scale = pr->sigma;
    if (!(h[0] > 0.0 && h[1] > 0.0 && h[2] > 0.0)) {
        fit->refusal = FE_SPHERE_PLANAR;
        return FE_EUNDETERMINED;
    }
    /* The frame divides moments of degree 4 by sigma^4: a spread so small
       (below about 1e-77) that sigma^4 is not a normal double cannot be
       represented there. */
    if (!(pow(pr->sigma, 4) >= DBL_MIN)) {
        fit->refusal = FE_SPHERE_DEGENERATE;
        return FE_EUNDETERMINED;
    }
    rc = fe__sphere_phi(q, pr->c, pr->sigma, pr->phi, mu);
    if (rc != FE_OK)
        return rc;
    /* Planarity: covariance eigenvalues. */
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            C[i * 3 + j] = pr->phi[(1 + i) * 10 + 1 + j] / n
                         - mu[1 + i] * mu[1 + j] / (n * n);
    rc = fe__sphere_eig3(C, w, NULL);
    if (rc != FE_OK)
        return rc;
    fit->planarity = w[2] > 0.0 ? fmax(w[0], 0.0) / w[2] : 0.0;
    if (fit->planarity < opt->min_planarity) {
        fit->refusal = FE_SPHERE_PLANAR;
        return FE_EUNDETERMINED;
    }
    if (fit->coverage < opt->min_coverage) {
        fit->refusal = FE_SPHERE_COVERAGE;
        return FE_EUNDETERMINED;
    }
    /* The initial guess: the box. */
    memset(beta, 0, FE__P * sizeof *beta);
    if (model == FE_FIT_SPHERE) {
        beta[3] = 1.0;
    } else if (model == FE_FIT_AXIAL) {
        for (int j = 0; j < 3; j++)
            beta[3 + j] = h[j] / pr->sigma;
    } else {
        beta[3] = pr->sigma * pr->sigma / (h[0] * h[0]);
        beta[6] = pr->sigma * pr->sigma / (h[1] * h[1]);
        beta[8] = pr->sigma * pr->sigma / (h[2] * h[2]);
    }
    return FE_OK;
}
/* Set up the frame and check the data ends here */
/* [[file:../literate/sphere.org::Carry the errors to the matrix][Carry the errors to the matrix]] */
static int fe__sphere_eig3(const double S[9], double w[3], double *V);

/* M = the symmetric square root of the matrix with entries a[6]. */
static int fe__sphere_sqrtm(const double a[6], double M[9])
{
    static const int e[3][3] = {{0, 1, 2}, {1, 3, 4}, {2, 4, 5}};
    double S[9], w[3], V[9];
    int rc;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            S[i * 3 + j] = a[e[i][j]];
    rc = fe__sphere_eig3(S, w, V);
    if (rc != FE_OK)
        return rc;
    if (!(w[0] > 0.0))
        return FE_ENOTPD;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double m = 0.0;
            for (int k = 0; k < 3; k++)
                m += V[k * 3 + i] * sqrt(w[k]) * V[k * 3 + j];
            M[i * 3 + j] = m;
        }
    return FE_OK;
}

static int fe__sphere_matrix_se(fe_sphere_fit *fit)
{
    int p = fit->nparams;
    memset(fit->matrix_se, 0, sizeof fit->matrix_se);
    if (fit->model != FE_FIT_ELLIPSOID) {
        for (int j = 0; j < 3; j++) {
            int k = fit->model == FE_FIT_SPHERE ? 3 : 3 + j;
            double s = fit->params[k];
            fit->matrix_se[4 * j] = sqrt(fit->cov[k * p + k]) / (s * s);
        }
        return FE_OK;
    }
    {
        double D[9][6], h = 0.0;
        for (int e = 0; e < 6; e++)
            h = fmax(h, fabs(fit->params[3 + e]));
        h *= 1e-6;
        /* Derivatives of the nine entries by the six parameters. */
        for (int e = 0; e < 6; e++) {
            double a[6], Mp[9], Mm[9];
            int rc;
            memcpy(a, fit->params + 3, sizeof a);
            a[e] += h;
            rc = fe__sphere_sqrtm(a, Mp);
            a[e] -= 2.0 * h;
            if (rc == FE_OK)
                rc = fe__sphere_sqrtm(a, Mm);
            if (rc != FE_OK)
                return rc;
            for (int k = 0; k < 9; k++)
                D[k][e] = (Mp[k] - Mm[k]) / (2.0 * h);
        }
        for (int k = 0; k < 9; k++) {
            double v = 0.0;
            for (int e = 0; e < 6; e++)
                for (int f = 0; f < 6; f++)
                    v += D[k][e] * fit->cov[(3 + e) * p + 3 + f] * D[k][f];
            fit->matrix_se[k] = sqrt(fmax(v, 0.0));
        }
    }
    return FE_OK;
}
/* Carry the errors to the matrix ends here */
/* [[file:../literate/sphere.org::Express the fit in the sensor's units][Express the fit in the sensor's units]] */
static int fe__sphere_finish(const fe__sphere_problem *pr, const fe_quadric *q,
                             const fe_sphere_options *opt, const double *beta,
                             double cost, const double *H, fe_sphere_fit *fit)
{
    double d[3], a[6], P[9 * FE__P], S[9], w[3], V[9], Hi[FE__P * FE__P];
    double scale[FE__P], s2, sigma = pr->sigma, worst = INFINITY;
    int p = pr->p, rc;

    fe__sphere_unpack(pr->model, beta, d, a, P);
    for (int j = 0; j < 3; j++) {
        fit->offset[j] = pr->c[j] + sigma * d[j];
        fit->params[j] = fit->offset[j];
        scale[j] = sigma;
    }
    if (pr->model == FE_FIT_ELLIPSOID) {
        for (int e = 0; e < 6; e++) {
            fit->params[3 + e] = a[e] / (sigma * sigma);
            scale[3 + e] = 1.0 / (sigma * sigma);
        }
    } else {
        for (int k = 3; k < p; k++) {
            if (beta[k] == 0.0) {
                fit->refusal = FE_SPHERE_DEGENERATE;
                return FE_ENOTPD;
            }
            fit->params[k] = sigma * fabs(beta[k]);
            scale[k] = beta[k] < 0.0 ? -sigma : sigma;
        }
    }
    cost = fmax(cost, 0.0);     /* theta' Phi theta can round below 0 */
    fit->rss = cost;
    fit->rms_percent = 50.0 * sqrt(cost / q->m[0]);
    /* The shape: eigenvalues of A. */
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            S[i * 3 + j] = fe__sphere_aij(a, i, j);
    rc = fe__sphere_eig3(S, w, V);
    if (rc != FE_OK)
        return rc;
    if (!(w[0] > 0.0)) {
        fit->refusal = FE_SPHERE_NOT_PD;
        return FE_ENOTPD;
    }
    fit->radius = 1.0;
    for (int k = 0; k < 3; k++) {
        fit->axes[k] = sigma / sqrt(w[2 - k]);
        fit->radius *= fit->axes[k];
    }
    fit->radius = cbrt(fit->radius);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double m = 0.0, inv = 0.0;
            for (int k = 0; k < 3; k++) {
                m += V[k * 3 + i] * sqrt(w[k]) * V[k * 3 + j];
                inv += V[k * 3 + i] / w[k] * V[k * 3 + j];
            }
            fit->matrix[i * 3 + j] = m / sigma;
            if (i == j) {
                double hj = sigma * sqrt(inv);
                fit->extent_lo[j] = (q->lo[j] - fit->offset[j]) / hj;
                fit->extent_hi[j] = (q->hi[j] - fit->offset[j]) / hj;
                worst = fmin(worst, fmin(fit->extent_hi[j], -fit->extent_lo[j]));
            }
        }
    /* Covariance of the natural parameters. */
    memcpy(Hi, H, (size_t)(p * p) * sizeof *Hi);
    {
        double inv[FE__P * FE__P];
        memset(inv, 0, sizeof inv);
        for (int k = 0; k < p; k++)
            inv[k * p + k] = 1.0;
        rc = fe__sphere_posv(p, p, Hi, inv);
        if (rc != FE_OK) {
            fit->refusal = rc == FE_ENOTPD ? FE_SPHERE_SINGULAR : fit->refusal;
            return rc;
        }
        s2 = cost / (q->m[0] - p);
        for (int k = 0; k < p; k++)
            for (int l = 0; l < p; l++)
                fit->cov[k * p + l] = s2 * scale[k] * scale[l] * inv[k * p + l];
        for (int k = 0; k < p; k++)
            fit->se[k] = fit->se_iid[k] = sqrt(fit->cov[k * p + k]);
    }
    rc = fe__sphere_matrix_se(fit);
    if (rc != FE_OK)
        return rc;
    if (worst < opt->min_extent) {
        fit->refusal = FE_SPHERE_HEMISPHERE;
        return FE_EUNDETERMINED;
    }
    return FE_OK;
}
/* Express the fit in the sensor's units ends here */
/* [[file:../literate/sphere.org::Fit the algebraic sphere][Fit the algebraic sphere]] */
static int fe__sphere_algebraic(const fe__sphere_problem *pr,
                                const fe_quadric *q,
                                const fe_sphere_options *opt,
                                fe_sphere_fit *fit)
{
    static const int sq[3] = {4, 7, 9};
    double N[16], Ni[16], gam[4], h[4], tt = 0.0, rss, s2, d[3], ss;
    double beta[FE__P], H[FE__P * FE__P], g[FE__P], cost, D[2][4];
    double sigma = pr->sigma, n = q->m[0];
    fe_sphere_options loose = *opt;     /* extents checked below */
    int rc;

    loose.min_extent = 0.0;
    for (int k = 0; k < 4; k++) {
        h[k] = 0.0;
        for (int l = 0; l < 4; l++)
            N[k * 4 + l] = pr->phi[k * 10 + l];
        for (int c = 0; c < 3; c++)
            h[k] += pr->phi[k * 10 + sq[c]];
        gam[k] = h[k];
    }
    for (int c = 0; c < 3; c++)
        for (int e = 0; e < 3; e++)
            tt += pr->phi[sq[c] * 10 + sq[e]];
    memcpy(Ni, N, sizeof Ni);
    rc = fe__sphere_posv(4, 1, Ni, gam);
    if (rc != FE_OK) {
        fit->refusal = rc == FE_ENOTPD ? FE_SPHERE_SINGULAR : fit->refusal;
        return rc;
    }
    for (int j = 0; j < 3; j++)
        d[j] = 0.5 * gam[1 + j];
    ss = gam[0] + d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    if (!(ss > 0.0)) {
        fit->refusal = FE_SPHERE_DEGENERATE;
        return FE_ENOTPD;
    }
    memset(beta, 0, sizeof beta);
    memcpy(beta, d, sizeof d);
    beta[3] = sqrt(ss);
    rc = pr->build(pr, beta, &cost, H, g);
    if (rc != FE_OK)
        return rc;
    fit->refusal = FE_SPHERE_ACCEPTED;
    fit->algebraic = 1;
    rc = fe__sphere_finish(pr, q, &loose, beta, cost, H, fit);
    if (rc != FE_OK)
        return rc;
    /* One-sided data: along some axis the samples do not reach both sides
       of the centre by min_extent of the box's half-width. */
    for (int j = 0; j < 3; j++) {
        double hb = 0.5 * (q->hi[j] - q->lo[j]);
        if (fmin(q->hi[j] - fit->offset[j], fit->offset[j] - q->lo[j])
            < opt->min_extent * hb) {
            fit->refusal = FE_SPHERE_HEMISPHERE;
            rc = FE_EUNDETERMINED;
        }
    }
    /* The linear estimator's covariance, carried to (b, s) in the sensor's
       units: b_j = c_j + sigma gam_j / 2, s = sigma sqrt(gam_0 + |d|^2). */
    rss = fmax(tt - (gam[0] * h[0] + gam[1] * h[1] + gam[2] * h[2] + gam[3] * h[3]), 0.0);
    s2 = rss / (n - 4.0);
    memcpy(Ni, N, sizeof Ni);
    {
        double inv[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
        int rc2 = fe__sphere_posv(4, 4, Ni, inv);
        if (rc2 != FE_OK)
            return rc2;
        for (int k = 0; k < 4; k++)
            for (int l = 0; l < 4; l++)
                Ni[k * 4 + l] = s2 * inv[k * 4 + l];
    }
    memset(fit->cov, 0, sizeof fit->cov);
    for (int a = 0; a < 4; a++)         /* D[0], D[1]: derivatives of */
        for (int b = 0; b < 4; b++) {   /* parameters a, b by gam */
            double ca = 0.0;
            for (int k = 0; k < 4; k++) {
                D[0][k] = a < 3 ? (k == a + 1 ? 0.5 * sigma : 0.0)
                                : sigma * (k == 0 ? 0.5 : 0.5 * d[k - 1]) / beta[3];
                D[1][k] = b < 3 ? (k == b + 1 ? 0.5 * sigma : 0.0)
                                : sigma * (k == 0 ? 0.5 : 0.5 * d[k - 1]) / beta[3];
            }
            for (int k = 0; k < 4; k++)
                for (int l = 0; l < 4; l++)
                    ca += D[0][k] * Ni[k * 4 + l] * D[1][l];
            fit->cov[a * 4 + b] = ca;
        }
    for (int a = 0; a < 4; a++)
        fit->se[a] = sqrt(fit->cov[a * 4 + a]);
    return rc;
}
/* Fit the algebraic sphere ends here */
/* [[file:../literate/sphere.org::Fit from moments or from stored samples][Fit from moments or from stored samples]] */
static int fe__sphere_run(const fe_quadric *q, fe_sphere_model model,
                          const fe_sphere_options *opt, fe__sphere_problem *pr,
                          fe_sphere_fit *fit, int stored);

/* After a failed fit of an ellipsoid: if the sphere fit says the data are
   one-sided, say that instead. */
static int fe__sphere_diagnose(const fe_quadric *q, fe_sphere_model model,
                               const fe_sphere_options *opt,
                               fe_sphere_fit *fit, int rc)
{
    fe_sphere_fit sphere;
    fe__sphere_problem pr;
    if (model == FE_FIT_SPHERE)
        return rc;
    if (fe__sphere_run(q, FE_FIT_SPHERE, opt, &pr, &sphere, 0) == FE_EUNDETERMINED
        && sphere.refusal == FE_SPHERE_HEMISPHERE) {
        memcpy(fit->extent_lo, sphere.extent_lo, sizeof fit->extent_lo);
        memcpy(fit->extent_hi, sphere.extent_hi, sizeof fit->extent_hi);
        fit->refusal = FE_SPHERE_HEMISPHERE;
        return FE_EUNDETERMINED;
    }
    return rc;
}

static int fe__sphere_run(const fe_quadric *q, fe_sphere_model model,
                          const fe_sphere_options *opt, fe__sphere_problem *pr,
                          fe_sphere_fit *fit, int stored)
{
    fe_sphere_options defaults = fe_sphere_default_options();
    fe__sphere_problem setup;
    double beta[FE__P], H[FE__P * FE__P], cost;
    int rc;

    if (opt == NULL)
        opt = &defaults;
    rc = fe__sphere_setup(q, model, opt, &setup, fit, beta);
    if (rc != FE_OK)
        return rc;
    if (stored) {               /* keep the samples, take the frame */
        setup.xyz = pr->xyz;
        setup.n = pr->n;
        setup.work = pr->work;
        setup.build = pr->build;
    } else {
        setup.n = (size_t)fe_quadric_count(q);  /* for the convergence test only */
        setup.build = fe__sphere_build_moments;
    }
    *pr = setup;
    rc = fe__sphere_iterate(pr, opt, beta, &cost, H, &fit->iterations,
                            &fit->refusal);
    if (rc == FE_EUNDETERMINED && model == FE_FIT_SPHERE
        && fit->refusal == FE_SPHERE_UNBOUNDED)
        return fe__sphere_algebraic(pr, q, opt, fit);
    if (rc == FE_ENOCONV || rc == FE_EUNDETERMINED || rc == FE_ENOTPD)
        return fe__sphere_diagnose(q, model, opt, fit, rc);
    if (rc != FE_OK)
        return rc;
    return fe__sphere_finish(pr, q, opt, beta, cost, H, fit);
}

int fe_sphere_fit_moments(const fe_quadric *q, fe_sphere_model model,
                          const fe_sphere_options *opt, fe_sphere_fit *fit)
{
    fe__sphere_problem pr;
    if (q == NULL || fit == NULL)
        return FE_EINVAL;
    return fe__sphere_run(q, model, opt, &pr, fit, 0);
}

int fe_sphere_fit_algebraic(const fe_quadric *q, const fe_sphere_options *opt,
                            fe_sphere_fit *fit)
{
    fe_sphere_options defaults = fe_sphere_default_options();
    fe__sphere_problem pr;
    double beta[FE__P];
    int rc;
    if (q == NULL || fit == NULL)
        return FE_EINVAL;
    if (opt == NULL)
        opt = &defaults;
    rc = fe__sphere_setup(q, FE_FIT_SPHERE, opt, &pr, fit, beta);
    if (rc != FE_OK)
        return rc;
    pr.build = fe__sphere_build_moments;
    return fe__sphere_algebraic(&pr, q, opt, fit);
}

static int fe__sphere_fit_samples(const double *xyz, size_t n,
                                  fe_sphere_model model,
                                  const fe_sphere_options *opt, double *work,
                                  fe_sphere_fit *fit)
{
    fe_quadric q = FE_QUADRIC_EMPTY;
    fe__sphere_problem pr;
    int rc = fe_quadric_add_many(&q, xyz, n, NULL);
    if (rc != FE_OK)
        return rc;
    memset(&pr, 0, sizeof pr);
    pr.xyz = xyz;
    pr.n = n;
    pr.work = work;
    pr.build = work != NULL ? fe__sphere_build_naive : fe__sphere_build_stored;
    return fe__sphere_run(&q, model, opt, &pr, fit, 1);
}

int fe_sphere_fit_stored(const double *xyz, size_t n, fe_sphere_model model,
                         const fe_sphere_options *opt, fe_sphere_fit *fit)
{
    if ((xyz == NULL && n > 0) || fit == NULL)
        return FE_EINVAL;
    return fe__sphere_fit_samples(xyz, n, model, opt, NULL, fit);
}

size_t fe_sphere_naive_workspace(size_t n, fe_sphere_model model)
{
    return n * (size_t)(fe__sphere_nparams(model) + 1);
}

int fe_sphere_fit_naive(const double *xyz, size_t n, fe_sphere_model model,
                        const fe_sphere_options *opt, double *work,
                        size_t work_len, fe_sphere_fit *fit)
{
    if ((xyz == NULL && n > 0) || fit == NULL || work == NULL
        || fe__sphere_nparams(model) == 0)
        return FE_EINVAL;
    if (work_len < fe_sphere_naive_workspace(n, model) || n > 2147483647u)
        return FE_ESIZE;
    return fe__sphere_fit_samples(xyz, n, model, opt, work, fit);
}
/* Fit from moments or from stored samples ends here */
/* [[file:../literate/sphere.org::Evaluate and apply a calibration][Evaluate and apply a calibration]] */
int fe_sphere_cost(const fe_quadric *q, const fe_sphere_fit *fit, double *rss)
{
    double beta[FE__P], theta[10], s = 0.0;
    if (q == NULL || fit == NULL || rss == NULL)
        return FE_EINVAL;
    /* A_x = M^T M, as an ellipsoid in q's reference frame. */
    for (int j = 0; j < 3; j++)
        beta[j] = fit->offset[j] - q->ref[j];
    for (int e = 0; e < 6; e++) {
        int j = fe__sphere_jk[e][0], k = fe__sphere_jk[e][1];
        double v = 0.0;
        for (int m = 0; m < 3; m++)
            v += fit->matrix[m * 3 + j] * fit->matrix[m * 3 + k];
        beta[3 + e] = v;
    }
    fe__sphere_theta(FE_FIT_ELLIPSOID, beta, theta, NULL);
    for (int k = 0; k < 10; k++)
        for (int l = 0; l < 10; l++) {
            int ek[3], el[3];
            fe_quadric_exponents(k, ek);
            fe_quadric_exponents(l, el);
            s += theta[k] * theta[l]
               * q->m[fe_quadric_index(ek[0] + el[0], ek[1] + el[1], ek[2] + el[2])];
        }
    *rss = s;
    return FE_OK;
}

void fe_sphere_apply(const fe_sphere_fit *fit, const double x[3], double y[3])
{
    double u[3], out[3];
    for (int j = 0; j < 3; j++)
        u[j] = x[j] - fit->offset[j];
    for (int i = 0; i < 3; i++)
        out[i] = fit->matrix[i * 3] * u[0] + fit->matrix[i * 3 + 1] * u[1]
               + fit->matrix[i * 3 + 2] * u[2];
    for (int i = 0; i < 3; i++)
        y[i] = out[i];
}
/* Evaluate and apply a calibration ends here */
/* [[file:../literate/sphere.org::Scale a calibration to a known field][Scale a calibration to a known field]] */
int fe_sphere_scale(const fe_sphere_fit *fit, double field, fe_sphere_scaled *out)
{
    double f;
    if (fit == NULL || out == NULL || !(field >= 0.0) || !isfinite(field)
        || !(fit->radius > 0.0) || !isfinite(fit->radius))
        return FE_EINVAL;
    f = field > 0.0 ? field : fit->radius;
    out->field = f;
    memcpy(out->offset, fit->offset, sizeof out->offset);
    for (int k = 0; k < 9; k++)
        out->matrix[k] = f * fit->matrix[k];
    out->gain = fit->radius / f;
    return FE_OK;
}

void fe_sphere_scaled_apply(const fe_sphere_scaled *s, const double x[3], double y[3])
{
    double u[3];
    for (int j = 0; j < 3; j++)
        u[j] = x[j] - s->offset[j];
    for (int i = 0; i < 3; i++)
        y[i] = s->matrix[i * 3] * u[0] + s->matrix[i * 3 + 1] * u[1]
             + s->matrix[i * 3 + 2] * u[2];
}
/* Scale a calibration to a known field ends here */
/* [[file:../literate/sphere.org::Express a calibration as ArduPilot's parameters][Express a calibration as ArduPilot's parameters]] */
int fe_sphere_to_ardupilot(const fe_sphere_fit *fit, double field_mgauss,
                           double mgauss_per_unit, fe_sphere_ardupilot *out)
{
    double K = mgauss_per_unit, w;
    if (fit == NULL || out == NULL || !(K > 0.0) || !isfinite(K) || !(field_mgauss >= 0.0)
        || !isfinite(field_mgauss) || !(fit->radius > 0.0) || !isfinite(fit->radius))
        return FE_EINVAL;
    w = field_mgauss > 0.0 ? field_mgauss / K : fit->radius;     /* F / K */
    for (int j = 0; j < 3; j++) {
        out->ofs[j] = -K * fit->offset[j];
        out->dia[j] = w * fit->matrix[4 * j];
    }
    out->odi[0] = w * fit->matrix[1];
    out->odi[1] = w * fit->matrix[2];
    out->odi[2] = w * fit->matrix[5];
    return FE_OK;
}
/* Express a calibration as ArduPilot's parameters ends here */
/* [[file:../literate/sphere.org::Measure the errors from blocks in time][Measure the errors from blocks in time]] */
static int fe__sphere_block_errors(const fe_quadric_blocks *qb, fe_sphere_fit *fit)
{
    double beta[FE__P], theta[10], T[10 * FE__P], phi[100], mu[FE_QUADRIC_MOMENTS];
    double H[FE__P * FE__P], Hi[FE__P * FE__P], g[FE_QUADRIC_BLOCKS][FE__P], gsum[FE__P];
    double Om[FE__P * FE__P], C[FE__P * FE__P], scale[FE__P], sigma = fit->frame_scale;
    double n = qb->all.m[0], nb[FE_QUADRIC_BLOCKS];
    int p = fit->nparams, B = 0, rc;

    /* The parameters in the frame of the solve. */
    memset(beta, 0, sizeof beta);
    for (int j = 0; j < 3; j++) {
        beta[j] = (fit->offset[j] - fit->frame_centre[j]) / sigma;
        scale[j] = sigma;
    }
    for (int k = 3; k < p; k++) {
        int ell = fit->model == FE_FIT_ELLIPSOID;
        beta[k] = ell ? fit->params[k] * sigma * sigma : fit->params[k] / sigma;
        scale[k] = ell ? 1.0 / (sigma * sigma) : sigma;
    }
    fe__sphere_theta(fit->model, beta, theta, T);
    /* H = T' Phi T from all samples. */
    rc = fe__sphere_phi(&qb->all, fit->frame_centre, sigma, phi, mu);
    if (rc != FE_OK)
        return rc;
    for (int k = 0; k < p; k++)
        for (int l = 0; l < p; l++) {
            double h = 0.0;
            for (int a = 0; a < 10; a++)
                for (int b = 0; b < 10; b++)
                    h += T[a * FE__P + k] * phi[a * 10 + b] * T[b * FE__P + l];
            H[k * p + l] = h;
        }
    /* The block sums g_b = T' Phi_b theta. */
    memset(gsum, 0, sizeof gsum);
    for (uint32_t b = 0; b < qb->nblocks && b < FE_QUADRIC_BLOCKS; b++) {
        double v[10];
        if (qb->block[b].m[0] == 0.0)
            continue;
        rc = fe__sphere_phi(&qb->block[b], fit->frame_centre, sigma, phi, mu);
        if (rc != FE_OK)
            return rc;
        for (int a = 0; a < 10; a++) {
            v[a] = 0.0;
            for (int c = 0; c < 10; c++)
                v[a] += phi[a * 10 + c] * theta[c];
        }
        for (int k = 0; k < p; k++) {
            g[B][k] = 0.0;
            for (int a = 0; a < 10; a++)
                g[B][k] += T[a * FE__P + k] * v[a];
            gsum[k] += g[B][k];
        }
        nb[B++] = qb->block[b].m[0];
    }
    if (B < 8)
        return FE_OK;           /* too few blocks: the independent errors stay */
    /* Omega: the spread of the centred block sums. */
    memset(Om, 0, sizeof Om);
    for (int b = 0; b < B; b++)
        for (int k = 0; k < p; k++)
            for (int l = 0; l < p; l++)
                Om[k * p + l] += (g[b][k] - nb[b] / n * gsum[k]) * (g[b][l] - nb[b] / n * gsum[l]);
    for (int k = 0; k < p * p; k++)
        Om[k] *= (double)B / (B - 1);
    /* H^-1 Omega H^-1, in the sensor's units. */
    memset(Hi, 0, sizeof Hi);
    for (int k = 0; k < p; k++)
        Hi[k * p + k] = 1.0;
    {
        double Hc[FE__P * FE__P];
        memcpy(Hc, H, sizeof Hc);
        rc = fe__sphere_posv(p, p, Hc, Hi);
        if (rc != FE_OK)
            return rc;
    }
    for (int k = 0; k < p; k++)
        for (int l = 0; l < p; l++) {
            double c = 0.0;
            for (int a = 0; a < p; a++)
                for (int b = 0; b < p; b++)
                    c += Hi[k * p + a] * Om[a * p + b] * Hi[b * p + l];
            C[k * p + l] = c;
        }
    for (int k = 0; k < p; k++)
        for (int l = 0; l < p; l++)
            fit->cov[k * p + l] = scale[k] * scale[l] * C[k * p + l];
    for (int k = 0; k < p; k++)
        fit->se[k] = sqrt(fmax(fit->cov[k * p + k], 0.0));
    fit->se_blocks = B;
    return fe__sphere_matrix_se(fit);
}

int fe_sphere_fit_blocks(const fe_quadric_blocks *qb, fe_sphere_model model,
                         const fe_sphere_options *opt, fe_sphere_fit *fit)
{
    int rc;
    if (qb == NULL || fit == NULL)
        return FE_EINVAL;
    rc = fe_sphere_fit_moments(&qb->all, model, opt, fit);
    if (rc != FE_OK || fit->algebraic)
        return rc;
    return fe__sphere_block_errors(qb, fit);
}
/* Measure the errors from blocks in time ends here */
/* [[file:../literate/sphere.org::Find the still segments][Find the still segments]] */
enum { FE__STILL_SLOT = 7 };    /* x, y, z, |x|, |rate|, verdict, spare */

fe_still_options fe_still_default_options(void)
{
    fe_still_options o = {50, 0.002, 0.0};
    return o;
}

size_t fe_still_workspace(size_t window)
{
    return FE__STILL_SLOT * window;
}

int fe_still_init(fe_still *s, const fe_still_options *opt, double *work, size_t work_len)
{
    fe_still_options o = opt != NULL ? *opt : fe_still_default_options();
    if (s == NULL || work == NULL || o.window < 2 || !(o.max_rel_sd >= 0.0)
        || !isfinite(o.max_rel_sd) || !(o.max_rate >= 0.0) || !isfinite(o.max_rate))
        return FE_EINVAL;
    if (work_len < fe_still_workspace(o.window))
        return FE_ESIZE;
    memset(s, 0, sizeof *s);
    s->opt = o;
    s->ring = work;
    return FE_OK;
}

/* Hand back the oldest sample held. */
static void fe__still_pop(fe_still *s, double out[3], int *still)
{
    const double *slot = s->ring + FE__STILL_SLOT * s->head;
    for (int j = 0; j < 3; j++)
        out[j] = slot[j];
    *still = slot[5] != 0.0;
    if (*still)
        s->still++;
    else
        s->moving++;
    s->head = (s->head + 1) % s->opt.window;
    s->count--;
}

/* Judge the full window: the sd of |x| against its mean, the largest rate. */
static void fe__still_judge(fe_still *s)
{
    size_t w = s->opt.window;
    double mean = 0.0, ss = 0.0, worst = 0.0;
    for (size_t k = 0; k < w; k++)
        mean += s->ring[FE__STILL_SLOT * k + 3] / (double)w;
    for (size_t k = 0; k < w; k++) {
        double d = s->ring[FE__STILL_SLOT * k + 3] - mean;
        ss += d * d;
        worst = fmax(worst, s->ring[FE__STILL_SLOT * k + 4]);
    }
    if (sqrt(ss / (double)(w - 1)) <= s->opt.max_rel_sd * mean
        && (s->opt.max_rate == 0.0 || worst <= s->opt.max_rate))
        for (size_t k = 0; k < w; k++)
            s->ring[FE__STILL_SLOT * k + 5] = 1.0;
}

int fe_still_push(fe_still *s, const double x[3], const double *rate, double out[3],
                  int *still, int *ready)
{
    double *slot;
    if (s == NULL || x == NULL || out == NULL || still == NULL || ready == NULL)
        return FE_EINVAL;
    for (int j = 0; j < 3; j++)
        if (!isfinite(x[j]) || (rate != NULL && !isfinite(rate[j])))
            return FE_ENONFINITE;
    *ready = s->count == s->opt.window;
    if (*ready)
        fe__still_pop(s, out, still);
    slot = s->ring + FE__STILL_SLOT * ((s->head + s->count) % s->opt.window);
    for (int j = 0; j < 3; j++)
        slot[j] = x[j];
    slot[3] = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    slot[4] = rate != NULL ? sqrt(rate[0] * rate[0] + rate[1] * rate[1] + rate[2] * rate[2])
                           : 0.0;
    slot[5] = 0.0;
    s->count++;
    if (s->count == s->opt.window)
        fe__still_judge(s);
    return FE_OK;
}

int fe_still_flush(fe_still *s, double out[3], int *still)
{
    if (s == NULL || out == NULL || still == NULL)
        return FE_EINVAL;
    if (s->count == 0)
        return FE_END;
    fe__still_pop(s, out, still);
    return FE_OK;
}
/* Find the still segments ends here */
/* [[file:../literate/sphere.org::Measure radial residuals and their robust scale][Measure radial residuals and their robust scale]] */
double fe_sphere_radial(const fe_sphere_fit *fit, const double x[3])
{
    double y[3];
    fe_sphere_apply(fit, x, y);
    return sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]) - 1.0;
}

/* Bin k holds |e| in [10^(k/25 - 7), 10^((k+1)/25 - 7)). */
int fe_radial_hist_add(fe_radial_hist *h, double e)
{
    double a = fabs(e);
    int k;
    if (h == NULL)
        return FE_EINVAL;
    if (!isfinite(e))
        return FE_ENONFINITE;
    k = a > 0.0 ? (int)floor(25.0 * (log10(a) + 7.0)) : 0;
    k = k < 0 ? 0 : k >= FE_RADIAL_BINS ? FE_RADIAL_BINS - 1 : k;
    h->count[k] += 1.0;
    h->n += 1.0;
    return FE_OK;
}

int fe_radial_hist_merge(fe_radial_hist *a, const fe_radial_hist *b)
{
    if (a == NULL || b == NULL)
        return FE_EINVAL;
    for (int k = 0; k < FE_RADIAL_BINS; k++)
        a->count[k] += b->count[k];
    a->n += b->n;
    return FE_OK;
}

double fe_radial_hist_scale(const fe_radial_hist *h)
{
    double half, below = 0.0;
    if (h == NULL || !(h->n > 0.0))
        return 0.0;
    half = 0.5 * h->n;
    for (int k = 0; k < FE_RADIAL_BINS; k++) {
        if (below + h->count[k] >= half) {
            /* Interpolate in log |e| within the bin. */
            double f = h->count[k] > 0.0 ? (half - below) / h->count[k] : 0.0;
            return 1.4826 * pow(10.0, ((double)k + f) / 25.0 - 7.0);
        }
        below += h->count[k];
    }
    return 1.4826 * 10.0;
}
/* Measure radial residuals and their robust scale ends here */
