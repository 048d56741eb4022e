/* SPDX-License-Identifier: MIT */
/* Tangled from literate/cli.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/cli.org::Command Line Declarations][Command Line Declarations]] */
#ifndef FOLDEST_CLI_H
#define FOLDEST_CLI_H

#define _POSIX_C_SOURCE 200809L
#include <stddef.h>
#include <stdio.h>
#include <sys/types.h>

#include <foldest.h>

enum {
    FE_CLI_OK = 0,
    FE_CLI_REFUSED = 1,
    FE_CLI_USAGE = 2,
    FE_CLI_INPUT = 3,
    FE_CLI_IO = 4
};

/* A subcommand: `foldest NAME ARGS...` calls run(argc, argv) with argv[0]
   = NAME. */
typedef struct fe_cli_command {
    const char *name;
    const char *summary;
    int (*run)(int argc, char **argv);
} fe_cli_command;
/* Command Line Declarations ends here */
/* [[file:../../literate/cli.org::Table Declarations][Table Declarations]] */
enum { FE_CLI_LINE_MAX = 1 << 16, FE_CLI_FIELDS_MAX = 4096,
       FE_CLI_LOOKAHEAD = 64 };

/* A CSV recording read row by row. */
typedef struct fe_cli_table {
    const char *name;           /* for messages: the path, or <stdin> */
    int fd;
    fe_csv_reader reader;
    char *buffer;
    char *scratch;              /* a copy of a looked-ahead line to split */
    char delimiter;
    size_t ncols;
    char **names;               /* ncols column names */
    int has_header;
    char **pending;             /* looked-ahead data lines, replayed first */
    size_t *pending_line;
    size_t npending, next_pending;
    size_t look_end;            /* the last line the look-ahead read */
    fe_csv_field *fields;
    size_t line;                /* line number of the row last returned */
    size_t rows;                /* rows returned so far */
    off_t size;                 /* file size for progress; 0: unknown */
    int progress;               /* show progress on stderr */
    void *gz;                   /* the zlib stream everything is read through */
    int decimal_comma;          /* 1: forced; 2: a semicolon table */
    unsigned declined;          /* lines in a row that the one pass declined */
    size_t bad[4];              /* rows skipped in this pass, by reason */
    int reread;                 /* fe_cli_table_reread: they are counted */
    int view;                   /* a batch's reader on a worker thread
                                   (fe_cli_table_each): it touches no
                                   global and shows no progress */
    int threads;                /* parse on this many threads (0, 1: one) */
    int serial;                 /* 1: the input cannot be cut */
    void *pass;                 /* the threads' pass, while one runs */
    const struct fe_cli_parts *parts;   /* fe_cli_table_fold's, while it runs */
    off_t part_at;              /* a part's reader (fe_cli_table_open_part): the
                                   next byte it reads */
    off_t at;                   /* the bytes the batches have handed out,
                                   for progress; 0: ask zlib */
} fe_cli_table;

/* Why a row was bad (the index of fe_cli_table.bad). */
enum { FE_CLI_BAD_EMPTY, FE_CLI_BAD_NONFINITE, FE_CLI_BAD_TEXT,
       FE_CLI_BAD_FIELDS, FE_CLI_BAD_REASONS };

/* The reader's options, for every table the process opens (set by the
   dispatcher from --decimal-comma and --skip-bad-rows). */
void fe_cli_reader_configure(int decimal_comma, int skip_bad_rows);
/* Turn on one reader option by its flag (from a command's options). */
void fe_cli_reader_option(const char *flag);

/* Rows skipped by --skip-bad-rows in the last pass over every table,
   by reason; and the same as a JSON object. */
void fe_cli_bad_rows(size_t counts[FE_CLI_BAD_REASONS]);
void fe_cli_json_bad_rows(FILE *out);

/* Open `path` ("-": standard input).  skip < 0 guesses where the data
   start; skip >= 0 skips that many lines.  On failure `err` holds the
   message and the return value is an exit status. */
int fe_cli_table_open(fe_cli_table *t, const char *path, long skip,
                      char *err, size_t errlen);

/* Say that t reads again a file another table of this run has read (a
   later pass of calibrate, which opens the file anew): the rows it skips
   were counted and reported by that table, so they are neither added to
   fe_cli_bad_rows nor reported again when t is closed. */
void fe_cli_table_reread(fe_cli_table *t);

/* Find the column `spec` (name, case-insensitive name, unique prefix, or
   number from 1); FE_CLI_USAGE with a message listing the columns if none. */
int fe_cli_table_column(const fe_cli_table *t, const char *spec, size_t *col,
                        char *err, size_t errlen);

/* Read the next row's columns cols[0..k-1] into out.  Returns FE_OK,
   FE_END, or an exit status with `err` = "FILE:LINE:COLUMN: message". */
int fe_cli_table_next(fe_cli_table *t, const size_t *cols, size_t k,
                      double *out, char *err, size_t errlen);

/* fe_cli_table_open_rewindable: the same, for a command that rewinds: an
   input that is not a regular file (standard input, a pipe) is first
   copied to an unlinked temporary file. */
int fe_cli_table_open_rewindable(fe_cli_table *t, const char *path, long skip,
                                 char *err, size_t errlen);

/* Parse a regular, uncompressed file on `threads` threads (the calling
   one included) from the next pass on: fe_cli_table_next then hands out
   rows parsed ahead, in file order, with the one-thread rows, lines,
   messages and bad-row counts.  Any other input, or threads <= 1: one
   reader, as before.  A pass must ask for the same cols (the same array,
   which the threads read until the pass ends) and k on every call;
   fe_cli_table_rewind and fe_cli_table_close end it. */
void fe_cli_table_threads(fe_cli_table *t, int threads);

/* The rows of a table, handed one at a time and in file order to
   fn(ctx, t, row), row[0..k-1] the columns cols[0..k-1], with t->line the
   row's line and t->rows counting it; parsed on `threads` threads
   (fe_cli_table_threads).  fn runs on the calling thread only, so it
   needs no lock.  Returns FE_END after the last row; an exit status with
   `err` = "FILE:LINE:COLUMN: message" for the first malformed row in file
   order; or fn's nonzero return, with err empty (fn said why). */
typedef int fe_cli_row_fn(void *ctx, fe_cli_table *t, const double *row);
int fe_cli_table_each(fe_cli_table *t, const size_t *cols, size_t k,
                      int threads, fe_cli_row_fn *fn, void *ctx,
                      char *err, size_t errlen);

/* A fold in parts, for fe_cli_table_fold.  A part is `size` bytes that
   start(part, config) makes empty; rows(part, config, x, n, &done) folds the n
   rows x[0..n*k-1] into it and returns FE_OK, or the library's refusal
   of row *done (the rows before it folded); merge(ctx, t, part, refused)
   folds a part into the command's own accumulation ctx.  start and rows
   run on whichever thread parsed the rows, so they may read only
   `config` (which must not change while the fold runs) and their part;
   merge runs on the calling thread, part after part in file order.  It
   is called with refused = FE_OK, or with a refusal, t->line then the
   refused row's line; it returns 0 to go on, or an exit status (having
   said why) to stop, which it must do after a refusal.
   A fold that is not a monoid sets in_order: then the threads only parse,
   and rows(ctx, config, ...) folds run after run of rows into ctx itself
   on the calling thread, in file order (start is not called, and merge
   only after a refusal, with part NULL). */
typedef struct fe_cli_parts {
    int in_order;
    size_t size;
    const void *config;
    void (*start)(void *part, const void *config);
    int (*rows)(void *part, const void *config, const double *x, size_t n, size_t *done);
    int (*merge)(void *ctx, fe_cli_table *t, const void *part, int refused);
} fe_cli_parts;

/* Fold the rows of a table (columns cols[0..k-1]) in parts: a regular,
   uncompressed file is cut into batches of lines that do not depend on
   `threads`, each batch is parsed and folded into a part of its own on
   one of `threads` threads, and the parts are merged in file order; the
   looked-ahead rows and any other input (a pipe, a gzip file, a file too
   small to cut) make one part on the calling thread.  So the result is
   the same, bit for bit, for every number of threads, and equal to one
   part's up to the rounding of the merges.  Returns FE_END after the
   last row; an exit status with `err` = "FILE:LINE:COLUMN: message" for
   the first malformed row in file order; or merge's nonzero return,
   with err empty.  t->rows counts the rows, t->line is the last one's. */
int fe_cli_table_fold(fe_cli_table *t, const size_t *cols, size_t k, int threads,
                      const fe_cli_parts *parts, void *ctx, char *err, size_t errlen);

/* A second reader of t's file, for a later part of a pass that another
   thread reads (discover's folds): `part` reads the rows after line
   `line` as t would, as if `rows` rows had been read, with buffers of its
   own and pread (t's offset is untouched); it shares t's descriptor,
   column names and conventions, so t must stay open while part is used,
   and t may be read meanwhile.  A part counts its bad rows in part->bad
   only and shows no progress.  FE_CLI_IO with a message when t's input
   cannot be read so (a gzip file) or without memory; nothing to close
   then.  fe_cli_table_close_part frees what a part holds. */
int fe_cli_table_open_part(fe_cli_table *part, const fe_cli_table *t, size_t line, size_t rows,
                           char *err, size_t errlen);
void fe_cli_table_close_part(fe_cli_table *part);

/* The threads to use by default: the processors online (1 when unknown;
   at most FE_CLI_THREADS_MAX).  fe_cli_parse_threads: --threads N, N from
   1 to FE_CLI_THREADS_MAX; FE_CLI_USAGE with a message otherwise. */
enum { FE_CLI_THREADS_MAX = 64 };
int fe_cli_threads_default(void);
int fe_cli_parse_threads(const char *text, int *threads, char *err,
                         size_t errlen);

/* Rewind to the first data row (FE_CLI_IO when the input cannot seek). */
int fe_cli_table_rewind(fe_cli_table *t, char *err, size_t errlen);

void fe_cli_table_close(fe_cli_table *t);
/* Table Declarations ends here */
/* [[file:../../literate/cli.org::Output Declarations][Output Declarations]] */
typedef struct fe_cli_output {
    FILE *file;
    char *path, *tmp;
    int pending;                /* slot of tmp among the pending paths */
} fe_cli_output;

/* Create a temporary file beside `path`; FE_CLI_IO with a message. */
int fe_cli_output_open(fe_cli_output *o, const char *path, char *err,
                       size_t errlen);
/* Flush, close and rename into place; FE_CLI_IO if any write failed. */
int fe_cli_output_commit(fe_cli_output *o, char *err, size_t errlen);
/* Close and delete: nothing is left behind. */
void fe_cli_output_abort(fe_cli_output *o);

/* Interruption.  fe_cli_signals_install: on SIGINT and SIGTERM, unlink
   every pending path (rmdir for a directory) and die of the signal.
   fe_cli_pending_add: register a path (copied); its slot, or -1 when the
   table is full or the path too long (then it is simply not removed).
   fe_cli_pending_drop: forget a slot (-1: nothing).  fe_cli_pending_clear:
   forget all.  fe_cli_signals_hold(1) blocks SIGINT and SIGTERM until
   fe_cli_signals_hold(0). */
void fe_cli_signals_install(void);
int fe_cli_pending_add(const char *path, int is_dir);
void fe_cli_pending_drop(int slot);
void fe_cli_pending_clear(void);
void fe_cli_signals_hold(int hold);

/* Flush and close standard output at the end of a command; when that or
   an earlier write failed, print why on stderr and return FE_CLI_IO if rc
   was FE_CLI_OK.  Otherwise return rc. */
int fe_cli_finish(const char *command, int rc);

/* Run the program argv[0] (looked up on PATH) with the arguments argv,
   NULL-terminated, and wait for it: no shell, so nothing in an argument
   is interpreted.  Its standard output and error go to /dev/null.
   Returns its exit status, or -1 when it could not be started or was
   killed by a signal. */
int fe_cli_spawn(char *const argv[]);

/* Progress of a table on stderr, when stderr is a terminal and the input
   is large; call once per row, cheap; fe_cli_progress_done clears it. */
void fe_cli_progress(fe_cli_table *t);
void fe_cli_progress_done(fe_cli_table *t);

/* A command's option: its long form ("--real") and whether it takes a
   value.  A table ends with {NULL, 0}. */
typedef struct fe_cli_option {
    const char *flag;
    int takes_value;
} fe_cli_option;

/* fe_cli_options: parse argv (argv[0] the command's name) with
   getopt_long against `opts`, plus --help/-h, --version/-V and the
   reader's --decimal-comma and --skip-bad-rows, which every command
   takes: --opt=value and --opt value, unambiguous abbreviations, options
   and operands in any order.  On success *argcp and *argvp are replaced by
   a canonical vector: argv[0], then each option as its full flag followed
   by its value, then the operands; --help alone if it was asked for.
   Returns FE_CLI_OK; -1 after printing the version; FE_CLI_USAGE after
   printing "foldest COMMAND: unknown option '--x'; did you mean '--y'?",
   an ambiguous abbreviation with its candidates, or a missing value. */
int fe_cli_options(const char *command, const fe_cli_option *opts, int *argcp,
                   char ***argvp);

/* Parse option values; FE_CLI_USAGE with a message on error. */
int fe_cli_parse_double(const char *opt, const char *text, double *value,
                        char *err, size_t errlen);
int fe_cli_parse_long(const char *opt, const char *text, long *value,
                      char *err, size_t errlen);

/* Split "a,b,c" into at most `max` names (in place); the count or -1. */
int fe_cli_split_list(char *text, char **items, int max);

/* Print one JSON string, escaped; bytes that are not UTF-8 become U+FFFD. */
void fe_cli_json_string(FILE *out, const char *s);

/* Print one JSON number: the shortest of 15, 16 or 17 significant digits
   that reads back as the same double, or null when it is not finite. */
void fe_cli_json_number(FILE *out, double x);

#endif /* FOLDEST_CLI_H */
/* Output Declarations ends here */
