/* SPDX-License-Identifier: MIT */
/* Tangled from literate/discover.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/discover.org::Discovery Accumulation Declarations][Discovery Accumulation Declarations]] */
#ifndef FOLDEST_DISCOVER_H
#define FOLDEST_DISCOVER_H

#include <stddef.h>
#include <stdint.h>

#include "foldest/fold.h"

#ifdef __cplusplus
extern "C" {
#endif

enum {
    FE_DISCOVER_MAX_COLUMNS = 64,   /* term columns m */
    FE_DISCOVER_MAX_GROUPS = 64,    /* candidate terms (groups of columns) */
    FE_DISCOVER_MAX_GROUP_SIZE = 3, /* columns in one term (three-axis terms) */
    FE_DISCOVER_MAX_BLOCKS = 64,    /* time blocks K */
    FE_DISCOVER_MAX_STEPS = 12,     /* forward-selection steps */
    FE_DISCOVER_MAX_ASIDE = 4,      /* terms set aside, and selections
                                       run again without them */
    FE_DISCOVER_LAGS = 16,          /* lagged products Z_1 .. Z_P a full
                                       accumulation can keep */
    FE_DISCOVER_DEFAULT_LAGS = 8,   /* ... and keeps unless told otherwise */
    FE_DISCOVER_EDGE = 4,           /* rows kept at each end of every
                                       recording: the highest order of the
                                       noise model */
    FE_DISCOVER_FINE_BLOCKS = 512,  /* most fine blocks (a power of two) */
    FE_DISCOVER_FINE_ROWS = 16,     /* fewest fitted rows in a fine block */
    FE_DISCOVER_SCALES = 9          /* log2 FE_DISCOVER_FINE_BLOCKS */
};

/* Rows per panel of fe_discover_add_rows, whose scratch (an M x M
   triangle and FE_DISCOVER_PANEL_ROWS + 1 rows) is part of the
   accumulation's storage. */
enum { FE_DISCOVER_PANEL_ROWS = 512 };

/* FE_DISCOVER_ACC_DOUBLES: fe_discover_acc_doubles(m, blocks) as a
   constant expression, for storage sized at compile time.  The values
   (blocks, T, first, last, counts) come first, the scratch last, at
   FE_DISCOVER_ACC_VALUES(m, blocks). */
#define FE_DISCOVER_ACC_VALUES(m, blocks)                                   \
    (((blocks) + 2) * ((m) + 1) * ((m) + 1) + 2 * ((m) + 1) + (blocks) + 1  \
     + FE_DISCOVER_LAGS * (((m) + 1) * ((m) + 1) + 2 * ((m) + 1))           \
     + (blocks) * ((m) + 1)                                                 \
     + 2 * (FE_DISCOVER_EDGE * ((m) + 1)) * (FE_DISCOVER_EDGE * ((m) + 1))    \
     + FE_DISCOVER_EDGE * ((m) + 1)                                         \
     + FE_DISCOVER_FINE_BLOCKS * ((m) + 1))
#define FE_DISCOVER_ACC_DOUBLES(m, blocks)                                  \
    (FE_DISCOVER_ACC_VALUES(m, blocks) + ((m) + 1) * ((m) + 1)              \
     + (FE_DISCOVER_PANEL_ROWS + 1) * ((m) + 1)                             \
     + (FE_DISCOVER_LAGS + FE_DISCOVER_PANEL_ROWS) * ((m) + 1))

/* The accumulation: K block Gram matrices of the rows (phi, r), one for
   held-out rows, the lag-one cross product, and the first and last rows;
   in a full accumulation also the lagged products Z_1 .. Z_P of the noise
   model, with the first and last P rows that a merge joins them by.
   Memory is the caller's: fe_discover_acc_doubles() doubles. */
typedef struct fe_discover_acc {
    size_t m;                   /* term columns; M = m + 1 with r */
    size_t blocks;              /* K */
    size_t base_cols;           /* columns 0 .. base_cols - 1 keep their
                                   products with every column: m for a full
                                   accumulation, fewer for a screen (below) */
    uint64_t fit_rows;          /* rows [0, fit_rows) are fitted, the rest held out */
    uint64_t row0;              /* global index of this part's first row */
    uint64_t n;                 /* rows folded into this part */
    int have_prev;              /* the last row can be followed (no break) */
    int first_linked;           /* the first row follows the previous part */
    double *gram;               /* (K + 1) x M x M, upper triangles */
    double *lag;                /* M x M, L = sum z_t z_{t-1}^T over fitted
                                   rows, folded: L_ii on the diagonal,
                                   L_ij + L_ji above it, zeros below, so
                                   that w^T lag w = w^T L w */
    double *first, *last;       /* M each */
    double *counts;             /* K + 1 row counts */
    size_t lags;                /* P: FE_DISCOVER_DEFAULT_LAGS unless set
                                   (fe_discover_set_lags), 0 in a screen */
    size_t nhist;               /* fitted rows in hist, <= P */
    size_t nhead;               /* rows in head, <= P */
    size_t nshead;              /* rows in shead */
    int head_open;              /* no break since the part's first row */
    int shead_pending;          /* the open recording began after a break
                                   in this part: its first rows go to
                                   edge_start once known (two ints side
                                   by side: the struct has no padding, so
                                   that copies compare byte for byte) */
    double *zlag;               /* P x M x M, Z_l = sum z_t z_{t-l}^T over
                                   fitted rows of one recording, full */
    double *hist;               /* P x M: the last fitted rows, newest
                                   first (rows past nhist are zero) */
    double *head;               /* P x M: the part's first rows */
    double *bsum;               /* K x M: each fitted block's sum of rows */
    double *edge_start;         /* (E M) x (E M): sum over recordings of
                                   x x^T, x = the first E = FE_DISCOVER_EDGE
                                   fitted rows stacked (zeros past the end) */
    double *edge_end;           /* the same for the last E, newest first */
    double *shead;              /* E x M: the open recording's first rows */
    size_t fine;                /* B: fine blocks, a power of two */
    double *fsum;               /* B x M: each fine block's sum of rows */
    double *work;               /* scratch of fe_discover_add_rows */
} fe_discover_acc;

/* fe_discover_acc_doubles: doubles of storage for m columns, K blocks. */
size_t fe_discover_acc_doubles(size_t m, size_t blocks);

/* fe_discover_acc_init: an empty accumulation over `storage` (at least
   fe_discover_acc_doubles(m, blocks) doubles, owned by the caller).  The
   whole stream has `fit_rows` fitted rows followed by held-out rows; this
   part starts at global row `row0` (0 unless the stream is split).
   Errors: FE_EINVAL, FE_ESIZE (m or blocks out of range), FE_ETOOFEW
   (fewer fitted rows than 2 per block). */
int fe_discover_acc_init(fe_discover_acc *a, size_t m, size_t blocks,
                         uint64_t fit_rows, uint64_t row0, double *storage,
                         size_t storage_doubles);

/* fe_discover_screen_init: an empty /screen/, the accumulation of the
   ranking pass: as fe_discover_acc_init, but of the products of columns
   base_cols .. m - 1 it keeps only those with r and with the next two
   columns (and the lag product only among columns 0 .. base_cols - 1 and
   r).  That is everything ranking each candidate against a base model in
   columns 0 .. base_cols - 1 reads, for about (base_cols + 4) M
   multiply-adds a row instead of M (M + 1).  Same storage; every
   fe_discover_add* function folds into it, and it merges with screens of
   the same base_cols.  fe_discover_select ranks from it with max_steps 0
   and the base terms inside the base columns (FE_EINVAL otherwise).
   base_cols == m is a full accumulation.  Errors: those of
   fe_discover_acc_init; FE_ESIZE for base_cols > m. */
int fe_discover_screen_init(fe_discover_acc *a, size_t m, size_t base_cols,
                            size_t blocks, uint64_t fit_rows, uint64_t row0,
                            double *storage, size_t storage_doubles);

/* fe_discover_set_lags: keep lags Z_1 .. Z_P, P = lags <= FE_DISCOVER_LAGS
   (FE_DISCOVER_DEFAULT_LAGS by default; 0: no noise model, selection then
   uses batch means and says so).  The cost of a row grows as P M^2.  Only
   on an empty full accumulation (FE_EINVAL otherwise, or for lags > 0 on a
   screen; FE_ESIZE for lags > FE_DISCOVER_LAGS).  Parts to be merged must
   agree. */
int fe_discover_set_lags(fe_discover_acc *a, size_t lags);

/* fe_discover_set_fine: the B fine blocks whose sums carry the noise
   model's long range (see the noise model below): a power of two, at most
   FE_DISCOVER_FINE_BLOCKS and at most fit_rows / FE_DISCOVER_FINE_ROWS; by
   default the most that allows.  B = 1 turns the long range off, and
   standard errors and tests are then those of the AR model alone.  Only
   on an empty accumulation (FE_EINVAL otherwise, or for B not a power of
   two; FE_ESIZE for B too large).  Parts to be merged must agree. */
int fe_discover_set_fine(fe_discover_acc *a, size_t blocks);

/* fe_discover_add: fold one row: m term values `phi` and the residual r =
   recording - simulation.  FE_ENONFINITE (accumulation unchanged) when any
   value is not finite or the sums would overflow (values above 1e100 are
   checked); FE_EINVAL when row0 is FE_DISCOVER_ROW_UNKNOWN (use
   fe_discover_add_row).  Cost about 1.5 M (M + 1) multiply-adds
   (fe_discover_add_rows is the fast path for many rows). */
int fe_discover_add(fe_discover_acc *a, const double *phi, double r);

/* fe_discover_add_rows: fold `nrows` rows at once: row i is the m term
   values phi[i * ldphi .. i * ldphi + m - 1] and the residual r[i].  The
   same accumulation as fe_discover_add row by row (up to rounding: sums
   are grouped differently), with two thirds of its arithmetic, M (M + 1)
   multiply-adds a row, all in level-3 BLAS: measured twice as fast at
   M = 16, five times at M = 54, no faster for a handful of columns.
   Stops at the first row that fe_discover_add would refuse (a value not
   finite, or sums that would overflow: FE_ENONFINITE): the rows before it
   are folded, the rest are not.  `*done` (if not NULL) receives how many
   rows were folded.  FE_EINVAL for null pointers, ldphi < m when nrows > 1, or
   row0 FE_DISCOVER_ROW_UNKNOWN (nothing folded). */
int fe_discover_add_rows(fe_discover_acc *a, const double *phi, size_t ldphi,
                         const double *r, size_t nrows, size_t *done);

/* fe_discover_add_columns: fold `nrows` rows given as columns, the layout
   in which terms are evaluated a vector at a time: term i of row t is
   phi[i * ldphi + t] (ldphi >= nrows when m > 1), its residual r[t].  The
   same accumulation, refusals and `*done` as fe_discover_add_rows, with no
   copy: the fast path of a screen (and of a full accumulation of at most
   8 columns M), by dot products in vector lanes. */
int fe_discover_add_columns(fe_discover_acc *a, const double *phi, size_t ldphi,
                            const double *r, size_t nrows, size_t *done);

/* fe_discover_break: the next row does not follow the last in time (a new
   recording begins): no lag product is formed across. */
void fe_discover_break(fe_discover_acc *a);

/* fe_discover_merge: a <- a (+) b, where b holds the rows right after a's
   (b->row0 == a->row0 + a->n).  An empty b is the identity (its break, if
   any, is kept); an empty a whose row0 is FE_DISCOVER_ROW_UNKNOWN takes
   b's.  FE_EMISMATCH otherwise or when the shapes differ; a is then
   unchanged. */
int fe_discover_merge(fe_discover_acc *a, const fe_discover_acc *b);
/* Discovery Accumulation Declarations ends here */
/* [[file:../../literate/discover.org::Discovery Accumulator Declarations][Discovery Accumulator Declarations]] */
/* The row0 of a part that does not know where it starts: it takes the
   index of its first row (fe_discover_add_row) or of the part merged into
   it.  fe_init and fe_discover_reset leave this. */
#define FE_DISCOVER_ROW_UNKNOWN UINT64_MAX

/* One row for the generic fold: its index in the whole stream, the m term
   values, the residual, and whether it begins a new recording (then no
   lag product is formed with the row before it). */
typedef struct fe_discover_row {
    uint64_t index;
    const double *phi;
    double r;
    int starts_recording;
} fe_discover_row;

/* fe_discover_reset: make a bound accumulation empty again, keeping its
   shape and storage; row0 <- FE_DISCOVER_ROW_UNKNOWN.  FE_EINVAL for NULL. */
int fe_discover_reset(fe_discover_acc *a);

/* fe_discover_add_row: fold one row that must be the part's next:
   row->index == row0 + n, or, while the part is empty and row0 is
   FE_DISCOVER_ROW_UNKNOWN, any index (row0 becomes it).  A row that
   starts a recording is folded as fe_discover_break then fe_discover_add.
   Errors: FE_EINVAL (NULL, a row out of order), FE_ENONFINITE; `a` is
   then unchanged. */
int fe_discover_add_row(fe_discover_acc *a, const fe_discover_row *row);

/* fe_discover_copy: dst's contents <- src's; dst is bound to its own
   storage with the same m, blocks and fit_rows (FE_EMISMATCH otherwise). */
int fe_discover_copy(fe_discover_acc *dst, const fe_discover_acc *src);

/* fe_discover_rebind: point a's arrays into `storage` (at least
   fe_discover_acc_doubles(a->m, a->blocks) doubles) laid out as
   fe_discover_acc_init lays them out, without touching any value: for an
   accumulation whose struct and storage were copied as bytes (a message,
   a file).  FE_EINVAL for NULL, FE_ESIZE for a shape out of range. */
int fe_discover_rebind(fe_discover_acc *a, double *storage);

/* fe_discover_accumulator: the accumulator for fe_fold and the parallel
   folds, over fe_discover_row observations and fe_discover_acc
   accumulations (bound first by fe_discover_acc_init; fe_init resets with
   row0 unknown).  Merges consecutive parts; copies deeply. */
fe_accumulator fe_discover_accumulator(void);
/* Discovery Accumulator Declarations ends here */
/* [[file:../../literate/discover.org::Discovery Selection Declarations][Discovery Selection Declarations]] */
/* A candidate term: a name and the columns it occupies. */
typedef struct fe_discover_group {
    const char *name;
    size_t first, count;        /* columns first .. first + count - 1 */
} fe_discover_group;

/* How the noise's correlation is handled. */
enum {
    FE_DISCOVER_NOISE_AR = 0,   /* an AR(p) noise model, generalised least
                                   squares (needs a full accumulation) */
    FE_DISCOVER_NOISE_BATCH = 1 /* batch means over the K blocks */
};

/* How the Haar levels' ratios V_t were read (fe_discover_noise's
   scale_shape). */
enum {
    FE_DISCOVER_SCALE_NONE = 0, /* no levels: too few rows, or batch means */
    FE_DISCOVER_SCALE_FLAT = 1, /* their weighted mean, the same at every
                                   level (a line would fall) */
    FE_DISCOVER_SCALE_LINE = 2, /* a line in the level, ln V_t = c + b t:
                                   a power law in the scale */
    FE_DISCOVER_SCALE_WALK = 3  /* a random walk beside the AR model,
                                   ln V_t = c + b t + ln(1 + A r_t) */
};

typedef struct fe_discover_options {
    double alpha;               /* family-wise level of a step: 0.05 */
    size_t max_steps;           /* at most this many terms added: 8 */
    const size_t *base;         /* groups always in the model (may be NULL) */
    size_t nbase;
    int noise;                  /* FE_DISCOVER_NOISE_AR (default) or _BATCH */
    size_t max_order;           /* highest AR order tried: 4, at most
                                   FE_DISCOVER_EDGE (and lags - 1) */
    size_t nprobes;             /* the last nprobes groups are probes
                                   (fe_catalog_add_probes): tested against
                                   the final model, never added: 0 */
} fe_discover_options;

/* fe_discover_default_options: alpha 0.05, 8 steps, no base terms, the AR
   noise model up to order 4, no probes. */
fe_discover_options fe_discover_default_options(void);

/* The noise model of a fitted model's residual e_t. */
typedef struct fe_discover_noise {
    int kind;                   /* FE_DISCOVER_NOISE_AR or _BATCH: what was
                                   used (batch for a screen, which has no
                                   lagged products) */
    size_t order;               /* p: e_t = sum phi_i e_{t-i} + eta_t */
    double phi[FE_DISCOVER_LAGS];
    double variance;            /* of e: gamma_0 */
    double innovation_variance; /* of eta (whitened residual, per row) */
    double n_eff;               /* n gamma_0 (1 - sum phi)^2 / sigma_eta^2:
                                   rows worth as many independent ones */
    size_t lags_tested;         /* H: lags of the portmanteau test (0: none) */
    double portmanteau;         /* Ljung-Box Q of the whitened residual */
    double portmanteau_dof;     /* H - p (at least 1) */
    double portmanteau_p;       /* its p-value; NaN without lagged products */
    int long_run;               /* 1 when whiteness was rejected (p < 0.05)
                                   and variances carry the long-run factor */
    double block_ratio;         /* R: the whitened residual's variance of
                                   block means over its variance per row
                                   (1 for white noise) */
    double block_p;             /* chi-square test of R = 1 (NaN: not made) */
    int long_range;             /* 1 when R > 1 is significant (p < 0.05):
                                   the location tests carry it (slow terms'
                                   variances carry the scale fit below) */
    size_t scales;              /* J: Haar levels of the fine blocks (0:
                                   too few rows to look) */
    double scale_model[FE_DISCOVER_SCALES + 1];
                                /* per level j = 1 .. J + 1, the variance of
                                   a Haar coefficient of the block sums that
                                   the AR model predicts, per unit of
                                   innovation variance (J + 1: the sum of
                                   all rows, over n) */
    double scale_used[FE_DISCOVER_SCALES + 1];
                                /* per level, the Haar coefficients the
                                   model's columns take up */
    double scale_ratio[FE_DISCOVER_SCALES + 1];
                                /* per level, V_j: the residual's Haar
                                   variance over the prediction, fitted
                                   (1 for noise the AR model describes) */
    int scale_shape;            /* FE_DISCOVER_SCALE_*: the fit that gave
                                   scale_ratio */
    double scale_slope;         /* b: ln V_t's rise per level (0 unless
                                   _LINE or _WALK) */
    double walk_ratio;          /* the walk's step variance over the
                                   innovation variance, read at the
                                   record's scale: A e^(c + b (J + 1)) (0
                                   unless _WALK) */
} fe_discover_noise;

/* fe_discover_noise_fit: the AR noise model of a series from its lagged
   sums q[0 .. maxp] (q_l = sum_t e_t e_{t-l} over n rows): Levinson-Durbin
   for every order up to maxp (< FE_DISCOVER_LAGS), the order chosen by
   BIC, n ln sigma_p^2 + p ln n.  Fills kind, order, phi, variance,
   innovation_variance and n_eff (not the portmanteau).  FE_EINVAL for
   NULL, n < 2 or maxp out of range; a series of zero variance has order 0. */
int fe_discover_noise_fit(const double *q, double n, size_t maxp,
                          fe_discover_noise *noise);

/* fe_discover_row_worth: what one of the n rows of a series with noise
   model nz is worth in independent rows, n_eff / n, divided by the block
   ratio R when a long range was found; within [1e-6, 1] (1 for white
   noise, or NULL).  A block of n_k rows weighs n_k times it, which is how
   the located windows and regions are tested under the noise model. */
double fe_discover_row_worth(const fe_discover_noise *nz, double n);

/* One candidate's test at one step. */
typedef struct fe_discover_rank {
    size_t group;
    double rss_drop;            /* Delta_J: the drop in RSS if added (in the
                                   current noise model's whitened metric) */
    double statistic;           /* t (one column) or F (several) */
    double p_value;             /* under the noise model (or batch means) */
    double delta_bic;           /* BIC change if added (negative: better) */
    int redundant;              /* already expressible by the model: not
                                   tested (p_value 1, the rest 0) */
} fe_discover_rank;

/* A summary of a fitted model. */
typedef struct fe_discover_fit {
    double rss, rms;            /* fitted rows */
    double bic;                 /* GLS: n ln(whitened RSS / n) + (params +
                                   p) ln n; batch: with the effective
                                   sample size */
    double heldout_rms;         /* NaN when nothing is held out */
    double lag1;                /* lag-one autocorrelation of the residual */
    double floor;               /* its high-frequency floor, sqrt(sum (e_t -
                                   e_{t-1})^2 / 2n): the noise's standard
                                   deviation when the residual is a smooth
                                   signal plus white noise */
    double n, n_eff, heldout_n;
    size_t params;
} fe_discover_fit;

/* One step of the selection path: the model after the step (the base
   terms, then the terms added so far), refitted. */
typedef struct fe_discover_step {
    size_t added;                               /* the group added; for
                                                   step 0 (the base)
                                                   (size_t)-1 */
    size_t ncols;                               /* = result's cols[0 .. ncols) */
    double coef[FE_DISCOVER_MAX_COLUMNS], stderr_[FE_DISCOVER_MAX_COLUMNS];
    double dof[FE_DISCOVER_MAX_COLUMNS];        /* of each coefficient's
                                                   interval */
    fe_discover_fit fit;
    fe_discover_noise noise;
} fe_discover_step;

/* What discovery found. */
typedef struct fe_discover_result {
    size_t steps;                               /* terms added */
    size_t added[FE_DISCOVER_MAX_STEPS];        /* their groups, in order */
    fe_discover_rank added_rank[FE_DISCOVER_MAX_STEPS];
    int paired[FE_DISCOVER_MAX_STEPS];          /* 0: the term passed
                                                   alone; 1: it entered
                                                   with the next step's
                                                   term, 2: with the
                                                   previous step's (no
                                                   candidate passed alone,
                                                   each of the two passed
                                                   given the other, and
                                                   added_rank is that test) */
    size_t alike[FE_DISCOVER_MAX_STEPS][FE_DISCOVER_MAX_GROUPS];
    size_t nalike[FE_DISCOVER_MAX_STEPS];       /* indistinguishable groups */
    /* The rankings: ranking[s][0..nranked[s]-1] before step s; the last
       one (s = steps) is what was left when selection stopped. */
    fe_discover_rank ranking[FE_DISCOVER_MAX_STEPS + 1][FE_DISCOVER_MAX_GROUPS];
    size_t nranked[FE_DISCOVER_MAX_STEPS + 1];
    /* The final model: its columns, coefficients and batch-means standard
       errors (and those of the baseline, the base terms alone). */
    size_t ncols;
    size_t cols[FE_DISCOVER_MAX_COLUMNS];
    double coef[FE_DISCOVER_MAX_COLUMNS], stderr_[FE_DISCOVER_MAX_COLUMNS];
    double t_critical[FE_DISCOVER_MAX_COLUMNS]; /* each coefficient's 95%
                                                   interval: coef +/-
                                                   t_critical stderr_ */
    double dof[FE_DISCOVER_MAX_COLUMNS];        /* of t_critical */
    fe_discover_fit baseline, final;
    fe_discover_noise noise;                    /* of the final model */
    fe_discover_step path[FE_DISCOVER_MAX_STEPS + 1];  /* steps + 1 */
    /* The probes (options.nprobes), each scored against the final model
       as a candidate would be: how many were tested (not redundant), the
       one with the smallest p-value, and that p-value times the number
       tested (Bonferroni, at most 1; NaN when none was tested). */
    size_t probes_tested;
    fe_discover_rank probe;
    double probe_p;
    /* How much worse the final model predicts the held-out rows than the
       baseline: (RSS_final - RSS_baseline) over the held-out rows, in
       standard deviations of that difference under the final noise model
       (positive: worse; NaN when nothing is held out or nothing named). */
    double heldout_z;
    /* Terms set aside: forward selection added each, and once the terms
       added after it were in, it no longer passed the test a candidate must
       pass (aside_rank: its test against the model without it); selection
       then ran again without it.  In the order they were set aside. */
    size_t naside;
    size_t aside[FE_DISCOVER_MAX_ASIDE];
    fe_discover_rank aside_rank[FE_DISCOVER_MAX_ASIDE];
} fe_discover_result;

/* fe_discover_workspace_doubles: scratch needed by fe_discover_select. */
size_t fe_discover_workspace_doubles(size_t m, size_t blocks);

/* fe_discover_select: rank the `ngroups` candidate groups, add terms by
   forward selection (a pair of them at a step where none passes alone
   and two pass each given the other, res->paired), fit them, and
   summarise baseline and final models, all from the accumulation.  From a
   screen (fe_discover_screen_init) it
   ranks only: max_steps must be 0 and the base groups must lie in the
   screen's base columns.  Errors: FE_EINVAL (also for a screen asked for
   more, or max_order out of range); FE_ETOOFEW (a block is empty);
   FE_ESINGULAR (the base terms are collinear, also in the metric of the
   noise model); FE_ENONFINITE (sums too large to whiten); FE_ESIZE
   (workspace too small). */
int fe_discover_select(const fe_discover_acc *a,
                       const fe_discover_group *groups, size_t ngroups,
                       const fe_discover_options *options,
                       fe_discover_result *result, double *work,
                       size_t work_doubles);

/* fe_discover_fit_columns: least-squares fit of the given columns from
   the accumulation: coefficients, batch-means standard errors and the
   summary.  Used for the baseline and the final model, and by callers
   who want a model of their own choosing.  From a screen, only columns
   among its base columns (FE_EINVAL otherwise).  FE_EINVAL too for a null
   a or fit, or a null cols or coef with ncols > 0 (both may be null for
   no column: the fit of r alone). */
int fe_discover_fit_columns(const fe_discover_acc *a, const size_t *cols,
                            size_t ncols, double *coef, double *stderr_,
                            fe_discover_fit *fit, double *work,
                            size_t work_doubles);

/* fe_discover_fit_noise: the same fit by feasible generalised least
   squares under an AR noise model of order at most max_order (<=
   FE_DISCOVER_EDGE, and below the accumulation's lags: the portmanteau
   needs one more), re-estimated from the fit's own residual:
   coefficients, their standard errors (stderr_ may be NULL), the summary
   and the noise model (with the portmanteau test of the whitened
   residual).  A full accumulation with lags only (FE_EINVAL for a screen,
   no lags or max_order out of range; fe_discover_select lowers it to
   lags - 1 instead); other errors as fe_discover_fit_columns. */
int fe_discover_fit_noise(const fe_discover_acc *a, const size_t *cols,
                          size_t ncols, size_t max_order, double *coef,
                          double *stderr_, fe_discover_fit *fit,
                          fe_discover_noise *noise, double *work,
                          size_t work_doubles);

#ifdef __cplusplus
}
#endif

#endif /* FOLDEST_DISCOVER_H */
/* Discovery Selection Declarations ends here */
