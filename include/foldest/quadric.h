/* SPDX-License-Identifier: MIT */
/* Tangled from literate/quadric.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/quadric.org::Quadric Moment Declarations][Quadric Moment Declarations]] */
#ifndef FOLDEST_QUADRIC_H
#define FOLDEST_QUADRIC_H

#include <stddef.h>
#include <stdint.h>

#include "foldest/fold.h"

#ifdef __cplusplus
extern "C" {
#endif

enum {
    FE_QUADRIC_MOMENTS = 35,    /* monomials of degree <= 4 in 3 variables */
    FE_QUADRIC_REGIONS = 100    /* equal-area regions of the sphere */
};

/* Flags of an accumulation. */
enum {
    FE_QUADRIC_HAS_REF = 1,     /* ref[] is set (first sample, or supplied) */
    FE_QUADRIC_FIXED_REF = 2    /* ref[] was supplied: it is also the centre
                                   for coverage */
};

/* The sufficient statistics of every quadric fit of three-axis samples:
   moments of degree <= 4 of u = x - ref, per-axis extremes of x, and the
   regions visited (with the box size at the visit).  A flat value: copy
   it, store it, send it.  All zero bytes is the empty accumulation whose
   reference is its first sample. */
typedef struct fe_quadric {
    double m[FE_QUADRIC_MOMENTS];  /* m[0] = N; m[k] = sum of u^alpha_k */
    double ref[3];                 /* the reference point c */
    double lo[3], hi[3];           /* per-axis min and max of x (N > 0) */
    float seen[FE_QUADRIC_REGIONS];  /* box size when region r was last
                                      visited; 0: never */
    uint32_t flags;                /* FE_QUADRIC_HAS_REF, _FIXED_REF */
    uint32_t reserved;             /* zero */
} fe_quadric;

#define FE_QUADRIC_EMPTY {{0}, {0}, {0}, {0}, {0}, 0, 0}

/* fe_quadric_init: the empty accumulation.  `centre` NULL: the reference
   is the first sample and coverage is measured from the centre of the
   bounding box; otherwise `centre` (3 doubles, copied) is the reference
   and the centre for coverage.  FE_EINVAL for NULL q, FE_ENONFINITE for a
   non-finite centre. */
int fe_quadric_init(fe_quadric *q, const double *centre);

/* fe_quadric_add: fold one sample x[0..2].  FE_ENONFINITE when x is not
   finite or a moment would overflow; then q is unchanged.  No allocation,
   no libc: freestanding. */
int fe_quadric_add(fe_quadric *q, const double x[3]);

/* fe_quadric_add_many: fold the n samples x[3k..3k+2], faster than n
   calls of fe_quadric_add (blocks of 512, vector code where the compiler
   offers it), with the same result up to rounding of the moments (the
   extremes and the coverage are identical).  Stops at the first sample
   refused; *done (if not NULL) receives how many were folded. */
int fe_quadric_add_many(fe_quadric *q, const double *x, size_t n,
                        size_t *done);

/* fe_quadric_merge: a <- a (+) b.  b's moments are moved to a's
   reference (binomial expansion) and added; extremes and coverage combine.
   FE_ENONFINITE on overflow; then a is unchanged. */
int fe_quadric_merge(fe_quadric *a, const fe_quadric *b);

/* fe_quadric_recentre: move q's moments to the reference `ref`.  Cost:
   about 400 multiplications.  FE_ENONFINITE on overflow (q unchanged). */
int fe_quadric_recentre(fe_quadric *q, const double ref[3]);

/* fe_quadric_compare: how far apart two accumulations of the same samples
   are (a fold against a split, threaded or distributed fold of it):
   *apart receives the largest moment difference, each relative to the
   size N s^d its N terms can reach (d its degree, s the largest extent of
   b's box about the reference).  The exact parts must agree: FE_EMISMATCH
   when the counts, references or boxes differ; FE_EINVAL for NULL.  Both
   must hold the same reference (recentre one first).  No allocation. */
int fe_quadric_compare(const fe_quadric *a, const fe_quadric *b, double *apart);

/* fe_quadric_count: N.  fe_quadric_regions: the number of regions
   visited while the box was at least half its final size (its largest
   half-width).  fe_quadric_coverage: their fraction of 100, in [0, 1].
   Each reads a NULL q, as an empty one, as 0. */
uint64_t fe_quadric_count(const fe_quadric *q);
double fe_quadric_coverage(const fe_quadric *q);
int fe_quadric_regions(const fe_quadric *q);

/* fe_quadric_region: the region (0..99) of the direction v (any length),
   or -1 for v = 0 or non-finite.  Band = floor(5 (z/|v| + 1)), sector =
   floor(longitude / 36 degrees): region = 10 band + sector. */
int fe_quadric_region(const double v[3]);

/* fe_quadric_index: position in m[] of the moment sum u1^a u2^b u3^c, or
   -1 when a + b + c > 4.  fe_quadric_exponents: the inverse (k < 35). */
int fe_quadric_index(int a, int b, int c);
void fe_quadric_exponents(int k, int e[3]);

/* fe_quadric_accumulator: the accumulator for fe_fold and friends, over
   observations of 3 doubles and accumulations of type fe_quadric.
   `centre` (NULL, or 3 doubles that must outlive the descriptor) is given
   to fe_quadric_init by fe_init. */
fe_accumulator fe_quadric_accumulator(const double *centre);

/* Consecutive blocks in time, for standard errors that survive correlated
   samples (sphere.org, "Honest standard errors").  `all` is the ordinary
   accumulation of every sample; block[0..nblocks-1] hold consecutive runs
   of block_len samples (the last may be shorter).  When the slots are full
   neighbours merge pairwise and block_len doubles, so memory is constant
   (about 13 KB) and there are between 8 and 16 blocks once N >= 16. */
enum { FE_QUADRIC_BLOCKS = 16 };
typedef struct fe_quadric_blocks {
    fe_quadric all;
    fe_quadric block[FE_QUADRIC_BLOCKS];
    uint64_t block_len;         /* 1, 2, 4, ... (0 in an all-zero struct: 1) */
    uint32_t nblocks;           /* blocks begun */
    uint32_t reserved;          /* zero */
} fe_quadric_blocks;

/* fe_quadric_blocks_init: the empty blocked accumulation (references are
   first samples).  FE_EINVAL for NULL. */
int fe_quadric_blocks_init(fe_quadric_blocks *qb);

/* fe_quadric_blocks_add: fold x[0..2] into `all` and the current block.
   FE_ENONFINITE as fe_quadric_add; then qb is unchanged.  No allocation;
   cost: two steps and a copy of one block, and every block_len samples
   at most 16 merges. */
int fe_quadric_blocks_add(fe_quadric_blocks *qb, const double x[3]);

/* fe_quadric_blocks_add_many: fold the n samples x[3k..3k+2] as n calls
   of fe_quadric_blocks_add would: the same blocks, counts, extremes and
   coverage, the moments equal up to rounding (each block's run and `all`
   go through fe_quadric_add_many).  Stops at the first sample refused;
   *done (if not NULL) receives how many were folded, and qb holds exactly
   those.  FE_EINVAL for NULL.  No allocation; about 13 KB of stack. */
int fe_quadric_blocks_add_many(fe_quadric_blocks *qb, const double *x, size_t n,
                               size_t *done);

/* fe_quadric_blocks_merge: a <- a followed in time by b: the blocks of the
   one with shorter blocks merge pairwise until both have the same length,
   then b's are appended (merging pairwise again while there are more than
   FE_QUADRIC_BLOCKS).  FE_EINVAL for NULL, FE_ENONFINITE on overflow (a
   unchanged).  Uses about 26 KB of stack. */
int fe_quadric_blocks_merge(fe_quadric_blocks *a, const fe_quadric_blocks *b);

/* Single precision, for a microcontroller with a float FPU (Cortex-M4F):
   the same moments in float, of d = x - ref, with the reference moved to
   the running mean whenever the mean has drifted from it by more than a
   tenth of the box's largest half-width (an exact binomial shift).  No
   coverage (it would take 400 bytes).  188 bytes; all zero bytes is the
   empty accumulation whose reference is its first sample. */
typedef struct fe_quadric_f32 {
    float m[FE_QUADRIC_MOMENTS];   /* m[0] = N (rounded past 2^24); m[k] =
                                      sum of d^alpha_k, as in fe_quadric */
    float ref[3];                  /* the reference point c */
    float lo[3], hi[3];            /* per-axis min and max of x (N > 0) */
    uint32_t n;                    /* N, exact */
    uint32_t recentres;            /* times the step moved the reference */
    uint32_t flags;                /* FE_QUADRIC_HAS_REF */
} fe_quadric_f32;

#define FE_QUADRIC_F32_EMPTY {{0}, {0}, {0}, {0}, 0, 0, 0}

/* fe_quadric_f32_init: the empty accumulation; `centre` NULL: the first
   sample is the first reference, else centre[0..2] (copied).  FE_EINVAL
   for NULL q, FE_ENONFINITE for a non-finite centre (q unchanged). */
int fe_quadric_f32_init(fe_quadric_f32 *q, const float *centre);

/* fe_quadric_f32_add (step): fold one sample x[0..2], in float
   arithmetic only (no double, no libc: freestanding).  FE_EINVAL for
   NULL, FE_ENONFINITE when x is not finite or a sum would overflow,
   FE_ESIZE past 2^32 - 1 samples; then q is unchanged.  Cost: 34
   multiply-adds, and now and then (logarithmically often) a re-centre. */
int fe_quadric_f32_add(fe_quadric_f32 *q, const float x[3]);

/* fe_quadric_f32_recentre: move q's moments to the reference `ref` (the
   binomial shift, in float).  FE_EINVAL for NULL, FE_ENONFINITE for a
   non-finite ref or on overflow (q unchanged). */
int fe_quadric_f32_recentre(fe_quadric_f32 *q, const float ref[3]);

/* fe_quadric_from_f32 (read-out): the double accumulation holding f's
   moments, count, reference and box, for fe_sphere_fit_moments on the
   host; its coverage is empty (not measured).  FE_EINVAL for NULL. */
int fe_quadric_from_f32(fe_quadric *q, const fe_quadric_f32 *f);

#ifdef __cplusplus
}
#endif

#endif /* FOLDEST_QUADRIC_H */
/* Quadric Moment Declarations ends here */
