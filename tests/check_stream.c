/* SPDX-License-Identifier: MIT */
/* Streams: array, generator and file descriptor sources; folding them;
   rewinding; truncated records and pipes. */
#define _POSIX_C_SOURCE 200809L
#include <fcntl.h>
#include <stdint.h>
#include <unistd.h>

#include "foldest.h"
#include "testutil.h"

START_TEST(array_source_folds_and_rewinds)
{
    const double z[3] = {55, 89, 144};
    fe_array_source st;
    fe_source src;
    fe_accumulator f = fe_meanvar_accumulator();
    fe_meanvar a = FE_MEANVAR_EMPTY;
    size_t done = 0;
    ck_assert_int_eq(fe_source_from_array(&src, &st, z, 3, sizeof(double)), FE_OK);
    ck_assert_int_eq(fe_fold_source(&f, &a, &src, &done), FE_OK);
    ck_assert_uint_eq(done, 3);
    ck_assert_double_eq(a.mean, 96.0);
    ck_assert_int_eq(fe_source_rewind(&src), FE_OK);
    ck_assert_int_eq(fe_fold_source(&f, &a, &src, &done), FE_OK);
    ck_assert_uint_eq(a.n, 6);
    ck_assert_double_eq_tol(fe_meanvar_variance(&a), 1613.6, 1e-9);
}
END_TEST

/* A generator: 1e6 seeded normals around 5; the stream is a function of
   the index, so rewinding replays it exactly. */
typedef struct { fe_rng rng; size_t n; } gen_ctx;

static int gen_normals(void *obs, size_t index, void *ctx)
{
    gen_ctx *g = ctx;
    if (index == 0)
        g->rng = fe_rng_seed(42);
    if (index >= g->n)
        return FE_END;
    *(double *)obs = 5.0 + fe_rng_normal(&g->rng);
    return FE_OK;
}

START_TEST(generator_source_in_constant_memory)
{
    gen_ctx g = {fe_rng_seed(0), fe_test_quick() ? 100000 : 1000000};
    double slot;
    fe_generator_source st;
    fe_source src;
    fe_accumulator f = fe_meanvar_accumulator();
    fe_meanvar a = FE_MEANVAR_EMPTY, b = FE_MEANVAR_EMPTY;
    ck_assert_int_eq(fe_source_from_generator(&src, &st, gen_normals, &g, &slot, sizeof slot), FE_OK);
    ck_assert_int_eq(fe_fold_source(&f, &a, &src, NULL), FE_OK);
    ck_assert_uint_eq(a.n, g.n);
    ck_assert_double_eq_tol(a.mean, 5.0, 0.01);
    ck_assert_double_eq_tol(fe_meanvar_variance(&a), 1.0, 0.02);
    ck_assert_int_eq(fe_source_rewind(&src), FE_OK);
    ck_assert_int_eq(fe_fold_source(&f, &b, &src, NULL), FE_OK);
    ck_assert_mem_eq(&a, &b, sizeof a);
}
END_TEST

static int count_visits(const void *acc, size_t index, void *ctx)
{
    (void)acc;
    *(size_t *)ctx = index;
    return FE_OK;
}

START_TEST(fd_source_reads_records_through_a_small_buffer)
{
    /* 1000 doubles through a 24-byte buffer: refills split every read. */
    char path[] = "/tmp/foldest-test-XXXXXX";
    int fd = mkstemp(path);
    double x[1000], buf[3];
    fe_fd_source st;
    fe_source src;
    fe_accumulator f = fe_meanvar_accumulator();
    fe_meanvar a = FE_MEANVAR_EMPTY, want = FE_MEANVAR_EMPTY;
    size_t last = 0;
    ck_assert_int_ge(fd, 0);
    unlink(path);
    for (int i = 0; i < 1000; i++)
        x[i] = i * 0.5;
    ck_assert_int_eq(write(fd, x, sizeof x), (ssize_t)sizeof x);
    ck_assert_int_eq(lseek(fd, 0, SEEK_SET), 0);
    ck_assert_int_eq(fe_source_from_fd(&src, &st, fd, sizeof(double), buf, sizeof buf), FE_OK);
    ck_assert_int_eq(fe_scan_source(&f, &a, &src, count_visits, &last, NULL), FE_OK);
    ck_assert_uint_eq(last, 1000);
    fe_meanvar_add_many(&want, x, 1000, NULL);
    FE_ASSERT_REL(a.mean, want.mean, 1e-14);
    FE_ASSERT_REL(a.m2, want.m2, 1e-12);
    /* Rewind by seeking. */
    ck_assert_int_eq(fe_source_rewind(&src), FE_OK);
    a = (fe_meanvar)FE_MEANVAR_EMPTY;
    ck_assert_int_eq(fe_fold_source(&f, &a, &src, NULL), FE_OK);
    ck_assert_uint_eq(a.n, 1000);
    /* A buffer of 20 bytes holds two and a half records: the half is
       moved to the front before the next read, and every value arrives. */
    ck_assert_int_eq(lseek(fd, 0, SEEK_SET), 0);
    ck_assert_int_eq(fe_source_from_fd(&src, &st, fd, sizeof(double), buf, 20), FE_OK);
    for (int i = 0; i < 1000; i++) {
        const void *obs;
        ck_assert_int_eq(fe_source_next(&src, &obs), FE_OK);
        ck_assert_double_eq(*(const double *)obs, x[i]);
    }
    /* A truncated last record is an error, after the whole records. */
    ck_assert_int_eq(write(fd, x, 3), 3);
    ck_assert_int_eq(fe_source_rewind(&src), FE_OK);
    a = (fe_meanvar)FE_MEANVAR_EMPTY;
    ck_assert_int_eq(fe_fold_source(&f, &a, &src, NULL), FE_EPARSE);
    ck_assert_uint_eq(a.n, 1000);
    close(fd);
}
END_TEST

/* An accumulator that sums doubles and counts how it was called: steps,
   calls of step_many, and the observations those were handed. */
typedef struct { double sum; size_t steps, batches, batched, largest; } call_count;

static int count_step(void *acc, const void *obs, void *ctx)
{
    call_count *c = acc;
    (void)ctx;
    c->sum += *(const double *)obs;
    c->steps++;
    return FE_OK;
}

static int count_step_many(void *acc, const void *obs, size_t n, size_t *done, void *ctx)
{
    call_count *c = acc;
    (void)ctx;
    for (size_t i = 0; i < n; i++)
        c->sum += ((const double *)obs)[i];
    c->batches++;
    c->batched += n;
    if (n > c->largest)
        c->largest = n;
    *done = n;
    return FE_OK;
}

static int generate_index(void *obs, size_t index, void *ctx)
{
    if (index >= *(const size_t *)ctx)
        return FE_END;
    *(double *)obs = (double)index;
    return FE_OK;
}

START_TEST(the_library_sources_in_memory_are_folded_through_step_many)
{
    /* stream.org: a fold without a visitor hands everything an array or
       file source already holds in memory to step_many at once, and any
       other source one observation at a time through step; with a visitor
       every observation goes through step.  The values 0 .. 999 sum to
       999 * 1000 / 2 = 499500 whichever way.  Array source: one batch of
       1000.  A file through a buffer of 64 doubles: every observation is
       folded, each batch at most 64.  A generator: 1000 steps.  Seed
       10223's stream:16 (the array source not recognised) folded the
       array by 1000 steps. */
    enum { N = 1000 };
    static double x[N];
    double buf[64], slot;
    size_t n = N, done = 0, visits = 0;
    char path[] = "/tmp/foldest-test-XXXXXX";
    fe_accumulator f = {"count", sizeof(call_count), sizeof(double), NULL, count_step,
                        count_step_many, NULL, NULL, NULL};
    fe_array_source as;
    fe_fd_source fs;
    fe_generator_source gs;
    fe_source src;
    call_count c;
    int fd;
    for (int i = 0; i < N; i++)
        x[i] = (double)i;
    ck_assert_int_eq(fe_source_from_array(&src, &as, x, N, sizeof(double)), FE_OK);
    c = (call_count){0};
    ck_assert_int_eq(fe_fold_source(&f, &c, &src, &done), FE_OK);
    ck_assert_uint_eq(done, N);
    ck_assert_double_eq(c.sum, 499500.0);
    ck_assert_uint_eq(c.batches, 1);
    ck_assert_uint_eq(c.batched, N);
    ck_assert_uint_eq(c.steps, 0);
    /* With a visitor, one observation at a time. */
    ck_assert_int_eq(fe_source_rewind(&src), FE_OK);
    c = (call_count){0};
    ck_assert_int_eq(fe_scan_source(&f, &c, &src, count_visits, &visits, &done), FE_OK);
    ck_assert_uint_eq(visits, N);
    ck_assert_double_eq(c.sum, 499500.0);
    ck_assert_uint_eq(c.steps, N);
    ck_assert_uint_eq(c.batches, 0);
    /* A file through 64 doubles. */
    fd = mkstemp(path);
    ck_assert_int_ge(fd, 0);
    unlink(path);
    ck_assert_int_eq(write(fd, x, sizeof x), (ssize_t)sizeof x);
    ck_assert_int_eq(lseek(fd, 0, SEEK_SET), 0);
    ck_assert_int_eq(fe_source_from_fd(&src, &fs, fd, sizeof(double), buf, sizeof buf), FE_OK);
    c = (call_count){0};
    ck_assert_int_eq(fe_fold_source(&f, &c, &src, &done), FE_OK);
    ck_assert_uint_eq(done, N);
    ck_assert_double_eq(c.sum, 499500.0);
    ck_assert_uint_eq(c.batched + c.steps, N);
    ck_assert_uint_ge(c.batches, N / 64);
    ck_assert_uint_le(c.largest, 64);
    close(fd);
    /* A generator holds nothing in memory. */
    ck_assert_int_eq(fe_source_from_generator(&src, &gs, generate_index, &n, &slot, sizeof slot),
                     FE_OK);
    c = (call_count){0};
    ck_assert_int_eq(fe_fold_source(&f, &c, &src, &done), FE_OK);
    ck_assert_uint_eq(done, N);
    ck_assert_double_eq(c.sum, 499500.0);
    ck_assert_uint_eq(c.steps, N);
    ck_assert_uint_eq(c.batches, 0);
}
END_TEST

START_TEST(batched_fold_stops_exactly_at_the_refused_observation)
{
    /* The library's own sources are folded in batches through step_many;
       a refusal must look as it does one observation at a time: the fold
       of those before it, *done their number, and the source just past the
       refused one.  Array source, then a file read through 64 doubles. */
    enum { N = 1000, BAD = 617 };
    static double x[N];
    double buf[64];
    char path[] = "/tmp/foldest-test-XXXXXX";
    fe_accumulator f = fe_meanvar_accumulator();
    for (int how = 0; how < 2; how++) {
        fe_array_source as;
        fe_fd_source fs;
        fe_source src;
        fe_meanvar a = FE_MEANVAR_EMPTY, want = FE_MEANVAR_EMPTY;
        const void *obs;
        size_t done = 0, wdone = 0;
        int fd = -1;
        for (int i = 0; i < N; i++)
            x[i] = 3.0 + 0.25 * i;
        x[BAD] = NAN;
        if (how == 0) {
            ck_assert_int_eq(fe_source_from_array(&src, &as, x, N, sizeof(double)), FE_OK);
        } else {
            fd = mkstemp(path);
            ck_assert_int_ge(fd, 0);
            unlink(path);
            ck_assert_int_eq(write(fd, x, sizeof x), (ssize_t)sizeof x);
            ck_assert_int_eq(lseek(fd, 0, SEEK_SET), 0);
            ck_assert_int_eq(fe_source_from_fd(&src, &fs, fd, sizeof(double), buf, sizeof buf),
                             FE_OK);
        }
        ck_assert_int_eq(fe_fold_source(&f, &a, &src, &done), FE_ENONFINITE);
        ck_assert_uint_eq(done, BAD);
        ck_assert_int_eq(fe_meanvar_add_many(&want, x, N, &wdone), FE_ENONFINITE);
        ck_assert_uint_eq(wdone, BAD);
        ck_assert_uint_eq(a.n, BAD);
        FE_ASSERT_REL(a.mean, want.mean, 1e-14);
        FE_ASSERT_REL(a.m2, want.m2, 1e-12);
        ck_assert_int_eq(fe_source_next(&src, &obs), FE_OK);
        ck_assert_double_eq(*(const double *)obs, x[BAD + 1]);
        ck_assert_int_eq(fe_fold_source(&f, &a, &src, &done), FE_OK);
        ck_assert_uint_eq(done, N - BAD - 2);
        ck_assert_uint_eq(a.n, N - 2);
        if (fd >= 0)
            close(fd);
    }
}
END_TEST

START_TEST(fd_source_on_a_pipe_cannot_rewind)
{
    int p[2];
    double x[4] = {1, 2, 3, 4}, buf[8];
    fe_fd_source st;
    fe_source src;
    fe_accumulator f = fe_meanvar_accumulator();
    fe_meanvar a = FE_MEANVAR_EMPTY;
    ck_assert_int_eq(pipe(p), 0);
    ck_assert_int_eq(write(p[1], x, sizeof x), (ssize_t)sizeof x);
    close(p[1]);
    ck_assert_int_eq(fe_source_from_fd(&src, &st, p[0], sizeof(double), buf, sizeof buf), FE_OK);
    ck_assert_int_eq(fe_fold_source(&f, &a, &src, NULL), FE_OK);
    ck_assert_double_eq(a.mean, 2.5);
    ck_assert_int_eq(fe_source_rewind(&src), FE_ENOTSUP);
    close(p[0]);
}
END_TEST

START_TEST(bad_arguments_and_mismatched_sizes)
{
    double z[2] = {1, 2}, slot;
    fe_array_source st;
    fe_source src;
    fe_accumulator f = fe_meanvar_accumulator();
    fe_meanvar a = FE_MEANVAR_EMPTY;
    fe_generator_source gs;
    fe_fd_source fs;
    ck_assert_int_eq(fe_source_from_array(&src, &st, z, 2, sizeof(float)), FE_OK);
    ck_assert_int_eq(fe_fold_source(&f, &a, &src, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_source_from_array(&src, &st, NULL, 2, 8), FE_EINVAL);
    ck_assert_int_eq(fe_source_from_generator(&src, &gs, NULL, NULL, &slot, 8), FE_EINVAL);
    ck_assert_int_eq(fe_source_from_fd(&src, &fs, -1, 8, z, sizeof z), FE_EINVAL);
    ck_assert_int_eq(fe_source_from_fd(&src, &fs, 0, 8, z, 4), FE_EINVAL);
    ck_assert_int_eq(fe_source_rewind(NULL), FE_EINVAL);
    ck_assert_uint_eq(a.n, 0);
}
END_TEST

START_TEST(fd_source_read_error_is_an_io_error)
{
    /* read() on a directory fails (EISDIR): FE_EIO, nothing folded. */
    double buf[8];
    fe_fd_source st;
    fe_source src;
    fe_accumulator f = fe_meanvar_accumulator();
    fe_meanvar a = FE_MEANVAR_EMPTY;
    size_t done = 9;
    int fd = open(".", O_RDONLY);
    ck_assert_int_ge(fd, 0);
    ck_assert_int_eq(fe_source_from_fd(&src, &st, fd, sizeof(double), buf, sizeof buf), FE_OK);
    ck_assert_int_eq(fe_fold_source(&f, &a, &src, &done), FE_EIO);
    ck_assert_uint_eq(done, 0);
    ck_assert_uint_eq(a.n, 0);
    ck_assert_uint_eq(st.len, 0);
    close(fd);
}
END_TEST

/* A generator of three values that counts its calls: after FE_END it must
   not be asked again until the source is rewound. */
static int three_then_end(void *obs, size_t index, void *ctx)
{
    int *calls = ctx;
    (*calls)++;
    if (index >= 3)
        return FE_END;
    *(double *)obs = (double)index;
    return FE_OK;
}

START_TEST(sources_at_their_edges)
{
    fe_source src;
    fe_array_source as;
    fe_generator_source gs;
    const void *obs;
    const unsigned char bytes[3] = {7, 8, 9};
    double slot;
    int calls = 0;
    /* One-byte observations are observations; a NULL array of one is not. */
    ck_assert_int_eq(fe_source_from_array(&src, &as, bytes, 3, 1), FE_OK);
    ck_assert_int_eq(fe_source_next(&src, &obs), FE_OK);
    ck_assert_int_eq(*(const unsigned char *)obs, 7);
    ck_assert_int_eq(fe_source_from_array(&src, &as, NULL, 1, 8), FE_EINVAL);
    ck_assert_int_eq(fe_source_from_array(&src, &as, NULL, 0, 8), FE_OK);
    ck_assert_int_eq(fe_source_next(&src, &obs), FE_END);
    /* A generator is not called past its end, and starts again when rewound. */
    ck_assert_int_eq(fe_source_from_generator(&src, &gs, three_then_end, &calls, &slot,
                                              sizeof slot), FE_OK);
    for (int i = 0; i < 3; i++)
        ck_assert_int_eq(fe_source_next(&src, &obs), FE_OK);
    ck_assert_int_eq(fe_source_next(&src, &obs), FE_END);
    ck_assert_int_eq(calls, 4);
    ck_assert_int_eq(fe_source_next(&src, &obs), FE_END);
    ck_assert_int_eq(fe_source_next(&src, &obs), FE_END);
    ck_assert_int_eq(calls, 4);
    ck_assert_int_eq(fe_source_rewind(&src), FE_OK);
    ck_assert_int_eq(fe_source_next(&src, &obs), FE_OK);
    ck_assert_double_eq(*(const double *)obs, 0.0);
    ck_assert_int_eq(calls, 5);
}
END_TEST

START_TEST(standard_input_is_a_source)
{
    /* Descriptor 0 is a valid source (standard input): a pipe put there
       for the test (and standard input put back after) folds to its
       mean; -1 is refused. */
    int p[2], saved = dup(0);          /* -1 when standard input is closed */
    double x[3] = {2, 4, 9}, buf[4];
    fe_fd_source st;
    fe_source src;
    fe_accumulator f = fe_meanvar_accumulator();
    fe_meanvar a = FE_MEANVAR_EMPTY;
    int rc;
    ck_assert_int_eq(pipe(p), 0);
    ck_assert_int_eq(write(p[1], x, sizeof x), (ssize_t)sizeof x);
    close(p[1]);
    ck_assert_int_eq(dup2(p[0], 0), 0);
    if (p[0] != 0)
        close(p[0]);
    rc = fe_source_from_fd(&src, &st, 0, sizeof(double), buf, sizeof buf);
    if (rc == FE_OK)
        rc = fe_fold_source(&f, &a, &src, NULL);
    if (saved >= 0) {
        ck_assert_int_eq(dup2(saved, 0), 0);
        close(saved);
    } else {
        close(0);
    }
    ck_assert_int_eq(rc, FE_OK);
    ck_assert_uint_eq(a.n, 3);
    ck_assert_double_eq(a.mean, 5.0);
    ck_assert_int_eq(fe_source_from_fd(&src, &st, -1, sizeof(double), buf, sizeof buf), FE_EINVAL);
}
END_TEST

/* Issue 20: a descriptor source's buffer at its edge: one record's bytes
   are enough (every record arrives), one byte less is refused. */
START_TEST(a_buffer_of_one_record_is_enough)
{
    char path[] = "/tmp/foldest-edge-XXXXXX";
    int fd = mkstemp(path);
    double x[5] = {1, 2, 3, 4, 5}, buf[1];
    fe_source src;
    fe_fd_source st;
    const void *obs;
    ck_assert_int_ge(fd, 0);
    unlink(path);
    ck_assert_int_eq(write(fd, x, sizeof x), (ssize_t)sizeof x);
    ck_assert_int_eq(lseek(fd, 0, SEEK_SET), 0);
    ck_assert_int_eq(fe_source_from_fd(&src, &st, fd, sizeof(double), buf, sizeof(double) - 1),
                     FE_EINVAL);
    ck_assert_int_eq(fe_source_from_fd(&src, &st, fd, sizeof(double), buf, sizeof(double)), FE_OK);
    for (int i = 0; i < 5; i++) {
        ck_assert_int_eq(fe_source_next(&src, &obs), FE_OK);
        ck_assert_double_eq(*(const double *)obs, x[i]);
    }
    ck_assert_int_eq(fe_source_next(&src, &obs), FE_END);
    close(fd);
}
END_TEST

/* Issue 20: each argument of the source functions alone at fault.  A
   refusal is FE_EINVAL with nothing read: *done is 0 (it was 99), the
   accumulation still empty, the visitor never called, and the source still
   at its first observation.  A source that cannot rewind says so. */
static int count_calls(const void *acc, size_t index, void *ctx)
{
    (void)acc;
    (void)index;
    (*(int *)ctx)++;
    return FE_OK;
}

START_TEST(each_argument_alone_is_refused_and_nothing_is_read)
{
    const double z[3] = {2, 3, 7};
    fe_array_source st;
    fe_source src, bad;
    fe_accumulator f = fe_meanvar_accumulator(), nostep = f;
    fe_meanvar a = FE_MEANVAR_EMPTY;
    const void *obs = NULL;
    int visits = 0;
    nostep.step = NULL;
    ck_assert_int_eq(fe_source_from_array(&src, &st, z, 3, sizeof(double)), FE_OK);
    /* fe_source_next: no source, a source without next, nowhere to point. */
    ck_assert_int_eq(fe_source_next(NULL, &obs), FE_EINVAL);
    bad = src;
    bad.next = NULL;
    ck_assert_int_eq(fe_source_next(&bad, &obs), FE_EINVAL);
    ck_assert_int_eq(fe_source_next(&src, NULL), FE_EINVAL);
    ck_assert_ptr_null(obs);
    ck_assert_uint_eq(st.pos, 0);
    /* fe_source_rewind: no source; a source that cannot rewind. */
    bad = src;
    bad.rewind = NULL;
    ck_assert_int_eq(fe_source_rewind(NULL), FE_EINVAL);
    ck_assert_int_eq(fe_source_rewind(&bad), FE_ENOTSUP);
    /* fe_fold_source and fe_scan_source (with and without a visitor). */
    for (int v = 0; v < 3; v++) {
        fe_visit_fn *visit = v == 2 ? count_calls : NULL;
        for (int c = 0; c < 6; c++) {
            const fe_accumulator *fc = c == 0 ? NULL : c == 1 ? &nostep : &f;
            void *acc = c == 2 ? NULL : &a;
            fe_source *sc = c == 3 ? NULL : c == 4 || c == 5 ? &bad : &src;
            size_t done = 99;
            int rc;
            bad = src;
            if (c == 4)
                bad.next = NULL;
            if (c == 5)
                bad.obs_size = sizeof(float);
            rc = v == 0 ? fe_fold_source(fc, acc, sc, &done)
                        : fe_scan_source(fc, acc, sc, visit, &visits, &done);
            ck_assert_msg(rc == FE_EINVAL, "case %d, %d: %d", v, c, rc);
            ck_assert_msg(done == 0, "case %d, %d: done = %zu", v, c, done);
            ck_assert_int_eq(fe_fold_source(fc, acc, sc, NULL), FE_EINVAL);
            ck_assert_uint_eq(a.n, 0);
            ck_assert_uint_eq(st.pos, 0);
        }
    }
    ck_assert_int_eq(visits, 0);
    /* And with every argument good, the three observations, visited at
       0, 1, 2 and 3. */
    {
        size_t done = 99;
        ck_assert_int_eq(fe_scan_source(&f, &a, &src, count_calls, &visits, &done), FE_OK);
        ck_assert_uint_eq(done, 3);
        ck_assert_int_eq(visits, 4);
        ck_assert_uint_eq(a.n, 3);
        ck_assert_double_eq(a.mean, 4.0);
    }
}
END_TEST

Suite *fe_stream_suite(void)
{
    Suite *s = suite_create("stream");
    TCase *t = tcase_create("core");
    tcase_set_timeout(t, 60);
    tcase_add_test(t, array_source_folds_and_rewinds);
    tcase_add_test(t, generator_source_in_constant_memory);
    tcase_add_test(t, fd_source_reads_records_through_a_small_buffer);
    tcase_add_test(t, fd_source_on_a_pipe_cannot_rewind);
    tcase_add_test(t, batched_fold_stops_exactly_at_the_refused_observation);
    tcase_add_test(t, the_library_sources_in_memory_are_folded_through_step_many);
    tcase_add_test(t, bad_arguments_and_mismatched_sizes);
    tcase_add_test(t, sources_at_their_edges);
    tcase_add_test(t, fd_source_read_error_is_an_io_error);
    tcase_add_test(t, standard_input_is_a_source);
    tcase_add_test(t, a_buffer_of_one_record_is_enough);
    tcase_add_test(t, each_argument_alone_is_refused_and_nothing_is_read);
    suite_add_tcase(s, t);
    return s;
}
