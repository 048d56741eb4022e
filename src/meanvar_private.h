/* SPDX-License-Identifier: MIT */
/* Tangled from literate/meanvar.org: do not edit; edit the .org and run make tangle. */
/* Private: the block kernel by loops alone, for the tests.  Not installed. */
#ifndef FOLDEST_MEANVAR_PRIVATE_H
#define FOLDEST_MEANVAR_PRIVATE_H

#include <stddef.h>

#include "foldest/meanvar.h"

/* fe__meanvar_block_portable: the accumulation of x[0..m-1], m >= 1, by
   the corrected two-pass formula with the lanes summed by plain loops
   (the kernel fe_meanvar_add_many uses where there is no SSE2).
   FE_ENONFINITE, out untouched, when the sum or M2 is not finite. */
int fe__meanvar_block_portable(const double *x, size_t m, fe_meanvar *out);

/* fe__meanvar_block_sse2: the same by the SSE2 kernel (the loops where
   there is no SSE2): the kernel fe_meanvar_add_many uses without AVX2,
   which the tests run on a processor that has AVX2 too. */
int fe__meanvar_block_sse2(const double *x, size_t m, fe_meanvar *out);

#endif /* FOLDEST_MEANVAR_PRIVATE_H */
