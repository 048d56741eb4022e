/* SPDX-License-Identifier: MIT */
/* Tangled from literate/parallel.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/parallel.org::Parallel Fold Declarations][Parallel Fold Declarations]] */
#ifndef FOLDEST_PARALLEL_H
#define FOLDEST_PARALLEL_H

#include <stddef.h>

#include "foldest/fold.h"
#include "foldest/stream.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The largest thread count the parallel folds accept (their bookkeeping
   lives on the caller's stack). */
#define FE_PARALLEL_MAX_THREADS 64

/* fe_parallel_chunk: the bounds [*begin, *end) of chunk t when n items are
   cut into `parts` consecutive chunks of sizes differing by at most one:
   [floor(t n / parts), floor((t+1) n / parts)).  This is the cut
   fe_parallel_fold uses; MPI programs use it to shard by rank.
   Errors: FE_EINVAL when parts == 0, t >= parts or a pointer is NULL. */
int fe_parallel_chunk(size_t n, unsigned parts, unsigned t, size_t *begin,
                      size_t *end);

/* fe_parallel_fold: fold the n observations of `obs` (stride f->obs_size)
   into `acc` on `threads` threads; the same as fe_fold up to rounding.
   The array is cut by fe_parallel_chunk; chunk 0 is folded into `acc` on
   the calling thread, chunk t >= 1 into partials[t - 1] (initialised with
   fe_init) on a new thread; then acc <- acc (+) partials[0] (+) ...
   (+) partials[threads - 2], in that order, on the calling thread.  The
   result depends only on n, threads and the data, never on scheduling;
   threads == 1 is exactly fe_fold.
   Memory: `partials` holds threads - 1 pointers to caller-owned
   accumulations (may be NULL when threads == 1), distinct from `acc` and
   from each other; their content afterwards is unspecified.
   Errors: FE_EINVAL (null or aliased arguments, threads == 0), FE_ESIZE
   (threads > FE_PARALLEL_MAX_THREADS), FE_ENOTSUP (threads > 1 and no
   merge): nothing is folded and `acc` is unchanged.  Otherwise, if a step
   refuses an observation, the code of the refusal with the lowest index is
   returned, `*done` (if not NULL) receives that index, and `acc` holds the
   fold of obs[0 .. *done).  If a merge or the init of a partial refuses,
   its code is returned, `*done` is the start of the chunk concerned and
   `acc` holds the fold of the chunks before it.
   Cost: the fold's work spread over the threads, plus threads - 1 thread
   creations (tens of microseconds each) and merges. */
int fe_parallel_fold(const fe_accumulator *f, void *acc, const void *obs,
                     size_t n, unsigned threads, void *const *partials,
                     size_t *done);

/* fe_parallel_fold_sources: fold `count` sources, one per thread, into
   `acc`: sources[0] into `acc` on the calling thread, sources[t] into
   partials[t - 1] on a new thread, merged in the order of the sources.
   The result is the fold of the concatenation sources[0] ++ sources[1]
   ++ ..., up to rounding.  Each source is used by one thread only and
   must not share state with another.  `*done` receives the number of
   observations of the concatenation folded; on a refusal, the first one
   (in concatenation order) is observation *done, with the same contract as
   fe_parallel_fold.  A source's own error (FE_EIO, FE_EPARSE) is a refusal
   like a step's.  Errors as fe_parallel_fold, plus FE_EINVAL when a
   source is NULL or its obs_size differs from f->obs_size. */
int fe_parallel_fold_sources(const fe_accumulator *f, void *acc,
                             fe_source *const *sources, unsigned count,
                             void *const *partials, size_t *done);

/* One slot of the ring used by fe_parallel_fold_source: caller memory for
   a batch of observations and for one accumulation. */
typedef struct fe_parallel_slot {
    void *obs;      /* batch * f->obs_size bytes, aligned for the observation */
    void *acc;      /* an accumulation, prepared like a partial */
} fe_parallel_slot;

/* The largest ring fe_parallel_fold_source accepts. */
#define FE_PARALLEL_MAX_SLOTS 256

/* fe_parallel_fold_source: fold the single source `src` into `acc` with
   `workers` worker threads (0: the calling thread does everything).  The
   calling thread reads `batch` observations at a time into a free slot of
   `slots` (nslots of them, 1 <= nslots <= FE_PARALLEL_MAX_SLOTS); a worker
   folds the batch into the slot's accumulation (initialised with fe_init);
   the calling thread merges the batch accumulations into `acc` in stream
   order.  The result depends only on `batch` and the data, never on
   `workers` or scheduling; it equals fe_fold_source up to rounding.
   Memory: the slots' buffers and accumulations are the caller's, distinct
   from each other and from `acc`; their content afterwards is unspecified.
   nslots >= 2 * workers keeps the workers busy.
   Errors: FE_EINVAL (null or aliased arguments, batch == 0, nslots out of
   range, src->obs_size != f->obs_size), FE_ESIZE (workers >
   FE_PARALLEL_MAX_THREADS), FE_ENOTSUP (no merge), FE_ENOMEM (the
   synchronisation could not be set up): nothing is read.  Otherwise the
   first refusal in stream order is returned with `*done` its index and
   `acc` the fold of the observations before it (a step's refusal, or the
   source's own error after all earlier batches); a merge or init refusal
   gives *done = the start of its batch.  Cost: a copy of each observation
   and one merge per batch on the calling thread, plus the steps spread over
   the workers. */
int fe_parallel_fold_source(const fe_accumulator *f, void *acc,
                            fe_source *src, unsigned workers, size_t batch,
                            const fe_parallel_slot *slots, unsigned nslots,
                            size_t *done);

#ifdef __cplusplus
}
#endif

#endif /* FOLDEST_PARALLEL_H */
/* Parallel Fold Declarations ends here */
