/* SPDX-License-Identifier: MIT */
/* Tangled from literate/sphere.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/sphere.org::Sphere Fit Declarations][Sphere Fit Declarations]] */
#ifndef FOLDEST_SPHERE_H
#define FOLDEST_SPHERE_H

#include <stddef.h>
#include <stdint.h>

#include "foldest/quadric.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The models. */
typedef enum fe_sphere_model {
    FE_FIT_SPHERE = 0,          /* centre and radius: 4 parameters */
    FE_FIT_AXIAL = 1,           /* centre and three axis scales: 6 */
    FE_FIT_ELLIPSOID = 2        /* centre and symmetric matrix: 9 */
} fe_sphere_model;

enum { FE_SPHERE_MAX_PARAMS = 9 };

/* Why a fit was refused (fit->refusal); 0 when it was not. */
enum fe_sphere_refusal {
    FE_SPHERE_ACCEPTED = 0,
    FE_SPHERE_TOO_FEW,          /* no more samples than parameters */
    FE_SPHERE_PLANAR,           /* samples near a plane or a line */
    FE_SPHERE_HEMISPHERE,       /* samples on one side of the centre */
    FE_SPHERE_COVERAGE,         /* coverage below min_coverage */
    FE_SPHERE_NOT_PD,           /* fitted quadric is not an ellipsoid */
    FE_SPHERE_DEGENERATE,       /* a fitted scale is zero */
    FE_SPHERE_SINGULAR,         /* Gauss-Newton matrix not positive definite */
    FE_SPHERE_NO_CONVERGENCE,   /* iteration limit reached */
    FE_SPHERE_UNBOUNDED         /* the best fit flattens into a plane */
};

/* One iteration, for the trace callback. */
typedef struct fe_sphere_iteration {
    int iteration;              /* from 1 */
    double cost;                /* S at the current parameters */
    double trial_cost;          /* S at current + step */
    double lambda;              /* damping used for the step */
    double step;                /* max |step| (frame of the solve) */
    int accepted;               /* the step lowered the cost */
    int nparams;
    const double *params;       /* after the iteration, frame of the solve */
} fe_sphere_iteration;

/* A nonzero return stops the fit, which then returns FE_ESTOPPED. */
typedef int fe_sphere_trace_fn(const fe_sphere_iteration *it, void *ctx);

typedef struct fe_sphere_options {
    int max_iterations;         /* default 100 */
    double xtol;                /* default 1e-11, relative step */
    double min_planarity;       /* default 1e-3; 0 disables */
    double min_extent;          /* default 0.5; 0 disables */
    double min_coverage;        /* default 0 (report only) */
    fe_sphere_trace_fn *trace;  /* NULL: no trace */
    void *trace_ctx;
} fe_sphere_options;

/* fe_sphere_default_options: the defaults above, by value. */
fe_sphere_options fe_sphere_default_options(void);

/* A fit.  Units are the sensor's.  matrix is row-major. */
typedef struct fe_sphere_fit {
    int model;                  /* fe_sphere_model */
    int refusal;                /* enum fe_sphere_refusal */
    uint64_t n;                 /* samples */
    int nparams;
    double offset[3];           /* b, the centre */
    double matrix[9];           /* M: y = M (x - b) lies on the unit sphere */
    double radius;              /* the field: geometric mean of semi-axes */
    double axes[3];             /* semi-axes, ascending */
    double params[FE_SPHERE_MAX_PARAMS]; /* b, then s (sphere), s1 s2 s3
                                   (axial) or A11 A12 A13 A22 A23 A33 of
                                   A_x = M^T M (ellipsoid) */
    double se[FE_SPHERE_MAX_PARAMS];     /* standard errors of params */
    double cov[FE_SPHERE_MAX_PARAMS * FE_SPHERE_MAX_PARAMS]; /* row-major,
                                   nparams x nparams */
    double rss;                 /* S = sum of r_i^2, r_i = 1 - |y_i|^2 */
    double rms_percent;         /* 50 sqrt(S / n) */
    double coverage;            /* fraction of the 100 regions visited */
    double extent_lo[3], extent_hi[3]; /* per axis, in half-widths */
    double planarity;           /* smallest/largest covariance eigenvalue */
    int iterations;
    int algebraic;              /* 1: sphere model only, Schmidt's cost has
                                   no finite minimum on these data and this
                                   is the algebraic least-squares sphere */
    double frame_centre[3];     /* c and sigma of the solve's frame */
    double frame_scale;
    double matrix_se[9];        /* standard errors of matrix's entries */
    double se_iid[FE_SPHERE_MAX_PARAMS]; /* the errors independent samples
                                   would have (se when se_blocks is 0) */
    int se_blocks;              /* 0: se assumes independent samples; B:
                                   batch means over B blocks in time */
} fe_sphere_fit;

/* fe_sphere_fit_moments: (iii), the fit users call.  Fits `model` to the
   moments `q`.  No allocation (a few kilobytes of stack).  Returns FE_OK;
   FE_ETOOFEW, FE_EUNDETERMINED, FE_ENOTPD or FE_ENOCONV with fit->refusal
   saying why (fit holds what was measured); FE_ESTOPPED when the trace
   asked; FE_EINVAL for NULL or an unknown model; FE_EINTERNAL if LAPACK
   rejects an argument.  opt NULL: defaults.  Cost: one moment shift and
   a few dozen 10x10 products per iteration, independent of N. */
int fe_sphere_fit_moments(const fe_quadric *q, fe_sphere_model model,
                          const fe_sphere_options *opt, fe_sphere_fit *fit);

/* fe_sphere_fit_blocks: fe_sphere_fit_moments on qb->all, with standard
   errors (se, cov, matrix_se) from the spread of the estimating equations
   over qb's blocks in time (batch means), which holds for correlated
   samples; se_iid keeps the independent-sample errors.  With fewer than 8
   blocks, or for the algebraic sphere, the errors are the independent
   ones and se_blocks is 0.  Errors as fe_sphere_fit_moments.  No
   allocation; cost: one 10 x 10 moment matrix per block. */
int fe_sphere_fit_blocks(const fe_quadric_blocks *qb, fe_sphere_model model,
                         const fe_sphere_options *opt, fe_sphere_fit *fit);

/* fe_sphere_fit_algebraic: the algebraic least-squares sphere, fitted
   linearly from the moments (what fe_sphere_fit_moments falls back to when
   Schmidt's sphere runs away; always defined for samples that are not
   coplanar); fit->algebraic is 1.  Refusals as fe_sphere_fit_moments (too
   few, planar, one-sided judged in the box's half-widths); after a fit the
   struct holds the sphere even when refused.  No allocation. */
int fe_sphere_fit_algebraic(const fe_quadric *q, const fe_sphere_options *opt,
                            fe_sphere_fit *fit);

/* fe_sphere_fit_stored: (ii), the same fit by accumulating J^T J and
   J^T r over the n stored samples xyz[3i..3i+2] at every iteration.
   Same errors as fe_sphere_fit_moments; xyz may be NULL for n = 0 (too
   few, FE_ETOOFEW). */
int fe_sphere_fit_stored(const double *xyz, size_t n, fe_sphere_model model,
                         const fe_sphere_options *opt, fe_sphere_fit *fit);

/* fe_sphere_naive_workspace: doubles of workspace fe_sphere_fit_naive
   needs for n samples: n (p + 1). */
size_t fe_sphere_naive_workspace(size_t n, fe_sphere_model model);

/* fe_sphere_fit_naive: (i), the same fit materialising J and r in the
   caller's `work` (work_len doubles; FE_ESIZE if too small, or for n
   above 2^31 - 1, which BLAS takes as an int: before anything is read). */
int fe_sphere_fit_naive(const double *xyz, size_t n, fe_sphere_model model,
                        const fe_sphere_options *opt, double *work,
                        size_t work_len, fe_sphere_fit *fit);

/* fe_sphere_cost: S = sum of (1 - |M (x_i - b)|^2)^2 of the calibration
   `fit` over the samples summarised by q (other data than it was fitted
   on, say), from the moments.  FE_EINVAL for NULL. */
int fe_sphere_cost(const fe_quadric *q, const fe_sphere_fit *fit,
                   double *rss);

/* fe_sphere_apply: y = M (x - b), the calibrated sample on the unit
   sphere.  x and y may be the same array. */
void fe_sphere_apply(const fe_sphere_fit *fit, const double x[3],
                     double y[3]);

/* A calibration scaled to a known field F: y = matrix (x - offset) has
   magnitude F (9.80665 for an accelerometer in m/s^2, the local Earth
   field for a magnetometer), and how the fit's field compares with F. */
typedef struct fe_sphere_scaled {
    double field;               /* F, in the units the user chose */
    double offset[3];           /* b, the sensor's units */
    double matrix[9];           /* F M, row-major */
    double gain;                /* fitted radius / F: sensor units per unit of F */
} fe_sphere_scaled;

/* fe_sphere_scale: the calibration `fit` scaled so that calibrated
   samples have magnitude `field`; field 0 takes the fitted radius (the
   calibrated samples stay in the sensor's units, gain 1).  FE_EINVAL for
   NULL, or a field that is negative or not finite, or a fit without a
   radius; then *out is unchanged.  No allocation. */
int fe_sphere_scale(const fe_sphere_fit *fit, double field,
                    fe_sphere_scaled *out);

/* fe_sphere_scaled_apply: y = matrix (x - offset), magnitude about F.
   x and y may be the same array. */
void fe_sphere_scaled_apply(const fe_sphere_scaled *s, const double x[3],
                            double y[3]);

/* ArduPilot's compass parameters: its driver corrects a reading h in
   milligauss as mat (h + ofs), mat symmetric with diagonal dia and
   off-diagonal odi = (m12, m13, m23). */
typedef struct fe_sphere_ardupilot {
    double ofs[3];              /* COMPASS_OFS_X/Y/Z, milligauss */
    double dia[3];              /* COMPASS_DIA_X/Y/Z */
    double odi[3];              /* COMPASS_ODI_X/Y/Z */
} fe_sphere_ardupilot;

/* fe_sphere_to_ardupilot: ArduPilot's parameters for `fit`, whose samples
   are in units of mgauss_per_unit milligauss (K: 1 in milligauss, 1000 in
   gauss): ofs = -K b and mat = F M / K, so that ArduPilot's corrected
   field has magnitude field_mgauss (F; 0: the fitted field K R, and mat
   is then R M, near the identity).  FE_EINVAL for NULL, a fit without a
   radius, K not finite and positive, or F negative or not finite (*out
   unchanged).  No allocation. */
int fe_sphere_to_ardupilot(const fe_sphere_fit *fit, double field_mgauss,
                           double mgauss_per_unit, fe_sphere_ardupilot *out);

/* Still segments: a streaming gate that passes the samples taken at rest
   (an accelerometer reads gravity only then).  A window of `window`
   consecutive samples is still when the standard deviation of |x| over it
   is at most max_rel_sd times its mean, and, when rates are given (a
   gyroscope), no rate's norm in it exceeds max_rate; every sample of a
   still window is still.  Decisions are final `window` samples later, so
   the gate hands samples back in order with that delay. */
typedef struct fe_still_options {
    size_t window;              /* default 50 */
    double max_rel_sd;          /* default 0.002 */
    double max_rate;            /* default 0: rates not tested */
} fe_still_options;

typedef struct fe_still {
    fe_still_options opt;
    double *ring;               /* the caller's: fe_still_workspace doubles */
    size_t head, count;         /* oldest sample, samples held */
    uint64_t still, moving;     /* samples handed back, by verdict */
} fe_still;

/* fe_still_default_options: the defaults above, by value. */
fe_still_options fe_still_default_options(void);

/* fe_still_workspace: doubles of ring fe_still_init needs: 7 window. */
size_t fe_still_workspace(size_t window);

/* fe_still_init: an empty gate over the caller's `work` (work_len
   doubles; FE_ESIZE if too small).  FE_EINVAL for NULL, a window below 2,
   or thresholds that are negative or not finite. */
int fe_still_init(fe_still *s, const fe_still_options *opt, double *work,
                  size_t work_len);

/* fe_still_push: take x (and rate, 3 doubles, or NULL); when the ring is
   full the oldest sample is handed back first: *ready = 1, out its x,
   *still its verdict; otherwise *ready = 0.  FE_ENONFINITE for a
   non-finite x or rate, FE_EINVAL for NULL; then s is unchanged.  No
   allocation; cost O(window). */
int fe_still_push(fe_still *s, const double x[3], const double *rate,
                  double out[3], int *still, int *ready);

/* fe_still_flush: at the end of the stream, hand back the oldest sample
   held (out, *still): FE_OK, or FE_END when none is left. */
int fe_still_flush(fe_still *s, double out[3], int *still);

/* Radial residuals and a robust scale for them, to reject outliers
   (samples far outside the bulk: a magnet passing by, a knock on an
   accelerometer).  fe_sphere_radial: e = |M (x - b)| - 1, the sample's
   radial error as a fraction of the field. */
double fe_sphere_radial(const fe_sphere_fit *fit, const double x[3]);

/* A histogram of |e| in constant memory: 25 bins a decade from 1e-7 to
   10 (below and above go to the end bins); the median of |e| is read to
   within 5 %.  All zero bytes is the empty histogram. */
enum { FE_RADIAL_BINS = 200 };
typedef struct fe_radial_hist {
    double count[FE_RADIAL_BINS];
    double n;
} fe_radial_hist;

/* fe_radial_hist_add: count |e|.  FE_ENONFINITE for a non-finite e (h
   unchanged), FE_EINVAL for NULL. */
int fe_radial_hist_add(fe_radial_hist *h, double e);

/* fe_radial_hist_merge: a <- a + b.  FE_EINVAL for NULL. */
int fe_radial_hist_merge(fe_radial_hist *a, const fe_radial_hist *b);

/* fe_radial_hist_scale: the robust scale of e, 1.4826 times the median
   of |e| (the standard deviation for normal errors centred on zero, as a
   fit's are); 0 for an empty histogram. */
double fe_radial_hist_scale(const fe_radial_hist *h);

/* fe_sphere_model_name: "sphere", "axial", "ellipsoid" (NULL if unknown);
   fe_sphere_model_parse: the inverse, FE_EINVAL if unknown. */
const char *fe_sphere_model_name(int model);
int fe_sphere_model_parse(const char *name, fe_sphere_model *model);

/* fe_sphere_refusal_string: a sentence for fit->refusal. */
const char *fe_sphere_refusal_string(int refusal);

#ifdef __cplusplus
}
#endif

#endif /* FOLDEST_SPHERE_H */
/* Sphere Fit Declarations ends here */
