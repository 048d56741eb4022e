/* SPDX-License-Identifier: MIT */
/* Discovery's ranking pass, in one run, over 10^6 records in memory:
     - the base model alone: its 3 terms (bias, gain, input) folded into the
       block Gram matrices, by every path the library has (row by row,
       panels of rows, panels of columns), the fastest taken;
     - ranking 50 candidates: the same records with 50 candidate terms beside
       the base (the catalog's shapes: powers and products of the state,
       v|v|, tanh(v/c), T - T0, T^4 - Ta^4, time, a difference for the delay)
       folded into a screen (fe_discover_screen_init: what ranking reads),
       then ranked (fe_discover_select with max_steps 0).
   The caller's work counts: the terms are evaluated inside the timed loop,
   a panel at a time, by columns (a loop per term, which the compiler
   vectorises; tanh by a branch-free expm1, checked against libm below), or
   row by row with libm for the row paths.
   Also timed, for reference: the full accumulation of all 53 terms, which
   forward selection needs after the first step.
   Then the same two folds from CSV files of the same records, as the
   command reads a recording (fe_csv_numbers, the split where it
   declines): with the 6 significant digits of a sensor
   recording, and with the 17 of an exact round trip.
   Prints ns per record; the ratios of issue 16 (ranking from a file at
   most 1.25 times the base fold; in memory, the screen's fold within 2
   times the bound of its multiply-adds at the core's peak, measured here
   by a loop of independent multiply-adds in registers), that the screen ranks as the full
   accumulation does (both by batch means: a screen keeps no lagged
   products; the exit status is 1 when they differ by more than 1e-6), and
   the accumulation's size, which does not depend on the number of
   records. */
#include <fcntl.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bench.h"
#include "foldest.h"

enum { BASE = 3, CAND = 50, K = 20, PANEL = FE_DISCOVER_PANEL_ROWS, PCOL = FE_DISCOVER_PANEL_ROWS, NS = 7 };

/* The screen's multiply-adds a row: the base columns' and r's whole rows,
   the band of each candidate, and the lag product among the whole ones. */
enum { SCREEN_MADDS = (BASE + 1) * (BASE + CAND + 1) + 3 * CAND + (BASE + 1) * (BASE + 1) };

/* Term values of record i (state: x, v, u, s, t, T, s of the record before):
   3 base terms, then (m > BASE) the 50 candidates.  Integer powers by
   multiplication; tanh is a catalog term (Coulomb friction's smooth sign)
   and is kept, four times. */
static void terms(const double *st, size_t m, double *phi)
{
    double x = st[0], v = st[1], u = st[2], s = st[3], t = st[4], T = st[5], sp = st[6];
    double x2, x3, v2, av, dT, T2, Ta2 = 293.15 * 293.15, c[CAND];
    int k = 0;
    phi[0] = 1.0;
    phi[1] = s;
    phi[2] = u;
    if (m == BASE)
        return;
    x2 = x * x;
    x3 = x2 * x;
    v2 = v * v;
    av = fabs(v);
    dT = T - 300.0;
    T2 = T * T;
    /* The catalog's shapes. */
    c[k++] = v;                         /* viscous friction */
    c[k++] = v * av;                    /* quadratic drag */
    c[k++] = tanh(v * 20.0);            /* Coulomb friction, four widths */
    c[k++] = tanh(v * 10.0);
    c[k++] = tanh(v * (1.0 / 0.3));
    c[k++] = tanh(v);
    c[k++] = x;                         /* linear stiffness */
    c[k++] = x3;                        /* cubic stiffness */
    c[k++] = dT;                        /* thermal sensitivity */
    c[k++] = T2 * T2 - Ta2 * Ta2;       /* radiative cooling */
    c[k++] = t;                         /* drift */
    c[k++] = (s - sp) * 100.0;          /* delay: ds/dt */
    c[k++] = dT * s;                    /* thermal gain */
    c[k++] = u * u;
    /* Powers and products of the state. */
    c[k++] = x2;
    c[k++] = x2 * x2;
    c[k++] = x3 * x2;
    c[k++] = v2;
    c[k++] = v2 * v;
    c[k++] = v2 * v2;
    c[k++] = v2 * av;
    c[k++] = dT * dT;
    c[k++] = t * t;
    c[k++] = t * s;
    c[k++] = t * u;
    c[k++] = t * x;
    {
        /* Pairwise products of x, v, u, s, dT: 10, then |.| times v. */
        double q[5] = {x, v, u, s, dT};
        for (int i = 0; i < 5; i++)
            for (int j = i + 1; j < 5; j++)
                c[k++] = q[i] * q[j];
        for (int i = 0; i < 5; i++)
            if (i != 1)
                c[k++] = fabs(q[i]) * v;
        c[k++] = x * v2;
        c[k++] = x2 * v;
        c[k++] = u * v2;
        c[k++] = s * v2;
        c[k++] = s * s;
        c[k++] = s * s * s;
        c[k++] = dT * v;
        c[k++] = dT * x2;
        c[k++] = u * x2;
        c[k++] = u * u * u;
    }
    for (int j = 0; j < k && j < (int)(m - BASE); j++)
        phi[BASE + j] = c[j];
}

/* tanh, branch-free so that a loop over a column vectorises: tanh|x| =
   e / (e + 2) with e = expm1(2|x|) = 2^k (expm1(r) + 1) - 1, 2|x| = k ln 2
   + r, |r| <= ln 2 / 2, expm1(r) by its Taylor series to r^13 (remainder
   below 1e-17 relative); |x| is capped at 20, where tanh is 1 to 1e-17.
   main() checks it against libm. */
static inline double tanh_lanes(double x)
{
    double a = fabs(x) < 20.0 ? fabs(x) : 20.0, y = 2.0 * a;
    double k = nearbyint(y * 1.4426950408889634);
    double r = (y - k * 0.693147180559945286) - k * 2.319046813846299558e-17;
    double p = 1.0 / 6227020800.0, e, scale;
    static const double inv_fact[12] = {1.0 / 479001600.0, 1.0 / 39916800.0,
                                        1.0 / 3628800.0,   1.0 / 362880.0,
                                        1.0 / 40320.0,     1.0 / 5040.0,
                                        1.0 / 720.0,       1.0 / 120.0,
                                        1.0 / 24.0,        1.0 / 6.0,
                                        1.0 / 2.0,         1.0};
    uint64_t bits = (uint64_t)((int64_t)k + 1023) << 52;
    for (int i = 0; i < 12; i++)
        p = p * r + inv_fact[i];
    p *= r;                                 /* expm1(r) */
    memcpy(&scale, &bits, sizeof scale);    /* 2^k */
    e = scale * p + (scale - 1.0);
    return copysign(e / (e + 2.0), x);
}

/* Term values of the q records at st by columns: term j of record t at
   col[j * ld + t], the same values as terms() (tanh to rounding), each
   column one loop. */
static void terms_columns(const double *st, size_t q, size_t m, double *col, size_t ld)
{
    double x[PCOL], v[PCOL], u[PCOL], s[PCOL], tm[PCOL], T[PCOL], dT[PCOL], sp[PCOL];
    double Ta2 = 293.15 * 293.15, *c = col;
    size_t t;
    for (t = 0; t < q; t++) {
        const double *r = st + NS * t;
        x[t] = r[0];
        v[t] = r[1];
        u[t] = r[2];
        s[t] = r[3];
        tm[t] = r[4];
        T[t] = r[5];
        dT[t] = r[5] - 300.0;
        sp[t] = r[6];
    }
#define COLUMN(expr)                                                        \
    do {                                                                    \
        for (t = 0; t < q; t++)                                             \
            c[t] = (expr);                                                  \
        c += ld;                                                            \
    } while (0)
    COLUMN(1.0);
    COLUMN(s[t]);
    COLUMN(u[t]);
    if (m == BASE)
        return;
    COLUMN(v[t]);
    COLUMN(v[t] * fabs(v[t]));
    COLUMN(tanh_lanes(v[t] * 20.0));
    COLUMN(tanh_lanes(v[t] * 10.0));
    COLUMN(tanh_lanes(v[t] * (1.0 / 0.3)));
    COLUMN(tanh_lanes(v[t]));
    COLUMN(x[t]);
    COLUMN(x[t] * x[t] * x[t]);
    COLUMN(dT[t]);
    COLUMN(T[t] * T[t] * (T[t] * T[t]) - Ta2 * Ta2);
    COLUMN(tm[t]);
    COLUMN((s[t] - sp[t]) * 100.0);
    COLUMN(dT[t] * s[t]);
    COLUMN(u[t] * u[t]);
    COLUMN(x[t] * x[t]);
    COLUMN(x[t] * x[t] * (x[t] * x[t]));
    COLUMN(x[t] * x[t] * x[t] * (x[t] * x[t]));
    COLUMN(v[t] * v[t]);
    COLUMN(v[t] * v[t] * v[t]);
    COLUMN(v[t] * v[t] * (v[t] * v[t]));
    COLUMN(v[t] * v[t] * fabs(v[t]));
    COLUMN(dT[t] * dT[t]);
    COLUMN(tm[t] * tm[t]);
    COLUMN(tm[t] * s[t]);
    COLUMN(tm[t] * u[t]);
    COLUMN(tm[t] * x[t]);
    COLUMN(x[t] * v[t]);
    COLUMN(x[t] * u[t]);
    COLUMN(x[t] * s[t]);
    COLUMN(x[t] * dT[t]);
    COLUMN(v[t] * u[t]);
    COLUMN(v[t] * s[t]);
    COLUMN(v[t] * dT[t]);
    COLUMN(u[t] * s[t]);
    COLUMN(u[t] * dT[t]);
    COLUMN(s[t] * dT[t]);
    COLUMN(fabs(x[t]) * v[t]);
    COLUMN(fabs(u[t]) * v[t]);
    COLUMN(fabs(s[t]) * v[t]);
    COLUMN(fabs(dT[t]) * v[t]);
    COLUMN(x[t] * (v[t] * v[t]));
    COLUMN(x[t] * x[t] * v[t]);
    COLUMN(u[t] * (v[t] * v[t]));
    COLUMN(s[t] * (v[t] * v[t]));
    COLUMN(s[t] * s[t]);
    COLUMN(s[t] * s[t] * s[t]);
    COLUMN(dT[t] * v[t]);
    COLUMN(dT[t] * (x[t] * x[t]));
    COLUMN(u[t] * (x[t] * x[t]));
    COLUMN(u[t] * u[t] * u[t]);
#undef COLUMN
}

/* By panels of columns: evaluate PCOL records into the column panel, fold
   them at once; into a screen with base_cols whole columns. */
static double fold_columns(const double *state, const double *r, size_t n, size_t m,
                           size_t base_cols, double *storage, size_t nst,
                           fe_discover_acc *a, double *panel)
{
    double best;
    int rc = FE_OK;
    FE_BENCH_BEST(best, 3, {
        fe_discover_screen_init(a, m, base_cols, K, n, 0, storage, nst);
        for (size_t i = 0; i < n; i += PCOL) {
            size_t q = n - i < PCOL ? n - i : PCOL;
            terms_columns(state + NS * i, q, m, panel, PCOL);
            rc |= fe_discover_add_columns(a, panel, PCOL, r + i, q, NULL);
        }
    });
    if (rc != FE_OK)
        fprintf(stderr, "bench_discover: a row was refused\n");
    return best;
}

/* Row by row: evaluate, fold. */
static double fold_rows(const double *state, const double *r, size_t n, size_t m,
                        double *storage, size_t nst, fe_discover_acc *a)
{
    double phi[BASE + CAND], best;
    int rc = FE_OK;
    FE_BENCH_BEST(best, 3, {
        fe_discover_acc_init(a, m, K, n, 0, storage, nst);
        for (size_t i = 0; i < n; i++) {
            terms(state + NS * i, m, phi);
            rc |= fe_discover_add(a, phi, r[i]);
        }
    });
    if (rc != FE_OK)
        fprintf(stderr, "bench_discover: a row was refused\n");
    return best;
}

/* By panels: evaluate PANEL rows into the panel, fold them at once. */
static double fold_panels(const double *state, const double *r, size_t n, size_t m,
                          double *storage, size_t nst, fe_discover_acc *a, double *panel)
{
    double best;
    int rc = FE_OK;
    FE_BENCH_BEST(best, 3, {
        fe_discover_acc_init(a, m, K, n, 0, storage, nst);
        for (size_t i = 0; i < n; i += PANEL) {
            size_t q = n - i < PANEL ? n - i : PANEL;
            for (size_t t = 0; t < q; t++)
                terms(state + NS * (i + t), m, panel + t * m);
            rc |= fe_discover_add_rows(a, panel, m, r + i, q, NULL);
        }
    });
    if (rc != FE_OK)
        fprintf(stderr, "bench_discover: a row was refused\n");
    return best;
}

/* The same records from a CSV file, as a recording is read: each line
   read in one pass (fe_csv_numbers), or split and parsed field by field
   when it declines, as the command does, the records of a panel evaluated by columns
   and folded.  Returns the best time, or -1 when the file cannot be read. */
static double fold_file(const char *path, size_t n, size_t m, size_t base_cols,
                        double *storage, size_t nst, fe_discover_acc *a, double *panel)
{
    double best, st[NS * PCOL], r[PCOL];
    char buf[4096];
    int bad = 0;
    FE_BENCH_BEST(best, 3, {
        fe_csv_reader rd;
        int fd = open(path, O_RDONLY);
        size_t q = 0;
        char *line;
        size_t len;
        fe_discover_screen_init(a, m, base_cols, K, n, 0, storage, nst);
        if (fd < 0 || fe_csv_reader_init(&rd, fd, buf, sizeof buf) != FE_OK) {
            bad = 1;
        } else {
            for (;;) {
                int end = fe_csv_next_line(&rd, &line, &len) != FE_OK;
                if (!end) {
                    fe_csv_field f[NS + 1];
                    double v[NS + 1];
                    size_t nf;
                    if (fe_csv_numbers(line, ',', v, NS + 1, &nf) == FE_OK && nf == NS + 1) {
                        memcpy(&st[NS * q], v, NS * sizeof *v);
                        r[q] = v[NS];
                    } else {
                        bad |= fe_csv_split(line, ',', f, NS + 1, &nf, NULL) != FE_OK
                               || nf != NS + 1;
                        for (size_t c = 0; c < NS && !bad; c++)
                            bad |= fe_csv_number(&f[c], &st[NS * q + c]) != FE_OK;
                        bad |= bad || fe_csv_number(&f[NS], &r[q]) != FE_OK;
                    }
                    q++;
                }
                if (q == PCOL || (end && q > 0)) {
                    terms_columns(st, q, m, panel, PCOL);
                    bad |= fe_discover_add_columns(a, panel, PCOL, r, q, NULL) != FE_OK;
                    q = 0;
                }
                if (end)
                    break;
            }
        }
        if (fd >= 0)
            close(fd);
    });
    if (bad || a->n != n)
        return -1.0;
    return best;
}

/* Write the records as CSV (NS state columns and r, `digits` significant
   digits) to a new temporary file; its path in `path`. */
static int write_file(char *path, const double *state, const double *r, size_t n, int digits)
{
    int fd = mkstemp(path);
    FILE *f = fd >= 0 ? fdopen(fd, "w") : NULL;
    if (f == NULL)
        return -1;
    for (size_t i = 0; i < n; i++) {
        const double *st = state + NS * i;
        for (int c = 0; c < NS; c++)
            fprintf(f, "%.*g,", digits, st[c]);
        fprintf(f, "%.*g\n", digits, r[i]);
    }
    return fclose(f) == 0 ? 0 : -1;
}

/* Rank from the accumulation: the base groups 0..2, the 50 candidates. */
static int rank(const fe_discover_acc *a, fe_discover_result *res, double *work, size_t nw)
{
    fe_discover_group groups[BASE + CAND];
    fe_discover_options o = fe_discover_default_options();
    size_t base[BASE] = {0, 1, 2};
    for (size_t j = 0; j < BASE + CAND; j++) {
        groups[j].name = "term";
        groups[j].first = j;
        groups[j].count = 1;
    }
    o.base = base;
    o.nbase = BASE;
    o.max_steps = 0;
    /* A screen keeps no lagged products, so it ranks by batch means; the
       full accumulation is asked the same, or the two would be compared
       under different noise models. */
    o.noise = FE_DISCOVER_NOISE_BATCH;
    return fe_discover_select(a, groups, BASE + CAND, &o, res, work, nw);
}

static double rel(double x, double y)
{
    double d = fabs(x - y), s = fabs(x) > fabs(y) ? fabs(x) : fabs(y);
    return s > 0 ? d / s : 0.0;
}

/* The core's peak rate of double multiply-adds, per ns: 128 independent
   chains of x = fma(x, m, c), vectorised and fused where the bench is
   compiled for a processor that has them (every chain read after, so that
   none is dropped), best of rounds. */
static double peak_multiply_adds(void)
{
    enum { CHAINS = 128, STEPS = 2000000 };
    double x[CHAINS], t, sink = 0.0;
    for (int k = 0; k < CHAINS; k++)
        x[k] = 1.0 + 1e-3 * k;
    FE_BENCH_BEST(t, 3, {
        for (int i = 0; i < STEPS; i++)
            for (int k = 0; k < CHAINS; k++)
                x[k] = fma(x[k], 0.999999, 1e-7);
        for (int k = 0; k < CHAINS; k++)
            sink += x[k];
    });
    fe_bench_keep(sink);
    return (double)CHAINS * STEPS / t / 1e9;
}

int main(int argc, char **argv)
{
    size_t n = argc > 1 ? (size_t)strtod(argv[1], NULL) : 1000000;
    double *state = malloc(NS * n * sizeof *state), *r = malloc(n * sizeof *r);
    fe_rng g = fe_rng_seed(3);
    size_t nst = fe_discover_acc_doubles(BASE + CAND, K), nst0 = fe_discover_acc_doubles(BASE, K);
    size_t nw = fe_discover_workspace_doubles(BASE + CAND, K);
    double *storage = malloc(nst * sizeof *storage), *work = malloc(nw * sizeof *work);
    double *storage2 = malloc(nst * sizeof *storage2);
    double *panel = malloc(PANEL * (BASE + CAND) * sizeof *panel);
    fe_discover_acc a, full;
    fe_discover_result *res = malloc(sizeof *res), *res_full = malloc(sizeof *res_full);
    double busy = fe_bench_busy_fraction();
    double t_terms_rows, t_terms_cols, t_base_rows, t_base_panels, t_base_cols, t_base;
    double t_full_panels, t_screen, t_select, tanh_err = 0.0, worst = 0.0;
    double t_file_base[2] = {-1.0, -1.0}, t_file_screen[2] = {-1.0, -1.0};
    const int file_digits[2] = {6, 17};
    char csv_path[4096];
    int rc;
    if (state == NULL || r == NULL || storage == NULL || storage2 == NULL || work == NULL
        || res == NULL || res_full == NULL || panel == NULL)
        return 1;
    for (size_t i = 0; i < n; i++) {
        double t = 0.01 * (double)i, *st = state + NS * i;
        st[0] = sin(0.3 * t) + 0.1 * fe_rng_normal(&g);
        st[1] = cos(0.3 * t) + 0.1 * fe_rng_normal(&g);
        st[2] = sin(0.17 * t + 1.0);
        st[3] = st[2] - st[0];
        st[4] = t / (0.01 * (double)n);
        st[5] = 300.0 + 5.0 * sin(0.001 * t) + 0.01 * fe_rng_normal(&g);
        st[6] = i > 0 ? st[3 - NS] : st[3];
        r[i] = 0.1 * st[1] * fabs(st[1]) + fe_rng_normal(&g);
    }
    /* The vectorisable tanh against libm, over [-30, 30] and near 0. */
    for (int i = -300000; i <= 300000; i++) {
        double x = 1e-4 * i, y = 1e-9 * i;
        double e1 = rel(tanh_lanes(x), tanh(x)), e2 = rel(tanh_lanes(y), tanh(y));
        tanh_err = e1 > tanh_err ? e1 : tanh_err;
        tanh_err = e2 > tanh_err ? e2 : tanh_err;
    }
    {
        /* How much of a record's cost is evaluating its terms. */
        double phi[BASE + CAND], sink = 0;
        FE_BENCH_BEST(t_terms_rows, 3, {
            for (size_t i = 0; i < n; i++) {
                terms(state + NS * i, BASE + CAND, phi);
                sink += phi[BASE + CAND - 1];
            }
        });
        FE_BENCH_BEST(t_terms_cols, 3, {
            for (size_t i = 0; i < n; i += PCOL) {
                size_t q = n - i < PCOL ? n - i : PCOL;
                terms_columns(state + NS * i, q, BASE + CAND, panel, PCOL);
                sink += panel[(BASE + CAND - 1) * PCOL];
            }
        });
        fe_bench_keep(sink);
    }
    /* The base model alone, every way. */
    t_base_rows = fold_rows(state, r, n, BASE, storage, nst, &a);
    t_base_panels = fold_panels(state, r, n, BASE, storage, nst, &a, panel);
    t_base_cols = fold_columns(state, r, n, BASE, BASE, storage, nst, &a, panel);
    t_base = t_base_rows;
    t_base = t_base_panels < t_base ? t_base_panels : t_base;
    t_base = t_base_cols < t_base ? t_base_cols : t_base;
    /* The full accumulation of all 53 terms (for reference), then the
       screen, kept for ranking. */
    t_full_panels = fold_panels(state, r, n, BASE + CAND, storage2, nst, &full, panel);
    t_screen = fold_columns(state, r, n, BASE + CAND, BASE, storage, nst, &a, panel);
    FE_BENCH_BEST(t_select, 3, rc = rank(&a, res, work, nw));
    if (rc != FE_OK || rank(&full, res_full, work, nw) != FE_OK) {
        fprintf(stderr, "bench_discover: ranking failed\n");
        return 1;
    }
    /* The screen ranks as the full accumulation does. */
    for (size_t i = 0; i < res->nranked[0]; i++) {
        const fe_discover_rank *x = &res->ranking[0][i], *y = &res_full->ranking[0][i];
        double d = rel(x->rss_drop, y->rss_drop);
        d = rel(x->statistic, y->statistic) > d ? rel(x->statistic, y->statistic) : d;
        d = x->group != y->group || x->redundant != y->redundant ? 1.0 : d;
        worst = d > worst ? d : worst;
    }
    /* From a file: the base model alone and the screen, with the digits
       of a sensor recording and with the 17 of an exact round trip. */
    for (int d = 0; d < 2; d++) {
        const char *dir = getenv("TMPDIR");
        snprintf(csv_path, sizeof csv_path, "%s/foldest-bench-XXXXXX", dir ? dir : "/tmp");
        if (write_file(csv_path, state, r, n, file_digits[d]) == 0) {
            t_file_base[d] = fold_file(csv_path, n, BASE, BASE, storage, nst, &a, panel);
            t_file_screen[d] = fold_file(csv_path, n, BASE + CAND, BASE, storage, nst, &a, panel);
        }
        remove(csv_path);
    }
    printf("discovery over %zu records in memory (ns per record, best of 3; the caller's"
           " term evaluation included)\n", n);
    if (busy >= 0)
        printf("  (other processes used %.0f%% of the CPU before the run: figures are noisy)\n",
               100 * busy);
    printf("  evaluating the %d terms alone: row by row (libm) %6.1f, by columns %6.1f"
           "   (tanh by columns vs libm: %.1e relative at worst)\n", BASE + CAND,
           1e9 * t_terms_rows / (double)n, 1e9 * t_terms_cols / (double)n, tanh_err);
    printf("  base model alone (%d terms):\n", BASE);
    printf("    row by row (fe_discover_add)                  %8.1f\n", 1e9 * t_base_rows / (double)n);
    printf("    panels of %d rows (fe_discover_add_rows)     %8.1f\n", PANEL,
           1e9 * t_base_panels / (double)n);
    printf("    panels of %d columns (fe_discover_add_columns) %6.1f\n", PCOL,
           1e9 * t_base_cols / (double)n);
    printf("  base + %d candidates:\n", CAND);
    printf("    full accumulation, panels of %d rows           %8.1f   (%zu multiply-adds a row)\n",
           PANEL, 1e9 * t_full_panels / (double)n, (size_t)((BASE + CAND + 1) * (BASE + CAND + 2)));
    printf("    screen, panels of %d columns                   %8.1f   (%zu multiply-adds a row)\n",
           PCOL, 1e9 * t_screen / (double)n,
           (size_t)SCREEN_MADDS);
    printf("  ranking the %d candidates from the screen        %8.3f ms in all\n", CAND,
           1e3 * t_select);
    printf("  the screen's ranking vs the full accumulation's: same order, %.1e relative at worst\n",
           worst);
    printf("  ratio ranking / base fold in memory, each by its fastest path: %.2f\n",
           (t_screen + t_select) / t_base);
    {
        double peak = peak_multiply_adds();
        double madds = (double)SCREEN_MADDS;
        double fold = 1e9 * (t_screen - t_terms_cols) / (double)n, bound = madds / peak;
        printf("  the screen's fold alone (less the terms' evaluation by columns): %.1f ns a record;"
               " its %.0f multiply-adds at the core's peak (%.1f a ns, measured): %.1f ns;"
               " ratio %.2f (goal <= 2: %s)\n", fold, madds, peak, bound, fold / bound,
               fold <= 2.0 * bound ? "met" : "not met");
    }
    for (int d = 0; d < 2; d++) {
        if (t_file_base[d] > 0 && t_file_screen[d] > 0) {
            printf("from a CSV file of the same records, %d significant digits (8 columns, read"
                   " as the command reads them):\n", file_digits[d]);
            printf("    base model alone                               %8.1f\n",
                   1e9 * t_file_base[d] / (double)n);
            printf("    screen of the %d candidates                    %8.1f\n", CAND,
                   1e9 * t_file_screen[d] / (double)n);
            printf("  ratio ranking / base fold from the file: %.2f   (goal <= 1.25: %s)\n",
                   (t_file_screen[d] + t_select) / t_file_base[d],
                   t_file_screen[d] + t_select <= 1.25 * t_file_base[d] ? "met" : "not met");
        } else {
            printf("from a CSV file: could not write or read one in $TMPDIR or /tmp (skipped)\n");
        }
    }
    printf("  accumulation: %zu doubles = %.1f KiB with the candidates (%zu = %.1f KiB base),"
           " for any number of records\n", nst, (double)nst * 8.0 / 1024.0, nst0,
           (double)nst0 * 8.0 / 1024.0);
    free(state);
    free(r);
    free(storage);
    free(storage2);
    free(work);
    free(panel);
    free(res);
    free(res_full);
    return worst < 1e-6 ? 0 : 1;
}
