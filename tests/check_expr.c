/* SPDX-License-Identifier: MIT */
/* Terms written as expressions: values against the same formulas written
   in C, precedence, errors at their columns, refusals, and the panel
   evaluation against the one-row one. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "foldest.h"
#include "testutil.h"

static const char *const names[] = {"position", "velocity", "t", "T (C)", "sim"};
enum { NV = 5 };

static double value_of(const char *text, const double *v)
{
    fe_expr e;
    size_t col = 99;
    char msg[256];
    double out = NAN;
    int rc = fe_expr_compile(&e, text, names, NV, &col, msg, sizeof msg);
    ck_assert_msg(rc == FE_OK, "%s: col %zu: %s", text, col, msg);
    ck_assert_uint_eq(col, 0);
    ck_assert_int_eq(fe_expr_eval(&e, v, &out), FE_OK);
    return out;
}

START_TEST(expressions_are_their_formulas)
{
    fe_rng rng = fe_rng_seed(5);
    for (int k = 0; k < 50; k++) {
        double v[NV], x, u, t, T, s;
        for (int j = 0; j < NV; j++)
            v[j] = 2.0 * fe_rng_uniform(&rng) - 1.0;
        v[3] = 20.0 + 5.0 * v[3];
        x = v[0], u = v[1], t = v[2], T = v[3], s = v[4];
        FE_ASSERT_REL(value_of("sin(2*pi*position/0.002)", v),
                      sin(2 * 3.14159265358979323846 * x / 0.002), 1e-15);
        FE_ASSERT_REL(value_of("velocity*abs(velocity)*cos(t)", v), u * fabs(u) * cos(t),
                      1e-15);
        FE_ASSERT_REL(value_of("sign(velocity)*exp(-(velocity/0.1)^2)", v),
                      ((u > 0) - (u < 0)) * exp(-(u / 0.1) * (u / 0.1)), 1e-14);
        FE_ASSERT_REL(value_of("(\"T (C)\" - 20)*sim + tanh(3*velocity)", v),
                      (T - 20) * s + tanh(3 * u), 1e-14);
        FE_ASSERT_REL(value_of("`T (C)`^4 / 1e8 - log(sqrt(abs(sim) + 1))", v),
                      pow(T, 4) / 1e8 - log(sqrt(fabs(s) + 1)), 1e-14);
        FE_ASSERT_REL(value_of("atan2(position, velocity) + min(t, sim) - max(t, sim)", v),
                      atan2(x, u) + fmin(t, s) - fmax(t, s), 1e-14);
        FE_ASSERT_REL(value_of("tan(0.5*position)", v), tan(0.5 * x), 1e-15);
    }
}
END_TEST

/* An unquoted name holds letters, digits, '_' and '.': every edge of each
   range ('a' and 'z', 'A' and 'Z', '0' and '9') inside a name that must be
   read whole (expr:202 of CI's sample 24773 stopped a name at a '0'). */
START_TEST(unquoted_names_hold_every_edge_of_their_ranges)
{
    static const char *const edge_names[] = {"az", "AZ", "n09", "_x.y", "x0"};
    const double v[5] = {2.0, 3.0, 5.0, 7.0, 11.0};
    fe_expr e;
    size_t col = 99;
    char msg[256];
    double out = NAN;
    ck_assert_int_eq(fe_expr_compile(&e, "az*AZ + n09 - _x.y/x0", edge_names, 5, &col, msg,
                                     sizeof msg), FE_OK);
    ck_assert_int_eq(fe_expr_eval(&e, v, &out), FE_OK);
    ck_assert_double_eq_tol(out, 2.0 * 3.0 + 5.0 - 7.0 / 11.0, 1e-15);
    ck_assert_int_eq(fe_expr_compile(&e, "x0", edge_names, 5, &col, msg, sizeof msg), FE_OK);
    ck_assert_int_eq(fe_expr_eval(&e, v, &out), FE_OK);
    ck_assert_double_eq(out, 11.0);
}
END_TEST

START_TEST(precedence_as_in_mathematics)
{
    const double v[NV] = {3, 0, 0, 0, 0};
    ck_assert_double_eq(value_of("-2^2", v), -4.0);        /* -(2^2) */
    ck_assert_double_eq(value_of("2^3^2", v), 512.0);      /* 2^(3^2) */
    ck_assert_double_eq(value_of("2^-1", v), 0.5);
    ck_assert_double_eq(value_of("1-2-3", v), -4.0);       /* left to right */
    ck_assert_double_eq(value_of("8/2/2", v), 2.0);
    ck_assert_double_eq(value_of("1+2*3^2", v), 19.0);
    ck_assert_double_eq(value_of("(1+2)*3", v), 9.0);
    ck_assert_double_eq(value_of("--position", v), 3.0);
    ck_assert_double_eq(value_of(" +position * 2 ", v), 6.0);
    ck_assert_double_eq(value_of("1.5e2 + .5 + 2E-1", v), 150.7);
}
END_TEST

/* Compiling `text` fails with rc at column col, with `part` in the message. */
static void fails_at(const char *text, int rc, size_t col, const char *part)
{
    fe_expr e;
    size_t c = 0;
    char msg[512];
    ck_assert_int_eq(fe_expr_compile(&e, text, names, NV, &c, msg, sizeof msg), rc);
    ck_assert_msg(c == col, "%s: column %zu, expected %zu (%s)", text, c, col, msg);
    ck_assert_msg(strstr(msg, part) != NULL, "%s: message '%s' lacks '%s'", text, msg, part);
}

START_TEST(errors_name_their_column)
{
    fails_at("sin(position", FE_EPARSE, 13, "missing ')'");
    fails_at("(position+1", FE_EPARSE, 12, "missing ')'");
    fails_at("position)", FE_EPARSE, 9, "unmatched ')'");
    fails_at("2*posiiton", FE_EPARSE, 3, "unknown name 'posiiton'");
    fails_at("2*posiiton", FE_EPARSE, 3, "names: pi, position, velocity, t, T (C), sim");
    fails_at("sine(t)", FE_EPARSE, 1, "unknown function");
    fails_at("atan2(t)", FE_EPARSE, 1, "two arguments");
    fails_at("sin(t, t)", FE_EPARSE, 1, "one argument");
    fails_at("1 +", FE_EPARSE, 4, "ends too soon");
    fails_at("1 $ 2", FE_EPARSE, 3, "unexpected character");
    fails_at("0x10", FE_EPARSE, 2, "unexpected character");     /* no hexadecimal */
    fails_at("1.2.3", FE_EPARSE, 1, "not a number");
    fails_at("\"T (C)", FE_EPARSE, 1, "unterminated");
    fails_at("", FE_EPARSE, 1, "ends too soon");
    fails_at("\"pi\"", FE_EPARSE, 1, "unknown name 'pi'");    /* quoted: a column, not pi */
    {
        /* Deeper than the machine: a sum of 17 nested values needs 17
           slots; nested parentheses beyond the parser's depth. */
        char deep[512] = "", sum[512] = "";
        for (int i = 0; i < 30; i++)
            strcat(deep, "(");
        strcat(deep, "1");
        for (int i = 0; i < 30; i++)
            strcat(deep, ")");
        fails_at(deep, FE_ESIZE, 25, "nested too deeply");
        for (int i = 0; i < 16; i++)
            strcat(sum, "1+(");
        strcat(sum, "1");
        for (int i = 0; i < 16; i++)
            strcat(sum, ")");
        fails_at(sum, FE_ESIZE, 49, "too deep for the machine");   /* the 17th value */
    }
    {
        /* Longer than FE_EXPR_MAX_CODE instructions. */
        char longer[1024] = "1";
        for (int i = 0; i < 70; i++)
            strcat(longer, "+1");
        fails_at(longer, FE_ESIZE, 128, "too long");
    }
    {
        fe_expr e;
        ck_assert_int_eq(fe_expr_compile(NULL, "1", names, NV, NULL, NULL, 0), FE_EINVAL);
        ck_assert_int_eq(fe_expr_compile(&e, NULL, names, NV, NULL, NULL, 0), FE_EINVAL);
        ck_assert_int_eq(fe_expr_compile(&e, "1", NULL, 1, NULL, NULL, 0), FE_EINVAL);
        ck_assert_int_eq(fe_expr_compile(&e, "pi", NULL, 0, NULL, NULL, 0), FE_OK);
    }
    {
        /* The message buffer holds a string after any call, down to one
           byte: on success the empty one, whatever the byte held.  A
           buffer of no bytes is not written. */
        fe_expr e;
        char one[1] = {'x'}, none[1] = {'x'};
        ck_assert_int_eq(fe_expr_compile(&e, "1", names, NV, NULL, one, 1), FE_OK);
        ck_assert_int_eq(one[0], '\0');
        one[0] = 'x';
        ck_assert_int_eq(fe_expr_compile(&e, "1 +", names, NV, NULL, one, 1), FE_EPARSE);
        ck_assert_int_eq(one[0], '\0');
        ck_assert_int_eq(fe_expr_compile(&e, "1", names, NV, NULL, none, 0), FE_OK);
        ck_assert_int_eq(fe_expr_compile(&e, "1 +", names, NV, NULL, none, 0), FE_EPARSE);
        ck_assert_int_eq(none[0], 'x');
    }
}
END_TEST

START_TEST(values_that_are_not_finite_are_refused)
{
    fe_expr e;
    double v[NV] = {-1, 0, 0, 0, 0}, out;
    ck_assert_int_eq(fe_expr_compile(&e, "log(position)", names, NV, NULL, NULL, 0), FE_OK);
    ck_assert_int_eq(fe_expr_eval(&e, v, &out), FE_ENONFINITE);
    ck_assert_int_eq(fe_expr_compile(&e, "1/velocity", names, NV, NULL, NULL, 0), FE_OK);
    ck_assert_int_eq(fe_expr_eval(&e, v, &out), FE_ENONFINITE);
    ck_assert_int_eq(fe_expr_compile(&e, "exp(1000)", names, NV, NULL, NULL, 0), FE_OK);
    ck_assert_int_eq(fe_expr_eval(&e, v, &out), FE_ENONFINITE);
    ck_assert_int_eq(fe_expr_eval(&e, NULL, NULL), FE_EINVAL);
    {
        double rows[4 * NV] = {0}, res[4], work[FE_EXPR_MAX_STACK * 4];
        size_t bad = 99;
        ck_assert_uint_ge(sizeof work / sizeof work[0], fe_expr_work_doubles(4));
        ck_assert_int_eq(fe_expr_compile(&e, "sqrt(position)", names, NV, NULL, NULL, 0),
                         FE_OK);
        rows[0 * NV] = 4, rows[1 * NV] = 9, rows[2 * NV] = -1, rows[3 * NV] = -4;
        ck_assert_int_eq(fe_expr_eval_rows(&e, rows, NV, 4, res, work, &bad), FE_ENONFINITE);
        ck_assert_uint_eq(bad, 2);                      /* the first bad row */
        ck_assert_double_eq(res[1], 3.0);
        ck_assert_int_eq(fe_expr_eval_rows(&e, rows, 0, 4, res, work, &bad), FE_EINVAL);
    }
}
END_TEST

START_TEST(a_program_not_made_by_the_compiler_is_refused)
{
    fe_expr e, good;
    double v[NV] = {1, 2, 3, 4, 5}, out, rows[2 * NV] = {0}, res[2],
           work[FE_EXPR_MAX_STACK * 2];
    ck_assert_int_eq(fe_expr_compile(&good, "position + velocity", names, NV, NULL, NULL, 0),
                     FE_OK);
    ck_assert_int_eq(fe_expr_eval(&good, v, &out), FE_OK);
    ck_assert_double_eq(out, 3.0);
    e = good;                           /* an operation with nothing to pop */
    e.ncode = 1;
    e.op[0] = good.op[2];
    ck_assert_int_eq(fe_expr_eval(&e, v, &out), FE_EINVAL);
    ck_assert_int_eq(fe_expr_eval_rows(&e, rows, NV, 2, res, work, NULL), FE_EINVAL);
    e = good;                           /* a variable past nvars */
    e.arg[1] = (double)good.nvars;
    ck_assert_int_eq(fe_expr_eval(&e, v, &out), FE_EINVAL);
    ck_assert_int_eq(fe_expr_eval_rows(&e, rows, NV, 2, res, work, NULL), FE_EINVAL);
    e = good;                           /* two values left on the stack */
    e.ncode = 2;
    ck_assert_int_eq(fe_expr_eval(&e, v, &out), FE_EINVAL);
    ck_assert_int_eq(fe_expr_eval_rows(&e, rows, NV, 2, res, work, NULL), FE_EINVAL);
    e = good;                           /* an operation that does not exist */
    e.op[2] = 200;
    ck_assert_int_eq(fe_expr_eval(&e, v, &out), FE_EINVAL);
    e = good;
    e.ncode = FE_EXPR_MAX_CODE + 1;
    ck_assert_int_eq(fe_expr_eval(&e, v, &out), FE_EINVAL);
}
END_TEST

START_TEST(a_panel_equals_its_rows)
{
    static const char *const texts[] = {
        "sin(2*pi*position/0.002)", "velocity*abs(velocity) - 3*sim^2/(1+t^2)",
        "max(min(position, velocity), -0.5) * atan2(t, 1 + sim^2)",
        "-(position - velocity)^3 + sign(t)*sqrt(abs(\"T (C)\"))",
        "exp(-t^2) * cos(velocity) * tanh(position) / 2 - 1e-3"};
    enum { N = 300 };
    static double rows[N * NV], out[N], work[FE_EXPR_MAX_STACK * N];
    fe_rng rng = fe_rng_seed(9);
    for (size_t i = 0; i < N * NV; i++)
        rows[i] = 4.0 * fe_rng_uniform(&rng) - 2.0;
    for (size_t k = 0; k < sizeof texts / sizeof texts[0]; k++) {
        fe_expr e;
        size_t bad = 0;
        ck_assert_int_eq(fe_expr_compile(&e, texts[k], names, NV, NULL, NULL, 0), FE_OK);
        ck_assert_int_eq(fe_expr_eval_rows(&e, rows, NV, N, out, work, &bad), FE_OK);
        for (size_t t = 0; t < N; t++) {
            double one;
            ck_assert_int_eq(fe_expr_eval(&e, rows + t * NV, &one), FE_OK);
            ck_assert_double_eq(out[t], one);               /* the same operations */
        }
    }
}
END_TEST

/* Which variables a program reads; a NULL name is a hole: never matched,
   never listed. */
START_TEST(what_a_program_reads)
{
    const char *holes[] = {"position", NULL, "t", "T (C)", NULL};
    fe_expr e;
    size_t col = 0;
    char msg[256];
    ck_assert_int_eq(fe_expr_compile(&e, "t*`T (C)` + t", names, NV, &col, msg, sizeof msg),
                     FE_OK);
    ck_assert_int_eq(fe_expr_reads(&e, 2), 1);
    ck_assert_int_eq(fe_expr_reads(&e, 3), 1);
    ck_assert_int_eq(fe_expr_reads(&e, 0), 0);
    ck_assert_int_eq(fe_expr_reads(&e, 4), 0);
    ck_assert_int_eq(fe_expr_reads(NULL, 2), 0);
    ck_assert_int_eq(fe_expr_compile(&e, "2 + 3", names, NV, &col, msg, sizeof msg), FE_OK);
    ck_assert_int_eq(fe_expr_reads(&e, 0), 0);   /* a constant's argument is no variable */
    ck_assert_int_eq(fe_expr_compile(&e, "velocity", holes, 5, &col, msg, sizeof msg),
                     FE_EPARSE);
    ck_assert_uint_eq(col, 1);
    ck_assert_str_eq(msg, "unknown name 'velocity'; names: pi, position, t, T (C)");
    ck_assert_int_eq(fe_expr_compile(&e, "t", holes, 5, &col, msg, sizeof msg), FE_OK);
    ck_assert_int_eq(fe_expr_reads(&e, 2), 1);
}
END_TEST

/* `k` copies of pre, then mid, then k copies of post, into t. */
static const char *repeat(char *t, size_t len, const char *pre, int k, const char *mid,
                          const char *post)
{
    t[0] = '\0';
    for (int i = 0; i < k; i++)
        strncat(t, pre, len - strlen(t) - 1);
    strncat(t, mid, len - strlen(t) - 1);
    for (int i = 0; i < k; i++)
        strncat(t, post, len - strlen(t) - 1);
    return t;
}

/* Issue 20: each limit of the compiler at its edge.  FE_EXPR_MAX_DEPTH
   counts the parser's levels, two a parenthesis or function argument and
   one a sign: 23 parentheses (48 levels) compile and 24 are refused at
   the 24th, 46 signs compile and 47 do not; 16 values on the stack
   compile and evaluate, 17 do not; 128 instructions compile, 129 do not
   (the 129th is refused where it is emitted). */
START_TEST(each_limit_of_the_compiler_is_met_at_its_edge)
{
    char t[1024];
    fe_expr e;
    double out = 0.0;
    fails_at(repeat(t, sizeof t, "(", 24, "1", ")"), FE_ESIZE, 25, "nested too deeply");
    ck_assert_int_eq(fe_expr_compile(&e, repeat(t, sizeof t, "(", 23, "7", ")"), names, NV, NULL,
                                     NULL, 0), FE_OK);
    ck_assert_int_eq(fe_expr_eval(&e, NULL, &out), FE_OK);
    ck_assert_double_eq(out, 7.0);
    fails_at(repeat(t, sizeof t, "sin(", 24, "1", ")"), FE_ESIZE, 97, "nested too deeply");
    ck_assert_int_eq(fe_expr_compile(&e, repeat(t, sizeof t, "abs(", 23, "2", ")"), names, NV,
                                     NULL, NULL, 0), FE_OK);
    ck_assert_int_eq(fe_expr_eval(&e, NULL, &out), FE_OK);
    ck_assert_double_eq(out, 2.0);
    fails_at(repeat(t, sizeof t, "-", 47, "1", ""), FE_ESIZE, 48, "nested too deeply");
    ck_assert_int_eq(fe_expr_compile(&e, repeat(t, sizeof t, "-", 46, "3", ""), names, NV, NULL,
                                     NULL, 0), FE_OK);
    ck_assert_int_eq(fe_expr_eval(&e, NULL, &out), FE_OK);
    ck_assert_double_eq(out, 3.0);                      /* an even number of signs */
    /* The stack: 1+(1+(...(1))) holds one value per level. */
    fails_at(repeat(t, sizeof t, "1+(", 16, "1", ")"), FE_ESIZE, 49, "too deep for the machine");
    ck_assert_int_eq(fe_expr_compile(&e, repeat(t, sizeof t, "1+(", 15, "1", ")"), names, NV,
                                     NULL, NULL, 0), FE_OK);
    ck_assert_uint_eq(e.depth, FE_EXPR_MAX_STACK);
    ck_assert_int_eq(fe_expr_eval(&e, NULL, &out), FE_OK);
    ck_assert_double_eq(out, 16.0);
    /* The length: -1 is two instructions and each +1 two more. */
    ck_assert_int_eq(fe_expr_compile(&e, repeat(t, sizeof t, "", 0, "-1", ""), names, NV, NULL,
                                     NULL, 0), FE_OK);
    ck_assert_uint_eq(e.ncode, 2);
    for (int i = 0; i < 63; i++)
        strcat(t, "+1");
    ck_assert_int_eq(fe_expr_compile(&e, t, names, NV, NULL, NULL, 0), FE_OK);
    ck_assert_uint_eq(e.ncode, FE_EXPR_MAX_CODE);
    ck_assert_int_eq(fe_expr_eval(&e, NULL, &out), FE_OK);
    ck_assert_double_eq(out, 62.0);
    memmove(t + 1, t, strlen(t) + 1);                   /* --1+1...: 129 instructions */
    t[0] = '-';
    fails_at(t, FE_ESIZE, 128, "too long");            /* the last +, the 129th */
}
END_TEST

/* Issue 20: the panel evaluation's row stride at its edge: a program that
   reads variable 3 needs ldv >= 4; 4 is taken, 3 refused (out untouched). */
START_TEST(a_row_stride_equal_to_the_variables_read_is_enough)
{
    fe_expr e;
    double rows[2 * 4] = {0, 0, 0, 5, 0, 0, 0, 7}, out[2] = {-1, -1}, work[FE_EXPR_MAX_STACK * 2];
    ck_assert_int_eq(fe_expr_compile(&e, "2*`T (C)`", names, NV, NULL, NULL, 0), FE_OK);
    ck_assert_uint_eq(e.nvars, 4);
    ck_assert_int_eq(fe_expr_eval_rows(&e, rows, 3, 2, out, work, NULL), FE_EINVAL);
    ck_assert_double_eq(out[0], -1.0);
    ck_assert_double_eq(out[1], -1.0);
    ck_assert_int_eq(fe_expr_eval_rows(&e, rows, 4, 2, out, work, NULL), FE_OK);
    ck_assert_double_eq(out[0], 10.0);
    ck_assert_double_eq(out[1], 14.0);
    /* Each null argument alone, with everything else right. */
    ck_assert_int_eq(fe_expr_eval_rows(NULL, rows, 4, 2, out, work, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_expr_eval_rows(&e, NULL, 4, 2, out, work, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_expr_eval_rows(&e, rows, 4, 2, NULL, work, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_expr_eval_rows(&e, rows, 4, 2, out, NULL, NULL), FE_EINVAL);
}
END_TEST

Suite *fe_expr_suite(void)
{
    Suite *s = suite_create("expr");
    TCase *t = tcase_create("expr");
    tcase_add_test(t, expressions_are_their_formulas);
    tcase_add_test(t, precedence_as_in_mathematics);
    tcase_add_test(t, unquoted_names_hold_every_edge_of_their_ranges);
    tcase_add_test(t, errors_name_their_column);
    tcase_add_test(t, values_that_are_not_finite_are_refused);
    tcase_add_test(t, a_program_not_made_by_the_compiler_is_refused);
    tcase_add_test(t, a_panel_equals_its_rows);
    tcase_add_test(t, what_a_program_reads);
    tcase_add_test(t, each_limit_of_the_compiler_is_met_at_its_edge);
    tcase_add_test(t, a_row_stride_equal_to_the_variables_read_is_enough);
    suite_add_tcase(s, t);
    return s;
}
