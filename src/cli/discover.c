/* SPDX-License-Identifier: MIT */
/* Tangled from literate/cli_discover.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/cli_discover.org::Discover Command Includes][Discover Command Includes]] */
#include "cli.h"

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

enum { FE__MAX_PAIRS = 64, FE__ROLES = 5, FE__PLOT_POINTS = 4000, FE__MAX_LOCATED = 128 };

/* User terms (--term): the other columns they may read, and the row of
   variables a term reads (the catalog's, then those columns). */
enum { FE__MAX_EXTRA = 16, FE__MAX_VARS = FE_CATALOG_VARS + FE__MAX_EXTRA,
       FE__MAX_USER = FE_DISCOVER_MAX_GROUPS, FE__MAX_TERM_FILES = 8 };

static const char *const fe__role_names[FE__ROLES] = {
    "position", "velocity", "temperature", "ambient", "input"};

/* The sample's field for role r, in the order of fe__role_names.  A switch,
   not pointer arithmetic from &s->position: C does not let a pointer to
   one member walk to the next. */
static double *fe__role(fe_sample *s, int r)
{
    switch (r) {
    case 0: return &s->position;
    case 1: return &s->velocity;
    case 2: return &s->temperature;
    case 3: return &s->ambient;
    default: return &s->input;
    }
}
/* Discover Command Includes ends here */
/* [[file:../../literate/cli_discover.org::Align a recording with its simulation][Align a recording with its simulation]] */
/* One simulation row: time, channel, the role columns, then the other
   columns user terms read. */
typedef struct fe__simrow {
    double t, s, role[FE__ROLES + FE__MAX_EXTRA];
    int valid;
} fe__simrow;

typedef struct fe__pair {
    const char *real_path, *sim_path;
    fe_cli_table real, sim;
    size_t real_cols[2 + FE__MAX_EXTRA];            /* time, channel, user terms' */
    size_t sim_cols[2 + FE__ROLES + FE__MAX_EXTRA]; /* time, channel, roles, user terms' */
    int role_col[FE__ROLES + FE__MAX_EXTRA];        /* index into sim_cols, -1 absent */
    /* The columns user terms read: of the simulation (interpolated like
       the roles, after them in role_col) and of the recording; their
       values at the current row. */
    size_t nsimx, nrealx;
    double simx[FE__MAX_EXTRA], realx[FE__MAX_EXTRA];
    fe__simrow w[4];
    double min_step, last_real_t;
    int started;
    size_t skipped;
    /* The simulation's median step (from a first scan of its times) and
       its span; the recording's first time; rows left out, by reason. */
    double step, sim_first, sim_last, first_real_t;
    size_t outside[3];
    int span_checked;
    /* --order K: the hook that takes the simulation's own rows between two
       recording rows returned (fe__run_node; NULL: none), and the time of
       the last row returned (-inf: none yet). */
    int (*node)(void *user, const struct fe__pair *p, fe_sample *s);
    void *node_user;
    double node_after;
} fe__pair;

/* Why a recording row is outside the simulation. */
enum { FE__BEFORE_START, FE__AFTER_END, FE__IN_GAP };

/* Read the next simulation row into w[3], shifting the window left. */
static int fe__sim_advance(fe__pair *p, char *err, size_t errlen)
{
    double v[2 + FE__ROLES + FE__MAX_EXTRA];
    size_t k = 2;
    int rc, nr = FE__ROLES + (int)p->nsimx;
    p->w[0] = p->w[1];
    p->w[1] = p->w[2];
    p->w[2] = p->w[3];
    p->w[3].valid = 0;
    for (int r = 0; r < nr; r++)
        if (p->role_col[r] >= 0)
            k = (size_t)p->role_col[r] + 1 > k ? (size_t)p->role_col[r] + 1 : k;
    rc = fe_cli_table_next(&p->sim, p->sim_cols, k, v, err, errlen);
    if (rc == FE_END)
        return FE_CLI_OK;
    if (rc != FE_OK)
        return rc;
    p->w[3].t = v[0];
    p->w[3].s = v[1];
    for (int r = 0; r < nr; r++)
        p->w[3].role[r] = p->role_col[r] >= 0 ? v[p->role_col[r]] : 0.0;
    p->w[3].valid = 1;
    if (p->w[2].valid) {
        double step = p->w[3].t - p->w[2].t;
        if (!(step > 0.0)) {
            snprintf(err, errlen, "%s:%zu: simulation time does not increase (%.17g after %.17g)",
                     p->sim.name, p->sim.line, p->w[3].t, p->w[2].t);
            return FE_CLI_INPUT;
        }
        if (p->min_step == 0.0 || step < p->min_step)
            p->min_step = step;
    }
    return FE_CLI_OK;
}

/* Two simulation rows may be interpolated between when they are less
   than five typical steps apart (the median step: bursts of fast rows do
   not make every ordinary step a gap, as the smallest step did). */
static int fe__linked(const fe__pair *p, const fe__simrow *a, const fe__simrow *b)
{
    return a->valid && b->valid && b->t - a->t <= 5.0 * p->step;
}

static int fe__cmp_step(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Scan the simulation's times once: its median step and its span; then
   rewind it.  A simulation whose time does not increase is reported by
   the passes, with its line. */
static int fe__sim_scan(fe__pair *p, char *err, size_t errlen)
{
    size_t n = 0, cap = 1024;
    double *steps = malloc(cap * sizeof *steps), t, prev = 0.0;
    int rc;
    if (steps == NULL) {
        snprintf(err, errlen, "out of memory");
        return FE_CLI_IO;
    }
    p->step = 0.0;
    while ((rc = fe_cli_table_next(&p->sim, p->sim_cols, 1, &t, err, errlen)) == FE_OK) {
        if (p->sim.rows == 1)
            p->sim_first = t;
        else if (t > prev) {
            if (n == cap) {
                double *more = realloc(steps, 2 * cap * sizeof *steps);
                if (more == NULL) {
                    free(steps);
                    snprintf(err, errlen, "out of memory");
                    return FE_CLI_IO;
                }
                steps = more;
                cap *= 2;
            }
            steps[n++] = t - prev;
        }
        prev = t;
        p->sim_last = t;
    }
    if (n > 0) {
        qsort(steps, n, sizeof *steps, fe__cmp_step);
        p->step = steps[n / 2];
    }
    free(steps);
    if (rc != FE_END)
        return rc;
    return fe_cli_table_rewind(&p->sim, err, errlen);
}

/* Say so when recording and simulation span times that differ a
   hundredfold: seconds against milliseconds, say. */
static void fe__check_spans(fe__pair *p)
{
    double real = p->last_real_t - p->first_real_t, sim = p->sim_last - p->sim_first;
    if (p->span_checked || !(real > 0.0) || !(sim > 0.0))
        return;
    p->span_checked = 1;
    if (real >= 100.0 * sim || sim >= 100.0 * real)
        fprintf(stderr, "foldest discover: warning: %s spans %.6g time units but %s spans %.6g "
                        "(%.0f times %s): do both use the same unit of time (seconds, milliseconds)?\n",
                p->real.name, real, p->sim.name, sim, real > sim ? real / sim : sim / real,
                real > sim ? "longer" : "shorter");
}

/* d(sim)/dt at window row i (1 or 2): central inside a segment. */
static double fe__dsim(const fe__pair *p, int i)
{
    const fe__simrow *a = fe__linked(p, &p->w[i - 1], &p->w[i]) ? &p->w[i - 1] : &p->w[i];
    const fe__simrow *b = fe__linked(p, &p->w[i], &p->w[i + 1]) ? &p->w[i + 1] : &p->w[i];
    return b->t > a->t ? (b->s - a->s) / (b->t - a->t) : 0.0;
}

/* Where role slot r of a row goes: a field of the sample, or (after the
   roles) a column a user term reads. */
static double *fe__slot(fe__pair *p, fe_sample *s, int r)
{
    return r < FE__ROLES ? fe__role(s, r) : &p->simx[r - FE__ROLES];
}

/* After the window moved on: w[1], a simulation row strictly between the
   last recording row returned and the next one, at t, and linked to the
   row before it, goes to the hook as a sample without a recording value. */
static int fe__pair_node(fe__pair *p, double t, char *err, size_t errlen)
{
    fe_sample s;
    int nr = FE__ROLES + (int)p->nsimx;
    if (p->node == NULL || !p->w[1].valid || !(p->node_after > -INFINITY)
        || !(p->w[1].t > p->node_after) || !(p->w[1].t < t) || !p->w[0].valid
        || !fe__linked(p, &p->w[0], &p->w[1]))
        return FE_CLI_OK;
    memset(&s, 0, sizeof s);
    s.t = p->w[1].t;
    s.real = NAN;
    s.sim = p->w[1].s;
    s.dsim = fe__dsim(p, 1);
    for (int r = 0; r < nr; r++)
        *fe__slot(p, &s, r) = p->w[1].role[r];
    if (p->node(p->node_user, p, &s) != FE_OK) {
        snprintf(err, errlen, "%s: a signature is not finite at t = %.17g (a row of the "
                 "simulation between two of the recording)", p->sim.name, s.t);
        return FE_CLI_INPUT;
    }
    return FE_CLI_OK;
}

/* The next recording row that the simulation covers, as a sample.
   Returns FE_OK, FE_END, or an exit status with a message. */
static int fe__pair_next(fe__pair *p, fe_sample *out, char *err, size_t errlen)
{
    double v[2 + FE__MAX_EXTRA];
    int rc, nr = FE__ROLES + (int)p->nsimx;
    if (!p->started) {
        for (int i = 0; i < 3; i++)
            if ((rc = fe__sim_advance(p, err, errlen)) != FE_CLI_OK)
                return rc;
        p->started = 1;
        p->last_real_t = -INFINITY;
        p->node_after = -INFINITY;
    }
    for (;;) {
        double t, lambda;
        rc = fe_cli_table_next(&p->real, p->real_cols, 2 + p->nrealx, v, err, errlen);
        if (rc == FE_END)
            fe__check_spans(p);
        if (rc != FE_OK)
            return rc;
        t = v[0];
        memcpy(p->realx, v + 2, p->nrealx * sizeof *v);
        if (p->real.rows == 1)
            p->first_real_t = t;
        if (!(t > p->last_real_t)) {
            snprintf(err, errlen, "%s:%zu: time does not increase (%.17g after %.17g)",
                     p->real.name, p->real.line, t, p->last_real_t);
            return FE_CLI_INPUT;
        }
        p->last_real_t = t;
        while (p->w[2].valid && p->w[2].t < t)
            if ((rc = fe__sim_advance(p, err, errlen)) != FE_CLI_OK
                || (rc = fe__pair_node(p, t, err, errlen)) != FE_CLI_OK)
                return rc;
        /* Now w[1].t < t <= w[2].t, or the simulation has ended or not
           begun.  A time the simulation has is always covered, whether it
           lands on w[1] or on w[2] (the loop stops at w[2].t == t). */
        {
            int on1 = p->w[1].valid && t == p->w[1].t, on2 = p->w[2].valid && t == p->w[2].t;
            if (!on1 && !on2
                && (!p->w[1].valid || t < p->w[1].t || !p->w[2].valid
                    || !fe__linked(p, &p->w[1], &p->w[2]))) {
                p->skipped++;
                p->outside[!p->w[1].valid || t < p->w[1].t ? FE__BEFORE_START
                           : !p->w[2].valid ? FE__AFTER_END : FE__IN_GAP]++;
                continue;
            }
            if (on2 && !on1) {  /* as if the window had moved one row on */
                memset(out, 0, sizeof *out);
                out->t = t;
                out->real = v[1];
                out->sim = p->w[2].s;
                out->dsim = fe__dsim(p, 2);
                for (int r = 0; r < nr; r++)
                    *fe__slot(p, out, r) = p->w[2].role[r];
                p->node_after = t;
                return FE_OK;
            }
        }
        memset(out, 0, sizeof *out);
        out->t = t;
        out->real = v[1];
        if (!p->w[2].valid || t == p->w[1].t) {
            out->sim = p->w[1].s;
            out->dsim = fe__dsim(p, 1);
            for (int r = 0; r < nr; r++)
                *fe__slot(p, out, r) = p->w[1].role[r];
        } else {
            lambda = (t - p->w[1].t) / (p->w[2].t - p->w[1].t);
            out->sim = p->w[1].s + lambda * (p->w[2].s - p->w[1].s);
            out->dsim = fe__dsim(p, 1) + lambda * (fe__dsim(p, 2) - fe__dsim(p, 1));
            for (int r = 0; r < nr; r++)
                *fe__slot(p, out, r) = p->w[1].role[r] + lambda * (p->w[2].role[r] - p->w[1].role[r]);
        }
        p->node_after = t;
        return FE_OK;
    }
}

static int fe__pair_rewind(fe__pair *p, char *err, size_t errlen)
{
    int rc = fe_cli_table_rewind(&p->real, err, errlen);
    if (rc == FE_CLI_OK)
        rc = fe_cli_table_rewind(&p->sim, err, errlen);
    memset(p->w, 0, sizeof p->w);
    p->started = 0;
    p->skipped = 0;
    memset(p->outside, 0, sizeof p->outside);
    p->min_step = 0.0;
    return rc;
}
/* Align a recording with its simulation ends here */
/* [[file:../../literate/cli_discover.org::A panel of rows][A panel of rows]] */
/* Rows waiting to be folded, with where each came from; nbreak: the
   breaks between pairs of files that come before them. */
typedef struct fe__panel {
    size_t n, nbreak;
    double vars[FE_DISCOVER_PANEL_ROWS][FE__MAX_VARS];
    double phi[FE_DISCOVER_PANEL_ROWS][FE_DISCOVER_MAX_COLUMNS];
    double r[FE_DISCOVER_PANEL_ROWS], t[FE_DISCOVER_PANEL_ROWS];
    size_t line[FE_DISCOVER_PANEL_ROWS];
    const char *file[FE_DISCOVER_PANEL_ROWS];
} fe__panel;

/* Evaluate the catalog's terms on the panel's rows (work: for
   fe_catalog_eval_rows); with c NULL the panel's columns are already
   there (the signatures of --order).  On a term that is not finite, p->n
   is its row's index, and none of the panel may be folded. */
static int fe__panel_terms(const fe_catalog *c, fe__panel *p, double *work)
{
    size_t done = 0;
    int rc = FE_OK;
    if (c != NULL && p->n > 0)
        rc = fe_catalog_eval_rows(c, p->vars[0], FE__MAX_VARS, p->n, p->phi[0],
                                  FE_DISCOVER_MAX_COLUMNS, work, &done);
    if (rc != FE_OK)
        p->n = done;
    return rc;
}

/* Fold the panel's breaks and rows; on a refusal, p->n is the refused
   row's index (the rows before it are folded). */
static int fe__panel_fold(fe_discover_acc *acc, fe__panel *p)
{
    size_t done = 0;
    int rc = FE_OK;
    for (; p->nbreak > 0; p->nbreak--)
        fe_discover_break(acc);
    if (p->n > 0)
        rc = fe_discover_add_rows(acc, p->phi[0], FE_DISCOVER_MAX_COLUMNS, p->r, p->n, &done);
    p->n = rc == FE_OK ? 0 : done;
    return rc;
}
/* A panel of rows ends here */
/* [[file:../../literate/cli_discover.org::Name a probe's bin][Name a probe's bin]] */
static void fe__probe_bin(const fe_term *t, char *buf, size_t len)
{
    const char *v = fe_catalog_var_names(NULL)[t->var];
    if (isinf(t->lo))
        snprintf(buf, len, "%s < %.4g", v, t->hi);
    else
        snprintf(buf, len, "%.4g <= %s < %.4g", t->lo, v, t->hi);
}
/* Name a probe's bin ends here */
/* [[file:../../literate/cli_discover.org::Discover Options][Discover Options]] */
static const char fe__discover_help[] =
    "usage: foldest discover --real REAL.csv --sim SIM.csv --channel NAME [options]\n"
    "\n"
    "Find what a simulation left out: locate where recording and simulation\n"
    "differ, name the missing physics from a catalog of candidate terms, fit it,\n"
    "and show the fit improve, also on held-out rows.\n"
    "\n"
    "  --real FILE, --sim FILE  a recording and its simulation (CSV, with a time\n"
    "                         column each); repeat the pair for several recordings;\n"
    "                         one input may be '-' (standard input) or a pipe: it is\n"
    "                         copied once to a temporary file, removed at exit\n"
    "  --channel NAME         the measured channel, a column of both files\n"
    "  --time NAME            the time column (default: 'time', else the first)\n"
    "  --role COLUMN=ROLE     a simulation column's role: position, velocity,\n"
    "                         temperature, ambient, input (temperatures in degrees C\n"
    "                         unless the name ends in _K); other columns are ignored\n"
    "  --base TERM,...        terms always fitted (the model's own parameters),\n"
    "                         e.g. bias,gain; default none\n"
    "  --term NAME=EXPR[:DESCRIPTION]  a candidate term of your own, e.g.\n"
    "                         'cogging=sin(2*pi*position/0.002):motor poles'; EXPR:\n"
    "                         + - * / ^ ( ), numbers, pi, abs sign sqrt exp log sin cos\n"
    "                         tan tanh atan2 min max, the variables t sim dsim and the\n"
    "                         roles given, and any other column by name (quoted with\n"
    "                         \" or ` when it has spaces or units); repeatable\n"
    "  --terms FILE           the same, one NAME=EXPR[:DESCRIPTION] a line ('#'\n"
    "                         starts a comment line); repeatable\n"
    "  --only TERM,...        test only these candidates (built-in or yours)\n"
    "  --exclude TERM,...     do not test these (--base terms are always kept)\n"
    "  --holdout F            keep the last fraction F of rows out of selection and\n"
    "                         fitting, and report the RMS on them (default 0.2; 0: none)\n"
    "  --noise MODEL          how the noise's correlation is handled: 'ar' (default),\n"
    "                         an autoregression re-estimated as terms enter, with\n"
    "                         generalised least squares; 'batch', batch means over\n"
    "                         the time blocks\n"
    "  --lags P               lagged products kept for the noise model (default 8,\n"
    "                         at most 16; 0: none, batch means); each costs M^2 a row\n"
    "  --blocks K             time blocks for locating (and batch means) (default 20)\n"
    "  --threads N            parse each regular file on N threads, and fold the\n"
    "                         later part of a long record on a thread of its own\n"
    "                         (default: the processors online); the result is the\n"
    "                         same for any N\n"
    "  --alpha A              family-wise false discovery level (default 0.05)\n"
    "  --order K              the time derivative the missing effect enters: 0 (default)\n"
    "                         adds it to the channel (an offset, a gain, a sensor's\n"
    "                         temperature coefficient); 2 to the channel's second\n"
    "                         derivative (a force per mass on a position or angle);\n"
    "                         1 to its first (a heat rate per capacity on a\n"
    "                         temperature).  With K > 0 the simulation's dynamics are\n"
    "                         identified from its columns, each term is carried through\n"
    "                         them to the channel, and coefficients are per unit of the\n"
    "                         K-th derivative; position and velocity (K = 2) or\n"
    "                         temperature (K = 1) default to the simulated channel\n"
    "  --report DIR           write DIR/report.md with plots (gnuplot, PNG)\n"
    "  --json                 print one JSON object instead of the story\n";

/* The help's second part (C11 compilers need only take strings of 4095
   bytes). */
static const char fe__discover_help_more[] =
    "\n"
    "Three-axis sensors (the best sphere through the samples is the simulation):\n"
    "  foldest discover --sphere FILE.csv [--columns x,y,z] [--time NAME]\n"
    "                   [--role COLUMN=temperature] [--holdout F] [--alpha A]\n"
    "                   [--blocks K] [--json]\n"
    "  names axis_gain (unequal scales), cross_axis (soft iron), thermal_offset,\n"
    "  drift against the sphere's radius and centre (bias, hard_iron); refuses\n"
    "  data that do not determine the sphere (one hemisphere, a plane).\n"
    "\n"
    "Terms (recording - simulation = sum of coefficient x term + noise):\n";

typedef struct fe__discover_args {
    fe__pair *pairs;
    size_t npairs;
    const char *channel, *time, *report, *base;
    const char *term[FE__MAX_USER], *terms_file[FE__MAX_TERM_FILES], *only, *exclude;
    size_t nterm, nterms_file;
    const char *role_column[FE__ROLES];
    double holdout, alpha;
    long blocks, lags;
    int threads;                /* --threads: parsing threads for each file */
    int json;
    int noise;                  /* FE_DISCOVER_NOISE_AR or _BATCH */
    long order;                 /* K: the derivative the effect enters (0 additive) */
} fe__discover_args;

static void fe__discover_usage(FILE *out)
{
    size_t n;
    const fe_term *t = fe_catalog_builtin_terms(&n);
    fputs(fe__discover_help, out);
    fputs(fe__discover_help_more, out);
    for (size_t i = 0; i < n; i++)
        fprintf(out, "  %-20s %s\n", t[i].name, t[i].description);
    fputs("\nExit status: 0 success (whatever the verdict), 1 the data cannot be\n"
          "analysed (too few rows, collinear base), 2 usage, 3 malformed input, 4 I/O.\n",
          out);
}

/* Whether o is one of the options both modes take with the same ranges
   (fe__discover_shared_option parses them). */
static int fe__discover_is_shared(const char *o)
{
    return strcmp(o, "--holdout") == 0 || strcmp(o, "--alpha") == 0
        || strcmp(o, "--blocks") == 0;
}

/* One of them (o is --holdout, --alpha or --blocks): FE_CLI_OK with the
   value set, or FE_CLI_USAGE with err. */
static int fe__discover_shared_option(const char *o, const char *v, double *holdout,
                                      double *alpha, long *blocks, char *err, size_t errlen)
{
    int rc;
    if (strcmp(o, "--holdout") == 0) {
        rc = fe_cli_parse_double(o, v, holdout, err, errlen);
        if (rc == FE_CLI_OK && !(*holdout >= 0.0 && *holdout < 0.9)) {
            snprintf(err, errlen, "--holdout: %s is not in [0, 0.9)", v);
            rc = FE_CLI_USAGE;
        }
    } else if (strcmp(o, "--alpha") == 0) {
        rc = fe_cli_parse_double(o, v, alpha, err, errlen);
        if (rc == FE_CLI_OK && !(*alpha > 0.0 && *alpha < 0.5)) {
            snprintf(err, errlen, "--alpha: %s is not in (0, 0.5)", v);
            rc = FE_CLI_USAGE;
        }
    } else {
        rc = fe_cli_parse_long(o, v, blocks, err, errlen);
        if (rc == FE_CLI_OK && (*blocks < 4 || *blocks > FE_DISCOVER_MAX_BLOCKS)) {
            snprintf(err, errlen, "--blocks: %s is not in [4, %d]", v, FE_DISCOVER_MAX_BLOCKS);
            rc = FE_CLI_USAGE;
        }
    }
    return rc;
}

static int fe__discover_parse(int argc, char **argv, fe__discover_args *a,
                              char *err, size_t errlen)
{
    size_t nreal = 0, nsim = 0;
    memset(a, 0, sizeof *a);
    a->pairs = calloc(FE__MAX_PAIRS, sizeof *a->pairs);
    a->holdout = 0.2;
    a->alpha = 0.05;
    a->blocks = 20;
    a->threads = fe_cli_threads_default();
    a->lags = FE_DISCOVER_DEFAULT_LAGS;
    if (a->pairs == NULL) {
        snprintf(err, errlen, "out of memory");
        return FE_CLI_IO;
    }
    for (int i = 1; i < argc; i++) {
        const char *o = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        int rc = FE_CLI_OK;
        if (strcmp(o, "--json") == 0) {
            a->json = 1;
            continue;
        }
        if (strcmp(o, "--help") == 0 || strcmp(o, "-h") == 0)
            return -1;
        if (v == NULL) {
            snprintf(err, errlen, "%s needs a value", o);
            return FE_CLI_USAGE;
        }
        i++;
        if (strcmp(o, "--real") == 0 || strcmp(o, "--sim") == 0) {
            size_t *n = o[2] == 'r' ? &nreal : &nsim;
            if (*n >= FE__MAX_PAIRS) {
                snprintf(err, errlen, "at most %d pairs", FE__MAX_PAIRS);
                return FE_CLI_USAGE;
            }
            if (o[2] == 'r')
                a->pairs[(*n)++].real_path = v;
            else
                a->pairs[(*n)++].sim_path = v;
        } else if (strcmp(o, "--channel") == 0) {
            a->channel = v;
        } else if (strcmp(o, "--time") == 0) {
            a->time = v;
        } else if (strcmp(o, "--base") == 0) {
            a->base = v;
        } else if (strcmp(o, "--term") == 0 || strcmp(o, "--terms") == 0) {
            int file = o[6] == 's';
            if ((file ? a->nterms_file : a->nterm) >= (file ? FE__MAX_TERM_FILES : FE__MAX_USER)) {
                snprintf(err, errlen, "%s: at most %d", o, file ? FE__MAX_TERM_FILES : FE__MAX_USER);
                return FE_CLI_USAGE;
            }
            if (file)
                a->terms_file[a->nterms_file++] = v;
            else
                a->term[a->nterm++] = v;
        } else if (strcmp(o, "--only") == 0) {
            a->only = v;
        } else if (strcmp(o, "--exclude") == 0) {
            a->exclude = v;
        } else if (strcmp(o, "--report") == 0) {
            a->report = v;
        } else if (fe__discover_is_shared(o)) {
            rc = fe__discover_shared_option(o, v, &a->holdout, &a->alpha, &a->blocks, err, errlen);
        } else if (strcmp(o, "--noise") == 0) {
            if (strcmp(v, "ar") == 0)
                a->noise = FE_DISCOVER_NOISE_AR;
            else if (strcmp(v, "batch") == 0)
                a->noise = FE_DISCOVER_NOISE_BATCH;
            else {
                snprintf(err, errlen, "--noise: '%s' is not 'ar' or 'batch'", v);
                rc = FE_CLI_USAGE;
            }
        } else if (strcmp(o, "--order") == 0) {
            rc = fe_cli_parse_long(o, v, &a->order, err, errlen);
            if (rc == FE_CLI_OK && (a->order < 0 || a->order > FE_DYNAMICS_MAX_ORDER)) {
                snprintf(err, errlen, "--order: %s is not 0, 1 or 2", v);
                rc = FE_CLI_USAGE;
            }
        } else if (strcmp(o, "--lags") == 0) {
            rc = fe_cli_parse_long(o, v, &a->lags, err, errlen);
            if (rc == FE_CLI_OK && (a->lags < 0 || a->lags > FE_DISCOVER_LAGS)) {
                snprintf(err, errlen, "--lags: %s is not in [0, %d]", v, FE_DISCOVER_LAGS);
                rc = FE_CLI_USAGE;
            }
        } else if (strcmp(o, "--threads") == 0) {
            rc = fe_cli_parse_threads(v, &a->threads, err, errlen);
        } else if (strcmp(o, "--role") == 0) {
            const char *eq = strchr(v, '=');
            int found = 0;
            for (int r = 0; eq != NULL && r < FE__ROLES; r++)
                if (strcmp(eq + 1, fe__role_names[r]) == 0) {
                    a->role_column[r] = v;      /* "COLUMN=ROLE"; cut below */
                    found = 1;
                }
            if (!found) {
                snprintf(err, errlen, "--role %s: want COLUMN=ROLE with ROLE one of "
                         "position, velocity, temperature, ambient, input", v);
                rc = FE_CLI_USAGE;
            } else {
                argv[i][eq - v] = '\0';
            }
        } else {
            snprintf(err, errlen, "unknown option '%s'", o);
            rc = FE_CLI_USAGE;
        }
        if (rc != FE_CLI_OK)
            return rc;
    }
    if (nreal == 0 || nreal != nsim) {
        snprintf(err, errlen, nreal == 0 ? "--real and --sim are required"
                                         : "give as many --sim files as --real files");
        return FE_CLI_USAGE;
    }
    if (a->channel == NULL) {
        snprintf(err, errlen, "--channel is required");
        return FE_CLI_USAGE;
    }
    a->npairs = nreal;
    return FE_CLI_OK;
}
/* Discover Options ends here */
/* [[file:../../literate/cli_discover.org::Open a pair and find its columns][Open a pair and find its columns]] */
static int fe__time_column(const fe_cli_table *t, const char *name, size_t *col,
                           char *err, size_t errlen)
{
    if (name != NULL)
        return fe_cli_table_column(t, name, col, err, errlen);
    if (fe_cli_table_column(t, "time", col, err, errlen) == FE_CLI_OK)
        return FE_CLI_OK;
    *col = 0;
    return FE_CLI_OK;
}

static int fe__pair_open(fe__pair *p, const fe__discover_args *a, unsigned *roles,
                         int *kelvin, char *err, size_t errlen)
{
    int rc;
    size_t k = 2;
    /* Three passes: an input that cannot seek (standard input, a pipe) is
       copied once to an unlinked temporary file (cli.org). */
    rc = fe_cli_table_open_rewindable(&p->real, p->real_path, -1, err, errlen);
    if (rc != FE_CLI_OK)
        return rc;
    rc = fe_cli_table_open_rewindable(&p->sim, p->sim_path, -1, err, errlen);
    if (rc != FE_CLI_OK)
        return rc;
    /* Each file parsed on --threads threads, the rows in file order
       (cli.org, "Every core on one file"): the passes see what one
       thread gives them. */
    fe_cli_table_threads(&p->real, a->threads);
    fe_cli_table_threads(&p->sim, a->threads);
    if ((rc = fe__time_column(&p->real, a->time, &p->real_cols[0], err, errlen)) != FE_CLI_OK
        || (rc = fe_cli_table_column(&p->real, a->channel, &p->real_cols[1], err, errlen)) != FE_CLI_OK
        || (rc = fe__time_column(&p->sim, a->time, &p->sim_cols[0], err, errlen)) != FE_CLI_OK
        || (rc = fe_cli_table_column(&p->sim, a->channel, &p->sim_cols[1], err, errlen)) != FE_CLI_OK)
        return rc;
    *roles = 0;
    for (int r = 0; r < FE__ROLES; r++) {
        p->role_col[r] = -1;
        if (a->role_column[r] == NULL)
            continue;
        rc = fe_cli_table_column(&p->sim, a->role_column[r], &p->sim_cols[k], err, errlen);
        if (rc != FE_CLI_OK)
            return rc;
        {
            const char *nm = p->sim.names[p->sim_cols[k]];
            size_t l = strlen(nm);
            if (l >= 2 && strcmp(nm + l - 2, "_K") == 0)
                kelvin[r] = 1;
        }
        p->role_col[r] = (int)k++;
        *roles |= 1u << r;
    }
    return fe__sim_scan(p, err, errlen);
}
/* Open a pair and find its columns ends here */
/* [[file:../../literate/cli_discover.org::Read the pairs as one stream][Read the pairs as one stream]] */
/* With --order K the state the dynamics act on defaults to the simulated
   channel: its value (position, temperature) and its derivative
   (velocity) when no column has that role. */
static void fe__fill_state(long order, const fe__pair *p, fe_sample *s)
{
    if (order == 2 && p->role_col[0] < 0)
        s->position = s->sim;
    if (order == 2 && p->role_col[1] < 0)
        s->velocity = s->dsim;
    if (order == 1 && p->role_col[2] < 0)
        s->temperature = s->sim;
}

typedef struct fe__stream {
    fe__discover_args *a;
    size_t cur;
    size_t skipped, outside[3];
} fe__stream;

/* Returns FE_OK, FE_END, or an exit status; *new_pair is set when the
   sample starts another recording. */
static int fe__stream_next(fe__stream *st, fe_sample *s, int *new_pair, char *err, size_t errlen)
{
    *new_pair = 0;
    while (st->cur < st->a->npairs) {
        fe__pair *p = &st->a->pairs[st->cur];
        int rc = fe__pair_next(p, s, err, errlen);
        if (rc == FE_OK) {
            fe__fill_state(st->a->order, p, s);
            return FE_OK;
        }
        if (rc != FE_END)
            return rc;
        st->skipped += p->skipped;
        for (int k = 0; k < 3; k++)
            st->outside[k] += p->outside[k];
        st->cur++;
        *new_pair = 1;
    }
    return FE_END;
}

static int fe__stream_rewind(fe__stream *st, char *err, size_t errlen)
{
    st->cur = 0;
    st->skipped = 0;
    memset(st->outside, 0, sizeof st->outside);
    for (size_t i = 0; i < st->a->npairs; i++) {
        int rc = fe__pair_rewind(&st->a->pairs[i], err, errlen);
        if (rc != FE_CLI_OK)
            return rc;
    }
    return FE_CLI_OK;
}
/* Read the pairs as one stream ends here */
/* [[file:../../literate/cli_discover.org::Candidate terms of the user's own][Candidate terms of the user's own]] */
/* One user term: the text as given, a copy split in place into name,
   expression and description, and the compiled program. */
typedef struct fe__user_term {
    const char *orig;           /* NAME=EXPR[:DESCRIPTION], as given */
    char *spec;                 /* its copy, split */
    const char *name, *text, *description;
    const char *file;           /* --terms FILE, or NULL for --term */
    size_t line;                /* the line in FILE */
    fe_expr e;
} fe__user_term;

typedef struct fe__user_terms {
    size_t n;
    fe__user_term t[FE__MAX_USER];
    char *buf[FE__MAX_TERM_FILES];      /* the --terms files' text */
    /* The columns the terms read, after the catalog's variables, and
       whether each is the recording's (else the simulation's). */
    size_t nextra;
    const char *extra[FE__MAX_EXTRA];
    int extra_real[FE__MAX_EXTRA];
} fe__user_terms;

static void fe__terms_free(fe__user_terms *ut)
{
    for (size_t i = 0; i < ut->n; i++)
        free(ut->t[i].spec);
    for (size_t i = 0; i < FE__MAX_TERM_FILES; i++)
        free(ut->buf[i]);
}

/* An error at column col (from 1; 0: none) of term u's text as given:
   "--term 'SPEC': col C: WHAT" or "FILE:LINE:C: WHAT", then the text with
   a caret under the column.  Returns the exit status. */
static int fe__term_error(const fe__user_term *u, size_t col, const char *what, char *err,
                          size_t errlen)
{
    int k;
    if (u->file != NULL)
        k = col > 0 ? snprintf(err, errlen, "%.1000s:%zu:%zu: %s", u->file, u->line, col, what)
                    : snprintf(err, errlen, "%.1000s:%zu: %s", u->file, u->line, what);
    else
        k = col > 0 ? snprintf(err, errlen, "--term '%.500s': col %zu: %s", u->orig, col, what)
                    : snprintf(err, errlen, "--term '%.500s': %s", u->orig, what);
    if (col > 0 && k > 0 && (size_t)k < errlen && strlen(u->orig) < 500)
        snprintf(err + k, errlen - (size_t)k, "\n  %s\n  %*s^", u->orig, (int)(col - 1), "");
    return u->file != NULL ? FE_CLI_INPUT : FE_CLI_USAGE;
}

/* `s` without leading and trailing blanks (in place). */
static char *fe__trim(char *s)
{
    size_t n;
    while (*s == ' ' || *s == '\t')
        s++;
    n = strlen(s);
    while (n > 0 && (s[n - 1] == ' ' || s[n - 1] == '\t'))
        s[--n] = '\0';
    return s;
}

/* Whether `name` is one of the comma-separated names of `list`. */
static int fe__in_list(const char *list, const char *name)
{
    size_t len = strlen(name);
    for (const char *q = list; q != NULL && *q != '\0';) {
        const char *comma = strchr(q, ',');
        size_t l = comma != NULL ? (size_t)(comma - q) : strlen(q);
        if (l == len && strncmp(q, name, len) == 0)
            return 1;
        q = comma != NULL ? comma + 1 : NULL;
    }
    return 0;
}

static int fe__is_builtin(const char *name)
{
    size_t nb;
    const fe_term *b = fe_catalog_builtin_terms(&nb);
    for (size_t i = 0; i < nb; i++)
        if (strcmp(b[i].name, name) == 0)
            return 1;
    return 0;
}
/* Candidate terms of the user's own ends here */
/* [[file:../../literate/cli_discover.org::Split a term's text and check its name][Split a term's text and check its name]] */
static int fe__terms_add(fe__user_terms *ut, const char *orig, const char *file, size_t line,
                         char *err, size_t errlen)
{
    fe__user_term *u;
    char *eq, *end, quote = 0;
    if (ut->n >= FE__MAX_USER) {
        snprintf(err, errlen, "more than %d user terms", FE__MAX_USER);
        return FE_CLI_USAGE;
    }
    u = &ut->t[ut->n];
    memset(u, 0, sizeof *u);
    u->orig = orig;
    u->file = file;
    u->line = line;
    if ((u->spec = malloc(strlen(orig) + 1)) == NULL) {
        snprintf(err, errlen, "out of memory");
        return FE_CLI_IO;
    }
    strcpy(u->spec, orig);
    ut->n++;
    if ((eq = strchr(u->spec, '=')) == NULL)
        return fe__term_error(u, 0, "want NAME=EXPR[:DESCRIPTION]", err, errlen);
    *eq = '\0';
    u->name = fe__trim(u->spec);
    if (*u->name == '\0' || (*u->name >= '0' && *u->name <= '9')
        || strspn(u->name, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_")
               != strlen(u->name))
        return fe__term_error(u, 0, "the name must be letters, digits and '_', not starting "
                                    "with a digit", err, errlen);
    if (fe__is_builtin(u->name)) {
        char what[256];
        snprintf(what, sizeof what, "'%s' is a built-in term's name: choose another", u->name);
        return fe__term_error(u, 0, what, err, errlen);
    }
    for (size_t i = 0; i + 1 < ut->n; i++)
        if (strcmp(ut->t[i].name, u->name) == 0) {
            char what[256];
            snprintf(what, sizeof what, "a term '%s' is already defined", u->name);
            return fe__term_error(u, 0, what, err, errlen);
        }
    for (end = eq + 1; *end != '\0'; end++)
        if (quote != 0)
            quote = *end == quote ? 0 : quote;
        else if (*end == '"' || *end == '`')
            quote = *end;
        else if (*end == ':')
            break;
    u->description = NULL;
    if (*end == ':') {
        *end = '\0';
        u->description = fe__trim(end + 1);
    }
    u->text = fe__trim(eq + 1);         /* columns still count from orig */
    for (const char *c = u->description; c != NULL && *c != '\0'; c++)
        if ((unsigned char)*c < 0x20 || *c == 0x7f)
            return fe__term_error(u, (size_t)(c - u->spec) + 1,
                                  "a control character in the description", err, errlen);
    if (u->description == NULL || *u->description == '\0')
        u->description = u->text;       /* the expression describes itself */
    return FE_CLI_OK;
}
/* Split a term's text and check its name ends here */
/* [[file:../../literate/cli_discover.org::Read the user's terms][Read the user's terms]] */
static int fe__terms_read_file(fe__user_terms *ut, size_t k, const char *path, char *err,
                               size_t errlen)
{
    FILE *f = strcmp(path, "-") == 0 ? stdin : fopen(path, "r");
    size_t len = 0, cap = 4096, line = 0;
    char *buf = malloc(cap), *at;
    int rc = FE_CLI_OK;
    if (f == NULL) {
        free(buf);
        snprintf(err, errlen, "--terms %.1000s: cannot read: %s", path, strerror(errno));
        return FE_CLI_IO;
    }
    if (buf == NULL) {
        if (f != stdin)
            fclose(f);
        snprintf(err, errlen, "out of memory");
        return FE_CLI_IO;
    }
    for (size_t got; (got = fread(buf + len, 1, cap - len - 1, f)) > 0;) {
        len += got;
        if (cap - len == 1) {
            char *more = realloc(buf, 2 * cap);
            if (more == NULL) {
                rc = FE_CLI_IO;
                break;
            }
            buf = more;
            cap *= 2;
        }
    }
    if (ferror(f) && rc == FE_CLI_OK)
        rc = FE_CLI_IO;
    if (f != stdin)
        fclose(f);
    buf[len] = '\0';
    ut->buf[k] = buf;
    if (rc != FE_CLI_OK) {
        snprintf(err, errlen, "--terms %.1000s: cannot read", path);
        return rc;
    }
    for (at = buf; at < buf + len && rc == FE_CLI_OK;) {
        char *nl = strchr(at, '\n'), *p;
        if (nl != NULL)
            *nl = '\0';
        if (nl != NULL && nl > at && nl[-1] == '\r')
            nl[-1] = '\0';
        line++;
        for (p = at; *p == ' ' || *p == '\t'; p++)
            ;
        if (*p != '\0' && *p != '#')
            rc = fe__terms_add(ut, at, path, line, err, errlen);
        if (nl == NULL)
            break;
        at = nl + 1;
    }
    return rc;
}
/* Read the user's terms ends here */
/* [[file:../../literate/cli_discover.org::Compile the user's terms][Compile the user's terms]] */
static int fe__terms_compile(fe__user_terms *ut, const fe__discover_args *a, unsigned roles,
                             char *err, size_t errlen)
{
    const fe__pair *p0 = &a->pairs[0];
    size_t nv, k, nall;
    const char *const *vn = fe_catalog_var_names(&nv);
    const char **names;
    int *is_real, rc = FE_CLI_OK;
    for (size_t i = 0; i < a->nterm && rc == FE_CLI_OK; i++)
        rc = fe__terms_add(ut, a->term[i], NULL, 0, err, errlen);
    for (size_t i = 0; i < a->nterms_file && rc == FE_CLI_OK; i++)
        rc = fe__terms_read_file(ut, i, a->terms_file[i], err, errlen);
    if (rc != FE_CLI_OK || ut->n == 0)
        return rc;
    nall = nv + p0->sim.ncols + p0->real.ncols;
    names = malloc(nall * sizeof *names);
    is_real = malloc(nall * sizeof *is_real);
    if (names == NULL || is_real == NULL) {
        free(names);
        free(is_real);
        snprintf(err, errlen, "out of memory");
        return FE_CLI_IO;
    }
    for (k = 0; k < nv; k++) {
        size_t r = k - FE_CATALOG_VAR_POSITION;     /* the role, for the role variables */
        names[k] = k >= FE_CATALOG_VAR_POSITION && !(roles & (1u << r)) ? NULL : vn[k];
        is_real[k] = 0;
    }
    for (size_t c = 0; c < p0->sim.ncols; c++)
        if (c != p0->sim_cols[0] && c != p0->sim_cols[1]) {
            names[k] = p0->sim.names[c];
            is_real[k++] = 0;
        }
    for (size_t c = 0; c < p0->real.ncols; c++) {
        int in_sim = 0;
        for (size_t j = 0; j < p0->sim.ncols; j++)
            in_sim |= strcmp(p0->sim.names[j], p0->real.names[c]) == 0;
        if (c != p0->real_cols[0] && c != p0->real_cols[1] && !in_sim) {
            names[k] = p0->real.names[c];
            is_real[k++] = 1;
        }
    }
    for (size_t i = 0; i < ut->n && rc == FE_CLI_OK; i++) {
        fe__user_term *u = &ut->t[i];
        size_t col = 0;
        char msg[600];
        if (fe_expr_compile(&u->e, u->text, names, k, &col, msg, sizeof msg) != FE_OK)
            rc = fe__term_error(u, (size_t)(u->text - u->spec) + col, msg, err, errlen);
    }
    ut->nextra = 0;
    for (size_t j = nv; j < k && rc == FE_CLI_OK; j++) {
        int used = 0;
        for (size_t i = 0; i < ut->n; i++)
            used |= fe_expr_reads(&ut->t[i].e, j);
        if (!used)
            continue;
        if (ut->nextra == FE__MAX_EXTRA) {
            snprintf(err, errlen, "the terms read more than %d columns", FE__MAX_EXTRA);
            rc = FE_CLI_USAGE;
            break;
        }
        ut->extra[ut->nextra] = names[j];
        ut->extra_real[ut->nextra++] = is_real[j];
    }
    for (size_t i = 0; i < ut->nextra; i++)
        names[nv + i] = ut->extra[i];
    for (size_t i = 0; i < ut->n && rc == FE_CLI_OK; i++)
        if (fe_expr_compile(&ut->t[i].e, ut->t[i].text, names, nv + ut->nextra, NULL, NULL, 0)
            != FE_OK) {
            snprintf(err, errlen, "internal error: term '%s' did not compile again", ut->t[i].name);
            rc = FE_CLI_IO;
        }
    free(names);
    free(is_real);
    return rc;
}
/* Compile the user's terms ends here */
/* [[file:../../literate/cli_discover.org::Find the terms' columns in a pair][Find the terms' columns in a pair]] */
static int fe__terms_open(const fe__user_terms *ut, fe__pair *p, char *err, size_t errlen)
{
    size_t k = 2;
    for (int r = 0; r < FE__ROLES; r++)
        if (p->role_col[r] >= 0 && (size_t)p->role_col[r] + 1 > k)
            k = (size_t)p->role_col[r] + 1;
    p->nsimx = p->nrealx = 0;
    for (size_t i = 0; i < ut->nextra; i++) {
        int rc;
        if (ut->extra_real[i]) {
            rc = fe_cli_table_column(&p->real, ut->extra[i], &p->real_cols[2 + p->nrealx++],
                                     err, errlen);
        } else {
            rc = fe_cli_table_column(&p->sim, ut->extra[i], &p->sim_cols[k], err, errlen);
            p->role_col[FE__ROLES + p->nsimx++] = (int)k++;
        }
        if (rc != FE_CLI_OK)
            return rc;
    }
    return FE_CLI_OK;
}

/* The row of variables of sample s of pair p: the catalog's, then the
   columns the terms read. */
static void fe__terms_row(const fe__user_terms *ut, const fe__pair *p, const fe_sample *s,
                          double *row)
{
    size_t ks = 0, kr = 0;
    fe_catalog_row(s, row);
    for (size_t i = 0; i < ut->nextra; i++)
        row[FE_CATALOG_VARS + i] = ut->extra_real[i] ? p->realx[kr++] : p->simx[ks++];
}
/* Find the terms' columns in a pair ends here */
/* [[file:../../literate/cli_discover.org::Add the user's terms to the catalog][Add the user's terms to the catalog]] */
static int fe__terms_choose(fe_catalog *c, const char *opt, const char *list, int keep,
                            const char *base, char *err, size_t errlen)
{
    const char *q = list;
    if (list == NULL)
        return FE_CLI_OK;
    while (q != NULL) {
        const char *comma = strchr(q, ',');
        size_t l = comma != NULL ? (size_t)(comma - q) : strlen(q);
        char name[256];
        snprintf(name, sizeof name, "%.*s", (int)(l < 255 ? l : 255), q);
        if (fe_catalog_find(c, name) < 0 && !fe__is_builtin(name)) {
            int n = snprintf(err, errlen, "%s: no term '%s'; terms:", opt, name);
            for (size_t j = 0; j < c->count && n > 0 && (size_t)n < errlen; j++)
                n += snprintf(err + n, errlen - (size_t)n, " %s", c->terms[j].name);
            return FE_CLI_USAGE;
        }
        q = comma != NULL ? comma + 1 : NULL;
    }
    for (size_t j = c->count; j-- > 0;) {
        const char *name = c->terms[j].name;
        if (fe__in_list(list, name) != keep && !fe__in_list(base, name)
            && strcmp(name, "offset") != 0)     /* --order's sensor offset stays */
            fe_catalog_remove(c, name);
    }
    return FE_CLI_OK;
}

static int fe__terms_catalog(fe__user_terms *ut, const fe__discover_args *a, fe_catalog *c,
                             char *err, size_t errlen)
{
    int rc;
    if (a->order > 0 && ut->nextra > 0) {
        snprintf(err, errlen, "--order %ld: a term may read only t, sim, dsim and the roles "
                 "(it is evaluated between rows too, where other columns are not known): "
                 "'%.200s' is read", a->order, ut->extra[0]);
        return FE_CLI_USAGE;
    }
    for (size_t i = 0; i < ut->n; i++)
        if ((rc = fe_catalog_add_expr(c, ut->t[i].name, ut->t[i].description, &ut->t[i].e))
            != FE_OK) {
            if (rc == FE_ESIZE)
                snprintf(err, errlen, "too many terms: at most %d with the built-in ones",
                         FE_DISCOVER_MAX_GROUPS);
            else
                snprintf(err, errlen, "term '%.200s' refused by the catalog", ut->t[i].name);
            return FE_CLI_USAGE;
        }
    if ((rc = fe__terms_choose(c, "--only", a->only, 1, a->base, err, errlen)) != FE_CLI_OK)
        return rc;
    return fe__terms_choose(c, "--exclude", a->exclude, 0, a->base, err, errlen);
}

/* The expression of catalog term j when it is the user's, else NULL. */
static const char *fe__terms_text(const fe__user_terms *ut, const fe_catalog *c, size_t j)
{
    for (size_t i = 0; i < ut->n && c->terms[j].expr != NULL; i++)
        if (c->terms[j].expr == &ut->t[i].e)
            return ut->t[i].text;
    return NULL;
}
/* Add the user's terms to the catalog ends here */
/* [[file:../../literate/cli_discover.org::Print the story][Print the story]] */
typedef struct fe__outcome {
    const fe_catalog *c;
    const fe_discover_result *r;
    const size_t *base;
    size_t nbase;
    double baseline_coef[FE_DISCOVER_MAX_COLUMNS];
    size_t rows, skipped, fit, heldout, blocks;
    size_t outside[3];                          /* skipped, by reason */
    double alpha;
    fe_located located[FE__MAX_LOCATED];
    size_t nlocated;
    const char *verdict;
    const char *why;                            /* why not "explained", or NULL */
    const fe_residual_map *map;                 /* residuals by block and region */
    /* The final model refitted on each recording alone (classical errors). */
    size_t npairs;
    double *per_coef, *per_se;                  /* npairs x ncols */
    double *per_rows, *per_held;                /* rows, held-out rows of each */
    size_t order;                               /* --order K */
    const fe_dynamics_fit *dyn;                 /* the simulation's, when K > 0 */
    /* User terms: the expression of each catalog term that is one (else
       NULL), and the channel's unit for reading their coefficients. */
    const char *expression[FE_DISCOVER_MAX_GROUPS];
    char unit[64];
} fe__outcome;

/* The coefficient of catalog term j in words: the catalog's reading of a
   built-in term; for a user term, what it adds to the channel per unit of
   its expression. */
static void fe__explain(const fe__outcome *o, size_t j, double coef, double se, char *words,
                        size_t len)
{
    if (o->expression[j] != NULL && o->order > 0)
        snprintf(words, len, "%s gains %.4g +/- %.2g times %s", o->order == 2 ? "d2x/dt2" : "dT/dt",
                 coef, se, o->expression[j]);
    else if (o->expression[j] != NULL)
        snprintf(words, len, "the recording exceeds the simulation by %.4g +/- %.2g%s%s per "
                 "unit of %s", coef, se, o->unit[0] != '\0' ? " " : "", o->unit,
                 o->expression[j]);
    else
        fe_dynamics_explain(o->c->terms[j].name, o->order, coef, se, words, len);
}

/* The final model's figures for column col: its coefficient, standard
   error, the half-width of its 95% interval and that interval's degrees
   of freedom (its own: see discover.org); zeros when col is not in the
   final model. */
typedef struct fe__coef {
    double value, se, halfwidth, dof;
} fe__coef;

static fe__coef fe__coef_of(const fe_discover_result *r, size_t col)
{
    fe__coef c = {0.0, 0.0, 0.0, 0.0};
    for (size_t i = 0; i < r->ncols; i++)
        if (r->cols[i] == col) {
            c.value = r->coef[i];
            c.se = r->stderr_[i];
            c.halfwidth = r->t_critical[i] * r->stderr_[i];
            c.dof = r->dof[i];
            break;
        }
    return c;
}

static void fe__json_number(FILE *f, double x)
{
    fe_cli_json_number(f, x);   /* one format in every command (cli.org) */
}

/* `, "key": number`. */
static void fe__json_pair(FILE *f, const char *key, double x)
{
    fprintf(f, ", \"%s\": ", key);
    fe__json_number(f, x);
}

static void fe__json_fit(FILE *f, const char *name, const fe_discover_fit *fit)
{
    fprintf(f, "\"%s\": {\"rms\": ", name);
    fe__json_number(f, fit->rms);
    fe__json_pair(f, "bic", fit->bic);
    fe__json_pair(f, "heldout_rms", fit->heldout_rms);
    fe__json_pair(f, "lag1", fit->lag1);
    fe__json_pair(f, "floor", fit->floor);
    fprintf(f, ", \"params\": %zu}", fit->params);
}

/* The word for how the Haar levels were read (FE_DISCOVER_SCALE_*). */
static const char *fe__scale_shape_name(int shape)
{
    switch (shape) {
    case FE_DISCOVER_SCALE_FLAT: return "flat";
    case FE_DISCOVER_SCALE_LINE: return "power_law";
    case FE_DISCOVER_SCALE_WALK: return "random_walk";
    default: return "none";
    }
}

static void fe__json_noise(FILE *f, const fe_discover_noise *nz)
{
    fprintf(f, "{\"model\": \"%s\", \"order\": %zu, \"phi\": [",
            nz->kind == FE_DISCOVER_NOISE_AR ? "ar" : "batch", nz->order);
    for (size_t i = 0; i < nz->order; i++) {
        fprintf(f, "%s", i ? ", " : "");
        fe__json_number(f, nz->phi[i]);
    }
    fprintf(f, "], \"variance\": ");
    fe__json_number(f, nz->variance);
    fe__json_pair(f, "innovation_variance", nz->innovation_variance);
    fe__json_pair(f, "effective_sample_size", nz->n_eff);
    fprintf(f, ", \"portmanteau\": {\"test\": \"ljung-box\", \"lags\": %zu",
            nz->lags_tested);
    fe__json_pair(f, "q", nz->portmanteau);
    fe__json_pair(f, "dof", nz->portmanteau_dof);
    fe__json_pair(f, "p_value", nz->portmanteau_p);
    fprintf(f, "}, \"long_run_correction\": %s, \"block_ratio\": ",
            nz->long_run ? "true" : "false");
    fe__json_number(f, nz->block_ratio);
    fe__json_pair(f, "block_p_value", nz->block_p);
    fprintf(f, ", \"long_range_correction\": %s", nz->long_range ? "true" : "false");
    if (nz->kind == FE_DISCOVER_NOISE_AR) {
        fprintf(f, ", \"scales\": {\"levels\": %zu, \"fine_blocks\": %zu, \"prediction\": [",
                nz->scales, (size_t)1 << nz->scales);
        for (size_t t = 0; nz->scales > 0 && t <= nz->scales; t++) {
            fprintf(f, "%s", t ? ", " : "");
            fe__json_number(f, nz->scale_model[t]);
        }
        fprintf(f, "], \"ratio\": [");
        for (size_t t = 0; nz->scales > 0 && t <= nz->scales; t++) {
            fprintf(f, "%s", t ? ", " : "");
            fe__json_number(f, nz->scale_ratio[t]);
        }
        fprintf(f, "], \"shape\": \"%s\"", fe__scale_shape_name(nz->scale_shape));
        fe__json_pair(f, "slope", nz->scale_slope);
        fe__json_pair(f, "walk_ratio", nz->walk_ratio);
        fprintf(f, "}");
    }
    fprintf(f, "}");
}

/* The selection path: each step's model refitted. */
static void fe__json_path(FILE *f, const fe__outcome *o)
{
    const fe_discover_result *r = o->r;
    fprintf(f, "\"path\": [");
    for (size_t s = 0; s <= r->steps; s++) {
        const fe_discover_step *st = &r->path[s];
        fprintf(f, "%s{\"step\": %zu, \"added\": ", s ? ", " : "", s);
        if (s == 0)
            fprintf(f, "null");
        else
            fe_cli_json_string(f, o->c->terms[st->added].name);
        fprintf(f, ", \"coefficients\": {");
        for (size_t j = 0; j < st->ncols; j++) {
            fprintf(f, "%s", j ? ", " : "");
            fe_cli_json_string(f, o->c->terms[r->cols[j]].name);
            fprintf(f, ": {\"value\": ");
            fe__json_number(f, st->coef[j]);
            fe__json_pair(f, "stderr", st->stderr_[j]);
            fprintf(f, "}");
        }
        fprintf(f, "}, \"rms\": ");
        fe__json_number(f, st->fit.rms);
        fe__json_pair(f, "heldout_rms", st->fit.heldout_rms);
        fe__json_pair(f, "bic", st->fit.bic);
        fprintf(f, ", \"noise_order\": %zu}", st->noise.order);
    }
    fprintf(f, "]");
}

static void fe__print_json(FILE *f, const fe__outcome *o)
{
    const fe_discover_result *r = o->r;
    fprintf(f, "{\"verdict\": \"%s\", \"why\": ", o->verdict);
    if (o->why != NULL)
        fe_cli_json_string(f, o->why);
    else
        fputs("null", f);
    fe__json_pair(f, "heldout_z", r->heldout_z);
    fprintf(f, ", \"set_aside\": [");
    for (size_t k = 0; k < r->naside; k++) {
        fprintf(f, "%s{\"name\": \"%s\", \"statistic\": ", k ? ", " : "",
                o->c->terms[r->aside[k]].name);
        fe__json_number(f, r->aside_rank[k].statistic);
        fe__json_pair(f, "p_value", r->aside_rank[k].p_value);
        fprintf(f, "}");
    }
    fprintf(f, "], ");
    if (r->probes_tested > 0) {
        const fe_term *t = &o->c->terms[r->probe.group];
        fprintf(f, "\"probes\": {\"tested\": %zu, \"variable\": \"%s\", \"bin\": [",
                r->probes_tested, fe_catalog_var_names(NULL)[t->var]);
        fe__json_number(f, t->lo);
        fprintf(f, ", ");
        fe__json_number(f, t->hi);
        fprintf(f, "]");
        fe__json_pair(f, "p", r->probe_p);
        fprintf(f, "}, ");
    }
    fprintf(f, "\"rows\": {\"compared\": %zu, \"outside_simulation\": %zu, \"fit\": %zu, "
               "\"heldout\": %zu, \"outside_by_reason\": {\"before_start\": %zu, "
               "\"after_end\": %zu, \"in_gap\": %zu}}, \"bad_rows\": ", o->rows, o->skipped,
            o->fit, o->heldout, o->outside[FE__BEFORE_START], o->outside[FE__AFTER_END],
            o->outside[FE__IN_GAP]);
    fe_cli_json_bad_rows(f);
    fprintf(f, ", \"order\": %zu, ", o->order);
    if (o->dyn != NULL) {
        fprintf(f, "\"simulation_dynamics\": {\"basis\": %zu, \"rows\": %.0f, \"r2\": ",
                o->dyn->nused, o->dyn->n);
        fe__json_number(f, o->dyn->r2);
        fe__json_pair(f, "rms", o->dyn->rms);
        fprintf(f, "}, ");
    }
    fprintf(f, "\"base\": [");
    for (size_t i = 0; i < o->nbase; i++) {
        fprintf(f, "%s", i ? ", " : "");
        fe_cli_json_string(f, o->c->terms[o->base[i]].name);
    }
    fprintf(f, "], ");
    fe__json_fit(f, "baseline", &r->baseline);
    fprintf(f, ", ");
    fe__json_fit(f, "final", &r->final);
    fprintf(f, ", \"noise\": ");
    fe__json_noise(f, &r->noise);
    fprintf(f, ", \"baseline_noise\": ");
    fe__json_noise(f, &r->path[0].noise);
    fprintf(f, ", ");
    fe__json_path(f, o);
    fprintf(f, ", \"located\": [");
    for (size_t i = 0; i < o->nlocated; i++) {
        char obj[1024];
        if (fe_located_json(&o->located[i], obj, sizeof obj) == FE_OK)
            fprintf(f, "%s%s", i ? ", " : "", obj);
    }
    fprintf(f, "], \"discovered\": [");
    for (size_t s = 0; s < r->steps; s++) {
        const fe_term *t = &o->c->terms[r->added[s]];
        fe__coef c = fe__coef_of(r, r->added[s]);
        char words[512];
        fe__explain(o, r->added[s], c.value, c.se, words, sizeof words);
        fprintf(f, "%s{\"name\": \"%s\", \"description\": ", s ? ", " : "", t->name);
        fe_cli_json_string(f, t->description);
        if (o->expression[r->added[s]] != NULL) {
            fprintf(f, ", \"expression\": ");
            fe_cli_json_string(f, o->expression[r->added[s]]);
        }
        fe__json_pair(f, "coefficient", c.value);
        fe__json_pair(f, "stderr", c.se);
        fe__json_pair(f, "dof", c.dof);
        fprintf(f, ", \"interval95\": [");
        fe__json_number(f, c.value - c.halfwidth);
        fprintf(f, ", ");
        fe__json_number(f, c.value + c.halfwidth);
        fprintf(f, "], \"statistic\": ");
        fe__json_number(f, r->added_rank[s].statistic);
        fe__json_pair(f, "p_value", r->added_rank[s].p_value);
        fe__json_pair(f, "rss_drop", r->added_rank[s].rss_drop);
        fprintf(f, ", \"entered_with\": ");
        if (r->paired[s] != 0)
            fe_cli_json_string(f, o->c->terms[r->added[r->paired[s] == 1 ? s + 1 : s - 1]].name);
        else
            fprintf(f, "null");
        fprintf(f, ", \"explanation\": ");
        fe_cli_json_string(f, words);
        fprintf(f, ", \"indistinguishable_from\": [");
        for (size_t j = 0; j < r->nalike[s]; j++) {
            fprintf(f, "%s", j ? ", " : "");
            fe_cli_json_string(f, o->c->terms[r->alike[s][j]].name);
        }
        fprintf(f, "]}");
    }
    fprintf(f, "], \"per_recording\": [");
    for (size_t q = 0; q < o->npairs && r->steps > 0 && o->per_coef != NULL; q++) {
        fprintf(f, "%s{\"recording\": %zu, \"rows\": %.0f, \"heldout\": %s, \"coefficients\": {",
                q ? ", " : "", q + 1, o->per_rows[q],
                o->per_held[q] >= o->per_rows[q] && o->per_rows[q] > 0 ? "true" : "false");
        for (size_t j = 0; j < r->ncols; j++) {
            fprintf(f, "%s\"%s\": ", j ? ", " : "", o->c->terms[r->cols[j]].name);
            fe__json_number(f, o->per_coef[q * r->ncols + j]);
        }
        fprintf(f, "}}");
    }
    fprintf(f, "], \"ranking\": [");
    for (size_t i = 0; i < r->nranked[0]; i++) {
        const fe_discover_rank *k = &r->ranking[0][i];
        fprintf(f, "%s{\"name\": \"%s\", \"rss_drop\": ", i ? ", " : "",
                o->c->terms[k->group].name);
        fe__json_number(f, k->rss_drop);
        fe__json_pair(f, "statistic", k->statistic);
        fe__json_pair(f, "p_value", k->p_value);
        fprintf(f, ", \"redundant\": %s}", k->redundant ? "true" : "false");
    }
    fprintf(f, "]}\n");
}

static int fe__cmp_rank(const void *a, const void *b)
{
    const fe_discover_rank *x = a, *y = b;
    return (x->p_value > y->p_value) - (x->p_value < y->p_value);
}

/* "noise: AR(2) ..." for the story. */
static void fe__story_noise(FILE *f, const char *what, const fe_discover_noise *nz,
                            double n, size_t blocks)
{
    fprintf(f, "noise (%s): ", what);
    if (nz->kind == FE_DISCOVER_NOISE_BATCH)
        fprintf(f, "batch means over %zu time blocks", blocks);
    else if (nz->order == 0)
        fprintf(f, "white (AR(0))");
    else {
        fprintf(f, "AR(%zu), phi =", nz->order);
        for (size_t i = 0; i < nz->order; i++)
            fprintf(f, "%s %.3g", i ? "," : "", nz->phi[i]);
    }
    fprintf(f, "; effective sample size %.0f of %.0f rows", nz->n_eff, n);
    if (nz->lags_tested > 0)
        fprintf(f, "; %s residual %s (Ljung-Box over %zu lags, p = %.2g)%s",
                nz->kind == FE_DISCOVER_NOISE_AR ? "whitened" : "the",
                nz->portmanteau_p < 0.01 ? "not white" : "white", nz->lags_tested,
                nz->portmanteau_p, nz->long_run ? ", variances widened by the long-run factor" : "");
    if (nz->kind == FE_DISCOVER_NOISE_AR && nz->scales > 0 && nz->scale_ratio[nz->scales] >= 1.5) {
        fprintf(f, "; slow variation beyond the AR model, read as ");
        if (nz->scale_shape == FE_DISCOVER_SCALE_WALK)
            fprintf(f, "a random walk beside it (step variance %.3g times the innovations')",
                    nz->walk_ratio);
        else if (nz->scale_shape == FE_DISCOVER_SCALE_LINE)
            fprintf(f, "a power law across the levels (growing as the scale to the power %.3g)",
                    nz->scale_slope / log(2.0));
        else
            fprintf(f, "the same excess at every level");
        fprintf(f, ": at the record's scale the residual "
                   "varies %.3g times as much as it predicts (%zu Haar levels of %zu blocks), "
                   "and slow terms' variances carry that",
                nz->scale_ratio[nz->scales], nz->scales, (size_t)1 << nz->scales);
    }
    if (nz->long_range)
        fprintf(f, "; block means vary %.3g times as much as white noise would (p = %.2g), "
                   "and the located windows are tested with that", nz->block_ratio, nz->block_p);
    fprintf(f, "\n");
}

static void fe__story_path(FILE *f, const fe__outcome *o)
{
    const fe_discover_result *r = o->r;
    fprintf(f, "\nselection path (each step refitted; coefficient +/- standard error):\n");
    fprintf(f, "  %-4s %-20s %11s %12s %12s  %s\n", "step", "added", "RMS", "held-out RMS",
            "BIC", "coefficients");
    for (size_t s = 0; s <= r->steps; s++) {
        const fe_discover_step *st = &r->path[s];
        fprintf(f, "  %-4zu %-20s %11.5g %12.5g %12.6g ", s,
                s == 0 ? "(base)" : o->c->terms[st->added].name, st->fit.rms,
                st->fit.heldout_rms, st->fit.bic);
        for (size_t j = 0; j < st->ncols; j++)
            fprintf(f, " %s %.4g+/-%.2g", o->c->terms[r->cols[j]].name, st->coef[j],
                    st->stderr_[j]);
        fprintf(f, "\n");
    }
}

/* Where the discovered terms help: each band of speed, position and
   temperature (the bands of one variable cover the rows once), with its
   share of the drop in the residual's sum of squares. */
static void fe__story_regions(FILE *f, const fe_residual_map *m)
{
    double total = 0.0;
    for (size_t g = 0; g < m->nregions; g++)
        if (strcmp(fe_region_variable(m->region[g]), "velocity") != 0)
            total += m->cell[g].sq0 - m->cell[g].sq1;
    fprintf(f, "\nwhere the discovered terms help (share of the drop in the residual's sum "
               "of squares, fitted rows):\n");
    for (size_t g = 0; g < m->nregions; g++) {
        const fe_residual_cell *b = &m->cell[g];
        fe_located l;
        char words[96];
        if (strcmp(fe_region_variable(m->region[g]), "velocity") == 0 || b->n == 0
            || !(total > 0))
            continue;
        memset(&l, 0, sizeof l);
        l.region = m->region[g];
        l.lo = m->region_lo[g];
        l.hi = m->region_hi[g];
        if (fe_region_describe(&l, words, sizeof words) != FE_OK)
            continue;
        fprintf(f, "  %-12s %-24s %6.0f rows  %5.1f%%   RMS %.4g -> %.4g\n",
                fe_region_variable(m->region[g]), words, b->n,
                100.0 * (b->sq0 - b->sq1) / total, sqrt(b->sq0 / b->n), sqrt(b->sq1 / b->n));
    }
}

/* The probes' line: how many, and the one that stands out most. */
static void fe__story_probe(FILE *f, const fe__outcome *o)
{
    const fe_discover_result *r = o->r;
    const fe_term *t;
    char bin[160];
    if (r->probes_tested == 0)
        return;
    t = &o->c->terms[r->probe.group];
    fe__probe_bin(t, bin, sizeof bin);
    fprintf(f, "  probes of the state: %zu bins tested against the final model; the strongest, "
               "%s, p = %.2g after Bonferroni%s\n", r->probes_tested, bin, r->probe_p,
            r->steps > 0 && r->probe_p < o->alpha ? ": a function of the state is left" : "");
}

static void fe__print_story(FILE *f, const fe__outcome *o)
{
    const fe_discover_result *r = o->r;
    fe_discover_rank sorted[FE_DISCOVER_MAX_GROUPS];
    double rel;
    fprintf(f, "compared %zu rows (%zu outside the simulation", o->rows, o->skipped);
    if (o->skipped > 0)
        fprintf(f, ": %zu before it starts, %zu after it ends, %zu in its gaps",
                o->outside[FE__BEFORE_START], o->outside[FE__AFTER_END], o->outside[FE__IN_GAP]);
    fprintf(f, "): %zu fitted, %zu held out\n", o->fit, o->heldout);
    fprintf(f, "baseline (simulation");
    for (size_t i = 0; i < o->nbase; i++)
        fprintf(f, " + %s", o->c->terms[o->base[i]].name);
    fprintf(f, "): RMS %.5g", r->baseline.rms);
    if (o->heldout > 0)
        fprintf(f, ", held-out RMS %.5g", r->baseline.heldout_rms);
    fprintf(f, ", lag-1 autocorrelation %.2f\n", r->baseline.lag1);
    if (o->dyn != NULL) {
        fprintf(f, "order %zu: the missing effect enters the %s derivative of the channel; the "
                   "simulation's own dynamics fitted on %zu functions of its state, R^2 = %.6f\n",
                o->order, o->order == 2 ? "second" : "first", o->dyn->nused, o->dyn->r2);
        if (o->dyn->r2 < 0.99)
            fprintf(f, "  warning: the simulation is not well described by those functions "
                       "(R^2 below 0.99): the terms' signatures are approximate\n");
    }
    fprintf(f, "\nwhere they differ:\n");
    if (o->nlocated == 0)
        fprintf(f, "  nowhere in particular (no time window or state region stands out)\n");
    for (size_t i = 0; i < o->nlocated; i++) {
        const fe_located *l = &o->located[i];
        char words[96];
        if (l->region == FE_REGION_TIME && l->pair == l->pair1)
            fprintf(f, "  recording %d, time %.4g to %.4g:", l->pair + 1, l->t0, l->t1);
        else if (l->region == FE_REGION_TIME)
            fprintf(f, "  recording %d time %.4g to recording %d time %.4g:", l->pair + 1,
                    l->t0, l->pair1 + 1, l->t1);
        else if (fe_region_describe(l, words, sizeof words) == FE_OK)
            fprintf(f, "  %s %s (%.0f rows):", fe_region_variable(l->region), words, l->n);
        fprintf(f, " mean residual %+.3g, mean square %.2fx typical (z = %.1f, t = %.1f);"
                   " after: %+.3g, %.2fx\n", l->mean_before, l->ms_ratio_before, l->z, l->t,
                l->mean_after, l->ms_ratio_after);
    }
    fprintf(f, "\n");
    fe__story_noise(f, "baseline", &r->path[0].noise, r->baseline.n, o->blocks);
    if (r->noise.kind == FE_DISCOVER_NOISE_BATCH)
        fprintf(f, "\ncandidates, first step (batch-means tests over %zu time blocks):\n",
                o->blocks);
    else
        fprintf(f, "\ncandidates, first step (generalised least squares under the baseline's "
                   "noise model, its slow levels read with each candidate in):\n");
    memcpy(sorted, r->ranking[0], r->nranked[0] * sizeof *sorted);
    qsort(sorted, r->nranked[0], sizeof *sorted, fe__cmp_rank);
    for (size_t i = 0; i < r->nranked[0]; i++)
        fprintf(f, "  %-20s RSS drop %10.4g   t = %7.2f   p = %.2g%s\n",
                o->c->terms[sorted[i].group].name, sorted[i].rss_drop, sorted[i].statistic,
                sorted[i].p_value, sorted[i].redundant ? "   (already in the model's span)" : "");
    fprintf(f, "\nwhat was left out:\n");
    if (r->steps == 0)
        fprintf(f, "  no candidate is significant at family-wise level %.3g\n", o->alpha);
    for (size_t s = 0; s < r->steps; s++) {
        const fe_term *t = &o->c->terms[r->added[s]];
        fe__coef c = fe__coef_of(r, r->added[s]);
        char words[512], few[128] = "";
        fe__explain(o, r->added[s], c.value, c.se, words, sizeof words);
        if (c.dof < 1.0)
            snprintf(few, sizeof few, " on %.2g degrees of freedom: the record is too short "
                     "to bound its slow noise", c.dof);
        fprintf(f, "  %zu. %s (%s): coefficient %.5g +/- %.2g (95%%: %.4g to %.4g%s), "
                   "statistic %.2f, p = %.2g\n     %s\n",
                s + 1, t->name, t->description, c.value, c.se, c.value - c.halfwidth,
                c.value + c.halfwidth, c.dof < 1.0 ? few : "", r->added_rank[s].statistic,
                r->added_rank[s].p_value, words);
        if (c.dof >= 1.0 && c.value - c.halfwidth <= 0.0 && c.value + c.halfwidth >= 0.0)
            fprintf(f, "     its own 95%% interval includes zero: in the final fit, with the noise "
                       "model and the other terms estimated beside it, it does not stand out, so "
                       "it is doubtful\n");
        if (r->paired[s] != 0)
            fprintf(f, "     entered with %s: no candidate passed alone, and each of the two "
                       "passes given the other (the statistic above is that test)\n",
                    o->c->terms[r->added[r->paired[s] == 1 ? s + 1 : s - 1]].name);
        if (r->nalike[s] > 0) {
            fprintf(f, "     indistinguishable on these data from:");
            for (size_t j = 0; j < r->nalike[s]; j++)
                fprintf(f, " %s", o->c->terms[r->alike[s][j]].name);
            fprintf(f, "\n");
        }
    }
    for (size_t k = 0; k < r->naside; k++)
        fprintf(f, "  set aside: %s, added first as a stand-in; with the terms above in, its "
                   "statistic is %.2f, p = %.2g, and selection ran again without it\n",
                o->c->terms[r->aside[k]].name, r->aside_rank[k].statistic,
                r->aside_rank[k].p_value);
    if (r->steps > 0)
        fe__story_path(f, o);
    if (r->steps > 0 && o->npairs > 1 && o->per_coef != NULL) {
        fprintf(f, "\nthe same model fitted on each recording alone (classical standard errors):\n");
        for (size_t q = 0; q < o->npairs; q++) {
            fprintf(f, "  recording %2zu (%4.0f rows%s):", q + 1, o->per_rows[q],
                    o->per_held[q] <= 0 ? "" : o->per_held[q] < o->per_rows[q]
                                                   ? ", partly held out" : ", held out");
            for (size_t s = 0; s < r->steps; s++)
                for (size_t j = 0; j < r->ncols; j++)
                    if (r->cols[j] == r->added[s])
                        fprintf(f, "  %s %.4g +/- %.2g", o->c->terms[r->added[s]].name,
                                o->per_coef[q * r->ncols + j], o->per_se[q * r->ncols + j]);
            fprintf(f, "\n");
        }
    }
    if (r->steps > 0 && o->map->nregions > 0)
        fe__story_regions(f, o->map);
    rel = r->baseline.rms > 0 ? 100.0 * (r->final.rms / r->baseline.rms - 1.0) : 0.0;
    fprintf(f, "\nfit: RMS %.5g -> %.5g (%+.2f%%), BIC %.6g -> %.6g, lag-1 %.2f -> %.2f; "
               "high-frequency floor %.3g (RMS %.3g times it)\n",
            r->baseline.rms, r->final.rms, rel, r->baseline.bic, r->final.bic,
            r->baseline.lag1, r->final.lag1, r->final.floor,
            r->final.floor > 0 ? r->final.rms / r->final.floor : 0.0);
    if (o->heldout > 0) {
        fprintf(f, "held out (never seen by selection or fitting): RMS %.5g -> %.5g (%+.2f%%",
                r->baseline.heldout_rms, r->final.heldout_rms,
                100.0 * (r->final.heldout_rms / r->baseline.heldout_rms - 1.0));
        if (isfinite(r->heldout_z))
            fprintf(f, "; %.2f standard deviations %s under the noise model",
                    fabs(r->heldout_z), r->heldout_z > 0 ? "worse" : "better");
        fprintf(f, ")\n");
    }
    fe__story_noise(f, "final", &r->noise, r->final.n, o->blocks);
    fprintf(f, "\nverdict: %s\n", o->verdict);
    if (o->why != NULL)
        fprintf(f, "  (%s)\n", o->why);
    fe__story_probe(f, o);
}
/* Print the story ends here */
/* [[file:../../literate/cli_discover.org::The unit in a column name, and a mean's standard error][The unit in a column name, and a mean's standard error]] */
/* Unit symbols recognised after the last '_' of a column name. */
static const char *const fe__unit_suffixes[] = {
    "m", "mm", "cm", "km", "um", "nm", "s", "ms", "us", "ns", "min", "h",
    "K", "C", "degC", "V", "mV", "uV", "A", "mA", "uA", "Ohm", "W", "mW", "J",
    "Pa", "kPa", "hPa", "MPa", "bar", "mbar", "N", "Nm", "Hz", "kHz",
    "rad", "deg", "g", "mg", "kg", "T", "mT", "uT", "nT", "G", "mG", NULL};

/* The unit of the column `name` into unit[len]: the text in a final [...]
   or (...), else a listed symbol after the last '_'; "" when none. */
static void fe__unit_of(const char *name, char *unit, size_t len)
{
    size_t n = strlen(name);
    const char *u;
    unit[0] = '\0';
    while (n > 0 && name[n - 1] == ' ')
        n--;
    if (n > 0 && (name[n - 1] == ']' || name[n - 1] == ')')) {
        char open = name[n - 1] == ']' ? '[' : '(';
        size_t a = n - 1, b = n - 1;            /* the unit is name[a, b) */
        while (a > 0 && name[a - 1] != open)
            a--;
        if (a == 0)
            return;                             /* no opening bracket */
        while (a < b && name[a] == ' ')
            a++;
        while (b > a && name[b - 1] == ' ')
            b--;
        if (b - a < len) {
            memcpy(unit, name + a, b - a);
            unit[b - a] = '\0';
        }
        return;
    }
    u = strrchr(name, '_');
    if (u == NULL || u == name)
        return;
    for (const char *const *k = fe__unit_suffixes; *k != NULL; k++)
        if (strcmp(u + 1, *k) == 0 && strlen(*k) < len) {
            strcpy(unit, *k);
            return;
        }
}

/* The standard error of the mean of n rows of sum `sum` and sum of squares
   `sq`, each row worth `w` independent rows (at least one row in all). */
static double fe__mean_se(double n, double sum, double sq, double w)
{
    double var = (sq - sum * sum / n) / (n - 1.0), neff = n * w;
    return sqrt((var > 0.0 ? var : 0.0) / (neff > 1.0 ? neff : 1.0));
}
/* The unit in a column name, and a mean's standard error ends here */
/* [[file:../../literate/cli_discover.org::Report files and the means of blocks and bins][Report files and the means of blocks and bins]] */
typedef struct fe__plot_info {
    const char *time_name;      /* the time column's name */
    const char *channel;        /* the channel's column name */
    const char *state_var;      /* position, velocity or temperature; NULL: none */
    const char *state_name;     /* its column's name */
    double held0, held1;        /* the held-out rows' span on the time axis */
    int held;                   /* there are held-out rows */
    const double *joins;        /* where each later recording starts */
    size_t njoins;
} fe__plot_info;

static int fe__have_gnuplot(void)
{
    char *const argv[] = {"gnuplot", "--version", NULL};
    return fe_cli_spawn(argv) == 0;
}

/* Run gnuplot on a script in the report folder `dir`, given as the
   script's argument ARG1 (a string gnuplot never parses); 0 when it
   succeeded. */
static int fe__run_gnuplot(const char *script, const char *dir)
{
    char *const argv[] = {"gnuplot", "-c", (char *)script, (char *)dir, NULL};
    return fe_cli_spawn(argv);
}

/* `s` as the inside of a single-quoted gnuplot string: ' doubled, control
   characters as '?'.  1 when it did not fit. */
static int fe__gnuplot_quote(char *out, size_t len, const char *s)
{
    size_t k = 0;
    for (; *s != '\0'; s++) {
        if (k + 3 > len)
            return 1;
        if (*s == '\'')
            out[k++] = '\'';
        out[k++] = (unsigned char)*s < 0x20 || *s == 0x7f ? '?' : *s;
    }
    out[k] = '\0';
    return 0;
}

/* Register the report's files (and its folder, when this run made it) as
   pending: removed if the command is interrupted before the end. */
static void fe__report_pending(const char *dir, int made)
{
    static const char *const names[] = {"residuals.dat", "blocks.dat", "bins.dat",
                                        "report.md", "plots.gp", "residual_time.png",
                                        "residual_state.png", "trajectory.png"};
    char path[4200];
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        fe_cli_pending_add(path, 0);
    }
    if (made)
        fe_cli_pending_add(dir, 1);
}

/* Write the means of blocks (`blocks` set: the middle time, then the
   held-out flag for i >= nfit, first and last time, recording) or of bins
   (the mean state value), with their standard errors; rows worth w0
   before, w1 after.  0, or -1 when the file could not be written. */
static int fe__write_means(const char *path, const fe_residual_cell *s, size_t n, size_t nfit,
                           int blocks, double w0, double w1)
{
    FILE *f = fopen(path, "w");
    int bad;
    if (f == NULL)
        return -1;
    for (size_t i = 0; i < n; i++) {
        const fe_residual_cell *b = &s[i];
        if (b->n < 2)
            continue;
        fprintf(f, "%.15g %.6g %.6g %.6g %.6g %.0f %.6g %.6g",
                blocks ? 0.5 * (b->t0 + b->t1) : b->sum_at / b->n,
                b->sum0 / b->n, fe__mean_se(b->n, b->sum0, b->sq0, w0),
                b->sum1 / b->n, fe__mean_se(b->n, b->sum1, b->sq1, w1),
                b->n, sqrt(b->sq0 / b->n), sqrt(b->sq1 / b->n));
        if (blocks)
            fprintf(f, " %d %.15g %.15g %d", i >= nfit, b->t0, b->t1, b->pair + 1);
        fputc('\n', f);
    }
    bad = ferror(f);
    return fclose(f) != 0 || bad ? -1 : 0;
}
/* Report files and the means of blocks and bins ends here */
/* [[file:../../literate/cli_discover.org::The page's list of data files][The page's list of data files]] */
static void fe__report_data(FILE *f, const fe__plot_info *pi)
{
    fprintf(f, "## Data\n\n"
               "Plain text, columns separated by one space; blocks and bins of fewer than "
               "two rows are left out.  Standard errors: the rows' spread over the square "
               "root of their count times what one row is worth in independent rows under "
               "the noise model (the baseline's before, the final model's after).\n\n"
               "- `blocks.dat`, one line per time block: 1 middle time (column `%s`%s), "
               "2 mean residual before the discovered terms, 3 its standard error, "
               "4 mean residual after, 5 its standard error, 6 rows, 7 RMS before, "
               "8 RMS after, 9 held out (1) or fitted (0), 10 first time, 11 last time, "
               "12 recording (1, 2, ...).\n",
            pi->time_name, pi->njoins > 0 ? "; recordings end to end" : "");
    if (pi->state_var != NULL)
        fprintf(f, "- `bins.dat`, one line per bin of `%s` (40 equal bins over its range, all "
                   "rows): 1 mean value of `%s` in the bin, 2 to 8 as in `blocks.dat`.\n",
                pi->state_name, pi->state_name);
    fprintf(f, "- `residuals.dat`, every few rows: 1 time (the recording's own clock), "
               "2 residual before, 3 after, 4 position, 5 velocity, 6 temperature "
               "(0 where the role is not given; with --order, the states corrected by the "
               "discovered terms), 7 the recording, 8 the simulation (column 7 minus column 3 "
               "is the simulation corrected by the discovered terms).\n"
               "- `plots.gp`, the gnuplot script: `gnuplot plots.gp` in this folder "
               "draws the plots again.\n");
}
/* The page's list of data files ends here */
/* [[file:../../literate/cli_discover.org::The page and the plot script][The page and the plot script]] */
/* The series of a plot: before and after (only one when no term was
   found), fitted and held out (only fitted when `filter` is NULL). */
static void fe__plot_series(FILE *f, const char *data, const char *filter, int terms,
                            int held)
{
    static const char *const colour[2] = {"#c0504d", "#1f4e79"};
    int first = 1;
    fprintf(f, "plot ");
    for (int h = 0; h <= held; h++)
        for (int a = 0; a <= terms; a++) {
            char y[64];
            if (filter != NULL)
                snprintf(y, sizeof y, "(%s == %d ? $%d : NaN)", filter, h, 2 + 2 * a);
            else
                snprintf(y, sizeof y, "%d", 2 + 2 * a);
            fprintf(f, "%s'%s' using 1:%s:%d with yerrorlines pt %d ps 0.9 lw 1.5 "
                       "lc rgb '%s' title '%s%s'",
                    first ? "" : ", \\\n     ", first ? data : "", y, 3 + 2 * a,
                    h ? 6 - 2 * a : 7 - 2 * a, colour[a],
                    !terms ? "mean residual" : a ? "after" : "before",
                    !held ? "" : h ? " (held out)" : " (fitted)");
            first = 0;
        }
    fputc('\n', f);
}

static int fe__write_report(const char *dir, const fe__outcome *o, const fe__plot_info *pi,
                            char *err, size_t errlen)
{
    /* U+2212 MINUS SIGN and U+00B1 PLUS-MINUS SIGN, in UTF-8. */
    static const char minus[] = "\xe2\x88\x92", pm[] = "\xc2\xb1";
    char path[4096], script[4096], unit[256], qtime[512], qchan[512], qstate[512] = "",
         qunit[512];
    fe_cli_output out;
    FILE *f;
    int plots = fe__have_gnuplot(), terms = o->r->steps > 0, rc;
    fe__unit_of(pi->channel, unit, sizeof unit);
    if (fe__gnuplot_quote(qtime, sizeof qtime, pi->time_name)
        || fe__gnuplot_quote(qchan, sizeof qchan, pi->channel)
        || fe__gnuplot_quote(qunit, sizeof qunit, unit)
        || (pi->state_var != NULL && fe__gnuplot_quote(qstate, sizeof qstate, pi->state_name))) {
        snprintf(err, errlen, "a column name is too long for the plot script");
        return FE_CLI_USAGE;
    }
    snprintf(path, sizeof path, "%s/report.md", dir);
    if ((rc = fe_cli_output_open(&out, path, err, errlen)) != FE_CLI_OK)
        return rc;
    f = out.file;
    fprintf(f, "# foldest discover report\n\n**Verdict: %s**\n\n```\n", o->verdict);
    fe__print_story(f, o);
    fprintf(f, "```\n\n");
    if (!plots)
        fprintf(f, "(gnuplot is not installed: no plots.  `gnuplot plots.gp` in this folder "
                   "draws them where it is.)\n\n");
    fprintf(f, "## Residual against time\n\n");
    if (plots)
        fprintf(f, "![mean residual against time](residual_time.png)\n\n");
    fprintf(f, "Mean residual of `%s` (recording %s model) per time block%s, at the block's "
               "middle time, with %s1 standard error.%s\n\n",
            pi->channel, minus, terms ? ", before and after the discovered terms" : "", pm,
            pi->held ? "  Blocks of held-out rows (never seen by selection or fitting) "
                       "are drawn with open points on the grey band." : "");
    if (pi->state_var != NULL) {
        fprintf(f, "## Residual against %s\n\n", pi->state_name);
        if (plots)
            fprintf(f, "![mean residual against %s](residual_state.png)\n\n", pi->state_name);
        fprintf(f, "Mean residual in 40 equal bins of `%s` (the %s), all rows, with %s1 "
                   "standard error.\n\n", pi->state_name, pi->state_var, pm);
    }
    if (o->order > 0) {
        fprintf(f, "## Recording, simulation and corrected simulation\n\n");
        if (plots)
            fprintf(f, "![recording, simulation and corrected simulation](trajectory.png)\n\n");
        fprintf(f, "`%s` as recorded, as simulated, and as simulated with the discovered terms "
                   "in its dynamics (to first order: the simulation plus each term's signature "
                   "times its coefficient, plus the sensor's offset)%s.\n\n", pi->channel,
                pi->held ? "; the grey band is held out, never seen by selection or fitting"
                         : "");
    }
    fe__report_data(f, pi);
    if ((rc = fe_cli_output_commit(&out, err, errlen)) != FE_CLI_OK)
        return rc;

    snprintf(script, sizeof script, "%s/plots.gp", dir);
    f = fopen(script, "w");
    if (f == NULL) {
        snprintf(err, errlen, "%.1000s: cannot write: %s", script, strerror(errno));
        return FE_CLI_IO;
    }
    fprintf(f, "# foldest discover: the report's plots.  In this folder: gnuplot plots.gp\n"
               "set terminal pngcairo size 1000,600 noenhanced\n"
               "set encoding utf8\nset datafile separator ' '\nset grid\n"
               "set key below horizontal samplen 3 spacing 1.2\nset bmargin 5.5\n"
               "set bars small\nset xzeroaxis lt -1 lw 1 lc rgb '#404040'\n"
               "if (ARGC > 0) cd ARG1\n"
               "set output 'residual_time.png'\n"
               "set title '%s: mean residual per time block, %s1 standard error'\n"
               "set xlabel '%s%s'\n"
               "set ylabel 'mean residual (recording %s model)%s%s%s'\n",
            qchan, pm, qtime, pi->njoins > 0 ? " (recordings end to end)" : "", minus,
            unit[0] ? " [" : "", qunit, unit[0] ? "]" : "");
    if (pi->held)
        fprintf(f, "set object 1 rect from first %.15g, graph 0 to first %.15g, graph 1 behind "
                   "fillcolor rgb '#e6e6e6' fillstyle solid 1.0 noborder\n"
                   "set label 1 'held out' at first %.15g, graph 0.96 left offset 0.5,0\n",
                pi->held0, pi->held1, pi->held0);
    for (size_t j = 0; j < pi->njoins; j++)
        fprintf(f, "set arrow %zu from first %.15g, graph 0 to first %.15g, graph 1 nohead "
                   "dashtype 3 lc rgb '#707070'\n", j + 1, pi->joins[j], pi->joins[j]);
    fe__plot_series(f, "blocks.dat", pi->held ? "$9" : NULL, terms, pi->held);
    if (pi->state_var != NULL) {
        fprintf(f, "unset object 1\nunset label 1\nunset arrow\n"
                   "set output 'residual_state.png'\n"
                   "set title '%s: mean residual in 40 bins of %s (all rows), %s1 standard error'\n"
                   "set xlabel '%s'\n", qchan, qstate, pm, qstate);
        fe__plot_series(f, "bins.dat", NULL, terms, 0);
    }
    if (o->order > 0)
        {
            fprintf(f, "unset object 1\nunset label 1\nunset arrow\n"
                       "set output 'trajectory.png'\n"
                       "set title '%s: recording, simulation and corrected simulation'\n"
                       "set xlabel '%s'\nset ylabel '%s%s%s%s'\n",
                    qchan, qtime, qchan, unit[0] ? " [" : "", qunit, unit[0] ? "]" : "");
            if (pi->held && pi->njoins == 0)
                fprintf(f, "set object 1 rect from first %.15g, graph 0 to first %.15g, graph 1 behind "
                           "fillcolor rgb '#e6e6e6' fillstyle solid 1.0 noborder\n",
                        pi->held0, pi->held1);
            fprintf(f, "set terminal pngcairo size 1000,900 noenhanced\n"
                       "set output 'trajectory.png'\nset multiplot layout 2,1\n"
                       "plot 'residuals.dat' using 1:7 with points pt 7 ps 0.3 lc rgb '#808080' "
                       "title 'recording', \\\n"
                       "     '' using 1:8 with lines lw 2 lc rgb '#c0504d' title 'simulation', \\\n"
                       "     '' using 1:($7-$3) with lines lw 2 lc rgb '#1f4e79' "
                       "title 'corrected simulation'\n"
                       "set title 'the same, less the simulation: how the trajectories part'\n"
                       "set ylabel 'against the simulation%s%s%s'\n"
                       "plot 'residuals.dat' using 1:2 with points pt 7 ps 0.3 lc rgb '#808080' "
                       "title 'recording %s simulation (less the offset)', \\\n"
                       "     '' using 1:($2-$3) with lines lw 2 lc rgb '#1f4e79' "
                       "title 'corrected %s simulation'\n"
                       "unset multiplot\n",
                    unit[0] ? " [" : "", qunit, unit[0] ? "]" : "", minus, minus);
        }
    if (fclose(f) != 0) {
        snprintf(err, errlen, "%.1000s: cannot write: %s", script, strerror(errno));
        return FE_CLI_IO;
    }
    if (plots && fe__run_gnuplot(script, dir) != 0) {
        snprintf(err, errlen, "%.1000s: gnuplot failed", script);
        return FE_CLI_IO;
    }
    return FE_CLI_OK;
}
/* The page and the plot script ends here */
/* [[file:../../literate/cli_discover.org::Run discovery on recordings][Run discovery on recordings]] */
static int fe__discover_sphere_main(int argc, char **argv);

/* Every option of discover and of discover --sphere (cli.org's
   fe_cli_options parses them; the loops below read the canonical form). */
static const fe_cli_option fe__discover_options[] = {
    {"--real", 1}, {"--sim", 1}, {"--channel", 1}, {"--time", 1}, {"--role", 1},
    {"--base", 1}, {"--holdout", 1}, {"--noise", 1}, {"--lags", 1}, {"--blocks", 1},
    {"--alpha", 1}, {"--order", 1}, {"--term", 1}, {"--terms", 1}, {"--only", 1},
    {"--exclude", 1}, {"--threads", 1},
    {"--report", 1}, {"--json", 0}, {"--sphere", 1}, {"--columns", 1}, {NULL, 0}};

/* Everything one run of the command holds, from the arguments to the
   outcome; released by fe__run_free on every path. */
typedef struct fe__run {
    fe__discover_args a;
    fe__stream st;
    fe_catalog cat;
    fe_catalog_scale scale;
    unsigned roles;
    int kelvin[FE__ROLES];
    double lo[3], hi[3];                /* position, velocity, temperature */
    double vlo[FE_CATALOG_VARS], vhi[FE_CATALOG_VARS];  /* every row variable */
    size_t nprobes;                     /* the catalog's last terms */
    size_t base[FE_DISCOVER_MAX_GROUPS], nbase;
    fe_discover_acc acc;
    double *storage, *work;
    size_t nwork;
    fe__panel *panel;
    fe_discover_result *res;
    fe_residual_map *map;
    fe_lsq *per;
    double *per_g;
    FILE *pts;
    char points[4200];
    /* The report's time plot: the fitted blocks, then the held-out rows in
       blocks of the same length, on a time axis that lays the recordings
       end to end. */
    fe_residual_cell *pblocks;
    size_t nplot, njoins;
    double joins[FE__MAX_PAIRS], held_x0, last_x, shift, step_x;
    /* --order K: the span and fit of the simulation's dynamics, the
       signatures, and the coefficients the states are corrected by
       (zero until a first selection). */
    fe_dynamics_span span;
    fe_dynamics_fit dyn;
    fe_dynamics_sens sens;
    fe_dynamics_deviation dev;
    int refine;                         /* Gauss-Newton: about x(theta) */
    int nodes;                          /* the simulation's rows between the
                                           recording's step the signatures
                                           (the fold and map passes) */
    double theta[FE_DISCOVER_MAX_GROUPS];
    double adj;                         /* the row's residual adjustment */
    fe__outcome out;
    fe__user_terms terms;               /* --term, --terms */
    double *term_work;                  /* fe_catalog_eval_rows's */
    /* Passes 2 and 3 in two parts: pass 1's marks; the later part's
       accumulation, residual map and per-recording fits, with their
       storage, and its workspace. */
    struct fe__mark *marks;
    size_t nmarks, mark_stride;
    fe_discover_acc acc2;
    double *storage2, *term_work2;
    fe_residual_map *map2;
    fe_lsq *per2;
    double *per_g2, *per_held2;
    char err[2048];
} fe__run;

static void fe__run_free(fe__run *u)
{
    if (u->pts != NULL)
        fclose(u->pts);
    for (size_t i = 0; i < u->a.npairs; i++) {
        fe_cli_table_close(&u->a.pairs[i].real);
        fe_cli_table_close(&u->a.pairs[i].sim);
    }
    free(u->a.pairs);
    free(u->storage);
    free(u->work);
    free(u->panel);
    free(u->res);
    free(u->map);
    free(u->pblocks);
    free(u->per);
    free(u->per_g);
    free(u->out.per_coef);
    free(u->out.per_se);
    free(u->out.per_rows);
    free(u->out.per_held);
    fe__terms_free(&u->terms);
    free(u->term_work);
    free(u->marks);
    free(u->storage2);
    free(u->term_work2);
    free(u->map2);
    free(u->per2);
    free(u->per_g2);
    free(u->per_held2);
}

#define FE__OOM(u) (snprintf((u)->err, sizeof (u)->err, "out of memory or internal error"), \
                    FE_CLI_IO)


enum { FE__PROBE_BINS = 8 };

/* Probes of every state variable the roles give, after the catalog's own
   and the user's terms (u->nprobes: how many). */
static void fe__run_probes(fe__run *u)
{
    static const struct { unsigned role; int var; } vars[] = {
        {FE_ROLE_POSITION, FE_CATALOG_VAR_POSITION}, {FE_ROLE_VELOCITY, FE_CATALOG_VAR_VELOCITY},
        {FE_ROLE_TEMPERATURE, FE_CATALOG_VAR_TEMPERATURE},
        {FE_ROLE_AMBIENT, FE_CATALOG_VAR_AMBIENT}, {FE_ROLE_INPUT, FE_CATALOG_VAR_INPUT}};
    size_t before = u->cat.count;
    for (size_t i = 0; i < sizeof vars / sizeof vars[0]; i++)
        if (u->roles & vars[i].role)
            (void)fe_catalog_add_probes(&u->cat, vars[i].var, u->vlo[vars[i].var],
                                        u->vhi[vars[i].var], FE__PROBE_BINS);
    u->nprobes = u->cat.count - before;
}

/* The refusal of panel row p->n, into u->err: the term that is not
   finite there, with the row's file, line and time. */
static void fe__name_refusal(fe__run *u, const fe__panel *p)
{
    const char *bad = NULL;
    double x = 0.0;
    for (size_t j = 0; j < u->cat.count && bad == NULL; j++)
        if (!isfinite(p->phi[p->n][j])) {
            bad = u->cat.terms[j].name;
            x = p->phi[p->n][j];
        }
    if (bad != NULL)
        snprintf(u->err, sizeof u->err, "%.1000s:%zu: term '%s' is %s at t = %g: refused, "
                 "nothing reported", p->file[p->n], p->line[p->n], bad,
                 isnan(x) ? "NaN" : "infinite", p->t[p->n]);
    else
        snprintf(u->err, sizeof u->err, "%.1000s:%zu: a term is not finite at t = %g",
                 p->file[p->n], p->line[p->n], p->t[p->n]);
}

enum { FE__MARKS = 32, FE__MARK_STRIDE = 1024, FE__SPLIT_MIN = 8192 };

/* Where the stream stood after `row` rows: in pair `cur`, with that
   pair's window and counters, its files having given lines real_line and
   sim_line (real_rows and sim_rows rows). */
typedef struct fe__mark {
    size_t row, cur;
    fe__simrow w[4];
    double min_step, last_real_t, first_real_t;
    int started;
    size_t skipped, outside[3];
    size_t real_line, real_rows, sim_line, sim_rows;
} fe__mark;

/* Pass 1, after each row: mark the stream every mark_stride rows. */
static void fe__mark_row(fe__run *u)
{
    const fe__pair *p = &u->a.pairs[u->st.cur];
    fe__mark *m;
    if (u->marks == NULL || u->out.rows % u->mark_stride != 0)
        return;
    if (u->nmarks == FE__MARKS) {       /* keep every other, twice as far apart */
        for (size_t j = 0; j < FE__MARKS / 2; j++)
            u->marks[j] = u->marks[2 * j + 1];
        u->nmarks = FE__MARKS / 2;
        u->mark_stride *= 2;
        if (u->out.rows % u->mark_stride != 0)
            return;
    }
    m = &u->marks[u->nmarks++];
    m->row = u->out.rows;
    m->cur = u->st.cur;
    memcpy(m->w, p->w, sizeof m->w);
    m->min_step = p->min_step;
    m->last_real_t = p->last_real_t;
    m->first_real_t = p->first_real_t;
    m->started = p->started;
    m->skipped = p->skipped;
    memcpy(m->outside, p->outside, sizeof m->outside);
    m->real_line = p->real.line;
    m->real_rows = p->real.rows;
    m->sim_line = p->sim.line;
    m->sim_rows = p->sim.rows;
}

/* The mark to cut a pass at: the one nearest row `target`, or NULL. */
static const fe__mark *fe__cut(const fe__run *u, size_t target)
{
    const char *env = getenv("FOLDEST_CUT");    /* the tests' switch and witness */
    const fe__mark *best = NULL;
    if (u->a.order != 0 || u->out.rows < FE__SPLIT_MIN || (env != NULL && strcmp(env, "0") == 0))
        return NULL;
    for (size_t j = 0; j < u->nmarks; j++) {
        const fe__mark *m = &u->marks[j];
        size_t d = m->row > target ? m->row - target : target - m->row;
        if (m->row > 0 && m->row < u->out.rows
            && (best == NULL || d < (best->row > target ? best->row - target : target - best->row)))
            best = m;
    }
    if (env != NULL && best != NULL)
        fprintf(stderr, "foldest: discover: a pass cut at row %zu of %zu\n", best->row,
                u->out.rows);
    return best;
}

/* Where pass 2's work is halved: a held-out row costs it about half a
   fitted one (no lagged products). */
static size_t fe__fold_middle(const fe__run *u)
{
    double half = 0.5 * ((double)u->out.fit + 0.5 * (double)u->out.heldout);
    return half <= (double)u->out.fit ? (size_t)half
                                      : u->out.fit + (size_t)(2.0 * (half - (double)u->out.fit));
}

/* A part of pass 2 or 3: its stream, accumulation (pass 2) or residual
   map and per-recording fits (pass 3), panel and workspace, its first
   row and the rows it folds (limit), and how it ended.  A part on
   another thread only reads u. */
typedef struct fe__part {
    fe__run *u;
    fe__stream *st;
    fe_discover_acc *acc;
    fe__panel *p;
    double *term_work;
    fe_residual_map *map;
    fe_lsq *per;
    double *per_held;
    size_t row0, limit;
    int rc, refused;            /* the stream's end or error; the fold's refusal */
    char err[2048];
} fe__part;

/* Fold the part's rows, a panel at a time (--order 0 only: the terms by
   fe_catalog_eval_rows, the lagged products by fe_discover_add_rows);
   on a refusal p->n is the refused row's index. */
static void fe__part_fold(fe__part *w)
{
    fe__panel *p = w->p;
    fe_sample s;
    size_t done = 0;
    int new_pair, rc = FE_END;
    w->refused = FE_OK;
    w->err[0] = '\0';
    p->n = p->nbreak = 0;
    while (done < w->limit
           && (rc = fe__stream_next(w->st, &s, &new_pair, w->err, sizeof w->err)) == FE_OK) {
        const fe__pair *pr = &w->st->a->pairs[w->st->cur];
        size_t k = p->n;
        if ((new_pair || k == FE_DISCOVER_PANEL_ROWS) && (k > 0 || p->nbreak > 0)
            && ((w->refused = fe__panel_terms(&w->u->cat, p, w->term_work)) != FE_OK
                || (w->refused = fe__panel_fold(w->acc, p)) != FE_OK))
            break;                              /* p->n: the refused row */
        if (new_pair)
            p->nbreak++;
        k = p->n;
        p->line[k] = pr->real.line;
        p->file[k] = pr->real.name;
        p->t[k] = s.t;
        p->r[k] = s.real - s.sim;
        fe__terms_row(&w->u->terms, pr, &s, p->vars[k]);
        p->n++;
        done++;
        rc = FE_END;
    }
    if (rc == FE_END && w->refused == FE_OK
        && (w->refused = fe__panel_terms(&w->u->cat, p, w->term_work)) == FE_OK)
        w->refused = fe__panel_fold(w->acc, p);
    w->rc = rc;
}

static void *fe__part_run(void *arg)
{
    fe__part_fold(arg);
    return NULL;
}

static void fe__part_map(fe__part *w);

static void *fe__part_run_map(void *arg)
{
    fe__part_map(arg);
    return NULL;
}

/* The later part's own readers: copies of the pairs from the mark's on,
   their tables second readers of the files, the mark's pair at the mark. */
typedef struct fe__later {
    fe__discover_args a;
    fe__stream st;
    size_t first, opened;       /* pairs first .. first + opened - 1 have readers */
} fe__later;

static void fe__later_close(fe__later *l)
{
    for (size_t i = l->first; i < l->first + l->opened; i++) {
        fe_cli_table_close_part(&l->a.pairs[i].real);
        fe_cli_table_close_part(&l->a.pairs[i].sim);
    }
    free(l->a.pairs);
    l->a.pairs = NULL;
}

/* The line after which a table's data begin. */
static size_t fe__data_line(const fe_cli_table *t)
{
    return t->npending > 0 ? t->pending_line[0] - 1 : t->look_end;
}

static void fe__mark_restore(fe__pair *p, const fe__mark *m);

static int fe__later_open(fe__later *l, const fe__run *u, const fe__mark *m)
{
    char err[1024];
    memset(l, 0, sizeof *l);
    l->a = u->a;
    l->first = m->cur;
    if ((l->a.pairs = malloc(u->a.npairs * sizeof *l->a.pairs)) == NULL)
        return FE_CLI_IO;
    memcpy(l->a.pairs, u->a.pairs, u->a.npairs * sizeof *l->a.pairs);
    for (size_t i = m->cur; i < u->a.npairs; i++) {
        fe__pair *p = &l->a.pairs[i];
        const fe__pair *o = &u->a.pairs[i];
        int at = i == m->cur;
        if (fe_cli_table_open_part(&p->real, &o->real, at ? m->real_line : fe__data_line(&o->real),
                                   at ? m->real_rows : 0, err, sizeof err) != FE_CLI_OK)
            break;
        if (fe_cli_table_open_part(&p->sim, &o->sim, at ? m->sim_line : fe__data_line(&o->sim),
                                   at ? m->sim_rows : 0, err, sizeof err) != FE_CLI_OK) {
            fe_cli_table_close_part(&p->real);
            break;
        }
        l->opened++;
        p->span_checked = 1;    /* pass 1 has warned */
    }
    if (l->opened < u->a.npairs - m->cur) {
        fe__later_close(l);
        return FE_CLI_IO;
    }
    fe__mark_restore(&l->a.pairs[m->cur], m);
    l->st.a = &l->a;
    l->st.cur = m->cur;
    return FE_CLI_OK;
}

/* The calling thread's readers parse on n threads: one while a later
   part has the other core, --threads again after. */
static void fe__pairs_threads(fe__run *u, int n)
{
    for (size_t i = 0; i < u->a.npairs; i++) {
        fe_cli_table_threads(&u->a.pairs[i].real, n);
        fe_cli_table_threads(&u->a.pairs[i].sim, n);
    }
}

/* The mark's pair as it stood at the mark. */
static void fe__mark_restore(fe__pair *p, const fe__mark *m)
{
    memcpy(p->w, m->w, sizeof p->w);
    p->min_step = m->min_step;
    p->last_real_t = m->last_real_t;
    p->first_real_t = m->first_real_t;
    p->started = m->started;
    p->skipped = m->skipped;
    memcpy(p->outside, m->outside, sizeof p->outside);
}

/* Pass 1: the catalog's scale, the state's ranges, the rows compared. */
static int fe__run_scan(fe__run *u)
{
    fe_sample s;
    int rc, new_pair;
    for (int v = 0; v < 3; v++) {
        u->lo[v] = INFINITY;
        u->hi[v] = -INFINITY;
    }
    for (int v = 0; v < FE_CATALOG_VARS; v++) {
        u->vlo[v] = INFINITY;
        u->vhi[v] = -INFINITY;
    }
    u->marks = u->a.order == 0 ? malloc(FE__MARKS * sizeof *u->marks) : NULL;  /* none: no cut */
    u->nmarks = 0;
    u->mark_stride = FE__MARK_STRIDE;
    while ((rc = fe__stream_next(&u->st, &s, &new_pair, u->err, sizeof u->err)) == FE_OK) {
        double row[FE_CATALOG_VARS];
        fe_catalog_row(&s, row);
        for (int v = 0; v < FE_CATALOG_VARS; v++) {
            u->vlo[v] = row[v] < u->vlo[v] ? row[v] : u->vlo[v];
            u->vhi[v] = row[v] > u->vhi[v] ? row[v] : u->vhi[v];
        }
        fe_catalog_scale_add(&u->scale, &s);
        if (u->a.order > 0 && fe_dynamics_span_add(&u->span, &s) != FE_OK) {
            snprintf(u->err, sizeof u->err, "%.1000s:%zu: a state value is not finite at t = %g",
                     u->a.pairs[u->st.cur].sim.name, u->a.pairs[u->st.cur].sim.line, s.t);
            return FE_CLI_INPUT;
        }
        for (int v = 0; v < 3; v++) {
            double x = *fe__role(&s, v);    /* position, velocity, temperature */
            u->lo[v] = x < u->lo[v] ? x : u->lo[v];
            u->hi[v] = x > u->hi[v] ? x : u->hi[v];
        }
        u->out.rows++;
        fe__mark_row(u);
    }
    if (rc != FE_END)
        return rc;
    /* A file with a header and no rows is malformed input (status 3), not
       a comparison with too few rows (a refusal). */
    for (size_t i = 0; i < u->a.npairs; i++) {
        const fe_cli_table *empty = u->a.pairs[i].real.rows == 0 ? &u->a.pairs[i].real
                                  : u->a.pairs[i].sim.rows == 0 ? &u->a.pairs[i].sim : NULL;
        if (empty != NULL) {
            snprintf(u->err, sizeof u->err, "%.1000s: no data rows", empty->name);
            return FE_CLI_INPUT;
        }
    }
    u->out.skipped = u->st.skipped;
    memcpy(u->out.outside, u->st.outside, sizeof u->out.outside);
    u->scale.temperature_kelvin = u->kelvin[2];
    u->scale.ambient_kelvin = u->kelvin[3];
    if ((u->a.order == 0 ? fe_catalog_init(&u->cat, u->roles, &u->scale)
                         : fe_dynamics_catalog_init(&u->cat, (size_t)u->a.order, u->roles,
                                                    &u->scale)) != FE_OK)
        return FE__OOM(u);
    if ((rc = fe__terms_catalog(&u->terms, &u->a, &u->cat, u->err, sizeof u->err)) != FE_CLI_OK)
        return rc;
    fe__run_probes(u);
    u->out.heldout = (size_t)floor(u->a.holdout * (double)u->out.rows);
    u->out.fit = u->out.rows - u->out.heldout;
    if (u->out.fit < 2 * (size_t)u->a.blocks + 10) {
        snprintf(u->err, sizeof u->err, "only %zu rows compared (%zu outside the simulation): "
                 "too few for %ld blocks", u->out.rows, u->st.skipped, u->a.blocks);
        return FE_CLI_REFUSED;
    }
    return FE_CLI_OK;
}

/* The base terms named by --base, as catalog columns. */
static int fe__run_base(fe__run *u)
{
    char *list, *items[FE_DISCOVER_MAX_GROUPS];
    int n;
    if (u->a.order > 0)                 /* the sensor's offset, always */
        u->base[u->nbase++] = FE_DYNAMICS_OFFSET;
    if (u->a.base == NULL)
        return FE_CLI_OK;
    if ((list = malloc(strlen(u->a.base) + 1)) == NULL)
        return FE__OOM(u);
    strcpy(list, u->a.base);
    n = fe_cli_split_list(list, items, FE_DISCOVER_MAX_GROUPS);
    for (int i = 0; i < n; i++) {
        long j = fe_catalog_find(&u->cat, items[i]);
        if (j < 0) {
            snprintf(u->err, sizeof u->err, "--base: no term '%.200s' (with these roles)",
                     items[i]);
            free(list);
            return FE_CLI_USAGE;
        }
        if (u->a.order > 0 && j == FE_DYNAMICS_OFFSET)
            continue;
        u->base[u->nbase++] = (size_t)j;
    }
    free(list);
    return FE_CLI_OK;
}

/* Row r of window w (0..2) of a simulation as a sample: its time,
   channel and roles, the channel's three-point derivative as dsim (one
   sided at a gap or an end), the state filled in as the stream does. */
static fe_sample fe__sim_sample(const fe__pair *p, long order, const fe__simrow *w)
{
    fe_sample s;
    const fe__simrow *a = fe__linked(p, &w[0], &w[1]) ? &w[0] : NULL;
    const fe__simrow *b = fe__linked(p, &w[1], &w[2]) ? &w[2] : NULL;
    memset(&s, 0, sizeof s);
    s.t = w[1].t;
    s.sim = w[1].s;
    for (int r = 0; r < FE__ROLES; r++)
        *fe__role(&s, r) = w[1].role[r];
    if (a != NULL && b != NULL) {
        double h0 = w[1].t - a->t, h1 = b->t - w[1].t;
        s.dsim = (h0 * h0 * b->s - h1 * h1 * a->s + (h1 * h1 - h0 * h0) * w[1].s)
                 / (h0 * h1 * (h0 + h1));
    } else if (a != NULL || b != NULL) {
        const fe__simrow *o = a != NULL ? a : b;
        s.dsim = (w[1].s - o->s) / (w[1].t - o->t);
    }
    fe__fill_state(order, p, &s);
    return s;
}

static int fe__run_node(void *user, const fe__pair *p, fe_sample *s);

/* The pass that identifies the simulation's dynamics (--order K), from
   the simulation's own rows: the recording's times may be uneven and the
   simulation interpolated onto them, and the second difference of an
   interpolated position is mostly the interpolation's kinks.  It also
   gives each pair the hook that carries the signatures through the
   simulation's rows between the recording's (fe__run_node). */
static int fe__run_ident(fe__run *u)
{
    fe_dynamics_ident id;
    if (u->a.order == 0)
        return FE_CLI_OK;
    if (fe_dynamics_ident_init(&id, &u->span) != FE_OK
        || fe_dynamics_sens_init(&u->sens, (size_t)u->a.order, u->cat.count - 1) != FE_OK
        || fe_dynamics_deviation_init(&u->dev, (size_t)u->a.order) != FE_OK)
        return FE__OOM(u);
    for (size_t q = 0; q < u->a.npairs; q++) {
        fe__pair *p = &u->a.pairs[q];
        fe__simrow w[3];
        double v[2 + FE__ROLES];
        size_t k = 2, n = 0;
        int rc;
        p->node = fe__run_node;
        p->node_user = u;
        for (int r = 0; r < FE__ROLES; r++)
            if (p->role_col[r] >= 0 && (size_t)p->role_col[r] + 1 > k)
                k = (size_t)p->role_col[r] + 1;
        if ((rc = fe_cli_table_rewind(&p->sim, u->err, sizeof u->err)) != FE_CLI_OK)
            return rc;
        fe_dynamics_ident_break(&id);
        memset(w, 0, sizeof w);
        for (;;) {
            rc = fe_cli_table_next(&p->sim, p->sim_cols, k, v, u->err, sizeof u->err);
            if (rc != FE_OK && rc != FE_END)
                return rc;
            w[0] = w[1];
            w[1] = w[2];
            w[2].valid = rc == FE_OK;
            if (rc == FE_OK) {
                w[2].t = v[0];
                w[2].s = v[1];
                for (int r = 0; r < FE__ROLES; r++)
                    w[2].role[r] = p->role_col[r] >= 0 ? v[p->role_col[r]] : 0.0;
            }
            if (w[1].valid) {
                fe_sample s = fe__sim_sample(p, u->a.order, w);
                int gap = w[0].valid && !fe__linked(p, &w[0], &w[1]);
                if (gap)
                    fe_dynamics_ident_break(&id);
                rc = fe_dynamics_ident_add(&id, &s);
                if (rc == FE_EINVAL) {
                    snprintf(u->err, sizeof u->err, "%.1000s:%zu: simulation time does not "
                             "increase", p->sim.name, p->sim.line);
                    return FE_CLI_INPUT;
                }
                if (rc != FE_OK) {
                    snprintf(u->err, sizeof u->err, "%.1000s:%zu: the simulation's state is not "
                             "finite at t = %g", p->sim.name, p->sim.line, s.t);
                    return FE_CLI_INPUT;
                }
                n++;
            }
            if (!w[2].valid && n > 0)
                break;
        }
    }
    if (fe_dynamics_ident_solve(&id, &u->dyn) != FE_OK) {
        snprintf(u->err, sizeof u->err, "too few rows to identify the simulation's dynamics");
        return FE_CLI_REFUSED;
    }
    return FE_CLI_OK;
}

/* Every term of the catalog at one row (the user's too: their other
   columns are the current row's). */
static int fe__run_terms(fe__run *u, const fe_sample *s, double *phi)
{
    double row[FE__MAX_VARS];
    fe__terms_row(&u->terms, &u->a.pairs[u->st.cur], s, row);
    return fe_catalog_eval_rows(&u->cat, row, FE__MAX_VARS, 1, phi, FE_DISCOVER_MAX_COLUMNS,
                                u->term_work, NULL);
}

/* The discovered terms times their coefficients at a sample: the forcing
   of the deviation (an fe_dynamics_fn).  Between rows there is only the
   sample: --order refuses terms that read other columns. */
static int fe__run_force(const fe_sample *s, double *g, void *user)
{
    const fe__run *u = user;
    double phi[FE_DISCOVER_MAX_COLUMNS], sum = 0.0;
    int rc = fe_catalog_eval(&u->cat, s, phi);
    if (rc != FE_OK)
        return rc;
    for (size_t j = 1; j < u->cat.count; j++)
        sum += u->theta[j] * phi[j];
    *g = sum;
    return FE_OK;
}

/* The columns of one row: the catalog's terms (--order 0), or each term's
   signature through the simulation's dynamics, the offset as it is.  Once
   refining (u->refine), about the corrected trajectory: the deviation
   under u->theta moves the sample's states (the caller sees them moved),
   the Jacobian and the terms are taken there, and u->adj receives the
   residual's adjustment -delta + sum theta_j s_j. */
static int fe__run_columns(fe__run *u, fe_sample *s, int new_pair, double *phi)
{
    size_t K = (size_t)u->a.order, m = u->cat.count;
    double a[FE_DYNAMICS_MAX_ORDER], raw[FE_DISCOVER_MAX_COLUMNS], d[FE_DYNAMICS_MAX_ORDER] = {0};
    int rc;
    u->adj = 0.0;
    if (K == 0)
        return fe__run_terms(u, s, phi);
    if (new_pair || !u->sens.started) {
        fe_dynamics_sens_restart(&u->sens);
        fe_dynamics_deviation_restart(&u->dev);
    }
    if ((rc = fe_dynamics_fit_jacobian(s, a, &u->dyn)) != FE_OK)
        return rc;
    if (u->refine) {
        if ((rc = fe_dynamics_deviation_step(&u->dev, s, a, fe_dynamics_fit_eval, &u->dyn,
                                             fe__run_force, u, d)) != FE_OK)
            return rc;
        *(K == 2 ? &s->position : &s->temperature) += d[0];
        if (K == 2)
            s->velocity += d[1];
        if ((rc = fe_dynamics_fit_jacobian(s, a, &u->dyn)) != FE_OK)
            return rc;
    }
    if ((rc = fe__run_terms(u, s, raw)) != FE_OK
        || (rc = fe_dynamics_sens_step(&u->sens, s->t, a, raw + 1, phi + 1, NULL)) != FE_OK)
        return rc;
    phi[0] = raw[FE_DYNAMICS_OFFSET];
    u->adj = -d[0];
    for (size_t j = 1; j < m; j++)
        u->adj += u->theta[j] * phi[j];
    return FE_OK;
}

/* A row of the simulation between two of the recording's (the pair's
   hook): the signatures and the deviation are carried through it, and
   nothing is folded.  Only while a pass folds or maps (u->nodes). */
static int fe__run_node(void *user, const fe__pair *p, fe_sample *s)
{
    fe__run *u = user;
    double phi[FE_DISCOVER_MAX_COLUMNS];
    if (!u->nodes)
        return FE_OK;
    fe__fill_state(u->a.order, p, s);
    return fe__run_columns(u, s, 0, phi);
}


/* Pass 2: every candidate term of every row into the engine's
   accumulation, a panel at a time (the terms by fe_catalog_eval_rows,
   the lagged products by fe_discover_add_rows' matrix products), the
   panel flushed before a break.  --order 0 folds in two parts when pass 1
   marked a cut (above); --order K folds the signatures row by row. */
static int fe__run_fold_parts(fe__run *u, const fe__mark *m, size_t nst);

static int fe__run_fold(fe__run *u)
{
    size_t nst = fe_discover_acc_doubles(u->cat.count, (size_t)u->a.blocks);
    const fe__mark *cut = fe__cut(u, fe__fold_middle(u));
    fe__panel *p;
    fe_sample s;
    int rc, new_pair;
    u->nwork = fe_discover_workspace_doubles(u->cat.count, (size_t)u->a.blocks);
    if (u->storage == NULL) {           /* a second fold (--order) reuses them */
        u->storage = malloc(nst * sizeof *u->storage);
        u->work = malloc(u->nwork * sizeof *u->work);
        u->panel = malloc(2 * sizeof *u->panel);
        u->term_work = malloc(fe_catalog_work_doubles(FE_DISCOVER_PANEL_ROWS)
                              * sizeof *u->term_work);
    }
    p = u->panel;
    if (u->storage == NULL || u->work == NULL || p == NULL || u->term_work == NULL)
        return FE__OOM(u);
    if (fe_discover_acc_init(&u->acc, u->cat.count, (size_t)u->a.blocks, u->out.fit, 0,
                             u->storage, nst) != FE_OK
        || fe_discover_set_lags(&u->acc, (size_t)u->a.lags) != FE_OK)
        return FE__OOM(u);
    if ((rc = fe__stream_rewind(&u->st, u->err, sizeof u->err)) != FE_CLI_OK)
        return rc;
    if (cut != NULL)
        return fe__run_fold_parts(u, cut, nst);
    fe_dynamics_sens_restart(&u->sens);
    p->n = p->nbreak = 0;
    u->nodes = u->a.order != 0;
    while ((rc = fe__stream_next(&u->st, &s, &new_pair, u->err, sizeof u->err)) == FE_OK) {
        size_t k = p->n;
        if ((new_pair || k == FE_DISCOVER_PANEL_ROWS)
            && (fe__panel_terms(u->a.order == 0 ? &u->cat : NULL, p, u->term_work) != FE_OK
                || fe__panel_fold(&u->acc, p) != FE_OK))
            break;                              /* p->n: the refused row */
        if (new_pair)
            fe_discover_break(&u->acc);
        k = p->n;
        p->line[k] = u->a.pairs[u->st.cur].real.line;
        p->file[k] = u->a.pairs[u->st.cur].real.name;
        p->t[k] = s.t;
        if (u->a.order == 0) {          /* the terms, a panel at a time */
            p->r[k] = s.real - s.sim;
            fe__terms_row(&u->terms, &u->a.pairs[u->st.cur], &s, p->vars[k]);
        } else {                        /* the signatures, row by row */
            if (fe__run_columns(u, &s, new_pair, p->phi[k]) != FE_OK)
                break;
            p->r[k] = s.real - s.sim + u->adj;
        }
        p->n++;
    }
    u->nodes = 0;
    if (rc == FE_OK
        || (rc == FE_END && (fe__panel_terms(u->a.order == 0 ? &u->cat : NULL, p, u->term_work)
                             != FE_OK || fe__panel_fold(&u->acc, p) != FE_OK))) {
        fe__name_refusal(u, p);
        return FE_CLI_INPUT;
    }
    return rc == FE_END ? FE_CLI_OK : rc;
}

/* Pass 2 in two parts, cut at mark m: the later part on its own thread
   with second readers when it can, else after the earlier one on the
   calling thread; then the later merged into the earlier. */
static int fe__run_fold_parts(fe__run *u, const fe__mark *m, size_t nst)
{
    fe__part part[2];
    fe__later later;
    pthread_t thread;
    int threaded = 0;
    if (u->storage2 == NULL) {
        u->storage2 = malloc(nst * sizeof *u->storage2);
        u->term_work2 = malloc(fe_catalog_work_doubles(FE_DISCOVER_PANEL_ROWS)
                               * sizeof *u->term_work2);
    }
    if (u->storage2 == NULL || u->term_work2 == NULL
        || fe_discover_acc_init(&u->acc2, u->cat.count, (size_t)u->a.blocks, u->out.fit, m->row,
                                u->storage2, nst) != FE_OK
        || fe_discover_set_lags(&u->acc2, (size_t)u->a.lags) != FE_OK)
        return FE__OOM(u);
    memset(part, 0, sizeof part);
    part[0].u = part[1].u = u;
    part[0].st = &u->st;
    part[0].acc = &u->acc;
    part[0].p = &u->panel[0];
    part[0].term_work = u->term_work;
    part[0].limit = m->row;
    part[1].acc = &u->acc2;
    part[1].p = &u->panel[1];
    part[1].term_work = u->term_work2;
    part[1].limit = (size_t)-1;
    if (u->a.threads > 1 && fe__later_open(&later, u, m) == FE_CLI_OK) {
        sigset_t all, mask;
        part[1].st = &later.st;
        sigfillset(&all);       /* signals stay the calling thread's */
        pthread_sigmask(SIG_BLOCK, &all, &mask);
        threaded = pthread_create(&thread, NULL, fe__part_run, &part[1]) == 0;
        pthread_sigmask(SIG_SETMASK, &mask, NULL);
        if (!threaded)
            fe__later_close(&later);
    }
    if (threaded)
        fe__pairs_threads(u, 1);
    fe__part_fold(&part[0]);
    if (threaded) {
        pthread_join(thread, NULL);
        fe__later_close(&later);
        fe__pairs_threads(u, u->a.threads);
    } else if (part[0].rc == FE_END && part[0].refused == FE_OK) {
        part[1].st = &u->st;    /* on from where the earlier part stopped */
        fe__part_fold(&part[1]);
    }
    for (int i = 0; i < 2; i++) {
        const fe__part *w = &part[i];
        if (w->refused != FE_OK) {
            fe__name_refusal(u, w->p);
            return FE_CLI_INPUT;
        }
        if (w->rc != FE_END) {
            snprintf(u->err, sizeof u->err, "%s", w->err);
            return w->rc;
        }
    }
    if (fe_discover_merge(&u->acc, &u->acc2) != FE_OK) {
        snprintf(u->err, sizeof u->err, "a lagged product is not finite: refused, nothing reported");
        return FE_CLI_INPUT;
    }
    return FE_CLI_OK;
}

/* Select the terms (discover.org). */
static int fe__run_select(fe__run *u)
{
    fe_discover_group groups[FE_DISCOVER_MAX_GROUPS];
    fe_discover_options opt = fe_discover_default_options();
    int rc;
    if (u->res == NULL && (u->res = malloc(sizeof *u->res)) == NULL)
        return FE__OOM(u);
    fe_catalog_groups(&u->cat, groups);
    opt.alpha = u->a.alpha;
    opt.base = u->base;
    opt.nbase = u->nbase;
    opt.noise = u->a.noise;
    opt.nprobes = u->nprobes;
    rc = fe_discover_select(&u->acc, groups, u->cat.count, &opt, u->res, u->work, u->nwork);
    if (rc != FE_OK) {
        snprintf(u->err, sizeof u->err, "%s%s", fe_strerror(rc),
                 rc == FE_ESINGULAR ? ": the base terms are collinear on these data"
                 : rc == FE_ETOOFEW ? ": a time block has no rows" : "");
        return FE_CLI_REFUSED;
    }
    memcpy(u->out.baseline_coef, u->res->path[0].coef,
           u->nbase * sizeof *u->out.baseline_coef);
    return FE_CLI_OK;
}

/* Gauss-Newton (--order K): fold and select again about the trajectory
   corrected by the terms found, until the coefficients stop moving (a
   fiftieth of a standard error) or FE__GN_ITERATIONS folds.  The baseline
   (the simulation with its offset) stays the first fold's; the map pass
   then integrates the deviation under the final coefficients. */
enum { FE__GN_ITERATIONS = 4 };

static void fe__run_theta(fe__run *u)
{
    const fe_discover_result *r = u->res;
    memset(u->theta, 0, sizeof u->theta);
    for (size_t j = 0; j < r->ncols; j++)
        if (r->cols[j] != FE_DYNAMICS_OFFSET)
            u->theta[r->cols[j]] = r->coef[j];
}

static int fe__run_refine(fe__run *u)
{
    fe_discover_step base0;
    fe_discover_fit baseline0;
    int rc;
    if (u->a.order == 0 || u->res->steps == 0)
        return FE_CLI_OK;
    base0 = u->res->path[0];
    baseline0 = u->res->baseline;
    u->refine = 1;
    for (int it = 0; it < FE__GN_ITERATIONS; it++) {
        double before[FE_DISCOVER_MAX_GROUPS];
        int moved = 0;
        memcpy(before, u->theta, sizeof before);
        fe__run_theta(u);
        for (size_t j = 0; j < u->res->ncols; j++) {
            size_t c = u->res->cols[j];
            if (fabs(u->theta[c] - before[c]) > 0.02 * u->res->stderr_[j])
                moved = 1;
        }
        for (size_t c = 1; c < u->cat.count; c++)
            if (before[c] != 0.0 && u->theta[c] == 0.0)
                moved = 1;                  /* a term left the model */
        if (it > 0 && !moved)
            break;
        if ((rc = fe__run_fold(u)) != FE_CLI_OK || (rc = fe__run_select(u)) != FE_CLI_OK)
            return rc;
    }
    fe__run_theta(u);
    u->res->path[0] = base0;
    u->res->baseline = baseline0;
    memcpy(u->out.baseline_coef, base0.coef, u->nbase * sizeof *u->out.baseline_coef);
    return FE_CLI_OK;
}

/* The report folder, and the file of residual points in it. */
static int fe__run_open_report(fe__run *u)
{
    int made;
    if (u->a.report == NULL)
        return FE_CLI_OK;
    made = mkdir(u->a.report, 0777) == 0;
    if (!made && errno != EEXIST) {
        snprintf(u->err, sizeof u->err, "%.1000s: cannot create: %s", u->a.report,
                 strerror(errno));
        return FE_CLI_IO;
    }
    fe__report_pending(u->a.report, made);
    u->nplot = (size_t)u->a.blocks
               + (u->out.heldout > 0 ? (size_t)ceil((double)u->out.heldout
                                                    * (double)u->a.blocks
                                                    / (double)u->out.fit) : 0);
    if ((u->pblocks = calloc(u->nplot, sizeof *u->pblocks)) == NULL)
        return FE__OOM(u);
    snprintf(u->points, sizeof u->points, "%s/residuals.dat", u->a.report);
    if ((u->pts = fopen(u->points, "w")) == NULL) {
        snprintf(u->err, sizeof u->err, "%.1000s: cannot write: %s", u->points,
                 strerror(errno));
        return FE_CLI_IO;
    }
    return FE_CLI_OK;
}

/* Room for the final model refitted on each recording alone. */
static int fe__run_per_alloc(fe__run *u)
{
    size_t m = u->res->ncols, np = u->a.npairs;
    u->out.npairs = np;
    u->per = calloc(np, sizeof *u->per);
    u->per_g = calloc(np * fe_lsq_storage(m), sizeof *u->per_g);
    u->out.per_coef = calloc(np * (m + 1), sizeof *u->out.per_coef);
    u->out.per_se = calloc(np * (m + 1), sizeof *u->out.per_se);
    u->out.per_rows = calloc(np, sizeof *u->out.per_rows);
    u->out.per_held = calloc(np, sizeof *u->out.per_held);
    if (u->per == NULL || u->per_g == NULL || u->out.per_coef == NULL
        || u->out.per_se == NULL || u->out.per_rows == NULL || u->out.per_held == NULL)
        return FE__OOM(u);
    for (size_t q = 0; q < np && m > 0; q++)
        fe_lsq_init(&u->per[q], m, u->per_g + q * fe_lsq_storage(m));
    return FE_CLI_OK;
}

/* The catalog's terms at a part's sample (--order 0). */
static int fe__part_terms(const fe__part *w, const fe_sample *s, double *phi)
{
    double row[FE__MAX_VARS];
    fe__terms_row(&w->u->terms, &w->st->a->pairs[w->st->cur], s, row);
    return fe_catalog_eval_rows(&w->u->cat, row, FE__MAX_VARS, 1, phi, FE_DISCOVER_MAX_COLUMNS,
                                w->term_work, NULL);
}

/* Pass 3's rows of a part: each row's residual before the discovered
   terms (simulation and base) and after them, into the part's residual
   map and per-recording fits, and (one part: the report) every few rows
   into the plot's points. */
static void fe__part_map(fe__part *w)
{
    fe__run *u = w->u;
    const fe_discover_result *r = u->res;
    size_t i = w->row0, stride = u->out.rows / FE__PLOT_POINTS + 1, done = 0;
    int rc = FE_END, new_pair, pair = (int)w->st->cur;
    fe_sample s;
    double phi[FE_DISCOVER_MAX_COLUMNS];
    w->refused = FE_OK;
    w->err[0] = '\0';
    while (done < w->limit
           && (rc = fe__stream_next(w->st, &s, &new_pair, w->err, sizeof w->err)) == FE_OK) {
        double before = s.real - s.sim, after;
        for (; new_pair && pair < (int)w->st->cur; pair++)     /* a recording ends */
            if (i > 0)
                fe_residual_map_break(w->map);
        pair = (int)w->st->cur;
        if (i >= u->out.fit)
            w->per_held[pair] += 1.0;
        if ((u->a.order == 0 ? fe__part_terms(w, &s, phi)
                             : fe__run_columns(u, &s, new_pair, phi)) != FE_OK) {
            snprintf(w->err, sizeof w->err, "a term is not finite at t = %g", s.t);
            w->refused = FE_ENONFINITE;
            break;
        }
        for (size_t j = 0; j < u->nbase; j++)
            before -= u->out.baseline_coef[j] * phi[u->base[j]];
        after = s.real - s.sim + (u->a.order == 0 ? 0.0 : u->adj);
        for (size_t j = 0; j < r->ncols; j++)
            after -= r->coef[j] * phi[r->cols[j]];
        if (fe_residual_map_add(w->map, &s, before, after) != FE_OK) {
            snprintf(w->err, sizeof w->err, "a residual is not finite at t = %g", s.t);
            w->refused = FE_ENONFINITE;
            break;
        }
        if (u->pblocks != NULL) {
            double x;
            size_t K = (size_t)u->a.blocks;
            size_t pk = i < u->out.fit ? (size_t)((double)i * (double)K / (double)u->out.fit)
                        : K + (size_t)((double)(i - u->out.fit) * (double)K / (double)u->out.fit);
            if (new_pair && i > 0) {
                if (s.t + u->shift <= u->last_x)
                    u->shift = u->last_x + u->step_x - s.t;
                if (u->njoins < FE__MAX_PAIRS)
                    u->joins[u->njoins++] = s.t + u->shift;
            }
            x = s.t + u->shift;
            if (i > 0 && !new_pair)
                u->step_x = x - u->last_x;
            u->last_x = x;
            if (i == u->out.fit)
                u->held_x0 = x;
            fe_residual_cell_add(&u->pblocks[pk < u->nplot ? pk : u->nplot - 1], x, pair, before,
                                 after);
        }
        if (r->ncols > 0) {
            double row[FE_DISCOVER_MAX_COLUMNS];
            for (size_t j = 0; j < r->ncols; j++)
                row[j] = phi[r->cols[j]];
            fe_lsq_add(&w->per[pair], row, s.real - s.sim, 1.0);
        }
        if (u->pts != NULL && i % stride == 0)
            fprintf(u->pts, "%.10g %.6g %.6g %.6g %.6g %.6g %.10g %.10g\n", s.t, before, after,
                    s.position, s.velocity, s.temperature, s.real, s.sim);
        i++;
        done++;
        rc = FE_END;
    }
    w->rc = rc;
}

/* Pass 3's parts: the later one's map and fits, then both parts as pass
   2's (fe__run_fold_parts), merged. */
static int fe__run_map_parts(fe__run *u, fe__part part[2], const fe__mark *m)
{
    size_t np = u->a.npairs, k = u->res->ncols;
    fe__later later;
    pthread_t thread;
    int threaded = 0;
    u->map2 = malloc(sizeof *u->map2);
    u->per2 = calloc(np, sizeof *u->per2);
    u->per_g2 = calloc(np * fe_lsq_storage(k), sizeof *u->per_g2);
    u->per_held2 = calloc(np, sizeof *u->per_held2);
    if (u->map2 == NULL || u->per2 == NULL || u->per_g2 == NULL || u->per_held2 == NULL
        || (u->term_work2 == NULL
            && (u->term_work2 = malloc(fe_catalog_work_doubles(FE_DISCOVER_PANEL_ROWS)
                                       * sizeof *u->term_work2)) == NULL)
        || fe_residual_map_init(u->map2, (size_t)u->a.blocks, u->out.fit, m->row, u->roles,
                                u->lo, u->hi) != FE_OK)
        return FE__OOM(u);
    for (size_t q = 0; q < np && k > 0; q++)
        fe_lsq_init(&u->per2[q], k, u->per_g2 + q * fe_lsq_storage(k));
    part[0].limit = m->row;
    part[1].u = u;
    part[1].map = u->map2;
    part[1].per = u->per2;
    part[1].per_held = u->per_held2;
    part[1].term_work = u->term_work2;
    part[1].row0 = m->row;
    part[1].limit = (size_t)-1;
    if (u->a.threads > 1 && fe__later_open(&later, u, m) == FE_CLI_OK) {
        sigset_t all, mask;
        part[1].st = &later.st;
        sigfillset(&all);
        pthread_sigmask(SIG_BLOCK, &all, &mask);
        threaded = pthread_create(&thread, NULL, fe__part_run_map, &part[1]) == 0;
        pthread_sigmask(SIG_SETMASK, &mask, NULL);
        if (!threaded)
            fe__later_close(&later);
    }
    if (threaded)
        fe__pairs_threads(u, 1);
    fe__part_map(&part[0]);
    if (threaded) {
        pthread_join(thread, NULL);
        fe__later_close(&later);
        fe__pairs_threads(u, u->a.threads);
    } else if (part[0].rc == FE_END && part[0].refused == FE_OK) {
        part[1].st = &u->st;
        fe__part_map(&part[1]);
    }
    for (int i = 0; i < 2; i++)
        if (part[i].refused != FE_OK || part[i].rc != FE_END) {
            snprintf(u->err, sizeof u->err, "%s", part[i].err);
            return part[i].refused != FE_OK ? FE_CLI_INPUT : part[i].rc;
        }
    if (fe_residual_map_merge(u->map, u->map2) != FE_OK) {
        snprintf(u->err, sizeof u->err, "a residual is not finite");
        return FE_CLI_INPUT;
    }
    for (size_t q = 0; q < np; q++) {
        if (k > 0 && fe_lsq_merge(&u->per[q], &u->per2[q]) != FE_OK) {
            snprintf(u->err, sizeof u->err, "a residual is not finite");
            return FE_CLI_INPUT;
        }
        u->out.per_held[q] += u->per_held2[q];
    }
    return FE_CLI_OK;
}

/* Pass 3: the rows into the residual map (locate.org), the per-recording
   fits and the plot's points; in two parts, as pass 2, when there is no
   report to write in file order. */
static int fe__run_map(fe__run *u)
{
    const fe__mark *cut;
    fe__part part[2];
    int rc;
    if ((u->map = malloc(sizeof *u->map)) == NULL)
        return FE__OOM(u);
    if (fe_residual_map_init(u->map, (size_t)u->a.blocks, u->out.fit, 0, u->roles, u->lo,
                             u->hi) != FE_OK)
        return FE__OOM(u);
    if ((rc = fe__run_open_report(u)) != FE_CLI_OK || (rc = fe__run_per_alloc(u)) != FE_CLI_OK
        || (rc = fe__stream_rewind(&u->st, u->err, sizeof u->err)) != FE_CLI_OK)
        return rc;
    fe_dynamics_sens_restart(&u->sens);
    memset(part, 0, sizeof part);
    part[0].u = u;
    part[0].st = &u->st;
    part[0].map = u->map;
    part[0].per = u->per;
    part[0].per_held = u->out.per_held;
    part[0].term_work = u->term_work;
    part[0].limit = (size_t)-1;
    cut = u->pts == NULL && u->pblocks == NULL ? fe__cut(u, u->out.rows / 2) : NULL;
    if (cut != NULL)
        return fe__run_map_parts(u, part, cut);
    u->nodes = u->a.order != 0;         /* one part, on this thread (--order is never cut) */
    fe__part_map(&part[0]);
    u->nodes = 0;
    if (part[0].refused != FE_OK || part[0].rc != FE_END) {
        snprintf(u->err, sizeof u->err, "%s", part[0].err);
        return part[0].refused != FE_OK ? FE_CLI_INPUT : part[0].rc;
    }
    return FE_CLI_OK;
}

/* The final model refitted on each recording alone (classical errors). */
static void fe__run_per_recording(fe__run *u)
{
    size_t m = u->res->ncols;
    for (size_t q = 0; q < u->a.npairs && m > 0; q++) {
        double *cov = malloc(m * m * sizeof *cov);
        double *w = malloc(fe_lsq_solve_work(m) * sizeof *w), rss;
        u->out.per_rows[q] = u->per[q].n;
        if (cov != NULL && w != NULL
            && fe_lsq_solve(&u->per[q], NULL, m, u->out.per_coef + q * m, &rss, cov, w) == FE_OK)
            for (size_t j = 0; j < m; j++)
                u->out.per_se[q * m + j] = sqrt(cov[j * m + j]);
        else
            for (size_t j = 0; j < m; j++)
                u->out.per_coef[q * m + j] = NAN;
        free(cov);
        free(w);
    }
}

/* Locate under the baseline's noise model, and decide the verdict
   (locate.org). */
static void fe__run_locate(fe__run *u)
{
    const fe_discover_result *r = u->res;
    fe_verdict v;
    fe_residual_map_locate(u->map, fe_discover_row_worth(&r->path[0].noise, r->baseline.n),
                           u->a.alpha, u->out.located, FE__MAX_LOCATED, &u->out.nlocated);
    if (u->out.nlocated > FE__MAX_LOCATED)
        u->out.nlocated = FE__MAX_LOCATED;
    v = fe_discover_verdict(r, u->map, u->out.nlocated, u->a.alpha);
    u->out.verdict = fe_verdict_text(v);
    u->out.why = fe_verdict_why(v);
    u->out.c = &u->cat;
    u->out.r = r;
    u->out.map = u->map;
    u->out.blocks = (size_t)u->a.blocks;
    u->out.alpha = u->a.alpha;
    u->out.base = u->base;
    u->out.nbase = u->nbase;
    u->out.order = (size_t)u->a.order;
    u->out.dyn = u->a.order > 0 ? &u->dyn : NULL;
    for (size_t j = 0; j < u->cat.count; j++)
        u->out.expression[j] = fe__terms_text(&u->terms, &u->cat, j);
    fe__unit_of(u->a.channel, u->out.unit, sizeof u->out.unit);
}

/* The report: the plot data, report.md and plots.gp, and the plots when
   gnuplot is there. */
static int fe__run_report(fe__run *u)
{
    fe__plot_info pi;
    const fe__pair *p0 = &u->a.pairs[0];
    const fe_discover_result *r = u->res;
    int v = -1;                 /* map->bin[v]: position, velocity, temperature */
    char bp[4200];
    double w0 = fe_discover_row_worth(&r->path[0].noise, r->baseline.n);
    double w1 = fe_discover_row_worth(&r->noise, r->final.n);
    int rc;
    fclose(u->pts);
    u->pts = NULL;
    memset(&pi, 0, sizeof pi);
    for (size_t i = 0; i < u->out.nlocated && v < 0; i++)
        if (u->out.located[i].region != FE_REGION_TIME) {
            const char *var = fe_region_variable(u->out.located[i].region);
            v = strcmp(var, "position") == 0 ? 0 : strcmp(var, "temperature") == 0 ? 2 : 1;
        }
    if (v < 0)
        v = u->roles & FE_ROLE_VELOCITY ? 1 : u->roles & FE_ROLE_TEMPERATURE ? 2
            : u->roles & FE_ROLE_POSITION ? 0 : -1;
    pi.time_name = p0->real.names[p0->real_cols[0]];
    pi.channel = p0->real.names[p0->real_cols[1]];
    if (v >= 0 && p0->role_col[v] >= 0) {
        pi.state_var = fe__role_names[v];
        pi.state_name = p0->sim.names[p0->sim_cols[p0->role_col[v]]];
    }
    pi.held = u->out.heldout > 0;
    pi.held0 = u->held_x0;
    pi.held1 = u->last_x;
    pi.joins = u->joins;
    pi.njoins = u->njoins;
    snprintf(bp, sizeof bp, "%s/blocks.dat", u->a.report);
    rc = fe__write_means(bp, u->pblocks, u->nplot, (size_t)u->a.blocks, 1, w0, w1) != 0
             ? FE_CLI_IO : FE_CLI_OK;
    snprintf(bp, sizeof bp, "%s/bins.dat", u->a.report);
    if (rc == FE_CLI_OK && pi.state_var != NULL
        && fe__write_means(bp, u->map->bin[v], FE_RESIDUAL_BINS, FE_RESIDUAL_BINS, 0, w0, w1) != 0)
        rc = FE_CLI_IO;
    if (rc != FE_CLI_OK) {
        snprintf(u->err, sizeof u->err, "%.1000s: cannot write the plot data", u->a.report);
        return rc;
    }
    rc = fe__write_report(u->a.report, &u->out, &pi, u->err, sizeof u->err);
    if (rc != FE_CLI_OK)
        return rc;
    fe_cli_pending_clear();
    if (!u->a.json)
        printf("report: %s/report.md\n", u->a.report);
    return FE_CLI_OK;
}

/* Open every pair and find its columns, those of the user's terms too. */
static int fe__run_open(fe__run *u)
{
    int rc;
    for (size_t i = 0; i < u->a.npairs; i++) {
        rc = fe__pair_open(&u->a.pairs[i], &u->a, &u->roles, u->kelvin, u->err, sizeof u->err);
        if (rc != FE_CLI_OK)
            return rc;
    }
    if (u->a.order > 0) {               /* the state defaults to the channel */
        u->roles |= u->a.order == 2 ? FE_ROLE_POSITION | FE_ROLE_VELOCITY : FE_ROLE_TEMPERATURE;
        fe_dynamics_span_init(&u->span, (size_t)u->a.order);
    }
    if ((rc = fe__terms_compile(&u->terms, &u->a, u->roles, u->err, sizeof u->err)) != FE_CLI_OK)
        return rc;
    for (size_t i = 0; i < u->a.npairs; i++)
        if ((rc = fe__terms_open(&u->terms, &u->a.pairs[i], u->err, sizeof u->err)) != FE_CLI_OK)
            return rc;
    u->st.a = &u->a;
    return FE_CLI_OK;
}

int fe_cli_discover(int argc, char **argv)
{
    fe__run *u = calloc(1, sizeof *u);
    int rc;
    if (u == NULL) {
        fprintf(stderr, "foldest discover: out of memory\n");
        return FE_CLI_IO;
    }
    rc = fe_cli_options("discover", fe__discover_options, &argc, &argv);
    if (rc != FE_CLI_OK) {
        free(u);
        return rc < 0 ? FE_CLI_OK : rc;
    }
    for (int i = 1; i < argc; i++)
        if (strcmp(argv[i], "--sphere") == 0) {
            free(u);
            return fe__discover_sphere_main(argc, argv);
        }
    rc = fe__discover_parse(argc, argv, &u->a, u->err, sizeof u->err);
    if (rc == -1) {
        fe__discover_usage(stdout);
        rc = FE_CLI_OK;
    } else if (rc == FE_CLI_OK) {
        if ((rc = fe__run_open(u)) == FE_CLI_OK && (rc = fe__run_scan(u)) == FE_CLI_OK
            && (rc = fe__run_base(u)) == FE_CLI_OK && (rc = fe__run_ident(u)) == FE_CLI_OK
            && (rc = fe__run_fold(u)) == FE_CLI_OK && (rc = fe__run_select(u)) == FE_CLI_OK
            && (rc = fe__run_refine(u)) == FE_CLI_OK && (rc = fe__run_map(u)) == FE_CLI_OK) {
            fe__run_per_recording(u);
            fe__run_locate(u);
            if (u->a.json)
                fe__print_json(stdout, &u->out);
            else
                fe__print_story(stdout, &u->out);
            if (u->pts != NULL)
                rc = fe__run_report(u);
        }
        if (rc != FE_CLI_OK)
            fprintf(stderr, "foldest discover: %s\n", u->err);
    } else {
        fprintf(stderr, "foldest discover: %s\n", u->err);
        if (rc == FE_CLI_USAGE)
            fprintf(stderr, "'foldest discover --help' for usage\n");
    }
    fe__run_free(u);
    free(u);
    return rc;
}
/* Run discovery on recordings ends here */
/* [[file:../../literate/cli_discover.org::Discover on a three-axis recording][Discover on a three-axis recording]] */
typedef struct fe__sphere_args {
    const char *path, *time, *temperature;
    char *columns;
    double holdout, alpha;
    long blocks;
    int json;
} fe__sphere_args;

static int fe__sphere_read(fe_cli_table *t, const size_t *cols, size_t k, double *v,
                           char *err, size_t errlen)
{
    return fe_cli_table_next(t, cols, k, v, err, errlen);
}

static int fe__discover_sphere(fe__sphere_args *a)
{
    fe_cli_table t;
    size_t cols[5], k = 3, rows = 0, fit_rows, held;
    char err[2048];
    double v[5], t1 = 0, temp1 = 0;
    fe_quadric q;
    fe_sphere_fit fit;
    fe_discover_acc acc;
    fe_catalog_axes cat;
    const fe_discover_group *groups = cat.groups;
    size_t base[2] = {0, 1};
    double *storage = NULL, *work = NULL, phi[FE_CATALOG_AXES_COLUMNS];
    fe_discover_result *res = NULL;
    fe_discover_options opt = fe_discover_default_options();
    int rc, has_time = 0, has_temp = a->temperature != NULL;
    double oct_n[8] = {0}, oct_s0[8] = {0}, oct_s1[8] = {0}, ms_all = 0;

    rc = fe_cli_table_open_rewindable(&t, a->path, -1, err, sizeof err);
    if (rc != FE_CLI_OK) {
        fprintf(stderr, "foldest discover: %s\n", err);
        return rc;
    }
    /* Columns: three axes, then time and temperature when given. */
    if (a->columns != NULL) {
        char *names[4];
        if (fe_cli_split_list(a->columns, names, 4) != 3) {
            fprintf(stderr, "foldest discover: --columns needs three columns, a,b,c\n");
            fe_cli_table_close(&t);
            return FE_CLI_USAGE;
        }
        for (int i = 0; i < 3; i++)
            if ((rc = fe_cli_table_column(&t, names[i], &cols[i], err, sizeof err)) != FE_CLI_OK)
                goto fail;
    } else if (t.ncols == 3) {
        cols[0] = 0;
        cols[1] = 1;
        cols[2] = 2;
    } else {
        fprintf(stderr, "foldest discover: %s has %zu columns: name the three axes with "
                        "--columns a,b,c\n", t.name, t.ncols);
        fe_cli_table_close(&t);
        return FE_CLI_USAGE;
    }
    if (a->time != NULL) {
        if ((rc = fe_cli_table_column(&t, a->time, &cols[k++], err, sizeof err)) != FE_CLI_OK)
            goto fail;
        has_time = 1;
    }
    if (has_temp
        && (rc = fe_cli_table_column(&t, a->temperature, &cols[k++], err, sizeof err)) != FE_CLI_OK)
        goto fail;

    /* Pass 1: the moments, and the sphere. */
    fe_quadric_init(&q, NULL);
    while ((rc = fe__sphere_read(&t, cols, k, v, err, sizeof err)) == FE_OK) {
        if (rows == 0) {
            t1 = has_time ? v[3] : 0.0;
            temp1 = has_temp ? v[k - 1] : 0.0;
        }
        if (fe_quadric_add(&q, v) != FE_OK) {
            snprintf(err, sizeof err, "%s:%zu: sample too large", t.name, t.line);
            rc = FE_CLI_INPUT;
            goto fail;
        }
        rows++;
    }
    if (rc != FE_END)
        goto fail;
    if (rows == 0) {            /* malformed input, not a refusal */
        snprintf(err, sizeof err, "%s: no data rows", t.name);
        rc = FE_CLI_INPUT;
        goto fail;
    }
    /* The refusal, not the status, decides here: a fit that fails still
       names its refusal. */
    (void)fe_sphere_fit_moments(&q, FE_FIT_SPHERE, NULL, &fit);
    if (fit.refusal == FE_SPHERE_TOO_FEW || fit.refusal == FE_SPHERE_PLANAR
        || fit.refusal == FE_SPHERE_HEMISPHERE || fit.refusal == FE_SPHERE_COVERAGE) {
        if (a->json) {
            printf("{\"verdict\": \"refused\", \"reason\": ");
            fe_cli_json_string(stdout, fe_sphere_refusal_string(fit.refusal));
            printf(", \"coverage\": ");
            fe_cli_json_number(stdout, fit.coverage);
            printf(", \"n\": %zu}\n", rows);
        }
        fprintf(stderr, "foldest discover: %s: the sphere is not determined by these data "
                        "(%s; coverage %.0f%% of the regions): nothing to compare against\n",
                t.name, fe_sphere_refusal_string(fit.refusal), 100.0 * fit.coverage);
        fe_cli_table_close(&t);
        return FE_CLI_REFUSED;
    }
    /* The sphere itself: the algebraic least-squares sphere, from the same
       moments (always defined when the data are not planar, unlike the
       geometric fit, which can run off to a plane when the data are a
       strong ellipsoid).  One-sidedness was judged above. */
    if (fe_sphere_fit_algebraic(&q, NULL, &fit) != FE_OK
        && fit.refusal != FE_SPHERE_HEMISPHERE) {
        fprintf(stderr, "foldest discover: %s: no sphere fits these samples\n", t.name);
        rc = FE_CLI_REFUSED;
        goto done;
    }
    held = (size_t)floor(a->holdout * (double)rows);
    fit_rows = rows - held;
    if (fe_catalog_axes_init(&cat, fit.offset, has_time, t1, has_temp, temp1) != FE_OK) {
        fprintf(stderr, "foldest discover: %s: the sphere's centre is not finite\n", t.name);
        rc = FE_CLI_REFUSED;
        goto done;
    }
    {
        size_t nst = fe_discover_acc_doubles(FE_CATALOG_AXES_COLUMNS, (size_t)a->blocks);
        size_t nw = fe_discover_workspace_doubles(FE_CATALOG_AXES_COLUMNS, (size_t)a->blocks);
        storage = malloc(nst * sizeof *storage);
        work = malloc(nw * sizeof *work);
        res = malloc(sizeof *res);
        if (storage == NULL || work == NULL || res == NULL) {
            snprintf(err, sizeof err, "out of memory");
            rc = FE_CLI_IO;
            goto fail;
        }
        if (fe_discover_acc_init(&acc, FE_CATALOG_AXES_COLUMNS, (size_t)a->blocks, fit_rows, 0,
                                 storage, nst) != FE_OK) {
            fprintf(stderr, "foldest discover: %s: %zu rows are too few for %ld blocks\n",
                    t.name, rows, a->blocks);
            rc = FE_CLI_REFUSED;
            goto done;
        }
        /* Pass 2: the block Gram matrices of the radial residual. */
        if ((rc = fe_cli_table_rewind(&t, err, sizeof err)) != FE_CLI_OK)
            goto fail;
        while ((rc = fe__sphere_read(&t, cols, k, v, err, sizeof err)) == FE_OK) {
            double len;
            if (fe_catalog_axes_eval(&cat, v, has_time ? v[3] : (double)t.rows,
                                     has_temp ? v[k - 1] : 0.0, phi, &len) != FE_OK
                || fe_discover_add(&acc, phi, len - fit.radius) != FE_OK) {
                snprintf(err, sizeof err, "%s:%zu: a sample at the centre", t.name, t.line);
                rc = FE_CLI_INPUT;
                goto fail;
            }
        }
        if (rc != FE_END)
            goto fail;
        opt.alpha = a->alpha;
        opt.base = base;
        opt.nbase = 2;
        opt.noise = FE_DISCOVER_NOISE_BATCH;    /* see the text */
        rc = fe_discover_select(&acc, cat.groups, cat.ngroups, &opt, res, work, nw);
        if (rc != FE_OK) {
            fprintf(stderr, "foldest discover: %s: %s\n", t.name, fe_strerror(rc));
            rc = FE_CLI_REFUSED;
            goto done;
        }
    }
    /* Pass 3: the residual by octant of orientation, before and after. */
    if ((rc = fe_cli_table_rewind(&t, err, sizeof err)) != FE_CLI_OK)
        goto fail;
    {
        size_t i = 0;
        while ((rc = fe__sphere_read(&t, cols, k, v, err, sizeof err)) == FE_OK) {
            double len, before, after;
            int o;
            if (fe_catalog_axes_eval(&cat, v, has_time ? v[3] : (double)t.rows,
                                     has_temp ? v[k - 1] : 0.0, phi, &len) != FE_OK)
                continue;                       /* refused in pass 2 */
            before = len - fit.radius;
            after = before;
            for (size_t j = 0; j < res->ncols; j++)
                after -= res->coef[j] * phi[res->cols[j]];
            o = (phi[1] > 0) + 2 * (phi[2] > 0) + 4 * (phi[3] > 0);
            if (i < fit_rows) {
                oct_n[o] += 1;
                oct_s0[o] += before * before;
                oct_s1[o] += after * after;
                ms_all += before * before;
            }
            i++;
        }
        if (rc != FE_END)
            goto fail;
        ms_all /= (double)fit_rows;
    }
    /* Report. */
    {
        const fe_discover_fit *b0 = &res->baseline, *b1 = &res->final;
        /* Explained when a term is named and the rows held out are not
           predicted worse with the terms than without (locate.org). */
        fe_verdict v = res->steps == 0              ? FE_VERDICT_NO_MISMATCH
                       : fe_discover_heldout_worse(res) ? FE_VERDICT_HELDOUT_WORSE
                                                        : FE_VERDICT_EXPLAINED;
        const char *verdict = fe_verdict_text(v), *why = fe_verdict_why(v);
        if (a->json) {
            printf("{\"verdict\": \"%s\", \"why\": ", verdict);
            if (why != NULL)
                fe_cli_json_string(stdout, why);
            else
                fputs("null", stdout);
            printf(", \"model\": \"sphere\", \"n\": %zu, \"heldout_rows\": %zu", rows, held);
            fe__json_pair(stdout, "radius", fit.radius);
            printf(", \"offset\": [");
            for (int c = 0; c < 3; c++) {
                printf("%s", c ? ", " : "");
                fe__json_number(stdout, fit.offset[c]);
            }
            printf("]");
            fe__json_pair(stdout, "coverage", fit.coverage);
            printf(", \"bad_rows\": ");
            fe_cli_json_bad_rows(stdout);
            for (int w = 0; w < 2; w++) {
                const fe_discover_fit *b = w ? b1 : b0;
                printf(", \"%s\": {\"rms\": ", w ? "final" : "baseline");
                fe__json_number(stdout, b->rms);
                fe__json_pair(stdout, "rms_percent", 100 * b->rms / fit.radius);
                fe__json_pair(stdout, "bic", b->bic);
                fe__json_pair(stdout, "heldout_rms", b->heldout_rms);
                fe__json_pair(stdout, "lag1", b->lag1);
                printf("}");
            }
            printf(", \"discovered\": [");
            for (size_t s = 0; s < res->steps; s++) {
                const fe_discover_group *g = &groups[res->added[s]];
                printf("%s{\"name\": \"%s\", \"description\": \"%s\", \"coefficients\": [",
                       s ? ", " : "", g->name, cat.description[res->added[s]]);
                for (size_t c = 0; c < g->count; c++)
                    for (size_t j = 0; j < res->ncols; j++)
                        if (res->cols[j] == g->first + c) {
                            printf("%s", c ? ", " : "");
                            fe__json_number(stdout, res->coef[j]);
                        }
                printf("], \"stderr\": [");
                for (size_t c = 0; c < g->count; c++)
                    for (size_t j = 0; j < res->ncols; j++)
                        if (res->cols[j] == g->first + c) {
                            printf("%s", c ? ", " : "");
                            fe__json_number(stdout, res->stderr_[j]);
                        }
                printf("]");
                fe__json_pair(stdout, "statistic", res->added_rank[s].statistic);
                fe__json_pair(stdout, "p_value", res->added_rank[s].p_value);
                printf("}");
            }
            printf("]}\n");
        } else {
            printf("%s: %zu samples (%zu held out); the sphere: centre (%.6g, %.6g, %.6g), "
                   "radius %.6g, coverage %.0f%%\n", t.name, rows, held, fit.offset[0],
                   fit.offset[1], fit.offset[2], fit.radius, 100 * fit.coverage);
            printf("baseline (sphere: radius and centre): radial RMS %.4g (%.3g%% of the radius), "
                   "held out %.4g, lag-1 %.2f\n", b0->rms, 100 * b0->rms / fit.radius,
                   b0->heldout_rms, b0->lag1);
            printf("\nwhere it differs (orientation octant of the sample, fitted rows):\n");
            for (int o = 0; o < 8; o++)
                if (oct_n[o] > 0)
                    printf("  octant %c%c%c  %6.0f samples  radial RMS %.4g -> %.4g  (%.2fx the "
                           "overall mean square)\n", o & 1 ? '+' : '-', o & 2 ? '+' : '-',
                           o & 4 ? '+' : '-', oct_n[o], sqrt(oct_s0[o] / oct_n[o]),
                           sqrt(oct_s1[o] / oct_n[o]), oct_s0[o] / oct_n[o] / ms_all);
            printf("\ncandidates, first step (Hotelling tests over %ld time blocks):\n", a->blocks);
            for (size_t i = 0; i < res->nranked[0]; i++) {
                const fe_discover_rank *r = &res->ranking[0][i];
                printf("  %-16s (%zu columns) RSS drop %10.4g   statistic %8.2f   p = %.2g\n",
                       groups[r->group].name, groups[r->group].count, r->rss_drop, r->statistic,
                       r->p_value);
            }
            printf("\nwhat the sphere left out:\n");
            if (res->steps == 0)
                printf("  nothing significant\n");
            for (size_t s = 0; s < res->steps; s++) {
                const fe_discover_group *g = &groups[res->added[s]];
                printf("  %zu. %s (%s): F = %.1f, p = %.2g; coefficients / radius:", s + 1,
                       g->name, cat.description[res->added[s]],
                       res->added_rank[s].statistic, res->added_rank[s].p_value);
                for (size_t c = 0; c < g->count; c++)
                    for (size_t j = 0; j < res->ncols; j++)
                        if (res->cols[j] == g->first + c)
                            printf(" %.4g +/- %.2g", res->coef[j] / fit.radius,
                                   res->stderr_[j] / fit.radius);
                printf("\n");
            }
            printf("\nfit: radial RMS %.4g%% -> %.4g%% of the radius, BIC %.6g -> %.6g, lag-1 "
                   "%.2f -> %.2f\n", 100 * b0->rms / fit.radius, 100 * b1->rms / fit.radius,
                   b0->bic, b1->bic, b0->lag1, b1->lag1);
            if (held > 0)
                printf("held out: radial RMS %.4g%% -> %.4g%%\n", 100 * b0->heldout_rms / fit.radius,
                       100 * b1->heldout_rms / fit.radius);
            printf("\nverdict: %s\n", verdict);
            if (why != NULL)
                printf("  (%s)\n", why);
        }
    }
    rc = FE_CLI_OK;
    goto done;
fail:
    fprintf(stderr, "foldest discover: %s\n", err);
done:
    fe_cli_table_close(&t);
    free(storage);
    free(work);
    free(res);
    return rc;
}
/* Discover on a three-axis recording ends here */
/* [[file:../../literate/cli_discover.org::Parse the three-axis options][Parse the three-axis options]] */
static int fe__discover_sphere_main(int argc, char **argv)
{
    fe__sphere_args a = {NULL, NULL, NULL, NULL, 0.2, 0.05, 20, 0};
    char err[512];
    for (int i = 1; i < argc; i++) {
        const char *o = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        int rc = FE_CLI_OK;
        if (strcmp(o, "--json") == 0) {
            a.json = 1;
            continue;
        }
        if (v == NULL) {
            fprintf(stderr, "foldest discover: %s needs a value\n", o);
            return FE_CLI_USAGE;
        }
        i++;
        if (strcmp(o, "--sphere") == 0)
            a.path = v;
        else if (strcmp(o, "--columns") == 0)
            a.columns = argv[i];
        else if (strcmp(o, "--time") == 0)
            a.time = v;
        else if (strcmp(o, "--role") == 0) {
            const char *eq = strchr(v, '=');
            if (eq == NULL || strcmp(eq + 1, "temperature") != 0) {
                snprintf(err, sizeof err, "--role with --sphere: COLUMN=temperature");
                rc = FE_CLI_USAGE;
            } else {
                argv[i][eq - v] = '\0';
                a.temperature = v;
            }
        } else if (fe__discover_is_shared(o)) {
            rc = fe__discover_shared_option(o, v, &a.holdout, &a.alpha, &a.blocks, err, sizeof err);
        } else {
            snprintf(err, sizeof err, "unknown option '%s' with --sphere", o);
            rc = FE_CLI_USAGE;
        }
        if (rc != FE_CLI_OK) {
            fprintf(stderr, "foldest discover: %s\n", err);
            return rc;
        }
    }
    return fe__discover_sphere(&a);
}
/* Parse the three-axis options ends here */
