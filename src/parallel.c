/* SPDX-License-Identifier: MIT */
/* Tangled from literate/parallel.org: do not edit; edit the .org and run make tangle. */
/* [[file:../literate/parallel.org::Parallel Fold Includes][Parallel Fold Includes]] */
#include <pthread.h>
#include <string.h>

#include "foldest/error.h"
#include "foldest/parallel.h"
/* Parallel Fold Includes ends here */
/* [[file:../literate/parallel.org::Cut an array into chunks][Cut an array into chunks]] */
static size_t fe__chunk_start(size_t n, unsigned parts, unsigned t)
{
    size_t q = n / parts, r = n % parts;
    return (size_t)t * q + ((size_t)t * r) / parts;
}

int fe_parallel_chunk(size_t n, unsigned parts, unsigned t, size_t *begin,
                      size_t *end)
{
    if (parts == 0 || t >= parts || begin == NULL || end == NULL)
        return FE_EINVAL;
    *begin = fe__chunk_start(n, parts, t);
    *end = fe__chunk_start(n, parts, t + 1);
    return FE_OK;
}
/* Cut an array into chunks ends here */
/* [[file:../literate/parallel.org::Parallel Fold Private Data][Parallel Fold Private Data]] */
struct fe__job {
    const fe_accumulator *f;
    void *acc;
    int needs_init;             /* a partial: fe_init it first */
    const unsigned char *obs;   /* an array chunk ... */
    size_t n;
    fe_source *src;             /* ... or a source (then obs is unused) */
    pthread_t thread;
    int spawned;                /* runs on `thread`; else on the caller */
    int ready;                  /* acc holds a valid accumulation */
    size_t done;
    int rc;
};
/* Parallel Fold Private Data ends here */
/* [[file:../literate/parallel.org::Run one job][Run one job]] */
static void fe__job_run(struct fe__job *j)
{
    j->done = 0;
    j->ready = 0;
    j->rc = j->needs_init ? fe_init(j->f, j->acc) : FE_OK; /* NOLINT(clang-analyzer-core.uninitialized.Branch): every job is filled before it runs */
    if (j->rc != FE_OK)
        return;
    j->ready = 1;
    if (j->src != NULL)
        j->rc = fe_fold_source(j->f, j->acc, j->src, &j->done);
    else
        j->rc = fe_fold(j->f, j->acc, j->obs, j->n, &j->done);
}

static void *fe__job_thread(void *arg)
{
    fe__job_run(arg);
    return NULL;
}
/* Run one job ends here */
/* [[file:../literate/parallel.org::Drive the jobs and merge their results in order][Drive the jobs and merge their results in order]] */
static int fe__parallel_drive(const fe_accumulator *f, void *acc,
                              struct fe__job *jobs, unsigned count,
                              size_t *done)
{
    size_t folded = 0;
    int rc = FE_OK, stopped = 0;

    for (unsigned t = 1; t < count; t++) {
        jobs[t].spawned = 0;
        if (jobs[t].src == NULL && jobs[t].n == 0)
            continue;
        jobs[t].spawned = pthread_create(&jobs[t].thread, NULL,
                                         fe__job_thread, &jobs[t]) == 0;
    }
    fe__job_run(&jobs[0]);
    folded = jobs[0].done;
    rc = jobs[0].rc;
    stopped = rc != FE_OK;
    for (unsigned t = 1; t < count; t++) {
        struct fe__job *j = &jobs[t];
        if (j->src == NULL && j->n == 0)
            continue;
        if (j->spawned)
            pthread_join(j->thread, NULL);
        else if (!stopped)
            fe__job_run(j);
        if (stopped)
            continue;           /* a lower index refused: join only */
        if (!j->ready) {
            rc = j->rc;         /* its init refused */
            stopped = 1;
            continue;
        }
        rc = fe_merge(f, acc, j->acc);
        if (rc != FE_OK) {
            stopped = 1;        /* acc is unchanged by the failed merge */
            continue;
        }
        folded += j->done;
        rc = j->rc;
        stopped = rc != FE_OK;
    }
    if (done != NULL)
        *done = folded;
    return rc;
}
/* Drive the jobs and merge their results in order ends here */
/* [[file:../literate/parallel.org::Check the arguments of a parallel fold][Check the arguments of a parallel fold]] */
static int fe__parallel_check(const fe_accumulator *f, const void *acc,
                              unsigned threads, void *const *partials)
{
    if (f == NULL || f->step == NULL || f->acc_size == 0 || f->obs_size == 0
        || acc == NULL || threads == 0)
        return FE_EINVAL;
    if (threads > FE_PARALLEL_MAX_THREADS)
        return FE_ESIZE;
    if (threads == 1)
        return FE_OK;
    if (f->merge == NULL)
        return FE_ENOTSUP;
    if (partials == NULL)
        return FE_EINVAL;
    for (unsigned t = 0; t + 1 < threads; t++) {
        if (partials[t] == NULL || partials[t] == acc)
            return FE_EINVAL;
        for (unsigned u = 0; u < t; u++)
            if (partials[u] == partials[t])
                return FE_EINVAL;
    }
    return FE_OK;
}
/* Check the arguments of a parallel fold ends here */
/* [[file:../literate/parallel.org::Fold an array on threads][Fold an array on threads]] */
int fe_parallel_fold(const fe_accumulator *f, void *acc, const void *obs,
                     size_t n, unsigned threads, void *const *partials,
                     size_t *done)
{
    struct fe__job jobs[FE_PARALLEL_MAX_THREADS];
    const unsigned char *z = obs;
    int rc;

    if (done != NULL)
        *done = 0;
    rc = fe__parallel_check(f, acc, threads, partials);
    if (rc != FE_OK)
        return rc;
    if (obs == NULL && n > 0)
        return FE_EINVAL;
    if (threads == 1)
        return fe_fold(f, acc, obs, n, done);
    for (unsigned t = 0; t < threads; t++) {
        struct fe__job *j = &jobs[t];
        size_t begin = fe__chunk_start(n, threads, t);
        size_t end = fe__chunk_start(n, threads, t + 1);
        memset(j, 0, sizeof *j);
        j->f = f;
        j->acc = t == 0 ? acc : partials[t - 1];
        j->needs_init = t > 0;
        j->obs = z + begin * f->obs_size;
        j->n = end - begin;
    }
    return fe__parallel_drive(f, acc, jobs, threads, done);
}
/* Fold an array on threads ends here */
/* [[file:../literate/parallel.org::Fold per-thread sources][Fold per-thread sources]] */
int fe_parallel_fold_sources(const fe_accumulator *f, void *acc,
                             fe_source *const *sources, unsigned count,
                             void *const *partials, size_t *done)
{
    struct fe__job jobs[FE_PARALLEL_MAX_THREADS];
    int rc;

    if (done != NULL)
        *done = 0;
    rc = fe__parallel_check(f, acc, count, partials);
    if (rc != FE_OK)
        return rc;
    if (sources == NULL)
        return FE_EINVAL;
    for (unsigned t = 0; t < count; t++) {
        if (sources[t] == NULL || sources[t]->next == NULL
            || sources[t]->obs_size != f->obs_size)
            return FE_EINVAL;
        for (unsigned u = 0; u < t; u++)
            if (sources[u] == sources[t])
                return FE_EINVAL;
    }
    for (unsigned t = 0; t < count; t++) {
        struct fe__job *j = &jobs[t];
        memset(j, 0, sizeof *j);
        j->f = f;
        j->acc = t == 0 ? acc : partials[t - 1];
        j->needs_init = t > 0;
        j->src = sources[t];
    }
    return fe__parallel_drive(f, acc, jobs, count, done);
}
/* Fold per-thread sources ends here */
/* [[file:../literate/parallel.org::Pipeline Private Data][Pipeline Private Data]] */
enum { FE__SLOT_FREE, FE__SLOT_FILLED, FE__SLOT_RUNNING, FE__SLOT_DONE };

struct fe__slot_state {
    int state;
    size_t n;                   /* observations in the batch */
    size_t done;                /* folded by its fold */
    int rc;                     /* its fold's code */
    int ready;                  /* its accumulation was initialised */
};

struct fe__pipeline {
    const fe_accumulator *f;
    const fe_parallel_slot *slots;
    struct fe__slot_state *st;
    unsigned nslots;
    size_t filled;              /* batches filled so far */
    size_t next_take;           /* the next batch to fold */
    int quit;                   /* no more batches will come */
    int discard;                /* a refusal happened: skip, do not fold */
    pthread_mutex_t lock;
    pthread_cond_t work;        /* a batch was filled, or quit */
    pthread_cond_t finished;    /* a batch was folded */
};
/* Pipeline Private Data ends here */
/* [[file:../literate/parallel.org::Claim and fold one batch][Claim and fold one batch]] */
/* Under the lock: the slot of the next batch to fold, or -1. */
static int fe__claim(struct fe__pipeline *p)
{
    unsigned s;
    if (p->next_take >= p->filled)
        return -1;
    s = (unsigned)(p->next_take % p->nslots);
    p->st[s].state = FE__SLOT_RUNNING;
    p->next_take++;
    return (int)s;
}

/* Without the lock: fold the batch in slot s (claimed by the caller). */
static void fe__batch_fold(struct fe__pipeline *p, unsigned s, int discard)
{
    struct fe__slot_state *b = &p->st[s];
    b->done = 0;
    b->ready = 0;
    b->rc = FE_OK;
    if (discard)
        return;
    b->rc = fe_init(p->f, p->slots[s].acc);
    if (b->rc != FE_OK)
        return;
    b->ready = 1;
    b->rc = fe_fold(p->f, p->slots[s].acc, p->slots[s].obs, b->n, &b->done);
}

/* Claim, fold, mark done; with the lock held on entry and on return. */
static int fe__fold_next_locked(struct fe__pipeline *p)
{
    int s = fe__claim(p), discard;
    if (s < 0)
        return 0;
    discard = p->discard;
    pthread_mutex_unlock(&p->lock);
    fe__batch_fold(p, (unsigned)s, discard);
    pthread_mutex_lock(&p->lock);
    p->st[s].state = FE__SLOT_DONE;
    pthread_cond_signal(&p->finished);
    return 1;
}

static void *fe__worker(void *arg)
{
    struct fe__pipeline *p = arg;
    pthread_mutex_lock(&p->lock);
    for (;;) {
        if (fe__fold_next_locked(p))
            continue;
        if (p->quit)
            break;
        pthread_cond_wait(&p->work, &p->lock);
    }
    pthread_mutex_unlock(&p->lock);
    return NULL;
}
/* Claim and fold one batch ends here */
/* [[file:../literate/parallel.org::Merge the next batch in stream order][Merge the next batch in stream order]] */
struct fe__merge_state {
    size_t merged;              /* batches merged (or discarded) */
    size_t folded;              /* observations in acc */
    int rc;                     /* the first refusal, or FE_OK */
    int stopped;
};

static void fe__merge_next(struct fe__pipeline *p, void *acc,
                           struct fe__merge_state *m)
{
    unsigned s = (unsigned)(m->merged % p->nslots);
    struct fe__slot_state *b = &p->st[s];

    pthread_mutex_lock(&p->lock);
    while (b->state != FE__SLOT_DONE)
        if (!fe__fold_next_locked(p))
            pthread_cond_wait(&p->finished, &p->lock);
    pthread_mutex_unlock(&p->lock);
    if (!m->stopped) {
        if (!b->ready) {
            m->rc = b->rc;
            m->stopped = 1;
        } else if ((m->rc = fe_merge(p->f, acc, p->slots[s].acc)) != FE_OK) {
            m->stopped = 1;
        } else {
            m->folded += b->done;
            m->rc = b->rc;
            m->stopped = b->rc != FE_OK;
        }
        if (m->stopped) {
            pthread_mutex_lock(&p->lock);
            p->discard = 1;
            pthread_mutex_unlock(&p->lock);
        }
    }
    pthread_mutex_lock(&p->lock);
    b->state = FE__SLOT_FREE;
    pthread_mutex_unlock(&p->lock);
    m->merged++;
}
/* Merge the next batch in stream order ends here */
/* [[file:../literate/parallel.org::Read, hand out and merge batches][Read, hand out and merge batches]] */
static int fe__pipeline_check(const fe_accumulator *f, const void *acc,
                              const fe_source *src, unsigned workers,
                              size_t batch, const fe_parallel_slot *slots,
                              unsigned nslots)
{
    if (f == NULL || f->step == NULL || f->acc_size == 0 || f->obs_size == 0
        || acc == NULL || src == NULL || src->next == NULL
        || src->obs_size != f->obs_size || batch == 0 || slots == NULL
        || nslots == 0 || nslots > FE_PARALLEL_MAX_SLOTS
        || batch > (size_t)-1 / f->obs_size)
        return FE_EINVAL;
    if (workers > FE_PARALLEL_MAX_THREADS)
        return FE_ESIZE;
    if (f->merge == NULL)
        return FE_ENOTSUP;
    for (unsigned t = 0; t < nslots; t++) {
        if (slots[t].obs == NULL || slots[t].acc == NULL
            || slots[t].acc == acc)
            return FE_EINVAL;
        for (unsigned u = 0; u < t; u++)
            if (slots[u].acc == slots[t].acc || slots[u].obs == slots[t].obs)
                return FE_EINVAL;
    }
    return FE_OK;
}

int fe_parallel_fold_source(const fe_accumulator *f, void *acc,
                            fe_source *src, unsigned workers, size_t batch,
                            const fe_parallel_slot *slots, unsigned nslots,
                            size_t *done)
{
    struct fe__slot_state st[FE_PARALLEL_MAX_SLOTS];
    pthread_t threads[FE_PARALLEL_MAX_THREADS];
    struct fe__pipeline p;
    struct fe__merge_state m = {0, 0, FE_OK, 0};
    unsigned started = 0;
    int src_rc = FE_OK, ended = 0, rc;

    if (done != NULL)
        *done = 0;
    rc = fe__pipeline_check(f, acc, src, workers, batch, slots, nslots);
    if (rc != FE_OK)
        return rc;
    memset(&p, 0, sizeof p);
    memset(st, 0, nslots * sizeof st[0]);
    p.f = f;
    p.slots = slots;
    p.st = st;
    p.nslots = nslots;
    if (pthread_mutex_init(&p.lock, NULL) != 0)
        return FE_ENOMEM;
    if (pthread_cond_init(&p.work, NULL) != 0) {
        pthread_mutex_destroy(&p.lock);
        return FE_ENOMEM;
    }
    if (pthread_cond_init(&p.finished, NULL) != 0) {
        pthread_cond_destroy(&p.work);
        pthread_mutex_destroy(&p.lock);
        return FE_ENOMEM;
    }
    for (unsigned t = 0; t < workers; t++)
        if (pthread_create(&threads[started], NULL, fe__worker, &p) == 0)
            started++;

    while (!ended && !m.stopped) {
        unsigned s = (unsigned)(p.filled % nslots);
        unsigned char *buf = slots[s].obs;
        size_t n = 0;
        while (p.filled - m.merged >= nslots && !m.stopped)
            fe__merge_next(&p, acc, &m);
        if (m.stopped)
            break;
        while (n < batch) {
            const void *obs;
            int r = fe_source_next(src, &obs);
            if (r != FE_OK) {
                src_rc = r == FE_END ? FE_OK : r;
                ended = 1;
                break;
            }
            memcpy(buf + n * f->obs_size, obs, f->obs_size);
            n++;
        }
        if (n > 0) {
            pthread_mutex_lock(&p.lock);
            st[s].n = n;
            st[s].state = FE__SLOT_FILLED;
            p.filled++;
            pthread_cond_signal(&p.work);
            pthread_mutex_unlock(&p.lock);
        }
    }
    while (m.merged < p.filled)
        fe__merge_next(&p, acc, &m);

    pthread_mutex_lock(&p.lock);
    p.quit = 1;
    pthread_cond_broadcast(&p.work);
    pthread_mutex_unlock(&p.lock);
    for (unsigned t = 0; t < started; t++)
        pthread_join(threads[t], NULL);
    pthread_cond_destroy(&p.finished);
    pthread_cond_destroy(&p.work);
    pthread_mutex_destroy(&p.lock);

    if (done != NULL)
        *done = m.folded;
    if (m.stopped)
        return m.rc;
    return src_rc;
}
/* Read, hand out and merge batches ends here */
