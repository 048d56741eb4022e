/* SPDX-License-Identifier: MIT */
/* Shared by the fuzz harnesses: a broken promise aborts, naming the
   condition (libFuzzer saves the input). */
#ifndef FE_FUZZ_REQUIRE_H
#define FE_FUZZ_REQUIRE_H

#include <stdio.h>
#include <stdlib.h>

#define REQUIRE(cond)                                                          \
    do {                                                                       \
        if (!(cond)) {                                                         \
            fprintf(stderr, "%s:%d: %s\n", __FILE__, __LINE__, #cond);         \
            abort();                                                           \
        }                                                                      \
    } while (0)

#endif /* FE_FUZZ_REQUIRE_H */
