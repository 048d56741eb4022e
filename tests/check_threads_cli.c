/* SPDX-License-Identifier: MIT */
/* --threads N of stats and calibrate (issue 16, item 1): a regular file is
   cut into batches parsed on N threads.  stats and calibrate's second
   pass fold each batch into a part where it was parsed and merge the
   parts in file order; calibrate's moments take the rows in file order.
   The cut does not depend on N, so every output, message, line number and
   exit status must be the same byte for byte on any number of threads,
   and equal to the uncut run's (one reader) but for the rounding of the
   merges: the same text, numbers to 1e-12.  FOLDEST_BATCH cuts the test
   files into batches of a few bytes (down to one) and makes the command
   say how it cut the file, so that each comparison below is known to
   compare a cut run.  Standard input, pipes and gzip files keep one
   reader.  Runs the built binary (FE_TEST_CLI). */
#define _POSIX_C_SOURCE 200809L
#include <ctype.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "foldest.h"
#include "testutil.h"
#include "cli_run.h"

#ifndef FE_TEST_CLI
#define FE_TEST_CLI "build/bin/foldest"
#endif

enum { OUT = 1 << 16 };

/* Remove the lines that say how the file was cut (one a pass); how many
   there were. */
static int strip_witness(char *out)
{
    int n = 0;
    char *at = out;
    while (*at != '\0') {
        char *nl = strchr(at, '\n'), *mark = strstr(at, " batches of ");
        if (nl == NULL)
            break;
        if (strncmp(at, "foldest: ", 9) == 0 && mark != NULL && mark < nl
            && strncmp(nl - 8, " threads", 8) == 0) {
            memmove(at, nl + 1, strlen(nl + 1) + 1);
            n++;
        } else {
            at = nl + 1;
        }
    }
    return n;
}

/* a and b are the same text but for the numbers in it, which agree to
   `rel` of the larger (counts and line numbers therefore exactly). */
static int same_but_rounding(const char *a, const char *b, double rel)
{
    while (*a != '\0' && *b != '\0') {
        int na = isdigit((unsigned char)*a) || (*a == '-' && isdigit((unsigned char)a[1]));
        int nb = isdigit((unsigned char)*b) || (*b == '-' && isdigit((unsigned char)b[1]));
        if (na && nb) {
            char *ea, *eb;
            double x = strtod(a, &ea), y = strtod(b, &eb);
            if (!(fabs(x - y) <= rel * fmax(fabs(x), fabs(y))))
                return 0;
            a = ea;
            b = eb;
        } else if (*a++ != *b++) {
            return 0;
        }
    }
    return *a == *b;
}

/* The helper's own check: a digit too many, a changed count, a changed
   word each fail it. */
START_TEST(same_but_rounding_tells)
{
    ck_assert(same_but_rounding("x: 1.0000000000001, n 300", "x: 1.0000000000002, n 300", 1e-12));
    ck_assert(!same_but_rounding("x: 1.000000000001, n 300", "x: 1.000000000003, n 300", 1e-12));
    ck_assert(!same_but_rounding("x: 1, n 300", "x: 1, n 301", 1e-12));
    ck_assert(!same_but_rounding("x: 1, n 300", "y: 1, n 300", 1e-12));
    ck_assert(!same_but_rounding("x: 1, n 300", "x: 1, n 300 ", 1e-12));
}
END_TEST

static void temp_path(char *path, size_t len, const char *suffix)
{
    int fd;
    snprintf(path, len, "/tmp/foldest-thr-XXXXXX");
    fd = mkstemp(path);
    ck_assert_int_ge(fd, 0);
    close(fd);
    unlink(path);
    strncat(path, suffix, len - strlen(path) - 1);
}

/* Samples on an ellipsoid (centre 100, -50, 30), three columns. */
static void ellipsoid_row(FILE *f, fe_rng *g, const char *sep, const char *eol)
{
    double v[3], s = 0.0;
    for (int j = 0; j < 3; j++) {
        v[j] = fe_rng_normal(g);
        s += v[j] * v[j];
    }
    s = sqrt(s);
    fprintf(f, "%.4f%s%.4f%s%.4f%s", 100 + 400 * v[0] / s + fe_rng_normal(g), sep,
            -50 + 380 * v[1] / s + fe_rng_normal(g), sep, 30 + 420 * v[2] / s + fe_rng_normal(g),
            eol);
}

/* The cases: a file of a few hundred lines (more than the 64 the opening
   looks at) and the command's arguments. */
struct thr_case {
    const char *what, *args;
    int status;                 /* the one-thread run's */
    const char *expect;         /* in the one-thread output; %s: the path */
};

static const struct thr_case cases[] = {
    {"metadata, header, CRLF", "stats --json", 0, "\"rows\": 300,"},
    {"--skip 1 then a header", "stats --skip 1 --json", 0, "\"rows\": 300,"},
    {"text in a cell", "stats", 3, "%s:153:3: 'x7' in column 'b' is not a number"},
    {"bad rows of every kind, skipped", "stats --skip-bad-rows --json", 0,
     "\"rows\": 296, \"bad_rows\": {\"total\": 4, \"empty_cell\": 1, \"not_finite\": 1, "
     "\"not_a_number\": 1, \"field_count\": 1}"},
    {"two errors: the first in file order", "stats", 3, "%s:103:1: expected 2 fields, found 1"},
    {"comments, blank lines, no final line feed", "stats --json", 0, "\"rows\": 300,"},
    {"a byte-order mark in the middle", "stats", 3, "%s:203:1: '"},
    {"an unterminated quote", "stats", 3, "%s:253:3: unterminated"},
    {"an overflow refused by the fold", "stats", 3, "%s:203: "},
    {"calibrate", "calibrate --json --model ellipsoid", 0, "\"n\": 300,"},
    {"calibrate --static", "calibrate --json --static --window 10 --still-sd 0.5", 0, "\"model\""},
    {"calibrate --robust --apply", "calibrate --robust --apply /dev/null", 0, "offset"},
    {"calibrate: a malformed row", "calibrate --json", 3, "%s:253:3: 'z' in column 'my'"},
    {"calibrate: a sample the moments refuse", "calibrate --json", 3, "%s:203:1: "},
    {"calibrate: a refused sample before a malformed row", "calibrate", 3, "%s:203:1: "},
};

static void write_case(const char *path, size_t which)
{
    FILE *f = fopen(path, "w");
    fe_rng g = fe_rng_seed(16 + which);
    ck_assert_ptr_nonnull(f);
    if (which >= 9) {
        fprintf(f, "Fs,50.00\nmx,my,mz\n");
        for (int i = 3; i <= 302; i++) {
            if ((which == 12 && i == 253) || (which == 14 && i == 210))
                fprintf(f, "1,z,3\n");
            else if ((which == 13 || which == 14) && i == 203)
                fprintf(f, "1e100,1,3\n");
            else
                ellipsoid_row(f, &g, ",", "\n");
        }
        fclose(f);
        return;
    }
    fprintf(f, "Fs,50.00,Hz%s", which == 0 ? "\r\n" : "\n");
    fprintf(f, "a,b%s", which == 0 ? "\r\n" : "\n");
    for (int i = 3; i <= 302; i++) {
        const char *eol = which == 0 ? "\r\n" : i == 302 && which == 5 ? "" : "\n";
        double a = 1000.0 + 3.0 * fe_rng_normal(&g), b = fe_rng_uniform(&g);
        if (which == 2 && i == 153)
            fprintf(f, "1,x7\n");
        else if (which == 3 && (i == 70 || i == 140 || i == 210 || i == 290))
            fprintf(f, "%s\n", i == 70 ? ",1" : i == 140 ? "NaN,1" : i == 210 ? "1,y" : "1");
        else if (which == 4 && (i == 103 || i == 250))
            fprintf(f, "%s\n", i == 103 ? "5" : "x,1");
        else if (which == 6 && i == 203)
            fprintf(f, "\xEF\xBB\xBF%.6g,%.6g\n", a, b);
        else if (which == 7 && i == 253)
            fprintf(f, "1,\"2\n");
        else if (which == 8 && i == 203)
            fprintf(f, "1e300,1\n");
        else
            fprintf(f, "%.6g,%.6g%s", a, b, eol);
        if (which == 5 && i % 37 == 0)
            fprintf(f, "# a comment\n\n   \n");
    }
    fclose(f);
}

/* Every case, cut into batches of 1, 7, 100 and 4096 bytes, on 1, 2, 3
   and 7 threads: the uncut run's status, messages and output but for
   rounding, and on every number of threads the same bytes. */
START_TEST(same_on_every_cut)
{
    static const int threads[] = {1, 2, 3, 7}, batch[] = {1, 7, 100, 4096};
    static char one[OUT], many[OUT], cut1[OUT];
    const struct thr_case *c = &cases[_i];
    char path[256], cmd[1024], want[512];
    int status;

    temp_path(path, sizeof path, ".csv");
    write_case(path, (size_t)_i);
    snprintf(cmd, sizeof cmd, "%s %s --threads 1 %s", FE_TEST_CLI, c->args, path);
    status = fe_test_run(cmd, FE_TEST_BOTH, one, sizeof one);
    snprintf(want, sizeof want, c->expect, path);
    ck_assert_msg(status == c->status && strstr(one, want) != NULL,
                  "%s: one thread: status %d, output:\n%s\n(wanted '%s')", c->what, status, one, want);
    ck_assert_msg(!strip_witness(one), "%s: one thread cut the file", c->what);
    for (size_t b = 0; b < sizeof batch / sizeof batch[0]; b++)
        for (size_t t = 0; t < sizeof threads / sizeof threads[0]; t++) {
            snprintf(cmd, sizeof cmd, "FOLDEST_BATCH=%d %s %s --threads %d %s", batch[b],
                     FE_TEST_CLI, c->args, threads[t], path);
            status = fe_test_run(cmd, FE_TEST_BOTH, many, sizeof many);
            /* One thread cuts the file only for a fold in parts. */
            ck_assert_msg(strip_witness(many) || threads[t] == 1,
                          "%s: --threads %d, batch %d: the file was not cut:\n%s", c->what,
                          threads[t], batch[b], many);
            ck_assert_msg(status == c->status && same_but_rounding(one, many, 1e-12),
                          "%s: --threads %d, batch %d: status %d, output\n%s\nand uncut\n%s",
                          c->what, threads[t], batch[b], status, many, one);
            if (threads[t] == 1)
                memcpy(cut1, many, strlen(many) + 1);
            ck_assert_msg(strcmp(cut1, many) == 0, "%s: --threads %d, batch %d:\n%s\none thread:\n%s",
                          c->what, threads[t], batch[b], many, cut1);
        }
    unlink(path);
}
END_TEST

/* A file large enough to be cut by the default rule (batches of at least
   64 KiB): stats and calibrate, JSON and --apply, bit for bit on 1, 2, 3
   and 7 threads, cut by the default rule or in batches of 64 KiB (the
   two agreeing to 1e-12). */
START_TEST(bit_equal_on_a_large_file)
{
    static const int threads[] = {2, 3, 7};
    static const char *const args[] = {"stats --json", "calibrate --json --model ellipsoid"};
    static char one[OUT], many[OUT], apply1[1 << 12], apply_n[1 << 12];
    size_t n = fe_test_quick() ? 40000 : 200000;
    char path[256], out1[256], outn[256], cmd[4096];
    fe_rng g = fe_rng_seed(1616);
    FILE *f;

    temp_path(path, sizeof path, ".csv");
    temp_path(out1, sizeof out1, ".1.csv");
    temp_path(outn, sizeof outn, ".n.csv");
    f = fopen(path, "w");
    ck_assert_ptr_nonnull(f);
    fprintf(f, "# a logger\nmx,my,mz\n");
    for (size_t i = 0; i < n; i++)
        ellipsoid_row(f, &g, ",", "\n");
    fclose(f);
    for (size_t a = 0; a < 2; a++) {
        static char cut1[OUT];
        snprintf(cmd, sizeof cmd, "%s %s --threads 1 %s", FE_TEST_CLI, args[a], path);
        ck_assert_int_eq(fe_test_run(cmd, FE_TEST_BOTH, one, sizeof one), 0);
        snprintf(cmd, sizeof cmd, "FOLDEST_BATCH=65536 %s %s --threads 1 %s", FE_TEST_CLI, args[a],
                 path);
        ck_assert_int_eq(fe_test_run(cmd, FE_TEST_BOTH, cut1, sizeof cut1), 0);
        ck_assert_msg(strip_witness(cut1), "not cut: %s", cut1);
        ck_assert_msg(same_but_rounding(one, cut1, 1e-12), "%s: batches of 64 KiB:\n%s\nthe default "
                      "cut:\n%s", args[a], cut1, one);
        for (size_t t = 0; t < sizeof threads / sizeof threads[0]; t++) {
            snprintf(cmd, sizeof cmd, "FOLDEST_BATCH=65536 %s %s --threads %d %s", FE_TEST_CLI,
                     args[a], threads[t], path);
            ck_assert_int_eq(fe_test_run(cmd, FE_TEST_BOTH, many, sizeof many), 0);
            ck_assert_msg(strip_witness(many), "not cut: %s", many);
            ck_assert_msg(strcmp(cut1, many) == 0, "%s --threads %d:\n%s\none thread:\n%s", args[a],
                          threads[t], many, cut1);
            /* The default cut (no FOLDEST_BATCH) too. */
            snprintf(cmd, sizeof cmd, "%s %s --threads %d %s", FE_TEST_CLI, args[a], threads[t], path);
            ck_assert_int_eq(fe_test_run(cmd, FE_TEST_BOTH, many, sizeof many), 0);
            ck_assert_str_eq(one, many);
        }
    }
    /* --apply writes the same samples in the same order. */
    snprintf(cmd, sizeof cmd, "%s calibrate --threads 1 --apply %s %s && %s calibrate --threads 3 "
             "--apply %s %s && cmp %s %s && md5sum < %s && md5sum < %s", FE_TEST_CLI, out1, path,
             FE_TEST_CLI, outn, path, out1, outn, out1, outn);
    ck_assert_int_eq(fe_test_run(cmd, FE_TEST_STDOUT, apply1, sizeof apply1), 0);
    snprintf(cmd, sizeof cmd, "wc -l < %s", outn);
    fe_test_run(cmd, FE_TEST_STDOUT, apply_n, sizeof apply_n);
    ck_assert_int_eq(atol(apply_n), (long)n + 1);
    unlink(path);
    unlink(out1);
    unlink(outn);
}
END_TEST

/* Standard input, a pipe and a gzip file: one reader (never cut), the
   file's numbers but for rounding. */
START_TEST(pipes_and_gzip_keep_one_reader)
{
    static char file[OUT], other[OUT];
    char path[256], gz[300], cmd[1024];
    temp_path(path, sizeof path, ".csv");
    write_case(path, 0);
    snprintf(gz, sizeof gz, "%s.gz", path);
    snprintf(cmd, sizeof cmd, "FOLDEST_BATCH=3 %s stats --json --threads 3 %s", FE_TEST_CLI, path);
    ck_assert_int_eq(fe_test_run(cmd, FE_TEST_BOTH, file, sizeof file), 0);
    ck_assert(strip_witness(file));
    snprintf(cmd, sizeof cmd, "cat %s | FOLDEST_BATCH=3 %s stats --json --threads 3 -", path,
             FE_TEST_CLI);
    ck_assert_int_eq(fe_test_run(cmd, FE_TEST_BOTH, other, sizeof other), 0);
    ck_assert_msg(!strip_witness(other), "a pipe was cut: %s", other);
    ck_assert(same_but_rounding(strstr(file, "\"rows\""), strstr(other, "\"rows\""), 1e-12));
    snprintf(cmd, sizeof cmd, "gzip -c %s > %s && FOLDEST_BATCH=3 %s stats --json --threads 3 %s",
             path, gz, FE_TEST_CLI, gz);
    ck_assert_int_eq(fe_test_run(cmd, FE_TEST_BOTH, other, sizeof other), 0);
    ck_assert_msg(!strip_witness(other), "a gzip file was cut: %s", other);
    ck_assert(same_but_rounding(strstr(file, "\"rows\""), strstr(other, "\"rows\""), 1e-12));
    unlink(path);
    unlink(gz);
}
END_TEST

/* Fewer rows than threads: read by one thread without FOLDEST_BATCH, and
   cut into one-byte batches with it; the same result either way. */
START_TEST(fewer_rows_than_threads)
{
    static char one[OUT], many[OUT];
    char path[256], cmd[1024];
    FILE *f;
    temp_path(path, sizeof path, ".csv");
    f = fopen(path, "w");
    ck_assert_ptr_nonnull(f);
    fprintf(f, "a,b\r\n1.5,2\r\n2.5,4\r\n");
    fclose(f);
    snprintf(cmd, sizeof cmd, "%s stats --skip 0 --json --threads 1 %s", FE_TEST_CLI, path);
    ck_assert_int_eq(fe_test_run(cmd, FE_TEST_BOTH, one, sizeof one), 0);
    ck_assert(strstr(one, "\"rows\": 2,") != NULL);
    snprintf(cmd, sizeof cmd, "%s stats --skip 0 --json --threads 7 %s", FE_TEST_CLI, path);
    ck_assert_int_eq(fe_test_run(cmd, FE_TEST_BOTH, many, sizeof many), 0);
    ck_assert_str_eq(one, many);
    snprintf(cmd, sizeof cmd, "FOLDEST_BATCH=1 %s stats --skip 0 --json --threads 7 %s",
             FE_TEST_CLI, path);
    ck_assert_int_eq(fe_test_run(cmd, FE_TEST_BOTH, many, sizeof many), 0);
    ck_assert(strip_witness(many));
    ck_assert_str_eq(one, many);
    unlink(path);
}
END_TEST

/* discover reads two files in several passes, pulling rows from both:
   on 2, 3 and 7 threads, cut into batches of 1 to 4096 bytes, its JSON is
   the one-thread JSON, and a simulation row that goes back in time is
   reported at its line. */
START_TEST(discover_same_on_every_cut)
{
    static const int threads[] = {2, 3, 7}, batch[] = {1, 97, 4096};
    static char one[OUT], many[OUT];
    char real[256], sim[256], cmd[2048], args[1024];
    temp_path(real, sizeof real, ".real.csv");
    temp_path(sim, sizeof sim, ".sim.csv");
    snprintf(cmd, sizeof cmd, "%s synth --effect viscous_friction --rows 3000 --real %s --sim %s",
             FE_TEST_CLI, real, sim);
    ck_assert_int_eq(fe_test_run(cmd, FE_TEST_STDOUT, one, sizeof one), 0);
    snprintf(args, sizeof args, "discover --real %s --sim %s --channel acceleration --role "
             "position=position --role velocity=velocity --role input=input --base bias,gain "
             "--holdout 0.3 --json", real, sim);
    for (int bad = 0; bad < 2; bad++) {
        int status;
        if (bad) {              /* line 1500 of the simulation: time 0 */
            snprintf(cmd, sizeof cmd, "sed -i '1500s/^[^,]*,/0,/' %s", sim);
            ck_assert_int_eq(system(cmd), 0);
        }
        snprintf(cmd, sizeof cmd, "%s %s --threads 1", FE_TEST_CLI, args);
        status = fe_test_run(cmd, FE_TEST_BOTH, one, sizeof one);
        ck_assert_int_eq(status, bad ? 3 : 0);
        ck_assert_msg(strstr(one, bad ? ":1500: simulation time does not increase" : "\"verdict\"")
                      != NULL, "%s", one);
        for (size_t t = 0; t < sizeof threads / sizeof threads[0]; t++)
            for (size_t b = 0; b < sizeof batch / sizeof batch[0]; b++) {
                snprintf(cmd, sizeof cmd, "FOLDEST_BATCH=%d %s %s --threads %d", batch[b],
                         FE_TEST_CLI, args, threads[t]);
                ck_assert_int_eq(fe_test_run(cmd, FE_TEST_BOTH, many, sizeof many), status);
                ck_assert_msg(strip_witness(many) >= 2, "not cut: %s", many);
                ck_assert_msg(strcmp(one, many) == 0, "--threads %d, batch %d:\n%s\none thread:\n%s",
                              threads[t], batch[b], many, one);
            }
    }
    unlink(real);
    unlink(sim);
}
END_TEST

/* Remove the lines that say where discover cut a pass; how many there
   were. */
static int strip_cut(char *out)
{
    int n = 0;
    char *at;
    while ((at = strstr(out, "foldest: discover: a pass cut at row ")) != NULL) {
        char *nl = strchr(at, '\n');
        memmove(at, nl != NULL ? nl + 1 : at + strlen(at), strlen(nl != NULL ? nl + 1 : "") + 1);
        n++;
    }
    return n;
}

/* A record of 20,000 rows: discover cuts passes 2 and 3 in two parts
   (the later on a thread of its own with second readers of the files, or
   after the earlier one on one thread, or when a file is gzip'd), so its
   JSON is the same bit for bit on 1, 2 and 3 threads, from a pipe and
   from a gzip file, and the one-piece fold's (FOLDEST_CUT=0) but for the
   rounding of the merges.  A term that is not finite in the later part is
   reported at its line, and one in the earlier part first. */
START_TEST(discover_same_in_two_parts)
{
    static char one[OUT], cut[OUT], many[OUT];
    char real[256], sim[256], gate[300], cmd[4096], args[2048];
    temp_path(real, sizeof real, ".real.csv");
    temp_path(sim, sizeof sim, ".sim.csv");
    snprintf(gate, sizeof gate, "%s.gate.csv", real);
    snprintf(cmd, sizeof cmd, "%s synth --effect viscous_friction --rows 20000 --real %s --sim %s",
             FE_TEST_CLI, real, sim);
    ck_assert_int_eq(fe_test_run(cmd, FE_TEST_STDOUT, one, sizeof one), 0);
    snprintf(args, sizeof args, "--sim %s --channel acceleration --role position=position "
             "--role velocity=velocity --role input=input --base bias,gain --holdout 0.3 --json",
             sim);
    snprintf(cmd, sizeof cmd, "FOLDEST_CUT=0 %s discover --real %s %s --threads 2", FE_TEST_CLI,
             real, args);
    ck_assert_int_eq(fe_test_run(cmd, FE_TEST_BOTH, one, sizeof one), 0);
    ck_assert_msg(strip_cut(one) == 0, "%s", one);
    snprintf(cmd, sizeof cmd, "FOLDEST_CUT=1 %s discover --real %s %s --threads 1", FE_TEST_CLI,
             real, args);
    ck_assert_int_eq(fe_test_run(cmd, FE_TEST_BOTH, cut, sizeof cut), 0);
    ck_assert_msg(strip_cut(cut) == 2, "passes 2 and 3 not cut: %s", cut);
    ck_assert_msg(same_but_rounding(one, cut, 1e-12), "cut:\n%.1500s\nin one piece:\n%.1500s", cut, one);
    for (int t = 2; t <= 3; t++) {
        snprintf(cmd, sizeof cmd, "FOLDEST_CUT=1 %s discover --real %s %s --threads %d",
                 FE_TEST_CLI, real, args, t);
        ck_assert_int_eq(fe_test_run(cmd, FE_TEST_BOTH, many, sizeof many), 0);
        ck_assert_int_eq(strip_cut(many), 2);
        ck_assert_msg(strcmp(cut, many) == 0, "--threads %d:\n%.1500s\none thread:\n%.1500s", t, many, cut);
    }
    /* The recording from a pipe (copied to a temporary file, read in
       parts), the simulation gzip'd (read after the earlier part). */
    snprintf(cmd, sizeof cmd, "gzip -k %s && cat %s | FOLDEST_CUT=1 %s discover --real - --sim "
             "%s.gz --channel acceleration --role position=position --role velocity=velocity "
             "--role input=input --base bias,gain --holdout 0.3 --json --threads 2", sim, real,
             FE_TEST_CLI, sim);
    ck_assert_int_eq(fe_test_run(cmd, FE_TEST_STDOUT, many, sizeof many), 0);
    ck_assert_msg(strcmp(strstr(cut, "\"rows\""), strstr(many, "\"rows\"")) == 0,
                  "a pipe and gzip:\n%.1500s\nfiles:\n%.1500s", many, cut);
    /* A column `gate`, 0 on line 15002 (and 5002): 1/gate is refused there. */
    for (int early = 0; early < 2; early++) {
        char status_one[512];
        snprintf(cmd, sizeof cmd, "awk -F, 'NR == 1 { print $0 \",gate\"; next } "
                 "{ print $0 \",\" ((NR == 15002 || (%d && NR == 5002)) ? 0 : 1) }' %s > %s",
                 early, real, gate);
        ck_assert_int_eq(system(cmd), 0);
        for (int t = 1; t <= 2; t++) {
            char *out = t == 1 ? status_one : many;
            size_t len = t == 1 ? sizeof status_one : sizeof many;
            char want[512];
            snprintf(cmd, sizeof cmd, "%s discover --real %s %s --term 'inv=1/gate' --threads %d",
                     FE_TEST_CLI, gate, args, t);
            ck_assert_int_eq(fe_test_run(cmd, FE_TEST_BOTH, out, len), 3);
            snprintf(want, sizeof want, "%s:%d: term 'inv' is infinite at t = ", gate,
                     early ? 5002 : 15002);
            ck_assert_msg(strstr(out, want) != NULL, "want %s, got %s", want, out);
        }
        ck_assert_str_eq(status_one, many);
    }
    /* Two recordings, 12,000 and 8,000 rows, the second held out whole:
       the later part reads the end of the first and all of the second
       from its start; it says the second is held out. */
    snprintf(cmd, sizeof cmd, "%s synth --effect viscous_friction --seed 7 --rows 12000 --real %s "
             "--sim %s 2>/dev/null && %s synth --effect viscous_friction --seed 8 --rows 8000 --real %s.2 "
             "--sim %s.2", FE_TEST_CLI, real, sim, FE_TEST_CLI, real, sim);
    ck_assert_int_eq(fe_test_run(cmd, FE_TEST_STDOUT, many, sizeof many), 0);
    snprintf(args, sizeof args, "--real %s --sim %s --real %s.2 --sim %s.2 --channel acceleration "
             "--role position=position --role velocity=velocity --role input=input --base "
             "bias,gain --holdout 0.4 --json", real, sim, real, sim);
    snprintf(cmd, sizeof cmd, "FOLDEST_CUT=0 %s discover %s", FE_TEST_CLI, args);
    ck_assert_int_eq(fe_test_run(cmd, FE_TEST_BOTH, one, sizeof one), 0);
    ck_assert_msg(strstr(one, "\"recording\": 2, \"rows\": 8000, \"heldout\": true") != NULL,
                  "%s", one);
    for (int t = 1; t <= 2; t++) {
        snprintf(cmd, sizeof cmd, "FOLDEST_CUT=1 %s discover %s --threads %d", FE_TEST_CLI, args, t);
        ck_assert_int_eq(fe_test_run(cmd, FE_TEST_BOTH, t == 1 ? cut : many, OUT), 0);
        ck_assert_int_eq(strip_cut(t == 1 ? cut : many), 2);
    }
    ck_assert_msg(same_but_rounding(one, cut, 1e-12), "cut:\n%.1500s\nin one piece:\n%.1500s", cut, one);
    ck_assert_msg(strcmp(cut, many) == 0, "two threads:\n%.1500s\none:\n%.1500s", many, cut);
    snprintf(cmd, sizeof cmd, "%s.gz", sim);
    unlink(cmd);
    snprintf(cmd, sizeof cmd, "%s.2", sim);
    unlink(cmd);
    snprintf(cmd, sizeof cmd, "%s.2", real);
    unlink(cmd);
    unlink(real);
    unlink(sim);
    unlink(gate);
}
END_TEST

/* --threads takes 1 to 64, in every command that reads tables. */
START_TEST(threads_option_checked)
{
    static const char *const bad[] = {"0", "-1", "x", "65", "2.5"};
    char cmd[512], out[4096];
    for (size_t c = 0; c < 3; c++)
        for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
            snprintf(cmd, sizeof cmd, "echo 1,2,3 | %s %s --threads %s %s", FE_TEST_CLI,
                     c == 2 ? "discover" : c ? "calibrate" : "stats", bad[i],
                     c == 2 ? "--real - --sim - --channel 1" : "-");
            ck_assert_int_eq(fe_test_run(cmd, FE_TEST_BOTH, out, sizeof out), 2);
            ck_assert_msg(strstr(out, "--threads") != NULL, "%s: %s", cmd, out);
        }
    snprintf(cmd, sizeof cmd, "echo 1,2,3 | %s stats --threads 64 -", FE_TEST_CLI);
    ck_assert_int_eq(fe_test_run(cmd, FE_TEST_BOTH, out, sizeof out), 0);
}
END_TEST

Suite *fe_threads_cli_suite(void)
{
    Suite *s = suite_create("threads_cli");
    TCase *t = tcase_create("threads");
    tcase_set_timeout(t, 120);
    tcase_add_test(t, same_but_rounding_tells);
    tcase_add_loop_test(t, same_on_every_cut, 0, (int)(sizeof cases / sizeof cases[0]));
    tcase_add_test(t, bit_equal_on_a_large_file);
    tcase_add_test(t, pipes_and_gzip_keep_one_reader);
    tcase_add_test(t, fewer_rows_than_threads);
    tcase_add_test(t, discover_same_on_every_cut);
    tcase_add_test(t, discover_same_in_two_parts);
    tcase_add_test(t, threads_option_checked);
    suite_add_tcase(s, t);
    return s;
}
