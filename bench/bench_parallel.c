/* SPDX-License-Identifier: MIT */
/* Parallel folds over data in memory, in one run: each accumulator of the
   table below folded with fe_parallel_fold on 1 thread (exactly fe_fold)
   and on 2 threads (and 4 when the machine has them), best of several
   runs.  Prints ns per observation, the speed-up, and checks that the
   parallel result agrees with the serial one.  The goal: at least 1.7x on
   2 threads, or, for a fold that already reads at the memory's pace on
   one core (the mean and variance since its block kernel reads 20 GB/s
   or more), 2 threads within 1.2 times the two-core read floor: the same
   array summed by a read-only accumulator through fe_parallel_fold, the
   memory's own pace on two cores (which is not twice one core's here).

   It also times the single-source pipeline (fe_parallel_fold_source: one
   reader thread, batches folded by a worker) against fe_fold_source.

   Usage: bench_parallel [n]   (n observations for the mean and variance,
   10^8 by default, 8e8 bytes; n/5 three-axis samples for the calibration
   moments, 4.8e8 bytes).

   To add an accumulator (the normal equations, ...): write a `generate`
   and an `agree` function like the meanvar ones and add a row to `rows`
   below.  The accumulation must be flat and at most sizeof(slot) bytes. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "bench.h"
#include "foldest.h"

typedef union { max_align_t align; unsigned char bytes[4096]; } slot;

typedef struct row {
    const char *name;
    fe_accumulator (*make)(void);
    /* Write observation i of the benchmark's data. */
    void (*generate)(void *obs, size_t i, fe_rng *r);
    /* The largest relative difference between two accumulations. */
    double (*agree)(const void *a, const void *b);
    double goal;                /* speed-up wanted on 2 threads */
    unsigned divide;            /* fold n / divide observations */
} row;

static void meanvar_generate(void *obs, size_t i, fe_rng *r)
{
    (void)i;
    *(double *)obs = 3.0 + fe_rng_normal(r);
}

static double meanvar_agree(const void *a, const void *b)
{
    const fe_meanvar *p = a, *q = b;
    if (p->n != q->n)
        return INFINITY;
    return fmax(fabs(p->mean - q->mean) / fabs(q->mean),
                fabs(p->m2 - q->m2) / fabs(q->m2));
}

/* Calibration moments: magnetometer-like samples on an ellipsoid far from
   the origin (24 bytes each). */
static fe_accumulator quadric_make(void)
{
    return fe_quadric_accumulator(NULL);
}

static void quadric_generate(void *obs, size_t i, fe_rng *r)
{
    static const double c[3] = {120.0, -35.0, 410.0}, semi[3] = {48.0, 50.0, 55.0};
    double u[3], *x = obs;
    (void)i;
    fe_rng_unit_vector(r, u);
    for (int j = 0; j < 3; j++)
        x[j] = c[j] + semi[j] * u[j] + 0.4 * fe_rng_normal(r);
}

/* Moments relative to the size their terms can reach; count, reference
   and extremes exactly (fe_quadric_compare). */
static double quadric_agree(const void *a, const void *b)
{
    double apart;
    return fe_quadric_compare(a, b, &apart) == FE_OK ? apart : INFINITY;
}

static const row rows[] = {
    {"mean+variance (fe_meanvar)", fe_meanvar_accumulator, meanvar_generate,
     meanvar_agree, 1.7, 1},
    {"calibration moments (fe_quadric)", quadric_make, quadric_generate,
     quadric_agree, 1.7, 5},
};

/* The read floor: an accumulator that only reads, summing its
   observations' bytes as doubles in eight lanes (ctx: the observation's
   size in bytes, a multiple of 8). */
typedef struct floor_acc { double lane[8]; } floor_acc;

static int floor_step_many(void *acc, const void *obs, size_t n, size_t *done, void *ctx)
{
    floor_acc *a = acc;
    const double *x = obs;
    size_t m = n * ((size_t)(uintptr_t)ctx / sizeof(double)), i = 0;
    for (; i + 8 <= m; i += 8)
        for (int l = 0; l < 8; l++)
            a->lane[l] += x[i + l];
    for (; i < m; i++)
        a->lane[0] += x[i];
    if (done != NULL)
        *done = n;
    return FE_OK;
}

static int floor_step(void *acc, const void *obs, void *ctx)
{
    return floor_step_many(acc, obs, 1, NULL, ctx);
}

static int floor_merge(void *acc, const void *other, void *ctx)
{
    floor_acc *a = acc;
    const floor_acc *b = other;
    (void)ctx;
    for (int l = 0; l < 8; l++)
        a->lane[l] += b->lane[l];
    return FE_OK;
}

static fe_accumulator floor_make(size_t obs_size)
{
    fe_accumulator f = {.name = "read floor", .acc_size = sizeof(floor_acc),
                        .obs_size = obs_size, .step = floor_step,
                        .step_many = floor_step_many, .merge = floor_merge,
                        .ctx = (void *)(uintptr_t)obs_size};
    return f;
}

/* Time one parallel fold of z by f on T threads into `result`. */
static double run_fold(fe_accumulator f, const char *name, const void *z, size_t n,
                       unsigned T, void *result)
{
    slot parts[FE_PARALLEL_MAX_THREADS];
    void *pp[FE_PARALLEL_MAX_THREADS];
    double t0;
    for (unsigned t = 0; t < FE_PARALLEL_MAX_THREADS; t++)
        pp[t] = &parts[t];
    t0 = fe_bench_now();
    if (fe_init(&f, result) != FE_OK
        || fe_parallel_fold(&f, result, z, n, T, pp, NULL) != FE_OK) {
        fprintf(stderr, "bench_parallel: %s: fold failed\n", name);
        exit(1);
    }
    return fe_bench_now() - t0;
}

/* Time one parallel fold of z on T threads into `result`. */
static double run_once(const row *w, const void *z, size_t n, unsigned T,
                       void *result)
{
    return run_fold(w->make(), w->name, z, n, T, result);
}

/* Time one fold of z read through an array source by a single reader,
   batches of 4096 folded by `workers` threads (fe_parallel_fold_source),
   or by fe_fold_source when workers < 0. */
static double run_source(const row *w, const void *z, size_t n, int workers,
                         void *result)
{
    enum { BATCH = 4096, SLOTS = 8 };
    fe_accumulator f = w->make();
    fe_array_source st;
    fe_source src;
    fe_parallel_slot ring[SLOTS];
    slot accs[SLOTS];
    double t0, t;
    int rc;
    for (int s = 0; s < SLOTS; s++) {
        ring[s].obs = malloc(BATCH * f.obs_size);
        ring[s].acc = &accs[s];
    }
    fe_source_from_array(&src, &st, z, n, f.obs_size);
    t0 = fe_bench_now();
    rc = fe_init(&f, result);
    if (rc == FE_OK)
        rc = workers < 0 ? fe_fold_source(&f, result, &src, NULL)
                         : fe_parallel_fold_source(&f, result, &src, (unsigned)workers,
                                                   BATCH, ring, SLOTS, NULL);
    t = fe_bench_now() - t0;
    for (int s = 0; s < SLOTS; s++)
        free(ring[s].obs);
    if (rc != FE_OK) {
        fprintf(stderr, "bench_parallel: %s: source fold failed\n", w->name);
        exit(1);
    }
    return t;
}

int main(int argc, char **argv)
{
    size_t n_all = argc > 1 ? (size_t)strtod(argv[1], NULL) : 100000000;
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    double busy = fe_bench_busy_fraction();
    int ok = 1;

    printf("parallel folds over data in memory (ns per observation, best of 5 interleaved runs); %ld cores online\n",
           cores);
    if (busy > 0.1)
        printf("  NOTE: the cores were %.0f%% busy before the run: other processes share them,\n"
               "  so the speed-ups below are pessimistic; rerun on a quiet machine\n", 100 * busy);
    for (size_t k = 0; k < sizeof rows / sizeof rows[0]; k++) {
        const row *w = &rows[k];
        fe_accumulator f = w->make();
        size_t n = n_all / w->divide;
        unsigned char *z = malloc(n * f.obs_size);
        fe_rng r = fe_rng_seed(2026);
        slot one, two, four, sum;
        double t1, t2, t4 = 0, d2, d4 = 0, speedup, r1 = 1e300, r2 = 1e300;
        int met;
        if (z == NULL || f.acc_size > sizeof(slot)) {
            fprintf(stderr, "bench_parallel: %s: cannot allocate\n", w->name);
            return 1;
        }
        for (size_t i = 0; i < n; i++)
            w->generate(z + i * f.obs_size, i, &r);
        /* Interleaved repetitions, best of each: a burst of load from
           elsewhere hits both thread counts alike. */
        t1 = t2 = t4 = 1e300;
        for (int rep = 0; rep < 5; rep++) {
            t1 = fmin(t1, run_once(w, z, n, 1, &one));
            t2 = fmin(t2, run_once(w, z, n, 2, &two));
            if (cores >= 4)
                t4 = fmin(t4, run_once(w, z, n, 4, &four));
            r1 = fmin(r1, run_fold(floor_make(f.obs_size), "read floor", z, n, 1, &sum));
            r2 = fmin(r2, run_fold(floor_make(f.obs_size), "read floor", z, n, 2, &sum));
        }
        d2 = w->agree(&two, &one);
        if (cores >= 4)
            d4 = w->agree(&four, &one);
        speedup = t1 / t2;
        printf("  %s over %zu observations (%.0f MB)\n", w->name, n,
               (double)(n * f.obs_size) / 1e6);
        printf("    1 thread (fe_fold)     %7.3f ns   %5.2f GB/s\n",
               1e9 * t1 / (double)n, (double)(n * f.obs_size) / t1 / 1e9);
        met = speedup >= w->goal || t2 <= 1.2 * r2;
        printf("    2 threads              %7.3f ns   %5.2f GB/s   speed-up %.2fx  goal >= %.1fx"
               " or within 1.2 of the floor  %s\n",
               1e9 * t2 / (double)n, (double)(n * f.obs_size) / t2 / 1e9, speedup,
               w->goal, met ? "met" : "NOT MET");
        printf("    read floor             %7.3f ns   %5.2f GB/s on 1 thread, %.3f ns   %5.2f GB/s"
               " on 2 (x%.2f); fold / floor %.2f on 1, %.2f on 2\n",
               1e9 * r1 / (double)n, (double)(n * f.obs_size) / r1 / 1e9,
               1e9 * r2 / (double)n, (double)(n * f.obs_size) / r2 / 1e9, r1 / r2, t1 / r1,
               t2 / r2);
        if (cores >= 4)
            printf("    4 threads              %7.3f ns   speed-up %.2fx\n",
                   1e9 * t4 / (double)n, t1 / t4);
        printf("    agreement with 1 thread: %.2e relative (goal <= 1e-12)\n",
               fmax(d2, d4));
        ok = ok && fmax(d2, d4) <= 1e-12;

        /* One source read by one reader: the reader copies every
           observation and calls `next` once per observation, so for a
           light step it is the bottleneck; heavy steps gain. */
        {
            slot ss, p0, p1;
            double ts = 1e300, tp0 = 1e300, tp1 = 1e300;
            for (int rep = 0; rep < 3; rep++) {
                ts = fmin(ts, run_source(w, z, n, -1, &ss));
                tp0 = fmin(tp0, run_source(w, z, n, 0, &p0));
                tp1 = fmin(tp1, run_source(w, z, n, 1, &p1));
            }
            printf("    one source: fe_fold_source %.3f ns; one reader + batches of 4096:"
                   " 0 workers %.3f ns, 1 worker %.3f ns (%.2fx)\n",
                   1e9 * ts / (double)n, 1e9 * tp0 / (double)n, 1e9 * tp1 / (double)n,
                   ts / tp1);
            ok = ok && w->agree(&p1, &one) <= 1e-12 && w->agree(&ss, &one) <= 1e-12;
        }
        free(z);
    }
    return ok ? 0 : 1;
}
