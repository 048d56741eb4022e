/* SPDX-License-Identifier: MIT */
/* Tangled from literate/lsq.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/lsq.org::Least Squares Declarations][Least Squares Declarations]] */
#ifndef FOLDEST_LSQ_H
#define FOLDEST_LSQ_H

#include <stddef.h>
#include <stdint.h>

#include "foldest/fold.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A sub-model column whose pivot ratio 1 - R^2 (its unexplained part,
   relative to its norm) is at or below this is treated as dependent. */
#define FE_LSQ_RANK_TOL 1e-12

/* The normal-equation accumulation of a least-squares problem with p
   columns: G = [J r]^T W [J r], (p+1) x (p+1), row-major in the caller's
   storage `g`; only the upper triangle (k <= l) is kept, the lower stays
   zero.  Index p is the response r.  n counts rows folded, wsum sums their
   weights.  The struct points into `g`: copy it with fe_lsq_copy (or
   fe_copy), not with `=`, to get an independent accumulation. */
typedef struct fe_lsq {
    size_t p;
    uint64_t n;
    double wsum;
    double *g;
} fe_lsq;

/* One row for the generic fold: p regressors at `j`, response r, weight w
   (use 1 for an unweighted fit; w >= 0). */
typedef struct fe_lsq_row {
    const double *j;
    double r;
    double w;
} fe_lsq_row;

/* fe_lsq_storage: the number of doubles `g` must hold, (p+1)^2. */
size_t fe_lsq_storage(size_t p);

/* fe_lsq_init: bind `a` to the caller's storage `g` (fe_lsq_storage(p)
   doubles, owned by the caller, must outlive `a`) and make it empty.
   p may be 0 (then only r^T W r is kept).  Errors: FE_EINVAL for nulls. */
int fe_lsq_init(fe_lsq *a, size_t p, double *g);

/* fe_lsq_reset: make a bound accumulation empty again. */
int fe_lsq_reset(fe_lsq *a);

/* fe_lsq_add: fold one row (j[0..p-1], r) with weight w.
   FE_ENONFINITE if j, r or w is not finite, or G would overflow;
   FE_EINVAL if w < 0 or a pointer is null.  On error `a` is unchanged.
   Cost: (p+1)(p+2)/2 multiply-adds. */
int fe_lsq_add(fe_lsq *a, const double *j, double r, double w);

/* fe_lsq_add_rows: fold m rows: row i is J[i*ldj .. i*ldj+p-1], r[i], and
   weight w[i] (w NULL: all weights 1).  Stops at the first row refused;
   `*done` (if not NULL) receives how many were folded.  Unweighted rows
   go through BLAS in blocks (equal to fe_lsq_add row by row up to
   rounding, several times faster for p >= 16).  Errors: those of
   fe_lsq_add for the row refused (the rows before it stay folded);
   FE_EINVAL, nothing folded, for a null a, a null r (or J, with p > 0)
   when m > 0, or ldj < p when m > 1 (one row needs no stride). */
int fe_lsq_add_rows(fe_lsq *a, const double *J, size_t ldj, const double *r,
                    const double *w, size_t m, size_t *done);

/* fe_lsq_add_sparse: fold one row whose only nonzero regressors are
   val[t] in columns idx[t], t < nnz (distinct, each < p), with response r
   and weight w.  The same result as fe_lsq_add on the dense row, at cost
   (nnz+1)(nnz+2)/2 instead of (p+1)(p+2)/2.  Errors as fe_lsq_add, and
   FE_EINVAL for an index out of range or repeated; `a` then unchanged. */
int fe_lsq_add_sparse(fe_lsq *a, const size_t *idx, const double *val,
                      size_t nnz, double r, double w);

/* fe_lsq_merge: a <- a + b (the rows of both).  FE_EMISMATCH if the
   column counts differ, FE_ENONFINITE if the sum would overflow; then `a`
   is unchanged.  `b` may not share storage with `a`. */
int fe_lsq_merge(fe_lsq *a, const fe_lsq *b);

/* fe_lsq_copy: dst's contents <- src's (dst bound to its own storage with
   the same p, else FE_EMISMATCH). */
int fe_lsq_copy(fe_lsq *dst, const fe_lsq *src);

/* fe_lsq_gram: G[k][l] for any 0 <= k, l <= p (symmetric read-out; index p
   is the response).  0 for indices out of range. */
double fe_lsq_gram(const fe_lsq *a, size_t k, size_t l);

/* fe_lsq_solve_work: doubles of workspace fe_lsq_solve needs for q
   columns: (q+1)^2. */
size_t fe_lsq_solve_work(size_t q);

/* fe_lsq_solve: fit the sub-model on columns cols[0..q-1] (distinct, each
   < p; cols NULL means 0..q-1) from the accumulation alone.  Writes, for
   the outputs that are not NULL: x[0..q-1] the coefficients, *rss the
   (weighted) residual sum of squares, cov[q*q] (row-major, full) the
   covariance sigma^2 A^{-1} with sigma^2 = rss / (n - q).  `work` holds
   fe_lsq_solve_work(q) doubles.  No allocation.
   Errors (nothing written): FE_EINVAL (nulls, q == 0, q > p, an index out
   of range or repeated), FE_ETOOFEW (no rows; or cov wanted and n <= q),
   FE_ESINGULAR (the columns are dependent to within FE_LSQ_RANK_TOL, or
   the solution is not finite), FE_EINTERNAL (LAPACK rejected an argument).
   Cost: q^3/3 flops (q^3 with cov). */
int fe_lsq_solve(const fe_lsq *a, const size_t *cols, size_t q, double *x,
                 double *rss, double *cov, double *work);

/* fe_lsq_scores_work: doubles of workspace fe_lsq_scores needs for a base
   of qb columns and nc candidates: qb*qb + qb*(nc+1). */
size_t fe_lsq_scores_work(size_t qb, size_t nc);

/* fe_lsq_scores: for the base model on columns base[0..qb-1] (qb may be 0)
   and each candidate column cand[i] (i < nc), score[i] = the drop in
   residual sum of squares from adding that one column to the base,
   c^2 / s with s = G_jj - G_jB G_BB^{-1} G_Bj and
   c = G_jr - G_jB G_BB^{-1} G_Br.  One Cholesky factorisation of G_BB and
   one triangular solve serve all candidates.  Optional outputs (NULL to
   skip): schur[i] = s for candidate i, *rss_base = RSS of the base.
   A candidate dependent on the base (s/G_jj <= FE_LSQ_RANK_TOL, including
   one that is in the base) scores 0; scores are clamped to [0, RSS_base].
   `work` holds fe_lsq_scores_work(qb, nc) doubles.
   Errors (nothing written): FE_EINVAL (nulls, an index out of range, a
   repeated base index), FE_ETOOFEW (no rows), FE_ESINGULAR (the base is
   dependent), FE_EINTERNAL.  Cost: qb^3/3 + qb^2 (nc+1) + nc qb flops. */
int fe_lsq_scores(const fe_lsq *a, const size_t *base, size_t qb,
                  const size_t *cand, size_t nc, double *score,
                  double *schur, double *rss_base, double *work);

/* fe_lsq_accumulator: the accumulator for fe_fold and friends, over
   observations of type fe_lsq_row and accumulations of type fe_lsq (bound
   by fe_lsq_init first: fe_init resets, fe_copy copies contents, fe_merge
   adds).  fe_scan is not supported (the accumulation points to storage). */
fe_accumulator fe_lsq_accumulator(void);

#ifdef __cplusplus
}
#endif

#endif /* FOLDEST_LSQ_H */
/* Least Squares Declarations ends here */
