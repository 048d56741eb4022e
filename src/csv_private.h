/* SPDX-License-Identifier: MIT */
/* Tangled from literate/csv.org: do not edit; edit the .org and run make tangle. */
/* Private: the split without its SSE2 fast path, for the tests.  Not
   installed. */
#ifndef FOLDEST_CSV_PRIVATE_H
#define FOLDEST_CSV_PRIVATE_H

#include "foldest/csv.h"

/* fe__csv_split_portable: fe_csv_split by the general loop alone. */
int fe__csv_split_portable(char *line, char delimiter, fe_csv_field *fields,
                           size_t max, size_t *count, size_t *bad_column);

#endif /* FOLDEST_CSV_PRIVATE_H */
