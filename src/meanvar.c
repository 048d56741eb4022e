/* SPDX-License-Identifier: MIT */
/* Tangled from literate/meanvar.org: do not edit; edit the .org and run make tangle. */
/* [[file:../literate/meanvar.org::Mean and Variance Includes][Mean and Variance Includes]] */
#include <math.h>

#include "foldest/error.h"
#include "foldest/meanvar.h"

enum { FE__MEANVAR_BLOCK = 512, FE__MEANVAR_LANES = 8 };
/* Mean and Variance Includes ends here */
/* [[file:../literate/meanvar.org::Fold one observation][Fold one observation]] */
int fe_meanvar_add(fe_meanvar *a, double x)
{
    double n1, delta, mean, m2;
    if (a == NULL)
        return FE_EINVAL;
    if (!isfinite(x))
        return FE_ENONFINITE;
    n1 = (double)(a->n + 1);
    delta = x - a->mean;
    mean = a->mean + delta / n1;
    m2 = a->m2 + delta * (x - mean);
    if (!isfinite(mean) || !isfinite(m2))
        return FE_ENONFINITE;
    a->n++;
    a->mean = mean;
    a->m2 = m2;
    return FE_OK;
}
/* Fold one observation ends here */
/* [[file:../literate/meanvar.org::Merge two accumulations][Merge two accumulations]] */
int fe_meanvar_merge(fe_meanvar *a, const fe_meanvar *b)
{
    double na, nb, n, delta, mean, m2;
    if (a == NULL || b == NULL)
        return FE_EINVAL;
    if (b->n == 0)
        return FE_OK;
    if (a->n == 0) {
        *a = *b;
        return FE_OK;
    }
    na = (double)a->n;
    nb = (double)b->n;
    n = na + nb;
    delta = b->mean - a->mean;
    mean = a->mean + delta * (nb / n);
    m2 = a->m2 + b->m2 + delta * delta * (na * nb / n);
    if (!isfinite(mean) || !isfinite(m2))
        return FE_ENONFINITE;
    a->n += b->n;
    a->mean = mean;
    a->m2 = m2;
    return FE_OK;
}
/* Merge two accumulations ends here */
/* [[file:../literate/meanvar.org::Summarise one block by corrected two-pass][Summarise one block by corrected two-pass]] */
static int fe__meanvar_block(const double *x, size_t m, fe_meanvar *out)
{
    double s[FE__MEANVAR_LANES] = {0}, q[FE__MEANVAR_LANES] = {0},
           c[FE__MEANVAR_LANES] = {0};
    double sum = 0.0, sq = 0.0, corr = 0.0, mean;
    size_t i = 0, l;

    /* First pass: the block's sum, hence its mean. */
    for (; i + FE__MEANVAR_LANES <= m; i += FE__MEANVAR_LANES)
        for (l = 0; l < FE__MEANVAR_LANES; l++)
            s[l] += x[i + l];
    for (; i < m; i++)
        sum += x[i];
    for (l = 0; l < FE__MEANVAR_LANES; l++)
        sum += s[l];
    if (!isfinite(sum))
        return FE_ENONFINITE;
    mean = sum / (double)m;

    /* Second pass: squared deviations and the first-order correction. */
    for (i = 0; i + FE__MEANVAR_LANES <= m; i += FE__MEANVAR_LANES)
        for (l = 0; l < FE__MEANVAR_LANES; l++) {
            double d = x[i + l] - mean;
            q[l] += d * d;
            c[l] += d;
        }
    for (; i < m; i++) {
        double d = x[i] - mean;
        sq += d * d;
        corr += d;
    }
    for (l = 0; l < FE__MEANVAR_LANES; l++) {
        sq += q[l];
        corr += c[l];
    }
    sq -= corr * corr / (double)m;
    if (!isfinite(sq))
        return FE_ENONFINITE;
    out->n = m;
    out->mean = mean + corr / (double)m;
    out->m2 = sq > 0.0 ? sq : 0.0;
    return FE_OK;
}
/* Summarise one block by corrected two-pass ends here */
/* [[file:../literate/meanvar.org::Fold an array block by block][Fold an array block by block]] */
int fe_meanvar_add_many(fe_meanvar *a, const double *x, size_t n,
                        size_t *done)
{
    size_t k = 0;
    int rc = FE_OK;

    if (done != NULL)
        *done = 0;
    if (a == NULL || (x == NULL && n > 0))
        return FE_EINVAL;
    while (k < n) {
        size_t m = n - k < FE__MEANVAR_BLOCK ? n - k : FE__MEANVAR_BLOCK;
        fe_meanvar block;
        rc = fe__meanvar_block(x + k, m, &block);
        if (rc == FE_OK)
            rc = fe_meanvar_merge(a, &block);
        if (rc == FE_OK) {
            k += m;
            continue;
        }
        /* Something in this block is not finite: find it one by one. */
        for (size_t end = k + m; k < end; k++) {
            rc = fe_meanvar_add(a, x[k]);
            if (rc != FE_OK)
                break;
        }
        if (rc != FE_OK)
            break;
    }
    if (done != NULL)
        *done = k;
    return rc;
}
/* Fold an array block by block ends here */
/* [[file:../literate/meanvar.org::Read out mean and variance][Read out mean and variance]] */
double fe_meanvar_mean(const fe_meanvar *a)
{
    return a->n > 0 ? a->mean : 0.0;
}

double fe_meanvar_variance(const fe_meanvar *a)
{
    return a->n > 1 ? a->m2 / (double)(a->n - 1) : 0.0;
}

double fe_meanvar_population_variance(const fe_meanvar *a)
{
    return a->n > 0 ? a->m2 / (double)a->n : 0.0;
}

double fe_meanvar_stddev(const fe_meanvar *a)
{
    return sqrt(fe_meanvar_variance(a));
}
/* Read out mean and variance ends here */
/* [[file:../literate/meanvar.org::Mean and variance as an accumulator][Mean and variance as an accumulator]] */
static int fe__meanvar_step(void *acc, const void *obs, void *ctx)
{
    (void)ctx;
    return fe_meanvar_add(acc, *(const double *)obs);
}

static int fe__meanvar_step_many(void *acc, const void *obs, size_t n,
                                 size_t *done, void *ctx)
{
    (void)ctx;
    return fe_meanvar_add_many(acc, obs, n, done);
}

static int fe__meanvar_merge(void *acc, const void *other, void *ctx)
{
    (void)ctx;
    return fe_meanvar_merge(acc, other);
}

fe_accumulator fe_meanvar_accumulator(void)
{
    fe_accumulator f = {
        .name = "meanvar",
        .acc_size = sizeof(fe_meanvar),
        .obs_size = sizeof(double),
        .init = 0,
        .step = fe__meanvar_step,
        .step_many = fe__meanvar_step_many,
        .merge = fe__meanvar_merge,
        .copy = 0,
        .ctx = 0,
    };
    return f;
}
/* Mean and variance as an accumulator ends here */
