/* SPDX-License-Identifier: MIT */
/* common.h: what the two acceptance generators (gen.c, gen_dyn.c) share
   word for word: their random numbers (splitmix64 seeding xoshiro256**),
   summaries of a series, the Levinson-Durbin recursion and the AR
   whitening of the true-spectrum GLS, and piecewise-constant steps.  Like
   them it includes and links nothing of foldest; static functions, each
   generator being one translation unit. */
#ifndef FOLDEST_ACCEPT_COMMON_H
#define FOLDEST_ACCEPT_COMMON_H

#include <math.h>
#include <stdint.h>
#include <string.h>

static uint64_t rng_s[4];

typedef struct { int k; double edge[32], level[33], ramp; } steps;

static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

static uint64_t xoshiro(void)
{
    uint64_t r = rotl(rng_s[1] * 5, 7) * 9, t = rng_s[1] << 17;
    rng_s[2] ^= rng_s[0];
    rng_s[3] ^= rng_s[1];
    rng_s[1] ^= rng_s[2];
    rng_s[0] ^= rng_s[3];
    rng_s[2] ^= t;
    rng_s[3] = rotl(rng_s[3], 45);
    return r;
}

static void rng_seed(uint64_t seed)
{
    for (int i = 0; i < 4; i++)
        rng_s[i] = splitmix64(&seed);
}

static double unif(void) { return ((double)(xoshiro() >> 11) + 0.5) * 0x1.0p-53; }

static double unif2(double a, double b) { return a + (b - a) * unif(); }

static double logunif(double a, double b) { return exp(unif2(log(a), log(b))); }

static double sgn_rand(void) { return unif() < 0.5 ? -1.0 : 1.0; }

static uint64_t hash_str(const char *s)
{
    uint64_t h = 1469598103934665603ULL;
    while (*s)
        h = (h ^ (unsigned char)*s++) * 1099511628211ULL;
    return h;
}

static double mean_of(const double *x, long n)
{
    double s = 0;
    for (long i = 0; i < n; i++)
        s += x[i];
    return s / (double)n;
}

static double sd_of(const double *x, long n)
{
    double m = mean_of(x, n), s = 0;
    for (long i = 0; i < n; i++)
        s += (x[i] - m) * (x[i] - m);
    return sqrt(s / (double)(n - 1));
}

static double rms_of(const double *x, long n)
{
    double s = 0;
    for (long i = 0; i < n; i++)
        s += x[i] * x[i];
    return sqrt(s / (double)n);
}

static double maxabs_of(const double *x, long n)
{
    double m = 0;
    for (long i = 0; i < n; i++)
        m = fabs(x[i]) > m ? fabs(x[i]) : m;
    return m;
}

static double clampd(double x, double lo, double hi) { return x < lo ? lo : x > hi ? hi : x; }

/* Levinson-Durbin: AR(p) prediction coefficients a[1..p] from r[0..p]. */
static void levinson(const double *r, int p, double *a)
{
    double e = r[0], tmp[64];
    memset(a, 0, (size_t)(p + 1) * sizeof *a);
    for (int k = 1; k <= p; k++) {
        double acc = r[k], kap;
        for (int j = 1; j < k; j++)
            acc -= a[j] * r[k - j];
        kap = e > 0 ? acc / e : 0;
        for (int j = 1; j < k; j++)
            tmp[j] = a[j] - kap * a[k - j];
        for (int j = 1; j < k; j++)
            a[j] = tmp[j];
        a[k] = kap;
        e *= 1 - kap * kap;
    }
}

/* The innovations of x under the AR(p) filter a, for rows p .. n - 1 only,
   into out[0 .. n - p): the conditional GLS.  The first p rows, filtered
   with fewer than p lags, are not innovations (row 0 keeps the series'
   whole variance, gamma_0, not sigma_eta^2); counted as if they were, they
   overstate z for columns with a level at the start (gain, bias, slow
   terms) under strongly coloured noise: for a gain under the resonant
   AR(2), z = -10.9 instead of -1.0.  Dropping them loses p of n rows. */
static void whiten(const double *a, int p, const double *x, double *out, long n)
{
    for (long i = p; i < n; i++) {
        double v = x[i];
        for (int k = 1; k <= p; k++)
            v -= a[k] * x[i - k];
        out[i - p] = v;
    }
}

static double steps_eval(const steps *s, double t)
{
    double v = s->level[0];
    for (int i = 0; i < s->k; i++)
        v += (s->level[i + 1] - s->level[i]) * clampd((t - s->edge[i]) / s->ramp + 0.5, 0, 1);
    return v;
}

/* The least squares of the generators' identifiability checks need
   scratch vectors: each generator defines vec() (calloc, or exit 4 with
   its own name). */
static double *vec(long n);

enum { ACCEPT_LSQ_MAXCOL = 20 };    /* columns of one regression, at most */

/* Least squares of y on k columns (n rows) by modified Gram-Schmidt (twice)
   on columns scaled to unit norm.  Writes coef and se (from the residual
   variance rss/(n-k)); returns the residual sum of squares, -1 when a
   column is numerically dependent on the others. */
static double lsq(double *const *cols, int k, const double *y, long n, double *coef, double *se)
{
    static double *q[ACCEPT_LSQ_MAXCOL], *res;
    static long qn;
    double r[ACCEPT_LSQ_MAXCOL][ACCEPT_LSQ_MAXCOL] = {{0}};
    double rinv[ACCEPT_LSQ_MAXCOL][ACCEPT_LSQ_MAXCOL] = {{0}};
    double scale[ACCEPT_LSQ_MAXCOL], qty[ACCEPT_LSQ_MAXCOL];
    double rss = 0;
    if (qn < n) {
        for (int j = 0; j < ACCEPT_LSQ_MAXCOL; j++) {
            free(q[j]);
            q[j] = vec(n);
        }
        free(res);
        res = vec(n);
        qn = n;
    }
    for (int j = 0; j < k; j++) {
        double nn = 0;
        for (long i = 0; i < n; i++)
            nn += cols[j][i] * cols[j][i];
        if (!(nn > 0) || !isfinite(nn))
            return -1;
        scale[j] = 1.0 / sqrt(nn);
        for (long i = 0; i < n; i++)
            q[j][i] = cols[j][i] * scale[j];
    }
    for (int j = 0; j < k; j++) {
        double nn = 0;
        for (int pass = 0; pass < 2; pass++)
            for (int l = 0; l < j; l++) {
                double d = 0;
                for (long i = 0; i < n; i++)
                    d += q[l][i] * q[j][i];
                r[l][j] += d;
                for (long i = 0; i < n; i++)
                    q[j][i] -= d * q[l][i];
            }
        for (long i = 0; i < n; i++)
            nn += q[j][i] * q[j][i];
        nn = sqrt(nn);
        if (nn < 1e-10)
            return -1;
        r[j][j] = nn;
        for (long i = 0; i < n; i++)
            q[j][i] /= nn;
    }
    memcpy(res, y, (size_t)n * sizeof *res);
    for (int j = 0; j < k; j++) {
        double d = 0;
        for (long i = 0; i < n; i++)
            d += q[j][i] * res[i];
        qty[j] = d;
        for (long i = 0; i < n; i++)
            res[i] -= d * q[j][i];
    }
    for (long i = 0; i < n; i++)
        rss += res[i] * res[i];
    for (int j = k - 1; j >= 0; j--) {
        rinv[j][j] = 1.0 / r[j][j];
        for (int c = j + 1; c < k; c++) {
            double s = 0;
            for (int l = j + 1; l <= c; l++)
                s += r[j][l] * rinv[l][c];
            rinv[j][c] = -s / r[j][j];
        }
    }
    for (int j = 0; j < k; j++) {
        double c = 0, v = 0;
        for (int l = j; l < k; l++) {
            c += rinv[j][l] * qty[l];
            v += rinv[j][l] * rinv[j][l];
        }
        coef[j] = c * scale[j];
        se[j] = sqrt(v * rss / (double)(n - k)) * scale[j];
    }
    return rss;
}

#endif /* FOLDEST_ACCEPT_COMMON_H */
