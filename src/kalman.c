/* SPDX-License-Identifier: MIT */
/* Tangled from literate/kalman.org: do not edit; edit the .org and run make tangle. */
/* [[file:../literate/kalman.org::Kalman Filter Includes][Kalman Filter Includes]] */
#include <math.h>
#include <string.h>

#include <cblas.h>
#include <lapacke.h>

#include "foldest/error.h"
#include "foldest/kalman.h"
#include "foldest/special.h"
/* Kalman Filter Includes ends here */
/* [[file:../literate/kalman.org::Lay out the workspace][Lay out the workspace]] */
/* Pointers into an fe_kalman's workspace. */
struct fe__kalman_ws {
    double *x;      /* n: working estimate          */
    double *P;      /* n x n: working covariance    */
    double *T;      /* n x n: Phi P; a copy of Lambda */
    double *PAT;    /* n x bmax: P A^T; fast path: g  */
    double *D;      /* bmax x bmax: D; fast path: L_Z */
    double *R;      /* bmax x (n + 1): [nu | A P]; fast path: L_Z^{-1} A */
    double *nu;     /* bmax: innovation; fast path: L_Z^{-1} z */
};

static size_t fe__kalman_work_doubles(size_t n, size_t b)
{
    return n + 2 * n * n + n * b + b * b + b * (n + 1) + b;
}

static inline struct fe__kalman_ws fe__kalman_layout(const fe_kalman *k)
{
    size_t n = k->n, b = k->bmax;
    struct fe__kalman_ws w;
    w.x = k->work;
    w.P = w.x + n;
    w.T = w.P + n * n;
    w.PAT = w.T + n * n;
    w.D = w.PAT + n * b;
    w.R = w.D + b * b;
    w.nu = w.R + b * (n + 1);
    return w;
}

size_t fe_kalman_doubles(size_t n, size_t bmax)
{
    if (n == 0 || bmax == 0 || n > FE_KALMAN_MAX_DIM || bmax > FE_KALMAN_MAX_DIM)
        return 0;
    return n + n * n + fe__kalman_work_doubles(n, bmax);
}

int fe_kalman_init(fe_kalman *k, size_t n, size_t bmax, double *mem,
                   size_t len)
{
    size_t need;
    if (k == NULL || mem == NULL || n == 0 || bmax == 0)
        return FE_EINVAL;
    need = fe_kalman_doubles(n, bmax);
    if (need == 0 || len < need)
        return FE_ESIZE;
    k->n = n;
    k->bmax = bmax;
    k->x = mem;
    k->P = mem + n;
    k->work = mem + n + n * n;
    k->count = 0;
    memset(mem, 0, (n + n * n) * sizeof *mem);
    return FE_OK;
}
/* Lay out the workspace ends here */
/* [[file:../literate/kalman.org::Check finiteness and symmetrise][Check finiteness and symmetrise]] */
static inline int fe__finite(const double *v, size_t len)
{
    /* v * 0 is 0 for a finite v and NaN otherwise; two independent sums
       let the compiler pair them in one vector register. */
    double s0 = 0.0, s1 = 0.0;
    size_t i = 0;
    for (; i + 2 <= len; i += 2) {
        s0 += v[i] * 0.0;
        s1 += v[i + 1] * 0.0;
    }
    if (i < len)
        s0 += v[i] * 0.0;
    return s0 + s1 == 0.0;
}

/* The report's scalars are results too: an innovation covariance that
   overflows (A = 1e200) can leave x and P finite, since the gain goes to
   zero, while log det D is infinite.  Such a step is refused. */
static inline int fe__report_finite(const fe_kalman_report *r)
{
    return r == NULL || (isfinite(r->nis) && isfinite(r->log_det_D));
}

static void fe__symmetrise(double *M, size_t n)
{
    for (size_t i = 0; i < n; i++)
        for (size_t j = i + 1; j < n; j++) {
            double s = 0.5 * (M[i * n + j] + M[j * n + i]);
            M[i * n + j] = s;
            M[j * n + i] = s;
        }
}

static inline int fe__kalman_usable(const fe_kalman *k)
{
    return k != NULL && k->x != NULL && k->P != NULL && k->work != NULL
        && k->n > 0 && k->bmax > 0 && k->n <= FE_KALMAN_MAX_DIM
        && k->bmax <= FE_KALMAN_MAX_DIM;
}

static inline int fe__kalman_check_obs(size_t n, size_t bmax,
                                       const fe_kalman_obs *o)
{
    if (o == NULL || o->b == 0 || o->A == NULL || o->z == NULL || o->Z == NULL)
        return FE_EINVAL;
    if (o->b > bmax)
        return FE_ESIZE;
    if (!fe__finite(o->A, o->b * n) || !fe__finite(o->z, o->b)
        || !fe__finite(o->Z, o->b * o->b))
        return FE_ENONFINITE;
    return FE_OK;
}

/* Map a LAPACK info to a status. */
static int fe__lapack_status(lapack_int info)
{
    return info == 0 ? FE_OK : info > 0 ? FE_ENOTPD : FE_EINTERNAL;
}
/* Check finiteness and symmetrise ends here */
/* [[file:../literate/kalman.org::Set the prior and copy][Set the prior and copy]] */
int fe_kalman_set_prior(fe_kalman *k, const double *x0, const double *P0)
{
    size_t n;
    if (!fe__kalman_usable(k) || P0 == NULL)
        return FE_EINVAL;
    n = k->n;
    if ((x0 != NULL && !fe__finite(x0, n)) || !fe__finite(P0, n * n))
        return FE_ENONFINITE;
    for (size_t i = 0; i < n; i++)
        if (P0[i * n + i] < 0.0)
            return FE_ENOTPD;
    if (x0 != NULL)
        memcpy(k->x, x0, n * sizeof *x0);
    else
        memset(k->x, 0, n * sizeof *k->x);
    memcpy(k->P, P0, n * n * sizeof *P0);
    fe__symmetrise(k->P, n);
    k->count = 0;
    return FE_OK;
}

int fe_kalman_set_prior_scaled(fe_kalman *k, const double *x0, double p0)
{
    size_t n;
    if (!fe__kalman_usable(k))
        return FE_EINVAL;
    n = k->n;
    if (!isfinite(p0) || (x0 != NULL && !fe__finite(x0, n)))
        return FE_ENONFINITE;
    if (p0 < 0.0)
        return FE_ENOTPD;
    if (x0 != NULL)
        memcpy(k->x, x0, n * sizeof *x0);
    else
        memset(k->x, 0, n * sizeof *k->x);
    memset(k->P, 0, n * n * sizeof *k->P);
    for (size_t i = 0; i < n; i++)
        k->P[i * n + i] = p0;
    k->count = 0;
    return FE_OK;
}

double fe_kalman_sigma(const fe_kalman *k, size_t i)
{
    if (k == NULL || k->P == NULL || i >= k->n)
        return NAN;
    return sqrt(k->P[i * k->n + i]);
}

int fe_kalman_copy(fe_kalman *dst, const fe_kalman *src)
{
    if (!fe__kalman_usable(dst) || !fe__kalman_usable(src))
        return FE_EINVAL;
    if (dst->n != src->n)
        return FE_EMISMATCH;
    if (dst != src) {
        memmove(dst->x, src->x, src->n * sizeof *src->x);
        memmove(dst->P, src->P, src->n * src->n * sizeof *src->P);
        dst->count = src->count;
    }
    return FE_OK;
}
/* Set the prior and copy ends here */
/* [[file:../literate/kalman.org::Update by solving with the Kalman denominator][Update by solving with the Kalman denominator]] */
static void fe__kalman_fill_report(fe_kalman_report *r, size_t b,
                                   double nis, double log_det)
{
    r->b = b;
    r->nis = nis;
    r->log_det_D = log_det;
}

static void fe__kalman_joseph(size_t n, size_t b, const fe_kalman_obs *o,
                              double *P, double *U, const double *K);

static int fe__kalman_solve_update(size_t n, const fe_kalman_obs *o,
                                   double *x, double *P,
                                   const struct fe__kalman_ws *w,
                                   fe_kalman_report *r, int joseph)
{
    const size_t b = o->b;
    const int ni = (int)n, bi = (int)b;
    double *PAT = w->PAT, *D = w->D, *R = w->R, *nu = w->nu;
    lapack_int info;
    int rc;

    /* PAT = P A^T (n x b). */
    cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasTrans, ni, bi, ni, 1.0, P,
                ni, o->A, ni, 0.0, PAT, bi);
    /* D = Z + A PAT (b x b); the lower triangle is what counts. */
    memcpy(D, o->Z, b * b * sizeof *D);
    cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, bi, bi, ni, 1.0,
                o->A, ni, PAT, bi, 1.0, D, bi);
    if (r != NULL && r->D != NULL)
        for (size_t i = 0; i < b; i++)
            for (size_t j = 0; j <= i; j++)
                r->D[i * b + j] = r->D[j * b + i] = D[i * b + j];
    /* nu = z - A x. */
    memcpy(nu, o->z, b * sizeof *nu);
    cblas_dgemv(CblasRowMajor, CblasNoTrans, bi, ni, -1.0, o->A, ni, x, 1,
                1.0, nu, 1);
    /* Right-hand sides [nu | A P], column-major b x (n + 1), ldb = b. */
    memcpy(R, nu, b * sizeof *R);
    memcpy(R + b, PAT, n * b * sizeof *R);
    /* Solve D [DiRes | DiAP] = [nu | A P] (column-major upper = row-major
       lower triangle of the symmetric D). */
    info = LAPACKE_dposv(LAPACK_COL_MAJOR, 'U', bi, ni + 1, D, bi, R, bi);
    rc = fe__lapack_status(info);
    if (rc != FE_OK)
        return rc;
    if (r != NULL) {
        double nis = 0.0, log_det = 0.0;
        for (size_t i = 0; i < b; i++) {
            nis += nu[i] * R[i];
            log_det += 2.0 * log(D[i * b + i]);
        }
        fe__kalman_fill_report(r, b, nis, log_det);
        if (r->innovation != NULL)
            memcpy(r->innovation, nu, b * sizeof *nu);
        if (r->whitened != NULL) {
            /* w = L^{-1} nu with L = U^T, U the column-major upper factor. */
            memcpy(r->whitened, nu, b * sizeof *nu);
            cblas_dtrsv(CblasColMajor, CblasUpper, CblasTrans, CblasNonUnit,
                        bi, D, bi, r->whitened, 1);
        }
    }
    /* x += PAT DiRes;  P -= PAT DiAP;  keep P symmetric. */
    cblas_dgemv(CblasRowMajor, CblasNoTrans, ni, bi, 1.0, PAT, bi, R, 1, 1.0,
                x, 1);
    cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasTrans, ni, ni, bi, -1.0,
                PAT, bi, R + b, bi, 1.0, P, ni);
    if (joseph)
        fe__kalman_joseph(n, b, o, P, PAT, R + b);
    fe__symmetrise(P, n);
    return FE_OK;
}
/* Update by solving with the Kalman denominator ends here */
/* [[file:../literate/kalman.org::Apply Joseph's form][Apply Joseph's form]] */
/* P holds M P = P - K A P of the standard update, K (n x b, row-major,
   leading dimension b) the gain; U (n x b) is scratch.  Make P the
   Joseph form M P + (K Z - (M P) A^T) K^T. */
static void fe__kalman_joseph(size_t n, size_t b, const fe_kalman_obs *o,
                              double *P, double *U, const double *K)
{
    const int ni = (int)n, bi = (int)b;
    /* U = (M P) A^T, then U = K Z - U (Z by its lower triangle). */
    cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasTrans, ni, bi, ni, 1.0, P,
                ni, o->A, ni, 0.0, U, bi);
    cblas_dsymm(CblasRowMajor, CblasRight, CblasLower, ni, bi, 1.0, o->Z, bi,
                K, bi, -1.0, U, bi);
    /* P += U K^T. */
    cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasTrans, ni, ni, bi, 1.0, U,
                bi, K, bi, 1.0, P, ni);
}
/* Apply Joseph's form ends here */
/* [[file:../literate/kalman.org::Decorrelate a packet][Decorrelate a packet]] */
/* A packet as decorrelated scalar rows: row i is (A[i], z[i]) with noise
   variance var[i * var_stride], or 1 when var is NULL. */
struct fe__rows {
    size_t b;
    const double *A;
    const double *z;
    const double *var;
    size_t var_stride;
    double log_det;     /* 2 sum log (L_Z)_ii: the whitening's share */
};

static int fe__kalman_decorrelate(size_t n, const fe_kalman_obs *o,
                                  const double *x, const double *P,
                                  const struct fe__kalman_ws *w,
                                  fe_kalman_report *r, struct fe__rows *p)
{
    const size_t b = o->b;
    const double *A = o->A, *Z = o->Z, *z = o->z;
    double *L = w->D, *Aw = w->R, *zw = w->nu, *g = w->PAT;
    int diagonal = 1;

    if (r != NULL && r->innovation != NULL)
        for (size_t i = 0; i < b; i++) {
            double s = z[i];
            for (size_t c = 0; c < n; c++)
                s -= A[i * n + c] * x[c];
            r->innovation[i] = s;
        }
    if (r != NULL && r->D != NULL)
        for (size_t i = 0; i < b; i++) {
            for (size_t c = 0; c < n; c++) {     /* g = P a_i */
                double s = 0.0;
                for (size_t e = 0; e < n; e++)
                    s += P[c * n + e] * A[i * n + e];
                g[c] = s;
            }
            for (size_t j = 0; j <= i; j++) {
                double s = Z[i * b + j];
                for (size_t c = 0; c < n; c++)
                    s += A[j * n + c] * g[c];
                r->D[i * b + j] = r->D[j * b + i] = s;
            }
        }
    p->b = b;
    p->log_det = 0.0;
    for (size_t i = 1; i < b && diagonal; i++)
        for (size_t j = 0; j < i; j++)
            diagonal &= Z[i * b + j] == 0.0;
    if (diagonal) {
        for (size_t i = 0; i < b; i++)
            if (!(Z[i * b + i] > 0.0))
                return FE_ENOTPD;
        p->A = A;
        p->z = z;
        p->var = Z;
        p->var_stride = b + 1;
        return FE_OK;
    }
    /* Z = L L^T, from the lower triangle of Z.  The diagonal of L is
       stored inverted: it is only ever divided by. */
    for (size_t j = 0; j < b; j++) {
        double s = Z[j * b + j], inv;
        for (size_t e = 0; e < j; e++)
            s -= L[j * b + e] * L[j * b + e];
        if (!(s > 0.0))
            return FE_ENOTPD;
        inv = 1.0 / sqrt(s);
        L[j * b + j] = inv;
        for (size_t i = j + 1; i < b; i++) {
            double t = Z[i * b + j];
            for (size_t e = 0; e < j; e++)
                t -= L[i * b + e] * L[j * b + e];
            L[i * b + j] = t * inv;
        }
        if (r != NULL)
            p->log_det -= 2.0 * log(inv);
    }
    /* Whiten: Aw = L^{-1} A, zw = L^{-1} z. */
    for (size_t i = 0; i < b; i++) {
        double inv = L[i * b + i];
        double t = z[i];
        for (size_t e = 0; e < i; e++)
            t -= L[i * b + e] * zw[e];
        zw[i] = t * inv;
        for (size_t c = 0; c < n; c++) {
            double s = A[i * n + c];
            for (size_t e = 0; e < i; e++)
                s -= L[i * b + e] * Aw[e * n + c];
            Aw[i * n + c] = s * inv;
        }
    }
    p->A = Aw;
    p->z = zw;
    p->var = NULL;
    p->var_stride = 0;
    return FE_OK;
}
/* Decorrelate a packet ends here */
/* [[file:../literate/kalman.org::Update by sequential scalar steps][Update by sequential scalar steps]] */
#if defined(__GNUC__)
#define FE__ALWAYS_INLINE __attribute__((always_inline)) inline
#else
#define FE__ALWAYS_INLINE inline
#endif

enum { FE__KALMAN_SMALL = 8 };

/* One scalar update of (xs, Ps) into (x, P) (the same arrays for an update
   in place): row a, value z, noise variance v.  Returns 0 when d is not a
   positive finite number, else d; *res receives the innovation. */
static FE__ALWAYS_INLINE double fe__kalman_row(const size_t n, const double *xs,
                                               const double *Ps, double *x,
                                               double *P, double *g,
                                               const double *a, double z,
                                               double v, double *res)
{
    double d = v, nu = z, inv, gain;
    /* g = P a, by rows of P (= columns: P is symmetric). */
    for (size_t c = 0; c < n; c++)
        g[c] = 0.0;
    for (size_t e = 0; e < n; e++)
        for (size_t c = 0; c < n; c++)
            g[c] += Ps[e * n + c] * a[e];
    for (size_t c = 0; c < n; c++) {
        d += a[c] * g[c];
        nu -= a[c] * xs[c];
    }
    if (!(d > 0.0) || !isfinite(d))
        return 0.0;
    inv = 1.0 / d;
    gain = nu * inv;
    for (size_t c = 0; c < n; c++)
        x[c] = xs[c] + g[c] * gain;
    /* (g_c g_e) inv is the same number as (g_e g_c) inv: the full square
       keeps P exactly symmetric. */
    for (size_t c = 0; c < n; c++)
        for (size_t e = 0; e < n; e++)
            P[c * n + e] = Ps[c * n + e] - (g[c] * g[e]) * inv;
    *res = nu;
    return d;
}

/* Fold the rows of p into (x, P), the first from (xs, Ps). */
static FE__ALWAYS_INLINE int fe__kalman_rows(const size_t n, const double *xs,
                                             const double *Ps, double *x,
                                             double *P, double *g,
                                             const struct fe__rows *p,
                                             fe_kalman_report *r)
{
    double nis = 0.0, log_det = p->log_det;
    /* p->b >= 1: the first row always runs, from (xs, Ps). */
    for (size_t i = 0; i == 0 || i < p->b; i++) {
        double v = p->var != NULL ? p->var[i * p->var_stride] : 1.0, res = 0.0;
        double d = i == 0
            ? fe__kalman_row(n, xs, Ps, x, P, g, p->A, p->z[0], v, &res)
            : fe__kalman_row(n, x, P, x, P, g, p->A + i * n, p->z[i], v, &res);
        if (d == 0.0)
            return FE_ENOTPD;
        if (r != NULL) {
            nis += res * res / d;
            log_det += log(d);
            if (r->whitened != NULL)
                r->whitened[i] = res / sqrt(d);
        }
    }
    if (r != NULL)
        fe__kalman_fill_report(r, p->b, nis, log_det);
    return FE_OK;
}

/* Run time n, in place (on the workspace copy). */
static int fe__kalman_rows_any(size_t n, double *x, double *P, double *g,
                               const struct fe__rows *p, fe_kalman_report *r)
{
    return fe__kalman_rows(n, x, P, x, P, g, p, r);
}

/* Compile-time n: update the caller's (x, P) in place, from a saved copy
   that puts them back if the update is refused or its result not finite. */
#define FE__KALMAN_SMALL_KERNEL(N)                                           \
    static int fe__kalman_small##N(double *x, double *P,                     \
                                   const struct fe__rows *p,                 \
                                   fe_kalman_report *r)                      \
    {                                                                        \
        double xo[N], Po[N * N], g[N];                                       \
        int rc;                                                              \
        memcpy(xo, x, sizeof xo);                                            \
        memcpy(Po, P, sizeof Po);                                            \
        rc = fe__kalman_rows(N, x, P, x, P, g, p, r);                        \
        if (rc == FE_OK && (!fe__finite(x, N) || !fe__finite(P, N * N)     \
                            || !fe__report_finite(r)))                       \
            rc = FE_ENONFINITE;                                              \
        if (rc != FE_OK) {                                                   \
            memcpy(x, xo, sizeof xo);                                        \
            memcpy(P, Po, sizeof Po);                                        \
        }                                                                    \
        return rc;                                                           \
    }
FE__KALMAN_SMALL_KERNEL(1)
FE__KALMAN_SMALL_KERNEL(2)
FE__KALMAN_SMALL_KERNEL(3)
FE__KALMAN_SMALL_KERNEL(4)
FE__KALMAN_SMALL_KERNEL(5)
FE__KALMAN_SMALL_KERNEL(6)
FE__KALMAN_SMALL_KERNEL(7)
FE__KALMAN_SMALL_KERNEL(8)

typedef int fe__kalman_small_fn(double *, double *, const struct fe__rows *,
                                fe_kalman_report *);

static fe__kalman_small_fn *const fe__kalman_small[FE__KALMAN_SMALL + 1] = {
    0, fe__kalman_small1, fe__kalman_small2, fe__kalman_small3,
    fe__kalman_small4, fe__kalman_small5, fe__kalman_small6,
    fe__kalman_small7, fe__kalman_small8};

/* The sequential update in place on (x, P) in the workspace. */
static int fe__kalman_seq_update(size_t n, const fe_kalman_obs *o, double *x,
                                 double *P, const struct fe__kalman_ws *w,
                                 fe_kalman_report *r)
{
    struct fe__rows p;
    int rc = fe__kalman_decorrelate(n, o, x, P, w, r, &p);
    if (rc != FE_OK)
        return rc;
    return fe__kalman_rows_any(n, x, P, w->PAT, &p, r);
}
/* Update by sequential scalar steps ends here */
/* [[file:../literate/kalman.org::Predict into the workspace][Predict into the workspace]] */
static int fe__kalman_check_model(size_t n, const fe_kalman_model *m)
{
    if (m == NULL || m->m > FE_KALMAN_MAX_DIM
        || (m->Gamma != NULL && m->m > 0 && m->u == NULL))
        return FE_EINVAL;
    if ((m->Phi != NULL && !fe__finite(m->Phi, n * n))
        || (m->Xi != NULL && !fe__finite(m->Xi, n * n))
        || (m->Gamma != NULL && m->m > 0
            && (!fe__finite(m->Gamma, n * m->m) || !fe__finite(m->u, m->m))))
        return FE_ENONFINITE;
    return FE_OK;
}

/* xo = Phi x + Gamma u, Po = Xi + Phi P Phi^T (xo, Po distinct from x, P). */
static void fe__kalman_predict_into(size_t n, const fe_kalman_model *m,
                                    const double *x, const double *P,
                                    double *xo, double *Po, double *T)
{
    const int ni = (int)n;
    if (m->Xi != NULL)
        memcpy(Po, m->Xi, n * n * sizeof *Po);
    else
        memset(Po, 0, n * n * sizeof *Po);
    if (m->Phi != NULL) {
        cblas_dgemv(CblasRowMajor, CblasNoTrans, ni, ni, 1.0, m->Phi, ni, x, 1,
                    0.0, xo, 1);
        cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, ni, ni, ni, 1.0,
                    m->Phi, ni, P, ni, 0.0, T, ni);
        cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasTrans, ni, ni, ni, 1.0, T,
                    ni, m->Phi, ni, 1.0, Po, ni);
    } else {
        memcpy(xo, x, n * sizeof *xo);
        for (size_t i = 0; i < n * n; i++)
            Po[i] += P[i];
    }
    if (m->Gamma != NULL && m->m > 0)
        cblas_dgemv(CblasRowMajor, CblasNoTrans, ni, (int)m->m, 1.0, m->Gamma,
                    (int)m->m, m->u, 1, 1.0, xo, 1);
    fe__symmetrise(Po, n);
}
/* Predict into the workspace ends here */
/* [[file:../literate/kalman.org::Step atomically][Step atomically]] */
/* Which covariance update a step runs. */
enum { FE__KALMAN_REFERENCE, FE__KALMAN_FAST, FE__KALMAN_JOSEPH };

static int fe__kalman_step(fe_kalman *k, const fe_kalman_model *m,
                           const fe_kalman_obs *o, fe_kalman_report *r,
                           int kind)
{
    struct fe__kalman_ws w;
    size_t n;
    int rc;

    if (!fe__kalman_usable(k))
        return FE_EINVAL;
    n = k->n;
    if (m != NULL && (rc = fe__kalman_check_model(n, m)) != FE_OK)
        return rc;
    if (o != NULL && (rc = fe__kalman_check_obs(n, k->bmax, o)) != FE_OK)
        return rc;
    w = fe__kalman_layout(k);
    if (m != NULL) {
        fe__kalman_predict_into(n, m, k->x, k->P, w.x, w.P, w.T);
    } else {
        memcpy(w.x, k->x, n * sizeof *w.x);
        memcpy(w.P, k->P, n * n * sizeof *w.P);
    }
    rc = FE_OK;
    if (o != NULL)
        rc = kind == FE__KALMAN_FAST
                 ? fe__kalman_seq_update(n, o, w.x, w.P, &w, r)
                 : fe__kalman_solve_update(n, o, w.x, w.P, &w, r,
                                           kind == FE__KALMAN_JOSEPH);
    if (rc == FE_OK && (!fe__finite(w.x, n) || !fe__finite(w.P, n * n)
                        || (o != NULL && !fe__report_finite(r))))
        rc = FE_ENONFINITE;
    if (rc != FE_OK)
        return rc;
    memcpy(k->x, w.x, n * sizeof *w.x);
    memcpy(k->P, w.P, n * n * sizeof *w.P);
    if (o != NULL)
        k->count++;
    return FE_OK;
}

int fe_kalman_update(fe_kalman *k, const fe_kalman_obs *o,
                     fe_kalman_report *r)
{
    if (o == NULL)
        return FE_EINVAL;
    return fe__kalman_step(k, NULL, o, r, FE__KALMAN_REFERENCE);
}

int fe_kalman_update_joseph(fe_kalman *k, const fe_kalman_obs *o,
                            fe_kalman_report *r)
{
    if (o == NULL)
        return FE_EINVAL;
    return fe__kalman_step(k, NULL, o, r, FE__KALMAN_JOSEPH);
}

int fe_kalman_update_fast(fe_kalman *k, const fe_kalman_obs *o,
                          fe_kalman_report *r)
{
    struct fe__kalman_ws w;
    struct fe__rows p;
    int rc;
    if (o == NULL || !fe__kalman_usable(k))
        return FE_EINVAL;
    if (k->n > FE__KALMAN_SMALL)
        return fe__kalman_step(k, NULL, o, r, FE__KALMAN_FAST);
    /* Small n: decorrelate, then the fixed-size kernel. */
    if (o->b == 0 || o->A == NULL || o->z == NULL || o->Z == NULL)
        return FE_EINVAL;
    if (o->b > k->bmax)
        return FE_ESIZE;
    if (o->b == 1 && (r == NULL || (r->innovation == NULL && r->D == NULL))) {
        /* A scalar packet is its own decorrelation.  Its finiteness is
           checked only when the kernel refuses it: a NaN or infinity in
           A or Z makes d non-finite, one in z makes the result so. */
        p.b = 1;
        p.A = o->A;
        p.z = o->z;
        p.var = o->Z;
        p.var_stride = 1;
        p.log_det = 0.0;
        rc = o->Z[0] > 0.0 ? fe__kalman_small[k->n](k->x, k->P, &p, r)
                           : FE_ENOTPD;
        if (rc == FE_OK)
            k->count++;
        else if (!fe__finite(o->A, k->n) || !isfinite(o->z[0])
                 || !isfinite(o->Z[0]))
            rc = FE_ENONFINITE;
        return rc;
    }
    if ((rc = fe__kalman_check_obs(k->n, k->bmax, o)) != FE_OK)
        return rc;
    w = fe__kalman_layout(k);
    rc = fe__kalman_decorrelate(k->n, o, k->x, k->P, &w, r, &p);
    if (rc != FE_OK)
        return rc;
    rc = fe__kalman_small[k->n](k->x, k->P, &p, r);
    if (rc == FE_OK)
        k->count++;
    return rc;
}

int fe_kalman_predict(fe_kalman *k, const fe_kalman_model *m)
{
    if (m == NULL)
        return FE_EINVAL;
    return fe__kalman_step(k, m, NULL, NULL, FE__KALMAN_REFERENCE);
}

int fe_kalman_track(fe_kalman *k, const fe_kalman_track_obs *o,
                    fe_kalman_report *r)
{
    if (o == NULL)
        return FE_EINVAL;
    return fe__kalman_step(k, &o->model, &o->obs, r, FE__KALMAN_REFERENCE);
}

int fe_kalman_track_fast(fe_kalman *k, const fe_kalman_track_obs *o,
                         fe_kalman_report *r)
{
    if (o == NULL)
        return FE_EINVAL;
    return fe__kalman_step(k, &o->model, &o->obs, r, FE__KALMAN_FAST);
}

int fe_kalman_track_joseph(fe_kalman *k, const fe_kalman_track_obs *o,
                           fe_kalman_report *r)
{
    if (o == NULL)
        return FE_EINVAL;
    return fe__kalman_step(k, &o->model, &o->obs, r, FE__KALMAN_JOSEPH);
}
/* Step atomically ends here */
/* [[file:../literate/kalman.org::Fold in information space][Fold in information space]] */
static size_t fe__info_scratch(size_t n, size_t b)
{
    size_t pk = b * b + b * (n + 1), pr = n * n + n * (n + 1);
    return pk > pr ? pk : pr;
}

size_t fe_kalman_info_doubles(size_t n, size_t bmax)
{
    if (n == 0 || bmax == 0 || n > FE_KALMAN_MAX_DIM || bmax > FE_KALMAN_MAX_DIM)
        return 0;
    return n + n * n + n * n + n + fe__info_scratch(n, bmax);
}

static int fe__info_usable(const fe_kalman_info *s)
{
    return s != NULL && s->eta != NULL && s->Lambda != NULL && s->work != NULL
        && s->n > 0 && s->bmax > 0 && s->n <= FE_KALMAN_MAX_DIM
        && s->bmax <= FE_KALMAN_MAX_DIM;
}

int fe_kalman_info_init(fe_kalman_info *s, size_t n, size_t bmax,
                        double *mem, size_t len)
{
    size_t need;
    if (s == NULL || mem == NULL || n == 0 || bmax == 0)
        return FE_EINVAL;
    need = fe_kalman_info_doubles(n, bmax);
    if (need == 0 || len < need)
        return FE_ESIZE;
    s->n = n;
    s->bmax = bmax;
    s->eta = mem;
    s->Lambda = mem + n;
    s->work = mem + n + n * n;
    s->count = 0;
    memset(mem, 0, (n + n * n) * sizeof *mem);
    return FE_OK;
}

int fe_kalman_info_set_prior(fe_kalman_info *s, const double *x0,
                             const double *P0)
{
    size_t n;
    double *Pc, *B;
    int rc;
    if (!fe__info_usable(s) || P0 == NULL)
        return FE_EINVAL;
    n = s->n;
    if ((x0 != NULL && !fe__finite(x0, n)) || !fe__finite(P0, n * n))
        return FE_ENONFINITE;
    Pc = s->work + n * n + n;
    B = Pc + n * n;
    memcpy(Pc, P0, n * n * sizeof *Pc);
    /* B = [I | x0], column-major n x (n + 1). */
    memset(B, 0, n * (n + 1) * sizeof *B);
    for (size_t i = 0; i < n; i++) {
        B[i * n + i] = 1.0;
        B[n * n + i] = x0 != NULL ? x0[i] : 0.0;
    }
    rc = fe__lapack_status(LAPACKE_dposv(LAPACK_COL_MAJOR, 'U', (int)n,
                                         (int)n + 1, Pc, (int)n, B, (int)n));
    if (rc != FE_OK)
        return rc;
    fe__symmetrise(B, n);
    if (!fe__finite(B, n * (n + 1)))
        return FE_ENONFINITE;
    memcpy(s->Lambda, B, n * n * sizeof *B);
    memcpy(s->eta, B + n * n, n * sizeof *B);
    s->count = 0;
    return FE_OK;
}

int fe_kalman_info_set_prior_scaled(fe_kalman_info *s, const double *x0,
                                    double p0)
{
    size_t n;
    if (!fe__info_usable(s))
        return FE_EINVAL;
    n = s->n;
    if (isnan(p0) || (x0 != NULL && !fe__finite(x0, n)))
        return FE_ENONFINITE;
    if (!(p0 > 0.0))
        return FE_ENOTPD;
    /* A variance so small that its inverse overflows is no prior. */
    if (!isfinite(1.0 / p0))
        return FE_ENONFINITE;
    for (size_t i = 0; x0 != NULL && i < n; i++)
        if (!isfinite(x0[i] / p0))
            return FE_ENONFINITE;
    memset(s->Lambda, 0, n * n * sizeof *s->Lambda);
    for (size_t i = 0; i < n; i++) {
        s->Lambda[i * n + i] = 1.0 / p0;
        s->eta[i] = x0 != NULL ? x0[i] / p0 : 0.0;
    }
    s->count = 0;
    return FE_OK;
}

/* Add (G, g) to (Lambda, eta) if every sum is finite. */
static int fe__info_add(fe_kalman_info *s, const double *G, const double *g)
{
    size_t n = s->n;
    int ok = 1;
    for (size_t i = 0; i < n * n; i++)
        ok &= isfinite(s->Lambda[i] + G[i]) != 0;
    for (size_t i = 0; i < n; i++)
        ok &= isfinite(s->eta[i] + g[i]) != 0;
    if (!ok)
        return FE_ENONFINITE;
    for (size_t i = 0; i < n * n; i++)
        s->Lambda[i] += G[i];
    for (size_t i = 0; i < n; i++)
        s->eta[i] += g[i];
    return FE_OK;
}

int fe_kalman_info_update(fe_kalman_info *s, const fe_kalman_obs *o)
{
    size_t n, b;
    int ni, bi, rc;
    double *G, *g, *Zc, *W;
    if (!fe__info_usable(s))
        return FE_EINVAL;
    n = s->n;
    if ((rc = fe__kalman_check_obs(n, s->bmax, o)) != FE_OK)
        return rc;
    b = o->b;
    ni = (int)n;
    bi = (int)b;
    G = s->work;
    g = G + n * n;
    Zc = g + n;
    W = Zc + b * b;
    memcpy(Zc, o->Z, b * b * sizeof *Zc);
    /* W = [A | z], column-major b x (n + 1). */
    for (size_t i = 0; i < b; i++) {
        for (size_t j = 0; j < n; j++)
            W[j * b + i] = o->A[i * n + j];
        W[n * b + i] = o->z[i];
    }
    rc = fe__lapack_status(LAPACKE_dposv(LAPACK_COL_MAJOR, 'U', bi, ni + 1,
                                         Zc, bi, W, bi));
    if (rc != FE_OK)
        return rc;
    /* G = A^T (Z^{-1} A), g = A^T (Z^{-1} z). */
    cblas_dgemm(CblasRowMajor, CblasTrans, CblasTrans, ni, ni, bi, 1.0, o->A,
                ni, W, bi, 0.0, G, ni);
    cblas_dgemv(CblasRowMajor, CblasTrans, bi, ni, 1.0, o->A, ni, W + n * b,
                1, 0.0, g, 1);
    fe__symmetrise(G, n);
    rc = fe__info_add(s, G, g);
    if (rc == FE_OK)
        s->count++;
    return rc;
}

int fe_kalman_info_merge(fe_kalman_info *s, const fe_kalman_info *t)
{
    int rc;
    if (!fe__info_usable(s) || !fe__info_usable(t))
        return FE_EINVAL;
    if (s->n != t->n)
        return FE_EMISMATCH;
    if (s == t) {
        /* Merging with itself doubles it; go through the workspace. */
        size_t n = s->n;
        memcpy(s->work, s->Lambda, n * n * sizeof *s->work);
        memcpy(s->work + n * n, s->eta, n * sizeof *s->work);
        rc = fe__info_add(s, s->work, s->work + n * n);
    } else {
        rc = fe__info_add(s, t->Lambda, t->eta);
    }
    if (rc == FE_OK)
        s->count += t == s ? s->count : t->count;
    return rc;
}

int fe_kalman_info_copy(fe_kalman_info *dst, const fe_kalman_info *src)
{
    if (!fe__info_usable(dst) || !fe__info_usable(src))
        return FE_EINVAL;
    if (dst->n != src->n)
        return FE_EMISMATCH;
    if (dst != src) {
        memmove(dst->eta, src->eta, src->n * sizeof *src->eta);
        memmove(dst->Lambda, src->Lambda, src->n * src->n * sizeof *src->Lambda);
        dst->count = src->count;
    }
    return FE_OK;
}

int fe_kalman_info_to_kalman(const fe_kalman_info *s, fe_kalman *k)
{
    struct fe__kalman_ws w;
    size_t n;
    double *B;
    int rc;
    if (!fe__info_usable(s) || !fe__kalman_usable(k))
        return FE_EINVAL;
    if (s->n != k->n)
        return FE_EMISMATCH;
    n = s->n;
    w = fe__kalman_layout(k);
    B = w.x;                 /* w.x and w.P are contiguous: n (n + 1) */
    memcpy(w.T, s->Lambda, n * n * sizeof *w.T);
    memset(B, 0, n * (n + 1) * sizeof *B);
    for (size_t i = 0; i < n; i++) {
        B[i * n + i] = 1.0;
        B[n * n + i] = s->eta[i];
    }
    rc = fe__lapack_status(LAPACKE_dposv(LAPACK_COL_MAJOR, 'U', (int)n,
                                         (int)n + 1, w.T, (int)n, B, (int)n));
    if (rc != FE_OK)
        return rc;
    fe__symmetrise(B, n);
    if (!fe__finite(B, n * (n + 1)))
        return FE_ENONFINITE;
    memcpy(k->P, B, n * n * sizeof *B);
    memcpy(k->x, B + n * n, n * sizeof *B);
    k->count = s->count;
    return FE_OK;
}
/* Fold in information space ends here */
/* [[file:../literate/kalman.org::Monitor the innovations][Monitor the innovations]] */
fe_kalman_monitor_params fe_kalman_monitor_default_params(void)
{
    fe_kalman_monitor_params p = {FE_KALMAN_MONITOR_LAGS, 2.0, 0.5, 10.0};
    return p;
}

static int fe__monitor_params_ok(const fe_kalman_monitor_params *p)
{
    return p->lags <= FE_KALMAN_MONITOR_LAGS && isfinite(p->scale_up)
        && p->scale_up > 1.0 && isfinite(p->scale_down)
        && p->scale_down > 0.0 && p->scale_down < 1.0
        && isfinite(p->threshold) && p->threshold > 0.0;
}

int fe_kalman_monitor_init(fe_kalman_monitor *m,
                           const fe_kalman_monitor_params *p)
{
    fe_kalman_monitor_params d = fe_kalman_monitor_default_params();
    if (m == NULL)
        return FE_EINVAL;
    if (p == NULL)
        p = &d;
    if (!fe__monitor_params_ok(p))
        return FE_EINVAL;
    memset(m, 0, sizeof *m);
    m->par = *p;
    return FE_OK;
}

/* One-sided CUSUM step of the log-likelihood ratio for scale lambda. */
static void fe__cusum(fe_kalman_monitor *m, double *S, uint64_t *start,
                      double llr, int side)
{
    if (*S == 0.0)
        *start = m->steps;
    *S = *S + llr > 0.0 ? *S + llr : 0.0;
    if (*S > m->par.threshold) {
        m->alarms++;
        if (m->alarm_step == 0) {
            m->alarm_step = m->steps;
            m->onset_step = *start;
            m->alarm_side = side;
        }
        *S = 0.0;
    }
}

int fe_kalman_monitor_add(fe_kalman_monitor *m, const fe_kalman_report *r)
{
    double bd, lu, ld;
    if (m == NULL || r == NULL || r->b == 0 || !fe__monitor_params_ok(&m->par))
        return FE_EINVAL;
    if (!isfinite(r->nis) || !isfinite(r->log_det_D))
        return FE_ENONFINITE;
    if (r->nis < 0.0)
        return FE_EINVAL;
    if (r->whitened != NULL) {
        size_t dim = r->b < FE_KALMAN_MONITOR_DIM ? r->b : FE_KALMAN_MONITOR_DIM;
        if (!fe__finite(r->whitened, dim))
            return FE_ENONFINITE;
    }
    bd = (double)r->b;
    m->steps++;
    m->dof += r->b;
    m->nis_sum += r->nis;
    if (r->whitened != NULL) {
        const double *w = r->whitened;
        size_t dim = r->b < FE_KALMAN_MONITOR_DIM ? r->b : FE_KALMAN_MONITOR_DIM;
        size_t slot = (size_t)(m->acf_steps % FE_KALMAN_MONITOR_LAGS);
        double s0 = 0.0;
        for (size_t i = 0; i < dim; i++)
            s0 += w[i] * w[i];
        m->acf[0] += s0;
        m->acf_terms[0] += dim;
        for (size_t l = 1; l <= m->par.lags && l <= m->acf_steps; l++) {
            size_t j = (size_t)((m->acf_steps - l) % FE_KALMAN_MONITOR_LAGS);
            size_t dj = m->ring_dim[j] < dim ? m->ring_dim[j] : dim;
            double s = 0.0;
            for (size_t i = 0; i < dj; i++)
                s += w[i] * m->ring[j][i];
            m->acf[l] += s;
            m->acf_terms[l] += dj;
        }
        for (size_t i = 0; i < dim; i++)
            m->ring[slot][i] = w[i];
        m->ring_dim[slot] = dim;
        m->acf_steps++;
    }
    lu = m->par.scale_up;
    ld = m->par.scale_down;
    fe__cusum(m, &m->cusum_up, &m->up_start,
              -0.5 * bd * log(lu) + 0.5 * r->nis * (1.0 - 1.0 / lu), +1);
    fe__cusum(m, &m->cusum_down, &m->down_start,
              -0.5 * bd * log(ld) + 0.5 * r->nis * (1.0 - 1.0 / ld), -1);
    return FE_OK;
}

double fe_kalman_monitor_mean_nis(const fe_kalman_monitor *m)
{
    return m->steps > 0 ? m->nis_sum / (double)m->steps : 0.0;
}

double fe_kalman_monitor_autocorr(const fe_kalman_monitor *m, size_t lag,
                                  uint64_t *terms)
{
    if (terms != NULL)
        *terms = 0;
    if (lag == 0 || lag > m->par.lags || m->acf_terms[lag] == 0
        || m->acf_terms[0] == 0 || !(m->acf[0] > 0.0))
        return NAN;
    if (terms != NULL)
        *terms = m->acf_terms[lag];
    return (m->acf[lag] / (double)m->acf_terms[lag])
         / (m->acf[0] / (double)m->acf_terms[0]);
}
/* Monitor the innovations ends here */
/* [[file:../literate/kalman.org::Compute the band of mean NIS][Compute the band of mean NIS]] */
int fe_kalman_monitor_nis_band(const fe_kalman_monitor *m, double prob,
                               double *lo, double *hi)
{
    double nu, steps;
    /* The upper level (1 + prob) / 2 must stay below 1: for the largest
       double below 1 it rounds to 1, whose quantile is infinite. */
    if (m == NULL || lo == NULL || hi == NULL || !(prob > 0.0 && 0.5 * (1.0 + prob) < 1.0))
        return FE_EINVAL;
    if (m->steps == 0)
        return FE_ETOOFEW;
    nu = (double)m->dof;
    steps = (double)m->steps;
    *lo = fe_chi2_quantile(0.5 * (1.0 - prob), nu) / steps;
    *hi = fe_chi2_quantile(0.5 * (1.0 + prob), nu) / steps;
    return FE_OK;
}
/* Compute the band of mean NIS ends here */
/* [[file:../literate/kalman.org::Kalman filters as accumulators][Kalman filters as accumulators]] */
static int fe__kalman_acc_init(void *acc, void *ctx)
{
    const fe_kalman_config *c = ctx;
    fe_kalman *k = acc;
    if (c == NULL)
        return FE_ENOTSUP;
    if (c->P0 != NULL)
        return fe_kalman_set_prior(k, c->x0, c->P0);
    return fe_kalman_set_prior_scaled(k, c->x0, c->p0);
}

static int fe__kalman_acc_step(void *acc, const void *obs, void *ctx)
{
    const fe_kalman_config *c = ctx;
    return c != NULL && c->fast ? fe_kalman_update_fast(acc, obs, NULL)
                                : fe_kalman_update(acc, obs, NULL);
}

static int fe__kalman_acc_track(void *acc, const void *obs, void *ctx)
{
    const fe_kalman_config *c = ctx;
    return c != NULL && c->fast ? fe_kalman_track_fast(acc, obs, NULL)
                                : fe_kalman_track(acc, obs, NULL);
}

static int fe__kalman_acc_copy(void *dst, const void *src, void *ctx)
{
    (void)ctx;
    return fe_kalman_copy(dst, src);
}

fe_accumulator fe_kalman_accumulator(const fe_kalman_config *cfg)
{
    fe_accumulator f = {
        .name = "kalman",
        .acc_size = sizeof(fe_kalman),
        .obs_size = sizeof(fe_kalman_obs),
        .init = fe__kalman_acc_init,
        .step = fe__kalman_acc_step,
        .step_many = 0,
        .merge = 0,
        .copy = fe__kalman_acc_copy,
        .ctx = (void *)cfg,
    };
    return f;
}

fe_accumulator fe_kalman_track_accumulator(const fe_kalman_config *cfg)
{
    fe_accumulator f = fe_kalman_accumulator(cfg);
    f.name = "kalman-track";
    f.obs_size = sizeof(fe_kalman_track_obs);
    f.step = fe__kalman_acc_track;
    return f;
}

static int fe__info_acc_init(void *acc, void *ctx)
{
    fe_kalman_info *s = acc;
    (void)ctx;
    if (!fe__info_usable(s))
        return FE_EINVAL;
    memset(s->eta, 0, s->n * sizeof *s->eta);
    memset(s->Lambda, 0, s->n * s->n * sizeof *s->Lambda);
    s->count = 0;
    return FE_OK;
}

static int fe__info_acc_step(void *acc, const void *obs, void *ctx)
{
    (void)ctx;
    return fe_kalman_info_update(acc, obs);
}

static int fe__info_acc_merge(void *acc, const void *other, void *ctx)
{
    (void)ctx;
    return fe_kalman_info_merge(acc, other);
}

static int fe__info_acc_copy(void *dst, const void *src, void *ctx)
{
    (void)ctx;
    return fe_kalman_info_copy(dst, src);
}

fe_accumulator fe_kalman_info_accumulator(void)
{
    fe_accumulator f = {
        .name = "kalman-info",
        .acc_size = sizeof(fe_kalman_info),
        .obs_size = sizeof(fe_kalman_obs),
        .init = fe__info_acc_init,
        .step = fe__info_acc_step,
        .step_many = 0,
        .merge = fe__info_acc_merge,
        .copy = fe__info_acc_copy,
        .ctx = 0,
    };
    return f;
}

static int fe__monitor_acc_init(void *acc, void *ctx)
{
    return fe_kalman_monitor_init(acc, ctx);
}

static int fe__monitor_acc_step(void *acc, const void *obs, void *ctx)
{
    (void)ctx;
    return fe_kalman_monitor_add(acc, obs);
}

fe_accumulator fe_kalman_monitor_accumulator(const fe_kalman_monitor_params *p)
{
    fe_accumulator f = {
        .name = "kalman-monitor",
        .acc_size = sizeof(fe_kalman_monitor),
        .obs_size = sizeof(fe_kalman_report),
        .init = fe__monitor_acc_init,
        .step = fe__monitor_acc_step,
        .step_many = 0,
        .merge = 0,
        .copy = 0,
        .ctx = (void *)p,
    };
    return f;
}
/* Kalman filters as accumulators ends here */
