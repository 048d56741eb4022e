/* SPDX-License-Identifier: MIT */
/* The noise model's cost, in one run: 10^6 records of 3 base terms and 15
   candidates (M = 19 columns with the residual), folded in panels of rows
   (fe_discover_add_rows) into a full accumulation without lagged products
   (fe_discover_set_lags 0 and fe_discover_set_fine 1: the fold without
   the noise model, neither its lagged products nor its fine blocks) and
   with 4, 8 and 16 of them and the fine blocks (8 lags is the default),
   best of NS runs each; then the
   selection from each.  Prints ns per record and the ratio against the
   fold without lags (the noise model's goal: at most 1.5), the memory of
   each accumulation (independent of the number of records), and how busy
   the machine was. */
#include <math.h>
#include <stdlib.h>

#include "bench.h"
#include "foldest.h"

enum { N = 1000000, BASE = 3, CAND = 15, M = BASE + CAND, K = 20, NS = 5 };

int main(void)
{
    double *phi = malloc((size_t)N * M * sizeof *phi), *r = malloc((size_t)N * sizeof *r);
    size_t nst = fe_discover_acc_doubles(M, K), nw = fe_discover_workspace_doubles(M, K);
    double *st = malloc(nst * sizeof *st), *w = malloc(nw * sizeof *w);
    const size_t lags[4] = {0, 4, 8, 16};
    double base_ns = 0.0, busy = fe_bench_busy_fraction();
    fe_discover_group g[M];
    fe_discover_options o = fe_discover_default_options();
    fe_discover_result *res = malloc(sizeof *res);
    size_t bases[BASE] = {0, 1, 2};
    fe_rng rng = fe_rng_seed(1);
    double e = 0.0;
    if (phi == NULL || r == NULL || st == NULL || w == NULL || res == NULL)
        return 1;
    for (size_t t = 0; t < N; t++) {
        double x = sin(1e-4 * (double)t), v = cos(1e-4 * (double)t);
        double *p = phi + t * M;
        p[0] = 1.0;
        p[1] = x;
        p[2] = sin(3e-3 * (double)t);
        for (int c = 0; c < CAND; c++)
            p[BASE + c] = c % 3 == 0 ? pow(v, (double)(c / 3 + 1))
                        : c % 3 == 1 ? x * pow(fabs(v), (double)(c / 3)) : tanh((c + 1) * v);
        e = 0.8 * e + fe_rng_normal(&rng);
        r[t] = 0.2 * p[BASE + 1] + e;
    }
    for (size_t c = 0; c < M; c++) {
        g[c].name = "term";
        g[c].first = c;
        g[c].count = 1;
    }
    o.base = bases;
    o.nbase = BASE;
    printf("bench_noise: %d records, %d base terms + %d candidates, K = %d blocks; "
           "machine busy %.0f%% before the run\n", N, BASE, CAND, K, 100.0 * busy);
    printf("%-6s %14s %10s %12s %14s\n", "lags", "fold ns/rec", "ratio", "select ms",
           "memory KiB");
    for (int i = 0; i < 4; i++) {
        fe_discover_acc a;
        double best, sel;
        int rc = FE_OK;
        FE_BENCH_BEST(best, NS,
                      rc |= fe_discover_acc_init(&a, M, K, (uint64_t)(0.8 * N), 0, st, nst);
                      rc |= fe_discover_set_lags(&a, lags[i]);
                      if (lags[i] == 0)     /* no noise model: no fine blocks either */
                          rc |= fe_discover_set_fine(&a, 1);
                      rc |= fe_discover_add_rows(&a, phi, M, r, N, NULL));
        if (rc != FE_OK) {
            fprintf(stderr, "bench_noise: the fold failed\n");
            return 1;
        }
        FE_BENCH_BEST(sel, 3, rc |= fe_discover_select(&a, g, M, &o, res, w, nw));
        if (rc != FE_OK) {
            fprintf(stderr, "bench_noise: selection failed\n");
            return 1;
        }
        if (i == 0)
            base_ns = 1e9 * best / N;
        printf("%-6zu %14.1f %10.2f %12.2f %14.0f\n", lags[i], 1e9 * best / N,
               1e9 * best / N / base_ns, 1e3 * sel, (double)nst * sizeof *st / 1024.0);
    }
    printf("goal: the noise model (8 lags, the default, with its fine blocks) at most 1.5 times the fold without it\n");
    free(phi);
    free(r);
    free(st);
    free(w);
    free(res);
    return 0;
}
