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

#endif /* FOLDEST_ACCEPT_COMMON_H */
