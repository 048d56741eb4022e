/* SPDX-License-Identifier: MIT */
/* Mean and variance over 10^8 doubles in memory, in one run:
     - the memory read floor (a sum that only reads),
     - a naive two-pass loop (sum, then squared deviations),
     - a single-accumulator Welford loop (a chain of dependent divisions),
     - GSL's gsl_rstat_add (on 10^7 values: it is slow),
     - the library: fe_fold with fe_meanvar_accumulator (blocked, merged).
   Prints ns per observation, ratios, and checks that the library's mean and
   variance agree with the two-pass result to 1e-12 relative. */
#include <math.h>
#include <stdlib.h>

#include <gsl/gsl_rstat.h>

#include "bench.h"
#include "foldest.h"

int main(int argc, char **argv)
{
    size_t n = argc > 1 ? (size_t)strtod(argv[1], NULL) : 100000000;
    size_t n_gsl = n / 10;
    double *x = malloc(n * sizeof *x);
    fe_rng r = fe_rng_seed(2026);
    double t_read, t_two, t_welford, t_gsl, t_fold;
    double two_mean = 0, two_var = 0, w_mean = 0, w_var = 0;
    fe_meanvar a = FE_MEANVAR_EMPTY;
    fe_accumulator f = fe_meanvar_accumulator();
    double rel_mean, rel_var, busy_before = fe_bench_busy_fraction(), busy_after;

    if (x == NULL) {
        fprintf(stderr, "bench_meanvar: cannot allocate %zu doubles\n", n);
        return 1;
    }
    for (size_t i = 0; i < n; i++)
        x[i] = 3.0 + fe_rng_normal(&r);

    FE_BENCH_BEST(t_read, 3, {
        double s[8] = {0};
        size_t i = 0;
        for (; i + 8 <= n; i += 8)
            for (int l = 0; l < 8; l++)
                s[l] += x[i + l];
        fe_bench_keep(s[0] + s[1] + s[2] + s[3] + s[4] + s[5] + s[6] + s[7]);
    });
    FE_BENCH_BEST(t_two, 3, {
        double s = 0, q = 0;
        for (size_t i = 0; i < n; i++)
            s += x[i];
        two_mean = s / (double)n;
        for (size_t i = 0; i < n; i++)
            q += (x[i] - two_mean) * (x[i] - two_mean);
        two_var = q / (double)(n - 1);
    });
    FE_BENCH_BEST(t_welford, 1, {
        double mean = 0, m2 = 0;
        for (size_t i = 0; i < n; i++) {
            double d = x[i] - mean;
            mean += d / (double)(i + 1);
            m2 += d * (x[i] - mean);
        }
        w_mean = mean;
        w_var = m2 / (double)(n - 1);
    });
    FE_BENCH_BEST(t_gsl, 1, {
        gsl_rstat_workspace *w = gsl_rstat_alloc();
        for (size_t i = 0; i < n_gsl; i++)
            gsl_rstat_add(x[i], w);
        fe_bench_keep(gsl_rstat_variance(w));
        gsl_rstat_free(w);
    });
    FE_BENCH_BEST(t_fold, 3, {
        a = (fe_meanvar)FE_MEANVAR_EMPTY;
        if (fe_fold(&f, &a, x, n, NULL) != FE_OK) {
            fprintf(stderr, "bench_meanvar: fold failed\n");
            exit(1);
        }
    });

    busy_after = fe_bench_busy_fraction();
    rel_mean = fabs(fe_meanvar_mean(&a) - two_mean) / fabs(two_mean);
    rel_var = fabs(fe_meanvar_variance(&a) - two_var) / two_var;
    printf("mean+variance over %zu doubles in memory (ns per observation, best of runs); "
           "machine busy %.0f%% before, %.0f%% after (other processes' share of the cores)\n",
           n, 100 * busy_before, 100 * busy_after);
    printf("  memory read floor (8-lane sum)     %7.3f\n", 1e9 * t_read / (double)n);
    printf("  naive two-pass loop                %7.3f\n", 1e9 * t_two / (double)n);
    printf("  single-accumulator Welford         %7.3f\n", 1e9 * t_welford / (double)n);
    printf("  GSL gsl_rstat_add (%zu values)  %7.3f\n", n_gsl, 1e9 * t_gsl / (double)n_gsl);
    printf("  foldest fe_fold(meanvar)           %7.3f   goal <= 1.5\n", 1e9 * t_fold / (double)n);
    printf("  ratios: fold/read floor %.2f (goal <= 1.2: %s), Welford/fold %.1f, two-pass/fold %.2f, GSL/fold %.1f\n",
           t_fold / t_read, t_fold / t_read <= 1.2 ? "met" : "not met", t_welford / t_fold, t_two / t_fold,
           (t_gsl / (double)n_gsl) / (t_fold / (double)n));
    printf("  agreement with two-pass: mean %.2e, variance %.2e relative (goal <= 1e-12);"
           " Welford variance %.2e\n", rel_mean, rel_var, fabs(w_var - two_var) / two_var);
    (void)w_mean;
    free(x);
    return rel_mean <= 1e-12 && rel_var <= 1e-12 ? 0 : 1;
}
