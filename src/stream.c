/* SPDX-License-Identifier: MIT */
/* Tangled from literate/stream.org: do not edit; edit the .org and run make tangle. */
/* [[file:../literate/stream.org::Stream Includes][Stream Includes]] */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <string.h>
#include <sys/types.h>
#include <unistd.h>

#include "foldest/error.h"
#include "foldest/stream.h"
/* Stream Includes ends here */
/* [[file:../literate/stream.org::Fold and scan a source][Fold and scan a source]] */
int fe_source_next(fe_source *src, const void **obs)
{
    if (src == NULL || src->next == NULL || obs == NULL)
        return FE_EINVAL;
    return src->next(src->self, obs);
}

int fe_source_rewind(fe_source *src)
{
    if (src == NULL)
        return FE_EINVAL;
    if (src->rewind == NULL)
        return FE_ENOTSUP;
    return src->rewind(src->self);
}

static int fe__array_next(void *self, const void **obs);
static int fe__fd_next(void *self, const void **obs);

/* The observations of one of the library's own sources that are already
   in memory, one after another: their number, *obs the first.  0 for any
   other source, or when more must be read. */
static size_t fe__source_in_memory(const fe_source *src, const void **obs)
{
    if (src->next == fe__array_next) {
        const fe_array_source *s = src->self;
        *obs = s->base + s->pos * s->obs_size;
        return s->count - s->pos;
    }
    if (src->next == fe__fd_next) {
        const fe_fd_source *s = src->self;
        *obs = s->buf + s->pos;
        return (s->len - s->pos) / s->obs_size;
    }
    return 0;
}

/* Consume n of those observations. */
static void fe__source_consume(fe_source *src, size_t n)
{
    if (src->next == fe__array_next)
        ((fe_array_source *)src->self)->pos += n;
    else
        ((fe_fd_source *)src->self)->pos += n * src->obs_size;
}

/* Fold a source with the accumulator's step_many, in batches of what the
   source holds in memory. */
static int fe__fold_source_many(const fe_accumulator *f, void *acc,
                                fe_source *src, size_t *done)
{
    size_t total = 0;
    int rc = FE_OK;
    while (rc == FE_OK) {
        const void *obs;
        size_t n = fe__source_in_memory(src, &obs), k = 0;
        if (n > 0) {
            rc = f->step_many(acc, obs, n, &k, f->ctx);
            fe__source_consume(src, rc == FE_OK ? n : k + 1);
        } else {
            rc = src->next(src->self, &obs);
            if (rc == FE_OK) {
                rc = f->step(acc, obs, f->ctx);
                k = rc == FE_OK;
            }
        }
        total += k;
    }
    *done = total;
    return rc == FE_END ? FE_OK : rc;
}

int fe_scan_source(const fe_accumulator *f, void *acc, fe_source *src,
                   fe_visit_fn *visit, void *visit_ctx, size_t *done)
{
    size_t k = 0;
    int rc = FE_OK;

    if (done != NULL)
        *done = 0;
    if (f == NULL || f->step == NULL || acc == NULL || src == NULL
        || src->next == NULL || src->obs_size != f->obs_size)
        return FE_EINVAL;
    if (visit == NULL && f->step_many != NULL) {
        size_t k = 0;
        rc = fe__fold_source_many(f, acc, src, &k);
        if (done != NULL)
            *done = k;
        return rc;
    }
    if (visit != NULL)
        rc = visit(acc, 0, visit_ctx);
    while (rc == FE_OK) {
        const void *obs;
        rc = src->next(src->self, &obs);
        if (rc != FE_OK)
            break;
        rc = f->step(acc, obs, f->ctx);
        if (rc != FE_OK)
            break;
        k++;
        if (visit != NULL)
            rc = visit(acc, k, visit_ctx);
    }
    if (done != NULL)
        *done = k;
    return rc == FE_END ? FE_OK : rc;
}

int fe_fold_source(const fe_accumulator *f, void *acc, fe_source *src,
                   size_t *done)
{
    return fe_scan_source(f, acc, src, NULL, NULL, done);
}
/* Fold and scan a source ends here */
/* [[file:../literate/stream.org::Array source][Array source]] */
static int fe__array_next(void *self, const void **obs)
{
    fe_array_source *s = self;
    if (s->pos >= s->count)
        return FE_END;
    *obs = s->base + s->pos++ * s->obs_size;
    return FE_OK;
}

static int fe__array_rewind(void *self)
{
    ((fe_array_source *)self)->pos = 0;
    return FE_OK;
}

int fe_source_from_array(fe_source *src, fe_array_source *state,
                         const void *base, size_t n, size_t obs_size)
{
    if (src == NULL || state == NULL || obs_size == 0 || (base == NULL && n > 0))
        return FE_EINVAL;
    state->base = base;
    state->count = n;
    state->pos = 0;
    state->obs_size = obs_size;
    src->next = fe__array_next;
    src->rewind = fe__array_rewind;
    src->self = state;
    src->obs_size = obs_size;
    return FE_OK;
}
/* Array source ends here */
/* [[file:../literate/stream.org::Generator source][Generator source]] */
static int fe__generator_next(void *self, const void **obs)
{
    fe_generator_source *s = self;
    int rc;
    if (s->ended)
        return FE_END;
    rc = s->generate(s->slot, s->index, s->gen_ctx);
    if (rc == FE_END)
        s->ended = 1;
    if (rc != FE_OK)
        return rc;
    s->index++;
    *obs = s->slot;
    return FE_OK;
}

static int fe__generator_rewind(void *self)
{
    fe_generator_source *s = self;
    s->index = 0;
    s->ended = 0;
    return FE_OK;
}

int fe_source_from_generator(fe_source *src, fe_generator_source *state,
                             fe_generate_fn *generate, void *gen_ctx,
                             void *slot, size_t obs_size)
{
    if (src == NULL || state == NULL || generate == NULL || slot == NULL
        || obs_size == 0)
        return FE_EINVAL;
    state->generate = generate;
    state->gen_ctx = gen_ctx;
    state->slot = slot;
    state->index = 0;
    state->ended = 0;
    src->next = fe__generator_next;
    src->rewind = fe__generator_rewind;
    src->self = state;
    src->obs_size = obs_size;
    return FE_OK;
}
/* Generator source ends here */
/* [[file:../literate/stream.org::File descriptor source][File descriptor source]] */
static int fe__fd_fill(fe_fd_source *s)
{
    size_t left = s->len - s->pos;
    if (left > 0 && s->pos > 0)
        memmove(s->buf, s->buf + s->pos, left);
    s->len = left;
    s->pos = 0;
    while (!s->eof && s->len < s->obs_size) {
        ssize_t got = read(s->fd, s->buf + s->len, s->cap - s->len);
        if (got < 0) {
            if (errno == EINTR)
                continue;
            return FE_EIO;
        }
        if (got == 0)
            s->eof = 1;
        s->len += (size_t)got;
    }
    return FE_OK;
}

static int fe__fd_next(void *self, const void **obs)
{
    fe_fd_source *s = self;
    if (s->len - s->pos < s->obs_size) {
        int rc = fe__fd_fill(s);
        if (rc != FE_OK)
            return rc;
        if (s->len == 0)
            return FE_END;
        if (s->len < s->obs_size)
            return FE_EPARSE;   /* a truncated last record */
    }
    *obs = s->buf + s->pos;
    s->pos += s->obs_size;
    return FE_OK;
}

static int fe__fd_rewind(void *self)
{
    fe_fd_source *s = self;
    if (s->start < 0)
        return FE_ENOTSUP;
    if (lseek(s->fd, (off_t)s->start, SEEK_SET) == (off_t)-1)
        return FE_EIO;
    s->len = s->pos = 0;
    s->eof = 0;
    return FE_OK;
}

int fe_source_from_fd(fe_source *src, fe_fd_source *state, int fd,
                      size_t obs_size, void *buffer, size_t buffer_size)
{
    off_t here;
    if (src == NULL || state == NULL || fd < 0 || obs_size == 0
        || buffer == NULL || buffer_size < obs_size)
        return FE_EINVAL;
    here = lseek(fd, 0, SEEK_CUR);
    state->fd = fd;
    state->buf = buffer;
    state->cap = buffer_size;
    state->len = state->pos = 0;
    state->obs_size = obs_size;
    state->start = here == (off_t)-1 ? -1 : (long long)here;
    state->eof = 0;
    src->next = fe__fd_next;
    src->rewind = state->start >= 0 ? fe__fd_rewind : NULL;
    src->self = state;
    src->obs_size = obs_size;
    return FE_OK;
}
/* File descriptor source ends here */
