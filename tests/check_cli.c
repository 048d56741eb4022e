/* SPDX-License-Identifier: MIT */
/* The foldest command: tables with metadata, headers, quotes, CRLF and
   white space; every malformed input gives FILE:LINE:COLUMN and its exit
   status.  Runs the built binary (FE_TEST_CLI) on files written here. */
#define _POSIX_C_SOURCE 200809L
#include <sys/wait.h>
#include <unistd.h>

#include "foldest.h"
#include "testutil.h"

#ifndef FE_TEST_CLI
#define FE_TEST_CLI "build/bin/foldest"
#endif

/* Write `content` to a fresh file; run `foldest ARGS FILE`; capture stdout
   and stderr (together, at most 4 KiB) and return the exit status. */
static int run_on(const char *args, const char *content, size_t len, char *out,
                  size_t outlen, char *path, size_t pathlen)
{
    char cmd[1024];
    FILE *p;
    size_t got;
    int fd, status;
    snprintf(path, pathlen, "/tmp/foldest-cli-XXXXXX");
    fd = mkstemp(path);
    ck_assert_int_ge(fd, 0);
    ck_assert_int_eq(write(fd, content, len), (ssize_t)len);
    close(fd);
    snprintf(cmd, sizeof cmd, "%s %s %s 2>&1", FE_TEST_CLI, args, path);
    p = popen(cmd, "r");
    ck_assert_ptr_nonnull(p);
    got = fread(out, 1, outlen - 1, p);
    out[got] = '\0';
    status = pclose(p);
    unlink(path);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

struct cli_case {
    const char *what, *args, *content;
    int status;
    const char *expect;         /* a substring of the output; %s is the path */
};

static const struct cli_case cases[] = {
    {"metadata lines then a header", "stats --json",
     "Fs,50.00\nInitialization time,60\nmx,my,mz\n1,2,3\n3,4,5\n", 0, "\"rows\": 2"},
    {"quoted header, CRLF", "stats --columns Time --json",
     "\"Time (s)\",\"x\"\r\n0.5,1\r\n1.5,2\r\n", 0, "\"mean\": 1,"},
    {"white space, no header", "stats --columns 2 --json",
     "0.1\t1 \n0.2\t3\n", 0, "\"mean\": 2,"},
    {"empty file", "stats", "", 3, "%s: no data"},
    {"header only", "stats", "a,b\n", 3, "%s: no data rows"},
    {"wrong field count", "stats", "a,b\n1,2\n3\n", 3, "%s:3:1: expected 2 fields, found 1"},
    {"not a number", "stats", "a,b\n1,2\n3,x4\n", 3, "%s:3:3: 'x4' in column 'b' is not a number"},
    {"NaN text", "stats", "a,b\n1,NaN\n", 3, "%s:2:3: 'NaN' in column 'b' is not a finite number"},
    {"Inf text", "stats", "a,b\n1,2\n-inf,2\n", 3, "%s:3:1: '-inf' in column 'a' is not a finite"},
    {"unterminated quote", "stats", "a,b\n1,2\n1,\"2\n", 3, "%s:3:3: unterminated"},
    {"unknown column", "stats --columns zz", "a,b\n1,2\n", 2, "no column 'zz'; the columns are: 'a', 'b'"},
    {"unknown option", "stats --frobnicate", "a\n1\n", 2, "unknown option '--frobnicate'"},
    /* Files as phones, loggers and spreadsheets export them (issue 19). */
    {"UTF-8 byte-order mark", "stats --columns time --json",
     "\xEF\xBB\xBFtime,x\n0,1\n1,3\n", 0, "[{\"name\": \"time\", \"mean\": 0.5,"},
    {"byte-order mark, column numbers after it", "stats",
     "\xEF\xBB\xBF" "a,b\n1,x\n", 3, "%s:2:3: 'x' in column 'b'"},
    {"semicolons and decimal commas", "stats --columns a,b --json",
     "a;b\n1,5;2\n2,5;4,25\n", 0, "{\"name\": \"a\", \"mean\": 2,"},
    {"semicolons, decimal commas, second column", "stats --columns b --json",
     "a;b\n1,5;2\n2,5;4,25\n", 0, "\"mean\": 3.125,"},
    {"semicolons with decimal points", "stats --columns b --json",
     "a;b\n1.5;2\n2.5;4.5\n", 0, "\"mean\": 3.25,"},
    {"--decimal-comma in a tab table", "stats --decimal-comma --columns a --json",
     "a\tb\n1,5\t2\n2,5\t3\n", 0, "\"mean\": 2,"},
    {"--decimal-comma refuses a point", "stats --decimal-comma",
     "a\tb\n1,5\t2\n2.5\t3\n", 3, "%s:3:1: '2.5' in column 'a' is not a number"},
    {"hexadecimal is not a number", "stats", "a,b\n1,2\n0x1p3,2\n", 3,
     "%s:3:1: '0x1p3' in column 'a' is not a number"},
    {"hexadecimal integer", "stats", "a\n1\n0x10\n", 3, "'0x10' in column 'a' is not a number"},
    {"infinity word", "stats", "a\n1\nInfinity\n", 3, "'Infinity' in column 'a' is not a finite number"},
    {"nan with a payload", "stats", "a\n1\nnan(0x7)\n", 3, "'nan(0x7)' in column 'a' is not a number"},
    {"empty cell", "stats", "a,b\n1,2\n3,\n", 3, "%s:3:3: empty cell in column 'b'"},
    {"more fields than the header", "stats", "a,b\n1,2\n3,4,5\n", 3,
     "%s:3:1: expected 2 fields, found 3"},
    {"empty cell first", "stats", "a,b\n1,2\n,4\n", 3, "%s:3:1: empty cell in column 'a'"},
    {"--skip-bad-rows counts by reason", "stats --skip-bad-rows --json",
     "a,b\n1,2\n,3\nNaN,4\nx,5\n7\n3,6\n", 0,
     "\"rows\": 2, \"bad_rows\": {\"total\": 4, \"empty_cell\": 1, \"not_finite\": 1, "
     "\"not_a_number\": 1, \"field_count\": 1}"},
    {"--skip-bad-rows says so", "stats --skip-bad-rows",
     "a,b\n1,2\n,3\n3,6\n", 0, "skipped 1 bad rows (1 with an empty cell, 0 with NaN"},
    {"no bad rows: zero in the JSON", "stats --json", "a\n1\n", 0,
     "\"bad_rows\": {\"total\": 0, "},
    {"--skip-bad-rows after --", "stats -- --skip-bad-rows", "a\n1\n", 2, NULL},
    /* The fold refuses a square that overflows, at the first such row in
       file order, even when the column before refuses a later row, and
       before the reader's complaint about a row after it. */
    {"the fold refuses the first row in file order", "stats",
     "a,b\n1,1\n2,1e300\n1e300,3\n", 3, "%s:3: "},
    {"the fold refuses the first row in file order, first column", "stats",
     "a,b\n1,1\n1e300,2\n3,1e300\n", 3, "%s:3: "},
    {"a refusal before a malformed row", "stats", "a\n1\n1e300\nx\n", 3, "%s:3: "},
};

START_TEST(table_driven)
{
    const struct cli_case *c = &cases[_i];
    char out[4096], path[64], want[512];
    int status = run_on(c->args, c->content, strlen(c->content), out, sizeof out,
                        path, sizeof path);
    snprintf(want, sizeof want, c->expect != NULL ? c->expect : "", path);
    ck_assert_msg(status == c->status, "%s: status %d, want %d; output:\n%s", c->what,
                  status, c->status, out);
    ck_assert_msg(strstr(out, want) != NULL, "%s: output lacks \"%s\":\n%s", c->what, want, out);
}
END_TEST

/* The fold takes the rows in runs of 512, column by column: over 1300
   rows (runs of 512, 512 and 276) the minimum and maximum are right with
   the extremes in the first row, inside a later run and in the last row,
   in a column of positive numbers and one of negative ones (neither may
   start from zero), and the mean and standard deviation are those of a
   long-double sum over the same numbers. */
START_TEST(stats_over_runs_of_rows)
{
    enum { N = 1300 };
    static char text[N * 32 + 16];
    char out[4096], path[64], want[256];
    size_t len = 0;
    long double sum[2] = {0, 0}, ss[2] = {0, 0};
    double x[2][N];
    len += (size_t)sprintf(text + len, "a,b\n");
    for (int i = 0; i < N; i++) {
        x[0][i] = i == 0 ? 5000 : i == 777 ? 1 : 2 + (double)(i % 100);
        x[1][i] = i == N - 1 ? -5000 : -(double)(i + 1);
        len += (size_t)sprintf(text + len, "%.17g,%.17g\n", x[0][i], x[1][i]);
        sum[0] += x[0][i];
        sum[1] += x[1][i];
    }
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < N; i++)
            ss[j] += (x[j][i] - sum[j] / N) * (x[j][i] - sum[j] / N);
    ck_assert_int_eq(run_on("stats --json", text, len, out, sizeof out, path, sizeof path), 0);
    for (int j = 0; j < 2; j++) {
        const char *at = strstr(out, j == 0 ? "\"name\": \"a\"" : "\"name\": \"b\"");
        double mean, sd, lo, hi;
        ck_assert_ptr_nonnull(at);
        ck_assert_int_eq(sscanf(at + 11, ", \"mean\": %lg, \"stddev\": %lg, \"min\": %lg, \"max\": %lg",
                                &mean, &sd, &lo, &hi), 4);
        FE_ASSERT_REL(mean, (double)(sum[j] / N), 1e-14);
        FE_ASSERT_REL(sd, sqrt((double)(ss[j] / (N - 1))), 1e-14);
        ck_assert_double_eq(lo, j == 0 ? 1 : -5000);
        ck_assert_double_eq(hi, j == 0 ? 5000 : -1);
    }
    snprintf(want, sizeof want, "\"rows\": %d,", N);
    ck_assert_ptr_nonnull(strstr(out, want));
}
END_TEST

/* Rows that the one pass reads and rows it declines give the numbers a
   long-double sum of the values written gives: 100 rows of numbers,
   every seventh with a padded, quoted or exponent field among them, then
   200 rows whose unused first column is text (the one pass declines 64
   of them in a row and stops asking), and the rows' count. */
START_TEST(rows_the_one_pass_declines_read_as_before)
{
    enum { N = 300 };
    static char text[N * 48 + 16];
    char out[4096], path[64], want[64];
    size_t len = (size_t)sprintf(text, "label,x,y\n");
    long double sum[2] = {0, 0};
    for (int i = 0; i < N; i++) {
        double x = 0.001 * (double)((i * 7919) % 1000) - 0.5, y = 25.0 + 0.25 * (i % 37);
        const char *form = i >= 100 ? "r%d,%.3f,%.2f\n" : i % 21 == 0 ? "%d, %.3f,%.2f\n"
                           : i % 21 == 7 ? "%d,%.3f,\"%.2f\"\n" : i % 21 == 14 ? "%d,%.3f,%.2fe0\n"
                           : "%d,%.3f,%.2f\n";
        len += (size_t)sprintf(text + len, form, i, x, y);
        sum[0] += x;
        sum[1] += y;
    }
    ck_assert_int_eq(run_on("stats --columns x,y --json", text, len, out, sizeof out, path,
                            sizeof path), 0);
    for (int j = 0; j < 2; j++) {
        const char *at = strstr(out, j == 0 ? "\"name\": \"x\"" : "\"name\": \"y\"");
        double mean;
        ck_assert_ptr_nonnull(at);
        ck_assert_int_eq(sscanf(at + 11, ", \"mean\": %lg", &mean), 1);
        FE_ASSERT_REL(mean, (double)(sum[j] / N), 1e-13);
    }
    snprintf(want, sizeof want, "\"rows\": %d,", N);
    ck_assert_ptr_nonnull(strstr(out, want));
}
END_TEST

/* A gzip file made here, independently of zlib: the header, one stored
   (uncompressed) deflate block per 65535 bytes, CRC-32 and length. */
static unsigned long crc32_of(const unsigned char *p, size_t n)
{
    unsigned long c = 0xFFFFFFFFul;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++)
            c = (c >> 1) ^ (0xEDB88320ul & (0ul - (c & 1ul)));
    }
    return c ^ 0xFFFFFFFFul;
}

static size_t gzip_stored(const char *text, size_t n, unsigned char *out)
{
    static const unsigned char head[10] = {0x1f, 0x8b, 8, 0, 0, 0, 0, 0, 0, 0xff};
    size_t o = 0, at = 0;
    unsigned long crc = crc32_of((const unsigned char *)text, n);
    memcpy(out, head, 10);
    o = 10;
    do {
        size_t len = n - at > 65535 ? 65535 : n - at;
        out[o++] = at + len == n ? 1 : 0;       /* BFINAL, BTYPE 00 */
        out[o++] = (unsigned char)(len & 0xff);
        out[o++] = (unsigned char)(len >> 8);
        out[o++] = (unsigned char)(~len & 0xff);
        out[o++] = (unsigned char)((~len >> 8) & 0xff);
        memcpy(out + o, text + at, len);
        o += len;
        at += len;
    } while (at < n);
    for (int k = 0; k < 4; k++)
        out[o++] = (unsigned char)((crc >> (8 * k)) & 0xff);
    for (int k = 0; k < 4; k++)
        out[o++] = (unsigned char)((n >> (8 * k)) & 0xff);
    return o;
}

START_TEST(gzip_files_read_like_plain_ones)
{
    static char text[200000], out[4096], plain[4096];
    static unsigned char gz[210000];
    char path[64];
    size_t n = 0, m;
    n += (size_t)snprintf(text + n, sizeof text - n, "\xEF\xBB\xBFt;x\n");
    for (int i = 0; i < 10000; i++)
        n += (size_t)snprintf(text + n, sizeof text - n, "%d;%d,%d\n", i, i % 13, i % 10);
    m = gzip_stored(text, n, gz);
    ck_assert_int_eq(run_on("stats --json", text, n, plain, sizeof plain, path, sizeof path), 0);
    ck_assert_int_eq(run_on("stats --json", (const char *)gz, m, out, sizeof out, path, sizeof path), 0);
    ck_assert_msg(strstr(out, "\"rows\": 10000") != NULL, "%s", out);
    /* Same numbers as the plain file (the file names differ). */
    ck_assert_str_eq(strstr(out, "\"rows\""), strstr(plain, "\"rows\""));
    /* A corrupt gzip stream is an error, not a short table. */
    gz[m - 5] ^= 0x55;
    ck_assert_int_ne(run_on("stats --json", (const char *)gz, m, out, sizeof out, path, sizeof path), 0);
    /* Standard input, compressed. */
    {
        char cmd[512];
        FILE *p;
        size_t got;
        int fd, status;
        gz[m - 5] ^= 0x55;
        snprintf(path, sizeof path, "/tmp/foldest-cli-XXXXXX");
        fd = mkstemp(path);
        ck_assert_int_ge(fd, 0);
        ck_assert_int_eq(write(fd, gz, m), (ssize_t)m);
        close(fd);
        snprintf(cmd, sizeof cmd, "cat %s | %s stats --json - 2>&1", path, FE_TEST_CLI);
        p = popen(cmd, "r");
        ck_assert_ptr_nonnull(p);
        got = fread(out, 1, sizeof out - 1, p);
        out[got] = '\0';
        status = pclose(p);
        unlink(path);
        ck_assert_int_eq(WEXITSTATUS(status), 0);
        ck_assert_str_eq(strstr(out, "\"rows\""), strstr(plain, "\"rows\""));
    }
}
END_TEST

/* ------------------------------------------------ JSON and its schemas */

#ifndef FE_TEST_SRC
#define FE_TEST_SRC "."
#endif

/* Run `cmd` (a shell command line writing JSON to stdout) into a file,
   require exit status `status`, then validate the file against
   doc/schema/SCHEMA with tests/schema/validate.py (python3, standard
   library only).  The output is left in `out`. */
static void json_valid(const char *cmd, int status, const char *schema, char *out, size_t outlen)
{
    char full[4096], file[64], msg[4096];
    FILE *p;
    size_t got;
    int fd, rc;
    snprintf(file, sizeof file, "/tmp/foldest-json-XXXXXX");
    fd = mkstemp(file);
    ck_assert_int_ge(fd, 0);
    close(fd);
    snprintf(full, sizeof full, "%s > %s 2>/dev/null", cmd, file);
    rc = system(full);
    ck_assert_msg(WIFEXITED(rc) && WEXITSTATUS(rc) == status, "%s: status %d, want %d", cmd,
                  WEXITSTATUS(rc), status);
    fe_test_read_file(file, out, outlen);
    snprintf(full, sizeof full, "python3 %s/tests/schema/validate.py %s/doc/schema/%s < %s 2>&1",
             FE_TEST_SRC, FE_TEST_SRC, schema, file);
    p = popen(full, "r");
    ck_assert_ptr_nonnull(p);
    got = fread(msg, 1, sizeof msg - 1, p);
    msg[got] = '\0';
    rc = pclose(p);
    unlink(file);
    ck_assert_msg(WIFEXITED(rc) && WEXITSTATUS(rc) == 0, "%s: output not valid against %s:\n%s\n%s",
                  cmd, schema, msg, out);
}

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    ck_assert_ptr_nonnull(f);
    fputs(text, f);
    fclose(f);
}

START_TEST(json_outputs_follow_their_schemas)
{
    static char out[1 << 16];
    char dir[64], cmd[2048], path[256];
    const char *F = FE_TEST_CLI;
    snprintf(dir, sizeof dir, "/tmp/foldest-schema-XXXXXX");
    ck_assert_ptr_nonnull(mkdtemp(dir));

    /* stats: a Latin-1 byte and a broken UTF-8 sequence in the header, a
       good UTF-8 name, a tab and a quote: the JSON stays UTF-8, the bad
       bytes become U+FFFD, the rest is escaped. */
    snprintf(path, sizeof path, "%s/names.csv", dir);
    write_text(path, "caf\xe9,\xe2\x82,\xce\xbcT,\"a\"\"b\tc\"\n0.1,1,2,3\n0.2,1,2,4\n,1,2,3\nNaN,1,1,1\n");
    snprintf(cmd, sizeof cmd, "%s stats --skip-bad-rows --json %s", F, path);
    json_valid(cmd, 0, "stats.schema.json", out, sizeof out);
    ck_assert_msg(strstr(out, "\"name\": \"caf\\ufffd\"") != NULL, "%s", out);
    ck_assert_msg(strstr(out, "\"name\": \"\\ufffd\\ufffd\"") != NULL, "%s", out);
    ck_assert_msg(strstr(out, "\"name\": \"\xce\xbcT\"") != NULL, "%s", out);
    ck_assert_msg(strstr(out, "\"name\": \"a\\\"b\\u0009c\"") != NULL, "%s", out);
    /* One number format: the shortest that reads back (15 to 17 digits). */
    ck_assert_msg(strstr(out, "\"min\": 0.1, \"max\": 0.2}") != NULL, "%s", out);
    ck_assert_msg(strstr(out, "\"bad_rows\": {\"total\": 2, \"empty_cell\": 1, \"not_finite\": 1") != NULL,
                  "%s", out);

    /* calibrate: a fit, and a refusal. */
    snprintf(path, sizeof path, "%s/mag.csv", dir);
    {
        FILE *f = fopen(path, "w");
        fe_rng g = fe_rng_seed(11);
        ck_assert_ptr_nonnull(f);
        fprintf(f, "t,mx,my,mz\n");
        for (int i = 0; i < 2000; i++) {
            double v[3];
            fe_rng_unit_vector(&g, v);
            fprintf(f, "%d,%.5f,%.5f,%.5f\n", i, 20 + 400 * v[0] + fe_rng_normal(&g),
                    -10 + 380 * v[1] + fe_rng_normal(&g), 5 + 420 * v[2] + fe_rng_normal(&g));
        }
        fclose(f);
    }
    for (int m = 0; m < 3; m++) {
        static const char *const model[] = {"sphere", "axial", "ellipsoid"};
        snprintf(cmd, sizeof cmd, "%s calibrate --model %s --columns mx,my,mz --json %s", F, model[m], path);
        json_valid(cmd, 0, "calibrate.schema.json", out, sizeof out);
    }
    /* With a known field, still segments and outliers rejected. */
    snprintf(cmd, sizeof cmd, "%s calibrate --columns mx,my,mz --field 48 --static --still-sd 0.05"
             " --robust --json %s", F, path);
    json_valid(cmd, 0, "calibrate.schema.json", out, sizeof out);
    ck_assert_msg(strstr(out, "\"robust_rejected\": ") != NULL, "%s", out);
    snprintf(path, sizeof path, "%s/plane.csv", dir);
    write_text(path, "x,y,z\n1,0,0\n0,1,0\n-1,0,0\n0,-1,0\n0.7,0.7,0\n-0.7,0.7,0\n0.7,-0.7,0\n-0.7,-0.7,0\n"
                     "0.6,0.8,0\n0.8,0.6,0\n-0.6,0.8,0\n0.8,-0.6,0\n");
    snprintf(cmd, sizeof cmd, "%s calibrate --columns x,y,z --json %s", F, path);
    json_valid(cmd, 1, "calibrate.schema.json", out, sizeof out);
    ck_assert_msg(strstr(out, "\"refusal\": \"") != NULL, "%s", out);

    /* discover --sphere: an analysis, and a refusal. */
    snprintf(cmd, sizeof cmd, "%s discover --sphere %s/mag.csv --columns mx,my,mz --json", F, dir);
    json_valid(cmd, 0, "discover-sphere.schema.json", out, sizeof out);
    snprintf(cmd, sizeof cmd, "%s discover --sphere %s --columns x,y,z --json", F, path);
    json_valid(cmd, 1, "discover-sphere.schema.json", out, sizeof out);
    ck_assert_msg(strstr(out, "\"verdict\": \"refused\"") != NULL, "%s", out);

    /* discover: a concealed effect, and none. */
    for (int e = 0; e < 2; e++) {
        snprintf(cmd, sizeof cmd, "%s synth --effect %s --seed 5 --rows 20000 --real %s/r.csv --sim %s/s.csv "
                 ">/dev/null 2>&1", F, e ? "none" : "quadratic_drag", dir, dir);
        ck_assert_int_eq(system(cmd), 0);
        snprintf(cmd, sizeof cmd, "%s discover --real %s/r.csv --sim %s/s.csv --channel acceleration "
                 "--role position=position --role velocity=velocity --role input=input --base bias,gain --json",
                 F, dir, dir);
        json_valid(cmd, 0, "discover.schema.json", out, sizeof out);
    }
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    ck_assert_int_eq(system(cmd), 0);
}
END_TEST

/* The validator itself refuses what it must: invalid UTF-8, NaN, a
   duplicate key, a missing required property, a wrong type. */
START_TEST(schema_validator_refuses)
{
    static const char *const bad[] = {
        "{\"file\": \"a\xff\", \"rows\": 1, \"bad_rows\": {\"total\": 0, \"empty_cell\": 0, \"not_finite\": 0, "
        "\"not_a_number\": 0, \"field_count\": 0}, \"columns\": []}",
        "{\"file\": \"a\", \"rows\": NaN, \"bad_rows\": {}, \"columns\": []}",
        "{\"file\": \"a\", \"file\": \"b\", \"rows\": 1, \"bad_rows\": {\"total\": 0, \"empty_cell\": 0, "
        "\"not_finite\": 0, \"not_a_number\": 0, \"field_count\": 0}, \"columns\": []}",
        "{\"file\": \"a\", \"rows\": 1, \"columns\": []}",
        "{\"file\": \"a\", \"rows\": \"1\", \"bad_rows\": {\"total\": 0, \"empty_cell\": 0, \"not_finite\": 0, "
        "\"not_a_number\": 0, \"field_count\": 0}, \"columns\": []}",
    };
    const char *good = "{\"file\": \"a\", \"rows\": 1, \"bad_rows\": {\"total\": 0, \"empty_cell\": 0, "
                       "\"not_finite\": 0, \"not_a_number\": 0, \"field_count\": 0}, \"columns\": []}";
    for (size_t i = 0; i <= sizeof bad / sizeof bad[0]; i++) {
        char path[64], cmd[1024];
        int fd, rc;
        const char *text = i < sizeof bad / sizeof bad[0] ? bad[i] : good;
        snprintf(path, sizeof path, "/tmp/foldest-json-XXXXXX");
        fd = mkstemp(path);
        ck_assert_int_ge(fd, 0);
        ck_assert_int_eq(write(fd, text, strlen(text)), (ssize_t)strlen(text));
        close(fd);
        snprintf(cmd, sizeof cmd, "python3 %s/tests/schema/validate.py %s/doc/schema/stats.schema.json < %s 2>/dev/null",
                 FE_TEST_SRC, FE_TEST_SRC, path);
        rc = system(cmd);
        unlink(path);
        ck_assert_msg(WIFEXITED(rc) && WEXITSTATUS(rc) == (text == good ? 0 : 1), "case %zu: status %d", i,
                      WEXITSTATUS(rc));
    }
}
END_TEST

/* Every option the bash completion offers for a command is in the
   command's man page and is accepted by the command (as --opt or
   --opt=value, before --help), and the man pages list the common ones. */
START_TEST(options_documented_completed_and_accepted)
{
    static const char *const commands[] = {"stats", "calibrate", "discover", "synth"};
    static char completion[16384], page[16384];
    char path[512];
    snprintf(path, sizeof path, "%s/doc/completion/foldest.bash", FE_TEST_SRC);
    fe_test_read_file(path, completion, sizeof completion);
    for (size_t c = 0; c < sizeof commands / sizeof commands[0]; c++) {
        char key[64], opts[1024], *at, *end;
        int count = 0;
        snprintf(path, sizeof path, "%s/doc/man/foldest-%s.1", FE_TEST_SRC, commands[c]);
        fe_test_read_file(path, page, sizeof page);
        snprintf(key, sizeof key, "%s) opts=\"", commands[c]);
        at = strstr(completion, key);
        ck_assert_msg(at != NULL, "no options for %s in the completion", commands[c]);
        at += strlen(key);
        end = strchr(at, '"');
        ck_assert_ptr_nonnull(end);
        snprintf(opts, sizeof opts, "%.*s", (int)(end - at), at);
        for (char *o = strtok(opts, " \n"); o != NULL; o = strtok(NULL, " \n")) {
            char man[64], cmd[512];
            int plain, valued;
            snprintf(man, sizeof man, "\\-\\-%s", o + 2);
            ck_assert_msg(strstr(page, man) != NULL, "%s: %s not in its man page", commands[c], o);
            snprintf(cmd, sizeof cmd, "%s %s %s --help >/dev/null 2>&1", FE_TEST_CLI, commands[c], o);
            plain = system(cmd);
            snprintf(cmd, sizeof cmd, "%s %s %s=x --help >/dev/null 2>&1", FE_TEST_CLI, commands[c], o);
            valued = system(cmd);
            ck_assert_msg((WIFEXITED(plain) && WEXITSTATUS(plain) == 0)
                          || (WIFEXITED(valued) && WEXITSTATUS(valued) == 0),
                          "%s does not accept %s", commands[c], o);
            count++;
        }
        ck_assert_int_ge(count, 3);
    }
    snprintf(path, sizeof path, "%s/doc/man/foldest.1", FE_TEST_SRC);
    fe_test_read_file(path, page, sizeof page);
    ck_assert(strstr(page, "\\-\\-decimal\\-comma") != NULL);
    ck_assert(strstr(page, "\\-\\-skip\\-bad\\-rows") != NULL);
    ck_assert(strstr(page, "\\-V") != NULL);
}
END_TEST

START_TEST(binary_and_long_lines)
{
    char out[4096], path[64], want[256];
    static char big[100000];
    const char bin[] = "a,b\n1,2\n\0\1\2\n";
    int status = run_on("stats", bin, sizeof bin - 1, out, sizeof out, path, sizeof path);
    ck_assert_int_eq(status, 3);
    snprintf(want, sizeof want, "%s:3:1: NUL byte", path);
    ck_assert_msg(strstr(out, want) != NULL, "%s", out);
    memset(big, '1', sizeof big);
    memcpy(big, "a\n1\n", 4);
    big[sizeof big - 1] = '\n';
    status = run_on("stats", big, sizeof big, out, sizeof out, path, sizeof path);
    ck_assert_int_eq(status, 3);
    snprintf(want, sizeof want, "%s:3:1: line longer than", path);
    ck_assert_msg(strstr(out, want) != NULL, "%s", out);
}
END_TEST

/* The dispatcher, each command's --help, and argument errors: the status
   and a message that names the problem. */
struct usage_case {
    const char *args;
    int status;
    const char *expect;
};

static const struct usage_case usage_cases[] = {
    {"", 2, "usage: foldest COMMAND"},
    {"help", 0, "commands:"},
    {"--help", 0, "'foldest COMMAND --help' documents each command."},
    {"--version", 0, "foldest 0."},
    {"frobnicate", 2, "unknown command 'frobnicate'"},
    {"stats --help", 0, "usage: foldest stats"},
    {"stats", 2, "usage: foldest stats"},
    {"stats a.csv b.csv", 2, "one input file, please"},
    {"stats --skip x a.csv", 2, "--skip: 'x' is not a whole number"},
    {"stats --skip -3 a.csv", 2, "--skip: negative"},
    {"stats /nonexistent/a.csv", 4, "/nonexistent/a.csv: cannot open"},
    {"calibrate --help", 0, "usage: foldest calibrate"},
    {"calibrate", 2, "usage: foldest calibrate"},
    {"calibrate --model cube a.csv", 2, "--model: 'cube' is not sphere, axial or ellipsoid"},
    {"calibrate --skip x a.csv", 2, "--skip: 'x' is not a whole number"},
    {"calibrate --skip -1 a.csv", 2, "--skip: negative"},
    {"calibrate --bogus a.csv", 2, "unknown option '--bogus'"},
    {"calibrate a.csv b.csv", 2, "one input file, please"},
    {"calibrate --apply out.csv -", 2, "--apply reads the input twice"},
    {"calibrate /nonexistent/a.csv", 4, "cannot open"},
    {"discover --help", 0, "usage: foldest discover"},
    {"discover --sphere", 2, "option '--sphere' needs a value"},
    {"discover --sphere a.csv --role t=velocity", 2, "--role with --sphere: COLUMN=temperature"},
    {"discover --sphere a.csv --holdout 0.95", 2, "--holdout: 0.95 is not in [0, 0.9)"},
    {"discover --sphere a.csv --blocks 2", 2, "--blocks: 2 is not in [4, 64]"},
    {"discover --sphere a.csv --alpha x", 2, "--alpha: 'x' is not a number"},
    {"discover --sphere a.csv --wobble 1", 2, "unknown option '--wobble'"},
    {"discover --sphere /nonexistent/a.csv", 4, "cannot open"},
    {"synth --help", 0, "usage: foldest synth"},
    {"synth --effect quadratic_drag --seed x --real r --sim s", 2, "--seed"},
    {"synth --effect drift --rho 1 --real r --sim s", 2, "--rho: 1 is not in [0, 1)"},
    {"synth --effect drift --rho -0.1 --real r --sim s", 2, "--rho: -0.1 is not in [0, 1)"},
    {"synth --effect drift --rho x --real r --sim s", 2, "--rho: 'x' is not a number"},
    /* Conventions of the shell (issue 19, item 8): getopt_long everywhere. */
    {"-V", 0, "foldest 0."},
    {"stats -V", 0, "foldest 0."},
    {"discover --version", 0, "foldest 0."},
    {"calibrate --version a.csv", 0, "foldest " FE_VERSION "\n"},
    {"synth --version --effect drift", 0, "foldest " FE_VERSION "\n"},
    {"stats -h", 0, "usage: foldest stats"},
    {"synth -h", 0, "usage: foldest synth"},
    {"discover -h --real x", 0, "usage: foldest discover"},
    {"stats --skip=x a.csv", 2, "--skip: 'x' is not a whole number"},
    {"calibrate --mo cube a.csv", 2, "--model: 'cube' is not sphere, axial or ellipsoid"},
    {"calibrate --mod=cube a.csv", 2, "--model: 'cube' is not sphere, axial or ellipsoid"},
    {"calibrate a.csv --skip -1", 2, "--skip: negative"},
    {"stats --colums a a.csv", 2, "unknown option '--colums'; did you mean '--columns'?"},
    {"discover --rael x --sim y --channel c", 2, "unknown option '--rael'; did you mean '--real'?"},
    {"synth --efect drag", 2, "unknown option '--efect'; did you mean '--effect'?"},
    {"calibrate --apple out.csv a.csv", 2, "unknown option '--apple'; did you mean '--apply'?"},
    {"stats --frobnicate a.csv", 2, "unknown option '--frobnicate'\n"},
    {"discover --r x", 2, "ambiguous option '--r': it could be --real --role --report"},
    {"synth --effect", 2, "option '--effect' needs a value"},
    {"stats -x a.csv", 2, "unknown option '-x'"},
    /* Documented ranges: the limits, and just inside and just outside them.
       A value accepted goes on to the missing file (status 4). */
    {"calibrate --static --window 1 /nonexistent/a.csv", 2, "--window: from 2 to 1000000 samples"},
    {"calibrate --static --window 2 /nonexistent/a.csv", 4, "cannot open"},
    {"calibrate --static --window 1000000 /nonexistent/a.csv", 4, "cannot open"},
    {"calibrate --static --window 1000001 /nonexistent/a.csv",
     2, "--window: from 2 to 1000000 samples"},
    {"calibrate --field 0 /nonexistent/a.csv", 2, "--field: a finite number, above 0"},
    {"calibrate --field 1e-300 /nonexistent/a.csv", 4, "cannot open"},
    {"calibrate --mgauss 0 /nonexistent/a.csv", 2, "--mgauss: a finite number, above 0"},
    {"calibrate --mgauss 1e-300 /nonexistent/a.csv", 4, "cannot open"},
    {"calibrate --robust --robust-k 0 /nonexistent/a.csv",
     2, "--robust-k: a finite number, above 0"},
    {"calibrate --robust --robust-k 1e-300 /nonexistent/a.csv", 4, "cannot open"},
    {"calibrate --field inf /nonexistent/a.csv", 2, "--field: a finite number, above 0"},
    {"calibrate --static --still-sd -1e-300 /nonexistent/a.csv",
     2, "--still-sd: a finite number, at least 0"},
    {"calibrate --static --still-sd 0 /nonexistent/a.csv", 4, "cannot open"},
    {"calibrate --static --gyro a,b,c --max-rate -1e-300 /nonexistent/a.csv",
     2, "--max-rate: a finite number, at least 0"},
    {"calibrate --static --gyro a,b,c --max-rate 0 /nonexistent/a.csv", 4, "cannot open"},
    {"discover --real /nonexistent/r.csv --sim /nonexistent/s.csv --channel y --blocks 3",
     2, "--blocks: 3 is not in [4, 64]"},
    {"discover --real /nonexistent/r.csv --sim /nonexistent/s.csv --channel y --blocks 4",
     4, "cannot open"},
    {"discover --real /nonexistent/r.csv --sim /nonexistent/s.csv --channel y --blocks 64",
     4, "cannot open"},
    {"discover --real /nonexistent/r.csv --sim /nonexistent/s.csv --channel y --blocks 65",
     2, "--blocks: 65 is not in [4, 64]"},
    {"discover --real /nonexistent/r.csv --sim /nonexistent/s.csv --channel y --holdout -0.01",
     2, "--holdout: -0.01 is not in [0, 0.9)"},
    {"discover --real /nonexistent/r.csv --sim /nonexistent/s.csv --channel y --holdout 0",
     4, "cannot open"},
    {"discover --real /nonexistent/r.csv --sim /nonexistent/s.csv --channel y --holdout 0.899",
     4, "cannot open"},
    {"discover --real /nonexistent/r.csv --sim /nonexistent/s.csv --channel y --holdout 0.9",
     2, "--holdout: 0.9 is not in [0, 0.9)"},
    {"discover --real /nonexistent/r.csv --sim /nonexistent/s.csv --channel y --alpha 0",
     2, "--alpha: 0 is not in (0, 0.5)"},
    {"discover --real /nonexistent/r.csv --sim /nonexistent/s.csv --channel y --alpha 0.001",
     4, "cannot open"},
    {"discover --real /nonexistent/r.csv --sim /nonexistent/s.csv --channel y --alpha 0.499",
     4, "cannot open"},
    {"discover --real /nonexistent/r.csv --sim /nonexistent/s.csv --channel y --alpha 0.5",
     2, "--alpha: 0.5 is not in (0, 0.5)"},
    {"discover --sphere /nonexistent/a.csv --blocks 3", 2, "--blocks: 3 is not in [4, 64]"},
    {"discover --sphere /nonexistent/a.csv --blocks 4", 4, "cannot open"},
    {"discover --sphere /nonexistent/a.csv --blocks 64", 4, "cannot open"},
    {"discover --sphere /nonexistent/a.csv --blocks 65", 2, "--blocks: 65 is not in [4, 64]"},
    {"discover --sphere /nonexistent/a.csv --holdout -0.01",
     2, "--holdout: -0.01 is not in [0, 0.9)"},
    {"discover --sphere /nonexistent/a.csv --holdout 0", 4, "cannot open"},
    {"discover --sphere /nonexistent/a.csv --holdout 0.899", 4, "cannot open"},
    {"discover --sphere /nonexistent/a.csv --holdout 0.9", 2, "--holdout: 0.9 is not in [0, 0.9)"},
    {"discover --sphere /nonexistent/a.csv --alpha 0", 2, "--alpha: 0 is not in (0, 0.5)"},
    {"discover --sphere /nonexistent/a.csv --alpha 0.001", 4, "cannot open"},
    {"discover --sphere /nonexistent/a.csv --alpha 0.499", 4, "cannot open"},
    {"discover --sphere /nonexistent/a.csv --alpha 0.5", 2, "--alpha: 0.5 is not in (0, 0.5)"},
    {"discover --real /nonexistent/r.csv --sim /nonexistent/s.csv --channel y --lags -1",
     2, "--lags: -1 is not in [0, 16]"},
    {"discover --real /nonexistent/r.csv --sim /nonexistent/s.csv --channel y --lags 0",
     4, "cannot open"},
    {"discover --real /nonexistent/r.csv --sim /nonexistent/s.csv --channel y --lags 16",
     4, "cannot open"},
    {"discover --real /nonexistent/r.csv --sim /nonexistent/s.csv --channel y --lags 17",
     2, "--lags: 17 is not in [0, 16]"},
    {"discover --real /nonexistent/r.csv --sim /nonexistent/s.csv --channel y --order -1",
     2, "--order: -1 is not 0, 1 or 2"},
    {"discover --real /nonexistent/r.csv --sim /nonexistent/s.csv --channel y --order 0",
     4, "cannot open"},
    {"discover --real /nonexistent/r.csv --sim /nonexistent/s.csv --channel y --order 2",
     4, "cannot open"},
    {"discover --real /nonexistent/r.csv --sim /nonexistent/s.csv --channel y --order 3",
     2, "--order: 3 is not 0, 1 or 2"},
    {"synth --effect quadratic_drag --real /nonexistent/r.csv --sim /nonexistent/s.csv --order -1",
     2, "--order: -1 is not 0, 1 or 2"},
    {"synth --effect quadratic_drag --real /nonexistent/r.csv --sim /nonexistent/s.csv --order 0",
     4, "cannot create"},
    {"synth --effect quadratic_drag --real /nonexistent/r.csv --sim /nonexistent/s.csv --order 2",
     4, "cannot create"},
    {"synth --effect quadratic_drag --real /nonexistent/r.csv --sim /nonexistent/s.csv --order 3",
     2, "--order: 3 is not 0, 1 or 2"},
    {"synth --effect drift --real /nonexistent/r.csv --sim /nonexistent/s.csv --rows -1",
     2, "--rows: -1 is not 100 or more"},
    {"synth --effect drift --real /nonexistent/r.csv --sim /nonexistent/s.csv --rows 0",
     4, "cannot create"},
    {"synth --effect drift --real /nonexistent/r.csv --sim /nonexistent/s.csv --rows 99",
     2, "--rows: 99 is not 100 or more"},
    {"synth --effect drift --real /nonexistent/r.csv --sim /nonexistent/s.csv --rows 100",
     4, "cannot create"},
    {"synth --effect drift --real /nonexistent/r.csv --sim /nonexistent/s.csv --seed -1",
     2, "--seed: -1 is not 0 or more"},
    {"synth --effect drift --real /nonexistent/r.csv --sim /nonexistent/s.csv --seed 0",
     4, "cannot create"},
    {"synth --effect drift --real /nonexistent/r.csv", 2, "--sim is required"},
    {"synth --real r.csv --sim s.csv", 2, "--effect is required"},
    {"synth --effect quadratic_drag --real /nonexistent/r.csv --sim /nonexistent/s.csv --rho 0",
     4, "cannot create"},
    {"synth --effect quadratic_drag --real /nonexistent/r.csv --sim /nonexistent/s.csv --rho 0.999",
     4, "cannot create"},
};

START_TEST(usage_and_help)
{
    const struct usage_case *c = &usage_cases[_i];
    char cmd[512], out[8192];
    FILE *p;
    size_t got;
    int status;
    snprintf(cmd, sizeof cmd, "cd /tmp && %s %s 2>&1 < /dev/null", FE_TEST_CLI, c->args);
    p = popen(cmd, "r");
    ck_assert_ptr_nonnull(p);
    got = fread(out, 1, sizeof out - 1, p);
    out[got] = '\0';
    status = pclose(p);
    status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    ck_assert_msg(status == c->status, "foldest %s: status %d, want %d:\n%s", c->args, status,
                  c->status, out);
    ck_assert_msg(strstr(out, c->expect) != NULL, "foldest %s: output lacks \"%s\":\n%s", c->args,
                  c->expect, out);
}
END_TEST

/* discover --sphere's text report, with a time column and a temperature. */
START_TEST(discover_sphere_in_words)
{
    static char content[1 << 17], out[4096];
    char path[64];
    size_t n = 0;
    fe_rng g = fe_rng_seed(4);
    int status;
    n += (size_t)snprintf(content + n, sizeof content - n, "time,mx,my,mz,temp\n");
    for (int i = 0; i < 2000; i++) {
        double v[3];
        fe_rng_unit_vector(&g, v);
        n += (size_t)snprintf(content + n, sizeof content - n, "%.2f,%.4f,%.4f,%.4f,%.2f\n",
                              0.02 * i, 30 + 410 * v[0] + fe_rng_normal(&g),
                              -20 + 380 * v[1] + fe_rng_normal(&g), 10 + 400 * v[2] + fe_rng_normal(&g),
                              25 + 0.001 * i);
    }
    status = run_on("discover --columns mx,my,mz --time time --role temp=temperature --blocks 8 "
                    "--holdout 0.2 --alpha 0.01 --sphere", content, n, out, sizeof out, path,
                    sizeof path);
    ck_assert_msg(status == 0, "status %d:\n%s", status, out);
    ck_assert_msg(strstr(out, "the sphere: centre (") != NULL, "%s", out);
    ck_assert_msg(strstr(out, "baseline (sphere: radius and centre): radial RMS") != NULL, "%s", out);
    ck_assert_msg(strstr(out, "axis_gain") != NULL, "%s", out);
}
END_TEST

Suite *fe_cli_suite(void)
{
    Suite *s = suite_create("cli");
    TCase *t = tcase_create("stats");
    tcase_set_timeout(t, 60);
    tcase_add_loop_test(t, table_driven, 0, (int)(sizeof cases / sizeof cases[0]));
    tcase_add_test(t, stats_over_runs_of_rows);
    tcase_add_test(t, rows_the_one_pass_declines_read_as_before);
    tcase_add_test(t, binary_and_long_lines);
    tcase_add_test(t, json_outputs_follow_their_schemas);
    tcase_add_test(t, schema_validator_refuses);
    tcase_add_test(t, options_documented_completed_and_accepted);
    tcase_add_test(t, gzip_files_read_like_plain_ones);
    tcase_add_loop_test(t, usage_and_help, 0, (int)(sizeof usage_cases / sizeof usage_cases[0]));
    tcase_add_test(t, discover_sphere_in_words);
    suite_add_tcase(s, t);
    return s;
}
