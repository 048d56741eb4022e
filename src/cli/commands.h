/* SPDX-License-Identifier: MIT */
/* Tangled from literate/cli.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/cli.org::Command Table][Command Table]] */
#ifndef FOLDEST_CLI_COMMANDS_H
#define FOLDEST_CLI_COMMANDS_H

#include "cli.h"

int fe_cli_stats(int argc, char **argv);
int fe_cli_discover(int argc, char **argv);
int fe_cli_synth(int argc, char **argv);
int fe_cli_calibrate(int argc, char **argv);

static const fe_cli_command fe_cli_commands[] = {
    {"discover", "find what a simulation left out: locate, name, model, prove", fe_cli_discover},
    {"synth", "write a recording/simulation pair with a concealed effect", fe_cli_synth},
    {"stats", "mean, standard deviation, min and max of columns", fe_cli_stats},
    {"calibrate", "sphere or ellipsoid calibration of a 3-axis sensor", fe_cli_calibrate},
};

#endif /* FOLDEST_CLI_COMMANDS_H */
/* Command Table ends here */
