/* SPDX-License-Identifier: MIT */
/* Tangled from literate/sessions.org: do not edit; edit the .org and run make tangle. */
/* [[file:../literate/sessions.org::Session Calibration Includes][Session Calibration Includes]] */
#include <math.h>
#include <string.h>

#include "foldest/error.h"
#include "foldest/sessions.h"
/* Session Calibration Includes ends here */
/* [[file:../literate/sessions.org::Evaluate the session residuals][Evaluate the session residuals]] */
void fe_sessions_matrix(const double *s, double S[3][3])
{
    S[0][0] = s[0]; S[0][1] = S[1][0] = s[1]; S[0][2] = S[2][0] = s[2];
    S[1][1] = s[3]; S[1][2] = S[2][1] = s[4]; S[2][2] = s[5];
}

/* The residuals and their gradients: with d = m - o, h = S d, rho = |h|,
   d rho / d S_kl = (h_k d_l + h_l d_k) / rho (k != l; h_k d_k / rho on the
   diagonal) and d rho / d o = -S h / rho. */
int fe_sessions_model(const double *x, fe_lm_sink *sink, void *ctx)
{
    const fe_sessions *c = ctx;
    double S[3][3];
    fe_sessions_matrix(x, S);
    for (size_t b = 0; b < c->count; b++) {
        size_t blk = c->one_offset ? 0 : b;
        const double *o = x + 6 + 3 * blk;
        for (size_t i = 0; i < c->n[b]; i++) {
            const double *m = c->m[b] + 3 * i;
            double d[3] = {m[0] - o[0], m[1] - o[1], m[2] - o[2]}, h[3], rho, jg[6], jl[3];
            int rc;
            for (int k = 0; k < 3; k++)
                h[k] = S[k][0] * d[0] + S[k][1] * d[1] + S[k][2] * d[2];
            rho = sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
            if (!(rho > 0.0) || !isfinite(rho))
                return FE_ENONFINITE;           /* a reading at the offset */
            jg[0] = h[0] * d[0] / rho;
            jg[1] = (h[0] * d[1] + h[1] * d[0]) / rho;
            jg[2] = (h[0] * d[2] + h[2] * d[0]) / rho;
            jg[3] = h[1] * d[1] / rho;
            jg[4] = (h[1] * d[2] + h[2] * d[1]) / rho;
            jg[5] = h[2] * d[2] / rho;
            for (int k = 0; k < 3; k++)
                jl[k] = -(S[k][0] * h[0] + S[k][1] * h[1] + S[k][2] * h[2]) / rho;
            rc = fe_lm_emit(sink, rho - 1.0, 1.0, jg, blk, jl);
            if (rc != FE_OK)
                return rc;
        }
    }
    return FE_OK;
}
/* Evaluate the session residuals ends here */
/* [[file:../literate/sessions.org::Start, measure and fit][Start, measure and fit]] */
size_t fe_sessions_params(const fe_sessions *c)
{
    return 6 + 3 * (c->one_offset ? 1 : c->count);
}

fe_lm_problem fe_sessions_problem(const fe_sessions *c)
{
    fe_lm_problem p = {6, 3, c->one_offset ? 1 : c->count, fe_sessions_model, (void *)c};
    return p;
}

/* Start: each offset at its session's centroid, S = I / mean radius. */
void fe_sessions_start(const fe_sessions *c, double *x)
{
    double r = 0.0;
    size_t total = 0, nblk = c->one_offset ? 1 : c->count;
    memset(x, 0, (6 + 3 * nblk) * sizeof *x);
    for (size_t b = 0; b < c->count; b++) {
        double *o = x + 6 + 3 * (c->one_offset ? 0 : b), cen[3] = {0, 0, 0};
        for (size_t i = 0; i < c->n[b]; i++)
            for (int k = 0; k < 3; k++)
                cen[k] += c->m[b][3 * i + k] / (double)c->n[b];
        for (size_t i = 0; i < c->n[b]; i++) {
            const double *m = c->m[b] + 3 * i;
            r += sqrt((m[0] - cen[0]) * (m[0] - cen[0]) + (m[1] - cen[1]) * (m[1] - cen[1])
                      + (m[2] - cen[2]) * (m[2] - cen[2]));
        }
        total += c->n[b];
        for (int k = 0; k < 3; k++)
            o[k] += cen[k] / (double)(c->one_offset ? c->count : 1);
    }
    x[0] = x[3] = x[5] = (double)total / r;
}

double fe_sessions_rms(const fe_sessions *c, const double *x, size_t b)
{
    double S[3][3], q = 0.0;
    const double *o = x + 6 + 3 * (c->one_offset ? 0 : b);
    fe_sessions_matrix(x, S);
    for (size_t i = 0; i < c->n[b]; i++) {
        const double *m = c->m[b] + 3 * i;
        double d[3] = {m[0] - o[0], m[1] - o[1], m[2] - o[2]}, h2 = 0.0;
        for (int k = 0; k < 3; k++) {
            double h = S[k][0] * d[0] + S[k][1] * d[1] + S[k][2] * d[2];
            h2 += h * h;
        }
        q += (sqrt(h2) - 1.0) * (sqrt(h2) - 1.0);
    }
    return sqrt(q / (double)c->n[b]);
}

size_t fe_sessions_work(const fe_sessions *c)
{
    fe_lm_problem p = fe_sessions_problem(c);
    return fe_lm_work(&p, FE_LM_SCHUR);
}

int fe_sessions_fit(const fe_sessions *c, double *x, double *work,
                    fe_lm_result *result)
{
    fe_lm_problem p;
    if (c == NULL || x == NULL || work == NULL || c->count == 0
        || c->count > FE_SESSIONS_MAX)
        return FE_EINVAL;
    p = fe_sessions_problem(c);
    fe_sessions_start(c, x);
    return fe_lm_solve(&p, FE_LM_SCHUR, NULL, x, work, NULL, NULL, result);
}
/* Start, measure and fit ends here */
