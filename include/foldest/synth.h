/* SPDX-License-Identifier: MIT */
/* Tangled from literate/synth.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/synth.org::Synthetic Experiment Declarations][Synthetic Experiment Declarations]] */
#ifndef FOLDEST_SYNTH_H
#define FOLDEST_SYNTH_H

#include <stddef.h>
#include <stdint.h>

#include "foldest/catalog.h"
#include "foldest/random.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct fe_synth_spec {
    const char *effect;         /* a built-in term's name, or "none" */
    uint64_t seed;
    size_t rows;                /* 200000 */
    double noise_sd;            /* sigma: 1 (order > 0: in 0.1 % of the
                                   channel's span) */
    double noise_rho;           /* lag-one correlation: 0.5 */
    double effect_size;         /* max |effect| / sigma: 0.3 */
    size_t order;               /* 0: the effect is added to the channel;
                                   2: to the cart's acceleration, 1: to the
                                   stand's dT/dt, integrated into the motion
                                   (output error; the channel is then the
                                   position or the temperature) */
    double parting;             /* order > 0: the static response to the
                                   largest forcing, in noise sds: 3 */
} fe_synth_spec;

/* fe_synth_default_spec: the concealed case for `effect` and `seed`. */
fe_synth_spec fe_synth_default_spec(const char *effect, uint64_t seed);

/* A generator; all state is here, the caller owns it. */
typedef struct fe_synth {
    fe_synth_spec spec;
    int thermal;                /* 0 mechanical rig, 1 thermal rig */
    long effect;                /* index in the built-in table; -1: none */
    double coefficient;         /* the truth */
    double sigma;               /* the noise's sd in channel units: noise_sd,
                                   times 1e-3 of the channel's span when
                                   order > 0 */
    unsigned roles;             /* roles the rig's columns have */
    fe_catalog_scale scale;     /* what discovery's first pass finds */
    double dt;
    double phase[3];            /* the input's phases, from the seed */
    /* running state */
    fe_rng physics, noise;
    size_t row;
    double x, v, temp, load, e;
    double xr, vr, tempr;       /* the real system's state (order > 0) */
    fe_sample prev, cur, next;
} fe_synth;

/* fe_synth_init: a generator for `spec`.  FE_EINVAL for an unknown effect
   or a rig that has no column the term needs (with order 2 the mechanical
   rig, with order 1 the thermal one; gain and delay are not forcings);
   FE_ETOOFEW for fewer than 100 rows. */
int fe_synth_init(fe_synth *g, const fe_synth_spec *spec);

/* fe_synth_next: the next row, with `real` = `sim` + effect + noise (order
   0), or the real system's position or temperature + noise (order > 0,
   `sim` then the simulated one).  FE_END after spec.rows rows. */
int fe_synth_next(fe_synth *g, fe_sample *s);

/* fe_synth_rewind: start again; the same rows follow. */
void fe_synth_rewind(fe_synth *g);

/* fe_synth_base: the base groups for this case (bias and gain, less the
   hidden term), as indices into catalog `c`; returns how many. */
size_t fe_synth_base(const fe_synth *g, const fe_catalog *c, size_t *base);

/* fe_synth_effects: the effect names with a rig, in catalog order, then
   "none" twice (one null case per rig: "none" and "none_thermal"). */
const char *const *fe_synth_effects(size_t *count);

#ifdef __cplusplus
}
#endif

#endif /* FOLDEST_SYNTH_H */
/* Synthetic Experiment Declarations ends here */
