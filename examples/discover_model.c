/* SPDX-License-Identifier: MIT */
/* Discovery with the model given as a C function.

   A cart on a spring is driven by a force u(t).  Our model of its
   acceleration has three parameters, theta = (g, f, zeta):

       a = g u - (2 pi f)^2 x - 2 zeta (2 pi f) v,

   input gain g, resonance frequency f (Hz), damping ratio zeta.  The
   recording (made by the library's synthetic generator, fe_synth) contains
   something the model lacks, concealed under coloured noise.  We hand the
   model to the engine as a callback, without a Jacobian (the library
   differentiates it by central differences), fold the rows once, and ask
   what was left out.  The model's own parameters are base terms: they
   absorb what a re-tuning of the model could explain, and only the rest
   counts as new physics.

   Build against an installed foldest:
     cc discover_model.c $(pkg-config --cflags --libs foldest) -o discover_model */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <foldest.h>

static int cart(const fe_sample *s, const double *theta, double *a, void *user)
{
    const double w = 6.283185307179586 * theta[1];
    (void)user;
    *a = theta[0] * s->input - w * w * s->position - 2.0 * theta[2] * w * s->velocity;
    return 0;
}

int main(void)
{
    static const double theta0[3] = {1.0, 0.4, 0.15};
    static const char *const names[3] = {"input gain g", "frequency f", "damping zeta"};
    const size_t K = 20;
    fe_synth_spec spec = fe_synth_default_spec("quadratic_drag", 7);
    fe_model model = {3, theta0, names, cart, NULL, 0, NULL, NULL};
    fe_synth gen;
    fe_catalog cat;
    fe_model_acc acc;
    fe_sample s;
    fe_discover_options opt = fe_discover_default_options();
    fe_discover_result *res = malloc(sizeof *res);
    double *storage = NULL, *work = NULL, theta[3], se[3];
    size_t bias;
    int rc;

    /* The data, and the catalog of candidate terms for its columns
       (position, velocity, input); the generator has done the first pass
       the catalog needs (first time, largest speed). */
    if (res == NULL || (rc = fe_synth_init(&gen, &spec)) != FE_OK
        || (rc = fe_catalog_init(&cat, gen.roles, &gen.scale)) != FE_OK) {
        fprintf(stderr, "discover_model: setup failed\n");
        return 1;
    }
    /* One pass: 70% of the rows fitted, the rest held out. */
    storage = malloc(fe_model_acc_doubles(3, cat.count, K) * sizeof *storage);
    if (storage == NULL
        || (rc = fe_model_acc_init(&acc, &model, &cat, K, (uint64_t)(0.7 * (double)spec.rows),
                                   storage, fe_model_acc_doubles(3, cat.count, K))) != FE_OK) {
        fprintf(stderr, "discover_model: %s\n", storage ? fe_strerror(rc) : "out of memory");
        return 1;
    }
    while (fe_synth_next(&gen, &s) == FE_OK)
        if ((rc = fe_model_add(&acc, &s)) != FE_OK) {
            fprintf(stderr, "discover_model: %s\n", fe_strerror(rc));
            return 1;
        }
    fe_model_break(&acc);       /* the recording ended */

    /* Select, with a sensor offset (bias) always in the model as well. */
    bias = (size_t)fe_catalog_find(&cat, "bias");
    opt.base = &bias;
    opt.nbase = 1;
    work = malloc(fe_model_workspace_doubles(&acc) * sizeof *work);
    if (work == NULL
        || (rc = fe_model_select(&acc, &opt, res, work, fe_model_workspace_doubles(&acc)))
               != FE_OK) {
        fprintf(stderr, "discover_model: %s\n", work ? fe_strerror(rc) : "out of memory");
        return 1;
    }

    printf("residual RMS of the model: %.4f (held out %.4f); after discovery: %.4f (%.4f)\n",
           res->baseline.rms, res->baseline.heldout_rms, res->final.rms,
           res->final.heldout_rms);
    printf("\nterms the model's parameters already express:");
    for (size_t i = 0; i < res->nranked[0]; i++)
        if (res->ranking[0][i].redundant)
            printf(" %s", fe_model_group_name(&acc, res->ranking[0][i].group));
    printf("\n\nwhat was left out:\n");
    if (res->steps == 0)
        printf("  nothing significant\n");
    for (size_t k = 0; k < res->steps; k++) {
        size_t g = res->added[k], term;
        char words[256];
        for (size_t j = 0; j < res->ncols; j++)
            if (res->cols[j] == g && fe_model_group_is_term(&acc, g, &term)) {
                fe_catalog_explain(cat.terms[term].name, res->coef[j], res->stderr_[j],
                                   words, sizeof words);
                printf("  %s (%s), p = %.2g\n    %s\n", cat.terms[term].name,
                       cat.terms[term].description, res->added_rank[k].p_value, words);
            }
    }
    printf("  (the generator hid quadratic drag with coefficient %.4g)\n", gen.coefficient);

    rc = fe_model_theta(&acc, res, theta, se);
    printf("\nthe model's parameters, re-fitted with it:\n");
    for (int i = 0; i < 3; i++)
        printf("  %-13s %.5f +/- %.5f (nominal %.5f)\n", names[i], theta[i], se[i], theta0[i]);
    if (rc == FE_EUNDETERMINED)
        printf("  (a parameter with +/- 0 was set aside: the data cannot determine it)\n");
    free(storage);
    free(work);
    free(res);
    return 0;
}
