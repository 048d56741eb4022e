/* SPDX-License-Identifier: MIT */
/* Tangled from literate/locate.org: do not edit; edit the .org and run make tangle. */
/* [[file:../literate/locate.org::Locate Includes][Locate Includes]] */
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "foldest/csv.h"
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
/* The span of a cell (time and recording of its first and last row)
   when the cell of a later part, with times y0 .. y1 in its recordings
   q0 .. q1 numbered from 0 in that part, joins it; x_empty when the cell
   had no rows.  The later part's recordings are numbered on by `shift`. */
static void fe__span_join(double *t0, int *pair, double *t1, int *pair1, int x_empty,
                          double y0, int q0, double y1, int q1, int shift)
{
    if (x_empty) {
        *t0 = y0;
        *pair = q0 + shift;
    }
    *t1 = y1;
    *pair1 = q1 + shift;
}

/* How far the recordings of a later part are numbered on when it joins a
   part of n rows whose current recording is `recording`: the same
   recording when the later part's first row follows on (first_linked). */
static int fe__recording_shift(uint64_t n, int recording, int first_linked)
{
    return n == 0 ? recording : recording + (first_linked ? 0 : 1);
}

int fe_innovations_merge(fe_innovations *a, const fe_innovations *b)
{
    int shift;
    if (a == NULL || b == NULL)
        return FE_EINVAL;
    if (a->blocks != b->blocks || a->total != b->total || b->row0 != a->row0 + a->n)
        return FE_EMISMATCH;
    if (b->n == 0)
        return FE_OK;
    shift = fe__recording_shift(a->n, a->recording, b->first_linked);
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
        fe__span_join(&x->t0, &x->pair, &x->t1, &x->pair1, x->n == 0, y->t0, y->pair, y->t1,
                      y->pair1, shift);
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
            cur.region = FE_REGION_TIME;
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
/* Append printf-formatted text at *at; FE_ESIZE when it does not fit. */
static int fe__append(char *buf, size_t len, size_t *at, const char *fmt, ...)
{
    va_list ap;
    int n;
    if (*at >= len)
        return FE_ESIZE;
    va_start(ap, fmt);
    n = vsnprintf(buf + *at, len - *at, fmt, ap);
    va_end(ap);
    if (n < 0 || (size_t)n >= len - *at)
        return FE_ESIZE;
    *at += (size_t)n;
    return FE_OK;
}

static int fe__json_num(char *buf, size_t len, size_t *at, const char *key, double v)
{
    char text[FE_CSV_DOUBLE_TEXT];
    if (fe_csv_format_double(v, text, sizeof text) != FE_OK)
        return fe__append(buf, len, at, ", \"%s\": null", key);
    return fe__append(buf, len, at, ", \"%s\": %s", key, text);
}

int fe_located_json(const fe_located *l, char *buf, size_t len)
{
    size_t at = 0;
    int rc, residual;
    char words[96];
    if (l == NULL || buf == NULL || len == 0)
        return FE_EINVAL;
    buf[0] = '\0';
    residual = l->test != NULL && strncmp(l->test, "residual", 8) == 0;
    if (l->region == FE_REGION_TIME) {
        rc = fe__append(buf, len, &at, "{\"kind\": \"time\", \"recording\": %d, "
                        "\"end_recording\": %d", l->pair + 1, l->pair1 + 1);
        if (rc == FE_OK)
            rc = fe__json_num(buf, len, &at, "start", l->t0);
        if (rc == FE_OK)
            rc = fe__json_num(buf, len, &at, "end", l->t1);
    } else {
        rc = fe_region_describe(l, words, sizeof words);
        if (rc == FE_OK)
            rc = fe__append(buf, len, &at, "{\"kind\": \"state\", \"variable\": \"%s\", "
                            "\"region\": \"%s\"", fe_region_variable(l->region), words);
    }
    if (rc == FE_OK)
        rc = fe__json_num(buf, len, &at, "rows", l->n);
    if (rc == FE_OK)
        rc = fe__json_num(buf, len, &at, "statistic", fabs(l->z) > fabs(l->t) ? l->z : l->t);
    if (rc == FE_OK)
        rc = fe__append(buf, len, &at, ", \"test\": \"%s\"", l->test != NULL ? l->test : "");
    if (rc == FE_OK)
        rc = fe__json_num(buf, len, &at, "p_value", l->p_value);
    if (residual) {
        if (rc == FE_OK)
            rc = fe__json_num(buf, len, &at, "mean_residual_before", l->mean_before);
        if (rc == FE_OK)
            rc = fe__json_num(buf, len, &at, "mean_residual_after", l->mean_after);
        if (rc == FE_OK)
            rc = fe__json_num(buf, len, &at, "ms_ratio_before", l->ms_ratio_before);
        if (rc == FE_OK)
            rc = fe__json_num(buf, len, &at, "ms_ratio_after", l->ms_ratio_after);
    } else {
        if (rc == FE_OK)
            rc = fe__json_num(buf, len, &at, "nis_statistic", l->z);
        if (rc == FE_OK)
            rc = fe__json_num(buf, len, &at, "acf_statistic", l->t);
        if (rc == FE_OK)
            rc = fe__json_num(buf, len, &at, "mean_nis_per_dof", l->mean_nis);
        if (rc == FE_OK)
            rc = fe__json_num(buf, len, &at, "lag1", l->lag1);
    }
    if (rc == FE_OK)
        rc = fe__append(buf, len, &at, "}");
    return rc;
}
/* Write a located window as JSON ends here */
/* [[file:../literate/locate.org::Name a region][Name a region]] */
const char *fe_region_variable(fe_region r)
{
    switch (r) {
    case FE_REGION_TIME: return "time";
    case FE_REGION_VELOCITY_NEGATIVE:
    case FE_REGION_VELOCITY_POSITIVE:
    case FE_REGION_VELOCITY_ZERO: return "velocity";
    case FE_REGION_SPEED: return "speed";
    case FE_REGION_POSITION_NEGATIVE:
    case FE_REGION_POSITION_POSITIVE: return "position";
    case FE_REGION_TEMPERATURE: return "temperature";
    }
    return "";
}

int fe_region_describe(const fe_located *l, char *buf, size_t len)
{
    int n;
    if (l == NULL || buf == NULL || len == 0)
        return FE_EINVAL;
    switch (l->region) {
    case FE_REGION_TIME: n = snprintf(buf, len, "%.4g to %.4g", l->t0, l->t1); break;
    case FE_REGION_VELOCITY_NEGATIVE: n = snprintf(buf, len, "v < 0"); break;
    case FE_REGION_VELOCITY_POSITIVE: n = snprintf(buf, len, "v > 0"); break;
    case FE_REGION_VELOCITY_ZERO: n = snprintf(buf, len, "v = 0"); break;
    case FE_REGION_SPEED: n = snprintf(buf, len, "|v| %.3g to %.3g", l->lo, l->hi); break;
    case FE_REGION_POSITION_NEGATIVE: n = snprintf(buf, len, "x < 0"); break;
    case FE_REGION_POSITION_POSITIVE: n = snprintf(buf, len, "x > 0"); break;
    case FE_REGION_TEMPERATURE: n = snprintf(buf, len, "%.4g to %.4g", l->lo, l->hi); break;
    default: n = snprintf(buf, len, "?"); break;
    }
    return n < 0 || (size_t)n >= len ? FE_ESIZE : FE_OK;
}
/* Name a region ends here */
/* [[file:../literate/locate.org::Start a residual map][Start a residual map]] */
/* The roles of the map's state variables, in the order of its ranges and
   bins: position, velocity, temperature. */
static const unsigned fe__state_role[3] = {FE_ROLE_POSITION, FE_ROLE_VELOCITY,
                                           FE_ROLE_TEMPERATURE};

static void fe__add_region(fe_residual_map *m, fe_region r, double lo, double hi)
{
    m->region[m->nregions] = r;
    m->region_lo[m->nregions] = lo;
    m->region_hi[m->nregions] = hi;
    m->nregions++;
}

int fe_residual_map_init(fe_residual_map *m, size_t blocks, uint64_t fit, uint64_t row0,
                         unsigned roles, const double lo[3], const double hi[3])
{
    if (m == NULL || (roles != 0 && (lo == NULL || hi == NULL)))
        return FE_EINVAL;
    if (blocks < 2 || blocks > FE_DISCOVER_MAX_BLOCKS)
        return FE_ESIZE;
    if (fit < 2 * (uint64_t)blocks)
        return FE_ETOOFEW;
    for (int v = 0; v < 3; v++)
        if (roles & fe__state_role[v]) {
            if (!isfinite(lo[v]) || !isfinite(hi[v]))
                return FE_ENONFINITE;
            if (lo[v] > hi[v])
                return FE_EINVAL;
        }
    memset(m, 0, sizeof *m);
    m->blocks = blocks;
    m->fit = fit;
    m->row0 = row0;
    m->first_linked = 1;
    m->roles = roles & (FE_ROLE_POSITION | FE_ROLE_VELOCITY | FE_ROLE_TEMPERATURE);
    for (int v = 0; v < 3; v++)
        if (m->roles & fe__state_role[v]) {
            m->lo[v] = lo[v];
            m->hi[v] = hi[v];
        }
    m->vmax = fabs(m->lo[1]) > fabs(m->hi[1]) ? fabs(m->lo[1]) : fabs(m->hi[1]);
    if (m->roles & FE_ROLE_VELOCITY) {
        fe__add_region(m, FE_REGION_VELOCITY_NEGATIVE, 0, 0);
        fe__add_region(m, FE_REGION_VELOCITY_POSITIVE, 0, 0);
        fe__add_region(m, FE_REGION_VELOCITY_ZERO, 0, 0);
        for (int b = 0; b < 4; b++)
            fe__add_region(m, FE_REGION_SPEED, m->vmax * b / 4.0, m->vmax * (b + 1) / 4.0);
    }
    if (m->roles & FE_ROLE_POSITION) {
        fe__add_region(m, FE_REGION_POSITION_NEGATIVE, 0, 0);
        fe__add_region(m, FE_REGION_POSITION_POSITIVE, 0, 0);
    }
    if (m->roles & FE_ROLE_TEMPERATURE)
        for (int b = 0; b < 4; b++)
            fe__add_region(m, FE_REGION_TEMPERATURE, m->lo[2] + (m->hi[2] - m->lo[2]) * b / 4.0,
                           m->lo[2] + (m->hi[2] - m->lo[2]) * (b + 1) / 4.0);
    return FE_OK;
}
/* Start a residual map ends here */
/* [[file:../literate/locate.org::Fold a row into the residual map][Fold a row into the residual map]] */
void fe_residual_cell_add(fe_residual_cell *c, double t, int pair, double before, double after)
{
    if (c == NULL)
        return;
    if (c->n == 0) {
        c->t0 = t;
        c->pair = pair;
    }
    c->t1 = t;
    c->pair1 = pair;
    c->n += 1;
    c->sum_at += t;
    c->sum0 += before;
    c->sq0 += before * before;
    c->sum1 += after;
    c->sq1 += after * after;
}

/* The band (0 .. bands - 1) of u in [lo, hi]; a value outside the range
   joins the band at its end (clamped before the conversion to int, which
   a value far outside would overflow). */
static int fe__band(double u, double lo, double hi, int bands)
{
    double w = hi - lo, q = w > 0 ? (u - lo) / w * bands : 0.0;
    return !(q > 0.0) ? 0 : q >= bands ? bands - 1 : (int)q;
}

static int fe__in_region(const fe_residual_map *m, size_t g, const fe_sample *s)
{
    switch (m->region[g]) {
    case FE_REGION_VELOCITY_NEGATIVE: return s->velocity < 0;
    case FE_REGION_VELOCITY_POSITIVE: return s->velocity > 0;
    case FE_REGION_VELOCITY_ZERO: return s->velocity == 0;
    case FE_REGION_SPEED:
        return s->velocity != 0
               && fe__band(fabs(s->velocity), 0.0, m->vmax, 4)
                      == fe__band(0.5 * (m->region_lo[g] + m->region_hi[g]), 0.0, m->vmax, 4);
    case FE_REGION_POSITION_NEGATIVE: return s->position < 0;
    case FE_REGION_POSITION_POSITIVE: return s->position > 0;
    case FE_REGION_TEMPERATURE:
        return fe__band(s->temperature, m->lo[2], m->hi[2], 4)
               == fe__band(0.5 * (m->region_lo[g] + m->region_hi[g]), m->lo[2], m->hi[2], 4);
    default: return 0;
    }
}

int fe_residual_map_add(fe_residual_map *m, const fe_sample *s, double before, double after)
{
    uint64_t i;
    size_t k, ncell = 0;
    double x[3], at[1 + FE_RESIDUAL_REGIONS + 3];
    fe_residual_cell *cell[1 + FE_RESIDUAL_REGIONS + 3];   /* the cells the row joins */
    if (m == NULL || s == NULL)
        return FE_EINVAL;
    x[0] = s->position;
    x[1] = s->velocity;
    x[2] = s->temperature;
    if (!isfinite(s->t) || !isfinite(before) || !isfinite(after))
        return FE_ENONFINITE;
    for (int v = 0; v < 3; v++)
        if ((m->roles & fe__state_role[v]) && !isfinite(x[v]))
            return FE_ENONFINITE;
    i = m->row0 + m->n;
    k = i < m->fit ? (size_t)(i * m->blocks / m->fit) : m->blocks;
    cell[ncell] = &m->block[k];
    at[ncell++] = s->t;
    for (size_t g = 0; g < m->nregions && i < m->fit; g++)
        if (fe__in_region(m, g, s)) {
            cell[ncell] = &m->cell[g];
            at[ncell++] = s->t;
        }
    for (int v = 0; v < 3; v++)
        if (m->roles & fe__state_role[v]) {
            cell[ncell] = &m->bin[v][fe__band(x[v], m->lo[v], m->hi[v], FE_RESIDUAL_BINS)];
            at[ncell++] = x[v];
        }
    /* Finite values can have sums that are not: refuse the row, with the
       map unchanged. */
    for (size_t c = 0; c < ncell; c++)
        if (!isfinite(cell[c]->sum0 + before) || !isfinite(cell[c]->sq0 + before * before)
            || !isfinite(cell[c]->sum_at + at[c])
            || !isfinite(cell[c]->sum1 + after) || !isfinite(cell[c]->sq1 + after * after))
            return FE_ENONFINITE;
    for (size_t c = 0; c < ncell; c++)
        fe_residual_cell_add(cell[c], at[c], m->recording, before, after);
    m->n++;
    return FE_OK;
}

void fe_residual_map_break(fe_residual_map *m)
{
    if (m == NULL)
        return;
    if (m->n > 0)
        m->recording++;
    else
        m->first_linked = 0;
}
/* Fold a row into the residual map ends here */
/* [[file:../literate/locate.org::Merge residual maps][Merge residual maps]] */
static void fe__cell_merge(fe_residual_cell *x, const fe_residual_cell *y, int shift)
{
    if (y->n == 0)
        return;
    fe__span_join(&x->t0, &x->pair, &x->t1, &x->pair1, x->n == 0, y->t0, y->pair, y->t1,
                  y->pair1, shift);
    x->n += y->n;
    x->sum_at += y->sum_at;
    x->sum0 += y->sum0;
    x->sq0 += y->sq0;
    x->sum1 += y->sum1;
    x->sq1 += y->sq1;
}

int fe_residual_map_merge(fe_residual_map *a, const fe_residual_map *b)
{
    int shift;
    if (a == NULL || b == NULL)
        return FE_EINVAL;
    if (a->blocks != b->blocks || a->fit != b->fit || a->roles != b->roles
        || b->row0 != a->row0 + a->n)
        return FE_EMISMATCH;
    for (int v = 0; v < 3; v++)
        if (a->lo[v] != b->lo[v] || a->hi[v] != b->hi[v])   /* cut from other ranges */
            return FE_EMISMATCH;
    if (b->n == 0)
        return FE_OK;
    shift = fe__recording_shift(a->n, a->recording, b->first_linked);
    for (size_t k = 0; k <= a->blocks; k++)
        fe__cell_merge(&a->block[k], &b->block[k], shift);
    for (size_t g = 0; g < a->nregions; g++)
        fe__cell_merge(&a->cell[g], &b->cell[g], shift);
    for (int v = 0; v < 3; v++)
        for (size_t j = 0; j < FE_RESIDUAL_BINS; j++)
            fe__cell_merge(&a->bin[v][j], &b->bin[v][j], shift);
    if (a->n == 0)
        a->first_linked = b->first_linked;
    a->recording = shift + b->recording;
    a->n += b->n;
    return FE_OK;
}
/* Merge residual maps ends here */
/* [[file:../literate/locate.org::Locate in the residual map][Locate in the residual map]] */
static int fe__cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The two-sided Bonferroni bound for `places` places, two statistics
   each, at family-wise level alpha. */
static double fe__bound(double alpha, size_t places)
{
    return -fe_normal_quantile(alpha / (double)(2 * places));
}

/* Which of a place's two statistics located it, and its p-value before
   Bonferroni: the mean square's upper tail, or the mean's two tails. */
static void fe__located_test(fe_located *l)
{
    int ms = l->z > fabs(l->t);
    l->test = ms ? "residual_ms" : "residual_mean";
    l->p_value = ms ? 0.5 * erfc(l->z / sqrt(2.0)) : erfc(fabs(l->t) / sqrt(2.0));
}

/* Fill a located place from a cell: its statistics against the yardstick
   ms (mean square) and, for regions, the overall mean. */
static void fe__located_cell(fe_located *l, const fe_residual_cell *b, double ms, double z,
                             double t)
{
    l->t0 = b->t0;
    l->t1 = b->t1;
    l->pair = b->pair;
    l->pair1 = b->pair1;
    l->n = b->n;
    l->z = z;
    l->t = t;
    fe__located_test(l);
    l->mean_before = b->sum0 / b->n;
    l->mean_after = b->sum1 / b->n;
    l->ms_ratio_before = b->sq0 / b->n / ms;
    l->ms_ratio_after = b->sq1 / b->n / ms;
}

int fe_residual_map_locate(const fe_residual_map *m, double worth, double alpha,
                           fe_located *out, size_t max, size_t *nout)
{
    double ms[FE_DISCOVER_MAX_BLOCKS], sorted[FE_DISCOVER_MAX_BLOCKS], med, thr;
    double all_n = 0, all_sq = 0, all_sum = 0;
    size_t K, count = 0;
    int open = 0;
    fe_located cur;
    if (m == NULL || nout == NULL || (max > 0 && out == NULL) || !(alpha > 0.0)
        || !(alpha < 1.0) || !(worth > 0.0) || !(worth <= 1.0))
        return FE_EINVAL;
    K = m->blocks;
    thr = fe__bound(alpha, K + m->nregions);
    for (size_t k = 0; k < K; k++) {
        ms[k] = m->block[k].n > 0 ? m->block[k].sq0 / m->block[k].n : 0.0;
        all_n += m->block[k].n;
        all_sq += m->block[k].sq0;
        all_sum += m->block[k].sum0;
    }
    memcpy(sorted, ms, K * sizeof *sorted);
    qsort(sorted, K, sizeof *sorted, fe__cmp_double);
    med = K % 2 ? sorted[K / 2] : 0.5 * (sorted[K / 2 - 1] + sorted[K / 2]);
    memset(&cur, 0, sizeof cur);
    for (size_t k = 0; k <= K && med > 0; k++) {
        const fe_residual_cell *b = k < K ? &m->block[k] : NULL;
        double z = 0, t = 0;
        int hit = 0;
        if (b != NULL && b->n >= 2) {
            double neff = b->n * worth;
            z = (ms[k] / med - 1.0) / sqrt(2.0 / neff);
            t = (b->sum0 / b->n) / sqrt(med / neff);
            hit = z > thr || fabs(t) > thr;
        }
        if (open && (!hit || b->pair != cur.pair1)) {
            if (count < max)
                out[count] = cur;
            count++;
            open = 0;
        }
        if (!hit)
            continue;
        if (!open) {
            memset(&cur, 0, sizeof cur);
            cur.region = FE_REGION_TIME;
            fe__located_cell(&cur, b, med, z, t);
            open = 1;
            continue;
        }
        {
            double n = cur.n + b->n;
            cur.mean_before = (cur.mean_before * cur.n + b->sum0) / n;
            cur.mean_after = (cur.mean_after * cur.n + b->sum1) / n;
            cur.ms_ratio_before = (cur.ms_ratio_before * cur.n * med + b->sq0) / (n * med);
            cur.ms_ratio_after = (cur.ms_ratio_after * cur.n * med + b->sq1) / (n * med);
            cur.n = n;
            cur.t1 = b->t1;
            cur.pair1 = b->pair1;
            cur.z = z > cur.z ? z : cur.z;
            cur.t = fabs(t) > fabs(cur.t) ? t : cur.t;
            fe__located_test(&cur);
        }
    }
    for (size_t g = 0; g < m->nregions && all_n > 0 && all_sq > 0; g++) {
        const fe_residual_cell *b = &m->cell[g];
        double msall = all_sq / all_n, neff, t, z;
        if (b->n < 2 || b->n > all_n - 2)
            continue;
        neff = b->n * worth;
        t = (b->sum0 / b->n - all_sum / all_n) / sqrt(msall / neff);
        z = (b->sq0 / b->n / msall - 1.0) / sqrt(2.0 / neff);
        if (fabs(t) > thr || z > thr) {
            memset(&cur, 0, sizeof cur);
            cur.region = m->region[g];
            cur.lo = m->region_lo[g];
            cur.hi = m->region_hi[g];
            fe__located_cell(&cur, b, msall, z, t);
            if (count < max)
                out[count] = cur;
            count++;
        }
    }
    *nout = count;
    return FE_OK;
}
/* Locate in the residual map ends here */
/* [[file:../literate/locate.org::Test the residual after the terms][Test the residual after the terms]] */
double fe_residual_map_largest_after(const fe_residual_map *m, double worth)
{
    double all_n = 0, all_sq = 0, all_sum = 0, worst = 0.0;
    if (m == NULL)
        return 0.0;
    for (size_t k = 0; k < m->blocks; k++) {
        all_n += m->block[k].n;
        all_sq += m->block[k].sq1;
        all_sum += m->block[k].sum1;
    }
    if (!(all_n > 0 && all_sq > 0))
        return 0.0;
    for (size_t g = 0; g < m->blocks + m->nregions; g++) {
        const fe_residual_cell *b = g < m->blocks ? &m->block[g] : &m->cell[g - m->blocks];
        double ms = all_sq / all_n, neff, t, z;
        if (b->n < 2 || b->n > all_n - 2)
            continue;
        neff = b->n * worth;
        t = (b->sum1 / b->n - all_sum / all_n) / sqrt(ms / neff);
        z = (b->sq1 / b->n / ms - 1.0) / sqrt(2.0 / neff);
        worst = fabs(t) > worst ? fabs(t) : worst;
        worst = z > worst ? z : worst;
    }
    return worst;
}
/* Test the residual after the terms ends here */
/* [[file:../literate/locate.org::Decide the verdict][Decide the verdict]] */
/* When the residual left counts as diverging trajectories. */
#define FE_DIVERGE_LAG1 0.98
#define FE_DIVERGE_RATIO 10.0

int fe_discover_heldout_worse(const fe_discover_result *r)
{
    return r != NULL && r->final.heldout_n > 0
           && r->final.heldout_rms > r->baseline.heldout_rms;
}

fe_verdict fe_discover_verdict(const fe_discover_result *r, const fe_residual_map *m,
                               size_t nlocated, double alpha)
{
    if (r == NULL || m == NULL)
        return FE_VERDICT_NO_MISMATCH;
    if (r->final.lag1 >= FE_DIVERGE_LAG1 && r->final.rms >= FE_DIVERGE_RATIO * r->final.floor)
        return FE_VERDICT_DIVERGES;
    if (r->steps == 0)
        return nlocated > 0 ? FE_VERDICT_UNEXPLAINED : FE_VERDICT_NO_MISMATCH;
    if (r->noise.kind == FE_DISCOVER_NOISE_AR && r->noise.portmanteau_p < 0.001)
        return FE_VERDICT_NOT_WHITE;
    if (fe_residual_map_largest_after(m, fe_discover_row_worth(&r->noise, r->final.n))
        > fe__bound(alpha, m->blocks + m->nregions))
        return FE_VERDICT_OUT_OF_LINE;
    if (r->probes_tested > 0 && r->probe_p < alpha)
        return FE_VERDICT_STATE_LEFT;
    if (fe_discover_heldout_worse(r))
        return FE_VERDICT_HELDOUT_WORSE;
    return FE_VERDICT_EXPLAINED;
}

const char *fe_verdict_text(fe_verdict v)
{
    switch (v) {
    case FE_VERDICT_NO_MISMATCH: return "no significant mismatch";
    case FE_VERDICT_EXPLAINED: return "mismatch explained";
    default: return "mismatch not explained by the catalog";
    }
}

const char *fe_verdict_why(fe_verdict v)
{
    switch (v) {
    case FE_VERDICT_NOT_WHITE:
        return "terms were found, but the residual left is not white noise: "
               "something else is missing";
    case FE_VERDICT_OUT_OF_LINE:
        return "terms were found, but a time window or state region stays out of line "
               "after them";
    case FE_VERDICT_STATE_LEFT:
        return "terms were found, but a function of the state that none of them describes "
               "still explains part of the residual (a probe of the state stands out): the "
               "catalog lacks the physics, and the terms found stand in for it";
    case FE_VERDICT_HELDOUT_WORSE:
        return "terms were found, but the rows held out are predicted worse with them than "
               "without them: what they fit does not carry over to rows they were not chosen "
               "on; they may stand in for physics the catalog lacks, or be too weak for these "
               "rows to confirm (the held-out z says how far beyond the noise the loss is)";
    case FE_VERDICT_DIVERGES:
        return "the residual left stays correlated (lag one 0.98 or more) at ten times its "
               "high-frequency floor or more: the trajectories diverge, as they do when the "
               "missing physics acts on the motion; try foldest discover --order 2 (a force "
               "on a position or angle) or --order 1 (a heat rate on a temperature), from C "
               "fe_dynamics";
    default: return NULL;
    }
}
/* Decide the verdict ends here */
