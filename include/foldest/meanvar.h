/* SPDX-License-Identifier: MIT */
/* Tangled from literate/meanvar.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/meanvar.org::Mean and Variance Declarations][Mean and Variance Declarations]] */
#ifndef FOLDEST_MEANVAR_H
#define FOLDEST_MEANVAR_H

#include <stddef.h>
#include <stdint.h>

#include "foldest/fold.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The running mean and variance of a stream of doubles: count, mean and
   the sum of squared deviations from the mean.  A plain value: copy it,
   store it, send it over the network.  Zero-initialised, it is empty. */
typedef struct fe_meanvar {
    uint64_t n;
    double mean;
    double m2;
} fe_meanvar;

/* The empty accumulation, for initialisers. */
#define FE_MEANVAR_EMPTY {0, 0.0, 0.0}

/* fe_meanvar_add: fold one observation (Welford).  FE_ENONFINITE when x,
   or the updated mean or M2, is not finite; then `a` is unchanged. */
int fe_meanvar_add(fe_meanvar *a, double x);

/* fe_meanvar_add_many: fold x[0..n-1] in blocks (same result as n calls of
   fe_meanvar_add, up to rounding, and faster).  Stops at the first value
   refused; `*done` (if not NULL) receives how many were folded. */
int fe_meanvar_add_many(fe_meanvar *a, const double *x, size_t n,
                        size_t *done);

/* fe_meanvar_merge: a <- a (+) b (Chan).  FE_ENONFINITE if the result
   would overflow; then `a` is unchanged. */
int fe_meanvar_merge(fe_meanvar *a, const fe_meanvar *b);

/* Read-outs.  The mean of an empty accumulation is 0; the variances are 0
   for fewer than two observations (sample) or none (population). */
double fe_meanvar_mean(const fe_meanvar *a);
double fe_meanvar_variance(const fe_meanvar *a);            /* M2/(n-1) */
double fe_meanvar_population_variance(const fe_meanvar *a); /* M2/n */
double fe_meanvar_stddev(const fe_meanvar *a);              /* sqrt of sample */

/* fe_meanvar_accumulator: the accumulator for fe_fold and friends, over
   observations of type double and accumulations of type fe_meanvar. */
fe_accumulator fe_meanvar_accumulator(void);

#ifdef __cplusplus
}
#endif

#endif /* FOLDEST_MEANVAR_H */
/* Mean and Variance Declarations ends here */
