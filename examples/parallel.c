/* SPDX-License-Identifier: MIT */
/* The mean and variance of 4 million values folded on 1, 2 and 4 threads:
   the same answer each time (to rounding; bit for bit for a given thread
   count), and the first bad value found wherever it is.

   Build against an installed foldest:
     cc parallel.c $(pkg-config --cflags --libs foldest) -o parallel */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include <foldest.h>

static double seconds(void)
{
    struct timespec t;
    timespec_get(&t, TIME_UTC);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int main(void)
{
    enum { N = 4000000, MAX_THREADS = 4 };
    double *x = malloc(N * sizeof *x);
    fe_accumulator mv = fe_meanvar_accumulator();
    fe_meanvar scratch[MAX_THREADS - 1];
    void *partials[MAX_THREADS - 1] = {&scratch[0], &scratch[1], &scratch[2]};
    fe_rng r = fe_rng_seed(42);
    size_t done = 0;
    int rc;

    if (x == NULL)
        return 1;
    for (size_t i = 0; i < N; i++)
        x[i] = 20.0 + 0.5 * fe_rng_normal(&r);

    for (unsigned threads = 1; threads <= MAX_THREADS; threads *= 2) {
        fe_meanvar a = FE_MEANVAR_EMPTY;
        double t0 = seconds();
        rc = fe_parallel_fold(&mv, &a, x, N, threads, partials, &done);
        if (rc != FE_OK) {
            fprintf(stderr, "parallel fold: %s\n", fe_strerror(rc));
            free(x);
            return 1;
        }
        printf("%u thread%s: n = %llu, mean = %.15g, variance = %.15g (%.1f ms)\n",
               threads, threads > 1 ? "s" : " ", (unsigned long long)a.n,
               fe_meanvar_mean(&a), fe_meanvar_variance(&a), 1e3 * (seconds() - t0));
    }

    /* Two bad values: the parallel fold reports the first, and keeps the
       fold of everything before it. */
    x[3000000] = NAN;
    x[1234567] = INFINITY;
    {
        fe_meanvar a = FE_MEANVAR_EMPTY;
        rc = fe_parallel_fold(&mv, &a, x, N, 4, partials, &done);
        printf("with bad values at 1234567 and 3000000, 4 threads: %s at index %zu;"
               " kept n = %llu, mean = %.6f\n", fe_strerror(rc), done,
               (unsigned long long)a.n, fe_meanvar_mean(&a));
    }
    free(x);
    return 0;
}
