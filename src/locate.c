/* SPDX-License-Identifier: MIT */
/* Tangled from literate/locate.org: do not edit; edit the .org and run make tangle. */
/* [[file:../literate/locate.org::Locate Includes][Locate Includes]] */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "foldest/error.h"
#include "foldest/locate.h"
#include "foldest/special.h"
/* Locate Includes ends here */
/* [[file:../literate/locate.org::Fold a report into its block][Fold a report into its block]] */
int fe_innovations_init(fe_innovations *a, size_t blocks, uint64_t total,
                        uint64_t row0)
{
    if (a == NULL)
        return FE_EINVAL;
    if (blocks < 2 || blocks > FE_DISCOVER_MAX_BLOCKS)
        return FE_ESIZE;
    if (total < 2 * (uint64_t)blocks)
        return FE_ETOOFEW;
    if (row0 >= total)
        return FE_ESIZE;
    memset(a, 0, sizeof *a);
    a->blocks = blocks;
    a->total = total;
    a->row0 = row0;
    a->first_linked = 1;
    return FE_OK;
}

int fe_innovations_add(fe_innovations *a, double t, const fe_kalman_report *r)
{
    fe_innovation_block *bk;
    size_t dim = 0;
    double sq = 0.0, acf = 0.0, pairs = 0.0;
    if (a == NULL || r == NULL || r->b == 0)
        return FE_EINVAL;
    if (!isfinite(t) || !isfinite(r->nis))
        return FE_ENONFINITE;
    if (r->nis < 0.0)
        return FE_EINVAL;
    if (a->row0 + a->n >= a->total)
        return FE_ESIZE;
    if (r->whitened != NULL) {
        dim = r->b < FE_KALMAN_MONITOR_DIM ? r->b : FE_KALMAN_MONITOR_DIM;
        for (size_t i = 0; i < dim; i++) {
            if (!isfinite(r->whitened[i]))
                return FE_ENONFINITE;
            sq += r->whitened[i] * r->whitened[i];
        }
        if (a->have_prev) {
            size_t d = dim < a->prev_dim ? dim : a->prev_dim;
            for (size_t i = 0; i < d; i++)
                acf += r->whitened[i] * a->prev[i];
            pairs = (double)d;
        }
    }
    bk = &a->block[(size_t)((a->row0 + a->n) * a->blocks / a->total)];
    /* Finite values can have squares or sums that are not: refuse them,
       with the accumulation unchanged. */
    if (!isfinite(bk->nis + r->nis) || !isfinite(bk->sq + sq) || !isfinite(bk->acf + acf))
        return FE_ENONFINITE;
    if (bk->n == 0) {
        bk->t0 = t;
        bk->pair = a->recording;
    }
    bk->t1 = t;
    bk->pair1 = a->recording;
    bk->n += 1.0;
    bk->dof += (double)r->b;
    bk->nis += r->nis;
    bk->sq += sq;
    bk->sq_terms += (double)dim;
    bk->acf += acf;
    bk->acf_terms += pairs;
    if (dim > 0)
        memcpy(a->prev, r->whitened, dim * sizeof *a->prev);
    if (a->n == 0) {
        if (dim > 0)
            memcpy(a->first, r->whitened, dim * sizeof *a->first);
        a->first_dim = dim;
    }
    a->prev_dim = dim;
    a->have_prev = dim > 0;
    a->n++;
    return FE_OK;
}

void fe_innovations_break(fe_innovations *a)
{
    if (a == NULL)
        return;
    a->have_prev = 0;
    if (a->n > 0)
        a->recording++;
    else
        a->first_linked = 0;
}
/* Fold a report into its block ends here */
/* [[file:../literate/locate.org::Merge consecutive parts][Merge consecutive parts]] */
int fe_innovations_merge(fe_innovations *a, const fe_innovations *b)
{
    int shift;
    if (a == NULL || b == NULL)
        return FE_EINVAL;
    if (a->blocks != b->blocks || a->total != b->total || b->row0 != a->row0 + a->n)
        return FE_EMISMATCH;
    if (b->n == 0)
        return FE_OK;
    shift = a->n == 0 ? a->recording : a->recording + (b->first_linked ? 0 : 1);
    if (a->n > 0 && a->have_prev && b->first_linked && b->first_dim > 0) {
        size_t d = a->prev_dim < b->first_dim ? a->prev_dim : b->first_dim;
        fe_innovation_block *bk = &a->block[(size_t)(b->row0 * a->blocks / a->total)];
        for (size_t i = 0; i < d; i++)
            bk->acf += a->prev[i] * b->first[i];
        bk->acf_terms += (double)d;
    }
    for (size_t k = 0; k < a->blocks; k++) {
        fe_innovation_block *x = &a->block[k];
        const fe_innovation_block *y = &b->block[k];
        if (y->n == 0)
            continue;
        if (x->n == 0) {
            x->t0 = y->t0;
            x->pair = y->pair + shift;
        }
        x->t1 = y->t1;
        x->pair1 = y->pair1 + shift;
        x->n += y->n;
        x->dof += y->dof;
        x->nis += y->nis;
        x->acf += y->acf;
        x->acf_terms += y->acf_terms;
        x->sq += y->sq;
        x->sq_terms += y->sq_terms;
    }
    if (a->n == 0) {
        memcpy(a->first, b->first, sizeof a->first);
        a->first_dim = b->first_dim;
        a->first_linked = b->first_linked;
    }
    memcpy(a->prev, b->prev, sizeof a->prev);
    a->prev_dim = b->prev_dim;
    a->have_prev = b->have_prev;
    a->recording = shift + b->recording;
    a->n += b->n;
    return FE_OK;
}
/* Merge consecutive parts ends here */
/* [[file:../literate/locate.org::Test one block][Test one block]] */
/* The lag-one autocorrelation, mean product over mean square, divided in
   the order that neither overflows nor underflows for squares that are
   tiny but not zero: 1 with *rho, or 0 when there is none to report (no
   pairs, no energy, or a ratio that is not finite). */
static int fe__lag1(double acf, double acf_terms, double sq, double sq_terms, double *rho)
{
    double v;
    if (!(acf_terms > 0 && sq > 0 && sq_terms > 0))
        return 0;
    v = (acf / sq) * (sq_terms / acf_terms);
    if (!isfinite(v))
        return 0;
    *rho = v;
    return 1;
}

static void fe__block_tests(const fe_innovation_block *b, double *z_nis, double *p_nis,
                            double *z_acf, double *p_acf)
{
    double p = b->dof > 0 ? fe_chi2_upper(b->nis, b->dof) : 1.0, rho;
    if (!(p > DBL_MIN))
        p = DBL_MIN;
    if (p > 1.0)
        p = 1.0;
    *p_nis = p;
    /* p = 1 (a block of zero NIS) would make z infinite: at most 1 - eps. */
    *z_nis = -fe_normal_quantile(p < 1.0 - DBL_EPSILON ? p : 1.0 - DBL_EPSILON);
    *z_acf = 0.0;
    *p_acf = 1.0;
    if (fe__lag1(b->acf, b->acf_terms, b->sq, b->sq_terms, &rho)) {
        *z_acf = rho * sqrt(b->acf_terms);
        *p_acf = erfc(fabs(*z_acf) / sqrt(2.0));
    }
}
/* Test one block ends here */
/* [[file:../literate/locate.org::Locate the windows][Locate the windows]] */
/* Pool a block's sum (over `count` terms) into a running mean of `*total`
   terms: the weights add to one, so the mean stays within the range of
   the blocks' means. */
static void fe__pool(double *mean, double *total, double sum, double count)
{
    double all = *total + count;
    if (!(count > 0))
        return;
    *mean = *mean * (*total / all) + sum / all;
    *total = all;
}

int fe_innovations_locate(const fe_innovations *a, double alpha, fe_located *out,
                          size_t max, size_t *nout)
{
    size_t count = 0;
    int open = 0;                       /* the last block extended a window */
    fe_located cur;
    /* The window's pooled figures as running means (per degree of freedom,
       per pair, per term), which cannot overflow as sums of blocks can. */
    double dof = 0, nis = 0, acf = 0, acf_terms = 0, sq = 0, sq_terms = 0;
    if (a == NULL || nout == NULL || (max > 0 && out == NULL) || !(alpha > 0.0)
        || !(alpha < 1.0))
        return FE_EINVAL;
    memset(&cur, 0, sizeof cur);
    for (size_t k = 0; k <= a->blocks; k++) {
        const fe_innovation_block *b = k < a->blocks ? &a->block[k] : NULL;
        double zn = 0, pn = 1, za = 0, pa = 1;
        int hit = 0;
        if (b != NULL && b->n > 0) {
            fe__block_tests(b, &zn, &pn, &za, &pa);
            hit = pn < alpha / (2.0 * (double)a->blocks)
                  || pa < alpha / (2.0 * (double)a->blocks);
        }
        if (open && (!hit || b->pair != cur.pair1)) {
            /* close the window */
            cur.mean_nis = nis;
            if (!fe__lag1(acf, 1.0, sq, 1.0, &cur.lag1))
                cur.lag1 = 0.0;
            if (count < max)
                out[count] = cur;
            count++;
            open = 0;
        }
        if (!hit)
            continue;
        if (!open) {
            memset(&cur, 0, sizeof cur);
            cur.is_time = 1;
            cur.t0 = b->t0;
            cur.pair = b->pair;
            cur.z = zn;
            cur.t = za;
            cur.p_value = 2.0;
            dof = nis = acf = acf_terms = sq = sq_terms = 0;
            open = 1;
        }
        cur.t1 = b->t1;
        cur.pair1 = b->pair1;
        cur.n += b->n;
        if (zn > cur.z)
            cur.z = zn;
        if (fabs(za) > fabs(cur.t))
            cur.t = za;
        if (pn < cur.p_value || pa < cur.p_value) {
            cur.test = pn <= pa ? "nis" : "innovation_acf";
            cur.p_value = pn <= pa ? pn : pa;
        }
        fe__pool(&nis, &dof, b->nis, b->dof);
        fe__pool(&acf, &acf_terms, b->acf, b->acf_terms);
        fe__pool(&sq, &sq_terms, b->sq, b->sq_terms);
    }
    *nout = count;
    return FE_OK;
}
/* Locate the windows ends here */
/* [[file:../literate/locate.org::Write a located window as JSON][Write a located window as JSON]] */
static int fe__json_num(char *buf, size_t len, size_t *at, const char *key, double v)
{
    int n = isfinite(v) ? snprintf(buf + *at, len - *at, ", \"%s\": %.10g", key, v)
                        : snprintf(buf + *at, len - *at, ", \"%s\": null", key);
    if (n < 0 || (size_t)n >= len - *at)
        return FE_ESIZE;
    *at += (size_t)n;
    return FE_OK;
}

int fe_located_json(const fe_located *l, char *buf, size_t len)
{
    size_t at = 0;
    int n, rc = FE_OK;
    if (l == NULL || buf == NULL || len == 0)
        return FE_EINVAL;
    buf[0] = '\0';
    n = snprintf(buf, len, "{\"kind\": \"time\", \"recording\": %d, \"end_recording\": %d",
                 l->pair + 1, l->pair1 + 1);
    if (n < 0 || (size_t)n >= len)
        return FE_ESIZE;
    at = (size_t)n;
    rc = fe__json_num(buf, len, &at, "start", l->t0);
    if (rc == FE_OK)
        rc = fe__json_num(buf, len, &at, "end", l->t1);
    if (rc == FE_OK)
        rc = fe__json_num(buf, len, &at, "rows", l->n);
    if (rc == FE_OK)
        rc = fe__json_num(buf, len, &at, "statistic",
                          fabs(l->z) > fabs(l->t) ? l->z : l->t);
    if (rc == FE_OK) {
        n = snprintf(buf + at, len - at, ", \"test\": \"%s\"",
                     l->test != NULL ? l->test : "");
        rc = n < 0 || (size_t)n >= len - at ? FE_ESIZE : FE_OK;
        if (rc == FE_OK)
            at += (size_t)n;
    }
    if (rc == FE_OK)
        rc = fe__json_num(buf, len, &at, "p_value", l->p_value);
    if (rc == FE_OK)
        rc = fe__json_num(buf, len, &at, "nis_statistic", l->z);
    if (rc == FE_OK)
        rc = fe__json_num(buf, len, &at, "acf_statistic", l->t);
    if (rc == FE_OK)
        rc = fe__json_num(buf, len, &at, "mean_nis_per_dof", l->mean_nis);
    if (rc == FE_OK)
        rc = fe__json_num(buf, len, &at, "lag1", l->lag1);
    if (rc == FE_OK) {
        n = snprintf(buf + at, len - at, "}");
        rc = n < 0 || (size_t)n >= len - at ? FE_ESIZE : FE_OK;
    }
    return rc;
}
/* Write a located window as JSON ends here */
