/* SPDX-License-Identifier: MIT */
/* Running the foldest command from a test: for the command-line suites,
   which define _POSIX_C_SOURCE before any include (popen, pclose). */
#ifndef FE_CLI_RUN_H
#define FE_CLI_RUN_H

#include <stdio.h>
#include <sys/wait.h>

#include <check.h>

/* What fe_test_run does with standard error: drop it, capture it with
   standard output, or leave it to the command's own redirections. */
enum { FE_TEST_STDOUT = 0, FE_TEST_BOTH = 1, FE_TEST_AS_GIVEN = 2 };

/* Run a shell command; its standard output, and standard error too when
   `both` is FE_TEST_BOTH (dropped for FE_TEST_STDOUT, as the command says
   for FE_TEST_AS_GIVEN), into out[len] (at most len - 1 bytes,
   NUL-terminated); its exit status, or -1 when it did not exit. */
static inline int fe_test_run(const char *cmd, int both, char *out, size_t len)
{
    char full[16384];
    FILE *p;
    size_t got;
    int status, n = snprintf(full, sizeof full, "%s %s", cmd,
                             both == FE_TEST_BOTH ? "2>&1"
                             : both == FE_TEST_STDOUT ? "2>/dev/null" : "");
    ck_assert_msg(n > 0 && (size_t)n < sizeof full, "command too long: %.200s", cmd);
    p = popen(full, "r");
    ck_assert_ptr_nonnull(p);
    got = fread(out, 1, len - 1, p);
    out[got] = '\0';
    status = pclose(p);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

#endif /* FE_CLI_RUN_H */
