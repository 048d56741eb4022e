/* Discovery's one pass, in one run, over 10^6 records in memory:
     - the base model alone: its 3 terms (bias, gain, input) folded into the
       block Gram matrices;
     - ranking 50 candidates: the same records with 50 candidate terms beside
       the base (the catalog's shapes: powers and products of the state,
       v|v|, tanh(v/c), T - T0, T^4 - Ta^4, time, a difference for the delay)
       folded into the same accumulation, then ranked (one selection step).
   Both folds are timed both ways a caller has: row by row (fe_discover_add)
   and with the terms evaluated into a panel of 256 rows folded by
   fe_discover_add_rows; the ratio takes each fold's faster way.
   Prints ns per record, the ratio (goal: ranking <= 3x the base fold), the
   multiply-adds per row and the rate they run at, and the accumulation's
   size, which does not depend on the number of records. */
#include <math.h>
#include <stdlib.h>

#include "bench.h"
#include "foldest.h"

enum { BASE = 3, CAND = 50, K = 20, PANEL = 256, NS = 7 };

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
    c[k++] = tanh(v / 0.05);            /* Coulomb friction, four widths */
    c[k++] = tanh(v / 0.1);
    c[k++] = tanh(v / 0.3);
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

int main(int argc, char **argv)
{
    size_t n = argc > 1 ? (size_t)strtod(argv[1], NULL) : 1000000;
    double *state = malloc(NS * n * sizeof *state), *r = malloc(n * sizeof *r);
    fe_rng g = fe_rng_seed(3);
    size_t nst = fe_discover_acc_doubles(BASE + CAND, K), nst0 = fe_discover_acc_doubles(BASE, K);
    size_t nw = fe_discover_workspace_doubles(BASE + CAND, K);
    double *storage = malloc(nst * sizeof *storage), *work = malloc(nw * sizeof *work);
    double *panel = malloc(PANEL * (BASE + CAND) * sizeof *panel);
    fe_discover_acc a;
    fe_discover_group groups[BASE + CAND];
    fe_discover_result *res = malloc(sizeof *res);
    fe_discover_options o = fe_discover_default_options();
    size_t base[BASE] = {0, 1, 2}, M = BASE + CAND + 1;
    double busy = fe_bench_busy_fraction();
    double t_terms, t_base_rows, t_rank_rows, t_base, t_rank, t_select;
    if (state == NULL || r == NULL || storage == NULL || work == NULL || res == NULL
        || panel == NULL)
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
    {
        /* How much of a record's cost is evaluating its terms. */
        double phi[BASE + CAND], sink = 0;
        FE_BENCH_BEST(t_terms, 3, {
            for (size_t i = 0; i < n; i++) {
                terms(state + NS * i, BASE + CAND, phi);
                sink += phi[BASE + CAND - 1];
            }
        });
        fe_bench_keep(sink);
    }
    t_base_rows = fold_rows(state, r, n, BASE, storage, nst, &a);
    t_rank_rows = fold_rows(state, r, n, BASE + CAND, storage, nst, &a);
    t_base = fold_panels(state, r, n, BASE, storage, nst, &a, panel);
    t_rank = fold_panels(state, r, n, BASE + CAND, storage, nst, &a, panel);
    for (size_t j = 0; j < BASE + CAND; j++) {
        groups[j].name = "term";
        groups[j].first = j;
        groups[j].count = 1;
    }
    o.base = base;
    o.nbase = BASE;
    o.max_steps = 0;
    {
        int rc = FE_OK;
        FE_BENCH_BEST(t_select, 3, rc |= fe_discover_select(&a, groups, BASE + CAND, &o, res, work, nw));
        if (rc != FE_OK) {
            fprintf(stderr, "bench_discover: selection failed: %s\n", fe_strerror(rc));
            return 1;
        }
    }
    printf("discovery over %zu records in memory (ns per record, best of 3)\n", n);
    if (busy >= 0)
        printf("  (other processes used %.0f%% of the CPU before the run: figures are noisy)\n",
               100 * busy);
    printf("  evaluating the %d terms alone                 %8.1f\n", BASE + CAND,
           1e9 * t_terms / (double)n);
    printf("  row by row (fe_discover_add):\n");
    printf("    base model alone (%d terms)                  %8.1f\n", BASE,
           1e9 * t_base_rows / (double)n);
    printf("    base + %d candidates                        %8.1f   (ratio %.1f)\n", CAND,
           1e9 * t_rank_rows / (double)n, t_rank_rows / t_base_rows);
    printf("  by panels of %d rows (fe_discover_add_rows):\n", PANEL);
    printf("    base model alone (%d terms)                  %8.1f\n", BASE,
           1e9 * t_base / (double)n);
    printf("    base + %d candidates                        %8.1f   (%.0f multiply-adds per row:"
           " %.1f GFLOP/s beyond the terms)\n", CAND, 1e9 * t_rank / (double)n,
           (double)(M * (M + 1)), 2.0 * (double)(M * (M + 1)) * (double)n / (t_rank - t_terms) / 1e9);
    printf("  ranking the %d candidates from the fold         %8.3f ms in all\n", CAND, 1e3 * t_select);
    /* Each through its faster path: for 4 columns the panels' BLAS calls
       cost as much as they save. */
    printf("  ratio ranking / base fold, each by its faster path: %.1f   (goal <= 3)\n",
           ((t_rank < t_rank_rows ? t_rank : t_rank_rows) + t_select)
               / (t_base < t_base_rows ? t_base : t_base_rows));
    printf("  accumulation: %zu doubles = %.1f KiB with the candidates (%zu = %.1f KiB base),"
           " for any number of records\n", nst, (double)nst * 8.0 / 1024.0, nst0,
           (double)nst0 * 8.0 / 1024.0);
    free(state);
    free(r);
    free(storage);
    free(work);
    free(panel);
    free(res);
    return 0;
}
