/* SPDX-License-Identifier: MIT */
/* Hostile input end to end: every foldest command that reads a file, on
   every kind of bad file (empty, header only, truncated, binary, a field
   that is not a number, NaN and Inf text, a wrong field count, a very long
   line, duplicate and missing columns), and on a CRLF file that must work.
   One table: for each case and each command, the exit status documented in
   cli.org, a message naming the file and the problem (FILE:LINE:COLUMN
   where there is a line), nothing on standard output, and no output file
   (--apply, --report, synth's pair) or temporary file left behind.  Then
   what needs no shell: names with shell metacharacters in every path
   argument and in column names, file modes, standard output on a full
   disk, interruption. */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
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
    {"hexadecimal number", "t,mx,my,mz\n", "9.99,1,2,0x1p3\n", GOOD_ROWS, 0, 0, 0, 3,
     "IN:102:10: '0x1p3' in column 'mz' is not a number"},
    {"empty cell", "t,mx,my,mz\n", "9.99,1,2,\n", GOOD_ROWS, 0, 0, 0, 3,
     "IN:102:10: empty cell in column 'mz'"},
    {"truncated gzip", NULL, NULL /* written by write_hostile */, GOOD_ROWS, 0, 0, 0, 3,
     "corrupt or truncated gzip data"},
    {"byte-order mark, semicolons, decimal commas (valid)", "\xEF\xBB\xBFt;mx;my;mz\n", "",
     GOOD_ROWS, 0, 0, 0, 0, NULL},
    {"too many fields", "t,mx,my,mz\n", "9.99,1,2,3,4\n", GOOD_ROWS, 0, 0, 0, 3,
     "IN:102:1: expected 4 fields, found 5"},
    {"too few fields", "t,mx,my,mz\n", "9.99,1,2\n", GOOD_ROWS, 0, 0, 0, 3,
     "IN:102:1: expected 4 fields, found 3"},
    {"very long line", "t,mx,my,mz\n", NULL /* 70000 digits */, GOOD_ROWS, 0, 0, 0, 3,
     "IN:102:1: line longer than 65534 bytes"},
    {"duplicate column", "t,mx,my,mz,mz\n", "", GOOD_ROWS, 0, 1, 1, 2,
     "IN: columns 4 and 5 are both named 'mz'"},
    {"missing column", "t,ax,ay,az\n", "", GOOD_ROWS, 0, 0, 1, 2, "IN: no column 'm"},
    {"CRLF line ends (valid)", "t,mx,my,mz\r\n", "", GOOD_ROWS, 1, 0, 0, 0, NULL},
};
enum { NCASES = sizeof cases / sizeof cases[0] };

static char dir[64];

static void write_rows_as(FILE *f, int rows, int crlf, int extra, double t0, int comma)
{
    fe_rng g = fe_rng_seed(5);
    for (int i = 0; i < rows; i++) {
        double v[3];
        char line[256];
        fe_rng_unit_vector(&g, v);
        snprintf(line, sizeof line, comma ? "%.2f;%.4f;%.4f;%.4f%s%s" : "%.2f,%.4f,%.4f,%.4f%s%s",
                 t0 + 0.01 * i, 20 + 400 * v[0], -10 + 380 * v[1], 5 + 420 * v[2],
                 extra ? (comma ? ";0" : ",0") : "", crlf ? "\r\n" : "\n");
        if (comma)              /* a spreadsheet's decimal commas */
            for (char *c = line; *c != '\0'; c++)
                if (*c == '.')
                    *c = ',';
        fputs(line, f);
    }
}

static void write_rows(FILE *f, int rows, int crlf, int extra, double t0)
{
    write_rows_as(f, rows, crlf, extra, t0, 0);
}

static void write_hostile(const char *path, const struct hostile *h)
{
    FILE *f;
    if (strcmp(h->what, "truncated gzip") == 0) {
        /* A valid recording compressed by gzip(1), cut in the middle. */
        struct hostile good = {"", "t,mx,my,mz\n", "", GOOD_ROWS, 0, 0, 0, 0, NULL};
        char cmd[512];
        write_hostile(path, &good);
        snprintf(cmd, sizeof cmd, "gzip -c '%s' > '%s.gz' && head -c 1500 '%s.gz' > '%s' && rm '%s.gz'",
                 path, path, path, path, path);
        ck_assert_int_eq(system(cmd), 0);
        return;
    }
    f = fopen(path, "wb");
    ck_assert_ptr_nonnull(f);
    if (h->header != NULL)
        fputs(h->header, f);
    write_rows_as(f, h->rows, h->crlf, h->extra, 0.0,
                  h->header != NULL && strchr(h->header, ';') != NULL);
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

/* ---------------------------------------------------------------- no shell,
   file modes, standard output, interruption.  These run foldest without a
   shell (fork and exec), so that a hostile name reaches it unchanged. */

/* What the next child gets besides: its standard input from this file,
   TMPDIR set to this folder (NULL: unchanged). */
static const char *child_stdin, *child_tmpdir;

/* Start foldest with `args` (NULL-terminated, without argv[0]) in the
   directory `cwd`, under `mask`, its stdout to `out` (NULL: /dev/null) and
   stderr to cwd/stderr.txt.  The child's pid. */
static pid_t start(const char *cwd, mode_t mask, const char *out, const char *const *args)
{
    char *argv[32];
    size_t n = 0;
    pid_t pid;
    argv[n++] = (char *)FE_TEST_CLI;
    while (args[n - 1] != NULL && n < 31) {
        argv[n] = (char *)args[n - 1];
        n++;
    }
    argv[n] = NULL;
    fflush(NULL);
    pid = fork();
    ck_assert_int_ge(pid, 0);
    if (pid == 0) {
        int fd;
        if (chdir(cwd) != 0)
            _exit(120);
        umask(mask);
        fd = open(out != NULL ? out : "/dev/null", O_WRONLY);
        if (fd < 0 || dup2(fd, 1) < 0)
            _exit(121);
        fd = open("stderr.txt", O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd < 0 || dup2(fd, 2) < 0)
            _exit(122);
        if (child_stdin != NULL && ((fd = open(child_stdin, O_RDONLY)) < 0 || dup2(fd, 0) < 0))
            _exit(124);
        if (child_tmpdir != NULL && setenv("TMPDIR", child_tmpdir, 1) != 0)
            _exit(125);
        execv(argv[0], argv);
        _exit(123);
    }
    return pid;
}

/* Wait for the child; its exit status, or 1000 + the signal that killed it. */
static int finish(pid_t pid)
{
    int status;
    ck_assert_int_eq(waitpid(pid, &status, 0), pid);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 1000 + WTERMSIG(status);
}

static int run_argv(const char *cwd, mode_t mask, const char *out, const char *const *args)
{
    return finish(start(cwd, mask, out, args));
}

static int exists(const char *dirpath, const char *name)
{
    char path[4096];
    struct stat st;
    ck_assert_msg((size_t)snprintf(path, sizeof path, "%s/%s", dirpath, name) < sizeof path,
                  "path too long: %s/%s", dirpath, name);
    return stat(path, &st) == 0;
}

static mode_t mode_of(const char *dirpath, const char *name)
{
    char path[2048];
    struct stat st;
    snprintf(path, sizeof path, "%s/%s", dirpath, name);
    ck_assert_msg(stat(path, &st) == 0, "no %s", path);
    return st.st_mode & 07777;
}

/* Does any name in `d` contain `part`? */
static int any_named(const char *d, const char *part)
{
    DIR *dd = opendir(d);
    struct dirent *e;
    int found = 0;
    if (dd == NULL)
        return 0;
    while ((e = readdir(dd)) != NULL)
        found |= strstr(e->d_name, part) != NULL;
    closedir(dd);
    return found;
}

static void read_stderr(const char *d, char *buf, size_t len)
{
    char path[256];
    snprintf(path, sizeof path, "%s/stderr.txt", d);
    fe_test_read_file(path, buf, len);
}

/* A valid recording d/good.csv: a header and GOOD_ROWS samples. */
static void write_good(const char *d)
{
    char path[128];
    FILE *f;
    snprintf(path, sizeof path, "%s/good.csv", d);
    f = fopen(path, "w");
    ck_assert_ptr_nonnull(f);
    fputs("t,mx,my,mz\n", f);
    write_rows(f, GOOD_ROWS, 0, 0, 0.0);
    fclose(f);
}

/* A synthetic pair r.csv, s.csv of `rows` rows in `d`. */
static void make_pair(const char *d, const char *rows)
{
    const char *args[] = {"synth", "--effect", "quadratic_drag", "--rows", rows,
                          "--real", "r.csv", "--sim", "s.csv", NULL};
    ck_assert_int_eq(run_argv(d, 022, NULL, args), 0);
}

static void remove_tree(const char *d)
{
    char cmd[256];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", d);
    ck_assert_int_eq(system(cmd), 0);
}

#define DISCOVER_ARGS(report)                                                             \
    {"discover", "--real", "r.csv", "--sim", "s.csv", "--channel", "acceleration", "--time", \
     "time", "--role", "position=position", "--role", "velocity=velocity", "--role",         \
     "input=input", "--base", "bias,gain", "--holdout", "0.3", "--report", report, NULL}

/* A report folder named with shell and gnuplot metacharacters is a folder:
   the report and its plots are written there and nothing is run (before,
   gnuplot started through sh ran `touch PWNED` in the working directory). */
static const char *const hostile_folders[] = {"x';touch PWNED;'", "bob's run",
                                              "x'\n!touch PWNED\n'", "$(touch PWNED)"};

START_TEST(report_folder_names_run_nothing)
{
    char d[64], rep[1200], err[4096];
    const char *args[] = DISCOVER_ARGS(hostile_folders[_i]);
    int status;
    snprintf(d, sizeof d, "/tmp/foldest-shell-XXXXXX");
    ck_assert_ptr_nonnull(mkdtemp(d));
    make_pair(d, "3000");
    status = run_argv(d, 022, NULL, args);
    read_stderr(d, err, sizeof err);
    ck_assert_msg(status == 0, "--report '%s': status %d\n%s", hostile_folders[_i], status, err);
    snprintf(rep, sizeof rep, "%s/%s", d, hostile_folders[_i]);
    ck_assert_msg(!exists(d, "PWNED") && !exists(rep, "PWNED"),
                  "--report '%s' ran a command", hostile_folders[_i]);
    ck_assert_msg(exists(rep, "report.md"), "no report.md in '%s'", rep);
    ck_assert_msg(exists(rep, "residual_time.png"), "no plot in '%s'\n%s", rep, err);
    remove_tree(d);
}
END_TEST

/* ---------------------------------------------------------------- every path argument
   Names with the metacharacters of the shell (quotes, ';', '$(...)',
   backquotes, '&', '|', spaces, a newline, globs, '!', '\') and of printf
   ('%s%n'), each a folder and inside the file names in it, in every path
   argument of every command: stats FILE; calibrate FILE --apply OUT;
   discover --sphere FILE; discover --real --sim --report; synth --real
   --sim; and the folder as TMPDIR for discover's copy of standard input.
   Every command works, or fails cleanly with the path in its message as it
   was given, and nothing is run: no file PWNED appears in the working
   directory, the folder, the report folder, the test's directory or /tmp.
   synth's suggested command, pasted into sh, analyses the pair. */
static const char *const hostile_names[] = {
    "x';touch PWNED;'", "a\"b;touch PWNED;\"c", "$(touch PWNED)", "`touch PWNED`",
    "bob's run & touch PWNED &", "a | touch PWNED", "x\ntouch PWNED\n",
    "* ?[a] ~ $HOME !! \\", "100% %s%n%x",
};

static int pwned_before[2];     /* PWNED was already in /tmp, in the test's directory */

static void assert_nothing_ran(const char *d, const char *h, const char *step)
{
    char sub[1024], rep[2048], cwd[1024];
    snprintf(sub, sizeof sub, "%s/%s", d, h);
    snprintf(rep, sizeof rep, "%s/%s rep", sub, h);
    ck_assert_ptr_nonnull(getcwd(cwd, sizeof cwd));
    ck_assert_msg(!exists(d, "PWNED") && !exists(sub, "PWNED") && !exists(rep, "PWNED")
                  && (pwned_before[0] || !exists("/tmp", "PWNED"))
                  && (pwned_before[1] || !exists(cwd, "PWNED")),
                  "%s, names '%s': a command was run", step, h);
}

/* foldest `args` in d: the status `want`, `expect` (if any) in its
   stderr (copied to err), nothing run. */
static void path_step(const char *d, const char *h, const char *const *args, int want,
                      const char *expect, char *err, size_t errlen)
{
    int status = run_argv(d, 022, NULL, args);
    read_stderr(d, err, errlen);
    ck_assert_msg(status == want, "foldest %s %s (names '%s'): status %d, want %d\n%s", args[0],
                  args[1], h, status, want, err);
    ck_assert_msg(expect == NULL || strstr(err, expect) != NULL,
                  "foldest %s (names '%s'): stderr lacks \"%s\":\n%s", args[0], h, expect, err);
    assert_nothing_ran(d, h, args[0]);
}

/* gnuplot plots.gp in the folder `where`, without a shell; its status. */
static int gnuplot_in(const char *where)
{
    pid_t pid;
    fflush(NULL);
    pid = fork();
    ck_assert_int_ge(pid, 0);
    if (pid == 0) {
        int fd = open("/dev/null", O_WRONLY);
        if (chdir(where) != 0 || fd < 0 || dup2(fd, 1) < 0)
            _exit(120);
        execlp("gnuplot", "gnuplot", "plots.gp", (char *)NULL);
        _exit(127);
    }
    return finish(pid);
}

START_TEST(every_path_argument_takes_any_name)
{
    const char *h = hostile_names[_i];
    char d[64], sub[1024], r[1024], s[1024], m[1024], cal[1024], rep[1024], missing[1024],
         nocal[1024], norep[1024], nor[1024], where[2048], cmd[8192];
    static char err[16384];
    int status;
    snprintf(d, sizeof d, "/tmp/foldest-paths-XXXXXX");
    ck_assert_ptr_nonnull(mkdtemp(d));
    ck_assert_ptr_nonnull(getcwd(cmd, sizeof cmd));
    pwned_before[0] = exists("/tmp", "PWNED");
    pwned_before[1] = exists(cmd, "PWNED");
    snprintf(sub, sizeof sub, "%s/%s", d, h);
    ck_assert_int_eq(mkdir(sub, 0755), 0);
    snprintf(r, sizeof r, "%s/%s r.csv", h, h);
    snprintf(s, sizeof s, "%s/%s s.csv", h, h);
    snprintf(m, sizeof m, "%s/%s m.csv", h, h);
    snprintf(cal, sizeof cal, "%s/%s cal.csv", h, h);
    snprintf(rep, sizeof rep, "%s/%s rep", h, h);
    snprintf(missing, sizeof missing, "%s/%s missing.csv", h, h);
    snprintf(nocal, sizeof nocal, "%s/no such folder/%s cal.csv", h, h);
    snprintf(norep, sizeof norep, "%s/no such folder/%s rep", h, h);
    snprintf(nor, sizeof nor, "%s/no such folder/%s r.csv", h, h);

    /* synth writes the pair; its suggestion, pasted into sh, runs discover. */
    {
        const char *args[] = {"synth", "--effect", "quadratic_drag", "--rows", "3000",
                              "--real", r, "--sim", s, NULL};
        const char *from, *to;
        path_step(d, h, args, 0, "analyse with:", err, sizeof err);
        ck_assert_msg(exists(d, r) && exists(d, s), "synth: no pair in '%s'", sub);
        from = strstr(err, "  foldest discover ");
        to = from != NULL ? strstr(from, " --holdout 0.3\n") : NULL;
        ck_assert_msg(to != NULL, "synth's suggestion:\n%s", err);
        from += strlen("  foldest");
        snprintf(cmd, sizeof cmd, "cd %s && %s%.*s --holdout 0.3 --json > /dev/null 2>&1", d,
                 FE_TEST_CLI, (int)(to - from), from);
        status = system(cmd);
        assert_nothing_ran(d, h, "synth's suggestion in sh");
        ck_assert_msg(status == 0, "synth's suggestion failed in sh:\n%s", cmd);
    }
    {
        const char *args[] = {"stats", r, NULL};
        path_step(d, h, args, 0, NULL, err, sizeof err);
    }
    {
        FILE *f;
        snprintf(where, sizeof where, "%s/%s", d, m);
        f = fopen(where, "w");
        ck_assert_ptr_nonnull(f);
        fputs("t,mx,my,mz\n", f);
        write_rows(f, GOOD_ROWS, 0, 0, 0.0);
        fclose(f);
    }
    {
        const char *args[] = {"calibrate", "--columns", "mx,my,mz", "--apply", cal, m, NULL};
        path_step(d, h, args, 0, NULL, err, sizeof err);
        ck_assert_msg(exists(d, cal), "calibrate --apply: no '%s'", cal);
    }
    {
        const char *args[] = {"discover", "--sphere", m, "--columns", "mx,my,mz", "--json", NULL};
        path_step(d, h, args, 0, NULL, err, sizeof err);
    }
    {
        const char *args[] = {"discover", "--real", r, "--sim", s, "--channel", "acceleration",
                              "--role", "velocity=velocity", "--base", "bias,gain",
                              "--report", rep, "--json", NULL};
        path_step(d, h, args, 0, NULL, err, sizeof err);
        snprintf(where, sizeof where, "%s/%s", d, rep);
        ck_assert_msg(exists(where, "report.md") && exists(where, "plots.gp"),
                      "no report in '%s'", where);
        /* The script, run where it was written, runs nothing either. */
        if (exists(where, "residual_time.png")) {
            ck_assert_int_eq(gnuplot_in(where), 0);
            assert_nothing_ran(d, h, "gnuplot plots.gp in the report folder");
        } else {
            fprintf(stderr, "SKIP gnuplot in a hostile folder: gnuplot is not installed\n");
        }
    }
    /* Standard input, copied into a TMPDIR of that name and gone after. */
    {
        const char *args[] = {"discover", "--real", "-", "--sim", s, "--channel", "acceleration",
                              "--role", "velocity=velocity", "--json", NULL};
        snprintf(where, sizeof where, "%s/%s", d, r);
        child_stdin = where;
        child_tmpdir = sub;
        path_step(d, h, args, 0, NULL, err, sizeof err);
        child_stdin = child_tmpdir = NULL;
        ck_assert_msg(!any_named(sub, "foldest-spool"), "a spool file left in '%s'", sub);
    }
    /* Failures name the path as given. */
    {
        const char *args[] = {"stats", missing, NULL};
        snprintf(where, sizeof where, "%s: cannot open", missing);
        path_step(d, h, args, 4, where, err, sizeof err);
    }
    {
        const char *args[] = {"calibrate", "--columns", "mx,my,mz", "--apply", nocal, m, NULL};
        snprintf(where, sizeof where, "%s: cannot create", nocal);
        path_step(d, h, args, 4, where, err, sizeof err);
    }
    {
        const char *args[] = {"synth", "--effect", "bias", "--rows", "100", "--real", nor,
                              "--sim", s, NULL};
        snprintf(where, sizeof where, "%s: cannot create", nor);
        path_step(d, h, args, 4, where, err, sizeof err);
    }
    {
        const char *args[] = {"discover", "--real", r, "--sim", s, "--channel", "acceleration",
                              "--report", norep, NULL};
        snprintf(where, sizeof where, "%s: cannot create", norep);
        path_step(d, h, args, 4, where, err, sizeof err);
    }
    remove_tree(d);
}
END_TEST

/* Column names reach the plot script as gnuplot strings: backquotes, '@'
   macros, quotes that would close the string and call system(), in the
   time, channel and state columns; the report is drawn, the labels say
   the names, and nothing runs, also when the script is run again. */
START_TEST(column_names_in_the_plot_script_run_nothing)
{
    static const char *const time = "t`touch PWNED`";
    static const char *const channel =
        "`touch PWNED` @ARG0 $(touch PWNED)' . system('touch PWNED') . 'x_m";
    static const char *const vel = "v' . system('touch PWNED') . '";
    static char text[1 << 20];
    char d[64], path[256], role[256];
    const char *args[] = {"discover", "--real", "r.csv", "--sim", "s.csv", "--channel", channel,
                          "--time", time, "--role", role, "--base", "bias", "--report", "rep",
                          NULL};
    snprintf(d, sizeof d, "/tmp/foldest-columns-XXXXXX");
    ck_assert_ptr_nonnull(mkdtemp(d));
    make_pair(d, "3000");
    for (int k = 0; k < 2; k++) {               /* rename the columns */
        FILE *f;
        char *nl;
        snprintf(path, sizeof path, "%s/%s", d, k ? "s.csv" : "r.csv");
        fe_test_read_file(path, text, sizeof text);
        nl = strchr(text, '\n');
        ck_assert_ptr_nonnull(nl);
        f = fopen(path, "w");
        ck_assert_ptr_nonnull(f);
        if (k)
            fprintf(f, "%s,%s,position,%s,input%s", time, channel, vel, nl);
        else
            fprintf(f, "%s,%s%s", time, channel, nl);
        fclose(f);
    }
    snprintf(role, sizeof role, "%s=velocity", vel);
    {
        char err[4096];
        int status = run_argv(d, 022, NULL, args);
        read_stderr(d, err, sizeof err);
        ck_assert_msg(status == 0, "status %d\n%s", status, err);
    }
    snprintf(path, sizeof path, "%s/rep", d);
    ck_assert_msg(!exists(d, "PWNED") && !exists(path, "PWNED"),
                  "a column name ran a command when foldest drew the plots");
    snprintf(path, sizeof path, "%s/rep/plots.gp", d);
    fe_test_read_file(path, text, sizeof text);
    ck_assert_msg(strstr(text, "set xlabel 't`touch PWNED`'\n") != NULL, "%s", text);
    ck_assert_msg(strstr(text, "set xlabel 'v'' . system(''touch PWNED'') . '''\n") != NULL,
                  "%s", text);
    ck_assert_msg(strstr(text, "(recording \xe2\x88\x92 model) [m]'\n") != NULL, "%s", text);
    snprintf(path, sizeof path, "%s/rep", d);
    if (exists(path, "residual_time.png"))
        ck_assert_int_eq(gnuplot_in(path), 0);
    else
        fprintf(stderr, "SKIP gnuplot on hostile column names: gnuplot is not installed\n");
    ck_assert_msg(!exists(d, "PWNED") && !exists(path, "PWNED"),
                  "a column name ran a command when the script ran again");
    remove_tree(d);
}
END_TEST

/* Output files have the mode the umask gives (not mkstemp's 0600). */
START_TEST(outputs_take_the_umask_mode)
{
    static const mode_t masks[] = {022, 027};
    char d[64];
    mode_t mask = masks[_i], want = 0666 & ~mask;
    const char *apply[] = {"calibrate", "--columns", "mx,my,mz", "--apply", "cal.csv",
                           "good.csv", NULL};
    const char *report[] = DISCOVER_ARGS("rep");
    snprintf(d, sizeof d, "/tmp/foldest-mode-XXXXXX");
    ck_assert_ptr_nonnull(mkdtemp(d));
    write_good(d);
    {
        const char *args[] = {"synth", "--effect", "quadratic_drag", "--rows", "2000",
                              "--real", "r.csv", "--sim", "s.csv", NULL};
        ck_assert_int_eq(run_argv(d, mask, NULL, args), 0);
    }
    ck_assert_int_eq(run_argv(d, mask, NULL, apply), 0);
    ck_assert_int_eq(run_argv(d, mask, NULL, report), 0);
    ck_assert_int_eq(mode_of(d, "r.csv"), want);
    ck_assert_int_eq(mode_of(d, "s.csv"), want);
    ck_assert_int_eq(mode_of(d, "cal.csv"), want);
    ck_assert_int_eq(mode_of(d, "rep/report.md"), want);
    remove_tree(d);
}
END_TEST

/* A failed write to standard output (a full disk) is an error: a message
   and status 4, not 0. */
static const char *const full_commands[][8] = {
    {"stats", "--json", "good.csv", NULL},
    {"stats", "good.csv", NULL},
    {"calibrate", "--columns", "mx,my,mz", "--json", "good.csv", NULL},
    {"calibrate", "--columns", "mx,my,mz", "good.csv", NULL},
    {"--version", NULL},
};

START_TEST(full_standard_output_is_an_error)
{
    char d[64], err[4096];
    int status;
    snprintf(d, sizeof d, "/tmp/foldest-full-XXXXXX");
    ck_assert_ptr_nonnull(mkdtemp(d));
    write_good(d);
    status = run_argv(d, 022, "/dev/full", full_commands[_i]);
    read_stderr(d, err, sizeof err);
    ck_assert_msg(status == 4, "foldest %s > /dev/full: status %d\n%s", full_commands[_i][0],
                  status, err);
    ck_assert_msg(strstr(err, "cannot write standard output: No space left on device") != NULL,
                  "foldest %s > /dev/full: stderr:\n%s", full_commands[_i][0], err);
    /* The same command to /dev/null succeeds: the failure is the output's. */
    ck_assert_int_eq(run_argv(d, 022, NULL, full_commands[_i]), 0);
    remove_tree(d);
}
END_TEST

/* SIGTERM while the command writes: it dies of the signal and leaves no
   partial output and no temporary file.  The test waits until the output
   is being written (a temporary file, or the report's first data file, is
   there), then sends the signal; the remaining work takes far longer than
   that (two million rows of synth, about 3 s; 300 000 rows through
   calibrate --apply or discover --report, 0.2 to 0.6 s). */
static void wait_for(const char *d, const char *part, pid_t pid)
{
    struct timespec nap = {0, 200000};
    for (int i = 0; i < 100000 && !any_named(d, part); i++) {
        int status;
        ck_assert_msg(waitpid(pid, &status, WNOHANG) == 0, "the command ended before writing");
        nanosleep(&nap, NULL);
    }
    ck_assert_msg(any_named(d, part), "no '%s' appeared", part);
}

START_TEST(interrupted_commands_leave_nothing)
{
    char d[64], sub[128];
    pid_t pid;
    int status;
    snprintf(d, sizeof d, "/tmp/foldest-signal-XXXXXX");
    ck_assert_ptr_nonnull(mkdtemp(d));
    snprintf(sub, sizeof sub, "%s/out", d);
    ck_assert_int_eq(mkdir(sub, 0755), 0);
    if (_i == 0) {              /* synth: the pair */
        const char *args[] = {"synth", "--effect", "quadratic_drag", "--rows", "2000000",
                              "--real", "out/r.csv", "--sim", "out/s.csv", NULL};
        pid = start(d, 022, NULL, args);
        wait_for(sub, ".tmp.", pid);
    } else if (_i == 1) {       /* calibrate --apply */
        char path[128];
        FILE *f;
        const char *args[] = {"calibrate", "--columns", "mx,my,mz", "--apply", "out/cal.csv",
                              "big.csv", NULL};
        snprintf(path, sizeof path, "%s/big.csv", d);
        f = fopen(path, "w");
        ck_assert_ptr_nonnull(f);
        fputs("t,mx,my,mz\n", f);
        write_rows(f, 300000, 0, 0, 0.0);
        fclose(f);
        pid = start(d, 022, NULL, args);
        wait_for(sub, ".tmp.", pid);
    } else {                    /* discover --report */
        const char *args[] = DISCOVER_ARGS("out/rep");
        make_pair(d, "300000");
        pid = start(d, 022, NULL, args);
        wait_for(sub, "rep", pid);
        snprintf(sub, sizeof sub, "%s/out/rep", d);
        wait_for(sub, "residuals.dat", pid);
        snprintf(sub, sizeof sub, "%s/out", d);
    }
    ck_assert_int_eq(kill(pid, SIGTERM), 0);
    status = finish(pid);
    ck_assert_msg(status == 1000 + SIGTERM, "case %d: status %d, not killed by SIGTERM", _i,
                  status);
    {
        DIR *dd = opendir(sub);
        struct dirent *e;
        ck_assert_ptr_nonnull(dd);
        while ((e = readdir(dd)) != NULL)
            ck_assert_msg(strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0,
                          "case %d: '%s' left behind after SIGTERM", _i, e->d_name);
        closedir(dd);
    }
    remove_tree(d);
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
    tcase_add_loop_test(t, report_folder_names_run_nothing, 0,
                        (int)(sizeof hostile_folders / sizeof hostile_folders[0]));
    tcase_add_loop_test(t, every_path_argument_takes_any_name, 0,
                        (int)(sizeof hostile_names / sizeof hostile_names[0]));
    tcase_add_test(t, column_names_in_the_plot_script_run_nothing);
    tcase_add_loop_test(t, outputs_take_the_umask_mode, 0, 2);
    tcase_add_loop_test(t, full_standard_output_is_an_error, 0,
                        (int)(sizeof full_commands / sizeof full_commands[0]));
    tcase_add_loop_test(t, interrupted_commands_leave_nothing, 0, 3);
    suite_add_tcase(s, t);
    return s;
}
