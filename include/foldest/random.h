/* SPDX-License-Identifier: MIT */
/* Tangled from literate/random.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/random.org::Random Declarations][Random Declarations]] */
#ifndef FOLDEST_RANDOM_H
#define FOLDEST_RANDOM_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* A xoshiro256** generator; the caller owns it, one per thread. */
typedef struct fe_rng {
    uint64_t s[4];
    double spare;               /* second Box-Muller deviate */
    int has_spare;
} fe_rng;

/* fe_rng_seed: the generator for `seed` (any value).  Same seed, same
   sequence, on every platform. */
fe_rng fe_rng_seed(uint64_t seed);

/* fe_rng_next: 64 uniformly distributed bits. */
uint64_t fe_rng_next(fe_rng *r);

/* fe_rng_uniform: a double uniform in [0, 1). */
double fe_rng_uniform(fe_rng *r);

/* fe_rng_normal: a standard normal deviate, N(0, 1). */
double fe_rng_normal(fe_rng *r);

/* fe_rng_unit_vector: u[0..2] uniform on the unit sphere (three normal
   deviates, normalised). */
void fe_rng_unit_vector(fe_rng *r, double u[3]);

#ifdef __cplusplus
}
#endif

#endif /* FOLDEST_RANDOM_H */
/* Random Declarations ends here */
