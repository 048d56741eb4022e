/* SPDX-License-Identifier: MIT */
/* Mean and variance of a stream, three ways: an array with fe_fold, a
   generator with fe_fold_source (constant memory, any length), and two
   halves folded apart and merged, as threads or machines would.

   Build against an installed foldest:
     cc meanvar.c $(pkg-config --cflags --libs foldest) -o meanvar */
#include <math.h>
#include <stdio.h>

#include <foldest.h>

/* Observation k of an endless-looking stream: seeded noise around 20. */
struct noisy { fe_rng rng; size_t length; };

static int noisy_next(void *obs, size_t index, void *ctx)
{
    struct noisy *g = ctx;
    if (index == 0)
        g->rng = fe_rng_seed(1);
    if (index >= g->length)
        return FE_END;
    *(double *)obs = 20.0 + 0.5 * fe_rng_normal(&g->rng);
    return FE_OK;
}

int main(void)
{
    const double z[3] = {55, 89, 144};
    fe_accumulator mv = fe_meanvar_accumulator();
    fe_meanvar a = FE_MEANVAR_EMPTY, left = FE_MEANVAR_EMPTY, right = FE_MEANVAR_EMPTY;
    int rc;

    /* 1. An array. */
    rc = fe_fold(&mv, &a, z, 3, NULL);
    if (rc != FE_OK) {
        fprintf(stderr, "fold: %s\n", fe_strerror(rc));
        return 1;
    }
    printf("array {55, 89, 144}: n = %llu, mean = %g, variance = %g\n",
           (unsigned long long)a.n, fe_meanvar_mean(&a), fe_meanvar_variance(&a));

    /* 2. A stream of a million observations, never stored. */
    {
        struct noisy g = {fe_rng_seed(0), 1000000};
        double slot;
        fe_generator_source state;
        fe_source src;
        fe_meanvar s = FE_MEANVAR_EMPTY;
        fe_source_from_generator(&src, &state, noisy_next, &g, &slot, sizeof slot);
        rc = fe_fold_source(&mv, &s, &src, NULL);
        if (rc != FE_OK) {
            fprintf(stderr, "fold_source: %s\n", fe_strerror(rc));
            return 1;
        }
        printf("stream of 10^6 (20 + 0.5 N(0,1)): mean = %.4f, stddev = %.4f\n",
               fe_meanvar_mean(&s), fe_meanvar_stddev(&s));
    }

    /* 3. Split, fold apart, merge: the same answer as the whole. */
    fe_fold(&mv, &left, z, 1, NULL);
    fe_fold(&mv, &right, z + 1, 2, NULL);
    fe_merge(&mv, &left, &right);
    printf("merged {55} + {89, 144}: mean = %g, variance = %g\n",
           fe_meanvar_mean(&left), fe_meanvar_variance(&left));

    /* 4. Bad input is refused and nothing is lost. */
    rc = fe_meanvar_add(&a, NAN);
    printf("adding NaN: %s; still n = %llu, mean = %g\n", fe_strerror(rc),
           (unsigned long long)a.n, fe_meanvar_mean(&a));
    return 0;
}
