/* SPDX-License-Identifier: MIT */
/* The MPI examples' options: -n N, the number of observations of the
   whole stream, and -nan I, a NaN planted at global index I, to watch a
   refusal travel through the reduction to the root. */
#ifndef FOLDEST_EXAMPLE_MPI_OPTIONS_H
#define FOLDEST_EXAMPLE_MPI_OPTIONS_H

#include <stdlib.h>
#include <string.h>

static void example_options(int argc, char **argv, size_t *n, size_t *nan_at)
{
    for (int i = 1; i + 1 < argc; i++) {
        if (strcmp(argv[i], "-n") == 0)
            *n = (size_t)strtod(argv[++i], NULL);
        else if (strcmp(argv[i], "-nan") == 0)
            *nan_at = (size_t)strtod(argv[++i], NULL);
    }
}

#endif
