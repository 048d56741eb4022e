/* SPDX-License-Identifier: MIT */
/* Tangled from literate/random.org: do not edit; edit the .org and run make tangle. */
/* [[file:../literate/random.org::Random Generator][Random Generator]] */
#include <math.h>

#include "foldest/random.h"

static uint64_t fe__splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9e3779b97f4a7c15u);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
    return z ^ (z >> 31);
}

static uint64_t fe__rotl(uint64_t x, int k)
{
    return (x << k) | (x >> (64 - k));
}

fe_rng fe_rng_seed(uint64_t seed)
{
    fe_rng r;
    for (int i = 0; i < 4; i++)
        r.s[i] = fe__splitmix64(&seed);
    r.spare = 0.0;
    r.has_spare = 0;
    return r;
}

uint64_t fe_rng_next(fe_rng *r)
{
    uint64_t *s = r->s;
    uint64_t result = fe__rotl(s[1] * 5, 7) * 9;
    uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = fe__rotl(s[3], 45);
    return result;
}

double fe_rng_uniform(fe_rng *r)
{
    return (double)(fe_rng_next(r) >> 11) * 0x1.0p-53;
}

double fe_rng_normal(fe_rng *r)
{
    const double two_pi = 6.283185307179586476925286766559;
    double u1, u2, radius;
    if (r->has_spare) {
        r->has_spare = 0;
        return r->spare;
    }
    u1 = 1.0 - fe_rng_uniform(r);       /* in (0, 1] */
    u2 = fe_rng_uniform(r);
    radius = sqrt(-2.0 * log(u1));
    r->spare = radius * sin(two_pi * u2);
    r->has_spare = 1;
    return radius * cos(two_pi * u2);
}

void fe_rng_unit_vector(fe_rng *r, double u[3])
{
    double s;
    do {
        s = 0.0;
        for (int j = 0; j < 3; j++) {
            u[j] = fe_rng_normal(r);
            s += u[j] * u[j];
        }
    } while (!(s > 0.0));
    s = sqrt(s);
    for (int j = 0; j < 3; j++)
        u[j] /= s;
}
/* Random Generator ends here */
