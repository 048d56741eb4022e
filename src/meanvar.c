/* SPDX-License-Identifier: MIT */
/* Tangled from literate/meanvar.org: do not edit; edit the .org and run make tangle. */
/* [[file:../literate/meanvar.org::Mean and Variance Includes][Mean and Variance Includes]] */
#include <math.h>

#include "foldest/error.h"
#include "foldest/meanvar.h"

#include "meanvar_private.h"

#if defined(__SSE2__) && !defined(FE_MEANVAR_PORTABLE)
#include <emmintrin.h>
#define FE__MEANVAR_SSE2 1
#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define FE__MEANVAR_AVX2 1
#endif
#endif

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
/* [[file:../literate/meanvar.org::Add eight lanes in their fixed order][Add eight lanes in their fixed order]] */
static double fe__meanvar_lane_total(const double l[FE__MEANVAR_LANES])
{
    return ((l[0] + l[4]) + (l[2] + l[6])) + ((l[1] + l[5]) + (l[3] + l[7]));
}
/* Add eight lanes in their fixed order ends here */
/* [[file:../literate/meanvar.org::Sum a block's lanes by loops][Sum a block's lanes by loops]] */
static void fe__meanvar_sum_lanes_portable(const double *x, size_t g,
                                           double s[FE__MEANVAR_LANES])
{
    for (size_t l = 0; l < FE__MEANVAR_LANES; l++)
        s[l] = 0.0;
    for (size_t i = 0; i < g * FE__MEANVAR_LANES; i += FE__MEANVAR_LANES)
        for (size_t l = 0; l < FE__MEANVAR_LANES; l++)
            s[l] += x[i + l];
}

static void fe__meanvar_deviate_lanes_portable(const double *x, size_t g, double mean,
                                               double q[FE__MEANVAR_LANES],
                                               double c[FE__MEANVAR_LANES])
{
    for (size_t l = 0; l < FE__MEANVAR_LANES; l++)
        q[l] = c[l] = 0.0;
    for (size_t i = 0; i < g * FE__MEANVAR_LANES; i += FE__MEANVAR_LANES)
        for (size_t l = 0; l < FE__MEANVAR_LANES; l++) {
            double d = x[i + l] - mean;
            q[l] += d * d;
            c[l] += d;
        }
}
/* Sum a block's lanes by loops ends here */
/* [[file:../literate/meanvar.org::Sum a block's lanes in SSE2 registers][Sum a block's lanes in SSE2 registers]] */
#if FE__MEANVAR_SSE2

static void fe__meanvar_sum_lanes(const double *x, size_t g,
                                  double s[FE__MEANVAR_LANES])
{
    __m128d s01 = _mm_setzero_pd(), s23 = s01, s45 = s01, s67 = s01;
    for (size_t i = 0; i < g * FE__MEANVAR_LANES; i += FE__MEANVAR_LANES) {
        s01 = _mm_add_pd(s01, _mm_loadu_pd(x + i));
        s23 = _mm_add_pd(s23, _mm_loadu_pd(x + i + 2));
        s45 = _mm_add_pd(s45, _mm_loadu_pd(x + i + 4));
        s67 = _mm_add_pd(s67, _mm_loadu_pd(x + i + 6));
    }
    _mm_storeu_pd(s, s01);
    _mm_storeu_pd(s + 2, s23);
    _mm_storeu_pd(s + 4, s45);
    _mm_storeu_pd(s + 6, s67);
}

static void fe__meanvar_deviate_lanes(const double *x, size_t g, double mean,
                                      double q[FE__MEANVAR_LANES],
                                      double c[FE__MEANVAR_LANES])
{
    const __m128d mu = _mm_set1_pd(mean);
    __m128d q01 = _mm_setzero_pd(), q23 = q01, q45 = q01, q67 = q01;
    __m128d c01 = q01, c23 = q01, c45 = q01, c67 = q01;
    for (size_t i = 0; i < g * FE__MEANVAR_LANES; i += FE__MEANVAR_LANES) {
        __m128d d01 = _mm_sub_pd(_mm_loadu_pd(x + i), mu);
        __m128d d23 = _mm_sub_pd(_mm_loadu_pd(x + i + 2), mu);
        __m128d d45 = _mm_sub_pd(_mm_loadu_pd(x + i + 4), mu);
        __m128d d67 = _mm_sub_pd(_mm_loadu_pd(x + i + 6), mu);
        q01 = _mm_add_pd(q01, _mm_mul_pd(d01, d01));
        q23 = _mm_add_pd(q23, _mm_mul_pd(d23, d23));
        q45 = _mm_add_pd(q45, _mm_mul_pd(d45, d45));
        q67 = _mm_add_pd(q67, _mm_mul_pd(d67, d67));
        c01 = _mm_add_pd(c01, d01);
        c23 = _mm_add_pd(c23, d23);
        c45 = _mm_add_pd(c45, d45);
        c67 = _mm_add_pd(c67, d67);
    }
    _mm_storeu_pd(q, q01);
    _mm_storeu_pd(q + 2, q23);
    _mm_storeu_pd(q + 4, q45);
    _mm_storeu_pd(q + 6, q67);
    _mm_storeu_pd(c, c01);
    _mm_storeu_pd(c + 2, c23);
    _mm_storeu_pd(c + 4, c45);
    _mm_storeu_pd(c + 6, c67);
}

#else
#define fe__meanvar_sum_lanes fe__meanvar_sum_lanes_portable
#define fe__meanvar_deviate_lanes fe__meanvar_deviate_lanes_portable
#endif
/* Sum a block's lanes in SSE2 registers ends here */
/* [[file:../literate/meanvar.org::Sum a block's lanes in AVX2 registers][Sum a block's lanes in AVX2 registers]] */
#if FE__MEANVAR_AVX2

__attribute__((target("avx2")))
static void fe__meanvar_sum_lanes_avx2(const double *x, size_t g,
                                       double s[FE__MEANVAR_LANES])
{
    __m256d s03 = _mm256_setzero_pd(), s47 = s03;
    for (size_t i = 0; i < g * FE__MEANVAR_LANES; i += FE__MEANVAR_LANES) {
        s03 = _mm256_add_pd(s03, _mm256_loadu_pd(x + i));
        s47 = _mm256_add_pd(s47, _mm256_loadu_pd(x + i + 4));
    }
    _mm256_storeu_pd(s, s03);
    _mm256_storeu_pd(s + 4, s47);
}

__attribute__((target("avx2")))
static void fe__meanvar_deviate_lanes_avx2(const double *x, size_t g, double mean,
                                           double q[FE__MEANVAR_LANES],
                                           double c[FE__MEANVAR_LANES])
{
    const __m256d mu = _mm256_set1_pd(mean);
    __m256d q03 = _mm256_setzero_pd(), q47 = q03, c03 = q03, c47 = q03;
    for (size_t i = 0; i < g * FE__MEANVAR_LANES; i += FE__MEANVAR_LANES) {
        __m256d d03 = _mm256_sub_pd(_mm256_loadu_pd(x + i), mu);
        __m256d d47 = _mm256_sub_pd(_mm256_loadu_pd(x + i + 4), mu);
        q03 = _mm256_add_pd(q03, _mm256_mul_pd(d03, d03));
        q47 = _mm256_add_pd(q47, _mm256_mul_pd(d47, d47));
        c03 = _mm256_add_pd(c03, d03);
        c47 = _mm256_add_pd(c47, d47);
    }
    _mm256_storeu_pd(q, q03);
    _mm256_storeu_pd(q + 4, q47);
    _mm256_storeu_pd(c, c03);
    _mm256_storeu_pd(c + 4, c47);
}

#endif
/* Sum a block's lanes in AVX2 registers ends here */
/* [[file:../literate/meanvar.org::Summarise one block by corrected two-pass][Summarise one block by corrected two-pass]] */
typedef void fe__meanvar_sum_fn(const double *, size_t, double *);
typedef void fe__meanvar_deviate_fn(const double *, size_t, double, double *, double *);

static int fe__meanvar_summarise(const double *x, size_t m, fe_meanvar *out,
                                 fe__meanvar_sum_fn *sum_lanes,
                                 fe__meanvar_deviate_fn *deviate_lanes)
{
    double s[FE__MEANVAR_LANES], q[FE__MEANVAR_LANES], c[FE__MEANVAR_LANES];
    double sum, sq, corr, mean;
    size_t g = m / FE__MEANVAR_LANES, i;

    /* First pass: the block's sum, hence its mean. */
    sum_lanes(x, g, s);
    sum = fe__meanvar_lane_total(s);
    for (i = g * FE__MEANVAR_LANES; i < m; i++)
        sum += x[i];
    if (!isfinite(sum))
        return FE_ENONFINITE;
    mean = sum / (double)m;

    /* Second pass: squared deviations and the first-order correction. */
    deviate_lanes(x, g, mean, q, c);
    sq = fe__meanvar_lane_total(q);
    corr = fe__meanvar_lane_total(c);
    for (i = g * FE__MEANVAR_LANES; i < m; i++) {
        double d = x[i] - mean;
        sq += d * d;
        corr += d;
    }
    sq -= corr * corr / (double)m;
    if (!isfinite(sq))
        return FE_ENONFINITE;
    out->n = m;
    out->mean = mean + corr / (double)m;
    out->m2 = sq > 0.0 ? sq : 0.0;
    return FE_OK;
}

static int fe__meanvar_block(const double *x, size_t m, fe_meanvar *out)
{
#if FE__MEANVAR_AVX2
    if (__builtin_cpu_supports("avx2"))
        return fe__meanvar_summarise(x, m, out, fe__meanvar_sum_lanes_avx2,
                                     fe__meanvar_deviate_lanes_avx2);
#endif
    return fe__meanvar_summarise(x, m, out, fe__meanvar_sum_lanes,
                                 fe__meanvar_deviate_lanes);
}

int fe__meanvar_block_portable(const double *x, size_t m, fe_meanvar *out)
{
    return fe__meanvar_summarise(x, m, out, fe__meanvar_sum_lanes_portable,
                                 fe__meanvar_deviate_lanes_portable);
}

int fe__meanvar_block_sse2(const double *x, size_t m, fe_meanvar *out)
{
    return fe__meanvar_summarise(x, m, out, fe__meanvar_sum_lanes,
                                 fe__meanvar_deviate_lanes);
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
