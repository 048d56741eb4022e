/* SPDX-License-Identifier: MIT */
/* Tangled from literate/cli.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/cli.org::Dispatch a subcommand][Dispatch a subcommand]] */
#include "cli.h"

#include <string.h>

#include "commands.h"

static void fe__cli_overview(FILE *out)
{
    fprintf(out, "foldest %s: foldable estimators for sensor recordings\n\n"
                 "usage: foldest COMMAND [OPTIONS] [FILE...]\n\ncommands:\n",
            FE_VERSION);
    for (size_t i = 0; i < sizeof fe_cli_commands / sizeof fe_cli_commands[0]; i++)
        fprintf(out, "  %-12s %s\n", fe_cli_commands[i].name, fe_cli_commands[i].summary);
    fprintf(out, "\n'foldest COMMAND --help' documents each command.\n"
                 "Exit status: 0 success, 1 data refused by the analysis, 2 usage error,\n"
                 "3 malformed input, 4 input/output error.\n");
}

int main(int argc, char **argv)
{
    fe_cli_signals_install();
    if (argc < 2 || strcmp(argv[1], "help") == 0 || strcmp(argv[1], "--help") == 0
        || strcmp(argv[1], "-h") == 0) {
        fe__cli_overview(argc < 2 ? stderr : stdout);
        return fe_cli_finish(NULL, argc < 2 ? FE_CLI_USAGE : FE_CLI_OK);
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("foldest %s\n", FE_VERSION);
        return fe_cli_finish(NULL, FE_CLI_OK);
    }
    for (size_t i = 0; i < sizeof fe_cli_commands / sizeof fe_cli_commands[0]; i++)
        if (strcmp(argv[1], fe_cli_commands[i].name) == 0)
            return fe_cli_finish(argv[1], fe_cli_commands[i].run(argc - 1, argv + 1));
    fprintf(stderr, "foldest: unknown command '%s'\n\n", argv[1]);
    fe__cli_overview(stderr);
    return FE_CLI_USAGE;
}
/* Dispatch a subcommand ends here */
