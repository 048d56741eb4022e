/* SPDX-License-Identifier: MIT */
/* Discovery from a recording folded in shards by the ranks of an MPI job:
   each rank folds its rows into discovery's block Gram matrices
   (fe_discover_acc, bound to the storage inside its cell), MPI_Reduce merges
   consecutive shards with fe_discover_merge (which also forms the one lag
   product across each cut), and the ROOT RANKS the candidate terms and
   selects a model with fe_discover_select.  The root checks the Gram
   matrices, the ranking and the selection against the serial fold and
   exits nonzero when they disagree.

   The residual r = recording - simulation hides quadratic drag (0.02 v|v|)
   under coloured (moving-average) noise; the candidates are a bias, a gain
   error, viscous drag, quadratic drag and a thermal term.  Two recordings
   are concatenated: the second begins at row n/2, and no lag product is
   formed across that boundary, whichever rank holds it.

     mpirun -np 4 discover_mpi                200003 rows
     mpirun -np 4 discover_mpi -n 2000000     ... another number of rows
     mpirun -np 4 discover_mpi -nan K         ... with a NaN in row K

   Build: mpicc -std=c11 discover_mpi.c $(pkg-config --cflags --libs foldest)
   (make check-mpi does it in the source tree). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <foldest/mpi.h>

#include "options.h"

enum {
    M = 5,                      /* candidate columns */
    K = 10,                     /* time blocks */
    DIM = M + 1,
    CAPACITY = FE_DISCOVER_ACC_DOUBLES(M, K),   /* fe_discover_acc_doubles(M, K) */
    VALUES = FE_DISCOVER_ACC_VALUES(M, K)       /* then fe_discover_add_rows' scratch */
};

FE_MPI_DEFINE_BOUND_REDUCTION(dc, fe_discover_acc, fe_discover_accumulator(), CAPACITY,
                              fe_mpi_rebind_discover);

static const fe_discover_group groups[M] = {
    {"bias", 0, 1}, {"gain", 1, 1}, {"viscous_drag", 2, 1}, {"quadratic_drag", 3, 1},
    {"thermal", 4, 1},
};

/* Row k depends on k only (the noise is a moving average of per-index
   draws, so it is coloured yet computable anywhere). */
static void row(size_t k, size_t n, size_t nan_at, double phi[M], double *r)
{
    double t = 0.01 * (double)k, s = 3.0 * sin(0.7 * t) + sin(2.3 * t);
    double v = 2.1 * cos(0.7 * t) + 2.3 * cos(2.3 * t), noise = 0.0;
    for (int lag = 0; lag < 3; lag++) {
        fe_rng g = fe_rng_seed(97 * (uint64_t)(k + 3 - (size_t)lag));
        noise += 0.02 * fe_rng_normal(&g);
    }
    phi[0] = 1.0;
    phi[1] = s;
    phi[2] = v;
    phi[3] = v * fabs(v);
    phi[4] = 20.0 + 5.0 * sin(6.283185307179586 * (double)k / (double)(n > 0 ? n : 1));
    *r = 0.02 * phi[3] + noise;
    if (k == nan_at)
        *r = NAN;
}

/* Fold rows [begin, end); the recording boundary at n/2 is a break. */
static int fold_range(fe_discover_acc *a, size_t begin, size_t end, size_t n, size_t nan_at,
                      size_t *done)
{
    double phi[M], r;
    int rc = FE_OK;
    *done = 0;
    for (size_t k = begin; k < end && rc == FE_OK; k++) {
        if (k == n / 2)
            fe_discover_break(a);
        row(k, n, nan_at, phi, &r);
        rc = fe_discover_add(a, phi, r);
        *done += rc == FE_OK;
    }
    return rc;
}

/* Every value in the storage (block Gram matrices, lag products, first and
   last rows, counts) relative to the scale of its terms: entry (i, j) of a
   Gram or lag matrix against sqrt(G_ii G_jj) of the whole fold's Gram
   (Cauchy-Schwarz), rows and counts against themselves. */
static double gram_apart(const fe_discover_acc *a, const fe_discover_acc *b)
{
    double worst = 0.0, diag[DIM] = {0};
    if (a->n != b->n || a->row0 != b->row0 || a->have_prev != b->have_prev)
        return INFINITY;
    for (size_t blk = 0; blk <= K; blk++)
        for (size_t i = 0; i < DIM; i++)
            diag[i] += b->gram[blk * DIM * DIM + i * DIM + i];
    for (size_t blk = 0; blk <= K + 1; blk++)     /* K + 1 Gram blocks, then lag */
        for (size_t i = 0; i < DIM; i++)
            for (size_t j = 0; j < DIM; j++) {
                size_t e = blk * DIM * DIM + i * DIM + j;
                double s = sqrt(diag[i] * diag[j]);
                if (s > 0.0)
                    worst = fmax(worst, fabs(a->gram[e] - b->gram[e]) / s);
            }
    for (size_t e = (K + 2) * DIM * DIM; e < VALUES; e++)
        worst = fmax(worst, fabs(a->gram[e] - b->gram[e])
                                / fmax(fabs(b->gram[e]), 1e-300));
    return worst;
}

/* The decisions must be the same; the statistics equal to 1e-9. */
static double results_apart(const fe_discover_result *a, const fe_discover_result *b)
{
    double d = 0.0;
    if (a->steps != b->steps || a->ncols != b->ncols)
        return INFINITY;
    for (size_t s = 0; s < a->steps; s++)
        if (a->added[s] != b->added[s])
            return INFINITY;
    for (size_t s = 0; s <= a->steps; s++) {
        if (a->nranked[s] != b->nranked[s])
            return INFINITY;
        /* Drops against the largest of the step (a drop of 1e-6 of it is
           a difference of sums that agree to rounding), statistics against
           max(|t|, 1) (a t of 0.07 is rounding noise of the same kind). */
        double top = 1e-300;
        for (size_t i = 0; i < b->nranked[s]; i++)
            top = fmax(top, fabs(b->ranking[s][i].rss_drop));
        for (size_t i = 0; i < a->nranked[s]; i++) {
            const fe_discover_rank *p = &a->ranking[s][i], *q = &b->ranking[s][i];
            if (p->group != q->group || p->redundant != q->redundant)
                return INFINITY;
            d = fmax(d, fabs(p->rss_drop - q->rss_drop) / top);
            d = fmax(d, fabs(p->statistic - q->statistic) / fmax(fabs(q->statistic), 1.0));
        }
    }
    for (size_t c = 0; c < a->ncols; c++)
        d = fmax(d, fabs(a->coef[c] - b->coef[c]) / fmax(fabs(b->coef[c]), 1e-300));
    return fmax(d, fabs(a->final.rss - b->final.rss) / b->final.rss);
}

int main(int argc, char **argv)
{
    size_t n = 200003, nan_at = (size_t)-1, begin, end, done = 0, sdone = 0;
    int rank, size, rc, ok = 1;
    fe_mpi_reduction red;
    dc_cell mine, all;

    MPI_Init(&argc, &argv);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    example_options(argc, argv, &n, &nan_at);

    /* 1. Each rank's part knows where it starts (row0 = its first row), so
       its rows land in the same blocks as in one fold. */
    fe_parallel_chunk(n, (unsigned)size, (unsigned)rank, &begin, &end);
    dc_cell_init(&mine, rank);
    rc = fe_discover_acc_init(&mine.acc, M, K, n * 4 / 5, begin, mine.storage, CAPACITY);
    if (rc == FE_OK)
        rc = fold_range(&mine.acc, begin, end, n, nan_at, &done);
    dc_cell_record(&mine, rc, done);

    /* 2. Merge the consecutive parts on the root. */
    if (dc_reduction(&red) != FE_OK) {
        fprintf(stderr, "rank %d: cannot create the MPI reduction\n", rank);
        MPI_Abort(MPI_COMM_WORLD, 2);
    }
    memset(&all, 0, sizeof all);
    fe_mpi_reduce(&red, &mine, &all, 0, MPI_COMM_WORLD);

    /* 3. The root ranks and selects, and checks against the serial fold. */
    if (rank == 0) {
        static double gs[CAPACITY];
        size_t nw = fe_discover_workspace_doubles(M, K);
        double *work = malloc(nw * sizeof *work), dg = INFINITY, dr = 0.0, goal = 1e-9;
        static fe_discover_result res, sres;
        fe_discover_options opt = fe_discover_default_options();
        fe_discover_acc serial;
        int src = FE_OK, xrc = FE_EINVAL, sxrc = FE_EINVAL, bound = 0;
        dc_cell_rebind(&all);           /* its pointers came from elsewhere */
        if (fe_discover_acc_init(&serial, M, K, n * 4 / 5, 0, gs, CAPACITY) == FE_OK) {
            bound = 1;
            src = fold_range(&serial, 0, n, n, nan_at, &sdone);
            dg = gram_apart(&all.acc, &serial);
        } else {
            dg = all.status == FE_ETOOFEW ? 0.0 : INFINITY;   /* too short: both refuse */
            src = FE_ETOOFEW;
        }
        printf("%d ranks folded %llu of %zu rows", size, (unsigned long long)all.done, n);
        if (all.status != FE_OK)
            printf("; stopped: %s at row %llu on rank %d", fe_strerror(all.status),
                   (unsigned long long)all.done, all.rank);
        printf("\n");
        ok = work != NULL && all.status == src && all.done == sdone && dg <= 1e-12;
        /* After a refusal both hold the fold of the rows before it: the
           selection from that prefix must agree too. */
        if (ok && bound) {
            xrc = fe_discover_select(&all.acc, groups, M, &opt, &res, work, nw);
            sxrc = fe_discover_select(&serial, groups, M, &opt, &sres, work, nw);
            ok = xrc == sxrc;
        }
        if (ok && xrc == FE_OK) {
            printf("root's ranking of the candidates before the first step:\n");
            for (size_t i = 0; i < res.nranked[0]; i++) {
                const fe_discover_rank *q = &res.ranking[0][i];
                printf("  %-16s RSS drop %10.4g  statistic %9.3g  p %.2g\n",
                       groups[q->group].name, q->rss_drop, q->statistic, q->p_value);
            }
            printf("root's selection:");
            for (size_t s = 0; s < res.steps; s++)
                printf(" %s", groups[res.added[s]].name);
            printf(" (final RMS %.4g, held-out RMS %.4g)\n", res.final.rms, res.final.heldout_rms);
            dr = results_apart(&res, &sres);
            /* The Gram matrices agree to 1e-12 of their terms; the ranking
               and the fit solve systems of condition below 1e3, on sums
               prewhitened by the noise model, which cancel: a slow column
               whitens to (1 - sum phi) of itself, so the whitened sums are
               (1 + sum phi^2) / (1 - sum phi)^2 times more sensitive to
               the rounding of the raw ones.  The goal scales with that. */
            {
                double sp = 0.0, sq = 0.0;
                for (size_t i = 0; i < sres.noise.order; i++) {
                    sp += sres.noise.phi[i];
                    sq += sres.noise.phi[i] * sres.noise.phi[i];
                }
                goal = 1e-9 * fmax(1.0, (1.0 + sq) / ((1.0 - sp) * (1.0 - sp)));
            }
            ok = dr <= goal;
        } else if (ok && bound) {
            printf("root's selection refused: %s (the serial one too)\n", fe_strerror(xrc));
        }
        printf("serial fold and selection: Gram matrices %.2e apart (goal <= 1e-12),"
               " ranking and fit %.2e apart (goal <= %.2g, same decisions)%s -> %s\n", dg, dr,
               goal, src != FE_OK ? ", stopped at the same refusal" : "", ok ? "agree" : "DISAGREE");
        free(work);
    }
    MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
    fe_mpi_reduction_free(&red);
    MPI_Finalize();
    return ok ? 0 : 1;
}
