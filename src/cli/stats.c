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
    "--threads N reads a regular file on N threads (default: the processors\n"
    "online); it is cut the same way for any N, so the result is the same for\n"
    "any N.  Standard input, pipes and gzip files are read by one thread.\n";

/* A part of the fold (fe_cli_table_fold): each column's mean and
   variance and extremes (valid when the column has values). */
typedef struct fe__stats_column {
    fe_meanvar mv;
    double lo, hi;
} fe__stats_column;

typedef struct fe__stats_part {
    size_t k;
    fe__stats_column col[];
} fe__stats_part;

/* The command's own accumulation: the part all the others merge into. */
typedef struct fe__stats_fold {
    fe__stats_part *all;
} fe__stats_fold;

static void fe__stats_start(void *part, const void *config)
{
    fe__stats_part *p = part;
    p->k = *(const size_t *)config;
    for (size_t j = 0; j < p->k; j++) {
        static const fe__stats_column empty = {FE_MEANVAR_EMPTY, 0.0, 0.0};
        p->col[j] = empty;
    }
}

/* Fold n rows of k columns, column by column in runs of FE__STATS_RUN.
   A refused value stops at the first row, in file order, that holds one
   (a later column may refuse an earlier row): the row the
   one-value-at-a-time fold stops at. */
enum { FE__STATS_RUN = 512 };

static int fe__stats_rows(void *part, const void *config, const double *x, size_t n,
                          size_t *done)
{
    fe__stats_part *p = part;
    (void)config;
    double run[FE__STATS_RUN];
    size_t first = n;
    int refused = FE_OK;
    for (size_t j = 0; j < p->k; j++) {
        fe__stats_column *c = &p->col[j];
        for (size_t i0 = 0; i0 < n && i0 < first; i0 += FE__STATS_RUN) {
            size_t m = n - i0 < FE__STATS_RUN ? n - i0 : FE__STATS_RUN, got;
            int rc, empty = c->mv.n == 0;
            for (size_t i = 0; i < m; i++)
                run[i] = x[(i0 + i) * p->k + j];
            rc = fe_meanvar_add_many(&c->mv, run, m, &got);
            for (size_t i = 0; i < got && i < m; i++) {
                if ((empty && i == 0) || run[i] < c->lo)    /* the column's first value */
                    c->lo = run[i];
                if ((empty && i == 0) || run[i] > c->hi)
                    c->hi = run[i];
            }
            if (rc != FE_OK) {
                if (i0 + got < first) {
                    first = i0 + got;
                    refused = rc;
                }
                break;
            }
        }
    }
    *done = first;
    return refused;
}

static int fe__stats_merge(void *ctx, fe_cli_table *t, const void *part, int refused)
{
    fe__stats_part *all = ((fe__stats_fold *)ctx)->all;
    const fe__stats_part *p = part;
    for (size_t j = 0; j < p->k && refused == FE_OK; j++) {
        fe__stats_column *a = &all->col[j];
        const fe__stats_column *b = &p->col[j];
        if (b->mv.n == 0)
            continue;
        if (a->mv.n == 0 || b->lo < a->lo)
            a->lo = b->lo;
        if (a->mv.n == 0 || b->hi > a->hi)
            a->hi = b->hi;
        refused = fe_meanvar_merge(&a->mv, &b->mv);
    }
    if (refused == FE_OK)
        return 0;
    fe_cli_progress_done(t);
    fprintf(stderr, "foldest stats: %s:%zu: %s\n", t->name, t->line, fe_strerror(refused));
    return FE_CLI_INPUT;
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
    fe__stats_fold fold = {NULL};
    fe_cli_parts parts = {0, 0, NULL, fe__stats_start, fe__stats_rows, fe__stats_merge};
    const fe__stats_column *col;

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
    parts.size = sizeof(fe__stats_part) + k * sizeof(fe__stats_column);
    parts.config = &k;
    fold.all = malloc(parts.size);
    if (fold.all == NULL)
        goto out_of_memory;
    fe__stats_start(fold.all, &k);
    col = fold.all->col;
    rc = fe_cli_table_fold(&t, cols, k, threads, &parts, &fold, err, sizeof err);
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
            fe_cli_json_number(stdout, fe_meanvar_mean(&col[j].mv));
            printf(", \"stddev\": ");
            fe_cli_json_number(stdout, fe_meanvar_stddev(&col[j].mv));
            printf(", \"min\": ");
            fe_cli_json_number(stdout, col[j].lo);
            printf(", \"max\": ");
            fe_cli_json_number(stdout, col[j].hi);
            printf("}");
        }
        printf("]}\n");
    } else {
        printf("%s: %zu rows\n%-24s %15s %15s %15s %15s\n", t.name, t.rows, "column",
               "mean", "stddev", "min", "max");
        for (size_t j = 0; j < k; j++)
            printf("%-24.24s %15.6g %15.6g %15.6g %15.6g\n", t.names[cols[j]],
                   fe_meanvar_mean(&col[j].mv), fe_meanvar_stddev(&col[j].mv), col[j].lo,
                   col[j].hi);
    }
    rc = FE_CLI_OK;
    goto done;
out_of_memory:
    fprintf(stderr, "foldest stats: out of memory\n");
    rc = FE_CLI_IO;
done:
    free(cols);
    free(fold.all);
    fe_cli_table_close(&t);
    return rc;
}
/* Summarise columns ends here */
