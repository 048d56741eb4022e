/* SPDX-License-Identifier: MIT */
/* Tangled from literate/fold.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/fold.org::Fold Declarations][Fold Declarations]] */
#ifndef FOLDEST_FOLD_H
#define FOLDEST_FOLD_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The functions an accumulator is made of.  `ctx` is the accumulator's
   context; none of these functions may modify it.  Each returns FE_OK or an
   error code, and on error leaves `acc` exactly as it was. */
typedef int fe_init_fn(void *acc, void *ctx);
typedef int fe_step_fn(void *acc, const void *obs, void *ctx);
/* Fold `n` observations in order; stop at the first one refused.  `*done`
   receives how many were folded; `acc` then holds their fold. */
typedef int fe_step_many_fn(void *acc, const void *obs, size_t n,
                            size_t *done, void *ctx);
typedef int fe_merge_fn(void *acc, const void *other, void *ctx);
typedef int fe_copy_fn(void *dst, const void *src, void *ctx);
/* Called by the scans with each accumulation; `index` is 0 for the initial
   one and k after the k-th observation.  A nonzero return stops the scan,
   which then returns that value. */
typedef int fe_visit_fn(const void *acc, size_t index, void *visit_ctx);

/* An accumulator: one estimator, described for the generic fold. */
typedef struct fe_accumulator {
    const char *name;           /* for messages; may be NULL */
    size_t acc_size;            /* bytes of one accumulation */
    size_t obs_size;            /* bytes of one observation (array stride) */
    fe_init_fn *init;           /* empty accumulation; NULL: zero bytes */
    fe_step_fn *step;           /* required */
    fe_step_many_fn *step_many; /* optional fast path for arrays */
    fe_merge_fn *merge;         /* NULL when accumulations cannot merge */
    fe_copy_fn *copy;           /* NULL when memcpy of acc_size is a copy */
    void *ctx;                  /* passed to every function; not modified */
} fe_accumulator;
/* Fold Declarations ends here */
/* [[file:../../literate/fold.org::Fold Function Declarations][Fold Function Declarations]] */
/* fe_init: set `acc` to the accumulator's empty accumulation.
   Errors: FE_EINVAL for null arguments, or the accumulator's own. */
int fe_init(const fe_accumulator *f, void *acc);

/* fe_step: fold one observation into `acc`.  On error `acc` is unchanged. */
int fe_step(const fe_accumulator *f, void *acc, const void *obs);

/* fe_fold: fold the `n` observations of the array `obs` (stride
   f->obs_size) into `acc`, in order.  Stops at the first observation
   refused and returns its code; `*done` (if not NULL) receives the number
   folded, and `acc` holds their fold.  n == 0 is allowed. */
int fe_fold(const fe_accumulator *f, void *acc, const void *obs, size_t n,
            size_t *done);

/* fe_scan: like fe_fold, but also writes the initial accumulation and each
   intermediate one to `out`, which must hold (n + 1) * f->acc_size bytes:
   out[0] is `acc` on entry, out[k] the accumulation after k observations.
   Only for flat accumulations (f->copy == NULL), else FE_ENOTSUP.  After an
   error at observation k, out[0..k] are written. */
int fe_scan(const fe_accumulator *f, void *acc, const void *obs, size_t n,
            void *out, size_t *done);

/* fe_scan_visit: fold as fe_fold, calling `visit` with the initial
   accumulation (index 0) and after each observation (index k).  A nonzero
   return from `visit` stops the scan and is returned. */
int fe_scan_visit(const fe_accumulator *f, void *acc, const void *obs,
                  size_t n, fe_visit_fn *visit, void *visit_ctx,
                  size_t *done);

/* fe_merge: acc <- acc (+) other.  FE_ENOTSUP when f->merge is NULL.
   On error `acc` is unchanged; `other` is never modified. */
int fe_merge(const fe_accumulator *f, void *acc, const void *other);

/* fe_copy: dst <- src, with f->copy or memcpy of f->acc_size bytes. */
int fe_copy(const fe_accumulator *f, void *dst, const void *src);
/* Fold Function Declarations ends here */
/* [[file:../../literate/fold.org::Product Declarations][Product Declarations]] */
/* A component of a product: an accumulator and where its observation
   begins inside the product's observation. */
typedef struct fe_product_part {
    const fe_accumulator *acc;
    size_t obs_offset;          /* bytes; acc->obs_size must fit after it */
} fe_product_part;

/* The product's description; it is the product accumulator's context. */
typedef struct fe_product {
    const fe_product_part *parts;
    size_t count;
} fe_product;

/* The product's accumulation: `accs[i]` is component i's accumulation and
   `spare[i]` scratch of the same kind, used to undo a partial step.  The
   caller owns all of it. */
typedef struct fe_product_acc {
    void *const *accs;
    void *const *spare;
} fe_product_acc;

/* fe_product_accumulator: fill `out` with the product of spec's parts over
   observations of `obs_size` bytes.  `spec` must outlive `out`.  The
   product merges when every part does.  Errors: FE_EINVAL when a part is
   unusable or does not fit inside obs_size. */
int fe_product_accumulator(fe_accumulator *out, const fe_product *spec,
                           size_t obs_size);

#ifdef __cplusplus
}
#endif

#endif /* FOLDEST_FOLD_H */
/* Product Declarations ends here */
