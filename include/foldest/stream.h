/* SPDX-License-Identifier: MIT */
/* Tangled from literate/stream.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/stream.org::Stream Declarations][Stream Declarations]] */
#ifndef FOLDEST_STREAM_H
#define FOLDEST_STREAM_H

#include <stddef.h>

#include "foldest/fold.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A pull-based stream of observations of obs_size bytes each. */
typedef struct fe_source {
    /* Point *obs at the next observation: FE_OK; FE_END when there is no
       more; or an error.  The observation stays valid until the next call. */
    int (*next)(void *self, const void **obs);
    /* Restart from the first observation; NULL when impossible. */
    int (*rewind)(void *self);
    void *self;                 /* the source's state, owned by the caller */
    size_t obs_size;
} fe_source;

/* fe_source_next, fe_source_rewind: call the source's functions.
   fe_source_rewind returns FE_ENOTSUP for a source that cannot rewind. */
int fe_source_next(fe_source *src, const void **obs);
int fe_source_rewind(fe_source *src);

/* fe_fold_source: fold every observation of `src` into `acc` until the
   source ends (returns FE_OK) or a step or the source fails (returns that
   code; `acc` holds the fold of the observations before it).  `*done`
   receives the number folded.  src->obs_size must equal f->obs_size. */
int fe_fold_source(const fe_accumulator *f, void *acc, fe_source *src,
                   size_t *done);

/* fe_scan_source: as fe_fold_source, calling `visit` with the initial
   accumulation (index 0) and after every observation. */
int fe_scan_source(const fe_accumulator *f, void *acc, fe_source *src,
                   fe_visit_fn *visit, void *visit_ctx, size_t *done);
/* Stream Declarations ends here */
/* [[file:../../literate/stream.org::Array Source Declarations][Array Source Declarations]] */
typedef struct fe_array_source {
    const unsigned char *base;
    size_t count, pos, obs_size;
} fe_array_source;

/* fe_source_from_array: make `src` yield the `n` observations of `base`
   (stride obs_size).  `state` and `base` must outlive `src`. */
int fe_source_from_array(fe_source *src, fe_array_source *state,
                         const void *base, size_t n, size_t obs_size);
/* Array Source Declarations ends here */
/* [[file:../../literate/stream.org::Generator Source Declarations][Generator Source Declarations]] */
/* Write observation number `index` (from 0) into `obs`; return FE_OK,
   FE_END when there is none, or an error. */
typedef int fe_generate_fn(void *obs, size_t index, void *gen_ctx);

typedef struct fe_generator_source {
    fe_generate_fn *generate;
    void *gen_ctx;
    void *slot;                 /* caller's memory for one observation */
    size_t index;
    int ended;
} fe_generator_source;

/* fe_source_from_generator: make `src` yield generate(slot, 0, gen_ctx),
   generate(slot, 1, gen_ctx), ... until it returns FE_END.  Rewinding
   restarts at index 0. */
int fe_source_from_generator(fe_source *src, fe_generator_source *state,
                             fe_generate_fn *generate, void *gen_ctx,
                             void *slot, size_t obs_size);
/* Generator Source Declarations ends here */
/* [[file:../../literate/stream.org::File Descriptor Source Declarations][File Descriptor Source Declarations]] */
typedef struct fe_fd_source {
    int fd;
    unsigned char *buf;
    size_t cap, len, pos, obs_size;
    long long start;            /* offset to rewind to; -1: not seekable */
    int eof;
} fe_fd_source;

/* fe_source_from_fd: make `src` read records of obs_size bytes (native
   byte order) from `fd` through `buffer` (at least obs_size bytes; a few
   kilobytes read efficiently; align it for the observation type).  The
   descriptor stays the caller's to close.  A trailing partial record is
   FE_EPARSE; a read error FE_EIO. */
int fe_source_from_fd(fe_source *src, fe_fd_source *state, int fd,
                      size_t obs_size, void *buffer, size_t buffer_size);

#ifdef __cplusplus
}
#endif

#endif /* FOLDEST_STREAM_H */
/* File Descriptor Source Declarations ends here */
