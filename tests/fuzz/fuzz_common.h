/* SPDX-License-Identifier: MIT */
/* Shared by the command-line harnesses: the foldest main (renamed
   fe_cli_main when the CLI is built for fuzzing), running it with its
   standard output captured and its standard error silenced, and a strict
   JSON validator (RFC 8259: no NaN, no Infinity, no trailing commas). */
#ifndef FE_FUZZ_COMMON_H
#define FE_FUZZ_COMMON_H

#define _GNU_SOURCE
#include <ctype.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

int fe_cli_main(int argc, char **argv);

#include "fuzz_require.h"

/* Write `n` bytes to a fresh file `path`. */
static void fe_fuzz_write(const char *path, const uint8_t *p, size_t n)
{
    FILE *f = fopen(path, "wb");
    REQUIRE(f != NULL);
    REQUIRE(fwrite(p, 1, n, f) == n);
    REQUIRE(fclose(f) == 0);
}

/* Run fe_cli_main(argc, argv); its stdout goes to *out (malloc'd, NUL
   terminated, *outlen bytes).  Stderr is silenced unless FE_FUZZ_VERBOSE
   is set (set it to see the messages when replaying a crash). */
static int fe_fuzz_run(int argc, char **argv, char **out, size_t *outlen)
{
    static int verbose = -1;
    int saved_out, saved_err = -1, mfd, status;
    off_t end;
    if (verbose < 0)
        verbose = getenv("FE_FUZZ_VERBOSE") != NULL;
    fflush(stdout);
    fflush(stderr);
    saved_out = dup(1);
    mfd = memfd_create("fuzz_stdout", 0);
    REQUIRE(saved_out >= 0 && mfd >= 0);
    dup2(mfd, 1);
    if (!verbose) {
        int null = open("/dev/null", O_WRONLY);
        saved_err = dup(2);
        dup2(null, 2);
        close(null);
    }
    status = fe_cli_main(argc, argv);
    fflush(stdout);
    fflush(stderr);
    dup2(saved_out, 1);
    close(saved_out);
    if (saved_err >= 0) {
        dup2(saved_err, 2);
        close(saved_err);
    }
    end = lseek(mfd, 0, SEEK_END);
    REQUIRE(end >= 0);
    *outlen = (size_t)end;
    *out = malloc(*outlen + 1);
    REQUIRE(*out != NULL);
    REQUIRE(pread(mfd, *out, *outlen, 0) == (ssize_t)*outlen);
    (*out)[*outlen] = '\0';
    close(mfd);
    return status;
}

/* A recursive-descent JSON validator: returns the end of one value, or NULL. */
static const char *fe_json_ws(const char *p)
{
    while (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r')
        p++;
    return p;
}

static const char *fe_json_value(const char *p, int depth);

static const char *fe_json_string(const char *p)
{
    if (*p++ != '"')
        return NULL;
    for (;;) {
        unsigned char c = (unsigned char)*p++;
        if (c == '"')
            return p;
        if (c < 0x20)
            return NULL;
        if (c == '\\') {
            c = (unsigned char)*p++;
            if (c == 'u') {
                for (int i = 0; i < 4; i++)
                    if (!isxdigit((unsigned char)*p++))
                        return NULL;
            } else if (strchr("\"\\/bfnrt", c) == NULL || c == '\0') {
                return NULL;
            }
        }
    }
}

static const char *fe_json_number(const char *p)
{
    if (*p == '-')
        p++;
    if (*p == '0')
        p++;
    else if (*p >= '1' && *p <= '9')
        while (isdigit((unsigned char)*p))
            p++;
    else
        return NULL;
    if (*p == '.') {
        p++;
        if (!isdigit((unsigned char)*p))
            return NULL;
        while (isdigit((unsigned char)*p))
            p++;
    }
    if (*p == 'e' || *p == 'E') {
        p++;
        if (*p == '+' || *p == '-')
            p++;
        if (!isdigit((unsigned char)*p))
            return NULL;
        while (isdigit((unsigned char)*p))
            p++;
    }
    return p;
}

static const char *fe_json_value(const char *p, int depth)
{
    if (depth > 64)
        return NULL;
    p = fe_json_ws(p);
    if (*p == '{' || *p == '[') {
        char close = *p == '{' ? '}' : ']';
        int object = *p == '{';
        p = fe_json_ws(p + 1);
        if (*p == close)
            return p + 1;
        for (;;) {
            if (object) {
                p = fe_json_string(fe_json_ws(p));
                if (p == NULL)
                    return NULL;
                p = fe_json_ws(p);
                if (*p++ != ':')
                    return NULL;
            }
            p = fe_json_value(p, depth + 1);
            if (p == NULL)
                return NULL;
            p = fe_json_ws(p);
            if (*p == close)
                return p + 1;
            if (*p++ != ',')
                return NULL;
        }
    }
    if (*p == '"')
        return fe_json_string(p);
    if (strncmp(p, "true", 4) == 0)
        return p + 4;
    if (strncmp(p, "false", 5) == 0)
        return p + 5;
    if (strncmp(p, "null", 4) == 0)
        return p + 4;
    return fe_json_number(p);
}

/* Nonzero when `s` is exactly one JSON value (surrounding white space allowed). */
static int fe_json_valid(const char *s)
{
    const char *end = fe_json_value(s, 0);
    return end != NULL && *fe_json_ws(end) == '\0';
}

/* A scratch directory /tmp/PREFIX-XXXXXX for the run, written into dir
   (at least 64 bytes) and removed with what it holds when the process
   exits normally (libFuzzer's time limit ends with exit). */
static char fe_fuzz_scratch_dir[64];

static void fe_fuzz_scratch_remove(void)
{
    char cmd[128];
    if (fe_fuzz_scratch_dir[0] == '\0')
        return;
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", fe_fuzz_scratch_dir);
    if (system(cmd) != 0)
        fprintf(stderr, "fuzz: could not remove %s\n", fe_fuzz_scratch_dir);
}

static void fe_fuzz_scratch(const char *prefix, char *dir, size_t len)
{
    snprintf(dir, len, "/tmp/%s-XXXXXX", prefix);
    REQUIRE(mkdtemp(dir) != NULL);
    snprintf(fe_fuzz_scratch_dir, sizeof fe_fuzz_scratch_dir, "%s", dir);
    REQUIRE(atexit(fe_fuzz_scratch_remove) == 0);
}

#endif /* FE_FUZZ_COMMON_H */
