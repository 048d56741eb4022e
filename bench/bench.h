/* SPDX-License-Identifier: MIT */
/* Shared by the benchmarks: a monotonic clock and a best-of-k timer. */
#ifndef FE_BENCH_H
#define FE_BENCH_H

#include <stdint.h>
#include <stdio.h>
#include <time.h>

#include "foldest.h"

static inline double fe_bench_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Run the statement(s) `...` in rounds of `reps` timings until a round's
   fastest is within 2 % of the fastest before it (the figure is stable),
   at most FE_BENCH_ROUNDS rounds; `best` receives the fastest time in
   seconds.  On a busy machine the rounds go on while the figure still
   moves. */
#define FE_BENCH_ROUNDS 6
#define FE_BENCH_BEST(best, reps, ...)                                      \
    do {                                                                     \
        (best) = 1e300;                                                      \
        for (int fe_k_ = 0; fe_k_ < FE_BENCH_ROUNDS; fe_k_++) {              \
            double fe_round_ = 1e300;                                        \
            int fe_stable_;                                                  \
            for (int fe_r_ = 0; fe_r_ < (reps); fe_r_++) {                   \
                double fe_t0_ = fe_bench_now();                              \
                __VA_ARGS__;                                                 \
                double fe_dt_ = fe_bench_now() - fe_t0_;                     \
                if (fe_dt_ < fe_round_)                                      \
                    fe_round_ = fe_dt_;                                      \
            }                                                                \
            fe_stable_ = fe_k_ > 0 && fe_round_ >= 0.98 * (best)             \
                         && fe_round_ <= 1.02 * (best);                      \
            if (fe_round_ < (best))                                          \
                (best) = fe_round_;                                          \
            if (fe_stable_)                                                  \
                break;                                                       \
        }                                                                    \
    } while (0)

/* The table the reading benchmarks share: a header and `rows` records of
   eight numeric columns of six or seven significant digits ("2201.72",
   "-0.764163"), drawn from `seed`, written to `out`.  Returns the bytes
   written (ftell), negative on an error. */
static inline double fe_bench_write_table8(FILE *out, long rows, uint64_t seed)
{
    fe_rng rng = fe_rng_seed(seed);
    fprintf(out, "c0,c1,c2,c3,c4,c5,c6,c7\n");
    for (long i = 0; i < rows; i++)
        for (int c = 0; c < 8; c++) {
            double u = fe_rng_uniform(&rng);
            if (c % 2)
                fprintf(out, "%.6f%c", 2.0 * u - 1.0, c == 7 ? '\n' : ',');
            else
                fprintf(out, "%.2f%c", 1e4 * u, c == 7 ? '\n' : ',');
        }
    return (double)ftell(out);
}

/* Keep the optimiser from deleting a computation whose result is unused. */
static inline void fe_bench_keep(double x)
{
    volatile double sink = x;
    (void)sink;
}

/* The fraction of CPU time other processes used during the half second
   before the run (from /proc/stat; -1 when unknown): a busy machine cannot
   show a parallel speed-up. */
static inline double fe_bench_busy_fraction(void)
{
    unsigned long long v[2][8];
    for (int k = 0; k < 2; k++) {
        FILE *f = fopen("/proc/stat", "r");
        int got = f != NULL
                  ? fscanf(f, "cpu %llu %llu %llu %llu %llu %llu %llu %llu",
                           &v[k][0], &v[k][1], &v[k][2], &v[k][3], &v[k][4],
                           &v[k][5], &v[k][6], &v[k][7])
                  : 0;
        if (f != NULL)
            fclose(f);
        if (got != 8)
            return -1.0;
        if (k == 0) {
            struct timespec half = {0, 500000000};
            nanosleep(&half, NULL);
        }
    }
    {
        unsigned long long total = 0, idle;
        for (int i = 0; i < 8; i++)
            total += v[1][i] - v[0][i];
        idle = (v[1][3] - v[0][3]) + (v[1][4] - v[0][4]);
        return total > 0 ? 1.0 - (double)idle / (double)total : -1.0;
    }
}

#endif /* FE_BENCH_H */
