/* SPDX-License-Identifier: MIT */
/* Tangled from literate/error.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/error.org::Error Codes][Error Codes]] */
#ifndef FOLDEST_ERROR_H
#define FOLDEST_ERROR_H

#ifdef __cplusplus
extern "C" {
#endif

/* Status codes returned by every foldest function that can fail. */
enum fe_status {
    FE_OK = 0,          /* success */
    FE_END,             /* a source has no more observations (not an error) */
    FE_EINVAL,          /* invalid argument: null pointer, zero size, bad dimension */
    FE_ENONFINITE,      /* an observation or parameter is NaN or infinite */
    FE_ENOTPD,          /* a matrix that must be positive definite is not */
    FE_ESINGULAR,       /* a linear system is singular or rank deficient */
    FE_ETOOFEW,         /* too few observations to determine the result */
    FE_EUNDETERMINED,   /* the data do not determine the model (coverage, geometry) */
    FE_ENOCONV,         /* an iteration did not converge */
    FE_ENOTSUP,         /* the operation is not supported (e.g. merge, rewind) */
    FE_ESIZE,           /* a buffer or dimension is too small or too large */
    FE_EMISMATCH,       /* accumulations are not compatible (dimension, reference) */
    FE_EIO,             /* reading or writing failed */
    FE_EPARSE,          /* input could not be parsed */
    FE_ENOMEM,          /* memory could not be obtained (never inside a step) */
    FE_ESTOPPED,        /* a callback asked to stop */
    FE_EINTERNAL,       /* a library defect: LAPACK rejected an argument */
    FE_STATUS_COUNT     /* number of codes; not a code */
};

/* fe_strerror: a short English description of a status code.
   Returns a pointer to a constant string, never NULL; an unknown code gives
   "unknown foldest status".  Thread-safe. */
const char *fe_strerror(int status);

#ifdef __cplusplus
}
#endif

#endif /* FOLDEST_ERROR_H */
/* Error Codes ends here */
