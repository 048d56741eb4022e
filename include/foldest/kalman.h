/* SPDX-License-Identifier: MIT */
/* Tangled from literate/kalman.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/kalman.org::Kalman Filter Declarations][Kalman Filter Declarations]] */
#ifndef FOLDEST_KALMAN_H
#define FOLDEST_KALMAN_H

#include <stddef.h>
#include <stdint.h>

#include "foldest/fold.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Largest state or packet dimension accepted (keeps sizes and LAPACK's
   int arguments far from overflow). */
#define FE_KALMAN_MAX_DIM 2048

/* A Kalman filter in covariance form: estimate x and covariance P.  All
   arrays belong to the caller and live in one buffer of
   fe_kalman_doubles(n, bmax) doubles given to fe_kalman_init.  Matrices are
   row-major.  P is kept exactly symmetric.  Use an fe_kalman from one
   thread at a time (the workspace is inside it). */
typedef struct fe_kalman {
    size_t n;          /* state dimension */
    size_t bmax;       /* largest packet dimension the workspace takes */
    double *x;         /* estimate, n */
    double *P;         /* covariance, n x n */
    double *work;      /* scratch: never read between calls */
    uint64_t count;    /* packets folded since the prior was set */
} fe_kalman;

/* One observation packet: z = A x + v, v ~ N(0, Z).  Nothing is kept. */
typedef struct fe_kalman_obs {
    size_t b;          /* number of measurements, 1..bmax */
    const double *A;   /* partials, b x n */
    const double *z;   /* measured values, b */
    const double *Z;   /* noise covariance, b x b, symmetric positive
                          definite; only its lower triangle is read */
} fe_kalman_obs;

/* What a step can say about its innovation.  The scalar fields are always
   filled; each pointer, when not NULL, is a caller buffer that receives:
   innovation: nu = z - A x (x before the step), b doubles;
   whitened:   L^{-1} nu with D = L L^T, b doubles (N(0, I) if the model
               is right);
   D:          the innovation covariance Z + A P A^T, b x b.
   On error the contents are unspecified. */
typedef struct fe_kalman_report {
    size_t b;          /* degrees of freedom of the NIS */
    double nis;        /* nu^T D^{-1} nu */
    double log_det_D;  /* log det D */
    double *innovation;
    double *whitened;
    double *D;
} fe_kalman_report;

/* fe_kalman_doubles: doubles needed for an n-state filter taking packets
   of up to bmax measurements (x, P and the workspace).  0 when n or bmax is
   0 or above FE_KALMAN_MAX_DIM. */
size_t fe_kalman_doubles(size_t n, size_t bmax);

/* fe_kalman_init: lay `k` out over mem[0..len), len >= fe_kalman_doubles.
   x and P are set to zero; set a prior next.  The caller keeps `mem`
   alive as long as `k` is used.  Errors: FE_EINVAL (NULL, zero size),
   FE_ESIZE (len too small, dimension too large). */
int fe_kalman_init(fe_kalman *k, size_t n, size_t bmax, double *mem,
                   size_t len);

/* fe_kalman_set_prior: x <- x0 (NULL: zero), P <- (P0 + P0^T)/2, count 0.
   Errors: FE_EINVAL, FE_ENONFINITE, FE_ENOTPD (a negative variance); on
   error `k` is unchanged. */
int fe_kalman_set_prior(fe_kalman *k, const double *x0, const double *P0);

/* fe_kalman_set_prior_scaled: x <- x0 (NULL: zero), P <- p0 I, p0 >= 0. */
int fe_kalman_set_prior_scaled(fe_kalman *k, const double *x0, double p0);

/* fe_kalman_sigma: the standard deviation sqrt(P_ii) of component i
   (NAN when i >= n): the 1-sigma bound of x[i]. */
double fe_kalman_sigma(const fe_kalman *k, size_t i);

/* fe_kalman_copy: dst's x, P and count <- src's.  Same n required
   (FE_EMISMATCH); bmax may differ. */
int fe_kalman_copy(fe_kalman *dst, const fe_kalman *src);

/* fe_kalman_update: fold one packet, the reference way (CBLAS products and
   one LAPACKE_dposv with both right-hand sides).  `r` may be NULL.
   Errors: FE_EINVAL, FE_ESIZE (b > bmax), FE_ENONFINITE (NaN or infinity in
   the packet or the result), FE_ENOTPD (D not positive definite),
   FE_EINTERNAL; on error `k` is unchanged, bit for bit.
   Cost O(n^2 b + n b^2 + b^3) flops plus 0.5 to 1 microsecond of CBLAS
   and LAPACKE call overhead; allocates nothing (column-major dposv). */
int fe_kalman_update(fe_kalman *k, const fe_kalman_obs *o,
                     fe_kalman_report *r);

/* fe_kalman_update_fast: the same update as sequential scalar updates of
   decorrelated rows (Z diagonal: as given; otherwise whitened by a
   hand-written Cholesky of Z), with fixed-size kernels for n <= 8; equal to
   fe_kalman_update to rounding (tested to 1e-12).  Requires Z positive
   definite (FE_ENOTPD otherwise, even when D would be).  Errors and the
   unchanged-on-error promise as fe_kalman_update.  Cost
   O(n^2 b + n b^2 + b^3) flops, no library calls, allocates nothing. */
int fe_kalman_update_fast(fe_kalman *k, const fe_kalman_obs *o,
                          fe_kalman_report *r);

/* fe_kalman_update_joseph: the reference update with the covariance in
   Joseph's form, P <- (I - K A) P (I - K A)^T + K Z K^T, arranged so that
   no term cancels to the size of the old P: right where the standard
   form loses everything (a vague prior against a precise measurement, P0
   = 1e10 I and Z = 1e-8 I: the standard forms give P = 0).  Errors and
   the unchanged-on-error promise as fe_kalman_update.  Cost about twice
   fe_kalman_update's O(n^2 b) products. */
int fe_kalman_update_joseph(fe_kalman *k, const fe_kalman_obs *o,
                            fe_kalman_report *r);
/* Kalman Filter Declarations ends here */
/* [[file:../../literate/kalman.org::Tracking Filter Declarations][Tracking Filter Declarations]] */
/* The motion model of one predict step:
   x <- Phi x + Gamma u,  P <- Xi + Phi P Phi^T.  All row-major. */
typedef struct fe_kalman_model {
    const double *Phi;    /* n x n; NULL: identity */
    const double *Gamma;  /* n x m; NULL or m == 0: no control input */
    const double *u;      /* control input, m */
    size_t m;
    const double *Xi;     /* process noise covariance, n x n; NULL: zero */
} fe_kalman_model;

/* An observation of the tracking filter: predict with `model`, then
   update with `obs`. */
typedef struct fe_kalman_track_obs {
    fe_kalman_model model;
    fe_kalman_obs obs;
} fe_kalman_track_obs;

/* fe_kalman_predict: apply the model alone (no packet; count unchanged).
   Errors: FE_EINVAL, FE_ENONFINITE; on error `k` is unchanged. */
int fe_kalman_predict(fe_kalman *k, const fe_kalman_model *m);

/* fe_kalman_track, fe_kalman_track_fast: one tracker step, predict then
   update (reference or fast update), atomically: on any error `k` is
   unchanged.  Errors as fe_kalman_predict and fe_kalman_update. */
int fe_kalman_track(fe_kalman *k, const fe_kalman_track_obs *o,
                    fe_kalman_report *r);
int fe_kalman_track_fast(fe_kalman *k, const fe_kalman_track_obs *o,
                         fe_kalman_report *r);
/* fe_kalman_track_joseph: the same with fe_kalman_update_joseph. */
int fe_kalman_track_joseph(fe_kalman *k, const fe_kalman_track_obs *o,
                           fe_kalman_report *r);
/* Tracking Filter Declarations ends here */
/* [[file:../../literate/kalman.org::Information Form Declarations][Information Form Declarations]] */
/* A filter in information form: Lambda = P^{-1}, eta = P^{-1} x.  Packets
   add to it and accumulations merge by addition, so shards of a stream can
   be folded apart (threads, machines) and merged.  Memory as fe_kalman:
   one caller buffer of fe_kalman_info_doubles(n, bmax) doubles. */
typedef struct fe_kalman_info {
    size_t n;
    size_t bmax;
    double *eta;       /* information vector, n */
    double *Lambda;    /* information matrix, n x n, exactly symmetric */
    double *work;
    uint64_t count;    /* packets folded (merge adds counts) */
} fe_kalman_info;

/* fe_kalman_info_doubles: doubles needed (0 on a bad dimension). */
size_t fe_kalman_info_doubles(size_t n, size_t bmax);

/* fe_kalman_info_init: lay out over mem[0..len) and set zero information
   (the uninformative prior, and the identity of merge).  Errors as
   fe_kalman_init. */
int fe_kalman_info_init(fe_kalman_info *s, size_t n, size_t bmax,
                        double *mem, size_t len);

/* fe_kalman_info_set_prior: Lambda <- P0^{-1}, eta <- P0^{-1} x0 (x0 NULL:
   zero), count 0.  FE_ENOTPD when P0 is not positive definite. */
int fe_kalman_info_set_prior(fe_kalman_info *s, const double *x0,
                             const double *P0);

/* fe_kalman_info_set_prior_scaled: P0 = p0 I, p0 > 0; p0 = INFINITY gives
   zero information.  FE_ENOTPD for p0 <= 0; FE_ENONFINITE for a NaN, or
   when 1/p0 or x0/p0 is not a double (p0 below 1/DBL_MAX, or tiny
   against x0); on error `s` is unchanged. */
int fe_kalman_info_set_prior_scaled(fe_kalman_info *s, const double *x0,
                                    double p0);

/* fe_kalman_info_update: Lambda += A^T Z^{-1} A, eta += A^T Z^{-1} z.
   Errors: FE_EINVAL, FE_ESIZE, FE_ENONFINITE, FE_ENOTPD (Z not positive
   definite), FE_EINTERNAL; on error `s` is unchanged.  Cost
   O(n^2 b + n b^2 + b^3). */
int fe_kalman_info_update(fe_kalman_info *s, const fe_kalman_obs *o);

/* fe_kalman_info_merge: s <- s (+) t, adding Lambda, eta and count.  Each
   shard must start from zero information and the prior be counted once.
   Errors: FE_EINVAL, FE_EMISMATCH (different n), FE_ENONFINITE; on error
   `s` is unchanged.  `t` is never modified.  Cost O(n^2). */
int fe_kalman_info_merge(fe_kalman_info *s, const fe_kalman_info *t);

/* fe_kalman_info_copy: dst's Lambda, eta and count <- src's (same n). */
int fe_kalman_info_copy(fe_kalman_info *dst, const fe_kalman_info *src);

/* fe_kalman_info_to_kalman: the covariance form, P = Lambda^{-1},
   x = P eta (one dposv with n + 1 right-hand sides, in k's workspace);
   k->count <- s->count.  FE_ENOTPD while the data do not determine x
   (Lambda singular).  On error `k` is unchanged.  Cost O(n^3). */
int fe_kalman_info_to_kalman(const fe_kalman_info *s, fe_kalman *k);
/* Information Form Declarations ends here */
/* [[file:../../literate/kalman.org::Innovation Monitor Declarations][Innovation Monitor Declarations]] */
/* The innovation monitor: a fold over fe_kalman_report values that says
   whether the filter's model is consistent with the data, and when it
   stopped being so.  A flat value: copy it, fe_scan it. */
enum {
    FE_KALMAN_MONITOR_LAGS = 4,  /* most autocorrelation lags kept */
    FE_KALMAN_MONITOR_DIM = 4    /* whitened components used for them */
};

typedef struct fe_kalman_monitor_params {
    size_t lags;         /* autocorrelation lags, 0..FE_KALMAN_MONITOR_LAGS */
    double scale_up;     /* CUSUM alternative lambda > 1 (NIS too large) */
    double scale_down;   /* CUSUM alternative 0 < lambda < 1 (too small) */
    double threshold;    /* CUSUM alarm level h > 0 (log-likelihood) */
} fe_kalman_monitor_params;

typedef struct fe_kalman_monitor {
    fe_kalman_monitor_params par;
    uint64_t steps;      /* reports folded */
    uint64_t dof;        /* sum of their b */
    double nis_sum;
    /* Autocorrelation of the whitened innovations. */
    uint64_t acf_steps;  /* reports that carried a whitened vector */
    double acf[FE_KALMAN_MONITOR_LAGS + 1];     /* sums of w_k . w_{k-l} */
    uint64_t acf_terms[FE_KALMAN_MONITOR_LAGS + 1];
    double ring[FE_KALMAN_MONITOR_LAGS][FE_KALMAN_MONITOR_DIM];
    size_t ring_dim[FE_KALMAN_MONITOR_LAGS];
    /* Two one-sided CUSUMs of the log-likelihood ratio. */
    double cusum_up, cusum_down;
    uint64_t up_start, down_start;  /* first step of the current excursion */
    uint64_t alarms;                /* CUSUM crossings (each resets it) */
    uint64_t alarm_step;            /* step (1-based) of the first; 0: none */
    uint64_t onset_step;            /* where that excursion began */
    int alarm_side;                 /* +1 too large, -1 too small, 0 none */
} fe_kalman_monitor;

/* fe_kalman_monitor_default_params: 4 lags, lambda 2 and 1/2, h = 10. */
fe_kalman_monitor_params fe_kalman_monitor_default_params(void);

/* fe_kalman_monitor_init: the empty monitor (p NULL: defaults).
   FE_EINVAL on NULL m or bad parameters. */
int fe_kalman_monitor_init(fe_kalman_monitor *m,
                           const fe_kalman_monitor_params *p);

/* fe_kalman_monitor_add: fold one report (b >= 1, finite nis >= 0;
   `whitened` may be NULL, and only its first FE_KALMAN_MONITOR_DIM
   components enter the autocorrelation).  Errors: FE_EINVAL,
   FE_ENONFINITE; on error `m` is unchanged.  O(lags) work. */
int fe_kalman_monitor_add(fe_kalman_monitor *m, const fe_kalman_report *r);

/* fe_kalman_monitor_mean_nis: mean NIS so far (0 when empty). */
double fe_kalman_monitor_mean_nis(const fe_kalman_monitor *m);

/* fe_kalman_monitor_nis_band: the interval that holds the mean NIS with
   probability `prob` (0 < prob < 1) if the model is right.
   FE_ETOOFEW when empty, FE_EINVAL on a bad argument (also for the
   largest double below 1, whose upper level (1 + prob)/2 rounds to 1). */
int fe_kalman_monitor_nis_band(const fe_kalman_monitor *m, double prob,
                               double *lo, double *hi);

/* fe_kalman_monitor_autocorr: normalised autocorrelation of the whitened
   innovations at `lag` (1..par.lags); about N(0, 1/terms) for a right
   model, `terms` (may be NULL) receiving that count.  NAN when there is
   not enough data or lag is out of range. */
double fe_kalman_monitor_autocorr(const fe_kalman_monitor *m, size_t lag,
                                  uint64_t *terms);
/* Innovation Monitor Declarations ends here */
/* [[file:../../literate/kalman.org::Kalman Accumulator Declarations][Kalman Accumulator Declarations]] */
/* Configuration of the covariance-form accumulators (their context): the
   prior that `init` sets, and which update runs.  Must outlive the
   accumulator. */
typedef struct fe_kalman_config {
    const double *x0;  /* prior estimate, n; NULL: zero */
    const double *P0;  /* prior covariance, n x n; NULL: p0 I */
    double p0;
    int fast;          /* nonzero: the sequential fast path */
} fe_kalman_config;

/* fe_kalman_accumulator: the static filter; accumulations fe_kalman
   (initialised with fe_kalman_init first: fe_init only sets the prior),
   observations fe_kalman_obs.  cfg NULL: reference update, and fe_init
   returns FE_ENOTSUP.  Does not merge; copies deeply. */
fe_accumulator fe_kalman_accumulator(const fe_kalman_config *cfg);

/* fe_kalman_track_accumulator: the tracker; observations
   fe_kalman_track_obs. */
fe_accumulator fe_kalman_track_accumulator(const fe_kalman_config *cfg);

/* fe_kalman_info_accumulator: the information form; accumulations
   fe_kalman_info (laid out by fe_kalman_info_init), observations
   fe_kalman_obs; init is zero information; merges by addition. */
fe_accumulator fe_kalman_info_accumulator(void);

/* fe_kalman_monitor_accumulator: the monitor over fe_kalman_report
   observations; `p` (NULL: defaults) must outlive it.  Flat, no merge. */
fe_accumulator fe_kalman_monitor_accumulator(const fe_kalman_monitor_params *p);

#ifdef __cplusplus
}
#endif

#endif /* FOLDEST_KALMAN_H */
/* Kalman Accumulator Declarations ends here */
