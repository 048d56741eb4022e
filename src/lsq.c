/* SPDX-License-Identifier: MIT */
/* Tangled from literate/lsq.org: do not edit; edit the .org and run make tangle. */
/* [[file:../literate/lsq.org::Least Squares Includes][Least Squares Includes]] */
#include <float.h>
#include <math.h>
#include <string.h>

#include <cblas.h>
#include <lapacke.h>

#include "foldest/error.h"
#include "foldest/lsq.h"

/* Bound on the diagonal of G; off-diagonals are bounded by it. */
#define FE__LSQ_BIG (DBL_MAX / 4)

/* Rows per BLAS block in fe_lsq_add_rows. */
enum { FE__LSQ_BLOCK = 256 };
/* Least Squares Includes ends here */
/* [[file:../literate/lsq.org::Bind, reset and read an accumulation][Bind, reset and read an accumulation]] */
size_t fe_lsq_storage(size_t p)
{
    return (p + 1) * (p + 1);
}

int fe_lsq_init(fe_lsq *a, size_t p, double *g)
{
    if (a == NULL || g == NULL)
        return FE_EINVAL;
    a->p = p;
    a->g = g;
    return fe_lsq_reset(a);
}

int fe_lsq_reset(fe_lsq *a)
{
    if (a == NULL || a->g == NULL)
        return FE_EINVAL;
    memset(a->g, 0, fe_lsq_storage(a->p) * sizeof *a->g);
    a->n = 0;
    a->wsum = 0.0;
    return FE_OK;
}

double fe_lsq_gram(const fe_lsq *a, size_t k, size_t l)
{
    size_t d = a->p + 1;
    if (k >= d || l >= d)
        return 0.0;
    return k <= l ? a->g[k * d + l] : a->g[l * d + k];
}
/* Bind, reset and read an accumulation ends here */
/* [[file:../literate/lsq.org::Fold one row][Fold one row]] */
int fe_lsq_add(fe_lsq *a, const double *j, double r, double w)
{
    size_t p, d, k, l;
    double *g;

    if (a == NULL || a->g == NULL || (j == NULL && a->p > 0))
        return FE_EINVAL;
    if (!isfinite(w) || !isfinite(r))
        return FE_ENONFINITE;
    if (w < 0.0)
        return FE_EINVAL;
    p = a->p;
    d = p + 1;
    g = a->g;
    for (k = 0; k < p; k++)
        if (!isfinite(j[k]))
            return FE_ENONFINITE;
    /* Refuse a row that would overflow a diagonal entry. */
    for (k = 0; k < d; k++) {
        double v = k < p ? j[k] : r;
        if (!(g[k * d + k] + w * v * v <= FE__LSQ_BIG))
            return FE_ENONFINITE;
    }
    if (!(a->wsum + w <= FE__LSQ_BIG))
        return FE_ENONFINITE;
    for (k = 0; k < d; k++) {
        double wk = w * (k < p ? j[k] : r);
        double *gk = g + k * d;
        for (l = k; l < p; l++)
            gk[l] += wk * j[l];
        gk[p] += wk * r;
    }
    a->n++;
    a->wsum += w;
    return FE_OK;
}
/* Fold one row ends here */
/* [[file:../literate/lsq.org::Fold an array of rows by blocks][Fold an array of rows by blocks]] */
/* Fold rows i0 .. i0+mb-1 of an unweighted block at once, or return an
   error without writing when any of them would be refused. */
static int fe__lsq_add_block(fe_lsq *a, const double *J, size_t ldj,
                             const double *r, size_t mb)
{
    size_t p = a->p, d = p + 1, i, k;
    double rr = 0.0;
    double *g = a->g;

    /* Finite values, and the guard on every new diagonal entry (a NaN or
       an infinity makes its column's sum fail the test). */
    for (i = 0; i < mb; i++)
        rr += r[i] * r[i];
    if (!(g[p * d + p] + rr <= FE__LSQ_BIG) || !(a->wsum + (double)mb <= FE__LSQ_BIG))
        return FE_ENONFINITE;
    for (k = 0; k < p; k++) {
        double ss = 0.0;
        for (i = 0; i < mb; i++)
            ss += J[i * ldj + k] * J[i * ldj + k];
        if (!(g[k * d + k] + ss <= FE__LSQ_BIG))
            return FE_ENONFINITE;
    }
    /* G_JJ += J'J, G_Jr += J'r, G_rr += r'r. */
    cblas_dsyrk(CblasRowMajor, CblasUpper, CblasTrans, (int)p, (int)mb, 1.0, J,
                (int)ldj, 1.0, g, (int)d);
    cblas_dgemv(CblasRowMajor, CblasTrans, (int)mb, (int)p, 1.0, J, (int)ldj, r, 1,
                1.0, g + p, (int)d);
    g[p * d + p] += rr;
    a->n += mb;
    a->wsum += (double)mb;
    return FE_OK;
}

int fe_lsq_add_rows(fe_lsq *a, const double *J, size_t ldj, const double *r,
                    const double *w, size_t m, size_t *done)
{
    size_t i = 0;
    int rc = FE_OK;

    if (done != NULL)
        *done = 0;
    if (a == NULL || a->g == NULL
        || (m > 0 && (r == NULL || (J == NULL && a->p > 0)))
        || (m > 1 && ldj < a->p))
        return FE_EINVAL;
    while (i < m) {
        size_t mb = m - i < FE__LSQ_BLOCK ? m - i : FE__LSQ_BLOCK, end;
        /* Unweighted blocks go to BLAS when nothing in them is refused. */
        if (w == NULL && a->p > 0 && ldj >= a->p
            && fe__lsq_add_block(a, J + i * ldj, ldj, r + i, mb) == FE_OK) {
            i += mb;
            continue;
        }
        for (end = i + mb; i < end; i++) {
            rc = fe_lsq_add(a, a->p > 0 ? J + i * ldj : NULL, r[i],
                            w != NULL ? w[i] : 1.0);
            if (rc != FE_OK)
                break;
        }
        if (rc != FE_OK)
            break;
    }
    if (done != NULL)
        *done = i;
    return rc;
}
/* Fold an array of rows by blocks ends here */
/* [[file:../literate/lsq.org::Fold one sparse row][Fold one sparse row]] */
int fe_lsq_add_sparse(fe_lsq *a, const size_t *idx, const double *val,
                      size_t nnz, double r, double w)
{
    size_t d, s, t;
    double *g;

    if (a == NULL || a->g == NULL || (nnz > 0 && (idx == NULL || val == NULL)))
        return FE_EINVAL;
    if (!isfinite(w) || !isfinite(r))
        return FE_ENONFINITE;
    if (w < 0.0)
        return FE_EINVAL;
    d = a->p + 1;
    g = a->g;
    for (s = 0; s < nnz; s++) {
        if (idx[s] >= a->p)
            return FE_EINVAL;
        for (t = 0; t < s; t++)
            if (idx[t] == idx[s])
                return FE_EINVAL;
        if (!isfinite(val[s]))
            return FE_ENONFINITE;
    }
    for (s = 0; s <= nnz; s++) {
        size_t k = s < nnz ? idx[s] : a->p;
        double v = s < nnz ? val[s] : r;
        if (!(g[k * d + k] + w * v * v <= FE__LSQ_BIG))
            return FE_ENONFINITE;
    }
    if (!(a->wsum + w <= FE__LSQ_BIG))
        return FE_ENONFINITE;
    for (s = 0; s <= nnz; s++) {
        size_t k = s < nnz ? idx[s] : a->p;
        double vs = s < nnz ? val[s] : r;
        for (t = s; t <= nnz; t++) {
            size_t l = t < nnz ? idx[t] : a->p;
            double vt = t < nnz ? val[t] : r;
            if (k <= l)
                g[k * d + l] += (w * vs) * vt;
            else
                g[l * d + k] += (w * vt) * vs;
        }
    }
    a->n++;
    a->wsum += w;
    return FE_OK;
}
/* Fold one sparse row ends here */
/* [[file:../literate/lsq.org::Merge and copy accumulations][Merge and copy accumulations]] */
int fe_lsq_merge(fe_lsq *a, const fe_lsq *b)
{
    size_t d, k, l;

    if (a == NULL || b == NULL || a->g == NULL || b->g == NULL)
        return FE_EINVAL;
    if (a->p != b->p)
        return FE_EMISMATCH;
    if (a->g == b->g)
        return FE_EINVAL;
    d = a->p + 1;
    for (k = 0; k < d; k++)
        if (!(a->g[k * d + k] + b->g[k * d + k] <= FE__LSQ_BIG))
            return FE_ENONFINITE;
    if (!(a->wsum + b->wsum <= FE__LSQ_BIG))
        return FE_ENONFINITE;
    for (k = 0; k < d; k++)
        for (l = k; l < d; l++)
            a->g[k * d + l] += b->g[k * d + l];
    a->n += b->n;
    a->wsum += b->wsum;
    return FE_OK;
}

int fe_lsq_copy(fe_lsq *dst, const fe_lsq *src)
{
    if (dst == NULL || src == NULL || dst->g == NULL || src->g == NULL)
        return FE_EINVAL;
    if (dst->p != src->p)
        return FE_EMISMATCH;
    if (dst->g != src->g)
        memcpy(dst->g, src->g, fe_lsq_storage(src->p) * sizeof *src->g);
    dst->n = src->n;
    dst->wsum = src->wsum;
    return FE_OK;
}
/* Merge and copy accumulations ends here */
/* [[file:../literate/lsq.org::Check a column list][Check a column list]] */
/* FE_OK when cols[0..q-1] are distinct and below p (cols NULL: 0..q-1). */
static int fe__lsq_check_cols(const size_t *cols, size_t q, size_t p)
{
    if (cols == NULL)
        return q <= p ? FE_OK : FE_EINVAL;
    for (size_t k = 0; k < q; k++) {
        if (cols[k] >= p)
            return FE_EINVAL;
        for (size_t l = 0; l < k; l++)
            if (cols[l] == cols[k])
                return FE_EINVAL;
    }
    return FE_OK;
}

static size_t fe__lsq_col(const size_t *cols, size_t k)
{
    return cols != NULL ? cols[k] : k;
}
/* Check a column list ends here */
/* [[file:../literate/lsq.org::Factor a sub-Gram matrix and check its rank][Factor a sub-Gram matrix and check its rank]] */
/* Cholesky factor U (upper) of the q x q matrix at m, leading dimension
   ld, in place.  A zero or negative diagonal entry, or a failed
   factorisation, is FE_ESINGULAR; the caller checks the pivots. */
static int fe__lsq_factor(double *m, size_t q, size_t ld)
{
    lapack_int info;
    for (size_t k = 0; k < q; k++)
        if (!(m[k * ld + k] > 0.0))
            return FE_ESINGULAR;
    info = LAPACKE_dpotrf(LAPACK_COL_MAJOR, 'L', (lapack_int)q, m,
                          (lapack_int)ld);
    if (info < 0)
        return FE_EINTERNAL;
    if (info > 0)
        return FE_ESINGULAR;
    return FE_OK;
}
/* Factor a sub-Gram matrix and check its rank ends here */
/* [[file:../literate/lsq.org::Solve a sub-model][Solve a sub-model]] */
size_t fe_lsq_solve_work(size_t q)
{
    return (q + 1) * (q + 1);
}

int fe_lsq_solve(const fe_lsq *a, const size_t *cols, size_t q, double *x,
                 double *rss, double *cov, double *work)
{
    size_t m = q + 1, k, l, p;
    double rr, zz, s2;
    int rc;

    if (a == NULL || a->g == NULL || work == NULL || q == 0 || q > a->p)
        return FE_EINVAL;
    p = a->p;
    rc = fe__lsq_check_cols(cols, q, p);
    if (rc != FE_OK)
        return rc;
    if (a->n == 0 || (cov != NULL && a->n <= q))
        return FE_ETOOFEW;

    /* Gather the augmented matrix [A b; b' rr], upper triangle. */
    for (k = 0; k < q; k++) {
        size_t ck = fe__lsq_col(cols, k);
        for (l = k; l < q; l++)
            work[k * m + l] = fe_lsq_gram(a, ck, fe__lsq_col(cols, l));
        work[k * m + q] = fe_lsq_gram(a, ck, p);
    }
    rr = fe_lsq_gram(a, p, p);

    /* Factor A = U'U; a pivot with 1 - R^2 below tolerance is dependence. */
    rc = fe__lsq_factor(work, q, m);
    if (rc != FE_OK)
        return rc;
    for (k = 0; k < q; k++) {
        size_t ck = fe__lsq_col(cols, k);
        double u = work[k * m + k];
        if (!(u * u > FE_LSQ_RANK_TOL * fe_lsq_gram(a, ck, ck)))
            return FE_ESINGULAR;
    }

    /* z = U^{-T} b in the last column; RSS = rr - |z|^2; x = U^{-1} z. */
    cblas_dtrsv(CblasRowMajor, CblasUpper, CblasTrans, CblasNonUnit,
                (int)q, work, (int)m, work + q, (int)m);
    zz = 0.0;
    for (k = 0; k < q; k++)
        zz += work[k * m + q] * work[k * m + q];
    cblas_dtrsv(CblasRowMajor, CblasUpper, CblasNoTrans, CblasNonUnit,
                (int)q, work, (int)m, work + q, (int)m);
    for (k = 0; k < q; k++)
        if (!isfinite(work[k * m + q]))
            return FE_ESINGULAR;
    s2 = rr - zz > 0.0 ? rr - zz : 0.0;

    /* Cov = sigma^2 A^{-1}, A^{-1} = U^{-1} U^{-T} by dpotri. */
    if (cov != NULL) {
        double sigma2 = s2 / (double)(a->n - q);
        lapack_int info = LAPACKE_dpotri(LAPACK_COL_MAJOR, 'L', (lapack_int)q,
                                         work, (lapack_int)m);
        if (info < 0)
            return FE_EINTERNAL;
        if (info > 0)
            return FE_ESINGULAR;
        for (k = 0; k < q; k++)
            for (l = k; l < q; l++)
                if (!isfinite(work[k * m + l] * sigma2))
                    return FE_ESINGULAR;
        for (k = 0; k < q; k++)
            for (l = k; l < q; l++)
                cov[k * q + l] = cov[l * q + k] = sigma2 * work[k * m + l];
    }
    if (x != NULL)
        for (k = 0; k < q; k++)
            x[k] = work[k * m + q];
    if (rss != NULL)
        *rss = s2;
    return FE_OK;
}
/* Solve a sub-model ends here */
/* [[file:../literate/lsq.org::Score candidate columns against a base][Score candidate columns against a base]] */
size_t fe_lsq_scores_work(size_t qb, size_t nc)
{
    return qb * qb + qb * (nc + 1);
}

int fe_lsq_scores(const fe_lsq *a, const size_t *base, size_t qb,
                  const size_t *cand, size_t nc, double *score,
                  double *schur, double *rss_base, double *work)
{
    size_t p, w1, k, i;
    double *u, *z, rr, zr, rssb;
    int rc;

    if (a == NULL || a->g == NULL || (qb > 0 && (base == NULL || work == NULL))
        || (nc > 0 && (cand == NULL || score == NULL)) || qb > a->p)
        return FE_EINVAL;
    p = a->p;
    rc = fe__lsq_check_cols(base, qb, p);
    if (rc != FE_OK)
        return rc;
    for (i = 0; i < nc; i++)
        if (cand[i] >= p)
            return FE_EINVAL;
    if (a->n == 0)
        return FE_ETOOFEW;
    w1 = nc + 1;
    u = work;
    z = qb > 0 ? work + qb * qb : NULL;
    rr = fe_lsq_gram(a, p, p);

    /* Factor G_BB = U'U and check the base's rank. */
    for (k = 0; k < qb; k++)
        for (size_t l = k; l < qb; l++)
            u[k * qb + l] = fe_lsq_gram(a, base[k], base[l]);
    if (qb > 0) {
        rc = fe__lsq_factor(u, qb, qb);
        if (rc != FE_OK)
            return rc;
        for (k = 0; k < qb; k++)
            if (!(u[k * qb + k] * u[k * qb + k]
                  > FE_LSQ_RANK_TOL * fe_lsq_gram(a, base[k], base[k])))
                return FE_ESINGULAR;
        /* Z = U^{-T} [G_B,cand  G_Br]: all candidates in one solve. */
        for (k = 0; k < qb; k++) {
            for (i = 0; i < nc; i++)
                z[k * w1 + i] = fe_lsq_gram(a, base[k], cand[i]);
            z[k * w1 + nc] = fe_lsq_gram(a, base[k], p);
        }
        cblas_dtrsm(CblasRowMajor, CblasLeft, CblasUpper, CblasTrans,
                    CblasNonUnit, (int)qb, (int)w1, 1.0, u, (int)qb, z,
                    (int)w1);
    }
    zr = 0.0;
    for (k = 0; k < qb; k++)
        zr += z[k * w1 + nc] * z[k * w1 + nc];
    rssb = rr - zr > 0.0 ? rr - zr : 0.0;
    if (!isfinite(rssb))
        return FE_ESINGULAR;

    /* s_j = G_jj - |z_j|^2, c_j = G_jr - z_j'z_r, score c^2/s. */
    for (i = 0; i < nc; i++) {
        size_t j = cand[i];
        double gjj = fe_lsq_gram(a, j, j), s = gjj, c = fe_lsq_gram(a, j, p);
        double sc = 0.0;
        for (k = 0; k < qb; k++) {
            s -= z[k * w1 + i] * z[k * w1 + i];
            c -= z[k * w1 + i] * z[k * w1 + nc];
        }
        if (s > FE_LSQ_RANK_TOL * gjj && isfinite(c * c / s)) {
            sc = c * c / s;
            if (sc > rssb)
                sc = rssb;
        }
        score[i] = sc;
        if (schur != NULL)
            schur[i] = s > 0.0 ? s : 0.0;
    }
    if (rss_base != NULL)
        *rss_base = rssb;
    return FE_OK;
}
/* Score candidate columns against a base ends here */
/* [[file:../literate/lsq.org::Least squares as an accumulator][Least squares as an accumulator]] */
static int fe__lsq_init(void *acc, void *ctx)
{
    (void)ctx;
    return fe_lsq_reset(acc);
}

static int fe__lsq_step(void *acc, const void *obs, void *ctx)
{
    const fe_lsq_row *row = obs;
    (void)ctx;
    return fe_lsq_add(acc, row->j, row->r, row->w);
}

static int fe__lsq_merge(void *acc, const void *other, void *ctx)
{
    (void)ctx;
    return fe_lsq_merge(acc, other);
}

static int fe__lsq_copy(void *dst, const void *src, void *ctx)
{
    (void)ctx;
    return fe_lsq_copy(dst, src);
}

fe_accumulator fe_lsq_accumulator(void)
{
    fe_accumulator f = {
        .name = "lsq",
        .acc_size = sizeof(fe_lsq),
        .obs_size = sizeof(fe_lsq_row),
        .init = fe__lsq_init,
        .step = fe__lsq_step,
        .step_many = 0,
        .merge = fe__lsq_merge,
        .copy = fe__lsq_copy,
        .ctx = 0,
    };
    return f;
}
/* Least squares as an accumulator ends here */
