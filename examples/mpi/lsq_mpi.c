/* SPDX-License-Identifier: MIT */
/* A least-squares fit from rows folded in shards by the ranks of an MPI job:
   each rank folds its shard into normal equations (fe_lsq), which point into
   storage, so the storage travels inside the cell
   (FE_MPI_DEFINE_BOUND_REDUCTION); MPI_Reduce adds them with fe_lsq_merge,
   and the ROOT SOLVES with fe_lsq_solve (coefficients, residual sum of
   squares, covariance).  The root checks the normal equations and the
   solution against the serial fold and exits nonzero when they disagree.

     mpirun -np 4 lsq_mpi                 500009 generated rows
     mpirun -np 4 lsq_mpi -n 10000000     ... another number of rows
     mpirun -np 4 lsq_mpi -nan K          ... with a NaN in row K

   Build: mpicc -std=c11 lsq_mpi.c $(pkg-config --cflags --libs foldest)
   (make check-mpi does it in the source tree). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <foldest/mpi.h>

#include "options.h"

/* The model: y = b0 + b1 t + b2 sin(2 pi t) + b3 cos(2 pi t) + b4 t^2. */
enum { P = 5, CAPACITY = (P + 1) * (P + 1), PIECE = 4096 };

FE_MPI_DEFINE_BOUND_REDUCTION(ls, fe_lsq, fe_lsq_accumulator(), CAPACITY,
                              fe_mpi_rebind_lsq);

static const double truth[P] = {1.5, -0.75, 0.3, 2.0, 0.125};

/* Row k depends on k only: regressors at t = k / n and a noisy response. */
static void row(size_t k, size_t n, size_t nan_at, double j[P], double *y)
{
    fe_rng r = fe_rng_seed(2654435761u * (uint64_t)k + 11);
    double t = 4.0 * (double)k / (double)(n > 1 ? n - 1 : 1);
    j[0] = 1.0;
    j[1] = t;
    j[2] = sin(6.283185307179586 * t);
    j[3] = cos(6.283185307179586 * t);
    j[4] = t * t;
    *y = 0.05 * fe_rng_normal(&r);
    for (int i = 0; i < P; i++)
        *y += truth[i] * j[i];
    if (k == nan_at)
        *y = NAN;
}

/* Fold rows [begin, end) into a, PIECE at a time. */
static int fold_range(fe_lsq *a, size_t begin, size_t end, size_t n, size_t nan_at,
                      size_t *done)
{
    static double J[PIECE][P], y[PIECE];
    size_t k = begin;
    int rc = FE_OK;
    *done = 0;
    while (k < end && rc == FE_OK) {
        size_t m = end - k < PIECE ? end - k : PIECE, got = 0;
        for (size_t i = 0; i < m; i++)
            row(k + i, n, nan_at, J[i], &y[i]);
        rc = fe_lsq_add_rows(a, &J[0][0], P, y, NULL, m, &got);
        *done += got;
        k += m;
    }
    return rc;
}

/* Entry (k, l) of the normal equations relative to sqrt(G_kk G_ll), the
   largest total magnitude its terms can have (Cauchy-Schwarz, weights
   >= 0): the entries that cancel are judged on the scale of their terms. */
static double gram_apart(const fe_lsq *a, const fe_lsq *b)
{
    double worst = 0.0;
    if (a->p != b->p || a->n != b->n)
        return INFINITY;
    for (size_t k = 0; k <= b->p; k++)
        for (size_t l = k; l <= b->p; l++) {
            double s = sqrt(fe_lsq_gram(b, k, k) * fe_lsq_gram(b, l, l));
            if (s > 0.0)
                worst = fmax(worst, fabs(fe_lsq_gram(a, k, l) - fe_lsq_gram(b, k, l)) / s);
        }
    return worst;
}

int main(int argc, char **argv)
{
    size_t n = 500009, nan_at = (size_t)-1, begin, end, done = 0, sdone = 0;
    int rank, size, rc, ok = 1;
    fe_mpi_reduction red;
    ls_cell mine, all;

    MPI_Init(&argc, &argv);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    example_options(argc, argv, &n, &nan_at);

    /* 1. Each rank binds its normal equations to its cell's storage and
       folds its shard into them. */
    fe_parallel_chunk(n, (unsigned)size, (unsigned)rank, &begin, &end);
    ls_cell_init(&mine, rank);
    rc = fe_lsq_init(&mine.acc, P, mine.storage);
    if (rc == FE_OK)
        rc = fold_range(&mine.acc, begin, end, n, nan_at, &done);
    ls_cell_record(&mine, rc, done);

    /* 2. Add them on the root. */
    if (ls_reduction(&red) != FE_OK) {
        fprintf(stderr, "rank %d: cannot create the MPI reduction\n", rank);
        MPI_Abort(MPI_COMM_WORLD, 2);
    }
    memset(&all, 0, sizeof all);
    fe_mpi_reduce(&red, &mine, &all, 0, MPI_COMM_WORLD);

    /* 3. The root solves, and checks against the serial fold. */
    if (rank == 0) {
        double gs[CAPACITY], x[P], sx[P], cov[P * P], scov[P * P], work[CAPACITY];
        double rss = 0, srss = 0, dg, dx = 0.0;
        fe_lsq serial;
        int src, xrc, sxrc;
        ls_cell_rebind(&all);           /* its pointer came from elsewhere */
        fe_lsq_init(&serial, P, gs);
        src = fold_range(&serial, 0, n, n, nan_at, &sdone);
        dg = gram_apart(&all.acc, &serial);
        printf("%d ranks folded %llu of %zu rows", size, (unsigned long long)all.done, n);
        if (all.status != FE_OK)
            printf("; stopped: %s at row %llu on rank %d", fe_strerror(all.status),
                   (unsigned long long)all.done, all.rank);
        printf("\n");
        ok = all.status == src && all.done == sdone && dg <= 1e-12;
        xrc = fe_lsq_solve(&all.acc, NULL, P, x, &rss, cov, work);
        sxrc = fe_lsq_solve(&serial, NULL, P, sx, &srss, scov, work);
        ok = ok && xrc == sxrc;
        if (xrc == FE_OK && sxrc == FE_OK) {
            printf("root's solution (truth in brackets):");
            for (int i = 0; i < P; i++) {
                printf(" %.6f+-%.1e [%g]", x[i], sqrt(cov[i * P + i]), truth[i]);
                /* The normal equations agree to 1e-12 of their terms;
                   the solve multiplies that by the condition of the
                   (column-scaled) system, below 1e3 for these columns. */
                dx = fmax(dx, fabs(x[i] - sx[i]) / fabs(sx[i]));
            }
            dx = fmax(dx, fabs(rss - srss) / srss);
            printf("\n  residual sum of squares %.6g\n", rss);
            ok = ok && dx <= 1e-9;
        } else {
            printf("root's solve refused: %s\n", fe_strerror(xrc));
        }
        printf("serial fold and solve: normal equations %.2e apart (goal <= 1e-12),"
               " solution %.2e apart (goal <= 1e-9)%s -> %s\n", dg, dx,
               src != FE_OK ? ", stopped at the same refusal" : "", ok ? "agree" : "DISAGREE");
    }
    MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
    fe_mpi_reduction_free(&red);
    MPI_Finalize();
    return ok ? 0 : 1;
}
