/* Discovery's one pass, in one run, over 10^6 records in memory:
     - the base model alone: its 3 terms (bias, gain, input) folded into the
       block Gram matrices;
     - ranking 50 candidates: the same records with 50 candidate terms beside
       the base (polynomials and products of the state, the catalog's shapes)
       folded into the same accumulation, then ranked (one selection step).
   Prints ns per record, the ratio (goal: ranking <= 3x the base fold), and the
   accumulation's size, which does not depend on the number of records. */
#include <math.h>
#include <stdlib.h>

#include "bench.h"
#include "foldest.h"

enum { BASE = 3, CAND = 50, K = 20 };

/* Term values of record i: 3 base terms, then candidates. */
static void terms(const double *state, size_t m, double *phi)
{
    double x = state[0], v = state[1], u = state[2], s = state[3], t = state[4];
    double c[CAND];
    phi[0] = 1.0;
    phi[1] = s;
    phi[2] = u;
    if (m == BASE)
        return;
    for (int k = 0; k < 10; k++) {
        c[5 * k + 0] = pow(x, k + 1);
        c[5 * k + 1] = v * pow(fabs(v), k);
        c[5 * k + 2] = tanh(v * (k + 1));
        c[5 * k + 3] = x * pow(v, k % 3) * (k + 1);
        c[5 * k + 4] = t * pow(u, k % 4);
    }
    for (size_t j = 0; j < m - BASE; j++)
        phi[BASE + j] = c[j];
}

static double fold(const double *state, const double *r, size_t n, size_t m,
                   double *storage, size_t nst, fe_discover_acc *a)
{
    double phi[BASE + CAND], best;
    FE_BENCH_BEST(best, 3, {
        fe_discover_acc_init(a, m, K, n, 0, storage, nst);
        for (size_t i = 0; i < n; i++) {
            terms(state + 5 * i, m, phi);
            fe_discover_add(a, phi, r[i]);
        }
    });
    return best;
}

int main(int argc, char **argv)
{
    size_t n = argc > 1 ? (size_t)strtod(argv[1], NULL) : 1000000;
    double *state = malloc(5 * n * sizeof *state), *r = malloc(n * sizeof *r);
    fe_rng g = fe_rng_seed(3);
    size_t nst = fe_discover_acc_doubles(BASE + CAND, K);
    size_t nw = fe_discover_workspace_doubles(BASE + CAND, K);
    double *storage = malloc(nst * sizeof *storage), *work = malloc(nw * sizeof *work);
    fe_discover_acc a;
    fe_discover_group groups[BASE + CAND];
    fe_discover_result *res = malloc(sizeof *res);
    fe_discover_options o = fe_discover_default_options();
    size_t base[BASE] = {0, 1, 2};
    double t_base, t_rank, t_select;
    if (state == NULL || r == NULL || storage == NULL || work == NULL || res == NULL)
        return 1;
    for (size_t i = 0; i < n; i++) {
        double t = 0.01 * (double)i;
        state[5 * i + 0] = sin(0.3 * t) + 0.1 * fe_rng_normal(&g);
        state[5 * i + 1] = cos(0.3 * t) + 0.1 * fe_rng_normal(&g);
        state[5 * i + 2] = sin(0.17 * t + 1.0);
        state[5 * i + 3] = state[5 * i + 2] - state[5 * i + 0];
        state[5 * i + 4] = t / (0.01 * (double)n);
        r[i] = 0.1 * state[5 * i + 1] * fabs(state[5 * i + 1]) + fe_rng_normal(&g);
    }
    {
        /* How much of a record's cost is evaluating its terms. */
        double phi[BASE + CAND], t_terms, sink = 0;
        FE_BENCH_BEST(t_terms, 3, {
            for (size_t i = 0; i < n; i++) {
                terms(state + 5 * i, BASE + CAND, phi);
                sink += phi[BASE + CAND - 1];
            }
        });
        fe_bench_keep(sink);
        printf("  (evaluating the 53 terms alone: %.1f ns per record)\n", 1e9 * t_terms / (double)n);
    }
    t_base = fold(state, r, n, BASE, storage, nst, &a);
    t_rank = fold(state, r, n, BASE + CAND, storage, nst, &a);
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
    printf("  base model alone (%d terms) folded            %8.1f\n", BASE, 1e9 * t_base / (double)n);
    printf("  base + %d candidates folded                  %8.1f\n", CAND, 1e9 * t_rank / (double)n);
    printf("  ranking the %d candidates from the fold        %8.3f ms in all\n", CAND, 1e3 * t_select);
    printf("  ratio ranking / base fold: %.1f   (goal <= 3)\n", (t_rank + t_select) / t_base);
    printf("  accumulation: %zu doubles = %.1f KiB, for any number of records\n", nst,
           (double)nst * 8.0 / 1024.0);
    free(state);
    free(r);
    free(storage);
    free(work);
    free(res);
    return 0;
}
