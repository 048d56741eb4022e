/* SPDX-License-Identifier: MIT */
/* Tangled from literate/sessions.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/sessions.org::Session Calibration Declarations][Session Calibration Declarations]] */
#ifndef FOLDEST_SESSIONS_H
#define FOLDEST_SESSIONS_H

#include <stddef.h>

#include "foldest/lm.h"

#ifdef __cplusplus
extern "C" {
#endif

enum { FE_SESSIONS_MAX = 64 };

/* Sessions of raw readings: session s has n[s] readings m[s][3i..3i+2].
   The readings stay the caller's. */
typedef struct fe_sessions {
    size_t count;
    const double *m[FE_SESSIONS_MAX];
    size_t n[FE_SESSIONS_MAX];
    int one_offset;             /* all sessions share offset block 0 */
} fe_sessions;

/* Parameters x: S as s00 s01 s02 s11 s12 s22, then 3 per offset block
   (fe_sessions_params(c) in all). */
size_t fe_sessions_params(const fe_sessions *c);

/* fe_sessions_matrix: the symmetric S from parameters x[0..5]. */
void fe_sessions_matrix(const double *x, double S[3][3]);

/* fe_sessions_problem: the problem for fe_lm_solve (6 globals, blocks of
   3); `c` must outlive it. */
fe_lm_problem fe_sessions_problem(const fe_sessions *c);

/* fe_sessions_model: the fe_lm model (ctx is the fe_sessions).
   FE_ENONFINITE when a reading sits at its offset. */
int fe_sessions_model(const double *x, fe_lm_sink *sink, void *ctx);

/* fe_sessions_start: a starting point: offsets at the session centroids,
   S = I / (mean distance to them). */
void fe_sessions_start(const fe_sessions *c, double *x);

/* fe_sessions_rms: the RMS of f over session b at parameters x. */
double fe_sessions_rms(const fe_sessions *c, const double *x, size_t b);

/* fe_sessions_work: doubles of workspace fe_sessions_fit needs. */
size_t fe_sessions_work(const fe_sessions *c);

/* fe_sessions_fit: start, then Levenberg-Marquardt with the Schur
   complement; x (fe_sessions_params(c) doubles) receives the solution.
   Errors as fe_lm_solve; FE_EINVAL for no sessions or too many. */
int fe_sessions_fit(const fe_sessions *c, double *x, double *work,
                    fe_lm_result *result);

#ifdef __cplusplus
}
#endif

#endif /* FOLDEST_SESSIONS_H */
/* Session Calibration Declarations ends here */
