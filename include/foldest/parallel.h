/* Tangled from literate/parallel.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/parallel.org::Parallel Fold Declarations][Parallel Fold Declarations]] */
#ifndef FOLDEST_PARALLEL_H
#define FOLDEST_PARALLEL_H

#include <stddef.h>

#include "foldest/fold.h"
#include "foldest/stream.h"

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

#endif /* FOLDEST_PARALLEL_H */
/* Parallel Fold Declarations ends here */
