/* SPDX-License-Identifier: MIT */
/* Tangled from literate/expr.org: do not edit; edit the .org and run make tangle. */
/* [[file:../literate/expr.org::Expression Includes][Expression Includes]] */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "foldest/csv.h"
#include "foldest/error.h"
#include "foldest/expr.h"
/* Expression Includes ends here */
/* [[file:../literate/expr.org::The instructions][The instructions]] */
enum {
    FE__CONST, FE__VAR, FE__NEG, FE__ADD, FE__SUB, FE__MUL, FE__DIV, FE__POW,
    FE__ABS, FE__SIGN, FE__SQRT, FE__EXP, FE__LOG, FE__SIN, FE__COS, FE__TAN, FE__TANH,
    FE__ATAN2, FE__MIN, FE__MAX
};

/* The functions by name, with their instruction and arity. */
static const struct {
    const char *name;
    unsigned char op;
    int arity;
} fe__functions[] = {
    {"abs", FE__ABS, 1},   {"sign", FE__SIGN, 1}, {"sqrt", FE__SQRT, 1},
    {"exp", FE__EXP, 1},   {"log", FE__LOG, 1},   {"sin", FE__SIN, 1},
    {"cos", FE__COS, 1},   {"tan", FE__TAN, 1},   {"tanh", FE__TANH, 1},
    {"atan2", FE__ATAN2, 2}, {"min", FE__MIN, 2}, {"max", FE__MAX, 2}};

static double fe__apply1(unsigned char op, double x)
{
    switch (op) {
    case FE__NEG: return -x;
    case FE__ABS: return fabs(x);
    case FE__SIGN: return (x > 0) - (x < 0);
    case FE__SQRT: return sqrt(x);
    case FE__EXP: return exp(x);
    case FE__LOG: return log(x);
    case FE__SIN: return sin(x);
    case FE__COS: return cos(x);
    case FE__TAN: return tan(x);
    default: return tanh(x);
    }
}

static double fe__apply2(unsigned char op, double x, double y)
{
    switch (op) {
    case FE__ADD: return x + y;
    case FE__SUB: return x - y;
    case FE__MUL: return x * y;
    case FE__DIV: return x / y;
    case FE__POW: return pow(x, y);
    case FE__ATAN2: return atan2(x, y);
    case FE__MIN: return x < y ? x : y;
    default: return x > y ? x : y;
    }
}

/* Operands of an instruction. */
static int fe__arity(unsigned char op)
{
    return op <= FE__VAR ? 0 : op == FE__NEG || (op >= FE__ABS && op <= FE__TANH) ? 1 : 2;
}
/* The instructions ends here */
/* [[file:../literate/expr.org::Parse an expression][Parse an expression]] */
typedef struct fe__parser {
    const char *at;
    const char *const *names;
    size_t nnames;
    fe_expr *e;
    size_t height, nest;
    int rc;
    const char *err_at;
    char *msg;
    size_t msglen;
} fe__parser;

static void fe__fail(fe__parser *p, int rc, const char *at, const char *what)
{
    if (p->rc != FE_OK)
        return;                 /* the first error is the one reported */
    p->rc = rc;
    p->err_at = at;
    if (p->msg != NULL && p->msglen > 0)
        snprintf(p->msg, p->msglen, "%s", what);
}

static void fe__emit(fe__parser *p, unsigned char op, double arg, const char *at)
{
    int k = fe__arity(op);
    if (p->rc != FE_OK)
        return;
    if (p->e->ncode >= FE_EXPR_MAX_CODE) {
        fe__fail(p, FE_ESIZE, at, "expression too long");
        return;
    }
    p->e->op[p->e->ncode] = op;
    p->e->arg[p->e->ncode++] = arg;
    p->height = p->height + 1 - (size_t)k;
    if (p->height > FE_EXPR_MAX_STACK) {
        fe__fail(p, FE_ESIZE, at, "expression too deep for the machine's stack");
        return;
    }
    if (p->height > p->e->depth)
        p->e->depth = p->height;
}

static void fe__skip(fe__parser *p)
{
    while (*p->at == ' ' || *p->at == '\t')
        p->at++;
}

static void fe__expr(fe__parser *p);

static void fe__number(fe__parser *p)
{
    const char *s = p->at;
    char buf[64];
    fe_csv_field f;
    double v;
    size_t len;
    while ((*p->at >= '0' && *p->at <= '9') || *p->at == '.')
        p->at++;
    if ((*p->at == 'e' || *p->at == 'E')
        && ((p->at[1] >= '0' && p->at[1] <= '9')
            || ((p->at[1] == '+' || p->at[1] == '-') && p->at[2] >= '0' && p->at[2] <= '9'))) {
        p->at += 2;
        while (*p->at >= '0' && *p->at <= '9')
            p->at++;
    }
    len = (size_t)(p->at - s);
    if (len >= sizeof buf) {
        fe__fail(p, FE_EPARSE, s, "number too long");
        return;
    }
    memcpy(buf, s, len);
    buf[len] = '\0';
    f.text = buf;
    f.column = 1;
    if (fe_csv_number(&f, &v) != FE_OK) {
        fe__fail(p, FE_EPARSE, s, "not a number");
        return;
    }
    fe__emit(p, FE__CONST, v, s);
}
static void fe__unknown(fe__parser *p, const char *at, const char *name, size_t len)
{
    char what[512];
    size_t k = (size_t)snprintf(what, sizeof what, "unknown name '%.*s'; names: pi",
                                (int)(len < 64 ? len : 64), name);
    for (size_t i = 0; i < p->nnames && k < sizeof what; i++)
        if (p->names[i] != NULL)
            k += (size_t)snprintf(what + k, sizeof what - k, ", %s", p->names[i]);
    fe__fail(p, FE_EPARSE, at, what);
}

static void fe__call(fe__parser *p, const char *at, const char *name, size_t len)
{
    size_t f = 0, nf = sizeof fe__functions / sizeof fe__functions[0];
    int args = 0;
    while (f < nf && !(strlen(fe__functions[f].name) == len
                       && memcmp(fe__functions[f].name, name, len) == 0))
        f++;
    if (f == nf) {
        fe__fail(p, FE_EPARSE, at, "unknown function (abs sign sqrt exp log sin cos tan "
                                   "tanh atan2 min max)");
        return;
    }
    p->at++;                                    /* '(' */
    for (;;) {
        fe__expr(p);
        args++;
        fe__skip(p);
        if (p->rc != FE_OK)
            return;
        if (*p->at == ',') {
            p->at++;
            continue;
        }
        if (*p->at != ')') {
            fe__fail(p, FE_EPARSE, p->at, "missing ')'");
            return;
        }
        p->at++;
        break;
    }
    if (args != fe__functions[f].arity) {
        fe__fail(p, FE_EPARSE, at, fe__functions[f].arity == 1
                                       ? "this function takes one argument"
                                       : "this function takes two arguments");
        return;
    }
    fe__emit(p, fe__functions[f].op, 0.0, at);
}

static void fe__name(fe__parser *p)
{
    const char *at = p->at, *name;
    size_t len;
    if (*p->at == '"' || *p->at == '`') {
        char q = *p->at++;
        name = p->at;
        while (*p->at != '\0' && *p->at != q)
            p->at++;
        if (*p->at != q) {
            fe__fail(p, FE_EPARSE, at, "unterminated quoted name");
            return;
        }
        len = (size_t)(p->at++ - name);
    } else {
        name = p->at;
        while ((*p->at >= 'a' && *p->at <= 'z') || (*p->at >= 'A' && *p->at <= 'Z')
               || (*p->at >= '0' && *p->at <= '9') || *p->at == '_' || *p->at == '.')
            p->at++;
        len = (size_t)(p->at - name);
        fe__skip(p);
        if (*p->at == '(') {
            fe__call(p, at, name, len);
            return;
        }
    }
    for (size_t i = 0; i < p->nnames; i++)
        if (p->names[i] != NULL && strlen(p->names[i]) == len
            && memcmp(p->names[i], name, len) == 0) {
            fe__emit(p, FE__VAR, (double)i, at);
            if (i + 1 > p->e->nvars)
                p->e->nvars = i + 1;
            return;
        }
    if (len == 2 && memcmp(name, "pi", 2) == 0 && *at != '"' && *at != '`') {
        fe__emit(p, FE__CONST, 3.14159265358979323846, at);
        return;
    }
    fe__unknown(p, at, name, len);
}
static void fe__unary(fe__parser *p);

static void fe__primary(fe__parser *p)
{
    fe__skip(p);
    if (p->rc != FE_OK)
        return;
    if (*p->at == '(') {
        p->at++;
        fe__expr(p);
        fe__skip(p);
        if (p->rc == FE_OK && *p->at != ')')
            fe__fail(p, FE_EPARSE, p->at, "missing ')'");
        else if (p->rc == FE_OK)
            p->at++;
    } else if ((*p->at >= '0' && *p->at <= '9') || *p->at == '.') {
        fe__number(p);
    } else if ((*p->at >= 'a' && *p->at <= 'z') || (*p->at >= 'A' && *p->at <= 'Z')
               || *p->at == '_' || *p->at == '"' || *p->at == '`') {
        fe__name(p);
    } else {
        fe__fail(p, FE_EPARSE, p->at, *p->at == '\0' ? "expression ends too soon"
                                                     : "unexpected character");
    }
}

static void fe__power(fe__parser *p)
{
    const char *at;
    fe__primary(p);
    fe__skip(p);
    if (p->rc != FE_OK || *p->at != '^')
        return;
    at = p->at++;
    fe__unary(p);
    fe__emit(p, FE__POW, 0.0, at);
}

static void fe__unary(fe__parser *p)
{
    fe__skip(p);
    if (++p->nest > FE_EXPR_MAX_DEPTH) {
        fe__fail(p, FE_ESIZE, p->at, "expression nested too deeply");
        return;
    }
    if (*p->at == '-' || *p->at == '+') {
        const char *at = p->at;
        int neg = *p->at++ == '-';
        fe__unary(p);
        if (neg)
            fe__emit(p, FE__NEG, 0.0, at);
    } else {
        fe__power(p);
    }
    p->nest--;
}

static void fe__term(fe__parser *p)
{
    fe__unary(p);
    for (;;) {
        const char *at;
        unsigned char op;
        fe__skip(p);
        if (p->rc != FE_OK || (*p->at != '*' && *p->at != '/'))
            return;
        at = p->at;
        op = *p->at++ == '*' ? FE__MUL : FE__DIV;
        fe__unary(p);
        fe__emit(p, op, 0.0, at);
    }
}

static void fe__expr(fe__parser *p)
{
    if (++p->nest > FE_EXPR_MAX_DEPTH) {
        fe__fail(p, FE_ESIZE, p->at, "expression nested too deeply");
        return;
    }
    fe__term(p);
    for (;;) {
        const char *at;
        unsigned char op;
        fe__skip(p);
        if (p->rc != FE_OK || (*p->at != '+' && *p->at != '-'))
            break;
        at = p->at;
        op = *p->at++ == '+' ? FE__ADD : FE__SUB;
        fe__term(p);
        fe__emit(p, op, 0.0, at);
    }
    p->nest--;
}
/* Parse an expression ends here */
/* [[file:../literate/expr.org::Compile][Compile]] */
int fe_expr_compile(fe_expr *e, const char *text, const char *const *names, size_t nnames,
                    size_t *col, char *msg, size_t msglen)
{
    fe__parser p;
    if (e == NULL || text == NULL || (nnames > 0 && names == NULL))
        return FE_EINVAL;
    memset(e, 0, sizeof *e);
    memset(&p, 0, sizeof p);
    p.at = text;
    p.names = names;
    p.nnames = nnames;
    p.e = e;
    p.rc = FE_OK;
    p.msg = msg;
    p.msglen = msglen;
    if (msg != NULL && msglen > 0)
        msg[0] = '\0';
    fe__expr(&p);
    fe__skip(&p);
    if (p.rc == FE_OK && *p.at != '\0')
        fe__fail(&p, FE_EPARSE, p.at, *p.at == ')' ? "unmatched ')'" : "unexpected character");
    if (p.rc == FE_OK && e->ncode == 0)
        fe__fail(&p, FE_EPARSE, p.at, "empty expression");
    if (col != NULL)
        *col = p.rc == FE_OK ? 0 : (size_t)(p.err_at - text) + 1;
    return p.rc;
}
/* Compile ends here */
/* [[file:../literate/expr.org::Evaluate][Evaluate]] */
/* Whether instruction i of e can run on a stack of height h (and leave
   the stack within its bounds). */
static int fe__step_ok(const fe_expr *e, size_t i, size_t h)
{
    unsigned char op = e->op[i];
    int k = fe__arity(op);
    if (op > FE__MAX)
        return 0;
    if (k == 0)
        return h < FE_EXPR_MAX_STACK
               && (op == FE__CONST || (e->arg[i] >= 0.0 && e->arg[i] < (double)e->nvars));
    return h >= (size_t)k;
}

int fe_expr_eval(const fe_expr *e, const double *v, double *out)
{
    double s[FE_EXPR_MAX_STACK] = {0};
    size_t h = 0;
    if (e == NULL || out == NULL || (e->nvars > 0 && v == NULL) || e->ncode == 0
        || e->ncode > FE_EXPR_MAX_CODE)
        return FE_EINVAL;
    for (size_t i = 0; i < e->ncode; i++) {
        unsigned char op = e->op[i];
        if (!fe__step_ok(e, i, h))
            return FE_EINVAL;
        switch (fe__arity(op)) {
        case 0: s[h++] = op == FE__CONST ? e->arg[i] : v[(size_t)e->arg[i]]; break;
        case 1: s[h - 1] = fe__apply1(op, s[h - 1]); break;
        default: s[h - 2] = fe__apply2(op, s[h - 2], s[h - 1]); h--; break;
        }
    }
    if (h != 1)
        return FE_EINVAL;
    *out = s[0];
    return isfinite(*out) ? FE_OK : FE_ENONFINITE;
}

size_t fe_expr_work_doubles(size_t n)
{
    return FE_EXPR_MAX_STACK * n;
}

int fe_expr_eval_rows(const fe_expr *e, const double *v, size_t ldv, size_t n, double *out,
                      double *work, size_t *bad)
{
    size_t h = 0;
    if (e == NULL || out == NULL || work == NULL || e->ncode == 0
        || e->ncode > FE_EXPR_MAX_CODE || (e->nvars > 0 && (v == NULL || ldv < e->nvars)))
        return FE_EINVAL;
    for (size_t i = 0, g = 0; i < e->ncode; i++) {      /* the program first */
        if (!fe__step_ok(e, i, g))
            return FE_EINVAL;
        g = g + 1 - (size_t)fe__arity(e->op[i]);
        if (i + 1 == e->ncode && g != 1)
            return FE_EINVAL;
    }
    for (size_t i = 0; i < e->ncode; i++) {
        unsigned char op = e->op[i];
        double *x = work + (h - (h > 0)) * n, *y = work + h * n;
        switch (fe__arity(op)) {
        case 0:
            if (op == FE__CONST)
                for (size_t t = 0; t < n; t++)
                    y[t] = e->arg[i];
            else
                for (size_t t = 0, j = (size_t)e->arg[i]; t < n; t++)
                    y[t] = v[t * ldv + j];
            h++;
            break;
        case 1:
            for (size_t t = 0; t < n; t++)
                x[t] = fe__apply1(op, x[t]);
            break;
        default:
            x = work + (h - 2) * n;
            y = work + (h - 1) * n;
            switch (op) {
            case FE__ADD: for (size_t t = 0; t < n; t++) x[t] += y[t]; break;
            case FE__SUB: for (size_t t = 0; t < n; t++) x[t] -= y[t]; break;
            case FE__MUL: for (size_t t = 0; t < n; t++) x[t] *= y[t]; break;
            case FE__DIV: for (size_t t = 0; t < n; t++) x[t] /= y[t]; break;
            default: for (size_t t = 0; t < n; t++) x[t] = fe__apply2(op, x[t], y[t]); break;
            }
            h--;
            break;
        }
    }
    memcpy(out, work, n * sizeof *out);
    for (size_t t = 0; t < n; t++)
        if (!isfinite(out[t])) {
            if (bad != NULL)
                *bad = t;
            return FE_ENONFINITE;
        }
    return FE_OK;
}
/* Evaluate ends here */
/* [[file:../literate/expr.org::Which variables a program reads][Which variables a program reads]] */
int fe_expr_reads(const fe_expr *e, size_t j)
{
    for (size_t i = 0; e != NULL && i < e->ncode && i < FE_EXPR_MAX_CODE; i++)
        if (e->op[i] == FE__VAR && e->arg[i] == (double)j)
            return 1;
    return 0;
}
/* Which variables a program reads ends here */
