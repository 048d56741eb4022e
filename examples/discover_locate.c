/* SPDX-License-Identifier: MIT */
/* What `foldest discover` does, through the library alone.

   The command reads a recording and its simulation; here the library's
   synthetic rig (fe_synth) stands in for both, a cart whose recording has
   a dry friction the simulation lacks, concealed under coloured noise.
   The same three passes as the command:

     1. the catalog's scale and the state's ranges (the generator knows
        the scale; the ranges are read here);
     2. every candidate term into the engine's accumulation, then select;
     3. each row's residual before and after the discovered terms into a
        residual map, which locates where they differ (time windows,
        regions of the state) under the noise model, and gives the verdict.

   Every accumulation here can be split across threads or machines and
   merged (fe_discover_merge, fe_residual_map_merge).

   Build against an installed foldest:
     cc discover_locate.c $(pkg-config --cflags --libs foldest) -o discover_locate */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <foldest.h>

enum { BLOCKS = 20 };

int main(void)
{
    fe_synth_spec spec = fe_synth_default_spec("coulomb_friction", 5);
    fe_synth gen;
    fe_catalog cat;
    fe_discover_acc acc;
    fe_discover_group groups[FE_DISCOVER_MAX_GROUPS];
    fe_discover_options opt = fe_discover_default_options();
    fe_discover_result *res = malloc(sizeof *res);
    fe_residual_map *map = malloc(sizeof *map);
    fe_located located[16];
    fe_sample s;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    double phi[FE_DISCOVER_MAX_COLUMNS], *storage = NULL, *work = NULL;
    size_t base[FE_DISCOVER_MAX_GROUPS], nbase, fit, nst, nwork, nlocated;
    fe_verdict verdict;
    int rc;

    spec.rows = 40000;
    fit = (size_t)(0.7 * (double)spec.rows);   /* the rest is held out */
    if (res == NULL || map == NULL || (rc = fe_synth_init(&gen, &spec)) != FE_OK
        || (rc = fe_catalog_init(&cat, gen.roles, &gen.scale)) != FE_OK) {
        fprintf(stderr, "discover_locate: setup failed\n");
        return 1;
    }

    /* Pass 1: the ranges of position, velocity and temperature. */
    while (fe_synth_next(&gen, &s) == FE_OK) {
        const double x[3] = {s.position, s.velocity, s.temperature};
        for (int v = 0; v < 3; v++) {
            lo[v] = x[v] < lo[v] ? x[v] : lo[v];
            hi[v] = x[v] > hi[v] ? x[v] : hi[v];
        }
    }

    /* Pass 2: the candidate terms of every row, then forward selection
       with the rig's own parameters (bias, gain) always in the model. */
    nst = fe_discover_acc_doubles(cat.count, BLOCKS);
    nwork = fe_discover_workspace_doubles(cat.count, BLOCKS);
    storage = malloc(nst * sizeof *storage);
    work = malloc(nwork * sizeof *work);
    if (storage == NULL || work == NULL
        || (rc = fe_discover_acc_init(&acc, cat.count, BLOCKS, fit, 0, storage, nst)) != FE_OK) {
        fprintf(stderr, "discover_locate: out of memory\n");
        return 1;
    }
    fe_synth_rewind(&gen);
    while (fe_synth_next(&gen, &s) == FE_OK)
        if ((rc = fe_catalog_eval(&cat, &s, phi)) != FE_OK
            || (rc = fe_discover_add(&acc, phi, s.real - s.sim)) != FE_OK) {
            fprintf(stderr, "discover_locate: %s\n", fe_strerror(rc));
            return 1;
        }
    nbase = fe_synth_base(&gen, &cat, base);
    fe_catalog_groups(&cat, groups);
    opt.base = base;
    opt.nbase = nbase;
    if ((rc = fe_discover_select(&acc, groups, cat.count, &opt, res, work, nwork)) != FE_OK) {
        fprintf(stderr, "discover_locate: %s\n", fe_strerror(rc));
        return 1;
    }

    /* Pass 3: the residual map.  Before: simulation and base terms with
       the baseline's coefficients (the path's first step); after: the
       final model. */
    if ((rc = fe_residual_map_init(map, BLOCKS, fit, 0, gen.roles, lo, hi)) != FE_OK) {
        fprintf(stderr, "discover_locate: %s\n", fe_strerror(rc));
        return 1;
    }
    fe_synth_rewind(&gen);
    while (fe_synth_next(&gen, &s) == FE_OK) {
        double before = s.real - s.sim, after = before;
        fe_catalog_eval(&cat, &s, phi);
        for (size_t j = 0; j < nbase; j++)
            before -= res->path[0].coef[j] * phi[base[j]];
        for (size_t j = 0; j < res->ncols; j++)
            after -= res->coef[j] * phi[res->cols[j]];
        if ((rc = fe_residual_map_add(map, &s, before, after)) != FE_OK) {
            fprintf(stderr, "discover_locate: %s\n", fe_strerror(rc));
            return 1;
        }
    }

    /* Where the baseline misses, under its noise model; then the verdict. */
    fe_residual_map_locate(map, fe_discover_row_worth(&res->path[0].noise, res->baseline.n),
                           opt.alpha, located, 16, &nlocated);
    printf("where simulation and recording differ (%zu places):\n", nlocated);
    for (size_t i = 0; i < nlocated && i < 16; i++) {
        char json[1024];
        fe_located_json(&located[i], json, sizeof json);
        printf("  %s\n", json);
    }
    printf("\nwhat was left out:\n");
    for (size_t k = 0; k < res->steps; k++) {
        const fe_term *t = &cat.terms[res->added[k]];
        for (size_t j = 0; j < res->ncols; j++)
            if (res->cols[j] == res->added[k]) {
                char words[256];
                fe_catalog_explain(t->name, res->coef[j], res->stderr_[j], words, sizeof words);
                printf("  %s, p = %.2g: %s\n", t->name, res->added_rank[k].p_value, words);
            }
    }
    printf("  (the generator hid %s with coefficient %.4g)\n", spec.effect, gen.coefficient);
    printf("\nresidual RMS %.4f -> %.4f, held out %.4f -> %.4f\n", res->baseline.rms,
           res->final.rms, res->baseline.heldout_rms, res->final.heldout_rms);
    verdict = fe_discover_verdict(res, map, nlocated, opt.alpha);
    printf("verdict: %s\n", fe_verdict_text(verdict));
    if (fe_verdict_why(verdict) != NULL)
        printf("  (%s)\n", fe_verdict_why(verdict));
    free(storage);
    free(work);
    free(res);
    free(map);
    return 0;
}
