/* SPDX-License-Identifier: MIT */
/* Tangled from literate/cli.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/cli.org::Summarise columns][Summarise columns]] */
#include "cli.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char fe__stats_help[] =
    "usage: foldest stats [--columns a,b,...] [--skip N] [--json] [--threads N]\n"
    "                     FILE.csv|-\n"
    "\n"
    "Count, mean, standard deviation, minimum and maximum of numeric columns,\n"
    "in one pass.  Columns are named by header name or number from 1; default:\n"
    "every column.  The header is found automatically among metadata lines;\n"
    "--skip N skips N lines first.  Malformed input: FILE:LINE:COLUMN: message.\n"
    "--threads N parses a regular file on N threads (default: the processors\n"
    "online); the rows are folded in file order, so the result is the same for\n"
    "any N.  Standard input, pipes and gzip files are read by one thread.\n";

/* The fold, in file order (fe_cli_table_each): the rows wait in a run of
   FE__STATS_RUN, column by column, with their lines, and each column's run
   goes to fe_meanvar_add_many, the mean and variance's block kernel. */
enum { FE__STATS_RUN = 512 };

typedef struct fe__stats_fold {
    size_t k, nrun;             /* columns; rows in the run */
    double *lo, *hi;
    fe_meanvar *mv;
    double *run;                /* k x FE__STATS_RUN: column j at j * FE__STATS_RUN */
    size_t run_line[FE__STATS_RUN];
} fe__stats_fold;

/* Fold the rows waiting in the run.  A value the fold refuses is reported
   at the first row, in file order, that holds one (a later column may
   refuse an earlier row): the row the one-value-at-a-time fold stops at. */
static int fe__stats_fold_run(fe__stats_fold *s, fe_cli_table *t)
{
    size_t first = s->nrun;
    int refused = FE_OK;
    for (size_t j = 0; j < s->k; j++) {
        const double *x = s->run + j * FE__STATS_RUN;
        size_t done;
        int rc = fe_meanvar_add_many(&s->mv[j], x, s->nrun, &done);
        if (rc != FE_OK && done < first) {
            first = done;
            refused = rc;
        }
        for (size_t i = 0; i < done; i++) {
            if (s->mv[j].n == done - i || x[i] < s->lo[j])  /* the column's first value */
                s->lo[j] = x[i];
            if (s->mv[j].n == done - i || x[i] > s->hi[j])
                s->hi[j] = x[i];
        }
    }
    s->nrun = 0;
    if (refused == FE_OK)
        return 0;
    fe_cli_progress_done(t);
    fprintf(stderr, "foldest stats: %s:%zu: %s\n", t->name, s->run_line[first],
            fe_strerror(refused));
    return FE_CLI_INPUT;
}

static int fe__stats_row(void *ctx, fe_cli_table *t, const double *row)
{
    fe__stats_fold *s = ctx;
    for (size_t j = 0; j < s->k; j++)
        s->run[j * FE__STATS_RUN + s->nrun] = row[j];
    s->run_line[s->nrun++] = t->line;
    if (s->nrun == FE__STATS_RUN && fe__stats_fold_run(s, t) != 0)
        return FE_CLI_INPUT;
    fe_cli_progress(t);
    return 0;
}

static const fe_cli_option fe__stats_options[] = {
    {"--columns", 1}, {"--skip", 1}, {"--json", 0}, {"--threads", 1}, {NULL, 0}};

int fe_cli_stats(int argc, char **argv)
{
    const char *path = NULL;
    char *columns = NULL, err[1024];
    long skip = -1;
    int json = 0, rc, threads = fe_cli_threads_default();
    fe_cli_table t;
    size_t k = 0, *cols = NULL;
    double *lo = NULL, *hi = NULL, *run = NULL;
    fe_meanvar *mv = NULL;
    fe__stats_fold fold;

    rc = fe_cli_options("stats", fe__stats_options, &argc, &argv);
    if (rc != FE_CLI_OK)
        return rc < 0 ? FE_CLI_OK : rc;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            fputs(fe__stats_help, stdout);
            return FE_CLI_OK;
        } else if (strcmp(argv[i], "--json") == 0) {
            json = 1;
        } else if (strcmp(argv[i], "--columns") == 0 && i + 1 < argc) {
            columns = argv[++i];
        } else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) {
            if (fe_cli_parse_threads(argv[++i], &threads, err, sizeof err) != FE_CLI_OK) {
                fprintf(stderr, "foldest stats: %s\n", err);
                return FE_CLI_USAGE;
            }
        } else if (strcmp(argv[i], "--skip") == 0 && i + 1 < argc) {
            int bad = fe_cli_parse_long("--skip", argv[++i], &skip, err, sizeof err) != FE_CLI_OK;
            if (bad || skip < 0) {
                fprintf(stderr, "foldest stats: %s\n", bad ? err : "--skip: negative");
                return FE_CLI_USAGE;
            }
        } else if (argv[i][0] == '-' && argv[i][1] != '\0') {
            fprintf(stderr, "foldest stats: unknown option '%s'\n%s", argv[i], fe__stats_help);
            return FE_CLI_USAGE;
        } else if (path == NULL) {
            path = argv[i];
        } else {
            fprintf(stderr, "foldest stats: one input file, please\n");
            return FE_CLI_USAGE;
        }
    }
    if (path == NULL) {
        fputs(fe__stats_help, stderr);
        return FE_CLI_USAGE;
    }
    rc = fe_cli_table_open(&t, path, skip, err, sizeof err);
    if (rc != FE_CLI_OK) {
        fprintf(stderr, "foldest stats: %s\n", err);
        return rc;
    }
    /* Room for every name --columns may list (a column may be named twice),
       not just for the table's columns. */
    cols = calloc(FE_CLI_FIELDS_MAX, sizeof *cols);
    if (cols == NULL)
        goto out_of_memory;
    if (columns != NULL) {
        char *names[FE_CLI_FIELDS_MAX];
        int n = fe_cli_split_list(columns, names, FE_CLI_FIELDS_MAX);
        if (n < 0) {
            fprintf(stderr, "foldest stats: --columns: more than %d names\n", FE_CLI_FIELDS_MAX);
            rc = FE_CLI_USAGE;
            goto done;
        }
        for (int i = 0; i < n; i++) {
            rc = fe_cli_table_column(&t, names[i], &cols[k++], err, sizeof err);
            if (rc != FE_CLI_OK) {
                fprintf(stderr, "foldest stats: %s\n", err);
                goto done;
            }
        }
    } else {
        for (k = 0; k < t.ncols; k++)
            cols[k] = k;
    }
    lo = calloc(k + 1, sizeof *lo);            /* + 1: never calloc(0) */
    hi = calloc(k + 1, sizeof *hi);
    mv = calloc(k + 1, sizeof *mv);
    run = calloc((k + 1) * FE__STATS_RUN, sizeof *run);
    if (lo == NULL || hi == NULL || mv == NULL || run == NULL)
        goto out_of_memory;
    fold.k = k;
    fold.nrun = 0;
    fold.lo = lo;
    fold.hi = hi;
    fold.mv = mv;
    fold.run = run;
    rc = fe_cli_table_each(&t, cols, k, threads, fe__stats_row, &fold, err, sizeof err);
    /* The rows still waiting come before the end, or a malformed row. */
    if ((rc == FE_END || err[0] != '\0') && fe__stats_fold_run(&fold, &t) != 0) {
        rc = FE_CLI_INPUT;
        goto done;
    }
    fe_cli_progress_done(&t);
    if (rc != FE_END) {
        if (err[0] != '\0')
            fprintf(stderr, "foldest stats: %s\n", err);
        goto done;
    }
    if (t.rows == 0) {
        fprintf(stderr, "foldest stats: %s: no data rows\n", t.name);
        rc = FE_CLI_INPUT;
        goto done;
    }
    if (json) {
        printf("{\"file\": ");
        fe_cli_json_string(stdout, t.name);
        printf(", \"rows\": %zu, \"bad_rows\": ", t.rows);
        fe_cli_json_bad_rows(stdout);
        printf(", \"columns\": [");
        for (size_t j = 0; j < k; j++) {
            printf("%s{\"name\": ", j ? ", " : "");
            fe_cli_json_string(stdout, t.names[cols[j]]);
            printf(", \"mean\": ");
            fe_cli_json_number(stdout, fe_meanvar_mean(&mv[j]));
            printf(", \"stddev\": ");
            fe_cli_json_number(stdout, fe_meanvar_stddev(&mv[j]));
            printf(", \"min\": ");
            fe_cli_json_number(stdout, lo[j]);
            printf(", \"max\": ");
            fe_cli_json_number(stdout, hi[j]);
            printf("}");
        }
        printf("]}\n");
    } else {
        printf("%s: %zu rows\n%-24s %15s %15s %15s %15s\n", t.name, t.rows, "column",
               "mean", "stddev", "min", "max");
        for (size_t j = 0; j < k; j++)
            printf("%-24.24s %15.6g %15.6g %15.6g %15.6g\n", t.names[cols[j]],
                   fe_meanvar_mean(&mv[j]), fe_meanvar_stddev(&mv[j]), lo[j], hi[j]);
    }
    rc = FE_CLI_OK;
    goto done;
out_of_memory:
    fprintf(stderr, "foldest stats: out of memory\n");
    rc = FE_CLI_IO;
done:
    free(cols);
    free(lo);
    free(hi);
    free(mv);
    free(run);
    fe_cli_table_close(&t);
    return rc;
}
/* Summarise columns ends here */
