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
    j->rc = j->needs_init ? fe_init(j->f, j->acc) : FE_OK;
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
