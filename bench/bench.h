/* Shared by the benchmarks: a monotonic clock and a best-of-k timer. */
#ifndef FE_BENCH_H
#define FE_BENCH_H

#include <stdio.h>
#include <time.h>

static inline double fe_bench_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Run the statement(s) `...` `reps` times; `best` receives the fastest time in seconds. */
#define FE_BENCH_BEST(best, reps, ...)                                      \
    do {                                                                     \
        (best) = 1e300;                                                      \
        for (int fe_r_ = 0; fe_r_ < (reps); fe_r_++) {                       \
            double fe_t0_ = fe_bench_now();                                  \
            __VA_ARGS__;                                                     \
            double fe_dt_ = fe_bench_now() - fe_t0_;                         \
            if (fe_dt_ < (best))                                             \
                (best) = fe_dt_;                                             \
        }                                                                    \
    } while (0)

/* Keep the optimiser from deleting a computation whose result is unused. */
static inline void fe_bench_keep(double x)
{
    volatile double sink = x;
    (void)sink;
}

#endif /* FE_BENCH_H */
