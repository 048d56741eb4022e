/* The mean and variance of 10^8 doubles in memory, in one run:
     - serially, on rank 0 alone (fe_fold over the whole array);
     - distributed, every rank folding its shard (the cut of
       fe_parallel_chunk) followed by MPI_Reduce with the merge as the
       operation; timed on the root from a barrier to the reduced result.
   Prints ns per observation and the speed-up (goal: at least 1.7x on 2
   ranks of a 2-core machine), and checks the agreement to 1e-12.

   Run by `make bench-mpi`:  mpirun -np 2 --oversubscribe bench_mpi [n] */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench.h"
#include <foldest/mpi.h>

FE_MPI_DEFINE_REDUCTION(mv, fe_meanvar, fe_meanvar_accumulator());

enum { SEND_PIECE = 1 << 24 };

int main(int argc, char **argv)
{
    size_t n = argc > 1 ? (size_t)strtod(argv[1], NULL) : 100000000;
    size_t begin, end, m;
    int rank, size, ok = 1;
    double busy = fe_bench_busy_fraction();
    double *x = NULL, t_serial = 1e300, t_mpi = 1e300;
    fe_accumulator f = fe_meanvar_accumulator();
    fe_meanvar serial = FE_MEANVAR_EMPTY;
    fe_mpi_reduction red;
    mv_cell mine, all;

    MPI_Init(&argc, &argv);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    fe_parallel_chunk(n, (unsigned)size, (unsigned)rank, &begin, &end);
    m = end - begin;

    /* The root generates the stream and sends each rank its shard, so that
       both timings fold the very same numbers. */
    x = malloc((rank == 0 ? n : m) * sizeof *x + 1);
    if (x == NULL) {
        fprintf(stderr, "bench_mpi: rank %d cannot allocate\n", rank);
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    if (rank == 0) {
        fe_rng r = fe_rng_seed(2026);
        for (size_t i = 0; i < n; i++)
            x[i] = 3.0 + fe_rng_normal(&r);
        for (int q = 1; q < size; q++) {
            size_t b, e;
            fe_parallel_chunk(n, (unsigned)size, (unsigned)q, &b, &e);
            for (size_t k = b; k < e; k += SEND_PIECE) {
                size_t c = e - k < SEND_PIECE ? e - k : SEND_PIECE;
                MPI_Send(x + k, (int)c, MPI_DOUBLE, q, 0, MPI_COMM_WORLD);
            }
        }
    } else {
        for (size_t k = 0; k < m; k += SEND_PIECE) {
            size_t c = m - k < SEND_PIECE ? m - k : SEND_PIECE;
            MPI_Recv(x + k, (int)c, MPI_DOUBLE, 0, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        }
    }
    if (mv_reduction(&red) != FE_OK)
        MPI_Abort(MPI_COMM_WORLD, 1);

    /* Five rounds, each timing the serial fold then the distributed one;
       the best of each is kept, so a burst of load from elsewhere hits
       both alike. */
    for (int rep = 0; rep < 5; rep++) {
        double t0, t;
        size_t done = 0;
        int rc;
        const double *shard = rank == 0 ? x + begin : x;

        /* Serial: the root alone.  The others wait asleep, polling a
           non-blocking barrier every millisecond: a blocking MPI_Barrier
           would spin on the other core and slow the root's reads. */
        MPI_Barrier(MPI_COMM_WORLD);
        if (rank == 0) {
            MPI_Request req;
            t0 = fe_bench_now();
            serial = (fe_meanvar)FE_MEANVAR_EMPTY;
            if (fe_fold(&f, &serial, x, n, NULL) != FE_OK)
                MPI_Abort(MPI_COMM_WORLD, 1);
            t = fe_bench_now() - t0;
            if (t < t_serial)
                t_serial = t;
            MPI_Ibarrier(MPI_COMM_WORLD, &req);
            MPI_Wait(&req, MPI_STATUS_IGNORE);
        } else {
            MPI_Request req;
            int arrived = 0;
            struct timespec ms = {0, 1000000};
            MPI_Ibarrier(MPI_COMM_WORLD, &req);
            while (MPI_Test(&req, &arrived, MPI_STATUS_IGNORE) == MPI_SUCCESS && !arrived)
                nanosleep(&ms, NULL);
        }

        /* Distributed: from a barrier to the reduced cell on the root. */
        MPI_Barrier(MPI_COMM_WORLD);
        t0 = MPI_Wtime();
        mv_cell_init(&mine, rank);
        rc = fe_fold(&f, &mine.acc, shard, m, &done);
        mv_cell_record(&mine, rc, done);
        fe_mpi_reduce(&red, &mine, &all, 0, MPI_COMM_WORLD);
        t = MPI_Wtime() - t0;
        if (t < t_mpi)
            t_mpi = t;
    }

    if (rank == 0) {
        double dm = fabs(all.acc.mean - serial.mean) / fabs(serial.mean);
        double dv = fabs(all.acc.m2 - serial.m2) / serial.m2;
        double speedup = t_serial / t_mpi;
        ok = all.status == FE_OK && all.done == n && dm <= 1e-12 && dv <= 1e-12;
        printf("mean+variance over %zu doubles in memory, MPI (ns per observation, best of 5 interleaved rounds)\n", n);
        if (busy > 0.1)
            printf("  NOTE: the cores were %.0f%% busy before the run: other processes share them,\n"
                   "  so the speed-up below is pessimistic; rerun on a quiet machine\n", 100 * busy);
        printf("  serial fe_fold on rank 0          %7.3f\n", 1e9 * t_serial / (double)n);
        printf("  %d ranks: shard folds + MPI_Reduce %7.3f   speed-up %.2fx  goal >= 1.7x  %s\n",
               size, 1e9 * t_mpi / (double)n, speedup, speedup >= 1.7 ? "met" : "NOT MET");
        printf("  agreement with serial: mean %.2e, M2 %.2e relative (goal <= 1e-12)\n", dm, dv);
    }
    MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
    fe_mpi_reduction_free(&red);
    free(x);
    MPI_Finalize();
    return ok ? 0 : 1;
}
