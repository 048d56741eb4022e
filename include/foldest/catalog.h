/* SPDX-License-Identifier: MIT */
/* Tangled from literate/catalog.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/catalog.org::Catalog Declarations][Catalog Declarations]] */
#ifndef FOLDEST_CATALOG_H
#define FOLDEST_CATALOG_H

#include <stddef.h>
#include <stdint.h>

#include "foldest/discover.h"
#include "foldest/expr.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Roles of the simulation's state columns, as bits. */
enum fe_role {
    FE_ROLE_POSITION = 1u << 0,
    FE_ROLE_VELOCITY = 1u << 1,
    FE_ROLE_TEMPERATURE = 1u << 2,
    FE_ROLE_AMBIENT = 1u << 3,
    FE_ROLE_INPUT = 1u << 4
};

/* One row of a recording-simulation pair. */
typedef struct fe_sample {
    double t;                   /* time */
    double real, sim;           /* recorded and simulated channel */
    double dsim;                /* d(sim)/dt */
    double position, velocity, temperature, ambient, input;
} fe_sample;

/* What some terms need from the whole data: found by a first pass. */
typedef struct fe_catalog_scale {
    uint64_t n;
    double t_first, temperature_first, vmax;
    int temperature_kelvin, ambient_kelvin;     /* columns already in K */
} fe_catalog_scale;

typedef double fe_term_fn(const fe_sample *s, const fe_catalog_scale *scale,
                          void *user);

/* A named term: a C function of a sample (eval), or an expression over a
   row of variables (expr; eval is then NULL). */
typedef struct fe_term {
    const char *name;
    const char *description;    /* one line of physics */
    fe_term_fn *eval;
    void *user;
    unsigned needs;             /* fe_role bits it needs */
    const fe_expr *expr;        /* an expression term, or NULL */
    int probe;                  /* 1: a probe of the state, not physics
                                   (fe_catalog_add_probes): 1 where row
                                   variable `var` lies in [lo, hi), else 0 */
    int var;                    /* a probe's fe_catalog_var */
    double lo, hi;              /* a probe's bin */
} fe_term;

/* The variables of a row, in this order: what an expression term reads,
   and what fe_catalog_eval_rows takes.  A caller may append its own
   (other columns of its data) after FE_CATALOG_VARS. */
enum fe_catalog_var {
    FE_CATALOG_VAR_T, FE_CATALOG_VAR_SIM, FE_CATALOG_VAR_DSIM, FE_CATALOG_VAR_POSITION,
    FE_CATALOG_VAR_VELOCITY, FE_CATALOG_VAR_TEMPERATURE, FE_CATALOG_VAR_AMBIENT,
    FE_CATALOG_VAR_INPUT, FE_CATALOG_VARS
};

/* A catalog: the terms one analysis tests. */
typedef struct fe_catalog {
    fe_term terms[FE_DISCOVER_MAX_GROUPS];
    size_t count;
    unsigned roles;
    fe_catalog_scale scale;
} fe_catalog;

/* fe_catalog_builtin_terms: the table of built-in terms (for help). */
const fe_term *fe_catalog_builtin_terms(size_t *count);

/* fe_catalog_scale_add: fold a sample into the first-pass scale. */
int fe_catalog_scale_add(fe_catalog_scale *scale, const fe_sample *s);

/* fe_catalog_init: the built-in terms whose roles are in `roles`, with
   the scale of a first pass.  The temperature terms also need ambient
   (newton_cooling, radiative_cooling) or only temperature
   (thermal_sensitivity). */
int fe_catalog_init(fe_catalog *c, unsigned roles, const fe_catalog_scale *scale);

/* fe_catalog_add: a user term.  FE_ESIZE when the catalog is full;
   FE_EINVAL for a NULL name or function or a name already present. */
int fe_catalog_add(fe_catalog *c, const char *name, const char *description,
                   fe_term_fn *eval, void *user);

/* fe_catalog_var_names: the names of the FE_CATALOG_VARS variables of a
   row ("t", "sim", "dsim", "position", ...), to compile expressions
   against (fe_expr_compile), the caller's own names appended. */
const char *const *fe_catalog_var_names(size_t *count);

/* fe_catalog_add_expr: a user term given by a compiled expression over a
   row of variables (fe_catalog_var_names, then the caller's).  The
   catalog keeps the pointers: name, description and e must outlive it.
   FE_ESIZE when the catalog is full; FE_EINVAL for a NULL name or e, or a
   name already present or of a built-in term (whose readings in words,
   fe_catalog_explain, would then be wrong). */
int fe_catalog_add_expr(fe_catalog *c, const char *name, const char *description,
                        const fe_expr *e);

/* The most bins fe_catalog_add_probes cuts a variable's range into. */
enum { FE_CATALOG_MAX_BINS = 16 };

/* fe_catalog_add_probes: bins - 1 probes of the row variable `var` (a
   fe_catalog_var from FE_CATALOG_VAR_POSITION on), appended: probe k is 1
   on rows whose variable lies in the k-th of `bins` equal bins of
   [lo, hi], else 0; the first bin is open below, and the last, open
   above, is left out (the probes and a constant would be collinear).
   Probes are not physics: discovery tests them against its final model
   and never selects them (fe_discover_options.nprobes), so that the
   verdict can ask whether some function of the state that no term
   describes is left.  fe_catalog_find does not see them.  All or none:
   FE_ESIZE when they do not fit; FE_EINVAL for NULL, a variable out of
   range, bins < 2 or > FE_CATALOG_MAX_BINS, lo >= hi or not finite. */
int fe_catalog_add_probes(fe_catalog *c, int var, double lo, double hi, size_t bins);

/* fe_catalog_remove: drop the term called `name`, the others keeping
   their order.  FE_EINVAL when there is none. */
int fe_catalog_remove(fe_catalog *c, const char *name);

/* fe_catalog_find: the index of the term called `name`, or -1. */
long fe_catalog_find(const fe_catalog *c, const char *name);

/* fe_catalog_eval: phi[j] = term j at sample s, j < c->count.
   FE_ENONFINITE if a term is not finite (phi is then incomplete);
   FE_EINVAL if an expression term reads a variable beyond
   FE_CATALOG_VARS (a sample does not have it: use fe_catalog_eval_rows). */
int fe_catalog_eval(const fe_catalog *c, const fe_sample *s, double *phi);

/* fe_catalog_row: the FE_CATALOG_VARS variables of sample s into row. */
void fe_catalog_row(const fe_sample *s, double *row);

/* fe_catalog_work_doubles: the workspace fe_catalog_eval_rows needs for
   n rows. */
size_t fe_catalog_work_doubles(size_t n);

/* fe_catalog_eval_rows: phi[t * ldphi + j] = term j at row t, for the n
   rows whose variable k is rows[t * ldv + k]; expression terms a panel
   at a time (fe_expr_eval_rows), the others row by row.  work holds
   fe_catalog_work_doubles(n) doubles.  FE_ENONFINITE when a term is not
   finite: *bad (if not NULL) is then the first such row, and phi is
   complete.  FE_EINVAL on NULL, ldv < FE_CATALOG_VARS or below what an
   expression reads, or ldphi < c->count.  No allocation. */
int fe_catalog_eval_rows(const fe_catalog *c, const double *rows, size_t ldv, size_t n,
                         double *phi, size_t ldphi, double *work, size_t *bad);

/* fe_catalog_groups: one single-column group per term, for the engine. */
void fe_catalog_groups(const fe_catalog *c, fe_discover_group *groups);

/* fe_catalog_explain: the coefficient of term `name` in words, e.g.
   "quadratic drag: a = -k v|v| with k = 0.012 +/- 0.002 (1/length)".
   Writes at most len bytes (NUL-terminated); returns FE_OK. */
int fe_catalog_explain(const char *name, double coef, double stderr_,
                       char *buf, size_t len);

/* The three-axis catalog: the radial residual r = |x - b| - R of a vector
   sensor against a sphere (centre b, radius R), in terms of the unit
   direction u = (x - b) / |x - b|. */
enum {
    FE_CATALOG_AXES_COLUMNS = 13,   /* 1; u; u_x^2, u_y^2; u_x u_y, u_x u_z,
                                       u_y u_z; (T - T1) u; t - t1 */
    FE_CATALOG_AXES_GROUPS = 6      /* bias, hard_iron, axis_gain,
                                       cross_axis, thermal_offset, drift */
};

typedef struct fe_catalog_axes {
    double centre[3];               /* b */
    double t1, temperature1;        /* the first time and temperature */
    size_t ngroups;                 /* the groups these data can test */
    fe_discover_group groups[FE_CATALOG_AXES_GROUPS];
    const char *description[FE_CATALOG_AXES_GROUPS];   /* of groups[i] */
} fe_catalog_axes;

/* fe_catalog_axes_init: the catalog for samples around `centre`: bias,
   hard_iron (the base: the sphere's own parameters), axis_gain,
   cross_axis, then thermal_offset when the samples have a temperature
   (the first is temperature1) and drift when they have a time (the first
   is t1).  Errors: FE_EINVAL (NULL), FE_ENONFINITE (centre, or t1 or
   temperature1 when used). */
int fe_catalog_axes_init(fe_catalog_axes *c, const double centre[3], int has_time, double t1,
                         int has_temperature, double temperature1);

/* fe_catalog_axes_eval: the FE_CATALOG_AXES_COLUMNS columns of sample x
   at time t and temperature temp into phi, and |x - b| into *radius.
   Errors: FE_EINVAL (NULL), FE_ENONFINITE (an input not finite),
   FE_ESINGULAR (x at the centre: no direction). */
int fe_catalog_axes_eval(const fe_catalog_axes *c, const double x[3], double t, double temp,
                         double *phi, double *radius);

#ifdef __cplusplus
}
#endif

#endif /* FOLDEST_CATALOG_H */
/* Catalog Declarations ends here */
