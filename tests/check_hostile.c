/* SPDX-License-Identifier: MIT */
/* Hostile input end to end: every foldest command that reads a file, on
   every kind of bad file (empty, header only, truncated, binary, a field
   that is not a number, NaN and Inf text, a wrong field count, a very long
   line, duplicate and missing columns), and on a CRLF file that must work.
   One table: for each case and each command, the exit status documented in
   cli.org, a message naming the file and the problem (FILE:LINE:COLUMN
   where there is a line), nothing on standard output, and no output file
   (--apply, --report, synth's pair) or temporary file left behind. */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "foldest.h"
#include "testutil.h"

#ifndef FE_TEST_CLI
#define FE_TEST_CLI "build/bin/foldest"
#endif

enum { GOOD_ROWS = 100, BAD_LINE = GOOD_ROWS + 2 };

/* The commands.  IN is the hostile file, GOOD a valid recording, OUT and
   REP outputs that must not appear when the command fails. */
static const char *const commands[] = {
    "stats IN",
    "stats --json - < IN",
    "calibrate --columns mx,my,mz IN",
    "calibrate --columns mx,my,mz --json --apply OUT IN",
    "discover --sphere IN --columns mx,my,mz --json",
    "discover --real IN --sim GOOD --time t --channel mz --report REP",
    "discover --real GOOD --sim IN --time t --channel mz --json",
};
enum { NCOMMANDS = sizeof commands / sizeof commands[0] };

/* A hostile file: header, GOOD_ROWS rows on a sphere, then `tail` (the bad
   line is line BAD_LINE) and more good rows unless `last`. */
struct hostile {
    const char *what;
    const char *header;         /* NULL: no header line at all (empty file) */
    const char *tail;           /* appended after the good rows */
    int rows;                   /* good rows: GOOD_ROWS or 0 */
    int crlf;
    int extra;                  /* rows carry a fifth field (for a fifth header name) */
    int only_selecting;         /* applies only to commands that select columns */
    int status;                 /* 0 for the CRLF control */
    const char *expect;         /* substring of stderr; IN is the path shown */
};

static const struct hostile cases[] = {
    {"empty file", NULL, "", 0, 0, 0, 0, 3, "IN: no data: the file is empty"},
    {"header only", "t,mx,my,mz\n", "", 0, 0, 0, 0, 3, "IN: no data rows"},
    {"truncated last line", "t,mx,my,mz\n", "9.99,1.5", GOOD_ROWS, 0, 0, 0, 3,
     "IN:102:1: expected 4 fields, found 2"},
    {"binary block", "t,mx,my,mz\n", "\x7f" "ELF\x02\x01\x01\x00\x00\x00\n1,2,3,4\n", GOOD_ROWS, 0, 0, 0, 3,
     "IN:102:1: NUL byte"},
    {"not a number", "t,mx,my,mz\n", "9.99,1,2,x3\n", GOOD_ROWS, 0, 0, 0, 3,
     "IN:102:10: 'x3' in column 'mz' is not a number"},
    {"NaN text", "t,mx,my,mz\n", "9.99,1,2,NaN\n", GOOD_ROWS, 0, 0, 0, 3,
     "IN:102:10: 'NaN' in column 'mz' is not a finite number"},
    {"Inf text", "t,mx,my,mz\n", "9.99,1,2,-Inf\n", GOOD_ROWS, 0, 0, 0, 3,
     "IN:102:10: '-Inf' in column 'mz' is not a finite number"},
    {"overflowing number", "t,mx,my,mz\n", "9.99,1,2,1e999\n", GOOD_ROWS, 0, 0, 0, 3,
     "IN:102:10: '1e999' in column 'mz' is not a finite number"},
    {"too many fields", "t,mx,my,mz\n", "9.99,1,2,3,4\n", GOOD_ROWS, 0, 0, 0, 3,
     "IN:102:1: expected 4 fields, found 5"},
    {"too few fields", "t,mx,my,mz\n", "9.99,1,2\n", GOOD_ROWS, 0, 0, 0, 3,
     "IN:102:1: expected 4 fields, found 3"},
    {"very long line", "t,mx,my,mz\n", NULL /* 70000 digits */, GOOD_ROWS, 0, 0, 0, 3,
     "IN:102:1: line longer than 65535 bytes"},
    {"duplicate column", "t,mx,my,mz,mz\n", "", GOOD_ROWS, 0, 1, 1, 2,
     "IN: columns 4 and 5 are both named 'mz'"},
    {"missing column", "t,ax,ay,az\n", "", GOOD_ROWS, 0, 0, 1, 2, "IN: no column 'm"},
    {"CRLF line ends (valid)", "t,mx,my,mz\r\n", "", GOOD_ROWS, 1, 0, 0, 0, NULL},
};
enum { NCASES = sizeof cases / sizeof cases[0] };

static char dir[64];

static void write_rows(FILE *f, int rows, int crlf, int extra, double t0)
{
    fe_rng g = fe_rng_seed(5);
    for (int i = 0; i < rows; i++) {
        double v[3];
        fe_rng_unit_vector(&g, v);
        fprintf(f, "%.2f,%.4f,%.4f,%.4f%s%s", t0 + 0.01 * i, 20 + 400 * v[0],
                -10 + 380 * v[1], 5 + 420 * v[2], extra ? ",0" : "", crlf ? "\r\n" : "\n");
    }
}

static void write_hostile(const char *path, const struct hostile *h)
{
    FILE *f = fopen(path, "wb");
    ck_assert_ptr_nonnull(f);
    if (h->header != NULL)
        fputs(h->header, f);
    write_rows(f, h->rows, h->crlf, h->extra, 0.0);
    if (h->tail != NULL) {
        /* The binary case has a NUL inside: write its bytes by length. */
        size_t n = strcmp(h->what, "binary block") == 0 ? 19 : strlen(h->tail);
        fwrite(h->tail, 1, n, f);
    } else {
        for (int i = 0; i < 70000; i++)
            fputc('1' + i % 9, f);
        fputc('\n', f);
    }
    if (h->tail != NULL && h->tail[0] != '\0' && strcmp(h->what, "truncated last line") != 0)
        write_rows(f, 20, 0, 0, 10.0);
    fclose(f);
}

/* Replace IN, GOOD, OUT, REP in `cmd` by paths in dir. */
static void expand(char *out, size_t len, const char *cmd)
{
    size_t k = 0;
    while (*cmd != '\0' && k + 128 < len) {
        const char *word = NULL, *file = NULL;
        if (strncmp(cmd, "IN", 2) == 0)
            word = "IN", file = "in.csv";
        else if (strncmp(cmd, "GOOD", 4) == 0)
            word = "GOOD", file = "good.csv";
        else if (strncmp(cmd, "OUT", 3) == 0)
            word = "OUT", file = "out.csv";
        else if (strncmp(cmd, "REP", 3) == 0)
            word = "REP", file = "rep";
        if (word != NULL) {
            k += (size_t)snprintf(out + k, len - k, "%s/%s", dir, file);
            cmd += strlen(word);
        } else {
            out[k++] = *cmd++;
        }
    }
    out[k] = '\0';
}

/* Run `cmd` in sh; stdout and stderr separately; the exit status. */
static int run(const char *cmd, char *out, size_t outlen, char *err, size_t errlen)
{
    char full[4096], path[128];
    FILE *p, *e;
    size_t got;
    int status;
    snprintf(path, sizeof path, "%s/stderr.txt", dir);
    snprintf(full, sizeof full, "%s %s 2>%s", FE_TEST_CLI, cmd, path);
    p = popen(full, "r");
    ck_assert_ptr_nonnull(p);
    got = fread(out, 1, outlen - 1, p);
    out[got] = '\0';
    status = pclose(p);
    e = fopen(path, "r");
    ck_assert_ptr_nonnull(e);
    got = fread(err, 1, errlen - 1, e);
    err[got] = '\0';
    fclose(e);
    unlink(path);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* Nothing but the inputs in dir: no output, no report, no temporary file. */
static void assert_nothing_written(const char *what)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    ck_assert_ptr_nonnull(d);
    while ((e = readdir(d)) != NULL)
        ck_assert_msg(strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0
                      || strcmp(e->d_name, "in.csv") == 0 || strcmp(e->d_name, "good.csv") == 0,
                      "%s: '%s' was left behind", what, e->d_name);
    closedir(d);
}

START_TEST(every_command_on_every_hostile_file)
{
    const struct hostile *h = &cases[_i / NCOMMANDS];
    const char *command = commands[_i % NCOMMANDS];
    char cmd[1024], want[512], path[128], what[512];
    static char out[65536], err[8192];
    int status;

    /* stats reads every column: duplicate or unexpected names are not its
       problem, since it selects none. */
    if (h->only_selecting && strncmp(command, "stats", 5) == 0)
        return;
    snprintf(dir, sizeof dir, "/tmp/foldest-hostile-XXXXXX");
    ck_assert_ptr_nonnull(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/good.csv", dir);
    {
        FILE *f = fopen(path, "w");
        ck_assert_ptr_nonnull(f);
        fputs("t,mx,my,mz\n", f);
        write_rows(f, GOOD_ROWS + 40, 0, 0, 0.0);
        fclose(f);
    }
    snprintf(path, sizeof path, "%s/in.csv", dir);
    write_hostile(path, h);
    expand(cmd, sizeof cmd, command);
    snprintf(what, sizeof what, "%s: foldest %s", h->what, command);
    status = run(cmd, out, sizeof out, err, sizeof err);
    if (h->status == 0) {
        /* The control: a CRLF file reads like an LF one.  discover of a
           recording against itself finds nothing and still succeeds. */
        ck_assert_msg(status == 0, "%s: status %d\n%s", what, status, err);
        ck_assert_msg(out[0] != '\0', "%s: no output", what);
        if (strstr(command, "OUT") != NULL) {      /* --apply wrote every sample */
            char line[256];
            int lines = 0;
            FILE *f;
            snprintf(path, sizeof path, "%s/out.csv", dir);
            f = fopen(path, "r");
            ck_assert_msg(f != NULL, "%s: no %s", what, path);
            while (fgets(line, sizeof line, f) != NULL)
                lines++;
            fclose(f);
            ck_assert_msg(lines >= GOOD_ROWS && lines <= GOOD_ROWS + 1, "%s: %d lines in %s", what,
                          lines, path);
        }
    } else {
        /* The path as the command shows it: "<stdin>" when read from "-". */
        expand(want, sizeof want, h->expect);
        if (strstr(command, "- < IN") != NULL) {
            char *at = strstr(want, path);
            if (at != NULL) {
                char rest[512];
                snprintf(rest, sizeof rest, "%s", at + strlen(path));
                snprintf(at, sizeof want - (size_t)(at - want), "<stdin>%s", rest);
            }
        }
        ck_assert_msg(status == h->status, "%s: status %d, want %d\n%s", what, status,
                      h->status, err);
        ck_assert_msg(strstr(err, want) != NULL, "%s: stderr lacks \"%s\":\n%s", what, want, err);
        ck_assert_msg(out[0] == '\0', "%s: printed on standard output:\n%s", what, out);
        unlink(path);
        snprintf(path, sizeof path, "%s/good.csv", dir);
        unlink(path);
        snprintf(path, sizeof path, "%s/in.csv", dir);
        assert_nothing_written(what);
    }
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    ck_assert_int_eq(system(cmd), 0);
}
END_TEST

/* synth writes two files: a bad argument or an unwritable target leaves
   neither (nor a temporary). */
struct synth_case {
    const char *args;
    int status;
    const char *expect;
};

static const struct synth_case synth_cases[] = {
    {"--effect quadratic_drag --rows abc --real R --sim S", 2, "--rows: 'abc' is not a whole number"},
    {"--effect warp_drive --real R --sim S", 2, "warp_drive"},
    {"--effect quadratic_drag --real R --sim DIR/missing/s.csv", 4, "cannot create"},
    {"--effect quadratic_drag --real DIR/missing/r.csv --sim S", 4, "cannot create"},
    {"--effect quadratic_drag --real R", 2, "--sim"},
};

START_TEST(synth_leaves_no_partial_pair)
{
    const struct synth_case *c = &synth_cases[_i];
    char cmd[1024], a[512];
    static char out[8192], err[8192];
    const char *s = c->args;
    size_t k = 0;
    int status;
    snprintf(dir, sizeof dir, "/tmp/foldest-hostile-XXXXXX");
    ck_assert_ptr_nonnull(mkdtemp(dir));
    while (*s != '\0' && k + 80 < sizeof a) {
        if (*s == 'R' && (s[1] == ' ' || s[1] == '\0')) {
            k += (size_t)snprintf(a + k, sizeof a - k, "%s/r.csv", dir);
            s++;
        } else if (*s == 'S' && (s[1] == ' ' || s[1] == '\0')) {
            k += (size_t)snprintf(a + k, sizeof a - k, "%s/s.csv", dir);
            s++;
        } else if (strncmp(s, "DIR", 3) == 0) {
            k += (size_t)snprintf(a + k, sizeof a - k, "%s", dir);
            s += 3;
        } else {
            a[k++] = *s++;
        }
    }
    a[k] = '\0';
    snprintf(cmd, sizeof cmd, "synth %s", a);
    status = run(cmd, out, sizeof out, err, sizeof err);
    ck_assert_msg(status == c->status, "synth %s: status %d, want %d\n%s", a, status, c->status, err);
    ck_assert_msg(strstr(err, c->expect) != NULL, "synth %s: stderr lacks \"%s\":\n%s", a,
                  c->expect, err);
    assert_nothing_written(cmd);
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    ck_assert_int_eq(system(cmd), 0);
}
END_TEST

Suite *fe_hostile_suite(void)
{
    Suite *s = suite_create("hostile");
    TCase *t = tcase_create("cli");
    tcase_set_timeout(t, 120);
    tcase_add_loop_test(t, every_command_on_every_hostile_file, 0, NCASES * NCOMMANDS);
    tcase_add_loop_test(t, synth_leaves_no_partial_pair, 0,
                        (int)(sizeof synth_cases / sizeof synth_cases[0]));
    suite_add_tcase(s, t);
    return s;
}
