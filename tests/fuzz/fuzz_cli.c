/* SPDX-License-Identifier: MIT */
/* libFuzzer harness: the command line's arguments and file handling.  The
   input is a list of arguments, one per line, then a line "--" and the
   content of a file; the argument "@" names that file (written to a
   scratch directory, the working directory of the run).  Arguments that
   could reach outside the scratch directory (containing '/'), that read
   standard input ("-"), or that would make the run long (synth, numbers
   of more than four digits) are replaced by "@".  The command must return
   a documented exit status (0 to 4), leave no temporary file behind, and
   create no file that its arguments did not name: an output name such as
   x';touch PWNED;' (the seeds *_shell_names) is a name, and a PWNED beside
   it would mean that something ran it. */
#include "fuzz_common.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>

static char dir[64];

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    fe_fuzz_scratch("foldest-fuzz-cli", dir, sizeof dir);
    REQUIRE(chdir(dir) == 0);
    return 0;
}

/* Does an argument name `name`, as itself or as the value in --opt=name? */
static int named_as_value(const char *name, int argc, char **argv)
{
    for (int i = 0; i < argc; i++) {
        const char *eq = strchr(argv[i], '=');
        if (strcmp(argv[i], name) == 0 || (eq != NULL && strcmp(eq + 1, name) == 0))
            return 1;
    }
    return 0;
}

/* The files of a report written into the working directory (--report .). */
static int report_file(const char *name)
{
    static const char *const names[] = {"report.md", "plots.gp", "blocks.dat", "bins.dat",
                                        "residuals.dat", "residual_time.png",
                                        "residual_state.png"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (strcmp(name, names[i]) == 0)
            return 1;
    return 0;
}

/* Remove the folder `name` and the files in it (a --report folder), without
   a shell: the name is whatever the fuzzer made. */
static void remove_folder(const char *name)
{
    DIR *d = opendir(name);
    struct dirent *e;
    REQUIRE(d != NULL);
    while ((e = readdir(d)) != NULL)
        if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0)
            REQUIRE(unlinkat(dirfd(d), e->d_name, 0) == 0);
    closedir(d);
    REQUIRE(rmdir(name) == 0);
}

/* Remove everything in the scratch directory (one level of subdirectories:
   --report DIR); fail if a half-written output (NAME.tmp.XXXXXX) is left,
   unless the arguments named that very file, or if anything is there that
   no argument named. */
static void sweep(int argc, char **argv)
{
    DIR *d = opendir(".");
    struct dirent *e;
    REQUIRE(d != NULL);
    while ((e = readdir(d)) != NULL) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
            continue;
        if (strstr(e->d_name, ".tmp.") != NULL && !named_as_value(e->d_name, argc, argv)) {
            fprintf(stderr, "fuzz_cli: temporary file left behind: %s\n", e->d_name);
            abort();
        }
        if (strcmp(e->d_name, "in.csv") != 0 && !report_file(e->d_name)
            && strstr(e->d_name, ".tmp.") == NULL && !named_as_value(e->d_name, argc, argv)) {
            fprintf(stderr, "fuzz_cli: '%s' was created, but no argument names it\n", e->d_name);
            abort();
        }
        if (unlink(e->d_name) != 0)
            remove_folder(e->d_name);
    }
    closedir(d);
}

static int long_number(const char *a)
{
    size_t digits = 0;
    for (; *a; a++)
        digits += isdigit((unsigned char)*a) != 0;
    return digits > 4;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    enum { MAXARGS = 24 };
    char *text = malloc(size + 1), *argv[MAXARGS + 2], *p, *out;
    const uint8_t *file = NULL;
    size_t filelen = 0, outlen;
    int argc = 0, status;
    static char at[] = "@", name[] = "foldest", path[] = "in.csv";
    REQUIRE(text != NULL);
    memcpy(text, data, size);
    text[size] = '\0';
    argv[argc++] = name;
    for (p = text; argc < MAXARGS && p < text + size;) {
        char *nl = memchr(p, '\n', (size_t)(text + size - p));
        if (nl == NULL)
            nl = text + size;
        *nl = '\0';
        if (strcmp(p, "--") == 0) {
            file = data + (nl - text) + 1;
            filelen = nl < text + size ? size - (size_t)(nl - text) - 1 : 0;
            break;
        }
        if (strlen(p) != (size_t)(nl - p))      /* a NUL inside: not an argument */
            p = at;
        if (strchr(p, '/') != NULL || strcmp(p, "-") == 0 || strcmp(p, "..") == 0 || strcmp(p, "synth") == 0
            || long_number(p))
            p = at;
        argv[argc++] = strcmp(p, "@") == 0 ? path : p;
        p = nl + 1;
    }
    argv[argc] = NULL;
    fe_fuzz_write(path, file != NULL ? file : (const uint8_t *)"", filelen);
    status = fe_fuzz_run(argc, argv, &out, &outlen);
    free(out);
    if (status < 0 || status > 4) {
        fprintf(stderr, "fuzz_cli: exit status %d\n", status);
        abort();
    }
    sweep(argc, argv);
    free(text);
    return 0;
}
