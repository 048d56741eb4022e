/* SPDX-License-Identifier: MIT */
/* Tangled from literate/schur.org: do not edit; edit the .org and run make tangle. */
/* [[file:../literate/schur.org::Schur Includes][Schur Includes]] */
#include <float.h>
#include <math.h>
#include <string.h>

#include <cblas.h>
#include <lapacke.h>

#include "foldest/error.h"
#include "foldest/schur.h"

#define FE__SCHUR_BIG (DBL_MAX / 4)
/* Schur Includes ends here */
/* [[file:../literate/schur.org::Bind and reset a Schur accumulation][Bind and reset a Schur accumulation]] */
size_t fe_schur_block_size(size_t ng, size_t nl)
{
    return nl * nl + nl + nl * ng;
}

size_t fe_schur_storage(size_t ng, size_t nl, size_t nb)
{
    return fe_lsq_storage(ng) + nb * fe_schur_block_size(ng, nl);
}

int fe_schur_init(fe_schur *a, size_t ng, size_t nl, size_t nb,
                  double *storage)
{
    int rc;
    if (a == NULL || storage == NULL || ng + nl == 0)
        return FE_EINVAL;
    rc = fe_lsq_init(&a->global, ng, storage);
    if (rc != FE_OK)
        return rc;
    a->ng = ng;
    a->nl = nl;
    a->nb = nb;
    a->blk = storage + fe_lsq_storage(ng);
    return fe_schur_reset(a);
}

int fe_schur_reset(fe_schur *a)
{
    if (a == NULL || a->blk == NULL)
        return FE_EINVAL;
    memset(a->blk, 0, a->nb * fe_schur_block_size(a->ng, a->nl) * sizeof *a->blk);
    return fe_lsq_reset(&a->global);
}

/* Pointers to the parts of block b. */
static double *fe__schur_V(const fe_schur *a, size_t b)
{
    return a->blk + b * fe_schur_block_size(a->ng, a->nl);
}
static double *fe__schur_v(const fe_schur *a, size_t b)
{
    return fe__schur_V(a, b) + a->nl * a->nl;
}
static double *fe__schur_C(const fe_schur *a, size_t b)
{
    return fe__schur_v(a, b) + a->nl;
}
/* Bind and reset a Schur accumulation ends here */
/* [[file:../literate/schur.org::Fold one arrow row][Fold one arrow row]] */
int fe_schur_add(fe_schur *a, const double *jg, size_t block,
                 const double *jl, double r, double w)
{
    size_t nl, ng, k, l;
    double *V, *v, *C;
    int rc;

    if (a == NULL || a->blk == NULL || (jg == NULL && a->ng > 0))
        return FE_EINVAL;
    if (block != FE_SCHUR_NONE && (block >= a->nb || (jl == NULL && a->nl > 0)))
        return FE_EINVAL;
    nl = a->nl;
    ng = a->ng;
    if (block != FE_SCHUR_NONE) {
        if (!isfinite(w))
            return FE_ENONFINITE;
        V = fe__schur_V(a, block);
        for (k = 0; k < nl; k++) {
            if (!isfinite(jl[k]))
                return FE_ENONFINITE;
            if (!(V[k * nl + k] + w * jl[k] * jl[k] <= FE__SCHUR_BIG))
                return FE_ENONFINITE;
        }
    }
    rc = fe_lsq_add(&a->global, jg, r, w);
    if (rc != FE_OK || block == FE_SCHUR_NONE)
        return rc;
    V = fe__schur_V(a, block);
    v = fe__schur_v(a, block);
    C = fe__schur_C(a, block);
    for (k = 0; k < nl; k++) {
        double wk = w * jl[k];
        for (l = k; l < nl; l++)
            V[k * nl + l] += wk * jl[l];
        v[k] += wk * r;
        for (l = 0; l < ng; l++)
            C[k * ng + l] += wk * jg[l];
    }
    return FE_OK;
}
/* Fold one arrow row ends here */
/* [[file:../literate/schur.org::Merge and copy Schur accumulations][Merge and copy Schur accumulations]] */
static int fe__schur_same_shape(const fe_schur *a, const fe_schur *b)
{
    return a->ng == b->ng && a->nl == b->nl && a->nb == b->nb;
}

int fe_schur_merge(fe_schur *a, const fe_schur *b)
{
    size_t bs, nl, k, i;
    int rc;

    if (a == NULL || b == NULL || a->blk == NULL || b->blk == NULL)
        return FE_EINVAL;
    if (!fe__schur_same_shape(a, b))
        return FE_EMISMATCH;
    if (a->blk == b->blk)
        return FE_EINVAL;
    nl = a->nl;
    bs = fe_schur_block_size(a->ng, nl);
    for (i = 0; i < a->nb; i++) {
        const double *Va = fe__schur_V(a, i), *Vb = fe__schur_V(b, i);
        for (k = 0; k < nl; k++)
            if (!(Va[k * nl + k] + Vb[k * nl + k] <= FE__SCHUR_BIG))
                return FE_ENONFINITE;
    }
    rc = fe_lsq_merge(&a->global, &b->global);
    if (rc != FE_OK)
        return rc;
    for (i = 0; i < a->nb * bs; i++)
        a->blk[i] += b->blk[i];
    return FE_OK;
}

int fe_schur_copy(fe_schur *dst, const fe_schur *src)
{
    int rc;
    if (dst == NULL || src == NULL || dst->blk == NULL || src->blk == NULL)
        return FE_EINVAL;
    if (!fe__schur_same_shape(dst, src))
        return FE_EMISMATCH;
    rc = fe_lsq_copy(&dst->global, &src->global);
    if (rc == FE_OK && dst->blk != src->blk)
        memcpy(dst->blk, src->blk,
               src->nb * fe_schur_block_size(src->ng, src->nl) * sizeof *src->blk);
    return rc;
}
/* Merge and copy Schur accumulations ends here */
/* [[file:../literate/schur.org::Factor a damped block][Factor a damped block]] */
/* m (n x n, row-major, leading dimension ld, upper) holds a matrix whose
   diagonal is already damped.  Factor it in place: m = U'U. */
static int fe__schur_factor(double *m, size_t n, size_t ld)
{
    lapack_int info;
    for (size_t k = 0; k < n; k++)
        if (!(m[k * ld + k] > 0.0) || !isfinite(m[k * ld + k]))
            return FE_ESINGULAR;
    if (n == 0)
        return FE_OK;
    info = LAPACKE_dpotrf(LAPACK_COL_MAJOR, 'L', (lapack_int)n, m, (lapack_int)ld);
    if (info < 0)
        return FE_EINTERNAL;
    if (info > 0)
        return FE_ESINGULAR;
    return FE_OK;
}

/* Damp, factor and rank-check an n x n block copied from `src` (upper,
   leading dimension lds) into `m` (leading dimension n). */
static int fe__schur_factor_block(double *m, const double *src, size_t n,
                                  size_t lds, double lambda)
{
    int rc;
    for (size_t k = 0; k < n; k++)
        for (size_t l = k; l < n; l++)
            m[k * n + l] = src[k * lds + l];
    for (size_t k = 0; k < n; k++)
        m[k * n + k] *= 1.0 + lambda;
    rc = fe__schur_factor(m, n, n);
    if (rc != FE_OK)
        return rc;
    for (size_t k = 0; k < n; k++)
        if (!(m[k * n + k] * m[k * n + k]
              > FE_LSQ_RANK_TOL * src[k * lds + k] * (1.0 + lambda)))
            return FE_ESINGULAR;
    return FE_OK;
}
/* Factor a damped block ends here */
/* [[file:../literate/schur.org::Solve an arrow system by elimination][Solve an arrow system by elimination]] */
size_t fe_schur_solve_work(size_t ng, size_t nl)
{
    return ng * ng + nl * nl + nl * ng + nl;
}

int fe_schur_solve(const fe_schur *a, double lambda, double *x, double *rss,
                   double *work)
{
    size_t ng, nl, nb, d, k, l, b;
    double *S, *R, *Z, *z, bx, rr;
    const double *G;
    int rc;

    if (a == NULL || a->blk == NULL || x == NULL || work == NULL
        || !(lambda >= 0.0) || !isfinite(lambda))
        return FE_EINVAL;
    if (a->global.n == 0)
        return FE_ETOOFEW;
    ng = a->ng;
    nl = a->nl;
    nb = a->nb;
    d = ng + 1;
    G = a->global.g;
    S = work;
    R = S + ng * ng;
    Z = R + nl * nl;
    z = Z + nl * ng;
    if (nl == 0)
        nb = 0;                 /* no local parameters: nothing to eliminate */

    /* S = U (damped), t = u (in x[0..ng-1]). */
    for (k = 0; k < ng; k++) {
        for (l = k; l < ng; l++)
            S[k * ng + l] = G[k * d + l];
        S[k * ng + k] *= 1.0 + lambda;
        x[k] = G[k * d + ng];
    }

    /* 1. Eliminate each block: S -= Z'Z, t -= Z'z with Z = R^{-T} C. */
    for (b = 0; b < nb; b++) {
        const double *V = fe__schur_V(a, b), *v = fe__schur_v(a, b),
                     *C = fe__schur_C(a, b);
        rc = fe__schur_factor_block(R, V, nl, nl, lambda);
        if (rc != FE_OK)
            return rc;
        if (ng == 0)
            continue;
        memcpy(Z, C, nl * ng * sizeof *Z);
        memcpy(z, v, nl * sizeof *z);
        cblas_dtrsm(CblasRowMajor, CblasLeft, CblasUpper, CblasTrans,
                    CblasNonUnit, (int)nl, (int)ng, 1.0, R, (int)nl, Z, (int)ng);
        cblas_dtrsv(CblasRowMajor, CblasUpper, CblasTrans, CblasNonUnit,
                    (int)nl, R, (int)nl, z, 1);
        cblas_dsyrk(CblasRowMajor, CblasUpper, CblasTrans, (int)ng, (int)nl,
                    -1.0, Z, (int)ng, 1.0, S, (int)ng);
        cblas_dgemv(CblasRowMajor, CblasTrans, (int)nl, (int)ng, -1.0, Z,
                    (int)ng, z, 1, 1.0, x, 1);
    }

    /* 2. Solve S dg = t.  Pivots are compared with the damped diagonal of
       U: a global direction that the blocks explain entirely is singular. */
    if (ng > 0) {
        lapack_int info;
        rc = fe__schur_factor(S, ng, ng);
        if (rc != FE_OK)
            return rc;
        for (k = 0; k < ng; k++)
            if (!(S[k * ng + k] * S[k * ng + k]
                  > FE_LSQ_RANK_TOL * G[k * d + k] * (1.0 + lambda)))
                return FE_ESINGULAR;
        info = LAPACKE_dpotrs(LAPACK_COL_MAJOR, 'L', (lapack_int)ng, 1, S,
                              (lapack_int)ng, x, (lapack_int)ng);
        if (info != 0)
            return FE_EINTERNAL;
    }

    /* 3. Back-substitute: dl_b = V_b^{-1} (v_b - C_b dg). */
    for (b = 0; b < nb; b++) {
        const double *V = fe__schur_V(a, b), *v = fe__schur_v(a, b),
                     *C = fe__schur_C(a, b);
        double *xl = x + ng + b * nl;
        lapack_int info;
        rc = fe__schur_factor_block(R, V, nl, nl, lambda);
        if (rc != FE_OK)
            return rc;
        memcpy(xl, v, nl * sizeof *xl);
        if (ng > 0)
            cblas_dgemv(CblasRowMajor, CblasNoTrans, (int)nl, (int)ng, -1.0, C,
                        (int)ng, x, 1, 1.0, xl, 1);
        info = LAPACKE_dpotrs(LAPACK_COL_MAJOR, 'L', (lapack_int)nl, 1, R,
                              (lapack_int)nl, xl, (lapack_int)nl);
        if (info != 0)
            return FE_EINTERNAL;
    }

    /* The solution must be finite; rss = r'Wr - x'b. */
    bx = 0.0;
    for (k = 0; k < ng; k++)
        bx += x[k] * G[k * d + ng];
    for (b = 0; b < nb; b++)
        for (k = 0; k < nl; k++)
            bx += x[ng + b * nl + k] * fe__schur_v(a, b)[k];
    if (!isfinite(bx))
        return FE_ESINGULAR;
    rr = G[ng * d + ng];
    if (rss != NULL)
        *rss = rr - bx > 0.0 ? rr - bx : 0.0;
    return FE_OK;
}
/* Solve an arrow system by elimination ends here */
/* [[file:../literate/schur.org::Schur accumulation as an accumulator][Schur accumulation as an accumulator]] */
static int fe__schur_init(void *acc, void *ctx)
{
    (void)ctx;
    return fe_schur_reset(acc);
}

static int fe__schur_step(void *acc, const void *obs, void *ctx)
{
    const fe_schur_row *row = obs;
    (void)ctx;
    return fe_schur_add(acc, row->jg, row->block, row->jl, row->r, row->w);
}

static int fe__schur_merge(void *acc, const void *other, void *ctx)
{
    (void)ctx;
    return fe_schur_merge(acc, other);
}

static int fe__schur_copy(void *dst, const void *src, void *ctx)
{
    (void)ctx;
    return fe_schur_copy(dst, src);
}

fe_accumulator fe_schur_accumulator(void)
{
    fe_accumulator f = {
        .name = "schur",
        .acc_size = sizeof(fe_schur),
        .obs_size = sizeof(fe_schur_row),
        .init = fe__schur_init,
        .step = fe__schur_step,
        .step_many = 0,
        .merge = fe__schur_merge,
        .copy = fe__schur_copy,
        .ctx = 0,
    };
    return f;
}
/* Schur accumulation as an accumulator ends here */
