/* SPDX-License-Identifier: MIT */
/* Tangled from literate/cli_discover.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/cli_discover.org::Write a synthetic pair][Write a synthetic pair]] */
#include "cli.h"

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const char fe__synth_help[] =
    "usage: foldest synth --effect NAME [--seed S] [--rows N] [--order K] [--rho R]\n"
    "                     --real REAL.csv --sim SIM.csv\n"
    "\n"
    "Write a recording/simulation pair of a synthetic experiment in which the\n"
    "recording has one effect the simulation lacks, concealed (at most 0.3 noise\n"
    "standard deviations per sample, coloured noise).  NAME is a catalog term or\n"
    "'none' (mechanical rig) or 'none_thermal' (thermal rig).  The truth and the\n"
    "command that analyses the pair are printed on standard error.\n"
    "\n"
    "  --order K   0 (default): the effect is added to the channel.  2: it acts on\n"
    "              the cart's acceleration and the channel is its position; 1: it\n"
    "              acts on the heated stand's dT/dt and the channel is its\n"
    "              temperature.  The trajectories part (by about 3 noise sds of\n"
    "              static response); analyse with discover --order K.\n"
    "  --rho R     the noise's lag-one correlation, an AR(1) with 0 <= R < 1\n"
    "              (default 0.5; 0: white noise).  Its standard deviation and the\n"
    "              effect's coefficient do not depend on R.\n";

/* `s` as one word of a POSIX shell (see above). */
static void fe__shell_word(FILE *f, const char *s)
{
    static const char safe[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"
                               "0123456789_-./,+:=@%";
    if (*s != '\0' && strspn(s, safe) == strlen(s)) {
        fputs(s, f);
        return;
    }
    fputc('\'', f);
    for (; *s != '\0'; s++)
        if (*s == '\'')
            fputs("'\\''", f);
        else
            fputc(*s, f);
    fputc('\'', f);
}

int fe_cli_synth(int argc, char **argv)
{
    const char *effect = NULL, *real = NULL, *sim = NULL;
    long seed = 1, rows = 0, order = 0;
    double rho = -1.0;                  /* not given: the generator's default */
    char err[1024];
    fe_synth g;
    fe_synth_spec spec;
    fe_sample s;
    fe_cli_output ro, so;
    int pending_real;
    int rc;
    static const fe_cli_option options[] = {
        {"--effect", 1}, {"--real", 1}, {"--sim", 1}, {"--seed", 1}, {"--rows", 1},
        {"--order", 1}, {"--rho", 1}, {NULL, 0}};
    rc = fe_cli_options("synth", options, &argc, &argv);
    if (rc != FE_CLI_OK)
        return rc < 0 ? FE_CLI_OK : rc;
    for (int i = 1; i < argc; i++) {
        const char *o = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(o, "--help") == 0 || strcmp(o, "-h") == 0) {
            size_t n;
            const char *const *e = fe_synth_effects(&n);
            fputs(fe__synth_help, stdout);
            printf("\neffects:");
            for (size_t j = 0; j < n; j++)
                printf(" %s", e[j]);
            printf("\n");
            return FE_CLI_OK;
        }
        if (v == NULL) {
            fprintf(stderr, "foldest synth: %s needs a value\n", o);
            return FE_CLI_USAGE;
        }
        i++;
        rc = FE_CLI_OK;
        if (strcmp(o, "--effect") == 0)
            effect = v;
        else if (strcmp(o, "--real") == 0)
            real = v;
        else if (strcmp(o, "--sim") == 0)
            sim = v;
        else if (strcmp(o, "--seed") == 0 || strcmp(o, "--rows") == 0) {
            long *to = strcmp(o, "--seed") == 0 ? &seed : &rows;
            rc = fe_cli_parse_long(o, v, to, err, sizeof err);
            if (rc == FE_CLI_OK && (*to < 0 || (to == &rows && *to > 0 && *to < 100))) {
                snprintf(err, sizeof err, "%s: %s is not %s", o, v,
                         to == &rows ? "100 or more (fe_synth_init's least), or 0 for the default"
                                     : "0 or more");
                rc = FE_CLI_USAGE;
            }
        } else if (strcmp(o, "--order") == 0) {
            rc = fe_cli_parse_long(o, v, &order, err, sizeof err);
            if (rc == FE_CLI_OK && (order < 0 || order > 2)) {
                snprintf(err, sizeof err, "--order: %s is not 0, 1 or 2", v);
                rc = FE_CLI_USAGE;
            }
        } else if (strcmp(o, "--rho") == 0) {
            rc = fe_cli_parse_double(o, v, &rho, err, sizeof err);
            if (rc == FE_CLI_OK && !(rho >= 0.0 && rho < 1.0)) {
                snprintf(err, sizeof err, "--rho: %s is not in [0, 1)", v);
                rc = FE_CLI_USAGE;
            }
        } else {
            snprintf(err, sizeof err, "unknown option '%s'", o);
            rc = FE_CLI_USAGE;
        }
        if (rc != FE_CLI_OK) {
            fprintf(stderr, "foldest synth: %s\n", err);
            return rc;
        }
    }
    if (effect == NULL || real == NULL || sim == NULL) {
        fprintf(stderr, "foldest synth: %s is required\n\n",
                effect == NULL ? "--effect" : real == NULL ? "--real" : "--sim");
        fputs(fe__synth_help, stderr);
        return FE_CLI_USAGE;
    }
    spec = fe_synth_default_spec(effect, (uint64_t)seed);
    if (rows > 0)
        spec.rows = (size_t)rows;
    spec.order = (size_t)order;
    if (rho >= 0.0)
        spec.noise_rho = rho;
    rc = fe_synth_init(&g, &spec);
    if (rc != FE_OK) {
        fprintf(stderr, "foldest synth: --effect %s%s: %s\n", effect,
                order == 2 ? " --order 2" : order == 1 ? " --order 1" : "",
                rc == FE_EINVAL ? (order > 0 ? "not a forcing the rig can host (the mechanical "
                                               "rig for --order 2, the thermal for --order 1; "
                                               "gain and delay describe the measurement)"
                                             : "not an effect a rig can host ('foldest synth --help')")
                                : fe_strerror(rc));
        return FE_CLI_USAGE;
    }
    if ((rc = fe_cli_output_open(&ro, real, err, sizeof err)) != FE_CLI_OK) {
        fprintf(stderr, "foldest synth: %s\n", err);
        return rc;
    }
    if ((rc = fe_cli_output_open(&so, sim, err, sizeof err)) != FE_CLI_OK) {
        fe_cli_output_abort(&ro);
        fprintf(stderr, "foldest synth: %s\n", err);
        return rc;
    }
    if (order == 2) {
        fprintf(ro.file, "time,position\n");
        fprintf(so.file, "time,position,velocity,input\n");
    } else if (order == 1) {
        fprintf(ro.file, "time,temperature\n");
        fprintf(so.file, "time,temperature,ambient,power\n");
    } else if (g.thermal) {
        fprintf(ro.file, "time,load\n");
        fprintf(so.file, "time,load,temperature,ambient\n");
    } else {
        fprintf(ro.file, "time,acceleration\n");
        fprintf(so.file, "time,acceleration,position,velocity,input\n");
    }
    while (fe_synth_next(&g, &s) == FE_OK) {
        fprintf(ro.file, "%.6f,%.10g\n", s.t, s.real);
        if (order == 2)
            fprintf(so.file, "%.6f,%.10g,%.10g,%.10g\n", s.t, s.sim, s.velocity, s.input);
        else if (order == 1)
            fprintf(so.file, "%.6f,%.10g,%.10g,%.10g\n", s.t, s.sim, s.ambient, s.input);
        else if (g.thermal)
            fprintf(so.file, "%.6f,%.10g,%.10g,%.10g\n", s.t, s.sim, s.temperature, s.ambient);
        else
            fprintf(so.file, "%.6f,%.10g,%.10g,%.10g,%.10g\n", s.t, s.sim, s.position,
                    s.velocity, s.input);
    }
    /* The pair appears whole or not at all: the recording stays pending
       until the simulation is in place, and goes if it cannot be. */
    if ((rc = fe_cli_output_commit(&ro, err, sizeof err)) != FE_CLI_OK) {
        fe_cli_output_abort(&so);
        fprintf(stderr, "foldest synth: %s\n", err);
        return rc;
    }
    pending_real = fe_cli_pending_add(real, 0);
    if ((rc = fe_cli_output_commit(&so, err, sizeof err)) != FE_CLI_OK) {
        unlink(real);
        fe_cli_pending_drop(pending_real);
        fprintf(stderr, "foldest synth: %s\n", err);
        return rc;
    }
    fe_cli_pending_drop(pending_real);
    fprintf(stderr, "synth: %zu rows; hidden effect %s, coefficient %.6g; noise sd %g, "
                    "lag-one correlation %g\n",
            spec.rows, effect, g.coefficient, g.sigma, spec.noise_rho);
    fprintf(stderr, "analyse with:\n  foldest discover --real ");
    fe__shell_word(stderr, real);
    fprintf(stderr, " --sim ");
    fe__shell_word(stderr, sim);
    if (order > 0) {
        fprintf(stderr, " --channel %s %s --order %ld --holdout 0.3\n",
                order == 2 ? "position" : "temperature",
                order == 2 ? "--role velocity=velocity --role input=input"
                           : "--role ambient=ambient --role power=input", order);
        return FE_CLI_OK;
    }
    fprintf(stderr, " --channel %s %s --base %s --holdout 0.3\n",
            g.thermal ? "load" : "acceleration",
            g.thermal ? "--role temperature=temperature --role ambient=ambient"
                      : "--role position=position --role velocity=velocity --role input=input",
            strcmp(effect, "bias") == 0 ? "gain" : strcmp(effect, "gain") == 0 ? "bias"
                                                                             : "bias,gain");
    return FE_CLI_OK;
}
/* Write a synthetic pair ends here */
