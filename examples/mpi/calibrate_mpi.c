/* SPDX-License-Identifier: MIT */
/* A magnetometer calibration from a stream folded in shards by the ranks of
   an MPI job: each rank folds its shard into the calibration moments
   (fe_quadric, 760 flat bytes), MPI_Reduce merges them with fe_quadric_merge
   as a (non-commutative) operation, and the ROOT SOLVES: it fits the
   ellipsoid to the merged moments with fe_sphere_fit_moments.  The root
   checks the moments and the fit against the serial fold of the same data
   and exits nonzero when they disagree.

     mpirun -np 4 calibrate_mpi              generated stream of 200003 samples
     mpirun -np 4 calibrate_mpi -n 5000000   ... of another length
     mpirun -np 4 calibrate_mpi -nan K       ... with a NaN in sample K

   Build: mpicc -std=c11 calibrate_mpi.c $(pkg-config --cflags --libs foldest)
   (make check-mpi does it in the source tree). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <foldest/mpi.h>

#include "options.h"

FE_MPI_DEFINE_REDUCTION(qm, fe_quadric, fe_quadric_accumulator(NULL));

enum { PIECE = 4096 };

/* Sample k of the stream depends on k only, so any rank can produce any
   slice and the root can replay the whole: a hard-iron offset, unequal
   soft-iron scales, and noise. */
static void sample(size_t k, size_t nan_at, double x[3])
{
    static const double offset[3] = {23.0, -41.0, 57.5}, semi[3] = {47.0, 50.5, 53.0};
    fe_rng r = fe_rng_seed(1000003u * (uint64_t)k + 7);
    double u[3];
    fe_rng_unit_vector(&r, u);
    for (int j = 0; j < 3; j++)
        x[j] = offset[j] + semi[j] * u[j] + 0.3 * fe_rng_normal(&r);
    if (k == nan_at)
        x[1] = NAN;
}

/* Fold samples [begin, end) into q, PIECE at a time, in constant memory. */
static int fold_range(fe_quadric *q, size_t begin, size_t end, size_t nan_at, size_t *done)
{
    fe_accumulator f = fe_quadric_accumulator(NULL);
    static double buf[PIECE][3];
    size_t k = begin;
    int rc = FE_OK;
    *done = 0;
    while (k < end && rc == FE_OK) {
        size_t m = end - k < PIECE ? end - k : PIECE, got = 0;
        for (size_t i = 0; i < m; i++)
            sample(k + i, nan_at, buf[i]);
        rc = fe_fold(&f, q, buf, m, &got);
        *done += got;
        k += m;
    }
    return rc;
}

/* How far apart two moment sets are: each moment relative to the size its
   terms can reach (fe_quadric_compare); infinite when the exact parts
   (count, reference, extremes) differ. */
static double moments_apart(const fe_quadric *p, const fe_quadric *q)
{
    double apart;
    return fe_quadric_compare(p, q, &apart) == FE_OK ? apart : INFINITY;
}

/* The largest difference of two calibrations: offsets relative to the
   field (the radius), and the matrices relative to their largest entry. */
static double fits_apart(const fe_sphere_fit *a, const fe_sphere_fit *b)
{
    double d = 0.0, big = 0.0;
    for (int j = 0; j < 9; j++)
        big = fmax(big, fabs(b->matrix[j]));
    for (int j = 0; j < 3; j++)
        d = fmax(d, fabs(a->offset[j] - b->offset[j]) / b->radius);
    for (int j = 0; j < 9; j++)
        d = fmax(d, fabs(a->matrix[j] - b->matrix[j]) / big);
    return fmax(d, fabs(a->radius - b->radius) / b->radius);
}

int main(int argc, char **argv)
{
    size_t n = 200003, nan_at = (size_t)-1, begin, end, done = 0, sdone = 0;
    int rank, size, rc, ok = 1;
    fe_mpi_reduction red;
    qm_cell mine, all;

    MPI_Init(&argc, &argv);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    example_options(argc, argv, &n, &nan_at);

    /* 1. Each rank folds its shard: the cut of the threads. */
    fe_parallel_chunk(n, (unsigned)size, (unsigned)rank, &begin, &end);
    qm_cell_init(&mine, rank);
    rc = fold_range(&mine.acc, begin, end, nan_at, &done);
    qm_cell_record(&mine, rc, done);

    /* 2. Merge on the root; every rank calls, whatever its fold said. */
    if (qm_reduction(&red) != FE_OK) {
        fprintf(stderr, "rank %d: cannot create the MPI reduction\n", rank);
        MPI_Abort(MPI_COMM_WORLD, 2);
    }
    memset(&all, 0, sizeof all);
    fe_mpi_reduce(&red, &mine, &all, 0, MPI_COMM_WORLD);

    /* 3. The root solves, and checks against the serial fold and fit. */
    if (rank == 0) {
        fe_quadric serial;
        fe_sphere_fit fit, sfit;
        int frc = FE_OK, sfrc = FE_OK, src;
        double dm, df = 0.0;
        fe_quadric_init(&serial, NULL);
        src = fold_range(&serial, 0, n, nan_at, &sdone);
        dm = moments_apart(&all.acc, &serial);
        printf("%d ranks folded %llu of %zu samples", size, (unsigned long long)all.done, n);
        if (all.status != FE_OK)
            printf("; stopped: %s at sample %llu on rank %d", fe_strerror(all.status),
                   (unsigned long long)all.done, all.rank);
        printf("\n");
        ok = all.status == src && all.done == sdone && dm <= 1e-12;
        if (fe_quadric_count(&serial) > 0) {
            frc = fe_sphere_fit_moments(&all.acc, FE_FIT_ELLIPSOID, NULL, &fit);
            sfrc = fe_sphere_fit_moments(&serial, FE_FIT_ELLIPSOID, NULL, &sfit);
            ok = ok && frc == sfrc && fit.refusal == sfit.refusal;
            if (frc == FE_OK && sfrc == FE_OK) {
                df = fits_apart(&fit, &sfit);
                printf("root's ellipsoid fit: offset (%.6f, %.6f, %.6f), field %.6f, rms %.4f %%,"
                       " coverage %.0f %%\n", fit.offset[0], fit.offset[1], fit.offset[2],
                       fit.radius, fit.rms_percent, 100 * fit.coverage);
                /* The moments agree to 1e-12; the fit iterates to a
                   relative step of 1e-11 (xtol) on a problem whose
                   condition is of order one (the samples cover the
                   sphere): the calibrations agree to 1e-9. */
                ok = ok && df <= 1e-9;
            } else {
                printf("root's fit refused: %s\n", fe_strerror(frc));
            }
        }
        printf("serial fold and fit: moments %.2e apart (goal <= 1e-12), calibration %.2e apart"
               " (goal <= 1e-9)%s -> %s\n", dm, df,
               src != FE_OK ? ", stopped at the same refusal" : "", ok ? "agree" : "DISAGREE");
    }
    MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
    fe_mpi_reduction_free(&red);
    MPI_Finalize();
    return ok ? 0 : 1;
}
