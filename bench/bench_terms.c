/* SPDX-License-Identifier: MIT */
/* What a term written as an expression costs against a term written in C
   of the same arithmetic, both evaluated the way foldest discover does
   (fe_catalog_eval_rows over panels of FE_DISCOVER_PANEL_ROWS rows): the
   built-in quadratic_drag against "velocity*abs(velocity)", and a C
   callback sin(2 pi x / p) against "sin(2*pi*position/0.002)".  Goal
   (issue 18): a user term at most 2x the built-in one.  Figures in ns per
   row, best of 5, measured in the same run. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench.h"
#include "foldest.h"

enum { N = 1 << 20, P = FE_DISCOVER_PANEL_ROWS, LDV = FE_CATALOG_VARS };

static double cogging(const fe_sample *s, const fe_catalog_scale *c, void *u)
{
    (void)c;
    (void)u;
    return sin(2 * 3.14159265358979323846 * s->position / 0.002);
}

/* A catalog of the one term `keep` of the built-in ones, or empty. */
static void one_term(fe_catalog *c, const char *keep)
{
    fe_catalog_scale scale;
    memset(&scale, 0, sizeof scale);
    scale.vmax = 1.0;
    fe_catalog_init(c, FE_ROLE_POSITION | FE_ROLE_VELOCITY, &scale);
    for (size_t j = c->count; j-- > 0;)
        if (keep == NULL || strcmp(c->terms[j].name, keep) != 0)
            fe_catalog_remove(c, c->terms[j].name);
}

/* Evaluate the catalog over all rows, a panel at a time; the sum of the
   values, so that nothing is optimised away. */
static double eval_all(const fe_catalog *c, const double *rows, double *phi, double *work)
{
    double sum = 0;
    for (size_t i = 0; i < N; i += P) {
        if (fe_catalog_eval_rows(c, rows + i * LDV, LDV, P, phi, 1, work, NULL) != FE_OK) {
            fprintf(stderr, "bench_terms: a panel was refused\n");
            exit(1);
        }
        sum += phi[P - 1];
    }
    return sum;
}

int main(void)
{
    double *rows = malloc((size_t)N * LDV * sizeof *rows), phi[P], *work;
    size_t nv;
    const char *const *names = fe_catalog_var_names(&nv);
    fe_catalog builtin, user, cfun, cexpr;
    fe_expr drag, cog;
    fe_rng rng = fe_rng_seed(3);
    double t_builtin, t_user, t_cfun, t_cexpr, t_rows, busy, s1 = 0, s2 = 0;
    work = malloc(fe_catalog_work_doubles(P) * sizeof *work);
    if (rows == NULL || work == NULL)
        return 1;
    for (size_t i = 0; i < N; i++) {
        fe_sample s;
        memset(&s, 0, sizeof s);
        s.t = 0.001 * (double)i;
        s.position = 0.01 * fe_rng_normal(&rng);
        s.velocity = fe_rng_normal(&rng);
        fe_catalog_row(&s, rows + i * LDV);
    }
    if (fe_expr_compile(&drag, "velocity*abs(velocity)", names, nv, NULL, NULL, 0) != FE_OK
        || fe_expr_compile(&cog, "sin(2*pi*position/0.002)", names, nv, NULL, NULL, 0) != FE_OK)
        return 1;
    one_term(&builtin, "quadratic_drag");
    one_term(&user, NULL);
    fe_catalog_add_expr(&user, "drag", NULL, &drag);
    one_term(&cfun, NULL);
    fe_catalog_add(&cfun, "cogging_c", NULL, cogging, NULL);
    one_term(&cexpr, NULL);
    fe_catalog_add_expr(&cexpr, "cogging", NULL, &cog);
    if (builtin.count != 1 || user.count != 1 || cfun.count != 1 || cexpr.count != 1)
        return 1;
    /* The two paths agree. */
    for (size_t i = 0; i < N; i += 4099) {
        double a, b;
        fe_catalog_eval_rows(&builtin, rows + i * LDV, LDV, 1, &a, 1, work, NULL);
        fe_catalog_eval_rows(&user, rows + i * LDV, LDV, 1, &b, 1, work, NULL);
        if (a != b) {
            fprintf(stderr, "bench_terms: %g != %g at row %zu\n", a, b, i);
            return 1;
        }
    }
    busy = fe_bench_busy_fraction();
    FE_BENCH_BEST(t_builtin, 5, s1 += eval_all(&builtin, rows, phi, work));
    FE_BENCH_BEST(t_user, 5, s2 += eval_all(&user, rows, phi, work));
    FE_BENCH_BEST(t_cfun, 5, s1 += eval_all(&cfun, rows, phi, work));
    FE_BENCH_BEST(t_cexpr, 5, s2 += eval_all(&cexpr, rows, phi, work));
    {   /* The one-sample path the command used before (fe_catalog_eval). */
        fe_sample s;
        FE_BENCH_BEST(t_rows, 5, {
            for (size_t i = 0; i < N; i++) {
                const double *r = rows + i * LDV;
                memset(&s, 0, sizeof s);
                s.velocity = r[FE_CATALOG_VAR_VELOCITY];
                fe_catalog_eval(&builtin, &s, phi);
                s1 += phi[0];
            }
        });
    }
    fe_bench_keep(s1 + s2);
    printf("one candidate term over %d rows, panels of %d (fe_catalog_eval_rows), ns per row, "
           "best of 5:\n", N, P);
    if (busy > 0.25)
        printf("  (other processes used %.0f%% of the CPU before the run: figures are noisy)\n",
               100 * busy);
    printf("  quadratic_drag, built in (C)            %6.2f\n", 1e9 * t_builtin / N);
    printf("  velocity*abs(velocity), expression      %6.2f   ratio %.2f   (goal <= 2)\n",
           1e9 * t_user / N, t_user / t_builtin);
    printf("  sin(2 pi x / p), a C callback           %6.2f\n", 1e9 * t_cfun / N);
    printf("  sin(2*pi*position/0.002), expression    %6.2f   ratio %.2f   (goal <= 2)\n",
           1e9 * t_cexpr / N, t_cexpr / t_cfun);
    printf("  quadratic_drag one sample at a time (fe_catalog_eval) %6.2f\n", 1e9 * t_rows / N);
    free(rows);
    free(work);
    return 0;
}
