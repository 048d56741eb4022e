/* SPDX-License-Identifier: MIT */
/* Tangled from literate/locate.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/locate.org::Locate Declarations][Locate Declarations]] */
#ifndef FOLDEST_LOCATE_H
#define FOLDEST_LOCATE_H

#include <stddef.h>
#include <stdint.h>

#include "foldest/discover.h"
#include "foldest/kalman.h"

#ifdef __cplusplus
extern "C" {
#endif

/* One located time window.  The statistics are on the standard normal
   scale. */
typedef struct fe_located {
    int is_time;                /* 1: a time window (the only kind located
                                   from innovations; the command's own list
                                   also has regions of the state) */
    const char *test;           /* what located it: "nis", "innovation_acf" */
    double t0, t1;              /* time of its first and last row */
    int pair, pair1;            /* recordings (from 0) of those rows */
    double n;                   /* rows (Kalman reports) in it */
    double z;                   /* largest NIS statistic of its blocks */
    double t;                   /* autocorrelation statistic largest in size */
    double p_value;             /* smallest block p-value (before Bonferroni) */
    double mean_nis;            /* pooled NIS per degree of freedom (1: right) */
    double lag1;                /* pooled lag-one autocorrelation (0: right) */
} fe_located;

/* fe_located_json: `l` as a JSON object of the discover command's
   "located" array, NUL-terminated in buf.  FE_ESIZE when it does not fit
   (buf then holds a truncated prefix); FE_EINVAL on NULL. */
int fe_located_json(const fe_located *l, char *buf, size_t len);

/* The innovations of a Kalman filter in K time blocks. */
typedef struct fe_innovation_block {
    double n;                   /* reports */
    double dof, nis;            /* sums of b and of the NIS */
    double acf, acf_terms;      /* lag-one products w_i . w_{i-1}, their count */
    double sq, sq_terms;        /* squares |w_i|^2, their count */
    double t0, t1;              /* first and last time */
    int pair, pair1;            /* recordings of the first and last report */
} fe_innovation_block;

typedef struct fe_innovations {
    size_t blocks;              /* K */
    uint64_t total;             /* reports expected in all */
    uint64_t row0;              /* global index of this part's first report */
    uint64_t n;                 /* reports folded into this part */
    int recording;              /* current recording (from 0 in this part) */
    int have_prev;              /* a whitened vector to pair with */
    int first_linked;           /* the first report follows the previous part */
    size_t prev_dim, first_dim;
    double prev[FE_KALMAN_MONITOR_DIM];     /* the last whitened vector */
    double first[FE_KALMAN_MONITOR_DIM];    /* the first one (for merge) */
    fe_innovation_block block[FE_DISCOVER_MAX_BLOCKS];
} fe_innovations;

/* fe_innovations_init: empty, for `total` reports of a whole stream in
   `blocks` blocks (2..FE_DISCOVER_MAX_BLOCKS); this part starts at global
   report `row0` (0 unless the stream is split).  Errors: FE_EINVAL
   (NULL), FE_ESIZE (blocks, or row0 >= total), FE_ETOOFEW (fewer than 2
   reports per block). */
int fe_innovations_init(fe_innovations *a, size_t blocks, uint64_t total,
                        uint64_t row0);

/* fe_innovations_add: fold the report of one filter step at time t (its
   whitened vector may be NULL: the NIS alone is then tested).  Errors:
   FE_EINVAL (NULL, b == 0, negative NIS), FE_ENONFINITE, FE_ESIZE (more
   than `total` reports); on error `a` is unchanged.  O(b), no allocation. */
int fe_innovations_add(fe_innovations *a, double t, const fe_kalman_report *r);

/* fe_innovations_break: the next report starts a new recording: no
   lag-one pair is formed across. */
void fe_innovations_break(fe_innovations *a);

/* fe_innovations_merge: a <- a (+) b, b holding the reports right after
   a's (b->row0 == a->row0 + a->n); equal to folding them in one part, up
   to rounding.  FE_EMISMATCH otherwise or when the shapes differ; a is
   then unchanged.  O(K). */
int fe_innovations_merge(fe_innovations *a, const fe_innovations *b);

/* fe_innovations_locate: the located time windows at family-wise level
   alpha (0 < alpha < 1; 0.05 is the engine's), at most `max` of them into
   out, their number into *nout (those beyond `max` are not written).
   Errors: FE_EINVAL. */
int fe_innovations_locate(const fe_innovations *a, double alpha, fe_located *out,
                          size_t max, size_t *nout);

#ifdef __cplusplus
}
#endif

#endif /* FOLDEST_LOCATE_H */
/* Locate Declarations ends here */
