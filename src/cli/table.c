/* SPDX-License-Identifier: MIT */
/* Tangled from literate/cli.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/cli.org::Table Includes][Table Includes]] */
#include "cli.h"

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#include <spawn.h>
#include <strings.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <getopt.h>
#include <pthread.h>
#include <zlib.h>

extern char **environ;          /* for posix_spawnp: POSIX, undeclared */

/* The reader's options (fe_cli_reader_configure) and the rows skipped in
   the current pass of every table, by reason. */
static int fe__cli_force_comma, fe__cli_skip_bad, fe__cli_stdin_used;
static size_t fe__cli_bad_total[FE_CLI_BAD_REASONS];

void fe_cli_reader_configure(int decimal_comma, int skip_bad_rows)
{
    fe__cli_force_comma = decimal_comma;
    fe__cli_skip_bad = skip_bad_rows;
    fe__cli_stdin_used = 0;
    memset(fe__cli_bad_total, 0, sizeof fe__cli_bad_total);
}

void fe_cli_reader_option(const char *flag)
{
    if (strcmp(flag, "--decimal-comma") == 0)
        fe__cli_force_comma = 1;
    else if (strcmp(flag, "--skip-bad-rows") == 0)
        fe__cli_skip_bad = 1;
}

void fe_cli_bad_rows(size_t counts[FE_CLI_BAD_REASONS])
{
    memcpy(counts, fe__cli_bad_total, sizeof fe__cli_bad_total);
}

void fe_cli_json_bad_rows(FILE *out)
{
    size_t *b = fe__cli_bad_total;
    fprintf(out, "{\"total\": %zu, \"empty_cell\": %zu, \"not_finite\": %zu, "
                 "\"not_a_number\": %zu, \"field_count\": %zu}",
            b[0] + b[1] + b[2] + b[3], b[FE_CLI_BAD_EMPTY], b[FE_CLI_BAD_NONFINITE],
            b[FE_CLI_BAD_TEXT], b[FE_CLI_BAD_FIELDS]);
}
/* Table Includes ends here */
/* [[file:../../literate/cli.org::Format a located message][Format a located message]] */
static int fe__cli_at(const fe_cli_table *t, size_t line, size_t column,
                      int status, char *err, size_t errlen,
                      const char *fmt, ...)
{
    va_list ap;
    int n = snprintf(err, errlen, "%s:%zu:%zu: ", t->name, line, column);
    if (n >= 0 && (size_t)n < errlen) {
        va_start(ap, fmt);
        vsnprintf(err + n, errlen - (size_t)n, fmt, ap);
        va_end(ap);
    }
    return status;
}

/* The message for a line the reader refused. */
static int fe__cli_line_error(const fe_cli_table *t, int rc, char *err,
                              size_t errlen)
{
    switch (rc) {
    case FE_ESIZE:
        return fe__cli_at(t, t->reader.line, 1, FE_CLI_INPUT, err, errlen,
                          "line longer than %d bytes", FE_CLI_LINE_MAX - 2);
    case FE_EPARSE:
        return fe__cli_at(t, t->reader.line, 1, FE_CLI_INPUT, err, errlen,
                          "NUL byte: this is not a text file");
    default:
        if (t->gz != NULL) {
            int zerr = Z_OK;
            const char *msg = gzerror((gzFile)t->gz, &zerr), *colon = strstr(msg, ": ");
            if (colon != NULL)          /* zlib's "<fd:N>: " prefix */
                msg = colon + 2;
            if (zerr != Z_OK && zerr != Z_ERRNO)
                return fe__cli_at(t, t->reader.line, 1, FE_CLI_INPUT, err, errlen,
                                  "corrupt or truncated gzip data (%s)", msg);
        }
        return fe__cli_at(t, t->reader.line, 1, FE_CLI_IO, err, errlen,
                          "read error: %s", strerror(errno));
    }
}

static int fe__cli_ignorable(const char *line)
{
    while (*line == ' ' || *line == '\t')
        line++;
    return *line == '\0' || *line == '#';
}

/* A field as a number, by the table's convention: with a decimal comma
   forced, only "1,5"; in a semicolon table "1,5" or "1.5". */
static int fe__cli_number(const fe_cli_table *t, const fe_csv_field *f, double *v)
{
    int rc;
    if (t->decimal_comma == 1)
        return fe_csv_number_comma(f, v);
    rc = fe_csv_number(f, v);
    if (rc == FE_EPARSE && t->decimal_comma == 2 && strchr(f->text, ',') != NULL)
        rc = fe_csv_number_comma(f, v);
    return rc;
}

static int fe__cli_numeric(const fe_cli_table *t, const fe_csv_field *f)
{
    double v;
    int rc = fe__cli_number(t, f, &v);
    return rc == FE_OK || rc == FE_ENONFINITE;
}

/* Read through zlib (transparent for bytes that are not gzip). */
static long fe__cli_gz_read(void *ctx, char *buf, size_t n)
{
    int got = gzread((gzFile)ctx, buf, (unsigned)(n > (1u << 30) ? (1u << 30) : n));
    if (got < 0) {
        int zerr;
        gzerror((gzFile)ctx, &zerr);
        if (zerr != Z_ERRNO)
            errno = EIO;        /* the message comes from gzerror */
        return -1;
    }
    if (got == 0) {
        /* zlib ends a truncated stream as if it were complete (it reads
           files still being written) and keeps Z_BUF_ERROR for gzerror. */
        int zerr;
        gzerror((gzFile)ctx, &zerr);
        if (zerr == Z_BUF_ERROR) {
            errno = EIO;
            return -1;
        }
    }
    return got;
}

/* Attach the zlib stream over a duplicate of t->fd and start the reader. */
static int fe__cli_attach(fe_cli_table *t)
{
    int fd = dup(t->fd);
    gzFile gz = fd >= 0 ? gzdopen(fd, "rb") : NULL;
    if (gz == NULL) {
        if (fd >= 0)
            close(fd);
        return -1;
    }
    gzbuffer(gz, 1u << 16);
    t->gz = gz;
    return fe_csv_reader_init_read(&t->reader, fe__cli_gz_read, gz, t->buffer,
                                   FE_CLI_LINE_MAX) == FE_OK ? 0 : -1;
}

/* Copy a non-seekable input once to an unlinked temporary file; the
   descriptor of the copy, positioned at its start, or -1. */
static int fe__cli_spool(int in)
{
    const char *dir = getenv("TMPDIR");
    char path[4096], buf[1 << 16];
    int fd;
    if (dir == NULL || *dir == '\0')
        dir = "/tmp";
    if ((size_t)snprintf(path, sizeof path, "%s/foldest-spool-XXXXXX", dir) >= sizeof path)
        return -1;
    fe_cli_signals_hold(1);
    fd = mkstemp(path);
    if (fd >= 0)
        unlink(path);           /* gone from the directory: nothing left behind */
    fe_cli_signals_hold(0);
    if (fd < 0)
        return -1;
    for (;;) {
        ssize_t got = read(in, buf, sizeof buf), put = 0;
        if (got < 0 && errno == EINTR)
            continue;
        if (got < 0)
            break;
        if (got == 0)
            return lseek(fd, 0, SEEK_SET) == 0 ? fd : (close(fd), -1);
        while (put < got) {
            ssize_t w = write(fd, buf + put, (size_t)(got - put));
            if (w < 0 && errno == EINTR)
                continue;
            if (w <= 0) {
                close(fd);
                return -1;
            }
            put += w;
        }
    }
    close(fd);
    return -1;
}

static char *fe__cli_strdup(const char *s)
{
    size_t n = strlen(s) + 1;
    char *p = malloc(n);
    if (p != NULL)
        memcpy(p, s, n);
    return p;
}
/* Format a located message ends here */
/* [[file:../../literate/cli.org::Open a table and find its header][Open a table and find its header]] */
static void fe__cli_free_lines(char **lines, size_t n)
{
    for (size_t i = 0; i < n; i++)
        free(lines[i]);
}

static int fe__cli_table_open(fe_cli_table *t, const char *path, long skip,
                              int rewindable, char *err, size_t errlen)
{
    char *look[FE_CLI_LOOKAHEAD];
    size_t look_line[FE_CLI_LOOKAHEAD], look_fields[FE_CLI_LOOKAHEAD];
    size_t nlook = 0, start, header = (size_t)-1, first_data;
    struct stat st;
    char *line;
    size_t len;
    int rc;

    memset(t, 0, sizeof *t);
    if (strcmp(path, "-") == 0 && fe__cli_stdin_used++) {
        snprintf(err, errlen, "-: standard input can be read only once: give files for the other inputs");
        t->fd = -1;
        return FE_CLI_USAGE;
    }
    t->name = strcmp(path, "-") == 0 ? "<stdin>" : path;
    t->fd = strcmp(path, "-") == 0 ? 0 : open(path, O_RDONLY);
    if (t->fd < 0) {
        snprintf(err, errlen, "%s: cannot open: %s", path, strerror(errno));
        return FE_CLI_IO;
    }
    if (fstat(t->fd, &st) == 0 && S_ISREG(st.st_mode))
        t->size = st.st_size;
    else if (rewindable) {
        int copy = fe__cli_spool(t->fd);
        if (copy < 0) {
            snprintf(err, errlen, "%s: cannot copy the input to a temporary file: %s",
                     t->name, strerror(errno));
            fe_cli_table_close(t);
            return FE_CLI_IO;
        }
        if (t->fd > 0)
            close(t->fd);
        t->fd = copy;
    }
    t->buffer = malloc(FE_CLI_LINE_MAX);
    t->scratch = malloc(FE_CLI_LINE_MAX);
    t->fields = malloc(FE_CLI_FIELDS_MAX * sizeof *t->fields);
    if (t->buffer == NULL || t->scratch == NULL || t->fields == NULL
        || fe__cli_attach(t) != 0) {
        snprintf(err, errlen, "%s: out of memory", t->name);
        fe_cli_table_close(t);
        return FE_CLI_IO;
    }

    /* Skip what the user said to skip. */
    for (long i = 0; skip > 0 && i < skip; i++) {
        rc = fe_csv_next_line(&t->reader, &line, &len);
        if (rc == FE_END)
            break;
        if (rc != FE_OK && rc != FE_ESIZE) {
            rc = fe__cli_line_error(t, rc, err, errlen);
            fe_cli_table_close(t);
            return rc;
        }
    }
    /* Look ahead. */
    while (nlook < (skip >= 0 ? 2 : FE_CLI_LOOKAHEAD)) {
        size_t nf;
        rc = fe_csv_next_line(&t->reader, &line, &len);
        if (rc == FE_END)
            break;
        if (rc != FE_OK) {
            rc = fe__cli_line_error(t, rc, err, errlen);
            fe__cli_free_lines(look, nlook);
            fe_cli_table_close(t);
            return rc;
        }
        if (fe__cli_ignorable(line))
            continue;
        if (nlook == 0) {
            t->delimiter = fe_csv_guess_delimiter(line);
            if (fe__cli_force_comma && t->delimiter == ',')
                t->delimiter = strchr(line, '\t') != NULL ? '\t' : FE_CSV_WHITESPACE;
            t->decimal_comma = fe__cli_force_comma ? 1 : t->delimiter == ';' ? 2 : 0;
        }
        look[nlook] = fe__cli_strdup(line);
        look_line[nlook] = t->reader.line;
        if (look[nlook] == NULL
            || fe_csv_split(line, t->delimiter, t->fields, FE_CLI_FIELDS_MAX,
                            &nf, NULL) == FE_ESIZE) {
            nf = FE_CLI_FIELDS_MAX + 1;
        }
        look_fields[nlook++] = nf;
    }
    t->look_end = t->reader.line;
    if (nlook == 0) {
        snprintf(err, errlen, "%s: no data: the file is empty", t->name);
        fe_cli_table_close(t);
        return FE_CLI_INPUT;
    }
    /* The data block: the longest run of lines with one field count, the
       later of equal runs (with --skip, everything after the skipped
       lines).  Lines after it are data too, and will be checked. */
    start = 0;
    if (skip < 0) {
        size_t best = 0;
        for (size_t i = 0, j; i < nlook; i = j) {
            for (j = i + 1; j < nlook && look_fields[j] == look_fields[i]; j++)
                ;
            if (j - i >= best) {
                best = j - i;
                start = i;
            }
        }
    }
    t->ncols = look_fields[skip < 0 ? start : nlook - 1];
    if (t->ncols > FE_CLI_FIELDS_MAX) {
        fe__cli_free_lines(look, nlook);
        rc = fe__cli_at(t, look_line[nlook - 1], 1, FE_CLI_INPUT, err, errlen,
                        "more than %d fields", FE_CLI_FIELDS_MAX);
        fe_cli_table_close(t);
        return rc;
    }
    /* Is the block's first line a header?  It is when one of its fields is
       not a number where the next line has a number (or it is alone). */
    {
        fe_csv_field *a = t->fields;
        fe_csv_field *b = malloc(FE_CLI_FIELDS_MAX * sizeof *b);
        char *copy0 = fe__cli_strdup(look[start]);
        char *copy1 = start + 1 < nlook ? fe__cli_strdup(look[start + 1]) : NULL;
        size_t na = 0, nb = 0;
        int is_header = 0;
        if (copy0 != NULL)
            fe_csv_split(copy0, t->delimiter, a, FE_CLI_FIELDS_MAX, &na, NULL);
        if (copy1 != NULL && b != NULL)
            fe_csv_split(copy1, t->delimiter, b, FE_CLI_FIELDS_MAX, &nb, NULL);
        for (size_t j = 0; j < na && !is_header; j++)
            if (!fe__cli_numeric(t, &a[j])
                && (start + 1 == nlook || (j < nb && fe__cli_numeric(t, &b[j]))))
                is_header = 1;
        if (is_header)
            header = start;
        t->names = calloc(t->ncols ? t->ncols : 1, sizeof *t->names);
        for (size_t j = 0; t->names != NULL && j < t->ncols; j++) {
            char number[32];
            snprintf(number, sizeof number, "%zu", j + 1);
            t->names[j] = fe__cli_strdup(is_header && j < na ? a[j].text : number);
        }
        free(copy0);
        free(copy1);
        free(b);
        t->has_header = is_header;
    }
    first_data = header == (size_t)-1 ? start : header + 1;
    /* Keep the looked-ahead data lines to replay them. */
    t->npending = nlook - first_data;
    t->pending = calloc(t->npending + 1, sizeof *t->pending);
    t->pending_line = calloc(t->npending + 1, sizeof *t->pending_line);
    for (size_t i = 0; i < nlook; i++) {
        if (i >= first_data && t->pending != NULL && t->pending_line != NULL) {
            t->pending[i - first_data] = look[i];
            t->pending_line[i - first_data] = look_line[i];
        } else {
            free(look[i]);
        }
    }
    if (t->names == NULL || t->pending == NULL || t->pending_line == NULL) {
        snprintf(err, errlen, "%s: out of memory", t->name);
        fe_cli_table_close(t);
        return FE_CLI_IO;
    }
    t->progress = isatty(2) && t->size > (off_t)(1 << 22);
    return FE_CLI_OK;
}

int fe_cli_table_open(fe_cli_table *t, const char *path, long skip,
                      char *err, size_t errlen)
{
    return fe__cli_table_open(t, path, skip, 0, err, errlen);
}

int fe_cli_table_open_rewindable(fe_cli_table *t, const char *path, long skip,
                                 char *err, size_t errlen)
{
    return fe__cli_table_open(t, path, skip, 1, err, errlen);
}
/* Open a table and find its header ends here */
/* [[file:../../literate/cli.org::Find a column by name or number][Find a column by name or number]] */
int fe_cli_table_column(const fe_cli_table *t, const char *spec, size_t *col,
                        char *err, size_t errlen)
{
    char *end;
    long number = strtol(spec, &end, 10);
    size_t found = (size_t)-1, matches = 0, speclen = strlen(spec);
    size_t n;

    for (size_t j = 0; j < t->ncols; j++)
        if (strcmp(t->names[j], spec) == 0) {
            for (size_t l = j + 1; l < t->ncols; l++)
                if (strcmp(t->names[l], spec) == 0) {
                    snprintf(err, errlen, "%s: columns %zu and %zu are both named '%s': "
                             "name the one you mean by its number", t->name, j + 1, l + 1, spec);
                    return FE_CLI_USAGE;
                }
            *col = j;
            return FE_CLI_OK;
        }
    for (size_t j = 0; j < t->ncols; j++)
        if (strcasecmp(t->names[j], spec) == 0) {
            *col = j;
            return FE_CLI_OK;
        }
    if (*spec != '\0' && *end == '\0' && number >= 1 && (size_t)number <= t->ncols) {
        *col = (size_t)number - 1;
        return FE_CLI_OK;
    }
    for (size_t j = 0; j < t->ncols; j++)
        if (speclen > 0 && strncasecmp(t->names[j], spec, speclen) == 0) {
            found = j;
            matches++;
        }
    if (matches == 1) {
        *col = found;
        return FE_CLI_OK;
    }
    n = (size_t)snprintf(err, errlen, "%s: %s column '%s'; the columns are:",
                         t->name, matches > 1 ? "ambiguous" : "no", spec);
    for (size_t j = 0; j < t->ncols && n < errlen; j++)
        n += (size_t)snprintf(err + n, errlen - n, "%s '%s'", j ? "," : "",
                              t->names[j]);
    return FE_CLI_USAGE;
}
/* Find a column by name or number ends here */
/* [[file:../../literate/cli.org::A row of plain numbers in one pass][A row of plain numbers in one pass]] */
enum { FE__CLI_ONE_PASS_COLUMNS = 64, FE__CLI_ONE_PASS_DECLINED = 64 };

/* The k requested columns of a line of ncols plain numbers, read in one
   pass into out: 1.  0 when the one pass declines the line or is not
   asked (out is then not written); the caller splits it. */
static int fe__cli_one_pass(fe_cli_table *t, const char *line, const size_t *cols, size_t k,
                            double *out)
{
    double v[FE__CLI_ONE_PASS_COLUMNS];
    size_t nv;
    if (t->declined >= FE__CLI_ONE_PASS_DECLINED || t->decimal_comma == 1
        || t->delimiter == FE_CSV_WHITESPACE || t->ncols > FE__CLI_ONE_PASS_COLUMNS)
        return 0;
    if (fe_csv_numbers(line, t->delimiter, v, t->ncols, &nv) != FE_OK || nv != t->ncols) {
        t->declined++;
        return 0;
    }
    t->declined = 0;
    for (size_t i = 0; i < k; i++)
        out[i] = v[cols[i]];
    return 1;
}
/* A row of plain numbers in one pass ends here */
/* [[file:../../literate/cli.org::Read the next row][Read the next row]] */
static int fe__cli_skip(fe_cli_table *t, int reason);

/* The threads' pass ("Every core on one file"): the next row, FE_END, an
   error, or FE__CLI_ONE when the input cannot be cut (read it here). */
enum { FE__CLI_ONE = -1 };
static int fe__cli_pass_next(fe_cli_table *t, const size_t *cols, size_t k,
                             double *out, char *err, size_t errlen);
static void fe__cli_pass_end(fe_cli_table *t);
static void fe__cli_progress_show(fe_cli_table *t);

/* One line: a row, FE_END, an error, or FE__CLI_SKIPPED for a bad row
   that --skip-bad-rows counted (the caller reads on: a loop, not a
   recursion, so that a file of bad rows cannot exhaust the stack). */
enum { FE__CLI_SKIPPED = -2 };
static int fe__cli_table_row(fe_cli_table *t, const size_t *cols, size_t k,
                             double *out, char *err, size_t errlen)
{
    char *line;
    size_t len, nf, bad = 0;
    int rc;

    for (;;) {
        if (t->next_pending < t->npending) {
            /* Split a copy: the looked-ahead line is replayed after a rewind. */
            line = t->scratch;
            strcpy(line, t->pending[t->next_pending]);
            t->line = t->pending_line[t->next_pending++];
        } else if ((t->threads > 1 || t->parts != NULL) && !t->serial && !t->view
                   && (rc = fe__cli_pass_next(t, cols, k, out, err, errlen)) != FE__CLI_ONE) {
            return rc;          /* a row parsed on a thread, or the end */
        } else {
            rc = fe_csv_next_line(&t->reader, &line, &len);
            if (rc == FE_END)
                return FE_END;
            if (rc != FE_OK)
                return fe__cli_line_error(t, rc, err, errlen);
            t->line = t->reader.line;
        }
        if (!fe__cli_ignorable(line))
            break;
    }
    if (fe__cli_one_pass(t, line, cols, k, out)) {
        t->rows++;
        return FE_OK;
    }
    rc = fe_csv_split(line, t->delimiter, t->fields, FE_CLI_FIELDS_MAX, &nf, &bad);
    if (rc == FE_EPARSE)
        return fe__cli_at(t, t->line, bad, FE_CLI_INPUT, err, errlen,
                          "unterminated or misplaced quote");
    if (rc != FE_OK || nf != t->ncols) {
        if (fe__cli_skip_bad)
            return fe__cli_skip(t, FE_CLI_BAD_FIELDS);
        return fe__cli_at(t, t->line, 1, FE_CLI_INPUT, err, errlen,
                          "expected %zu fields, found %s%zu", t->ncols,
                          rc == FE_ESIZE ? "more than " : "", rc == FE_ESIZE ? (size_t)FE_CLI_FIELDS_MAX : nf);
    }
    for (size_t i = 0; i < k; i++) {
        const fe_csv_field *f = &t->fields[cols[i]];
        int reason;
        rc = fe__cli_number(t, f, &out[i]);
        if (rc == FE_OK)
            continue;
        reason = f->text[0] == '\0' ? FE_CLI_BAD_EMPTY
                 : rc == FE_ENONFINITE ? FE_CLI_BAD_NONFINITE : FE_CLI_BAD_TEXT;
        if (fe__cli_skip_bad)
            return fe__cli_skip(t, reason);
        if (reason == FE_CLI_BAD_EMPTY)
            return fe__cli_at(t, t->line, f->column, FE_CLI_INPUT, err, errlen,
                              "empty cell in column '%s' (--skip-bad-rows skips such rows)",
                              t->names[cols[i]]);
        return fe__cli_at(t, t->line, f->column, FE_CLI_INPUT, err, errlen,
                          "'%s' in column '%s' is not a %snumber", f->text,
                          t->names[cols[i]], reason == FE_CLI_BAD_NONFINITE ? "finite " : "");
    }
    t->rows++;
    return FE_OK;
}

/* Count a bad row; the caller goes on to the next one. */
static int fe__cli_skip(fe_cli_table *t, int reason)
{
    t->bad[reason]++;
    if (!t->view && !t->reread) /* a worker's view: the caller adds them */
        fe__cli_bad_total[reason]++;
    return FE__CLI_SKIPPED;
}

void fe_cli_table_reread(fe_cli_table *t)
{
    t->reread = 1;
}

int fe_cli_table_next(fe_cli_table *t, const size_t *cols, size_t k,
                      double *out, char *err, size_t errlen)
{
    int rc;
    while ((rc = fe__cli_table_row(t, cols, k, out, err, errlen)) == FE__CLI_SKIPPED)
        continue;
    return rc;
}

int fe_cli_table_rewind(fe_cli_table *t, char *err, size_t errlen)
{
    if (lseek(t->fd, 0, SEEK_CUR) == (off_t)-1 || gzrewind((gzFile)t->gz) != 0) {
        snprintf(err, errlen, "%s: cannot read the input twice (a pipe?)", t->name);
        return FE_CLI_IO;
    }
    fe_csv_reader_init_read(&t->reader, fe__cli_gz_read, t->gz, t->buffer, FE_CLI_LINE_MAX);
    /* The skipped rows are counted again in the new pass. */
    for (int r = 0; r < FE_CLI_BAD_REASONS; r++) {
        fe__cli_bad_total[r] -= t->bad[r];
        t->bad[r] = 0;
    }
    /* Skip to just past the last looked-ahead line (a header with no data
       after it too); replay the looked-ahead data lines. */
    {
        char *line;
        size_t len;
        while (t->reader.line < t->look_end)
            if (fe_csv_next_line(&t->reader, &line, &len) == FE_END)
                break;
    }
    t->next_pending = 0;
    t->rows = 0;
    fe__cli_pass_end(t);
    t->at = 0;
    return FE_CLI_OK;
}

void fe_cli_table_close(fe_cli_table *t)
{
    fe__cli_pass_end(t);
    size_t nbad = t->bad[0] + t->bad[1] + t->bad[2] + t->bad[3];
    if (nbad > 0 && !t->reread)
        fprintf(stderr, "foldest: %s: skipped %zu bad rows (%zu with an empty cell, "
                        "%zu with NaN or infinity, %zu with text, %zu with a wrong number "
                        "of fields)\n", t->name, nbad, t->bad[FE_CLI_BAD_EMPTY],
                t->bad[FE_CLI_BAD_NONFINITE], t->bad[FE_CLI_BAD_TEXT], t->bad[FE_CLI_BAD_FIELDS]);
    memset(t->bad, 0, sizeof t->bad);
    if (t->gz != NULL)
        gzclose_r((gzFile)t->gz);
    t->gz = NULL;
    if (t->fd > 0)
        close(t->fd);
    t->fd = -1;
    for (size_t j = 0; t->names != NULL && j < t->ncols; j++)
        free(t->names[j]);
    fe__cli_free_lines(t->pending, t->pending != NULL ? t->npending : 0);
    free(t->names);
    free(t->pending);
    free(t->pending_line);
    free(t->fields);
    free(t->buffer);
    free(t->scratch);
    t->scratch = NULL;
    t->names = NULL;
    t->pending = NULL;
    t->pending_line = NULL;
    t->fields = NULL;
    t->buffer = NULL;
}
/* Read the next row ends here */
/* [[file:../../literate/cli.org::Parallel Pass Private Data][Parallel Pass Private Data]] */
enum { FE__CLI_BATCH = 1 << 20, FE__CLI_BATCH_MIN = 1 << 16, FE__CLI_SLOTS = 4,
       FE__CLI_RUN = 512, FE__CLI_PART = -3 };

/* Rows --skip-bad-rows skipped before row `row` of a batch, by reason:
   the counts so far (bad rows are few; the list grows as needed). */
typedef struct fe__cli_skipped {
    size_t row, bad[FE_CLI_BAD_REASONS];
} fe__cli_skipped;

/* A slot is written row by row by the thread that parses into it, so
   slots (and parts) start on a cache line of their own
   (FE__CLI_CACHE_LINE): two threads writing neighbours' counters each
   row would cost a third of the run in cache misses. */
enum { FE__CLI_CACHE_LINE = 64 };

/* One batch's rows, parsed by whichever thread claimed it. */
typedef struct fe__cli_batch {
    _Alignas(FE__CLI_CACHE_LINE) double *rows;  /* n rows of k doubles */
    size_t *line;               /* each row's line within the batch, from 2 */
    size_t n, cap;
    size_t lines;               /* the lines the batch holds */
    fe__cli_skipped *skipped;   /* where the counts of bad rows grew */
    size_t nskipped, skipped_cap;
    off_t end;                  /* the byte after its last line */
    int status;                 /* FE_END: all read; else the error after row n */
    int ready;
    char err[1024];
    /* fe_cli_table_fold: the rows go to the part in runs of FE__CLI_RUN,
       and only the run being parsed is kept (rows and line from run0). */
    void *part;
    size_t run0, last_line;     /* the run's first row; the last row's line */
    int fold_rc;                /* FE_OK, or the refusal of row run0 */
} fe__cli_batch;

/* The state the threads share, under `lock`. */
typedef struct fe__cli_pass {
    const fe_cli_table *t;      /* read-only while the pass runs */
    const size_t *cols;
    size_t k;
    const fe_cli_parts *parts;  /* fe_cli_table_fold's, or NULL */
    off_t data, size, step;     /* D, the file's size, the batch size S */
    size_t nbatches, nslots;
    fe__cli_batch *slot;        /* batch b in slot b % nslots */
    pthread_mutex_t lock;
    pthread_cond_t ready, room;
    size_t next;                /* the first batch not claimed */
    size_t taken;               /* batches the calling thread has taken */
    size_t failed;              /* the first batch that failed (nbatches: none) */
    int stop;
    /* The calling thread's side, without the lock: the batch it hands
       out (`have`: taken from the ring), its next row, the number of the
       line before it, the bad rows already counted, the end. */
    size_t cur, pos, base, bad_seen, nworkers;
    int have, done;
    struct fe__cli_worker *w;   /* w[0]: the calling thread's buffers */
} fe__cli_pass;

/* A thread's buffers for the view it parses through. */
typedef struct fe__cli_worker {
    fe__cli_pass *pass;
    char *buffer;
    fe_csv_field *fields;
    pthread_t thread;
} fe__cli_worker;

/* The byte range a batch's reader reads with pread. */
typedef struct fe__cli_range {
    int fd;
    off_t at, end;
} fe__cli_range;
/* Parallel Pass Private Data ends here */
/* [[file:../../literate/cli.org::Find where a batch begins][Find where a batch begins]] */
static off_t fe__cli_batch_start(const fe__cli_pass *p, size_t b)
{
    char buf[4096];
    off_t at;
    if (b == 0)
        return p->data;
    if (b >= p->nbatches)
        return p->size;
    at = p->data + (off_t)b * p->step - 1;
    while (at < p->size) {
        size_t want = (size_t)(p->size - at < (off_t)sizeof buf ? p->size - at : (off_t)sizeof buf);
        ssize_t got = pread(p->t->fd, buf, want, at);
        const char *nl;
        if (got < 0 && errno == EINTR)
            continue;
        if (got <= 0)
            return -1;
        nl = memchr(buf, '\n', (size_t)got);
        if (nl != NULL)
            return at + (nl - buf) + 1;
        at += got;
    }
    return p->size;
}

static long fe__cli_pread(void *ctx, char *buf, size_t n)
{
    fe__cli_range *r = ctx;
    ssize_t got;
    if ((off_t)n > r->end - r->at)
        n = (size_t)(r->end - r->at);
    if (n == 0)
        return 0;
    got = pread(r->fd, buf, n, r->at);
    if (got > 0)
        r->at += got;
    else if (got == 0) {        /* the file shrank under us */
        errno = EIO;
        return -1;
    }
    return (long)got;
}
/* Find where a batch begins ends here */
/* [[file:../../literate/cli.org::Parse one batch on a worker][Parse one batch on a worker]] */
/* Note that the bad rows before row s->n now number v->bad; -1 without
   memory. */
static int fe__cli_note_skipped(fe__cli_batch *s, const fe_cli_table *v)
{
    if (s->nskipped == s->skipped_cap) {
        size_t cap = s->skipped_cap ? 2 * s->skipped_cap : 16;
        fe__cli_skipped *more = realloc(s->skipped, cap * sizeof *more);
        if (more == NULL)
            return -1;
        s->skipped = more;
        s->skipped_cap = cap;
    }
    s->skipped[s->nskipped].row = s->n;
    memcpy(s->skipped[s->nskipped++].bad, v->bad, sizeof v->bad);
    return 0;
}

/* Fold the run of rows parsed since the last into the batch's part;
   FE_OK, or the refusal (s->fold_rc, with s->run0 the refused row and
   s->last_line its line). */
static int fe__cli_fold_run(const fe__cli_pass *p, fe__cli_batch *s)
{
    size_t done;
    int rc = p->parts->rows(s->part, p->parts->config, s->rows, s->n - s->run0, &done);
    if (rc != FE_OK) {
        s->fold_rc = rc;
        s->last_line = s->line[done];
        s->run0 += done;
        return rc;
    }
    s->run0 = s->n;
    return FE_OK;
}

static void fe__cli_parse_batch(fe__cli_pass *p, fe__cli_worker *w, size_t b,
                                fe__cli_batch *s)
{
    const fe_cli_table *t = p->t;
    fe__cli_range range;
    fe_cli_table v;
    off_t start = fe__cli_batch_start(p, b), end = fe__cli_batch_start(p, b + 1);
    size_t skipped = 0;
    int folds = p->parts != NULL && !p->parts->in_order;     /* here, into a part */

    s->n = s->lines = s->nskipped = s->run0 = 0;
    s->end = end;
    s->err[0] = '\0';
    s->fold_rc = FE_OK;
    if (folds)
        p->parts->start(s->part, p->parts->config);
    if (start < 0 || end < 0) {
        s->status = fe__cli_at(t, 1, 1, FE_CLI_IO, s->err, sizeof s->err,
                               "read error: %s", strerror(errno));
        return;
    }
    memset(&v, 0, sizeof v);
    v.name = t->name;
    v.fd = -1;
    v.buffer = w->buffer;
    v.fields = w->fields;
    v.delimiter = t->delimiter;
    v.ncols = t->ncols;
    v.names = t->names;
    v.has_header = t->has_header;
    v.decimal_comma = t->decimal_comma;
    v.view = 1;
    range.fd = t->fd;
    range.at = start;
    range.end = end > start ? end : start;
    fe_csv_reader_init_read(&v.reader, fe__cli_pread, &range, w->buffer, FE_CLI_LINE_MAX);
    v.reader.line = 1;          /* not the first line: no byte-order mark */
    for (;;) {
        int rc;
        if (folds && s->n - s->run0 == FE__CLI_RUN && fe__cli_fold_run(p, s) != FE_OK) {
            s->status = FE_END;     /* nothing after the refusal counts */
            return;
        }
        if (s->n - s->run0 == s->cap) {
            size_t cap = s->cap ? 2 * s->cap : 4096;
            double *rows = realloc(s->rows, cap * (p->k + 1) * sizeof *rows);
            size_t *line = rows != NULL ? realloc(s->line, cap * sizeof *line) : NULL;
            if (rows != NULL)
                s->rows = rows;
            if (line == NULL) {
                s->status = fe__cli_at(t, v.reader.line, 1, FE_CLI_IO, s->err, sizeof s->err,
                                       "out of memory");
                break;
            }
            s->line = line;
            s->cap = cap;
        }
        rc = fe_cli_table_next(&v, p->cols, p->k, s->rows + (s->n - s->run0) * p->k, s->err,
                               sizeof s->err);
        if (v.bad[0] + v.bad[1] + v.bad[2] + v.bad[3] > skipped
            && fe__cli_note_skipped(s, &v) != 0) {
            s->status = fe__cli_at(t, v.reader.line, 1, FE_CLI_IO, s->err, sizeof s->err,
                                   "out of memory");
            break;
        }
        skipped = v.bad[0] + v.bad[1] + v.bad[2] + v.bad[3];
        if (rc == FE_OK) {
            s->line[s->n++ - s->run0] = s->last_line = v.line;
            continue;
        }
        s->status = rc;
        if (rc == FE_END)
            s->lines = v.reader.line - 1;
        break;
    }
    if (folds && s->n > s->run0)        /* the rows before the end or an error */
        fe__cli_fold_run(p, s);
}
/* Parse one batch on a worker ends here */
/* [[file:../../literate/cli.org::Claim batches until none is left][Claim batches until none is left]] */
/* With the lock held: the batch to parse next, or nbatches for none now. */
static size_t fe__cli_claim(fe__cli_pass *p)
{
    if (p->stop || p->next >= p->nbatches || p->next > p->failed
        || p->next >= p->taken + p->nslots)
        return p->nbatches;
    return p->next++;
}

/* With the lock held: parse batch b without it and publish the result. */
static void fe__cli_fill(fe__cli_pass *p, fe__cli_worker *w, size_t b)
{
    fe__cli_batch *s = &p->slot[b % p->nslots];
    pthread_mutex_unlock(&p->lock);
    fe__cli_parse_batch(p, w, b, s);
    pthread_mutex_lock(&p->lock);
    s->ready = 1;
    if ((s->status != FE_END || s->fold_rc != FE_OK) && b < p->failed)
        p->failed = b;
    pthread_cond_broadcast(&p->ready);
}

static void *fe__cli_worker_run(void *arg)
{
    fe__cli_worker *w = arg;
    fe__cli_pass *p = w->pass;
    pthread_mutex_lock(&p->lock);
    for (;;) {
        size_t b = fe__cli_claim(p);
        if (b < p->nbatches) {
            fe__cli_fill(p, w, b);
            continue;
        }
        if (p->stop || p->next >= p->nbatches || p->next > p->failed)
            break;
        pthread_cond_wait(&p->room, &p->lock);  /* the ring is full */
    }
    pthread_mutex_unlock(&p->lock);
    return NULL;
}
/* Claim batches until none is left ends here */
/* [[file:../../literate/cli.org::Give a batch's message the file's line number][Give a batch's message the file's line number]] */
static void fe__cli_relocate(char *err, size_t errlen, const char *name, size_t base)
{
    size_t n = strlen(name);
    char *end, rest[1024];
    unsigned long long rel;
    if (strncmp(err, name, n) != 0 || err[n] != ':' || !isdigit((unsigned char)err[n + 1]))
        return;
    rel = strtoull(err + n + 1, &end, 10);
    if (*end != ':' || rel < 1)
        return;
    snprintf(rest, sizeof rest, "%s", end);
    snprintf(err + n + 1, errlen - n - 1, "%zu%s", base + (size_t)rel - 1, rest);
}
/* Give a batch's message the file's line number ends here */
/* [[file:../../literate/cli.org::Decide whether to cut the file][Decide whether to cut the file]] */
static off_t fe__cli_data_offset(const fe_cli_table *t)
{
    char buf[1 << 16];
    unsigned char magic[2];
    size_t lines = 0;
    off_t at = 0;
    if (t->size <= 0 || t->fd < 0 || t->view
        || pread(t->fd, magic, 2, 0) != 2 || (magic[0] == 0x1f && magic[1] == 0x8b))
        return 0;
    while (lines < t->look_end && at < t->size) {
        ssize_t got = pread(t->fd, buf, sizeof buf, at);
        const char *q, *end;
        if (got < 0 && errno == EINTR)
            continue;
        if (got <= 0)
            return 0;
        for (q = buf, end = buf + got; lines < t->look_end
             && (q = memchr(q, '\n', (size_t)(end - q))) != NULL; q++)
            lines++;
        at = lines < t->look_end ? at + got : at + (q - buf);  /* q: past the LF */
    }
    return lines == t->look_end ? at : 0;
}
/* Decide whether to cut the file ends here */
/* [[file:../../literate/cli.org::Hand the rows out in file order][Hand the rows out in file order]] */
void fe_cli_table_threads(fe_cli_table *t, int threads)
{
    t->threads = threads;
}

/* Stop the workers, wait for them and free the pass. */
static void fe__cli_pass_end(fe_cli_table *t)
{
    fe__cli_pass *p = t->pass;
    if (p == NULL)
        return;
    pthread_mutex_lock(&p->lock);
    p->stop = 1;
    pthread_cond_broadcast(&p->room);
    pthread_mutex_unlock(&p->lock);
    for (size_t i = 1; i <= p->nworkers; i++)
        pthread_join(p->w[i].thread, NULL);
    pthread_cond_destroy(&p->room);
    pthread_cond_destroy(&p->ready);
    pthread_mutex_destroy(&p->lock);
    for (size_t i = 0; i < p->nslots; i++) {
        free(p->slot[i].rows);
        free(p->slot[i].line);
        free(p->slot[i].skipped);
        free(p->slot[i].part);
    }
    for (size_t i = 0; i < p->nslots / FE__CLI_SLOTS; i++) {     /* the threads */
        free(p->w[i].buffer);
        free(p->w[i].fields);
    }
    free(p->slot);
    free(p->w);
    free(p);
    t->pass = NULL;
}

/* n bytes rounded up to whole cache lines (aligned_alloc's sizes). */
static size_t fe__cli_lines(size_t n)
{
    return (n + FE__CLI_CACHE_LINE - 1) / FE__CLI_CACHE_LINE * FE__CLI_CACHE_LINE;
}

/* Cut the file and start the workers; FE__CLI_ONE when it cannot be cut
   (t->serial is then set), FE_CLI_IO without memory. */
static int fe__cli_pass_start(fe_cli_table *t, const size_t *cols, size_t k,
                              char *err, size_t errlen)
{
    const char *env = getenv("FOLDEST_BATCH");
    long batch = env != NULL ? strtol(env, NULL, 10) : 0;   /* 0: not asked */
    off_t data, step;
    fe__cli_pass *p;
    struct stat st;
    sigset_t all, mask;
    if (fstat(t->fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > t->size)
        t->size = st.st_size;   /* a log that grew since it was opened */
    data = fe__cli_data_offset(t);
    /* Parts are cut the same way on any number of threads (16 batches,
       four each for four threads), so that they merge the same way. */
    step = (data > 0 ? t->size - data : 0) / (t->parts != NULL ? 16 : 4 * (off_t)t->threads);
    step = step > FE__CLI_BATCH ? FE__CLI_BATCH : step;
    if (batch > 0)
        step = (off_t)batch;
    else if (step < FE__CLI_BATCH_MIN)
        step = data > 0 && t->size - data >= 2 * FE__CLI_BATCH_MIN ? FE__CLI_BATCH_MIN : 0;
    if (data <= 0 || step <= 0 || data >= t->size) {
        t->serial = 1;
        return FE__CLI_ONE;
    }
    p = calloc(1, sizeof *p);
    if (p == NULL)
        goto out_of_memory;
    p->t = t;
    p->cols = cols;
    p->k = k;
    p->parts = t->parts;
    p->data = data;
    p->size = t->size;
    p->step = step;
    p->nbatches = (size_t)((t->size - data + step - 1) / step);
    p->failed = p->nbatches;
    p->nslots = FE__CLI_SLOTS * (size_t)t->threads;
    p->base = t->look_end;
    p->slot = aligned_alloc(FE__CLI_CACHE_LINE, p->nslots * sizeof *p->slot);
    if (p->slot != NULL)
        memset(p->slot, 0, p->nslots * sizeof *p->slot);
    p->w = calloc((size_t)t->threads, sizeof *p->w);
    if (p->slot == NULL || p->w == NULL) {
        free(p->slot);
        free(p->w);
        free(p);
        goto out_of_memory;
    }
    pthread_mutex_init(&p->lock, NULL);
    pthread_cond_init(&p->ready, NULL);
    pthread_cond_init(&p->room, NULL);
    t->pass = p;
    for (size_t i = 0; p->parts != NULL && !p->parts->in_order && i < p->nslots; i++)
        if ((p->slot[i].part = aligned_alloc(FE__CLI_CACHE_LINE, fe__cli_lines(p->parts->size)))
            == NULL) {
            fe__cli_pass_end(t);
            goto out_of_memory;
        }
    for (int i = 0; i < t->threads; i++) {
        p->w[i].pass = p;
        p->w[i].buffer = malloc(FE_CLI_LINE_MAX);
        p->w[i].fields = malloc(FE_CLI_FIELDS_MAX * sizeof *p->w[i].fields);
        if (p->w[i].buffer == NULL || p->w[i].fields == NULL) {
            fe__cli_pass_end(t);
            goto out_of_memory;
        }
    }
    /* w[0] is the calling thread; a thread that cannot start is not
       needed.  The workers start with every signal blocked, so that
       SIGINT and SIGTERM reach the calling thread, whose
       fe_cli_signals_hold keeps them out of its critical sections. */
    sigfillset(&all);
    pthread_sigmask(SIG_BLOCK, &all, &mask);
    for (int i = 1; i < t->threads; i++)
        if (pthread_create(&p->w[i].thread, NULL, fe__cli_worker_run, &p->w[i]) == 0)
            p->nworkers = (size_t)i;
        else
            break;
    pthread_sigmask(SIG_SETMASK, &mask, NULL);
    if (env != NULL)            /* the tests' witness that the file was cut */
        fprintf(stderr, "foldest: %s: %zu batches of %lld bytes on %zu threads\n", t->name,
                p->nbatches, (long long)p->step, p->nworkers + 1);
    return FE_CLI_OK;
out_of_memory:
    snprintf(err, errlen, "%s: out of memory", t->name);
    return FE_CLI_IO;
}

/* Count the bad rows skipped before row `upto` of batch s (all: SIZE_MAX). */
static void fe__cli_count_skipped(fe__cli_pass *p, fe_cli_table *t, const fe__cli_batch *s,
                                  size_t upto)
{
    while (p->bad_seen < s->nskipped && s->skipped[p->bad_seen].row <= upto) {
        const size_t *now = s->skipped[p->bad_seen].bad;
        const size_t *before = p->bad_seen > 0 ? s->skipped[p->bad_seen - 1].bad : NULL;
        for (int r = 0; r < FE_CLI_BAD_REASONS; r++) {
            size_t d = now[r] - (before != NULL ? before[r] : 0);
            t->bad[r] += d;
            if (!t->reread)
                fe__cli_bad_total[r] += d;
        }
        p->bad_seen++;
    }
}

/* Batch s (the one handed out) is done: its lines are counted and its
   slot is free for a worker. */
static void fe__cli_batch_done(fe__cli_pass *p, fe_cli_table *t, fe__cli_batch *s)
{
    p->base += s->lines;
    t->at = s->end;
    pthread_mutex_lock(&p->lock);
    s->ready = 0;
    p->taken++;
    pthread_cond_broadcast(&p->room);
    pthread_mutex_unlock(&p->lock);
    p->cur++;
    p->have = 0;
}

/* The batch handed out is done (its rows handed out or folded): count its lines, free
   its slot, show progress; FE_OK, or the batch's own error, which comes
   after its rows. */
static int fe__cli_pass_batch_end(fe_cli_table *t, size_t rows_before, char *err, size_t errlen)
{
    fe__cli_pass *p = t->pass;
    fe__cli_batch *s = &p->slot[p->cur % p->nslots];
    fe__cli_count_skipped(p, t, s, (size_t)-1);
    if (s->status != FE_END) {
        p->done = 1;
        fe__cli_relocate(s->err, sizeof s->err, t->name, p->base);
        snprintf(err, errlen, "%s", s->err);
        return s->status;
    }
    fe__cli_batch_done(p, t, s);
    if (rows_before >> 16 != t->rows >> 16)
        fe__cli_progress_show(t);
    return FE_OK;
}

static int fe__cli_pass_next(fe_cli_table *t, const size_t *cols, size_t k,
                             double *out, char *err, size_t errlen)
{
    fe__cli_pass *p = t->pass;
    fe__cli_batch *s;
    int rc;
    if (p == NULL) {
        if ((rc = fe__cli_pass_start(t, cols, k, err, errlen)) != FE_CLI_OK)
            return rc;
        p = t->pass;
    }
    if (cols != p->cols || k != p->k) {
        snprintf(err, errlen, "%s: internal error: other columns asked for in a threaded pass",
                 t->name);
        return FE_CLI_IO;
    }
    for (;;) {
        if (p->done || p->cur >= p->nbatches)
            return FE_END;
        s = &p->slot[p->cur % p->nslots];
        if (!p->have) {         /* wait for the batch, parsing others meanwhile */
            pthread_mutex_lock(&p->lock);
            while (!s->ready) {
                size_t c = fe__cli_claim(p);
                if (c < p->nbatches)
                    fe__cli_fill(p, &p->w[0], c);
                else
                    pthread_cond_wait(&p->ready, &p->lock);
            }
            pthread_mutex_unlock(&p->lock);
            p->have = 1;
            p->pos = p->bad_seen = 0;
        }
        if (p->parts != NULL)
            return FE__CLI_PART;    /* fe_cli_table_fold takes the part */
        if (p->pos < s->n) {
            fe__cli_count_skipped(p, t, s, p->pos);
            memcpy(out, s->rows + p->pos * p->k, p->k * sizeof *out);
            t->line = p->base + s->line[p->pos++] - 1;
            t->rows++;
            return FE_OK;
        }
        if ((rc = fe__cli_pass_batch_end(t, t->rows, err, errlen)) != FE_OK)
            return rc;
    }
}

int fe_cli_table_each(fe_cli_table *t, const size_t *cols, size_t k,
                      int threads, fe_cli_row_fn *fn, void *ctx,
                      char *err, size_t errlen)
{
    double *row = malloc((k + 1) * sizeof *row);
    int rc;
    err[0] = '\0';
    if (row == NULL) {
        snprintf(err, errlen, "%s: out of memory", t->name);
        return FE_CLI_IO;
    }
    fe_cli_table_threads(t, threads);
    while ((rc = fe_cli_table_next(t, cols, k, row, err, errlen)) == FE_OK)
        if ((rc = fn(ctx, t, row)) != 0) {
            err[0] = '\0';
            break;
        }
    fe__cli_pass_end(t);        /* cols may go once this returns */
    free(row);
    return rc;
}

/* Fold the calling thread's run of *n rows into `into`: 0, or after a
   refusal merge's exit status, with t->rows and t->line at the refused
   row. */
static int fe__cli_run_fold(fe_cli_table *t, const fe_cli_parts *parts, void *ctx, void *into,
                            const double *run, const size_t *line, size_t *n)
{
    size_t done;
    int rc = *n > 0 ? parts->rows(into, parts->config, run, *n, &done) : FE_OK;
    if (rc != FE_OK) {
        t->rows -= *n - done - 1;
        t->line = line[done];
        return parts->merge(ctx, t, parts->in_order ? NULL : into, rc);
    }
    *n = 0;
    return 0;
}

/* A fold in parts: merge the part of the batch handed out
   (fe__cli_pass_next said FE__CLI_PART), counting its rows as handing
   them out one by one would have.  FE_OK to go on; else merge's exit
   status (err empty) or the batch's error. */
static int fe__cli_pass_part(fe_cli_table *t, const fe_cli_parts *parts, void *ctx,
                             char *err, size_t errlen)
{
    fe__cli_pass *p = t->pass;
    fe__cli_batch *s = &p->slot[p->cur % p->nslots];
    size_t rows = t->rows;
    int rc;
    if (s->fold_rc != FE_OK) {  /* the rows before the refused one, then it */
        fe__cli_count_skipped(p, t, s, s->run0);
        t->rows += s->run0 + 1;
        t->line = p->base + s->last_line - 1;
        p->done = 1;
        err[0] = '\0';
        return parts->merge(ctx, t, s->part, s->fold_rc);
    }
    t->rows += s->n;
    if (s->n > 0)
        t->line = p->base + s->last_line - 1;
    if ((rc = parts->merge(ctx, t, s->part, FE_OK)) != 0) {
        p->done = 1;
        err[0] = '\0';
        return rc;
    }
    return fe__cli_pass_batch_end(t, rows, err, errlen);
}

/* A fold in order: the rows of the batch handed out join the calling
   thread's run (run, line, *n) as if read one by one, and each full run
   is folded, so that the runs are the one reader's.  FE_OK to go on;
   merge's exit status after a refusal (err empty); or the batch's error,
   the run then holding the rows before it. */
static int fe__cli_pass_rows(fe_cli_table *t, const fe_cli_parts *parts, void *ctx,
                             double *run, size_t *line, size_t *n, char *err, size_t errlen)
{
    fe__cli_pass *p = t->pass;
    fe__cli_batch *s = &p->slot[p->cur % p->nslots];
    size_t rows = t->rows;
    for (size_t i = 0; i < s->n; i++) {
        fe__cli_count_skipped(p, t, s, i);
        memcpy(run + *n * p->k, s->rows + i * p->k, p->k * sizeof *run);
        t->line = line[(*n)++] = p->base + s->line[i] - 1;
        t->rows++;
        if (*n == FE__CLI_RUN) {
            int rc = fe__cli_run_fold(t, parts, ctx, ctx, run, line, n);
            if (rc != 0) {
                p->done = 1;
                err[0] = '\0';
                return rc;
            }
        }
    }
    return fe__cli_pass_batch_end(t, rows, err, errlen);
}

int fe_cli_table_fold(fe_cli_table *t, const size_t *cols, size_t k, int threads,
                      const fe_cli_parts *parts, void *ctx, char *err, size_t errlen)
{
    size_t line[FE__CLI_RUN], n = 0;
    double *run = malloc(FE__CLI_RUN * (k + 1) * sizeof *run);
    void *mine = malloc(parts->in_order ? 1 : parts->size);
    void *into = parts->in_order ? ctx : mine;      /* where this thread's rows go */
    int rc;
    err[0] = '\0';
    if (run == NULL || mine == NULL) {
        free(run);
        free(mine);
        snprintf(err, errlen, "%s: out of memory", t->name);
        return FE_CLI_IO;
    }
    fe_cli_table_threads(t, threads);
    t->parts = parts;
    if (!parts->in_order)
        parts->start(mine, parts->config);
    for (;;) {
        int stop;
        rc = fe_cli_table_next(t, cols, k, run + n * k, err, errlen);
        if (rc == FE_OK) {
            line[n++] = t->line;
            fe_cli_progress(t);
            if (n < FE__CLI_RUN)
                continue;
        } else if (rc == FE__CLI_PART && parts->in_order) {
            rc = fe__cli_pass_rows(t, parts, ctx, run, line, &n, err, errlen);
            if (rc == FE_OK)
                continue;
            if (err[0] == '\0')
                break;          /* refused, and said so */
        }
        /* A full run, the end, a malformed row or a part: the rows this
           thread read come first. */
        if ((stop = fe__cli_run_fold(t, parts, ctx, into, run, line, &n)) != 0) {
            rc = stop;
            err[0] = '\0';
            break;
        }
        if (rc == FE_OK)
            continue;
        if (!parts->in_order) {
            if ((stop = parts->merge(ctx, t, mine, FE_OK)) != 0) {
                rc = stop;
                err[0] = '\0';
                break;
            }
            parts->start(mine, parts->config);
        }
        if (rc != FE__CLI_PART || (rc = fe__cli_pass_part(t, parts, ctx, err, errlen)) != FE_OK)
            break;
    }
    fe__cli_pass_end(t);        /* cols may go once this returns */
    t->parts = NULL;
    free(run);
    free(mine);
    return rc;
}

int fe_cli_threads_default(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1 : n > FE_CLI_THREADS_MAX ? FE_CLI_THREADS_MAX : (int)n;
}

int fe_cli_parse_threads(const char *text, int *threads, char *err, size_t errlen)
{
    long n;
    if (fe_cli_parse_long("--threads", text, &n, err, errlen) != FE_CLI_OK)
        return FE_CLI_USAGE;
    if (n < 1 || n > FE_CLI_THREADS_MAX) {
        snprintf(err, errlen, "--threads: from 1 to %d", FE_CLI_THREADS_MAX);
        return FE_CLI_USAGE;
    }
    *threads = (int)n;
    return FE_CLI_OK;
}
/* Hand the rows out in file order ends here */
/* [[file:../../literate/cli.org::Open a second reader at a line][Open a second reader at a line]] */
static long fe__cli_part_read(void *ctx, char *buf, size_t n)
{
    fe_cli_table *t = ctx;
    ssize_t got = pread(t->fd, buf, n, t->part_at);
    if (got > 0)
        t->part_at += got;
    return (long)got;
}

int fe_cli_table_open_part(fe_cli_table *part, const fe_cli_table *t, size_t line, size_t rows,
                           char *err, size_t errlen)
{
    char buf[1 << 16];
    unsigned char magic[2];
    struct stat st;
    size_t lf = 0;
    off_t at = 0;
    memset(part, 0, sizeof *part);
    part->fd = -1;
    if (t->fd < 0 || fstat(t->fd, &st) != 0 || !S_ISREG(st.st_mode)
        || pread(t->fd, magic, 2, 0) != 2 || (magic[0] == 0x1f && magic[1] == 0x8b)) {
        snprintf(err, errlen, "%s: cannot be read from the middle", t->name);
        return FE_CLI_IO;
    }
    while (lf < line) {         /* line + 1 begins after the line-th LF */
        ssize_t got = pread(t->fd, buf, sizeof buf, at);
        const char *q = buf, *end;
        if (got <= 0) {
            snprintf(err, errlen, "%s: has no line %zu", t->name, line + 1);
            return FE_CLI_IO;
        }
        for (end = buf + got; lf < line && (q = memchr(q, '\n', (size_t)(end - q))) != NULL; q++)
            lf++;
        at = lf < line ? at + got : at + (q - buf);
    }
    part->buffer = malloc(FE_CLI_LINE_MAX);
    part->fields = malloc(FE_CLI_FIELDS_MAX * sizeof *part->fields);
    if (part->buffer == NULL || part->fields == NULL) {
        fe_cli_table_close_part(part);
        snprintf(err, errlen, "%s: out of memory", t->name);
        return FE_CLI_IO;
    }
    part->name = t->name;
    part->fd = t->fd;
    part->delimiter = t->delimiter;
    part->ncols = t->ncols;
    part->names = t->names;
    part->has_header = t->has_header;
    part->decimal_comma = t->decimal_comma;
    part->size = st.st_size;
    part->view = 1;             /* no globals, no progress */
    part->threads = 1;
    part->part_at = at;
    fe_csv_reader_init_read(&part->reader, fe__cli_part_read, part, part->buffer,
                            FE_CLI_LINE_MAX);
    part->reader.line = line;   /* not the first line: no byte-order mark */
    part->line = line;
    part->rows = rows;
    return FE_CLI_OK;
}

void fe_cli_table_close_part(fe_cli_table *part)
{
    free(part->buffer);
    free(part->fields);
    part->buffer = NULL;
    part->fields = NULL;
}
/* Open a second reader at a line ends here */
/* [[file:../../literate/cli.org::Write output atomically][Write output atomically]] */
/* The mode a file created with 0666 gets under the current umask. */
static mode_t fe__cli_umask_mode(void)
{
    mode_t mask = umask(0);
    umask(mask);
    return (mode_t)(0666 & ~mask);
}

int fe_cli_output_open(fe_cli_output *o, const char *path, char *err,
                       size_t errlen)
{
    size_t n = strlen(path) + 16;
    int fd, saved;
    o->file = NULL;
    o->pending = -1;
    o->path = fe__cli_strdup(path);
    o->tmp = calloc(n, 1);
    if (o->path == NULL || o->tmp == NULL) {
        snprintf(err, errlen, "%s: out of memory", path);
        free(o->path);
        free(o->tmp);
        o->path = o->tmp = NULL;
        return FE_CLI_IO;
    }
    snprintf(o->tmp, n, "%s.tmp.XXXXXX", path);
    fe_cli_signals_hold(1);
    fd = mkstemp(o->tmp);
    if (fd >= 0) {
        o->pending = fe_cli_pending_add(o->tmp, 0);
        if (fchmod(fd, fe__cli_umask_mode()) == 0)
            o->file = fdopen(fd, "w");
    }
    saved = errno;
    fe_cli_signals_hold(0);
    if (o->file == NULL) {
        snprintf(err, errlen, "%s: cannot create: %s", path, strerror(saved));
        if (fd >= 0) {
            close(fd);
            unlink(o->tmp);
        }
        fe_cli_pending_drop(o->pending);
        free(o->path);
        free(o->tmp);
        o->path = o->tmp = NULL;
        o->pending = -1;
        return FE_CLI_IO;
    }
    return FE_CLI_OK;
}

int fe_cli_output_commit(fe_cli_output *o, char *err, size_t errlen)
{
    int bad = ferror(o->file) != 0;
    bad |= fclose(o->file) != 0;
    o->file = NULL;
    fe_cli_signals_hold(1);
    if (bad || rename(o->tmp, o->path) != 0) {
        fe_cli_signals_hold(0);
        snprintf(err, errlen, "%s: cannot write: %s", o->path, strerror(errno));
        fe_cli_output_abort(o);
        return FE_CLI_IO;
    }
    fe_cli_pending_drop(o->pending);
    fe_cli_signals_hold(0);
    free(o->tmp);
    free(o->path);
    o->tmp = o->path = NULL;
    o->pending = -1;
    return FE_CLI_OK;
}

void fe_cli_output_abort(fe_cli_output *o)
{
    if (o->file != NULL)
        fclose(o->file);
    if (o->tmp != NULL)
        unlink(o->tmp);
    fe_cli_pending_drop(o->pending);
    free(o->tmp);
    free(o->path);
    o->file = NULL;
    o->tmp = o->path = NULL;
    o->pending = -1;
}
/* Write output atomically ends here */
/* [[file:../../literate/cli.org::Remove pending files when interrupted][Remove pending files when interrupted]] */
enum { FE__CLI_PENDING = 16, FE__CLI_PENDING_PATH = 4200 };
static char fe__cli_pending_path[FE__CLI_PENDING][FE__CLI_PENDING_PATH];
static volatile sig_atomic_t fe__cli_pending_used[FE__CLI_PENDING];

int fe_cli_pending_add(const char *path, int is_dir)
{
    size_t n = strlen(path);
    if (n >= FE__CLI_PENDING_PATH)
        return -1;
    for (int i = 0; i < FE__CLI_PENDING; i++)
        if (!fe__cli_pending_used[i]) {
            memcpy(fe__cli_pending_path[i], path, n + 1);
            fe__cli_pending_used[i] = is_dir ? 2 : 1;
            return i;
        }
    return -1;
}

void fe_cli_pending_drop(int slot)
{
    if (slot >= 0 && slot < FE__CLI_PENDING)
        fe__cli_pending_used[slot] = 0;
}

void fe_cli_pending_clear(void)
{
    for (int i = 0; i < FE__CLI_PENDING; i++)
        fe__cli_pending_used[i] = 0;
}

/* Set while the signals are held; a signal that a thread without the
   main thread's mask (OpenBLAS starts its workers before main) catches
   meanwhile is kept here and raised again when the hold ends. */
static volatile sig_atomic_t fe__cli_held, fe__cli_deferred;

/* Files first, then directories (which are then empty, if they were
   ours); only async-signal-safe calls. */
static void fe__cli_on_signal(int sig)
{
    if (fe__cli_held) {
        fe__cli_deferred = sig;
        /* Read again (volatile): a hold that ended meanwhile has already
           looked for a deferred signal; then the handler goes on. */
        /* cppcheck-suppress identicalInnerCondition */
        if (fe__cli_held)
            return;             /* fe_cli_signals_hold(0) raises it */
    }
    for (int pass = 1; pass <= 2; pass++)
        for (int i = 0; i < FE__CLI_PENDING; i++)
            if (fe__cli_pending_used[i] == pass) {
                if (pass == 1)
                    unlink(fe__cli_pending_path[i]);
                else
                    rmdir(fe__cli_pending_path[i]);
            }
    signal(sig, SIG_DFL);
    raise(sig);
}

void fe_cli_signals_install(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = fe__cli_on_signal;
    sigemptyset(&sa.sa_mask);
    sigaddset(&sa.sa_mask, SIGINT);
    sigaddset(&sa.sa_mask, SIGTERM);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
}

void fe_cli_signals_hold(int hold)
{
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGINT);
    sigaddset(&set, SIGTERM);
    if (hold) {
        sigprocmask(SIG_BLOCK, &set, NULL);
        fe__cli_held = 1;
    } else {
        fe__cli_held = 0;
        sigprocmask(SIG_UNBLOCK, &set, NULL);
        if (fe__cli_deferred)
            raise(fe__cli_deferred);
    }
}
/* Remove pending files when interrupted ends here */
/* [[file:../../literate/cli.org::Check standard output at the end][Check standard output at the end]] */
int fe_cli_finish(const char *command, int rc)
{
    int bad = 0, why = 0;
    if (fflush(stdout) != 0) {
        bad = 1;
        why = errno;
    }
    if (ferror(stdout))
        bad = 1;
#ifndef FE_CLI_KEEP_STDOUT
    if (fclose(stdout) != 0 && !bad) {
        bad = 1;
        why = errno;
    }
#endif
    if (!bad)
        return rc;
    fprintf(stderr, "foldest%s%s: cannot write standard output: %s\n",
            command != NULL ? " " : "", command != NULL ? command : "",
            why != 0 ? strerror(why) : "write error");
    return rc == FE_CLI_OK ? FE_CLI_IO : rc;
}
/* Check standard output at the end ends here */
/* [[file:../../literate/cli.org::Start a program without a shell][Start a program without a shell]] */
int fe_cli_spawn(char *const argv[])
{
    posix_spawn_file_actions_t fa;
    pid_t pid;
    int status, rc;
    if (posix_spawn_file_actions_init(&fa) != 0)
        return -1;
    rc = posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    if (rc == 0)
        rc = posix_spawn_file_actions_addopen(&fa, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
    if (rc == 0)
        rc = posix_spawnp(&pid, argv[0], &fa, NULL, argv, environ);
    posix_spawn_file_actions_destroy(&fa);
    if (rc != 0)
        return -1;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR)
            return -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}
/* Start a program without a shell ends here */
/* [[file:../../literate/cli.org::Show progress][Show progress]] */
void fe_cli_progress(fe_cli_table *t)
{
    if ((t->rows & 0xffff) == 0)
        fe__cli_progress_show(t);
}

static void fe__cli_progress_show(fe_cli_table *t)
{
    off_t at;
    if (!t->progress)
        return;
    at = t->at > 0 ? t->at : t->gz != NULL ? (off_t)gzoffset((gzFile)t->gz) : (off_t)-1;
    if (at >= 0)
        fprintf(stderr, "\r%s: %3.0f%% (%zu rows)", t->name,
                100.0 * (double)at / (double)t->size, t->rows);
}

void fe_cli_progress_done(fe_cli_table *t)
{
    if (t->progress)
        fprintf(stderr, "\r%*s\r", 60, "");
}

/* Edit distance (insertions, deletions, substitutions, transpositions)
   between a and b, up to 63 bytes each; larger when longer. */
static size_t fe__cli_distance(const char *a, const char *b)
{
    size_t n = strlen(a), m = strlen(b), d[64][64];
    if (n > 63 || m > 63)
        return 64;
    for (size_t i = 0; i <= n; i++)
        d[i][0] = i;
    for (size_t j = 0; j <= m; j++)
        d[0][j] = j;
    for (size_t i = 1; i <= n; i++)
        for (size_t j = 1; j <= m; j++) {
            size_t best = d[i - 1][j - 1] + (a[i - 1] != b[j - 1]);
            if (d[i - 1][j] + 1 < best)
                best = d[i - 1][j] + 1;
            if (d[i][j - 1] + 1 < best)
                best = d[i][j - 1] + 1;
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]
                && d[i - 2][j - 2] + 1 < best)
                best = d[i - 2][j - 2] + 1;
            d[i][j] = best;
        }
    return d[n][m];
}

enum { FE__CLI_OPTS_MAX = 48, FE__CLI_ARGV_MAX = 4096 };

/* The options every command takes, after its own. */
static const fe_cli_option fe__cli_common[] = {
    {"--help", 0}, {"--version", 0}, {"--decimal-comma", 0}, {"--skip-bad-rows", 0}, {NULL, 0}};

/* Say what is wrong with the option argv[at] (getopt_long refused it). */
static void fe__cli_bad_option(const char *command, const char *arg, const struct option *lo,
                               int missing_value)
{
    char name[128];
    const char *best = NULL;
    size_t len, best_d = (size_t)-1, prefixed = 0;
    if (missing_value) {
        fprintf(stderr, "foldest %s: option '%s' needs a value\n", command, arg);
        return;
    }
    if (arg[0] != '-' || arg[1] != '-') {
        fprintf(stderr, "foldest %s: unknown option '%s'\n", command, arg);
        return;
    }
    snprintf(name, sizeof name, "%s", arg + 2);
    name[strcspn(name, "=")] = '\0';
    len = strlen(name);
    for (const struct option *o = lo; o->name != NULL; o++)
        prefixed += len > 0 && strncmp(o->name, name, len) == 0;
    if (prefixed > 1) {
        fprintf(stderr, "foldest %s: ambiguous option '--%s': it could be", command, name);
        for (const struct option *o = lo; o->name != NULL; o++)
            if (strncmp(o->name, name, len) == 0)
                fprintf(stderr, " --%s", o->name);
        fputc('\n', stderr);
        return;
    }
    for (const struct option *o = lo; o->name != NULL; o++) {
        size_t d = fe__cli_distance(name, o->name);
        if (d < best_d) {
            best_d = d;
            best = o->name;
        }
    }
    if (best != NULL && best_d <= (len < 6 ? 1 : len < 12 ? 2 : 3))
        fprintf(stderr, "foldest %s: unknown option '--%s'; did you mean '--%s'?\n", command,
                name, best);
    else
        fprintf(stderr, "foldest %s: unknown option '--%s'\n", command, name);
}

int fe_cli_options(const char *command, const fe_cli_option *opts, int *argcp,
                   char ***argvp)
{
    static struct option lo[FE__CLI_OPTS_MAX + 1];
    static const char *flag_of[FE__CLI_OPTS_MAX];
    static char *out[FE__CLI_ARGV_MAX + 1];
    int argc = *argcp, n = 0, k = 1, c, index;
    char **argv = *argvp;
    const fe_cli_option *tables[2] = {opts, fe__cli_common};

    /* getopt_long's table from ours, the common options after. */
    for (int t = 0; t < 2; t++)
        for (const fe_cli_option *o = tables[t]; o != NULL && o->flag != NULL; o++) {
            if (n == FE__CLI_OPTS_MAX)
                return FE_CLI_USAGE;
            lo[n].name = o->flag + 2;
            lo[n].has_arg = o->takes_value ? required_argument : no_argument;
            lo[n].flag = NULL;
            lo[n].val = 256 + n;
            flag_of[n++] = o->flag;
        }
    memset(&lo[n], 0, sizeof lo[n]);
    if (argc > FE__CLI_ARGV_MAX) {
        fprintf(stderr, "foldest %s: more than %d arguments\n", command, FE__CLI_ARGV_MAX);
        return FE_CLI_USAGE;
    }
    /* Options first, in the canonical form. */
    out[0] = argv[0];
    optind = 0;                 /* a fresh scan, even if main runs again */
    opterr = 0;
    while ((c = getopt_long(argc, argv, ":hV", lo, &index)) != -1) {
        const char *flag;
        if (c == '?' || c == ':') {
            const char *arg = optopt != 0 && optopt < 256 ? NULL : argv[optind - 1];
            char shortopt[3] = {'-', (char)optopt, '\0'};
            fe__cli_bad_option(command, arg != NULL ? arg : shortopt, lo, c == ':');
            fprintf(stderr, "'foldest %s --help' for usage\n", command);
            return FE_CLI_USAGE;
        }
        index = c >= 256 ? c - 256 : -1;    /* ours, or -h and -V */
        flag = index >= 0 ? flag_of[index] : c == 'h' ? "--help" : "--version";
        if (strcmp(flag, "--version") == 0) {
            printf("foldest %s\n", FE_VERSION);
            return -1;
        }
        if (strcmp(flag, "--help") == 0) {
            out[1] = (char *)"--help";
            out[2] = NULL;
            *argcp = 2;
            *argvp = out;
            return FE_CLI_OK;
        }
        if (strcmp(flag, "--decimal-comma") == 0 || strcmp(flag, "--skip-bad-rows") == 0) {
            fe_cli_reader_option(flag);
            continue;
        }
        out[k++] = (char *)flag;
        if (index >= 0 && lo[index].has_arg == required_argument)
            out[k++] = optarg;
    }
    /* Then the operands, which getopt_long has moved to the end. */
    while (optind < argc)
        out[k++] = argv[optind++];
    out[k] = NULL;
    *argcp = k;
    *argvp = out;
    return FE_CLI_OK;
}

int fe_cli_parse_double(const char *opt, const char *text, double *value,
                        char *err, size_t errlen)
{
    char *end;
    double v;
    errno = 0;
    v = strtod(text, &end);
    if (end == text || *end != '\0' || errno == ERANGE || v != v) {
        snprintf(err, errlen, "%s: '%s' is not a number", opt, text);
        return FE_CLI_USAGE;
    }
    *value = v;
    return FE_CLI_OK;
}

int fe_cli_parse_long(const char *opt, const char *text, long *value,
                      char *err, size_t errlen)
{
    char *end;
    long v;
    errno = 0;
    v = strtol(text, &end, 10);
    if (end == text || *end != '\0' || errno == ERANGE) {
        snprintf(err, errlen, "%s: '%s' is not a whole number", opt, text);
        return FE_CLI_USAGE;
    }
    *value = v;
    return FE_CLI_OK;
}

int fe_cli_split_list(char *text, char **items, int max)
{
    int n = 0;
    char *p = text;
    for (;;) {
        char *comma = strchr(p, ',');
        if (n == max)
            return -1;
        items[n++] = p;
        if (comma == NULL)
            return n;
        *comma = '\0';
        p = comma + 1;
    }
}

/* Length of the well-formed UTF-8 sequence at s (RFC 3629: no overlong
   forms, no surrogates, nothing above U+10FFFF), or 0. */
static size_t fe__cli_utf8_length(const unsigned char *s)
{
    unsigned c = s[0];
    size_t n;
    unsigned lo = 0x80, hi = 0xBF;
    if (c < 0x80)
        return 1;
    if (c >= 0xC2 && c <= 0xDF)
        n = 2;
    else if (c >= 0xE0 && c <= 0xEF) {
        n = 3;
        if (c == 0xE0)
            lo = 0xA0;          /* overlong */
        else if (c == 0xED)
            hi = 0x9F;          /* surrogates */
    } else if (c >= 0xF0 && c <= 0xF4) {
        n = 4;
        if (c == 0xF0)
            lo = 0x90;
        else if (c == 0xF4)
            hi = 0x8F;          /* above U+10FFFF */
    } else
        return 0;
    if (s[1] < lo || s[1] > hi)
        return 0;
    for (size_t i = 2; i < n; i++)
        if (s[i] < 0x80 || s[i] > 0xBF)
            return 0;
    return n;
}

void fe_cli_json_string(FILE *out, const char *s)
{
    const unsigned char *p = (const unsigned char *)s;
    fputc('"', out);
    while (*p != '\0') {
        size_t n = fe__cli_utf8_length(p);
        if (n == 0) {
            fputs("\\ufffd", out);   /* not UTF-8: the replacement character */
            p++;
        } else if (*p == '"' || *p == '\\') {
            fprintf(out, "\\%c", *p++);
        } else if (*p < 0x20 || *p == 0x7F) {
            fprintf(out, "\\u%04x", *p++);
        } else {
            fwrite(p, 1, n, out);
            p += n;
        }
    }
    fputc('"', out);
}

void fe_cli_json_number(FILE *out, double x)
{
    char text[FE_CSV_DOUBLE_TEXT];
    /* The shortest of 15, 16 and 17 significant digits that reads back as
       x: 0.04, not 0.040000000000000001. */
    fputs(fe_csv_format_double(x, text, sizeof text) == FE_OK ? text : "null", out);
}
/* Show progress ends here */
