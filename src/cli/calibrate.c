/* SPDX-License-Identifier: MIT */
/* Tangled from literate/calibrate.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/calibrate.org::Calibrate Includes and Help][Calibrate Includes and Help]] */
#include "cli.h"

#include <errno.h>
#include <math.h>
#include <sys/stat.h>
#include <stdlib.h>
#include <string.h>

/* The help in parts: C11 compilers need only take strings of 4095 bytes. */
static const char *const fe__calibrate_help[] = {
    "usage: foldest calibrate [--model sphere|axial|ellipsoid] [--columns a,b,c]\n"
    "                         [--skip N] [--json] [--trace] [--apply OUT.csv]\n"
    "                         [--field F] [--export ardupilot|c|json]\n"
    "                         [--mgauss K] [--static [--window N] [--still-sd E]\n"
    "                         [--gyro a,b,c --max-rate R]] [--robust [--robust-k K]]\n"
    "                         [--report DIR] [--threads N]\n"
    "                         FILE.csv|-\n"
    "\n"
    "Calibrate a three-axis magnetometer or accelerometer: find the offset b and\n"
    "the matrix M such that y = M (x - b) lies on the unit sphere, from samples\n"
    "taken in many orientations (a constant field, or gravity at rest).\n"
    "\n"
    "  --model M       sphere (offset, radius), axial (offset, three axis\n"
    "                  scales; the default) or ellipsoid (offset and a symmetric\n"
    "                  matrix: soft iron, cross-axis terms)\n"
    "  --columns a,b,c the three columns, by header name, unique prefix or number\n"
    "                  from 1; default: the table's columns when it has three\n"
    "  --skip N        skip N lines before the header (default: found\n"
    "                  automatically after metadata lines)\n"
    "  --threads N     read a regular file on N threads (default: the\n"
    "                  processors online); it is cut the same way for any N,\n"
    "                  so the result is the same for any N; standard input,\n"
    "                  pipes and gzip files are read by one thread\n"
    "  --json          print one JSON object: model, n, offset, offset_se,\n"
    "                  offset_se_iid, se_blocks, matrix (3x3, to the unit\n"
    "                  sphere), matrix_se, radius, axes, params,\n"
    "                  params_se, rms_percent, rms_radial_percent, coverage,\n"
    "                  coverage_fold, planarity, extent_lo, extent_hi,\n"
    "                  iterations, algebraic, refusal\n"
    "  --trace         print the Gauss-Newton iterations on standard error\n"
    "  --apply OUT.csv write the calibrated samples R M (x - b) (R: the fitted\n"
    "                  field, or F with --field) to OUT.csv; needs a file, not\n"
    "                  standard input\n"
    ,
    "  --field F       the known field: calibrated samples have magnitude F\n"
    "                  (9.80665 for an accelerometer in m/s^2, the local Earth\n"
    "                  field for a magnetometer); the report gives the fitted\n"
    "                  field R against F (gain R/F, sensor units per unit of F)\n"
    "                  and --json adds field, field_matrix (F M) and gain\n"
    "  --export FORMAT print the calibration for firmware instead of the report:\n"
    "                  ardupilot: a parameter file, COMPASS_OFS_X/Y/Z (= -b, in\n"
    "                  milligauss: ArduPilot adds its offsets), COMPASS_DIA_X/Y/Z\n"
    "                  and COMPASS_ODI_X/Y/Z (the symmetric matrix F M, applied\n"
    "                  after the offsets; --field in milligauss); c: a C header\n"
    "                  with the offset b and the matrix F M as float arrays,\n"
    "                  y = M (x - b); json: as --json\n"
    "  --mgauss K      milligauss per sensor unit for --export ardupilot\n"
    "                  (default 1: the samples are in milligauss; 1000 for gauss)\n"
    "  --static        fit the still segments only (an accelerometer at rest, as\n"
    "                  in a six-pose calibration): a window of N samples is still\n"
    "                  when the standard deviation of |x| over it is at most E\n"
    "                  times its mean (and, with --gyro, no angular rate in it\n"
    "                  exceeds R); every sample of a still window is kept, the\n"
    "                  others are left out and counted (static_kept,\n"
    "                  static_left_out); --apply still writes every sample\n"
    "  --window N      the still window, in samples (default 50)\n"
    "  --still-sd E    the relative standard deviation of a still window\n"
    "                  (default 0.002)\n"
    "  --gyro a,b,c    gyroscope columns for --static, tested with --max-rate R\n"
    "                  (in the gyroscope's units; default 0: not tested)\n"
    "  --robust        reject outliers: samples whose radial error |y| - 1 is\n"
    "                  beyond K robust standard deviations (1.4826 times the\n"
    "                  median |error|) of the first fit, and fit again from the\n"
    "                  kept samples' moments (two more passes: robust_rejected);\n"
    "                  from standard input the samples cannot be read again, so\n"
    "                  they are only counted against provisional fits made while\n"
    "                  folding (robust_flagged), and not rejected\n"
    "  --robust-k K    the rejection threshold in robust standard deviations\n"
    "                  (default 5)\n"
    "  --report DIR    write DIR/report.md: the report, with plots (gnuplot, PNG)\n"
    "                  of the raw and calibrated samples in three projections\n"
    "                  and on the sphere, the radial errors' histogram and the\n"
    "                  coverage map, and their data; needs a file\n"
    "\n"
    ,
    "The samples are folded once into 35 moments; the fit never reads them again.\n"
    "The moments are also kept for 8 to 16 consecutive blocks in time, and the\n"
    "standard errors come from the blocks' spread (batch means): they hold for\n"
    "correlated samples, as a sensor turned by hand gives (offset_se_iid: what\n"
    "independent samples would give).\n"
    "From a file a second pass counts the coverage exactly from the fitted centre\n"
    "(100 equal-area regions), measures the radial RMS error, and writes --apply.\n"
    "rms_percent is 50 sqrt(S/n), S the sum of (1 - |y|^2)^2: the RMS radial\n"
    "error to first order.  When the data are so far from a sphere that the\n"
    "sphere model's Gauss-Newton fit runs off to infinity, the sphere is the\n"
    "algebraic least-squares sphere, and the output says so (algebraic: true).\n"
    "\n"
    "The fit is refused (exit status 1, with the reason) when the samples are\n"
    "too few, lie near a plane, cover one side of the sphere only, or give a\n"
    "quadric that is not an ellipsoid.  A malformed field gives\n"
    "FILE:LINE:COLUMN: message and exit status 3, with no output.  Exit status:\n"
    "0 success, 1 refused, 2 usage, 3 malformed input, 4 input/output error.\n"
    "Progress is shown on standard error for large files when it is a terminal.\n",
    NULL};

static void fe__calibrate_usage(FILE *out)
{
    for (int k = 0; fe__calibrate_help[k] != NULL; k++)
        fputs(fe__calibrate_help[k], out);
}
/* Calibrate Includes and Help ends here */
/* [[file:../../literate/calibrate.org::Calibrate Options][Calibrate Options]] */
enum fe__calibrate_export { FE__EXPORT_NONE, FE__EXPORT_ARDUPILOT, FE__EXPORT_C };

typedef struct fe__calibrate_args {
    const char *path, *apply, *report;
    char *columns;
    long skip;
    double field;               /* 0: not given */
    double mgauss;              /* milligauss per sensor unit */
    int still;                  /* --static */
    int robust;                 /* --robust */
    double robust_k;
    char *gyro;                 /* --gyro columns, or NULL */
    fe_still_options still_opt;
    int export_format;          /* fe__calibrate_export */
    int json, trace;
    int threads;                /* --threads: parsing threads for every pass */
    fe_sphere_model model;
} fe__calibrate_args;

/* Parse argv; FE_CLI_OK, or an exit status after printing why (-1 for
   --help, printed). */
static const fe_cli_option fe__calibrate_options[] = {
    {"--model", 1}, {"--columns", 1}, {"--apply", 1}, {"--skip", 1}, {"--json", 0},
    {"--trace", 0}, {"--field", 1}, {"--export", 1}, {"--mgauss", 1}, {"--static", 0}, {"--window", 1},
    {"--still-sd", 1}, {"--gyro", 1}, {"--max-rate", 1}, {"--robust", 0},
    {"--robust-k", 1}, {"--report", 1}, {"--threads", 1}, {NULL, 0}};

/* The number after option `name`: finite, above 0 (or at least 0 when
   zero_ok); FE_CLI_OK, or FE_CLI_USAGE after saying why. */
static int fe__calibrate_number(const char *name, const char *text, int zero_ok, double *out)
{
    char err[512];
    double v;
    if (fe_cli_parse_double(name, text, &v, err, sizeof err) != FE_CLI_OK) {
        fprintf(stderr, "foldest calibrate: %s\n", err);
        return FE_CLI_USAGE;
    }
    if (!isfinite(v) || !(zero_ok ? v >= 0.0 : v > 0.0)) {
        fprintf(stderr, "foldest calibrate: %s: a finite number, %s\n", name,
                zero_ok ? "at least 0" : "above 0");
        return FE_CLI_USAGE;
    }
    *out = v;
    return FE_CLI_OK;
}

static int fe__calibrate_parse(int argc, char **argv, fe__calibrate_args *a)
{
    char err[512];
    int rc;
    memset(a, 0, sizeof *a);
    a->skip = -1;
    a->mgauss = 1.0;
    a->still_opt = fe_still_default_options();
    a->robust_k = 5.0;
    a->model = FE_FIT_AXIAL;
    a->threads = fe_cli_threads_default();
    rc = fe_cli_options("calibrate", fe__calibrate_options, &argc, &argv);
    if (rc != FE_CLI_OK)
        return rc;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            fe__calibrate_usage(stdout);
            return -1;
        } else if (strcmp(argv[i], "--json") == 0) {
            a->json = 1;
        } else if (strcmp(argv[i], "--trace") == 0) {
            a->trace = 1;
        } else if (strcmp(argv[i], "--model") == 0 && i + 1 < argc) {
            if (fe_sphere_model_parse(argv[++i], &a->model) != FE_OK) {
                fprintf(stderr, "foldest calibrate: --model: '%s' is not sphere, axial or ellipsoid\n",
                        argv[i]);
                return FE_CLI_USAGE;
            }
        } else if (strcmp(argv[i], "--field") == 0 && i + 1 < argc) {
            if (fe__calibrate_number("--field", argv[++i], 0, &a->field) != FE_CLI_OK)
                return FE_CLI_USAGE;
        } else if (strcmp(argv[i], "--export") == 0 && i + 1 < argc) {
            const char *fmt = argv[++i];
            if (strcmp(fmt, "ardupilot") == 0)
                a->export_format = FE__EXPORT_ARDUPILOT;
            else if (strcmp(fmt, "c") == 0)
                a->export_format = FE__EXPORT_C;
            else if (strcmp(fmt, "json") == 0)
                a->json = 1;
            else {
                fprintf(stderr, "foldest calibrate: --export: '%s' is not ardupilot, c or json\n",
                        fmt);
                return FE_CLI_USAGE;
            }
        } else if (strcmp(argv[i], "--report") == 0 && i + 1 < argc) {
            a->report = argv[++i];
        } else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) {
            if (fe_cli_parse_threads(argv[++i], &a->threads, err, sizeof err) != FE_CLI_OK) {
                fprintf(stderr, "foldest calibrate: %s\n", err);
                return FE_CLI_USAGE;
            }
        } else if (strcmp(argv[i], "--robust") == 0) {
            a->robust = 1;
        } else if (strcmp(argv[i], "--robust-k") == 0 && i + 1 < argc) {
            if (fe__calibrate_number("--robust-k", argv[++i], 0, &a->robust_k) != FE_CLI_OK)
                return FE_CLI_USAGE;
        } else if (strcmp(argv[i], "--static") == 0) {
            a->still = 1;
        } else if (strcmp(argv[i], "--gyro") == 0 && i + 1 < argc) {
            a->gyro = argv[++i];
        } else if (strcmp(argv[i], "--window") == 0 && i + 1 < argc) {
            long w;
            int bad = fe_cli_parse_long("--window", argv[++i], &w, err, sizeof err) != FE_CLI_OK;
            if (bad || w < 2 || w > 1000000) {
                fprintf(stderr, "foldest calibrate: %s\n",
                        bad ? err : "--window: from 2 to 1000000 samples");
                return FE_CLI_USAGE;
            }
            a->still_opt.window = (size_t)w;
        } else if ((strcmp(argv[i], "--still-sd") == 0 || strcmp(argv[i], "--max-rate") == 0)
                   && i + 1 < argc) {
            const char *name = argv[i];
            double v;
            if (fe__calibrate_number(name, argv[++i], 1, &v) != FE_CLI_OK)
                return FE_CLI_USAGE;
            if (name[2] == 's')
                a->still_opt.max_rel_sd = v;
            else
                a->still_opt.max_rate = v;
        } else if (strcmp(argv[i], "--mgauss") == 0 && i + 1 < argc) {
            if (fe__calibrate_number("--mgauss", argv[++i], 0, &a->mgauss) != FE_CLI_OK)
                return FE_CLI_USAGE;
        } else if (strcmp(argv[i], "--columns") == 0 && i + 1 < argc) {
            a->columns = argv[++i];
        } else if (strcmp(argv[i], "--apply") == 0 && i + 1 < argc) {
            a->apply = argv[++i];
        } else if (strcmp(argv[i], "--skip") == 0 && i + 1 < argc) {
            int bad = fe_cli_parse_long("--skip", argv[++i], &a->skip, err, sizeof err) != FE_CLI_OK;
            if (bad || a->skip < 0) {
                fprintf(stderr, "foldest calibrate: %s\n", bad ? err : "--skip: negative");
                return FE_CLI_USAGE;
            }
        } else if (argv[i][0] == '-' && argv[i][1] != '\0') {
            fprintf(stderr, "foldest calibrate: unknown option or missing value '%s'\n",
                    argv[i]);
            fe__calibrate_usage(stderr);
            return FE_CLI_USAGE;
        } else if (a->path == NULL) {
            a->path = argv[i];
        } else {
            fprintf(stderr, "foldest calibrate: one input file, please\n");
            return FE_CLI_USAGE;
        }
    }
    if (a->path == NULL) {
        fe__calibrate_usage(stderr);
        return FE_CLI_USAGE;
    }
    if (a->export_format != FE__EXPORT_NONE && a->json) {
        fprintf(stderr, "foldest calibrate: one output: --export %s or --json\n",
                a->export_format == FE__EXPORT_C ? "c" : "ardupilot");
        return FE_CLI_USAGE;
    }
    if (!a->still && (a->gyro != NULL || a->still_opt.max_rate > 0.0)) {
        fprintf(stderr, "foldest calibrate: --gyro and --max-rate go with --static\n");
        return FE_CLI_USAGE;
    }
    if (a->report != NULL && strcmp(a->path, "-") == 0) {
        fprintf(stderr, "foldest calibrate: --report plots the samples, read again after the "
                        "fit: give a file, not standard input\n");
        return FE_CLI_USAGE;
    }
    if (a->apply != NULL && strcmp(a->path, "-") == 0) {
        fprintf(stderr, "foldest calibrate: --apply reads the input twice (fit, then "
                        "calibrate): give a file, not standard input\n");
        return FE_CLI_USAGE;
    }
    return FE_CLI_OK;
}
/* Calibrate Options ends here */
/* [[file:../../literate/calibrate.org::Choose the columns and fold the samples][Choose the columns and fold the samples]] */
static int fe__calibrate_columns(fe_cli_table *t, char *spec, size_t cols[3])
{
    char err[2048], *names[4];
    int n;
    if (spec == NULL && cols == NULL)
        return FE_CLI_OK;
    if (spec == NULL) {
        if (t->ncols == 3) {
            for (size_t j = 0; j < 3; j++)
                cols[j] = j;
            return FE_CLI_OK;
        }
        fprintf(stderr, "foldest calibrate: %s has %zu columns: name three with "
                        "--columns a,b,c; the columns are:", t->name, t->ncols);
        for (size_t j = 0; j < t->ncols; j++)
            fprintf(stderr, "%s '%s'", j ? "," : "", t->names[j]);
        fputc('\n', stderr);
        return FE_CLI_USAGE;
    }
    n = fe_cli_split_list(spec, names, 4);
    if (n != 3) {
        fprintf(stderr, "foldest calibrate: --columns needs three columns, a,b,c\n");
        return FE_CLI_USAGE;
    }
    for (int j = 0; j < 3; j++)
        if (fe_cli_table_column(t, names[j], &cols[j], err, sizeof err) != FE_CLI_OK) {
            fprintf(stderr, "foldest calibrate: %s\n", err);
            return FE_CLI_USAGE;
        }
    return FE_CLI_OK;
}

/* --robust from standard input: count the samples far outside the bulk
   of a provisional fit, refitted each time the blocks double. */
typedef struct fe__calibrate_flags {
    fe_sphere_model model;
    double k;
    uint64_t len_seen, flagged;
    int have;
    fe_sphere_fit fit;
    fe_radial_hist hist;
} fe__calibrate_flags;

static void fe__calibrate_flag(fe__calibrate_flags *fl, const fe_quadric_blocks *q,
                               const double y[3])
{
    double e;
    if (q->block_len != fl->len_seen && q->all.m[0] >= 512) {
        fl->len_seen = q->block_len;
        fl->have = fe_sphere_fit_moments(&q->all, fl->model, NULL, &fl->fit) == FE_OK;
    }
    if (!fl->have)
        return;
    e = fe_sphere_radial(&fl->fit, y);
    if (fl->hist.n >= 100 && fabs(e) > fl->k * fe_radial_hist_scale(&fl->hist))
        fl->flagged++;
    fe_radial_hist_add(&fl->hist, e);
}

/* What the walks of --robust do with each sample the fit used. */
typedef int fe__calibrate_visit(void *ctx, const double x[3]);

/* A pass's state for its rows, handed in file order by fe_cli_table_each
   (cli.org, "Every core on one file") when the pass has a gate, flags or
   output: the rows may be parsed on several threads, but every sample
   below is folded on the calling thread, in the order of the file, so
   the pass gives the one-thread result bit for bit, the gate's and the
   flags' included. */
typedef struct fe__calibrate_rows {
    size_t ncols;
    fe_still *gate;             /* --static, or NULL */
    int still, ready;           /* the gate's last verdict */
    fe__calibrate_flags *fl;    /* the first pass: --robust from stdin */
    fe_quadric_blocks *q;       /* the first pass: the moments */
    double run[3 * 512];        /* the first pass: samples not yet folded */
    size_t run_line[512], nrun; /* and their lines */
    fe__calibrate_visit *visit; /* the walks: each sample fitted */
    void *ctx;
    struct fe__calibrate_measure *m;   /* the second pass */
    const fe_sphere_scaled *sc;
} fe__calibrate_rows;

/* The rows' state at the start of a pass: every column, the gate (or
   NULL), no verdict held back; the pass fills in what it needs. */
static fe__calibrate_rows fe__calibrate_rows_start(size_t ncols, fe_still *gate)
{
    static const fe__calibrate_rows blank;
    fe__calibrate_rows r = blank;
    r.ncols = ncols;
    r.gate = gate;
    r.still = r.ready = 1;
    return r;
}

/* A row through the gate: 1 when *y is a sample to use (its verdict in
   r->still), 0 when the gate holds it, or the library's error. */
static int fe__calibrate_gate(fe__calibrate_rows *r, const double *x, double y[3])
{
    if (r->gate == NULL) {
        memcpy(y, x, 3 * sizeof *y);
        return FE_OK;
    }
    return fe_still_push(r->gate, x, r->ncols == 6 ? x + 3 : NULL, y, &r->still, &r->ready);
}

/* A sample the library refused, at its line. */
static int fe__calibrate_refused_at(fe_cli_table *t, int rc)
{
    fe_cli_progress_done(t);
    fprintf(stderr, "foldest calibrate: %s:%zu:1: %s\n", t->name, t->line, fe_strerror(rc));
    return FE_CLI_INPUT;
}

/* Fold the samples waiting in the run; a refused one is reported at the
   line it came with. */
static int fe__calibrate_fold_run(fe__calibrate_rows *r, fe_cli_table *t)
{
    size_t done;
    int rc = fe_quadric_blocks_add_many(r->q, r->run, r->nrun, &done);
    r->nrun = 0;
    if (rc == FE_OK)
        return 0;
    t->line = r->run_line[done];
    return fe__calibrate_refused_at(t, rc);
}

static int fe__calibrate_fold_row(void *ctx, fe_cli_table *t, const double *x)
{
    fe__calibrate_rows *r = ctx;
    double y[3];
    int rc = fe__calibrate_gate(r, x, y);
    if (rc == FE_OK && r->ready && r->still && r->fl != NULL) {
        rc = fe_quadric_blocks_add(r->q, y);
        if (rc == FE_OK)
            fe__calibrate_flag(r->fl, r->q, y);
    } else if (rc == FE_OK && r->ready && r->still) {
        memcpy(r->run + 3 * r->nrun, y, sizeof y);
        r->run_line[r->nrun++] = t->line;
        if (r->nrun == sizeof r->run_line / sizeof r->run_line[0]
            && (rc = fe__calibrate_fold_run(r, t)) != 0)
            return rc;
    }
    if (rc != FE_OK)
        return fe__calibrate_refused_at(t, rc);
    fe_cli_progress(t);
    return 0;
}

/* Without a gate or flags the rows are the samples, and the moments take
   them as the threads parsed them, a batch at a time, in file order
   (fe_cli_table_fold, in_order: the blocks follow the count of samples). */
static int fe__calibrate_moments_rows(void *ctx, const void *config, const double *x, size_t n,
                                      size_t *done)
{
    (void)config;
    return fe_quadric_blocks_add_many(ctx, x, n, done);
}

static int fe__calibrate_moments_refused(void *ctx, fe_cli_table *t, const void *part, int rc)
{
    (void)ctx;
    (void)part;
    return fe__calibrate_refused_at(t, rc);
}

/* Fold the samples, or with a gate (--static) the still ones, which it
   hands back `window` samples late, and the rest at the end; flag them
   when asked. */
static int fe__calibrate_fold(fe_cli_table *t, const size_t cols[6], size_t ncols, int threads,
                              fe_still *gate, fe__calibrate_flags *fl, fe_quadric_blocks *q)
{
    char err[1024];
    double y[3];
    int rc, still = 1;
    fe__calibrate_rows r = fe__calibrate_rows_start(ncols, gate);
    r.fl = fl;
    r.q = q;
    fe_quadric_blocks_init(q);
    if (gate == NULL && fl == NULL && ncols == 3) {
        const fe_cli_parts parts = {1, 0, NULL, NULL, fe__calibrate_moments_rows,
                                    fe__calibrate_moments_refused};
        rc = fe_cli_table_fold(t, cols, 3, threads, &parts, q, err, sizeof err);
    } else {
        rc = fe_cli_table_each(t, cols, ncols, threads, fe__calibrate_fold_row, &r, err,
                               sizeof err);
    }
    /* The samples still waiting come before a malformed row. */
    if ((rc == FE_END || err[0] != '\0') && fe__calibrate_fold_run(&r, t) != 0)
        return FE_CLI_INPUT;
    fe_cli_progress_done(t);
    if (rc != FE_END) {
        if (err[0] != '\0')
            fprintf(stderr, "foldest calibrate: %s\n", err);
        return rc;
    }
    while (gate != NULL && fe_still_flush(gate, y, &still) == FE_OK)
        if (still && (rc = fe_quadric_blocks_add(q, y)) != FE_OK) {
            fprintf(stderr, "foldest calibrate: %s: %s\n", t->name, fe_strerror(rc));
            return FE_CLI_INPUT;
        }
    if (t->rows == 0) {
        fprintf(stderr, "foldest calibrate: %s: no data rows\n", t->name);
        return FE_CLI_INPUT;
    }
    return FE_CLI_OK;
}
/* Choose the columns and fold the samples ends here */
/* [[file:../../literate/calibrate.org::Measure exactly and apply in a second pass][Measure exactly and apply in a second pass]] */
typedef struct fe__calibrate_pass2 {
    int done;                   /* the pass ran */
    int regions;
    double rms_radial_percent;
    int still;                  /* --static: the counts below */
    uint64_t kept, left_out;
    int robust;                 /* 1: rejected, 2: flagged only */
    uint64_t rejected;
    double threshold;           /* |e| beyond it rejected (robust 1) */
    double region_n[FE_QUADRIC_REGIONS];  /* --report: the coverage map */
    double hist[80], hist_lo, hist_w;     /* --report: radial errors, % */
} fe__calibrate_pass2;

/* Read the file again and hand every sample the fit used (all, or the
   gate's still ones) to visit; for --robust.  A sample visit refuses is
   reported at its line; a malformed row (the file changed since the first
   pass) with the reader's message. */
static int fe__calibrate_walk_row(void *ctx, fe_cli_table *t, const double *x)
{
    fe__calibrate_rows *r = ctx;
    double y[3];
    int rc = fe__calibrate_gate(r, x, y);
    if (rc == FE_OK && r->ready && r->still)
        rc = r->visit(r->ctx, y);
    return rc == FE_OK ? 0 : fe__calibrate_refused_at(t, rc);
}

static int fe__calibrate_walk(const fe__calibrate_args *a, const size_t cols[6],
                              size_t ncols, fe_still *gate, fe__calibrate_visit *visit,
                              void *ctx)
{
    char err[1024];
    double y[3];
    fe_cli_table t;
    int rc, still;
    fe__calibrate_rows r = fe__calibrate_rows_start(ncols, gate);
    r.visit = visit;
    r.ctx = ctx;
    rc = fe_cli_table_open(&t, a->path, a->skip, err, sizeof err);
    if (rc != FE_CLI_OK) {
        fprintf(stderr, "foldest calibrate: %s\n", err);
        return rc;
    }
    fe_cli_table_reread(&t);
    if (gate != NULL)
        fe_still_init(gate, &gate->opt, gate->ring, fe_still_workspace(gate->opt.window));
    rc = fe_cli_table_each(&t, cols, ncols, a->threads, fe__calibrate_walk_row, &r, err,
                           sizeof err);
    if (rc == FE_END) {
        rc = FE_OK;
        while (rc == FE_OK && gate != NULL && fe_still_flush(gate, y, &still) == FE_OK)
            if (still)
                rc = visit(ctx, y);
        if (rc == FE_OK) {
            fe_cli_table_close(&t);
            return FE_CLI_OK;
        }
        fprintf(stderr, "foldest calibrate: %s: %s\n", t.name, fe_strerror(rc));
        rc = FE_CLI_INPUT;
    } else if (err[0] != '\0') {
        fprintf(stderr, "foldest calibrate: %s\n", err);
    }
    fe_cli_table_close(&t);
    return rc;
}

/* --robust on a file: the histogram of the radial errors under the first
   fit, then the samples within k robust standard deviations folded anew. */
typedef struct fe__calibrate_robust {
    const fe_sphere_fit *fit;
    fe_radial_hist hist;
    double threshold;
    uint64_t rejected;
    fe_quadric_blocks *q;
} fe__calibrate_robust;

static int fe__calibrate_robust_hist(void *ctx, const double x[3])
{
    fe__calibrate_robust *r = ctx;
    return fe_radial_hist_add(&r->hist, fe_sphere_radial(r->fit, x));
}

static int fe__calibrate_robust_keep(void *ctx, const double x[3])
{
    fe__calibrate_robust *r = ctx;
    if (fabs(fe_sphere_radial(r->fit, x)) > r->threshold) {
        r->rejected++;
        return FE_OK;
    }
    return fe_quadric_blocks_add(r->q, x);
}

/* One sample of the second pass: measured when it was fitted (still, or
   no gate), written in any case. */
enum { FE__CAL_HIST = 80 };

/* What the pass measures of the samples it keeps: a part of a fold
   (fe_cli_table_fold), so that each thread can measure its own batches. */
typedef struct fe__calibrate_tally {
    unsigned char hit[FE_QUADRIC_REGIONS];
    double ss, n;
    double region_n[FE_QUADRIC_REGIONS];  /* --report: samples per region */
    double hist[FE__CAL_HIST];  /* --report: radial errors, % */
} fe__calibrate_tally;

typedef struct fe__calibrate_measure {
    fe__calibrate_tally tally;
    const fe_sphere_fit *fit;
    double hist_lo, hist_w;     /* the histogram's bins (--report) */
    FILE *samples;              /* --report: samples.dat, or NULL */
    unsigned long seen, stride;
    double reject;              /* --robust: |e| beyond it not measured */
    FILE *apply;
} fe__calibrate_measure;

/* Measure one sample the fit kept (m is read, not written); 0 when
   --robust rejects it, unmeasured. */
static int fe__calibrate_tally_add(fe__calibrate_tally *a, const fe__calibrate_measure *m,
                                   const double x[3])
{
    double y[3], len;
    int r;
    if (m->reject > 0.0 && fabs(fe_sphere_radial(m->fit, x)) > m->reject)
        return 0;
    fe_sphere_apply(m->fit, x, y);
    r = fe_quadric_region(y);
    if (r >= 0)
        a->hit[r] = 1;
    len = sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
    a->ss += (len - 1.0) * (len - 1.0);
    a->n += 1.0;
    if (r >= 0)
        a->region_n[r] += 1.0;
    if (m->hist_w > 0.0) {
        double b = floor((100.0 * (len - 1.0) - m->hist_lo) / m->hist_w);
        if (b >= 0.0 && b < FE__CAL_HIST)
            a->hist[(int)b] += 1.0;
    }
    return 1;
}

static void fe__calibrate_one(fe__calibrate_measure *m, const fe_sphere_scaled *sc,
                              const double x[3], int still)
{
    double y[3];
    if (still)
        still = fe__calibrate_tally_add(&m->tally, m, x);
    if (m->samples != NULL && m->seen++ % m->stride == 0) {
        fe_sphere_apply(m->fit, x, y);
        fprintf(m->samples, "%.10g %.10g %.10g %.8g %.8g %.8g %.6g %d\n", x[0], x[1], x[2],
                y[0], y[1], y[2],
                100.0 * (sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]) - 1.0), still);
    }
    if (m->apply != NULL) {
        fe_sphere_scaled_apply(sc, x, y);
        fprintf(m->apply, "%.10g,%.10g,%.10g\n", y[0], y[1], y[2]);
    }
}

/* The pass in parts, when it writes nothing and has no gate: the rows are
   the samples, and they are measured on the threads that parse them. */
static void fe__calibrate_tally_start(void *part, const void *config)
{
    static const fe__calibrate_tally empty;
    (void)config;
    *(fe__calibrate_tally *)part = empty;
}

static int fe__calibrate_tally_rows(void *part, const void *config, const double *x, size_t n,
                                    size_t *done)
{
    for (size_t i = 0; i < n; i++)
        fe__calibrate_tally_add(part, config, x + 3 * i);
    *done = n;
    return FE_OK;
}

static int fe__calibrate_tally_merge(void *ctx, fe_cli_table *t, const void *part, int refused)
{
    fe__calibrate_tally *a = ctx;
    const fe__calibrate_tally *b = part;
    (void)t;
    (void)refused;              /* the rows are never refused */
    for (int r = 0; r < FE_QUADRIC_REGIONS; r++) {
        a->hit[r] |= b->hit[r];
        a->region_n[r] += b->region_n[r];
    }
    a->ss += b->ss;
    a->n += b->n;
    for (int i = 0; i < FE__CAL_HIST; i++)
        a->hist[i] += b->hist[i];
    return 0;
}

static int fe__calibrate_measure_row(void *ctx, fe_cli_table *t, const double *x)
{
    fe__calibrate_rows *r = ctx;
    double y[3];
    int rc = fe__calibrate_gate(r, x, y);
    if (rc != FE_OK)
        return fe__calibrate_refused_at(t, rc);
    if (r->ready)
        fe__calibrate_one(r->m, r->sc, y, r->still);
    fe_cli_progress(t);
    return 0;
}

static int fe__calibrate_second_pass(const fe__calibrate_args *a,
                                     const size_t cols[6], size_t ncols,
                                     fe_still *gate, double reject, size_t rows,
                                     const fe_sphere_fit *fit,
                                     const fe_sphere_scaled *sc,
                                     fe__calibrate_pass2 *out)
{
    char err[1024];
    static const fe__calibrate_measure none;
    fe__calibrate_measure m = none;
    double y[3];
    const char *apply = a->apply;
    fe_cli_output o;
    fe_cli_table table, *t = &table;
    int rc, still = 1;
    fe__calibrate_rows r;

    memset(out, 0, sizeof *out);
    if (strcmp(a->path, "-") == 0)
        return FE_CLI_OK;       /* standard input: no second pass */
    rc = fe_cli_table_open(t, a->path, a->skip, err, sizeof err);
    if (rc != FE_CLI_OK) {
        fprintf(stderr, "foldest calibrate: %s\n", err);
        return rc;
    }
    fe_cli_table_reread(t);
    if (apply != NULL) {
        rc = fe_cli_output_open(&o, apply, err, sizeof err);
        if (rc != FE_CLI_OK) {
            fprintf(stderr, "foldest calibrate: %s\n", err);
            fe_cli_table_close(t);
            return rc;
        }
        fprintf(o.file, "%s_cal,%s_cal,%s_cal\n", t->names[cols[0]],
                t->names[cols[1]], t->names[cols[2]]);
        m.apply = o.file;
    }
    m.reject = reject;
    if (a->report != NULL) {
        char path[4200];
        snprintf(path, sizeof path, "%s/samples.dat", a->report);
        m.samples = fopen(path, "w");
        if (m.samples == NULL) {
            fprintf(stderr, "foldest calibrate: %s: cannot write: %s\n", path, strerror(errno));
            if (apply != NULL)
                fe_cli_output_abort(&o);
            fe_cli_table_close(t);
            return FE_CLI_IO;
        }
        m.stride = rows > 20000 ? (unsigned long)((rows + 19999) / 20000) : 1;
        m.hist_w = 8.0 * fmax(fit->rms_percent, 0.001) / FE__CAL_HIST;
        m.hist_lo = -0.5 * FE__CAL_HIST * m.hist_w;
    }
    if (gate != NULL)
        fe_still_init(gate, &gate->opt, gate->ring, fe_still_workspace(gate->opt.window));
    m.fit = fit;
    r = fe__calibrate_rows_start(ncols, gate);
    r.m = &m;
    r.sc = sc;
    if (gate == NULL && ncols == 3 && m.samples == NULL && m.apply == NULL) {
        const fe_cli_parts parts = {0, sizeof(fe__calibrate_tally), &m, fe__calibrate_tally_start,
                                    fe__calibrate_tally_rows, fe__calibrate_tally_merge};
        rc = fe_cli_table_fold(t, cols, 3, a->threads, &parts, &m.tally, err, sizeof err);
    } else {
        rc = fe_cli_table_each(t, cols, ncols, a->threads, fe__calibrate_measure_row, &r, err,
                               sizeof err);
    }
    fe_cli_progress_done(t);
    if (rc == FE_END)
        while (gate != NULL && fe_still_flush(gate, y, &still) == FE_OK)
            fe__calibrate_one(&m, sc, y, still);
    if (rc != FE_END) {
        if (err[0] != '\0')
            fprintf(stderr, "foldest calibrate: %s\n", err);
        if (apply != NULL)
            fe_cli_output_abort(&o);
        if (m.samples != NULL)
            fclose(m.samples);
        fe_cli_table_close(t);
        return rc;
    }
    if (apply != NULL && fe_cli_output_commit(&o, err, sizeof err) != FE_CLI_OK) {
        fprintf(stderr, "foldest calibrate: %s\n", err);
        if (m.samples != NULL)
            fclose(m.samples);
        fe_cli_table_close(t);
        return FE_CLI_IO;
    }
    out->done = 1;
    for (int r = 0; r < FE_QUADRIC_REGIONS; r++)
        out->regions += m.tally.hit[r];
    memcpy(out->region_n, m.tally.region_n, sizeof out->region_n);
    memcpy(out->hist, m.tally.hist, sizeof out->hist);
    out->hist_lo = m.hist_lo;
    out->hist_w = m.hist_w;
    if (m.samples != NULL && fclose(m.samples) != 0) {
        fprintf(stderr, "foldest calibrate: %s/samples.dat: cannot write\n", a->report);
        fe_cli_table_close(t);
        return FE_CLI_IO;
    }
    out->rms_radial_percent = m.tally.n > 0 ? 100.0 * sqrt(m.tally.ss / m.tally.n) : 0.0;
    fe_cli_table_close(t);
    return FE_CLI_OK;
}
/* Measure exactly and apply in a second pass ends here */
/* [[file:../../literate/calibrate.org::Print a calibration][Print a calibration]] */
static void fe__calibrate_json_array(const double *v, int n)
{
    printf("[");
    for (int k = 0; k < n; k++) {
        printf("%s", k ? ", " : "");
        fe_cli_json_number(stdout, v[k]);
    }
    printf("]");
}

/* `, "key": [[a, b, c], [d, e, f], [g, h, i]]`, a row-major 3 x 3 matrix. */
static void fe__calibrate_json_matrix(const char *key, const double *m)
{
    printf(", \"%s\": [", key);
    for (int i = 0; i < 3; i++) {
        printf("%s", i ? ", " : "");
        fe__calibrate_json_array(m + 3 * i, 3);
    }
    printf("]");
}

/* `, "key": number`, the number as every command writes it (cli.org). */
static void fe__calibrate_json_key(const char *key, double x)
{
    printf(", \"%s\": ", key);
    fe_cli_json_number(stdout, x);
}

static void fe__calibrate_json(const fe_cli_table *t, const fe_sphere_fit *f,
                               const fe_sphere_scaled *sc, double field,
                               int rc, const fe__calibrate_pass2 *p2)
{
    int fitted = rc == FE_OK || f->refusal == FE_SPHERE_HEMISPHERE
                 || f->refusal == FE_SPHERE_COVERAGE;
    printf("{\"file\": ");
    fe_cli_json_string(stdout, t->name);
    printf(", \"model\": \"%s\", \"n\": %llu", fe_sphere_model_name(f->model),
           (unsigned long long)f->n);
    if (fitted && f->iterations > 0 && f->radius > 0.0) {
        printf(", \"offset\": ");
        fe__calibrate_json_array(f->offset, 3);
        printf(", \"offset_se\": ");
        fe__calibrate_json_array(f->se, 3);
        printf(", \"offset_se_iid\": ");
        fe__calibrate_json_array(f->se_iid, 3);
        printf(", \"se_blocks\": %d", f->se_blocks);
        fe__calibrate_json_matrix("matrix_se", f->matrix_se);
        fe__calibrate_json_matrix("matrix", f->matrix);
        fe__calibrate_json_key("radius", f->radius);
        printf(", \"axes\": ");
        fe__calibrate_json_array(f->axes, 3);
        printf(", \"params\": ");
        fe__calibrate_json_array(f->params, f->nparams);
        printf(", \"params_se\": ");
        fe__calibrate_json_array(f->se, f->nparams);
        fe__calibrate_json_key("rms_percent", f->rms_percent);
        if (field > 0.0) {
            fe__calibrate_json_key("field", sc->field);
            fe__calibrate_json_matrix("field_matrix", sc->matrix);
            fe__calibrate_json_key("gain", sc->gain);
        }
    } else {
        printf(", \"offset\": null, \"matrix\": null, \"rms_percent\": null");
    }
    fe__calibrate_json_key("rms_radial_percent", p2->done ? p2->rms_radial_percent : NAN);
    fe__calibrate_json_key("coverage", p2->done ? p2->regions / 100.0 : f->coverage);
    fe__calibrate_json_key("coverage_fold", f->coverage);
    fe__calibrate_json_key("planarity", f->planarity);
    if (f->extent_lo[0] != 0.0 || f->extent_hi[0] != 0.0) {
        printf(", \"extent_lo\": ");
        fe__calibrate_json_array(f->extent_lo, 3);
        printf(", \"extent_hi\": ");
        fe__calibrate_json_array(f->extent_hi, 3);
    }
    if (p2->still)
        printf(", \"static_kept\": %llu, \"static_left_out\": %llu",
               (unsigned long long)p2->kept, (unsigned long long)p2->left_out);
    if (p2->robust == 1) {
        printf(", \"robust_rejected\": %llu", (unsigned long long)p2->rejected);
        fe__calibrate_json_key("robust_threshold_percent", 100.0 * p2->threshold);
    } else if (p2->robust == 2) {
        printf(", \"robust_flagged\": %llu", (unsigned long long)p2->rejected);
    }
    printf(", \"bad_rows\": ");
    fe_cli_json_bad_rows(stdout);
    printf(", \"iterations\": %d, \"algebraic\": %s, \"refusal\": ", f->iterations,
           f->algebraic ? "true" : "false");
    if (rc == FE_OK)
        printf("null");
    else
        fe_cli_json_string(stdout, f->refusal != FE_SPHERE_ACCEPTED
                                       ? fe_sphere_refusal_string(f->refusal)
                                       : fe_strerror(rc));
    printf("}\n");
}

static void fe__calibrate_text(FILE *out, const fe_cli_table *t, const fe_sphere_fit *f,
                               const fe_sphere_scaled *sc, double field,
                               const fe__calibrate_pass2 *p2)
{
    static const char *const axis[3] = {"x", "y", "z"};
    fprintf(out, "%s: %s fit of %llu samples, %d iterations\n", t->name,
           fe_sphere_model_name(f->model), (unsigned long long)f->n, f->iterations);
    if (p2->still)
        fprintf(out, "  static           %llu still samples kept, %llu left out (moving or handled)\n",
               (unsigned long long)p2->kept, (unsigned long long)p2->left_out);
    if (p2->robust == 1)
        fprintf(out, "  robust           %llu outliers rejected (radial error beyond %.3g %% of the\n"
               "                   field), fitted again from the kept samples\n",
               (unsigned long long)p2->rejected, 100.0 * p2->threshold);
    else if (p2->robust == 2)
        fprintf(out, "  robust           %llu outliers flagged against provisional fits; standard\n"
               "                   input cannot be read again: none rejected\n",
               (unsigned long long)p2->rejected);
    fprintf(out, "  offset b         ");
    for (int j = 0; j < 3; j++)
        fprintf(out, "  %s %.6g +- %.2g", axis[j], f->offset[j], f->se[j]);
    fprintf(out, "\n  matrix M (y = M (x - b) on the unit sphere), +- standard errors\n");
    for (int i = 0; i < 3; i++)
        fprintf(out, "      %14.7g %14.7g %14.7g    +- %9.2g %9.2g %9.2g\n", f->matrix[3 * i],
               f->matrix[3 * i + 1], f->matrix[3 * i + 2], f->matrix_se[3 * i],
               f->matrix_se[3 * i + 1], f->matrix_se[3 * i + 2]);
    if (f->se_blocks > 0)
        fprintf(out, "  errors           from the spread of %d blocks in time (batch means): the\n"
               "                   offsets' are %.2g, %.2g, %.2g times what independent\n"
               "                   samples would give\n", f->se_blocks, f->se[0] / f->se_iid[0],
               f->se[1] / f->se_iid[1], f->se[2] / f->se_iid[2]);
    fprintf(out, "  field            %.6g (semi-axes %.6g %.6g %.6g)\n", f->radius, f->axes[0],
           f->axes[1], f->axes[2]);
    if (field > 0.0) {
        fprintf(out, "  known field      F = %.6g: the fitted field is %.6g F (gain %.6g sensor\n"
               "                   units per unit of F); calibrated samples y = F M (x - b)\n",
               sc->field, sc->gain, sc->gain);
        fprintf(out, "  matrix F M\n");
        for (int i = 0; i < 3; i++)
            fprintf(out, "      %14.7g %14.7g %14.7g\n", sc->matrix[3 * i], sc->matrix[3 * i + 1],
                   sc->matrix[3 * i + 2]);
    }
    if (f->model != FE_FIT_ELLIPSOID) {
        fprintf(out, "  scales          ");
        for (int k = 3; k < f->nparams; k++)
            fprintf(out, "  %.6g +- %.2g", f->params[k], f->se[k]);
        fprintf(out, "\n");
    }
    if (f->algebraic)
        fprintf(out, "  method           the algebraic least-squares sphere: Schmidt's residual\n"
               "                   has no finite minimum on these data, which are far from\n"
               "                   a sphere (try --model ellipsoid)\n");
    fprintf(out, "  rms residual     %.3f %% of the field", f->rms_percent);
    if (p2->done)
        fprintf(out, " (radial, exact: %.3f %%)", p2->rms_radial_percent);
    fprintf(out, "\n  coverage         %d %% of 100 equal-area regions%s\n",
           p2->done ? p2->regions : (int)lround(100 * f->coverage),
           p2->done ? "" : " (estimated in the fold)");
    fprintf(out, "  extents          x [%.2f, %.2f]  y [%.2f, %.2f]  z [%.2f, %.2f]\n",
           f->extent_lo[0], f->extent_hi[0], f->extent_lo[1], f->extent_hi[1],
           f->extent_lo[2], f->extent_hi[2]);
}

/* --export ardupilot: a parameter file as ArduPilot's tools load it (NAME
   VALUE, # comments); --export c: a header. */
static void fe__calibrate_export(const fe__calibrate_args *a, const fe_cli_table *t,
                                 const fe_sphere_fit *f, const fe_sphere_scaled *sc)
{
    static const char xyz[3] = {'X', 'Y', 'Z'};
    if (a->export_format == FE__EXPORT_ARDUPILOT) {
        fe_sphere_ardupilot ap;
        (void)fe_sphere_to_ardupilot(f, a->field, a->mgauss, &ap);  /* checked args */
        printf("# foldest calibrate: %s, %s fit of %llu samples, rms %.3f %%\n", t->name,
               fe_sphere_model_name(f->model), (unsigned long long)f->n, f->rms_percent);
        printf("# ArduPilot corrects h (milligauss) as mat (h + OFS); %g mG per sensor unit;\n"
               "# corrected field %.6g mG%s\n", a->mgauss,
               a->field > 0.0 ? a->field : a->mgauss * f->radius,
               a->field > 0.0 ? " (--field)" : " (the fitted field)");
        for (int j = 0; j < 3; j++)
            printf("COMPASS_OFS_%c %.9g\n", xyz[j], ap.ofs[j]);
        for (int j = 0; j < 3; j++)
            printf("COMPASS_DIA_%c %.9g\n", xyz[j], ap.dia[j]);
        for (int j = 0; j < 3; j++)
            printf("COMPASS_ODI_%c %.9g\n", xyz[j], ap.odi[j]);
        return;
    }
    printf("/* foldest calibrate: %s, %s fit of %llu samples, rms %.3f %% */\n", t->name,
           fe_sphere_model_name(f->model), (unsigned long long)f->n, f->rms_percent);
    printf("/* Calibrated sample: y = FOLDEST_CAL_MATRIX (x - FOLDEST_CAL_OFFSET),\n"
           "   |y| = FOLDEST_CAL_FIELD (%s). */\n",
           a->field > 0.0 ? "the known field, --field" : "the fitted field, sensor units");
    printf("#ifndef FOLDEST_CAL_H\n#define FOLDEST_CAL_H\n");
    /* %#.9g keeps the decimal point: 1 prints as 1.00000000, and 1.f is a
       float literal where 1f is not; nine digits round-trip a float. */
    printf("static const float FOLDEST_CAL_FIELD = %#.9gf;\n", sc->field);
    printf("static const float FOLDEST_CAL_OFFSET[3] = {%#.9gf, %#.9gf, %#.9gf};\n",
           sc->offset[0], sc->offset[1], sc->offset[2]);
    printf("static const float FOLDEST_CAL_MATRIX[3][3] = {\n");
    for (int i = 0; i < 3; i++)
        printf("    {%#.9gf, %#.9gf, %#.9gf}%s\n", sc->matrix[3 * i], sc->matrix[3 * i + 1],
               sc->matrix[3 * i + 2], i < 2 ? "," : "");
    printf("};\n#endif\n");
}

static void fe__calibrate_refusal(const fe_cli_table *t, const fe_sphere_fit *f, int rc)
{
    fprintf(stderr, "foldest calibrate: %s: %s fit refused: %s\n", t->name,
            fe_sphere_model_name(f->model),
            f->refusal != FE_SPHERE_ACCEPTED ? fe_sphere_refusal_string(f->refusal)
                                             : fe_strerror(rc));
    fprintf(stderr, "  %llu samples, coverage about %.0f %%, planarity %.3g",
            (unsigned long long)f->n, 100 * f->coverage, f->planarity);
    if (f->refusal == FE_SPHERE_HEMISPHERE)
        fprintf(stderr, "; the samples reach x [%.2f, %.2f]  y [%.2f, %.2f]  z [%.2f, %.2f]"
                        " of the half-widths about the centre",
                f->extent_lo[0], f->extent_hi[0], f->extent_lo[1], f->extent_hi[1],
                f->extent_lo[2], f->extent_hi[2]);
    fputc('\n', stderr);
}

static int fe__calibrate_trace(const fe_sphere_iteration *it, void *ctx)
{
    (void)ctx;
    fprintf(stderr, "iteration %2d: cost %.10g, trial %.10g, lambda %.3g, step %.3g%s\n",
            it->iteration, it->cost, it->trial_cost, it->lambda, it->step,
            it->accepted ? "" : " (rejected)");
    return 0;
}
/* Print a calibration ends here */
/* [[file:../../literate/calibrate.org::Write the report][Write the report]] */
static const char *const fe__calibrate_report_files[] = {
    "report.md", "plots.gp", "samples.dat", "radial.dat", "coverage.dat", "raw.png",
    "calibrated.png", "sphere.png", "radial.png", "coverage.png", NULL};

/* Make the folder (or take it as it is) and register its files. */
static int fe__calibrate_report_dir(const char *dir)
{
    char path[4200];
    int made = mkdir(dir, 0777) == 0;
    if (!made && errno != EEXIST) {
        fprintf(stderr, "foldest calibrate: %s: cannot create: %s\n", dir, strerror(errno));
        return FE_CLI_IO;
    }
    for (int k = 0; fe__calibrate_report_files[k] != NULL; k++) {
        snprintf(path, sizeof path, "%s/%s", dir, fe__calibrate_report_files[k]);
        fe_cli_pending_add(path, 0);
    }
    if (made)
        fe_cli_pending_add(dir, 1);
    return FE_CLI_OK;
}

static int fe__calibrate_gnuplot(char *const argv[])
{
    return fe_cli_spawn(argv);
}

/* The histogram, the coverage map, the page and the script; then gnuplot. */
static int fe__calibrate_report(const fe__calibrate_args *a, const fe_cli_table *t,
                                const size_t cols[6], const fe_sphere_fit *f,
                                const fe_sphere_scaled *sc, const fe__calibrate_pass2 *p2)
{
    char path[4200];
    char *const version[] = {"gnuplot", "--version", NULL};
    int plots = fe__calibrate_gnuplot(version) == 0, bad;
    FILE *o;

    snprintf(path, sizeof path, "%s/radial.dat", a->report);
    if ((o = fopen(path, "w")) == NULL)
        goto fail;
    for (int k = 0; k < 80; k++)
        fprintf(o, "%.6g %.0f\n", p2->hist_lo + (k + 0.5) * p2->hist_w, p2->hist[k]);
    if (fclose(o) != 0)
        goto fail;
    snprintf(path, sizeof path, "%s/coverage.dat", a->report);
    if ((o = fopen(path, "w")) == NULL)
        goto fail;
    for (int band = 0; band < 10; band++)       /* a row per band of z */
        for (int sector = 0; sector < 10; sector++)
            fprintf(o, "%.0f%c", p2->region_n[10 * band + sector], sector < 9 ? ' ' : '\n');
    if (fclose(o) != 0)
        goto fail;

    snprintf(path, sizeof path, "%s/report.md", a->report);
    if ((o = fopen(path, "w")) == NULL)
        goto fail;
    fprintf(o, "# foldest calibrate report\n\n"
               "Columns `%s`, `%s`, `%s` of `%s`.\n\n```\n", t->names[cols[0]],
            t->names[cols[1]], t->names[cols[2]], t->name);
    fe__calibrate_text(o, t, f, sc, a->field, p2);
    fprintf(o, "```\n\n");
    if (!plots)
        fprintf(o, "(gnuplot is not installed: no plots.  `gnuplot plots.gp` in this folder "
                   "draws them where it is.)\n\n");
    fprintf(o, "## Raw samples\n\n%s"
               "The samples as recorded, in three planes: an ellipse off the origin is hard "
               "iron (the offset) and soft iron (the matrix).%s\n\n",
            plots ? "![raw samples](raw.png)\n\n" : "",
            p2->still ? "  Grey: left out by --static." : "");
    fprintf(o, "## Calibrated samples\n\n%s%s"
               "M (x - b) in the same planes and on the sphere, in units of the field: on "
               "the unit circle and sphere when the calibration is right.\n\n",
            plots ? "![calibrated samples](calibrated.png)\n\n" : "",
            plots ? "![on the sphere](sphere.png)\n\n" : "");
    fprintf(o, "## Radial error\n\n%s"
               "The histogram of |M (x - b)| - 1 of the fitted samples, in per cent of the "
               "field (RMS %.3f %%).\n\n",
            plots ? "![radial error](radial.png)\n\n" : "", p2->rms_radial_percent);
    fprintf(o, "## Coverage\n\n%s"
               "The fitted samples in the 100 equal-area regions of the sphere (rows: 10 "
               "bands of z from -1 to 1; columns: 10 sectors of 36 degrees of longitude); "
               "%d regions have samples.  Empty regions are orientations the sensor never "
               "took.\n\n",
            plots ? "![coverage](coverage.png)\n\n" : "", p2->regions);
    fprintf(o, "## Data\n\n"
               "- `samples.dat`: raw x y z, calibrated x y z (units of the field), radial "
               "error in per cent, 1 fitted or 0 left out; every sample up to 20000, else "
               "every k-th.\n- `radial.dat`: bin centre in per cent, samples.\n"
               "- `coverage.dat`: 10 rows (bands of z) of 10 counts (sectors).\n"
               "- `plots.gp`: `gnuplot plots.gp` in this folder draws the plots again.\n");
    bad = ferror(o);
    if (fclose(o) != 0 || bad)
        goto fail;

    snprintf(path, sizeof path, "%s/plots.gp", a->report);
    if ((o = fopen(path, "w")) == NULL)
        goto fail;
    fprintf(o, "# foldest calibrate: the report's plots.  In this folder: gnuplot plots.gp\n"
               "if (ARGC > 0) cd ARG1\n"
               "set terminal pngcairo size 1200,420 noenhanced\nset grid\nunset key\n"
               "set output 'raw.png'\nset multiplot layout 1,3 title 'raw samples'\n"
               "set size ratio -1\n");
    for (int pl = 0; pl < 2; pl++) {
        static const char *const lab[3][2] = {{"x", "y"}, {"x", "z"}, {"y", "z"}};
        static const int c[3][2] = {{1, 2}, {1, 3}, {2, 3}};
        if (pl == 1)
            fprintf(o, "set output 'calibrated.png'\n"
                       "set multiplot layout 1,3 title 'calibrated samples, units of the field'\n"
                       "set xrange [-1.3:1.3]\nset yrange [-1.3:1.3]\n"
                       "set object 1 circle at 0,0 size 1 fs empty border lc rgb '#000000'\n");
        for (int k = 0; k < 3; k++)
            fprintf(o, "set xlabel '%s'\nset ylabel '%s'\n"
                       "plot 'samples.dat' using %d:($8 == 1 ? $%d : NaN) with dots "
                       "lc rgb '#1f4e79', '' using %d:($8 == 0 ? $%d : NaN) with dots "
                       "lc rgb '#b0b0b0'\n",
                    lab[k][0], lab[k][1], c[k][0] + 3 * pl, c[k][1] + 3 * pl, c[k][0] + 3 * pl,
                    c[k][1] + 3 * pl);
        fprintf(o, "unset multiplot\nunset object 1\nset autoscale\n");
    }
    fprintf(o, "set terminal pngcairo size 700,700 noenhanced\nset output 'sphere.png'\n"
               "set title 'calibrated samples on the unit sphere'\nset view equal xyz\n"
               "set xyplane at -1.3\nset xrange [-1.3:1.3]\nset yrange [-1.3:1.3]\n"
               "set zrange [-1.3:1.3]\n"
               "set parametric\nset isosamples 13,13\nset urange [0:2*pi]\n"
               "set vrange [-pi/2:pi/2]\nset xlabel 'x'\nset ylabel 'y'\nset zlabel 'z'\n"
               "splot cos(u)*cos(v), sin(u)*cos(v), sin(v) with lines lc rgb '#d0d0d0', "
               "'samples.dat' using ($8 == 1 ? $4 : NaN):5:6 with dots lc rgb '#1f4e79'\n"
               "unset parametric\nunset view\nset autoscale\n"
               "set terminal pngcairo size 800,500 noenhanced\nset output 'radial.png'\n"
               "set title 'radial error of the fitted samples'\n"
               "set xlabel 'radial error |M (x - b)| - 1 (%% of the field)'\n"
               "set ylabel 'samples'\nset style fill solid 0.6\nset boxwidth %.6g\n"
               "plot 'radial.dat' using 1:2 with boxes lc rgb '#1f4e79'\n"
               "set terminal pngcairo size 800,500 noenhanced\nset output 'coverage.png'\n"
               "set title 'coverage: fitted samples in the 100 equal-area regions'\n"
               "set xlabel 'longitude (sector of 36 degrees)'\n"
               "set ylabel 'band of z, from -1 (bottom) to 1 (top)'\n"
               "set xrange [-0.5:9.5]\nset yrange [-0.5:9.5]\n"
               "set palette defined (0 '#ffffff', 1 '#9ecae1', 2 '#08306b')\n"
               "plot 'coverage.dat' matrix with image\n", p2->hist_w);
    bad = ferror(o);
    if (fclose(o) != 0 || bad)
        goto fail;
    if (plots) {
        char *const argv[] = {"gnuplot", "-c", path, (char *)a->report, NULL};
        if (fe__calibrate_gnuplot(argv) != 0) {
            fprintf(stderr, "foldest calibrate: %s: gnuplot failed\n", path);
            return FE_CLI_IO;
        }
    }
    return FE_CLI_OK;
fail:
    fprintf(stderr, "foldest calibrate: %s: cannot write: %s\n", path, strerror(errno));
    return FE_CLI_IO;
}
/* Write the report ends here */
/* [[file:../../literate/calibrate.org::Calibrate a recording][Calibrate a recording]] */
int fe_cli_calibrate(int argc, char **argv)
{
    fe__calibrate_args a;
    fe__calibrate_pass2 p2;
    fe_sphere_options opt = fe_sphere_default_options();
    fe_cli_table t;
    fe_quadric_blocks q;
    fe_sphere_fit fit;
    fe_sphere_scaled sc;
    fe_still gate, *g = NULL;
    fe__calibrate_flags flag_state, *flags = NULL;
    fe__calibrate_robust robust;
    double *ring = NULL;
    size_t cols[6], ncols;
    char err[1024];
    uint64_t still_kept = 0, still_out = 0;
    int rc = fe__calibrate_parse(argc, argv, &a), fitrc;

    if (rc != FE_CLI_OK)
        return rc < 0 ? FE_CLI_OK : rc;
    rc = fe_cli_table_open(&t, a.path, a.skip, err, sizeof err);
    if (rc != FE_CLI_OK) {
        fprintf(stderr, "foldest calibrate: %s\n", err);
        return rc;
    }
    rc = fe__calibrate_columns(&t, a.columns, cols);
    if (rc == FE_CLI_OK)
        rc = fe__calibrate_columns(&t, a.gyro, a.gyro != NULL ? cols + 3 : NULL);
    ncols = a.gyro != NULL ? 6 : 3;
    if (rc == FE_CLI_OK && a.still) {
        size_t len = fe_still_workspace(a.still_opt.window);
        ring = malloc(len * sizeof *ring);
        if (ring == NULL || fe_still_init(&gate, &a.still_opt, ring, len) != FE_OK) {
            fprintf(stderr, "foldest calibrate: --window %zu: out of memory\n",
                    a.still_opt.window);
            rc = FE_CLI_IO;
        }
        g = &gate;
    }
    memset(&robust, 0, sizeof robust);
    if (a.robust && strcmp(a.path, "-") == 0) {
        memset(&flag_state, 0, sizeof flag_state);
        flag_state.model = a.model;
        flag_state.k = a.robust_k;
        flags = &flag_state;
    }
    if (rc == FE_CLI_OK)
        rc = fe__calibrate_fold(&t, cols, ncols, a.threads, g, flags, &q);
    if (rc != FE_CLI_OK)
        goto done;
    if (g != NULL) {
        still_kept = g->still;
        still_out = g->moving;
    }
    if (a.trace)
        opt.trace = fe__calibrate_trace;
    fitrc = fe_sphere_fit_blocks(&q, a.model, &opt, &fit);
    if (fitrc == FE_OK && a.robust && flags == NULL) {
        /* Two more passes: the bulk's scale under this fit, then the
           samples within k of it folded anew and fitted again. */
        fe_sphere_fit first = fit;
        robust.fit = &first;
        rc = fe__calibrate_walk(&a, cols, ncols, g, fe__calibrate_robust_hist, &robust);
        robust.threshold = a.robust_k * fe_radial_hist_scale(&robust.hist);
        robust.q = &q;
        fe_quadric_blocks_init(&q);
        if (rc == FE_CLI_OK)
            rc = fe__calibrate_walk(&a, cols, ncols, g, fe__calibrate_robust_keep, &robust);
        if (rc != FE_CLI_OK)
            goto done;
        fitrc = fe_sphere_fit_blocks(&q, a.model, &opt, &fit);
    }
    memset(&p2, 0, sizeof p2);
    memset(&sc, 0, sizeof sc);
    if (fitrc == FE_OK && fe_sphere_scale(&fit, a.field, &sc) != FE_OK)
        fitrc = FE_EINVAL;      /* not reached: an accepted fit has a radius */
    if (fitrc == FE_OK) {
        if (a.report != NULL)
            rc = fe__calibrate_report_dir(a.report);
        if (rc == FE_CLI_OK)
            rc = fe__calibrate_second_pass(&a, cols, ncols, g, robust.threshold, t.rows, &fit,
                                           &sc, &p2);
        if (rc != FE_CLI_OK)
            goto done;
    }
    p2.still = a.still;
    p2.kept = still_kept;
    p2.left_out = still_out;
    p2.robust = a.robust ? (flags != NULL ? 2 : 1) : 0;
    p2.rejected = flags != NULL ? flags->flagged : robust.rejected;
    p2.threshold = robust.threshold;
    if (a.json)
        fe__calibrate_json(&t, &fit, &sc, a.field, fitrc, &p2);
    if (fitrc != FE_OK) {
        fe__calibrate_refusal(&t, &fit, fitrc);
        rc = FE_CLI_REFUSED;
        goto done;
    }
    if (a.export_format != FE__EXPORT_NONE)
        fe__calibrate_export(&a, &t, &fit, &sc);
    else if (!a.json)
        fe__calibrate_text(stdout, &t, &fit, &sc, a.field, &p2);
    if (a.report != NULL) {
        rc = fe__calibrate_report(&a, &t, cols, &fit, &sc, &p2);
        if (rc != FE_CLI_OK)
            goto done;
        fe_cli_pending_clear();
        if (!a.json && a.export_format == FE__EXPORT_NONE)
            printf("  report           %s/report.md\n", a.report);
    }
done:                                   /* every path after the open */
    free(ring);
    fe_cli_table_close(&t);
    return rc;
}
/* Calibrate a recording ends here */
