/* SPDX-License-Identifier: MIT */
/* Tangled from literate/expr.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/expr.org::Expression Declarations][Expression Declarations]] */
#ifndef FOLDEST_EXPR_H
#define FOLDEST_EXPR_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

enum {
    FE_EXPR_MAX_CODE = 128,     /* instructions of one expression */
    FE_EXPR_MAX_STACK = 16,     /* values on the machine's stack */
    FE_EXPR_MAX_DEPTH = 48      /* levels of the parser's recursion: a
                                   parenthesis or a function's argument
                                   takes two, a sign one (23 nested
                                   parentheses, 46 signs) */
};

/* A compiled expression: a program for a stack machine.  A flat struct:
   copy it, keep it; it refers to nothing outside itself. */
typedef struct fe_expr {
    size_t ncode;
    unsigned char op[FE_EXPR_MAX_CODE];
    double arg[FE_EXPR_MAX_CODE];       /* a constant, or a variable's index */
    size_t depth;                       /* the stack it needs */
    size_t nvars;                       /* variables it may read: indices < nvars */
} fe_expr;

/* fe_expr_compile: compile `text` against the variable names
   names[0 .. nnames) (any strings; the first match wins).  On an error
   returns FE_EPARSE (syntax, unknown name, wrong arguments) or FE_ESIZE
   (longer or deeper than the machine), with *col the column (from 1) in
   text where it was found and a message in msg[msglen] (either may be
   NULL); e is then unusable.  FE_EINVAL for NULL e or text. */
int fe_expr_compile(fe_expr *e, const char *text, const char *const *names, size_t nnames,
                    size_t *col, char *msg, size_t msglen);

/* fe_expr_eval: the value at the variables v[0 .. nvars).  FE_ENONFINITE
   when it is not finite (*out is then NaN or infinite); FE_EINVAL on
   NULL.  No allocation; about 10 bytes of stack per level of
   FE_EXPR_MAX_STACK. */
int fe_expr_eval(const fe_expr *e, const double *v, double *out);

/* fe_expr_work_doubles: the workspace fe_expr_eval_rows needs for n
   rows. */
size_t fe_expr_work_doubles(size_t n);

/* fe_expr_eval_rows: out[t] for the n rows whose variable j is
   v[t * ldv + j], each instruction applied to the whole panel; work holds
   fe_expr_work_doubles(n) doubles.  FE_ENONFINITE when a value is not
   finite: *bad (if not NULL) is then the first such row, and out[] is
   complete.  FE_EINVAL on NULL or ldv < nvars. */
int fe_expr_eval_rows(const fe_expr *e, const double *v, size_t ldv, size_t n, double *out,
                      double *work, size_t *bad);

/* fe_expr_reads: 1 when the program reads variable j, else 0 (also for
   NULL e).  A caller that gathers its variables from files reads only the
   columns some expression needs. */
int fe_expr_reads(const fe_expr *e, size_t j);

#ifdef __cplusplus
}
#endif

#endif /* FOLDEST_EXPR_H */
/* Expression Declarations ends here */
