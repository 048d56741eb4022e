/* SPDX-License-Identifier: MIT */
/* libFuzzer harness: the expression compiler.  Any bytes, as the text of
   an expression, either compile or are refused with a column inside the
   text (from 1 to its length + 1) and a message; a compiled program stays
   within its fixed limits, reads only the variables it names, and gives
   the same value one row at a time and over a panel. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "foldest.h"
#include "fuzz_require.h"

static const char *const names[] = {"x", "velocity", "t", "T (C)", "position"};
enum { NV = 5, N = 7 };

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char text[1024], msg[256];
    fe_expr e;
    size_t col = 0, bad = 0;
    double rows[N * NV], out[N], work[FE_EXPR_MAX_STACK * N];
    int rc;
    if (size >= sizeof text)
        return 0;
    memcpy(text, data, size);
    text[size] = '\0';
    rc = fe_expr_compile(&e, text, names, NV, &col, msg, sizeof msg);
    REQUIRE(rc == FE_OK || rc == FE_EPARSE || rc == FE_ESIZE);
    if (rc != FE_OK) {
        REQUIRE(col >= 1 && col <= strlen(text) + 1);
        REQUIRE(msg[0] != '\0');
        return 0;
    }
    REQUIRE(e.ncode >= 1 && e.ncode <= FE_EXPR_MAX_CODE);
    REQUIRE(e.depth >= 1 && e.depth <= FE_EXPR_MAX_STACK);
    REQUIRE(e.nvars <= NV);
    for (size_t i = 0; i < N * NV; i++)
        rows[i] = (double)((int)(i * 37 % 11) - 5) / 3.0;
    rc = fe_expr_eval_rows(&e, rows, NV, N, out, work, &bad);
    REQUIRE(rc == FE_OK || rc == FE_ENONFINITE);
    for (size_t t = 0; t < N; t++) {
        double one;
        int r1 = fe_expr_eval(&e, rows + t * NV, &one);
        REQUIRE(r1 == FE_OK || r1 == FE_ENONFINITE);
        REQUIRE((r1 == FE_OK) == (isfinite(out[t]) != 0));
        if (r1 == FE_OK)
            REQUIRE(one == out[t]);
    }
    return 0;
}
