/* SPDX-License-Identifier: MIT */
/* Tangled from literate/schur.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/schur.org::Schur Declarations][Schur Declarations]] */
#ifndef FOLDEST_SCHUR_H
#define FOLDEST_SCHUR_H

#include <stddef.h>
#include <stdint.h>

#include "foldest/fold.h"
#include "foldest/lsq.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The block index of a row that touches no local block. */
#define FE_SCHUR_NONE ((size_t)-1)

/* The normal-equation accumulation of an arrow-shaped problem: ng global
   parameters and nb local blocks of nl parameters.  `global` is the
   augmented Gram matrix of the global columns (U, u, r'Wr; it counts every
   row and holds the weight sum); `blk` holds nb blocks of
   fe_schur_block_size(ng, nl) doubles each: V_b (nl x nl, upper triangle,
   row-major), v_b (nl), C_b (nl x ng, row-major).  All in the caller's
   storage; copy with fe_schur_copy, not `=`. */
typedef struct fe_schur {
    size_t ng, nl, nb;
    fe_lsq global;
    double *blk;
} fe_schur;

/* One row for the generic fold: jg[0..ng-1], the block index (or
   FE_SCHUR_NONE) and jl[0..nl-1], response r, weight w (1: unweighted). */
typedef struct fe_schur_row {
    const double *jg;
    size_t block;
    const double *jl;
    double r;
    double w;
} fe_schur_row;

/* Doubles per local block: nl*nl + nl + nl*ng. */
size_t fe_schur_block_size(size_t ng, size_t nl);

/* fe_schur_storage: doubles of storage for the whole accumulation:
   (ng+1)^2 + nb * fe_schur_block_size(ng, nl). */
size_t fe_schur_storage(size_t ng, size_t nl, size_t nb);

/* fe_schur_init: bind `a` to `storage` (fe_schur_storage doubles, owned by
   the caller, must outlive `a`) and make it empty.  FE_EINVAL for nulls or
   ng + nl == 0. */
int fe_schur_init(fe_schur *a, size_t ng, size_t nl, size_t nb,
                  double *storage);

/* fe_schur_reset: make a bound accumulation empty again. */
int fe_schur_reset(fe_schur *a);

/* fe_schur_add: fold one row.  FE_EINVAL for a null jg (ng > 0), a block
   index >= nb (other than FE_SCHUR_NONE), a null jl with a block, w < 0;
   FE_ENONFINITE for a non-finite value or an overflow.  On error `a` is
   unchanged.  Cost: (ng+1)(ng+2)/2 + nl(nl+1)/2 + nl(ng+1) multiply-adds. */
int fe_schur_add(fe_schur *a, const double *jg, size_t block,
                 const double *jl, double r, double w);

/* fe_schur_merge: a <- a + b.  FE_EMISMATCH for different shapes,
   FE_ENONFINITE on overflow; then `a` is unchanged. */
int fe_schur_merge(fe_schur *a, const fe_schur *b);

/* fe_schur_copy: dst's contents <- src's (same shape, own storage). */
int fe_schur_copy(fe_schur *dst, const fe_schur *src);

/* fe_schur_solve_work: doubles of workspace for fe_schur_solve:
   ng*ng + nl*nl + nl*ng + nl (independent of the number of blocks). */
size_t fe_schur_solve_work(size_t ng, size_t nl);

/* fe_schur_solve: solve (A + lambda diag(A)) x = J'W r by eliminating the
   local blocks: x[0..ng-1] the global part, x[ng + b*nl ..] block b.
   lambda >= 0 (0: the least-squares solution).  *rss (if not NULL)
   receives r'Wr - x'J'Wr, clamped at 0 (the residual sum of squares when
   lambda == 0).  `work` holds fe_schur_solve_work(ng, nl) doubles.
   Errors: FE_EINVAL (nulls, lambda < 0 or not finite), FE_ETOOFEW (no
   rows), FE_ESINGULAR (a block or the reduced system is singular to within
   FE_LSQ_RANK_TOL, or a damped diagonal A_kk (1 + lambda) overflows; x
   is then unspecified), FE_EINTERNAL.
   Cost: O(nb (nl^3 + nl^2 ng + nl ng^2) + ng^3). */
int fe_schur_solve(const fe_schur *a, double lambda, double *x, double *rss,
                   double *work);

/* fe_schur_accumulator: the accumulator for fe_fold and friends over
   fe_schur_row observations and fe_schur accumulations (bound first with
   fe_schur_init).  Merges; fe_scan is not supported. */
fe_accumulator fe_schur_accumulator(void);

#ifdef __cplusplus
}
#endif

#endif /* FOLDEST_SCHUR_H */
/* Schur Declarations ends here */
