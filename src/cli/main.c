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
                 "Options of the table reader, for every command:\n"
                 "  --decimal-comma   '1,5' is 1.5 (found by itself in a semicolon table)\n"
                 "  --skip-bad-rows   skip rows with an empty, NaN or text cell or a wrong\n"
                 "                    number of fields, and count them (default: stop)\n"
                 "Inputs may be gzip-compressed; a UTF-8 byte-order mark is ignored.\n"
                 "Exit status: 0 success, 1 data refused by the analysis, 2 usage error,\n"
                 "3 malformed input, 4 input/output error.\n");
}

/* Take the reader's options out of argv, from anywhere before "--". */
static int fe__cli_reader_options(int argc, char **argv)
{
    int comma = 0, skip = 0, out = 1;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--") == 0) {
            while (i < argc)
                argv[out++] = argv[i++];
            break;
        }
        if (strcmp(argv[i], "--decimal-comma") == 0)
            comma = 1;
        else if (strcmp(argv[i], "--skip-bad-rows") == 0)
            skip = 1;
        else
            argv[out++] = argv[i];
    }
    argv[out] = NULL;
    fe_cli_reader_configure(comma, skip);
    return out;
}

/* When the BLAS is OpenBLAS: one thread, and its idle workers stopped
   (declared weak: with another BLAS they are absent, and nothing is
   done). */
extern void openblas_set_num_threads(int) __attribute__((weak));
extern void blas_thread_shutdown_(void) __attribute__((weak));

static void fe__cli_blas_one_thread(void)
{
    if (openblas_set_num_threads != NULL)
        openblas_set_num_threads(1);
    if (blas_thread_shutdown_ != NULL)
        blas_thread_shutdown_();
}

int main(int argc, char **argv)
{
    fe__cli_blas_one_thread();
    fe_cli_signals_install();
    argc = fe__cli_reader_options(argc, argv);
    if (argc < 2 || strcmp(argv[1], "help") == 0 || strcmp(argv[1], "--help") == 0
        || strcmp(argv[1], "-h") == 0) {
        fe__cli_overview(argc < 2 ? stderr : stdout);
        return fe_cli_finish(NULL, argc < 2 ? FE_CLI_USAGE : FE_CLI_OK);
    }
    if (strcmp(argv[1], "--version") == 0 || strcmp(argv[1], "-V") == 0) {
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
