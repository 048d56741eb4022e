/* SPDX-License-Identifier: MIT */
/* Tangled from literate/error.org: do not edit; edit the .org and run make tangle. */
/* [[file:../literate/error.org::Error Messages][Error Messages]] */
#include "foldest/error.h"

static const char *const fe__messages[FE_STATUS_COUNT] = {
    [FE_OK]            = "success",
    [FE_END]           = "end of stream",
    [FE_EINVAL]        = "invalid argument",
    [FE_ENONFINITE]    = "value is NaN or infinite",
    [FE_ENOTPD]        = "matrix is not positive definite",
    [FE_ESINGULAR]     = "system is singular or rank deficient",
    [FE_ETOOFEW]       = "too few observations",
    [FE_EUNDETERMINED] = "data do not determine the model",
    [FE_ENOCONV]       = "iteration did not converge",
    [FE_ENOTSUP]       = "operation not supported",
    [FE_ESIZE]         = "buffer or dimension out of range",
    [FE_EMISMATCH]     = "accumulations are not compatible",
    [FE_EIO]           = "input/output error",
    [FE_EPARSE]        = "malformed input",
    [FE_ENOMEM]        = "out of memory",
    [FE_ESTOPPED]      = "stopped by callback",
    [FE_EINTERNAL]     = "internal error: LAPACK rejected an argument",
};

const char *fe_strerror(int status)
{
    if (status < 0 || status >= FE_STATUS_COUNT)
        return "unknown foldest status";
    return fe__messages[status];
}
/* Error Messages ends here */
