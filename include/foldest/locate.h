/* SPDX-License-Identifier: MIT */
/* Tangled from literate/locate.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/locate.org::Locate Declarations][Locate Declarations]] */
#ifndef FOLDEST_LOCATE_H
#define FOLDEST_LOCATE_H

#include <stddef.h>
#include <stdint.h>

#include "foldest/catalog.h"
#include "foldest/discover.h"
#include "foldest/kalman.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Where a located place lies: a window of time, or a region of the
   state.  The bounded regions (speed, temperature) carry their bounds in
   fe_located's lo and hi; the others, and time windows, 0 and 0. */
typedef enum fe_region {
    FE_REGION_TIME = 0,             /* consecutive time blocks */
    FE_REGION_VELOCITY_NEGATIVE,    /* v < 0 */
    FE_REGION_VELOCITY_POSITIVE,    /* v > 0 */
    FE_REGION_VELOCITY_ZERO,        /* v = 0 */
    FE_REGION_SPEED,                /* lo <= |v| < hi, v != 0 */
    FE_REGION_POSITION_NEGATIVE,    /* x < 0 */
    FE_REGION_POSITION_POSITIVE,    /* x > 0 */
    FE_REGION_TEMPERATURE           /* lo <= T < hi */
} fe_region;

/* fe_region_variable: the state variable a region is cut from ("time",
   "velocity", "speed", "position", "temperature"); "" for a value out of
   range.  Static storage. */
const char *fe_region_variable(fe_region r);

/* One located window or region.  The statistics are on the standard
   normal scale. */
typedef struct fe_located {
    fe_region region;           /* FE_REGION_TIME: a time window */
    double lo, hi;              /* bounds of a speed or temperature band;
                                   0 and 0 for any other place */
    const char *test;           /* what located it: "nis", "innovation_acf",
                                   "residual_mean", "residual_ms" */
    double t0, t1;              /* time of its first and last row */
    int pair, pair1;            /* recordings (from 0) of those rows */
    double n;                   /* rows (Kalman reports) in it */
    double z;                   /* largest NIS or mean-square statistic */
    double t;                   /* autocorrelation or mean statistic largest
                                   in size */
    double p_value;             /* smallest block p-value (before Bonferroni) */
    double mean_nis;            /* pooled NIS per degree of freedom (1: right) */
    double lag1;                /* pooled lag-one autocorrelation (0: right) */
    /* From a residual map: the residual before and after the discovered
       terms, its mean and its mean square over the typical one. */
    double mean_before, mean_after, ms_ratio_before, ms_ratio_after;
} fe_located;

/* fe_region_describe: the region of `l` in words ("v < 0", "|v| 0.5 to
   1", "20 to 25"; the time span for a time window), NUL-terminated in
   buf.  FE_ESIZE when it does not fit; FE_EINVAL on NULL. */
int fe_region_describe(const fe_located *l, char *buf, size_t len);

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

/* A residual map: the residual of a simulation against a recording,
   before and after the discovered terms, by time block and by region of
   the state. */
enum {
    FE_RESIDUAL_REGIONS = 13,   /* v < 0, v > 0, v = 0, four speed bands,
                                   x < 0, x > 0, four temperature bands */
    FE_RESIDUAL_BINS = 40       /* bins of each state variable (plots) */
};

/* What the map keeps of the rows of one block, region or bin. */
typedef struct fe_residual_cell {
    double n;                   /* rows */
    double sum0, sq0;           /* residual before: sum, sum of squares */
    double sum1, sq1;           /* after */
    double t0, t1;              /* time (bins: value) of the first and last row */
    double sum_at;              /* sum of the rows' times (bins: values) */
    int pair, pair1;            /* recordings of those rows */
} fe_residual_cell;

/* fe_residual_cell_add: one row at time (or value) `at` of recording
   `pair`, with its residual before and after, into c.  Exposed so that a
   caller can keep cells of its own (a plot's blocks) in the same form. */
void fe_residual_cell_add(fe_residual_cell *c, double at, int pair, double before,
                          double after);

typedef struct fe_residual_map {
    size_t blocks;              /* K: block K holds the held-out rows */
    uint64_t fit;               /* fitted rows of the whole stream (the
                                   rows after them are held out) */
    uint64_t row0;              /* global index of this part's first row */
    uint64_t n;                 /* rows folded into this part */
    int recording;              /* current recording (from 0 in this part) */
    int first_linked;           /* the first row follows the previous part */
    unsigned roles;             /* FE_ROLE_POSITION, _VELOCITY, _TEMPERATURE */
    double lo[3], hi[3];        /* ranges of position, velocity, temperature */
    double vmax;                /* largest |v| */
    size_t nregions;
    fe_region region[FE_RESIDUAL_REGIONS];
    double region_lo[FE_RESIDUAL_REGIONS], region_hi[FE_RESIDUAL_REGIONS];
    fe_residual_cell block[FE_DISCOVER_MAX_BLOCKS + 1];
    fe_residual_cell cell[FE_RESIDUAL_REGIONS];
    /* Every row (held-out ones too) by position, velocity, temperature. */
    fe_residual_cell bin[3][FE_RESIDUAL_BINS];
} fe_residual_map;

/* fe_residual_map_init: empty, for a stream whose first `fit` rows are
   fitted (the rest held out), in `blocks` time blocks
   (2..FE_DISCOVER_MAX_BLOCKS); this part starts at global row `row0`.
   `roles` (FE_ROLE_* of catalog.h) says which state variables the rows
   carry; lo[i], hi[i] are the whole stream's ranges of position,
   velocity and temperature (i = 0, 1, 2; read only for a role present),
   from which the regions and bins are cut.  Errors: FE_EINVAL (NULL, lo
   > hi), FE_ENONFINITE (a range not finite), FE_ESIZE (blocks),
   FE_ETOOFEW (fit < 2 blocks). */
int fe_residual_map_init(fe_residual_map *m, size_t blocks, uint64_t fit, uint64_t row0,
                         unsigned roles, const double lo[3], const double hi[3]);

/* fe_residual_map_add: fold one row (its time and state from s) with its
   residual before and after the discovered terms.  Errors: FE_EINVAL
   (NULL), FE_ENONFINITE (time, state or residual); on error m is
   unchanged.  O(regions), no allocation. */
int fe_residual_map_add(fe_residual_map *m, const fe_sample *s, double before, double after);

/* fe_residual_map_break: the next row starts a new recording. */
void fe_residual_map_break(fe_residual_map *m);

/* fe_residual_map_merge: a <- a (+) b, b holding the rows right after a's
   (b->row0 == a->row0 + a->n): equal to folding them in one part, up to
   rounding.  FE_EMISMATCH otherwise or when the shapes differ; a is then
   unchanged. */
int fe_residual_map_merge(fe_residual_map *a, const fe_residual_map *b);

/* fe_residual_map_locate: the time windows and state regions where the
   residual before the discovered terms stands out, at family-wise level
   alpha (0 < alpha < 1), each row counting `worth` independent rows
   (fe_discover_row_worth of the baseline's noise model; 1 for white
   noise).  At most `max` into out (time windows first), their number into
   *nout.  Errors: FE_EINVAL (NULL, alpha or worth out of (0, 1]). */
int fe_residual_map_locate(const fe_residual_map *m, double worth, double alpha,
                           fe_located *out, size_t max, size_t *nout);

/* fe_residual_map_largest_after: the largest |t| (mean) or z (mean
   square) of any fitted block or region for the residual after the
   discovered terms, each row counting `worth` independent rows
   (fe_discover_row_worth of the final noise model).  0 when the map is
   empty or m is NULL. */
double fe_residual_map_largest_after(const fe_residual_map *m, double worth);

/* The verdict of a discovery. */
typedef enum fe_verdict {
    FE_VERDICT_NO_MISMATCH = 0,     /* nothing named, nothing located */
    FE_VERDICT_EXPLAINED,           /* named; the residual left is white and
                                       nothing stays out of line */
    FE_VERDICT_UNEXPLAINED,         /* located, but nothing named */
    FE_VERDICT_NOT_WHITE,           /* named, but the whitened residual left
                                       is not white */
    FE_VERDICT_OUT_OF_LINE,         /* named, but a window or region stays
                                       out of line after the terms */
    FE_VERDICT_DIVERGES,            /* the residual left stays correlated far
                                       above its high-frequency floor: the
                                       trajectories part (output error) */
    FE_VERDICT_STATE_LEFT,          /* named, but a probe of the state still
                                       explains part of the residual
                                       (fe_discover_result.probe_p) */
    FE_VERDICT_HELDOUT_WORSE        /* named, but the held-out rows are
                                       predicted worse with the terms than
                                       by the baseline */
} fe_verdict;

/* fe_discover_verdict: the verdict of the result r, whose map is m and
   whose location found `nlocated` places, at family-wise level alpha.
   FE_VERDICT_NO_MISMATCH on NULL. */
fe_verdict fe_discover_verdict(const fe_discover_result *r, const fe_residual_map *m,
                               size_t nlocated, double alpha);

/* fe_discover_heldout_worse: 1 when rows were held out and the final
   model predicts them worse than the baseline (fe_discover_verdict's last
   test, also the whole verdict of a model without a residual map, as the
   three-axis mode's), else 0; 0 on NULL. */
int fe_discover_heldout_worse(const fe_discover_result *r);

/* fe_verdict_text: "no significant mismatch", "mismatch explained" or
   "mismatch not explained by the catalog".  fe_verdict_why: why not
   explained when terms were named (NULL otherwise).  Static storage. */
const char *fe_verdict_text(fe_verdict v);
const char *fe_verdict_why(fe_verdict v);

#ifdef __cplusplus
}
#endif

#endif /* FOLDEST_LOCATE_H */
/* Locate Declarations ends here */
