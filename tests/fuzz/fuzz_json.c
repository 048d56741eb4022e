/* SPDX-License-Identifier: MIT */
/* libFuzzer harness: the JSON output.  The input is a recording (CSV
   text); `foldest stats --json`, `foldest calibrate --json` (each model)
   and `foldest discover --json` (the file as recording and simulation) run
   on it.  Whatever the data, standard output is either empty or exactly
   one valid JSON value (no NaN or Infinity: JSON has none), and a command
   that succeeded printed one. */
#include "fuzz_common.h"

#include <fcntl.h>

static char dir[64];

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    fe_fuzz_scratch("foldest-fuzz-json", dir, sizeof dir);
    return 0;
}

static void check(int argc, char **argv)
{
    char *out;
    size_t len;
    int status = fe_fuzz_run(argc, argv, &out, &len);
    REQUIRE(status >= 0 && status <= 4);
    if (status == 0)
        REQUIRE(len > 0);
    if (len > 0 && !fe_json_valid(out)) {
        fprintf(stderr, "fuzz_json: %s %s printed invalid JSON (status %d):\n%s\n",
                argv[0], argv[1], status, out);
        abort();
    }
    free(out);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[128];
    snprintf(path, sizeof path, "%s/in.csv", dir);
    fe_fuzz_write(path, data, size);
    {
        char *argv[] = {"foldest", "stats", "--json", path, NULL};
        check(4, argv);
    }
    {
        static char *models[] = {"sphere", "axial", "ellipsoid"};
        char *argv[] = {"foldest", "calibrate", "--json", "--model", models[size % 3], path, NULL};
        check(6, argv);
    }
    {
        char *argv[] = {"foldest", "discover", "--json", "--real", path, "--sim", path,
                        "--channel", "2", "--blocks", "2", NULL};
        check(11, argv);
    }
    unlink(path);
    return 0;
}
