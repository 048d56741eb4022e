/* SPDX-License-Identifier: MIT */
/* Tangled from literate/catalog.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/catalog.org::Catalog Declarations][Catalog Declarations]] */
#ifndef FOLDEST_CATALOG_H
#define FOLDEST_CATALOG_H

#include <stddef.h>
#include <stdint.h>

#include "foldest/discover.h"

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

/* A named term. */
typedef struct fe_term {
    const char *name;
    const char *description;    /* one line of physics */
    fe_term_fn *eval;
    void *user;
    unsigned needs;             /* fe_role bits it needs */
} fe_term;

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

/* fe_catalog_find: the index of the term called `name`, or -1. */
long fe_catalog_find(const fe_catalog *c, const char *name);

/* fe_catalog_eval: phi[j] = term j at sample s, j < c->count.
   FE_ENONFINITE if a term is not finite (phi is then incomplete). */
int fe_catalog_eval(const fe_catalog *c, const fe_sample *s, double *phi);

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
