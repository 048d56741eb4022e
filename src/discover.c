/* SPDX-License-Identifier: MIT */
/* Tangled from literate/discover.org: do not edit; edit the .org and run make tangle. */
/* [[file:../literate/discover.org::Discovery Includes][Discovery Includes]] */
#include <math.h>
#include <string.h>

#include <cblas.h>
#include <lapacke.h>

#include "foldest/discover.h"
#include "foldest/error.h"
#include "foldest/special.h"
#include "lanes.h"

/* Element (i, j) of a symmetric matrix stored in its upper triangle. */
static double fe__sym(const double *g, size_t dim, size_t i, size_t j)
{
    return i <= j ? g[i * dim + j] : g[j * dim + i];
}
/* Discovery Includes ends here */
/* [[file:../literate/discover.org::Fold the lagged products][Fold the lagged products]] */
/* S += x x^T for x the `count` rows at `rows` stacked (M each), S of
   side E M. */
static void fe__discover_edge_add(double *S, size_t dim, const double *rows, size_t count)
{
    size_t n = FE_DISCOVER_EDGE * dim, c = count * dim;
    for (size_t i = 0; i < c; i++)
        for (size_t j = 0; j < c; j++)
            S[i * n + j] += rows[i] * rows[j];
}

static size_t fe__discover_min(size_t x, size_t y)
{
    return x < y ? x : y;
}

/* No first rows are pending (the stored ones zeroed: the accumulation's
   bytes do not depend on the path that led to it). */
static void fe__discover_shead_clear(fe_discover_acc *a)
{
    memset(a->shead, 0, a->nshead * (a->m + 1) * sizeof *a->shead);
    a->nshead = 0;
    a->shead_pending = 0;
}

/* The open recording ends (a break, or the part is merged before one):
   its last rows into the edges, if it has at least E fitted rows (a
   shorter one keeps its transient rows: its start and end would overlap).
   Its first rows went in when the E-th arrived. */
static void fe__discover_edges_close(fe_discover_acc *a)
{
    size_t dim = a->m + 1;
    if (a->lags == 0)
        return;
    if (a->nhist >= FE_DISCOVER_EDGE)
        fe__discover_edge_add(a->edge_end, dim, a->hist, FE_DISCOVER_EDGE);
    fe__discover_shead_clear(a);
}

/* Forget the rows that the next row would pair with: a break. */
static void fe__discover_lags_cut(fe_discover_acc *a)
{
    memset(a->hist, 0, a->nhist * (a->m + 1) * sizeof *a->hist);
    a->nhist = 0;
}

/* Fold one row z (M values) of block k into the lagged products. */
static void fe__discover_lags_row(fe_discover_acc *a, const double *z, int fitted)
{
    size_t dim = a->m + 1, P = a->lags;
    if (P == 0 || !fitted)
        return;                 /* held-out rows (the last) pair with none */
    for (size_t l = 1; l <= a->nhist; l++) {
        const double *p = a->hist + (l - 1) * dim;
        double *zl = a->zlag + (l - 1) * dim * dim;
        for (size_t i = 0; i < dim; i++) {
            double zi = z[i], *row = zl + i * dim;
            for (size_t j = 0; j < dim; j++)
                row[j] += zi * p[j];
        }
    }
    memmove(a->hist + dim, a->hist, (P - 1) * dim * sizeof *a->hist);
    memcpy(a->hist, z, dim * sizeof *z);
    if (a->nhist < P)
        a->nhist++;
    memset(a->hist + a->nhist * dim, 0, (P - a->nhist) * dim * sizeof *a->hist);
    if (a->head_open && a->nhead < P)
        memcpy(a->head + a->nhead++ * dim, z, dim * sizeof *z);
    if (a->shead_pending) {
        memcpy(a->shead + a->nshead++ * dim, z, dim * sizeof *z);
        if (a->nshead == FE_DISCOVER_EDGE) {
            fe__discover_edge_add(a->edge_start, dim, a->shead, a->nshead);
            fe__discover_shead_clear(a);
        }
    }
}

/* Fold q fitted rows at once, with level-3 BLAS: the panel is laid out
   after the last P rows (oldest first, zeros where there are none), so
   that Z_l += X^T X_{-l} is one matrix product per lag; then the rows
   kept (hist, head, shead) are taken from the same buffer. */
static void fe__discover_lags_panel(fe_discover_acc *a, const double *const *col,
                                    size_t ts, size_t q)
{
    size_t dim = a->m + 1, P = a->lags, E = FE_DISCOVER_EDGE;
    double *buf = a->work + dim * dim + (FE_DISCOVER_PANEL_ROWS + 1) * dim;
    for (size_t j = 0; j < P; j++)
        memcpy(buf + (P - 1 - j) * dim, a->hist + j * dim, dim * sizeof *buf);
    for (size_t t = 0; t < q; t++)
        for (size_t c = 0; c < dim; c++)
            buf[(P + t) * dim + c] = col[c][t * ts];
    for (size_t l = 1; l <= P; l++)
        cblas_dgemm(CblasRowMajor, CblasTrans, CblasNoTrans, (int)dim, (int)dim, (int)q, 1.0,
                    buf + P * dim, (int)dim, buf + (P - l) * dim, (int)dim, 1.0,
                    a->zlag + (l - 1) * dim * dim, (int)dim);
    for (size_t t = 0; t < q && a->head_open && a->nhead < P; t++)
        memcpy(a->head + a->nhead++ * dim, buf + (P + t) * dim, dim * sizeof *buf);
    for (size_t t = 0; t < q && a->shead_pending; t++) {
        memcpy(a->shead + a->nshead++ * dim, buf + (P + t) * dim, dim * sizeof *buf);
        if (a->nshead == E) {
            fe__discover_edge_add(a->edge_start, dim, a->shead, E);
            fe__discover_shead_clear(a);
        }
    }
    for (size_t j = 0; j < P; j++)
        memcpy(a->hist + j * dim, buf + (P + q - 1 - j) * dim, dim * sizeof *buf);
    a->nhist = a->nhist + q < P ? a->nhist + q : P;
}

/* The sums of n columns of q values each, in lanes (below): one chain of
   q dependent additions a column (four cycles each) was most of a
   screen's fold. */
static void fe__discover_sums(const double *const *z, size_t n, size_t q, double *out);

/* The fine blocks: B = 2^J, the most (up to FE_DISCOVER_FINE_BLOCKS) of
   at least FE_DISCOVER_FINE_ROWS fitted rows each; one for short records. */
static size_t fe__discover_fine_count(uint64_t fit_rows)
{
    size_t b = 1;
    while (2 * b <= FE_DISCOVER_FINE_BLOCKS
           && (uint64_t)(2 * b) * FE_DISCOVER_FINE_ROWS <= fit_rows)
        b *= 2;
    return b;
}

/* The fine block of a fitted global row, and the first row of fine block
   k (k = B: fit_rows). */
static size_t fe__discover_fine(const fe_discover_acc *a, uint64_t row)
{
    return (size_t)(row * a->fine / a->fit_rows);
}

static uint64_t fe__discover_fine_cut(const fe_discover_acc *a, size_t k)
{
    return ((uint64_t)k * a->fit_rows + a->fine - 1) / a->fine;
}

/* Add q fitted rows, from global row `row` on, given by columns (value c
   of row t at col[c][t * ts]), to their fine blocks' sums. */
static void fe__discover_fine_rows(fe_discover_acc *a, const double *const *col,
                                   size_t ts, size_t q, uint64_t row)
{
    size_t dim = a->m + 1, t = 0;
    while (t < q) {
        size_t k = fe__discover_fine(a, row + t), stop = q;
        uint64_t end = fe__discover_fine_cut(a, k + 1);
        if (end - (row + t) < (uint64_t)(q - t))
            stop = t + (size_t)(end - (row + t));
        for (size_t c = 0; c < dim; c++) {
            double s = 0.0;
            for (size_t i = t; i < stop; i++)
                s += col[c][i * ts];
            a->fsum[k * dim + c] += s;
        }
        t = stop;
    }
}

/* Fold q rows of block k given by columns (value c of row t at
   col[c][t * ts]): the block's sums (the columns' sums given in `sums`,
   as the column path makes them in lanes; NULL: summed here), and the
   lagged products. */
static void fe__discover_lags_rows(fe_discover_acc *a, const double *const *col,
                                   size_t ts, size_t q, size_t k, const double *sums)
{
    double z[FE_DISCOVER_MAX_COLUMNS + 1];
    int fitted = k < a->blocks;
    if (fitted && sums != NULL) {
        for (size_t c = 0; c <= a->m; c++)
            a->bsum[k * (a->m + 1) + c] += sums[c];
    } else {
        for (size_t c = 0; c <= a->m && fitted; c++) {
            double s = 0.0;
            for (size_t t = 0; t < q; t++)
                s += col[c][t * ts]; /* NOLINT(clang-analyzer-core.NullDereference): col[0 .. m] are the panel's columns */
            a->bsum[k * (a->m + 1) + c] += s;
        }
    }
    if (fitted && a->lags > 0)  /* the long range is the AR model's: none in a screen */
        fe__discover_fine_rows(a, col, ts, q, a->row0 + a->n);
    if (a->lags == 0 || !fitted)
        return;
    if (q >= 8) {
        fe__discover_lags_panel(a, col, ts, q);
        return;
    }
    for (size_t t = 0; t < q; t++) {
        for (size_t c = 0; c <= a->m; c++)
            z[c] = col[c][t * ts];
        fe__discover_lags_row(a, z, fitted);
    }
}

/* Whether folding z would keep every lagged sum finite (the slow path). */
static int fe__discover_lags_finite(const fe_discover_acc *a, const double *z)
{
    size_t dim = a->m + 1;
    for (size_t l = 1; l <= a->nhist; l++)
        for (size_t i = 0; i < dim; i++)
            for (size_t j = 0; j < dim; j++)
                if (!isfinite(a->zlag[(l - 1) * dim * dim + i * dim + j]
                              + z[i] * a->hist[(l - 1) * dim + j]))
                    return 0;
    return 1;
}

/* a <- a (+) b for the lagged products, b following a; before the
   counts and rows of the merge are updated (a->n is a's own). */
static void fe__discover_lags_merge(fe_discover_acc *a, const fe_discover_acc *b)
{
    size_t dim = a->m + 1, P = a->lags;
    for (size_t i = 0; i < a->blocks * dim; i++)
        a->bsum[i] += b->bsum[i];
    for (size_t i = 0; i < a->fine * dim; i++)
        a->fsum[i] += b->fsum[i];
    if (P == 0)
        return;
    for (size_t i = 0; i < P * dim * dim; i++)
        a->zlag[i] += b->zlag[i];
    {
        size_t E = FE_DISCOVER_EDGE, ne = 2 * E * dim * E * dim;
        for (size_t i = 0; i < ne; i++)
            a->edge_start[i] += b->edge_start[i];  /* edge_end follows edge_start */
        if (a->n > 0 && !b->first_linked) {
            fe__discover_edges_close(a);
            if (b->nhead >= E) {                         /* b's first recording's start */
                fe__discover_edge_add(a->edge_start, dim, b->head, E);
            } else if (b->head_open) {                   /* it goes on past b: pending */
                memcpy(a->shead, b->head, b->nhead * dim * sizeof *a->shead);
                a->nshead = b->nhead;
                a->shead_pending = 1;
            }
        } else if (a->n > 0) {
            if (a->shead_pending) {
                size_t take = fe__discover_min(E - a->nshead, b->nhead);
                memcpy(a->shead + a->nshead * dim, b->head, take * dim * sizeof *a->shead);
                a->nshead += take;
                if (a->nshead == E)
                    fe__discover_edge_add(a->edge_start, dim, a->shead, E);
                if (a->nshead == E || !b->head_open)
                    fe__discover_shead_clear(a);
            }
            /* a's recording ends inside b after fewer than E of b's rows: b
               did not close it (too short for b); it is closed here, if long
               enough, with a's last rows. */
            if (!b->head_open && b->nhead < E && b->nhead + a->nhist >= E) {
                double part[FE_DISCOVER_EDGE * (FE_DISCOVER_MAX_COLUMNS + 1)];
                for (size_t j = 0; j < b->nhead; j++)       /* newest first */
                    memcpy(part + j * dim, b->head + (b->nhead - 1 - j) * dim, dim * sizeof *part);
                memcpy(part + b->nhead * dim, a->hist, (E - b->nhead) * dim * sizeof *part);
                fe__discover_edge_add(a->edge_end, dim, part, E);
            }
        }
        /* From here on the open recording is b's, unless b's first one is
           the open one (continuing a's, or pending above). */
        if (a->n == 0 || !b->head_open) {
            memcpy(a->shead, b->shead, E * dim * sizeof *a->shead);
            a->nshead = b->nshead;
            a->shead_pending = b->shead_pending;
        }
    }
    if (a->n > 0 && b->first_linked)      /* products across the cut */
        for (size_t j = 0; j < b->nhead; j++)
            for (size_t d = 1; d <= a->nhist && j + d <= P; d++) {
                double *zl = a->zlag + (j + d - 1) * dim * dim;
                const double *x = b->head + j * dim, *y = a->hist + (d - 1) * dim;
                for (size_t u = 0; u < dim; u++)
                    for (size_t v = 0; v < dim; v++)
                        zl[u * dim + v] += x[u] * y[v];
            }
    if (a->n == 0) {
        memcpy(a->head, b->head, P * dim * sizeof *a->head);
        a->nhead = b->nhead;
        a->head_open = b->head_open;
    } else {
        size_t add = 0;
        if (a->head_open && b->first_linked)
            for (; add < b->nhead && a->nhead + add < P; add++)
                memcpy(a->head + (a->nhead + add) * dim, b->head + add * dim,
                       dim * sizeof *a->head);
        a->nhead += add;
        a->head_open = a->head_open && b->first_linked && b->head_open;
    }
    /* The newest fitted rows: b's, then a's when b has fewer than P and
       continues a (all a's when b has none: held-out rows only). */
    {
        size_t keep = 0;
        if (a->n > 0 && b->first_linked && b->head_open && b->nhist < P)
            keep = a->nhist < P - b->nhist ? a->nhist : P - b->nhist;
        memmove(a->hist + b->nhist * dim, a->hist, keep * dim * sizeof *a->hist);
        memcpy(a->hist, b->hist, b->nhist * dim * sizeof *a->hist);
        a->nhist = b->nhist + keep;
        memset(a->hist + a->nhist * dim, 0, (P - a->nhist) * dim * sizeof *a->hist);
    }
}
/* Fold the lagged products ends here */
/* [[file:../literate/discover.org::Fold a row into its block][Fold a row into its block]] */
size_t fe_discover_acc_doubles(size_t m, size_t blocks)
{
    return FE_DISCOVER_ACC_DOUBLES(m, blocks);
}

/* The first global row of block k (k = K: the first held-out row). */
static uint64_t fe__discover_cut(const fe_discover_acc *a, size_t k)
{
    if (k >= a->blocks)
        return a->fit_rows;
    return ((uint64_t)k * a->fit_rows + a->blocks - 1) / a->blocks;
}

static size_t fe__discover_block(const fe_discover_acc *a, uint64_t row)
{
    if (row >= a->fit_rows)
        return a->blocks;                       /* held out */
    return (size_t)(row * a->blocks / a->fit_rows);
}

static void fe__discover_layout(fe_discover_acc *a, double *storage)
{
    size_t dim = a->m + 1;
    a->gram = storage;
    a->lag = a->gram + (a->blocks + 1) * dim * dim;
    a->first = a->lag + dim * dim;
    a->last = a->first + dim;
    a->counts = a->last + dim;
    a->zlag = a->counts + a->blocks + 1;
    a->hist = a->zlag + FE_DISCOVER_LAGS * dim * dim;
    a->head = a->hist + FE_DISCOVER_LAGS * dim;
    a->bsum = a->head + FE_DISCOVER_LAGS * dim;
    a->edge_start = a->bsum + a->blocks * dim;
    a->edge_end = a->edge_start + FE_DISCOVER_EDGE * dim * FE_DISCOVER_EDGE * dim;
    a->shead = a->edge_end + FE_DISCOVER_EDGE * dim * FE_DISCOVER_EDGE * dim;
    a->fsum = a->shead + FE_DISCOVER_EDGE * dim;
    a->work = a->fsum + FE_DISCOVER_FINE_BLOCKS * dim;
}

int fe_discover_acc_init(fe_discover_acc *a, size_t m, size_t blocks,
                         uint64_t fit_rows, uint64_t row0, double *storage,
                         size_t storage_doubles)
{
    return fe_discover_screen_init(a, m, m, blocks, fit_rows, row0, storage,
                                   storage_doubles);
}

int fe_discover_screen_init(fe_discover_acc *a, size_t m, size_t base_cols,
                            size_t blocks, uint64_t fit_rows, uint64_t row0,
                            double *storage, size_t storage_doubles)
{
    size_t need;
    if (a == NULL || storage == NULL)
        return FE_EINVAL;
    if (m == 0 || m > FE_DISCOVER_MAX_COLUMNS || blocks < 2
        || blocks > FE_DISCOVER_MAX_BLOCKS || base_cols > m)
        return FE_ESIZE;
    need = fe_discover_acc_doubles(m, blocks);
    if (storage_doubles < need)
        return FE_ESIZE;
    if (fit_rows < 2 * (uint64_t)blocks)
        return FE_ETOOFEW;
    memset(storage, 0, need * sizeof *storage);
    a->m = m;
    a->blocks = blocks;
    a->base_cols = base_cols;
    a->fit_rows = fit_rows;
    a->row0 = row0;
    a->n = 0;
    a->have_prev = 0;
    a->first_linked = 1;
    a->lags = base_cols == m ? FE_DISCOVER_DEFAULT_LAGS : 0;
    a->nhist = 0;
    a->nhead = 0;
    a->head_open = 1;
    a->nshead = 0;
    a->shead_pending = 0;
    a->fine = fe__discover_fine_count(fit_rows);
    fe__discover_layout(a, storage);
    return FE_OK;
}

int fe_discover_set_fine(fe_discover_acc *a, size_t blocks)
{
    if (a == NULL || a->n > 0 || blocks == 0 || (blocks & (blocks - 1)) != 0)
        return FE_EINVAL;
    if (blocks > FE_DISCOVER_FINE_BLOCKS
        || (blocks > 1 && (uint64_t)blocks * FE_DISCOVER_FINE_ROWS > a->fit_rows))
        return FE_ESIZE;
    a->fine = blocks;
    return FE_OK;
}

int fe_discover_set_lags(fe_discover_acc *a, size_t lags)
{
    if (a == NULL || a->n > 0 || (lags > 0 && a->base_cols < a->m))
        return FE_EINVAL;
    if (lags > FE_DISCOVER_LAGS)
        return FE_ESIZE;
    a->lags = lags;
    return FE_OK;
}

/* The columns kept whole are the base columns and r: the u-th of them,
   u <= base_cols. */
static size_t fe__discover_whole(const fe_discover_acc *a, size_t u)
{
    return u < a->base_cols ? u : a->m;
}

/* Whether entry (i, j), i <= j, of a block's triangle is kept: always in
   a full accumulation; in a screen, when i is kept whole, j is r, or j is
   one of the next two columns after i. */
static int fe__discover_kept(const fe_discover_acc *a, size_t i, size_t j)
{
    return i < a->base_cols || j == a->m || j - i < FE_DISCOVER_MAX_GROUP_SIZE;
}

/* Where the kept entries of row i of a triangle end: the band's end, or
   the row's (r is then added on its own when the band stops short). */
static size_t fe__discover_row_end(const fe_discover_acc *a, size_t i)
{
    size_t dim = a->m + 1, band = i + FE_DISCOVER_MAX_GROUP_SIZE;
    return i < a->base_cols || band > dim ? dim : band;
}

/* Add the folded z p^T to T among the columns kept whole: z_i p_i on the
   diagonal, z_i p_j + p_i z_j above. */
static void fe__discover_lag_pair(const fe_discover_acc *a, const double *z,
                                  const double *p)
{
    size_t dim = a->m + 1, nr = a->base_cols + 1;
    for (size_t u = 0; u < nr; u++) {
        size_t i = fe__discover_whole(a, u);
        double zi = z[i], pi = p[i];
        double *ti = a->lag + i * dim;
        ti[i] += zi * pi;
        for (size_t v = u + 1; v < nr; v++) {
            size_t j = fe__discover_whole(a, v);
            ti[j] += zi * p[j] + pi * z[j];
        }
    }
}

/* Some value above 1e100 in magnitude: products may overflow. */
static int fe__discover_large(const double *z, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (fabs(z[i]) > 1e100)
            return 1;
    return 0;
}

int fe_discover_add(fe_discover_acc *a, const double *phi, double r)
{
    size_t dim, k;
    uint64_t row;
    double z[FE_DISCOVER_MAX_COLUMNS + 1], *g;

    if (a == NULL || phi == NULL)
        return FE_EINVAL;
    dim = a->m + 1;
    for (size_t i = 0; i < a->m; i++) {
        if (!isfinite(phi[i]))
            return FE_ENONFINITE;
        z[i] = phi[i];
    }
    if (!isfinite(r))
        return FE_ENONFINITE;
    z[a->m] = r;
    if (a->row0 == FE_DISCOVER_ROW_UNKNOWN)
        return FE_EINVAL;       /* a part that does not know its place */
    row = a->row0 + a->n;
    k = fe__discover_block(a, row);
    g = a->gram + k * dim * dim;
    if (fe__discover_large(z, dim) || (a->have_prev && k < a->blocks
                                       && fe__discover_large(a->last, dim))) {
        /* The slow path: every new sum kept must be finite before any is
           written. */
        for (size_t i = 0; i < dim; i++)
            for (size_t j = i; j < dim; j++)
                if (fe__discover_kept(a, i, j) && !isfinite(g[i * dim + j] + z[i] * z[j]))
                    return FE_ENONFINITE;
        if (a->have_prev && k < a->blocks)
            for (size_t u = 0; u <= a->base_cols; u++)
                for (size_t v = u; v <= a->base_cols; v++) {
                    const double *p = a->last;
                    size_t i = fe__discover_whole(a, u), j = fe__discover_whole(a, v);
                    /* z[0 .. m] are set above and i, j <= m. */
                    double add = j == i ? z[i] * p[i] : z[i] * p[j] + p[i] * z[j]; /* NOLINT(clang-analyzer-core.UndefinedBinaryOperatorResult) */
                    if (!isfinite(a->lag[i * dim + j] + add))
                        return FE_ENONFINITE;
                }
        if (k < a->blocks && !fe__discover_lags_finite(a, z))
            return FE_ENONFINITE;
    }
    /* Add z z^T to the block's upper triangle, where it is kept. */
    for (size_t i = 0; i < dim; i++) {
        double zi = z[i];
        double *gi = g + i * dim;
        size_t end = fe__discover_row_end(a, i);
        if (zi == 0.0)
            continue;
        for (size_t j = i; j < end; j++)
            gi[j] += zi * z[j];
        if (end < dim)
            gi[a->m] += zi * z[a->m];
    }
    a->counts[k] += 1.0;
    /* Add z_t z_{t-1}^T, folded, when the previous row is a fitted neighbour. */
    if (a->have_prev && k < a->blocks)
        fe__discover_lag_pair(a, z, a->last);
    fe__discover_lags_row(a, z, k < a->blocks);
    for (size_t i = 0; i < dim && k < a->blocks; i++)
        a->bsum[k * dim + i] += z[i];
    if (k < a->blocks && a->lags > 0) {
        const double *zc[FE_DISCOVER_MAX_COLUMNS + 1];
        for (size_t i = 0; i < dim; i++)
            zc[i] = z + i;
        fe__discover_fine_rows(a, zc, 0, 1, a->row0 + a->n);
    }
    if (a->n == 0)
        memcpy(a->first, z, dim * sizeof *z);
    memcpy(a->last, z, dim * sizeof *z);
    a->have_prev = k < a->blocks;
    a->n++;
    return FE_OK;
}

void fe_discover_break(fe_discover_acc *a)
{
    if (a == NULL)
        return;
    a->have_prev = 0;
    if (a->n == 0) {
        a->first_linked = 0;
    } else if (a->nhist > 0 || a->shead_pending) {
        fe__discover_edges_close(a);
        a->shead_pending = a->lags > 0;
        a->head_open = 0;
    } else {
        a->head_open = 0;
    }
    fe__discover_lags_cut(a);
}
/* Fold a row into its block ends here */
/* [[file:../literate/discover.org::Merge consecutive accumulations][Merge consecutive accumulations]] */
int fe_discover_merge(fe_discover_acc *a, const fe_discover_acc *b)
{
    size_t dim, total;
    if (a == NULL || b == NULL)
        return FE_EINVAL;
    if (a->m != b->m || a->blocks != b->blocks || a->fit_rows != b->fit_rows
        || a->base_cols != b->base_cols || a->lags != b->lags || a->fine != b->fine)
        return FE_EMISMATCH;
    if (b->n == 0) {            /* the identity, carrying b's break if any */
        if (!b->first_linked)
            fe_discover_break(a);
        return FE_OK;
    }
    if (a->n == 0 && a->row0 == FE_DISCOVER_ROW_UNKNOWN)
        a->row0 = b->row0;      /* an empty part adopts b's place */
    else if (b->row0 != a->row0 + a->n)
        return FE_EMISMATCH;
    dim = a->m + 1;
    total = (a->blocks + 1) * dim * dim;
    for (size_t i = 0; i < total; i++)
        a->gram[i] += b->gram[i];
    for (size_t i = 0; i <= a->blocks; i++)
        a->counts[i] += b->counts[i];
    for (size_t i = 0; i < dim * dim; i++)
        a->lag[i] += b->lag[i];
    fe__discover_lags_merge(a, b);
    /* The lag product across the cut. */
    if (a->n > 0 && a->have_prev && b->first_linked
        && fe__discover_block(a, b->row0) < a->blocks)
        fe__discover_lag_pair(a, b->first, a->last);
    if (a->n == 0) {
        memcpy(a->first, b->first, dim * sizeof *a->first);
        a->first_linked = b->first_linked;
    }
    memcpy(a->last, b->last, dim * sizeof *a->last);
    a->have_prev = b->have_prev;
    a->n += b->n;
    return FE_OK;
}
/* Merge consecutive accumulations ends here */
/* [[file:../literate/discover.org::Fold a panel of rows][Fold a panel of rows]] */
/* Copy up to q rows into the scratch panel past its row 0 (kept for the
   row before the panel): value i of row t at z[t * ts + i * is], rows
   (ts = M, is = 1) for dsyrk or columns (ts = 1, is =
   FE_DISCOVER_PANEL_ROWS) for the lane kernels, checking every value; the
   count of rows before the first with a value that is not finite or above
   1e100 in magnitude. */
static inline size_t fe__discover_load(fe_discover_acc *a, const double *phi, size_t ldphi,
                                       const double *r, size_t q, size_t ts, size_t is)
{
    size_t dim = a->m + 1, m = a->m;
    double *z = a->work + dim * dim + dim;
    for (size_t t = 0; t < q; t++) {
        const double *pt = phi + t * ldphi;
        double *zt = z + t * ts;
        int ok = fabs(r[t]) <= 1e100;           /* false for NaN too */
        for (size_t i = 0; i < m; i++) {
            zt[i * is] = pt[i];
            ok &= fabs(pt[i]) <= 1e100;
        }
        zt[m * is] = r[t];
        if (!ok)
            return t;
    }
    return q;
}

/* Fold the q loaded rows, all in block k. */
static void fe__discover_panel(fe_discover_acc *a, size_t k, size_t q)
{
    size_t dim = a->m + 1;
    double *x = a->work, *c = x + dim * dim, *z = c + dim;
    double *g = a->gram + k * dim * dim, *t = a->lag;
    int fitted = k < a->blocks, linked = fitted && a->have_prev;
    size_t pairs = linked ? q : q - 1;
    const double *rows[FE_DISCOVER_MAX_COLUMNS + 1] = {0};

    for (size_t j = 0; j < dim; j++)
        rows[j] = z + j;
    fe__discover_lags_rows(a, rows, dim, q, k, NULL);
    /* X = Z^T Z, into the block. */
    cblas_dsyrk(CblasRowMajor, CblasUpper, CblasTrans, (int)dim, (int)q, 1.0, z,
                (int)dim, 0.0, x, (int)dim);
    for (size_t i = 0; i < dim; i++)
        for (size_t j = i; j < dim; j++)
            g[i * dim + j] += x[i * dim + j];
    a->counts[k] += (double)q;
    if (a->n == 0)
        memcpy(a->first, z, dim * sizeof *z);
    if (fitted && pairs > 0) {
        double diag[FE_DISCOVER_MAX_COLUMNS + 1] = {0}; /* dim entries set below */
        double sign = linked ? 1.0 : -1.0;
        double *c0 = linked ? c : z, *cp = z + (q - 1) * dim;
        if (linked)
            memcpy(c, a->last, dim * sizeof *c);
        /* The diagonal directly: T_ii += sum_s c_{s,i} c_{s-1,i}. */
        for (size_t i = 0; i < dim; i++)
            diag[i] = t[i * dim + i];
        for (size_t s = 1; s <= pairs; s++) {
            const double *cs = c0 + s * dim, *cr = cs - dim;
            for (size_t i = 0; i < dim; i++)
                diag[i] += cs[i] * cr[i];
        }
        /* Above it: 2X +- c_0 c_0^T - c_p c_p^T, ... */
        for (size_t i = 0; i < dim; i++)
            for (size_t j = i + 1; j < dim; j++)
                t[i * dim + j] += 2.0 * x[i * dim + j] + sign * c0[i] * c0[j] - cp[i] * cp[j];
        memcpy(a->last, cp, dim * sizeof *cp);
        /* ... - D, from the differences made in place, last row first. */
        for (size_t s = pairs; s > 0; s--) {
            double *cs = c0 + s * dim;
            const double *cr = cs - dim;
            for (size_t i = 0; i < dim; i++)
                cs[i] -= cr[i];
        }
        cblas_dsyrk(CblasRowMajor, CblasUpper, CblasTrans, (int)dim, (int)pairs, -1.0,
                    c0 + dim, (int)dim, 1.0, t, (int)dim);
        for (size_t i = 0; i < dim; i++)
            t[i * dim + i] = diag[i];
    } else {
        memcpy(a->last, z + (q - 1) * dim, dim * sizeof *z);
    }
    a->have_prev = fitted;
    a->n += q;
}
/* Fold a panel of rows ends here */
/* [[file:../literate/discover.org::Compile the discovery kernels][Compile the discovery kernels]] */
#define FE__L 4
#define FE__DISCOVER_DOTS_FN fe__discover_dots4
#define FE__DISCOVER_BAND_FN fe__discover_band4
#define FE__DISCOVER_SUMS_FN fe__discover_sums4
#define FE__DISCOVER_TARGET FE__LANES_CLONES
/* out[4 a + c] += sum_{t < q} x[a][t] y[c][t], a, c < 4. */
FE__DISCOVER_TARGET
static void FE__DISCOVER_DOTS_FN(const double *const *x, const double *const *y, size_t q,
                                 double *out)
{
    const double *x0 = x[0], *x1 = x[1], *x2 = x[2], *x3 = x[3];
    const double *y0 = y[0], *y1 = y[1], *y2 = y[2], *y3 = y[3];
    double s[16][FE__L] = {{0}};
    size_t t;
    for (t = 0; t + FE__L <= q; t += FE__L)
        for (int l = 0; l < FE__L; l++) {
            double a0 = x0[t + l], a1 = x1[t + l], a2 = x2[t + l], a3 = x3[t + l];
            double b0 = y0[t + l], b1 = y1[t + l], b2 = y2[t + l], b3 = y3[t + l];
            s[0][l] += a0 * b0;
            s[1][l] += a0 * b1;
            s[2][l] += a0 * b2;
            s[3][l] += a0 * b3;
            s[4][l] += a1 * b0;
            s[5][l] += a1 * b1;
            s[6][l] += a1 * b2;
            s[7][l] += a1 * b3;
            s[8][l] += a2 * b0;
            s[9][l] += a2 * b1;
            s[10][l] += a2 * b2;
            s[11][l] += a2 * b3;
            s[12][l] += a3 * b0;
            s[13][l] += a3 * b1;
            s[14][l] += a3 * b2;
            s[15][l] += a3 * b3;
        }
    for (int c = 0; c < 16; c++) {
        double v = 0.0;
        for (int l = 0; l < FE__L; l++)
            v += s[c][l];
        for (size_t u = t; u < q; u++)
            v += x[c / 4][u] * y[c % 4][u];
        out[c] += v;
    }
}

/* out[j] = sum_{t < q} z[j][t] for the n columns z[0 .. n-1], four
   columns at a time (four chains of additions, not one). */
FE__DISCOVER_TARGET
static void FE__DISCOVER_SUMS_FN(const double *const *z, size_t n, size_t q, double *out)
{
    for (size_t j = 0; j < n; j += 4) {
        const double *p[4];
        double s[4][FE__L] = {{0}};
        size_t t;
        for (int c = 0; c < 4; c++)
            p[c] = z[j + (size_t)c < n ? j + (size_t)c : j];
        for (t = 0; t + FE__L <= q; t += FE__L)
            for (int l = 0; l < FE__L; l++) {
                s[0][l] += p[0][t + l];
                s[1][l] += p[1][t + l];
                s[2][l] += p[2][t + l];
                s[3][l] += p[3][t + l];
            }
        for (int c = 0; c < 4 && j + (size_t)c < n; c++) {
            double v = 0.0;
            for (int l = 0; l < FE__L; l++)
                v += s[c][l];
            for (size_t u = t; u < q; u++)
                v += p[c][u];
            out[j + (size_t)c] = v;
        }
    }
}

/* For the n columns z[0 .. n-1]: out[3 j + d] += sum_t z[j][t] z[j+d][t]
   for d < 3 and j + d < n, and sums[j] = sum_t z[j][t], four columns j at
   a time (the sums ride on the loads the products make, on the adders,
   which the multiply-adds leave idle). */
FE__DISCOVER_TARGET
static void FE__DISCOVER_BAND_FN(const double *const *z, size_t n, size_t q, double *out,
                                 double *sums)
{
    for (size_t j = 0; j < n; j += 4) {
        const double *p[6];
        double s[12][FE__L] = {{0}}, v[12], c1[4][FE__L] = {{0}};
        size_t t;
        for (int c = 0; c < 6; c++)
            p[c] = z[j + (size_t)c < n ? j + (size_t)c : j];
        for (t = 0; t + FE__L <= q; t += FE__L)
            for (int l = 0; l < FE__L; l++) {
                double u0 = p[0][t + l], u1 = p[1][t + l], u2 = p[2][t + l],
                       u3 = p[3][t + l], u4 = p[4][t + l], u5 = p[5][t + l];
                c1[0][l] += u0;
                c1[1][l] += u1;
                c1[2][l] += u2;
                c1[3][l] += u3;
                s[0][l] += u0 * u0;
                s[1][l] += u0 * u1;
                s[2][l] += u0 * u2;
                s[3][l] += u1 * u1;
                s[4][l] += u1 * u2;
                s[5][l] += u1 * u3;
                s[6][l] += u2 * u2;
                s[7][l] += u2 * u3;
                s[8][l] += u2 * u4;
                s[9][l] += u3 * u3;
                s[10][l] += u3 * u4;
                s[11][l] += u3 * u5;
            }
        for (int c = 0; c < 12; c++) {
            v[c] = 0.0;
            for (int l = 0; l < FE__L; l++)
                v[c] += s[c][l];
            for (size_t u = t; u < q; u++)
                v[c] += p[c / 3][u] * p[c / 3 + c % 3][u];
        }
        /* Keep the products that exist: (j + a, j + a + d) inside n. */
        for (size_t a = 0; a < 4 && j + a < n; a++)
            for (size_t d = 0; d < 3 && j + a + d < n; d++)
                out[3 * (j + a) + d] += v[3 * a + d];
        for (size_t a = 0; a < 4 && j + a < n; a++) {
            double w = 0.0;
            for (int l = 0; l < FE__L; l++)
                w += c1[a][l];
            for (size_t u = t; u < q; u++)
                w += p[a][u];
            sums[j + a] = w;
        }
    }
}
#undef FE__DISCOVER_TARGET
#undef FE__L
#undef FE__DISCOVER_DOTS_FN
#undef FE__DISCOVER_BAND_FN
#undef FE__DISCOVER_SUMS_FN

#if defined(FE__LANES_X86)
#define FE__L 8
#define FE__DISCOVER_DOTS_FN fe__discover_dots8
#define FE__DISCOVER_BAND_FN fe__discover_band8
#define FE__DISCOVER_SUMS_FN fe__discover_sums8
#define FE__DISCOVER_TARGET FE__LANES_WIDE
/* out[4 a + c] += sum_{t < q} x[a][t] y[c][t], a, c < 4. */
FE__DISCOVER_TARGET
static void FE__DISCOVER_DOTS_FN(const double *const *x, const double *const *y, size_t q,
                                 double *out)
{
    const double *x0 = x[0], *x1 = x[1], *x2 = x[2], *x3 = x[3];
    const double *y0 = y[0], *y1 = y[1], *y2 = y[2], *y3 = y[3];
    double s[16][FE__L] = {{0}};
    size_t t;
    for (t = 0; t + FE__L <= q; t += FE__L)
        for (int l = 0; l < FE__L; l++) {
            double a0 = x0[t + l], a1 = x1[t + l], a2 = x2[t + l], a3 = x3[t + l];
            double b0 = y0[t + l], b1 = y1[t + l], b2 = y2[t + l], b3 = y3[t + l];
            s[0][l] += a0 * b0;
            s[1][l] += a0 * b1;
            s[2][l] += a0 * b2;
            s[3][l] += a0 * b3;
            s[4][l] += a1 * b0;
            s[5][l] += a1 * b1;
            s[6][l] += a1 * b2;
            s[7][l] += a1 * b3;
            s[8][l] += a2 * b0;
            s[9][l] += a2 * b1;
            s[10][l] += a2 * b2;
            s[11][l] += a2 * b3;
            s[12][l] += a3 * b0;
            s[13][l] += a3 * b1;
            s[14][l] += a3 * b2;
            s[15][l] += a3 * b3;
        }
    for (int c = 0; c < 16; c++) {
        double v = 0.0;
        for (int l = 0; l < FE__L; l++)
            v += s[c][l];
        for (size_t u = t; u < q; u++)
            v += x[c / 4][u] * y[c % 4][u];
        out[c] += v;
    }
}

/* out[j] = sum_{t < q} z[j][t] for the n columns z[0 .. n-1], four
   columns at a time (four chains of additions, not one). */
FE__DISCOVER_TARGET
static void FE__DISCOVER_SUMS_FN(const double *const *z, size_t n, size_t q, double *out)
{
    for (size_t j = 0; j < n; j += 4) {
        const double *p[4];
        double s[4][FE__L] = {{0}};
        size_t t;
        for (int c = 0; c < 4; c++)
            p[c] = z[j + (size_t)c < n ? j + (size_t)c : j];
        for (t = 0; t + FE__L <= q; t += FE__L)
            for (int l = 0; l < FE__L; l++) {
                s[0][l] += p[0][t + l];
                s[1][l] += p[1][t + l];
                s[2][l] += p[2][t + l];
                s[3][l] += p[3][t + l];
            }
        for (int c = 0; c < 4 && j + (size_t)c < n; c++) {
            double v = 0.0;
            for (int l = 0; l < FE__L; l++)
                v += s[c][l];
            for (size_t u = t; u < q; u++)
                v += p[c][u];
            out[j + (size_t)c] = v;
        }
    }
}

/* For the n columns z[0 .. n-1]: out[3 j + d] += sum_t z[j][t] z[j+d][t]
   for d < 3 and j + d < n, and sums[j] = sum_t z[j][t], four columns j at
   a time (the sums ride on the loads the products make, on the adders,
   which the multiply-adds leave idle). */
FE__DISCOVER_TARGET
static void FE__DISCOVER_BAND_FN(const double *const *z, size_t n, size_t q, double *out,
                                 double *sums)
{
    for (size_t j = 0; j < n; j += 4) {
        const double *p[6];
        double s[12][FE__L] = {{0}}, v[12], c1[4][FE__L] = {{0}};
        size_t t;
        for (int c = 0; c < 6; c++)
            p[c] = z[j + (size_t)c < n ? j + (size_t)c : j];
        for (t = 0; t + FE__L <= q; t += FE__L)
            for (int l = 0; l < FE__L; l++) {
                double u0 = p[0][t + l], u1 = p[1][t + l], u2 = p[2][t + l],
                       u3 = p[3][t + l], u4 = p[4][t + l], u5 = p[5][t + l];
                c1[0][l] += u0;
                c1[1][l] += u1;
                c1[2][l] += u2;
                c1[3][l] += u3;
                s[0][l] += u0 * u0;
                s[1][l] += u0 * u1;
                s[2][l] += u0 * u2;
                s[3][l] += u1 * u1;
                s[4][l] += u1 * u2;
                s[5][l] += u1 * u3;
                s[6][l] += u2 * u2;
                s[7][l] += u2 * u3;
                s[8][l] += u2 * u4;
                s[9][l] += u3 * u3;
                s[10][l] += u3 * u4;
                s[11][l] += u3 * u5;
            }
        for (int c = 0; c < 12; c++) {
            v[c] = 0.0;
            for (int l = 0; l < FE__L; l++)
                v[c] += s[c][l];
            for (size_t u = t; u < q; u++)
                v[c] += p[c / 3][u] * p[c / 3 + c % 3][u];
        }
        /* Keep the products that exist: (j + a, j + a + d) inside n. */
        for (size_t a = 0; a < 4 && j + a < n; a++)
            for (size_t d = 0; d < 3 && j + a + d < n; d++)
                out[3 * (j + a) + d] += v[3 * a + d];
        for (size_t a = 0; a < 4 && j + a < n; a++) {
            double w = 0.0;
            for (int l = 0; l < FE__L; l++)
                w += c1[a][l];
            for (size_t u = t; u < q; u++)
                w += p[a][u];
            sums[j + a] = w;
        }
    }
}
#undef FE__DISCOVER_TARGET
#undef FE__L
#undef FE__DISCOVER_DOTS_FN
#undef FE__DISCOVER_BAND_FN
#undef FE__DISCOVER_SUMS_FN
#endif

static void fe__discover_dots(const double *const *x, const double *const *y, size_t q,
                              double *out)
{
#if defined(FE__LANES_X86)
    if (FE__LANES_HAVE_WIDE()) {
        fe__discover_dots8(x, y, q, out);
        return;
    }
#endif
    fe__discover_dots4(x, y, q, out);
}

static void fe__discover_band(const double *const *z, size_t n, size_t q, double *out,
                              double *sums)
{
#if defined(FE__LANES_X86)
    if (FE__LANES_HAVE_WIDE()) {
        fe__discover_band8(z, n, q, out, sums);
        return;
    }
#endif
    fe__discover_band4(z, n, q, out, sums);
}

static void fe__discover_sums(const double *const *z, size_t n, size_t q, double *out)
{
#if defined(FE__LANES_X86)
    if (FE__LANES_HAVE_WIDE()) {
        fe__discover_sums8(z, n, q, out);
        return;
    }
#endif
    fe__discover_sums4(z, n, q, out);
}
/* Compile the discovery kernels ends here */
/* [[file:../literate/discover.org::Fold a panel of columns][Fold a panel of columns]] */
/* Whether panels take the column path: a screen, or a narrow full
   accumulation. */
static int fe__discover_by_columns(const fe_discover_acc *a)
{
    return a->base_cols < a->m || a->m + 1 <= 8;
}

/* out[a * ny + c] = sum_{t < q} col[xi[a]][t + xoff] col[yi[c]][t] for
   a < nx, c < ny, in tiles of four by four (a short tile repeats a column
   and drops its products). */
static void fe__discover_cross(const double *const *col, const size_t *xi, size_t nx,
                               size_t xoff, const size_t *yi, size_t ny, size_t q,
                               double *out)
{
    for (size_t a = 0; a < nx; a += 4)
        for (size_t c = 0; c < ny; c += 4) {
            const double *x[4], *y[4];
            double o[16] = {0};
            size_t na = nx - a < 4 ? nx - a : 4, nc = ny - c < 4 ? ny - c : 4;
            for (size_t k = 0; k < 4; k++) {
                x[k] = col[xi[a + (k < na ? k : 0)]] + xoff;
                y[k] = col[yi[c + (k < nc ? k : 0)]];
            }
            fe__discover_dots(x, y, q, o);
            for (size_t k = 0; k < na; k++)
                for (size_t h = 0; h < nc; h++)
                    out[(a + k) * ny + c + h] = o[4 * k + h];
        }
}

/* Fold the q rows of the columns col[0 .. m] (col[m] is r), all in block
   k, and return 1; or return 0 and fold nothing when the panel's sums of
   squares do not show every value to be at most 1e100 in magnitude. */
static int fe__discover_column_panel(fe_discover_acc *a, size_t k,
                                     const double *const *col, size_t q)
{
    size_t dim = a->m + 1, m = a->m, nb = a->base_cols, nr = nb + 1;
    size_t idx[FE_DISCOVER_MAX_COLUMNS + 1], whole[FE_DISCOVER_MAX_COLUMNS + 1] = {0};
    double band[3 * FE_DISCOVER_MAX_COLUMNS], *out = a->work;  /* nr x dim <= dim x dim */
    double sums[FE_DISCOVER_MAX_COLUMNS + 1];   /* the columns' sums, with the band */
    double *g = a->gram + k * dim * dim;
    int fitted = k < a->blocks, linked = fitted && a->have_prev;

    for (size_t j = 0; j < dim; j++)
        idx[j] = j;
    for (size_t u = 0; u < nr; u++)
        whole[u] = fe__discover_whole(a, u);
    /* The whole rows, each against every column: base column i keeps its
       products with columns i .. m, r those with the others (its products
       with the base columns are theirs). */
    fe__discover_cross(col, whole, nr, 0, idx, dim, q, out);
    if (nb < m) {
        const double *wc[FE_DISCOVER_MAX_COLUMNS + 1];
        double ws[FE_DISCOVER_MAX_COLUMNS + 1];
        memset(band, 0, 3 * (m - nb) * sizeof *band);
        fe__discover_band(col + nb, m - nb, q, band, sums + nb);
        for (size_t u = 0; u < nr; u++)
            wc[u] = col[whole[u]];
        fe__discover_sums(wc, nr, q, ws);
        for (size_t u = 0; u < nr; u++)
            sums[whole[u]] = ws[u];
    } else {
        fe__discover_sums(col, dim, q, sums);
    }
    /* The guard, read off the sums: see the text. */
    for (size_t u = 0; u < nr; u++)
        if (!(out[u * dim + whole[u]] <= 1e200))
            return 0;
    for (size_t j = nb; j < m; j++)
        if (!(band[3 * (j - nb)] <= 1e200))
            return 0;
    for (size_t u = 0; u < nr; u++) {
        size_t i = whole[u];
        for (size_t j = u < nb ? i : nb; j < dim; j++) {
            if (i <= j)
                g[i * dim + j] += out[u * dim + j];
            else
                g[j * dim + i] += out[u * dim + j];
        }
    }
    /* The band of the other columns. */
    for (size_t j = nb; j < m; j++)
        for (size_t d = 0; d < 3 && j + d < m; d++)
            g[j * dim + j + d] += band[3 * (j - nb) + d];
    a->counts[k] += (double)q;
    fe__discover_lags_rows(a, col, 1, q, k, sums);
    if (a->n == 0)
        for (size_t c = 0; c < dim; c++)
            a->first[c] = col[c][0];
    /* The lag product among the whole columns: L_uv = sum_t z_t,i z_t-1,j,
       with the row before the panel when it is a fitted neighbour. */
    if (fitted && (linked || q > 1)) {
        memset(out, 0, nr * nr * sizeof *out);
        if (q > 1)
            fe__discover_cross(col, whole, nr, 1, whole, nr, q - 1, out);
        for (size_t u = 0; u < nr && linked; u++)
            for (size_t v = 0; v < nr; v++)
                out[u * nr + v] += col[whole[u]][0] * a->last[whole[v]];
        for (size_t u = 0; u < nr; u++) {
            double *t = a->lag + whole[u] * dim;
            t[whole[u]] += out[u * nr + u];
            for (size_t v = u + 1; v < nr; v++)
                t[whole[v]] += out[u * nr + v] + out[v * nr + u];
        }
    }
    for (size_t c = 0; c < dim; c++)
        a->last[c] = col[c][q - 1];
    a->have_prev = fitted;
    a->n += q;
    return 1;
}

/* Copy q rows, transposed, into the scratch panel's columns (ld
   FE_DISCOVER_PANEL_ROWS), pointed to by col[0 .. m]; the count of rows
   loaded, as fe__discover_load. */
static size_t fe__discover_load_columns(fe_discover_acc *a, const double *phi,
                                        size_t ldphi, const double *r, size_t q,
                                        const double **col)
{
    size_t dim = a->m + 1;
    const double *z = a->work + dim * dim + dim;
    for (size_t c = 0; c < dim; c++)
        col[c] = z + c * FE_DISCOVER_PANEL_ROWS;
    return fe__discover_load(a, phi, ldphi, r, q, 1, FE_DISCOVER_PANEL_ROWS);
}

/* The count of rows before the first with a value the guard stops. */
static size_t fe__discover_good_rows(const double *const *col, size_t n, size_t q)
{
    for (size_t t = 0; t < q; t++)
        for (size_t c = 0; c < n; c++)
            if (!(fabs(col[c][t]) <= 1e100))
                return t;
    return q;
}

/* The rows of the next panel: at most FE_DISCOVER_PANEL_ROWS of the
   `left`, all in the block of the next row (returned in *k). */
static size_t fe__discover_panel_rows(const fe_discover_acc *a, size_t left, size_t *k)
{
    uint64_t row = a->row0 + a->n;
    size_t q = left < FE_DISCOVER_PANEL_ROWS ? left : FE_DISCOVER_PANEL_ROWS;
    *k = fe__discover_block(a, row);
    if (*k < a->blocks && fe__discover_cut(a, *k + 1) - row < q)
        q = (size_t)(fe__discover_cut(a, *k + 1) - row);
    return q;
}
/* Fold a panel of columns ends here */
/* [[file:../literate/discover.org::Fold many rows][Fold many rows]] */
int fe_discover_add_rows(fe_discover_acc *a, const double *phi, size_t ldphi,
                         const double *r, size_t nrows, size_t *done)
{
    size_t i = 0;
    int rc = FE_OK;

    if (done != NULL)
        *done = 0;
    if (a == NULL || (nrows > 0 && (phi == NULL || r == NULL))
        || (nrows > 1 && ldphi < a->m)
        || (nrows > 0 && a->row0 == FE_DISCOVER_ROW_UNKNOWN))
        return FE_EINVAL;
    while (i < nrows && rc == FE_OK) {
        size_t k, got = 0, q = fe__discover_panel_rows(a, nrows - i, &k);
        const double *col[FE_DISCOVER_MAX_COLUMNS + 1];
        int by_columns = fe__discover_by_columns(a);
        if (!(a->have_prev && fe__discover_large(a->last, a->m + 1)))
            got = by_columns
                      ? fe__discover_load_columns(a, phi + i * ldphi, ldphi, r + i, q, col)
                      : fe__discover_load(a, phi + i * ldphi, ldphi, r + i, q, a->m + 1, 1);
        if (got > 0 && (!by_columns || fe__discover_column_panel(a, k, col, got))) {
            if (!by_columns)
                fe__discover_panel(a, k, got);
            i += got;
            continue;
        }
        /* A row that is not finite, has a value above 1e100, or follows
           one (got == 0), or a panel whose sums the column path would not
           trust: the row step decides, row by row, with its guard. */
        for (size_t t = 0; t < (got > 0 ? got : 1) && rc == FE_OK; t++) {
            rc = fe_discover_add(a, phi + i * ldphi, r[i]);
            i += rc == FE_OK;
        }
    }
    if (done != NULL)
        *done = i;
    return rc;
}

int fe_discover_add_columns(fe_discover_acc *a, const double *phi, size_t ldphi,
                            const double *r, size_t nrows, size_t *done)
{
    size_t i = 0;
    int rc = FE_OK;

    if (done != NULL)
        *done = 0;
    if (a == NULL || (nrows > 0 && (phi == NULL || r == NULL))
        || (nrows > 0 && a->m > 1 && ldphi < nrows)
        || (nrows > 0 && a->row0 == FE_DISCOVER_ROW_UNKNOWN))
        return FE_EINVAL;
    while (i < nrows && rc == FE_OK) {
        size_t k, dim = a->m + 1, got = 0, q = fe__discover_panel_rows(a, nrows - i, &k);
        const double *col[FE_DISCOVER_MAX_COLUMNS + 1];
        double row[FE_DISCOVER_MAX_COLUMNS];
        for (size_t c = 0; c < a->m; c++)
            col[c] = phi + c * ldphi + i;
        col[a->m] = r + i;
        if (!(a->have_prev && fe__discover_large(a->last, dim))) {
            if (fe__discover_by_columns(a)) {
                got = fe__discover_column_panel(a, k, col, q) ? q : 0;
            } else {
                /* A wide full accumulation: rows into the scratch panel. */
                double *z = a->work + dim * dim + dim;
                got = fe__discover_good_rows(col, dim, q);
                for (size_t t = 0; t < got; t++)
                    for (size_t c = 0; c < dim; c++)
                        z[t * dim + c] = col[c][t];
                if (got > 0)
                    fe__discover_panel(a, k, got);
            }
        }
        if (got > 0) {
            i += got;
            continue;
        }
        /* The panel holds a row the guard stops, or follows one: the row
           step decides, row by row, over the panel's rows. */
        for (size_t t = 0; t < q && rc == FE_OK; t++) {
            for (size_t c = 0; c < a->m; c++)
                row[c] = phi[c * ldphi + i];
            rc = fe_discover_add(a, row, r[i]);
            i += rc == FE_OK;
        }
    }
    if (done != NULL)
        *done = i;
    return rc;
}
/* Fold many rows ends here */
/* [[file:../literate/discover.org::Fold rows that carry their index][Fold rows that carry their index]] */
int fe_discover_rebind(fe_discover_acc *a, double *storage)
{
    if (a == NULL || storage == NULL)
        return FE_EINVAL;
    if (a->m == 0 || a->m > FE_DISCOVER_MAX_COLUMNS || a->blocks < 2
        || a->blocks > FE_DISCOVER_MAX_BLOCKS || a->base_cols > a->m
        || a->lags > FE_DISCOVER_LAGS || a->nhist > a->lags || a->nhead > a->lags
        || a->nshead > FE_DISCOVER_EDGE)
        return FE_ESIZE;
    fe__discover_layout(a, storage);
    return FE_OK;
}

int fe_discover_reset(fe_discover_acc *a)
{
    if (a == NULL || a->gram == NULL)
        return FE_EINVAL;
    memset(a->gram, 0, fe_discover_acc_doubles(a->m, a->blocks) * sizeof *a->gram);
    a->row0 = FE_DISCOVER_ROW_UNKNOWN;
    a->n = 0;
    a->have_prev = 0;
    a->first_linked = 1;
    a->nhist = 0;
    a->nhead = 0;
    a->head_open = 1;
    a->nshead = 0;
    a->shead_pending = 0;
    return FE_OK;
}

/* Whether fe_discover_add would accept the row right after a break
   (then no lag product is formed: only the block's sums can overflow). */
static int fe__discover_ok_after_break(const fe_discover_acc *a, const double *phi, double r)
{
    size_t dim = a->m + 1, k;
    double z[FE_DISCOVER_MAX_COLUMNS + 1];
    const double *g;
    for (size_t i = 0; i < a->m; i++)
        z[i] = phi[i];
    z[a->m] = r;
    for (size_t i = 0; i < dim; i++)
        if (!isfinite(z[i]))
            return FE_ENONFINITE;
    if (!fe__discover_large(z, dim))
        return FE_OK;
    k = fe__discover_block(a, a->row0 + a->n);
    g = a->gram + k * dim * dim;
    for (size_t i = 0; i < dim; i++)
        for (size_t j = i; j < dim; j++)
            if (fe__discover_kept(a, i, j) && !isfinite(g[i * dim + j] + z[i] * z[j]))
                return FE_ENONFINITE;
    return FE_OK;
}

int fe_discover_add_row(fe_discover_acc *a, const fe_discover_row *row)
{
    uint64_t row0;
    int rc;
    if (a == NULL || row == NULL || row->index == FE_DISCOVER_ROW_UNKNOWN || row->phi == NULL)
        return FE_EINVAL;
    row0 = a->row0;
    if (a->n == 0 && a->row0 == FE_DISCOVER_ROW_UNKNOWN)
        a->row0 = row->index;
    else if (row->index != a->row0 + a->n)
        return FE_EINVAL;
    /* A break closes the recording's edges, which cannot be undone bit for
       bit: the row is checked first, and the break made only for a row that
       will be folded. */
    if (row->starts_recording) {
        rc = fe__discover_ok_after_break(a, row->phi, row->r);
        if (rc != FE_OK) {
            a->row0 = row0;
            return rc;
        }
        fe_discover_break(a);
    }
    rc = fe_discover_add(a, row->phi, row->r);
    if (rc != FE_OK)            /* without a break: add changed nothing */
        a->row0 = row0;
    return rc;
}

int fe_discover_copy(fe_discover_acc *dst, const fe_discover_acc *src)
{
    double *storage;
    if (dst == NULL || src == NULL || dst->gram == NULL || src->gram == NULL)
        return FE_EINVAL;
    if (dst->m != src->m || dst->blocks != src->blocks
        || dst->fit_rows != src->fit_rows || dst->base_cols != src->base_cols
        || dst->lags != src->lags)
        return FE_EMISMATCH;
    if (dst == src)
        return FE_OK;
    storage = dst->gram;
    memcpy(storage, src->gram,
           fe_discover_acc_doubles(src->m, src->blocks) * sizeof *storage);
    *dst = *src;
    fe__discover_layout(dst, storage);
    return FE_OK;
}

static int fe__discover_init_fn(void *acc, void *ctx)
{
    (void)ctx;
    return fe_discover_reset(acc);
}

static int fe__discover_step_fn(void *acc, const void *obs, void *ctx)
{
    (void)ctx;
    return fe_discover_add_row(acc, obs);
}

static int fe__discover_merge_fn(void *acc, const void *other, void *ctx)
{
    (void)ctx;
    return fe_discover_merge(acc, other);
}

static int fe__discover_copy_fn(void *dst, const void *src, void *ctx)
{
    (void)ctx;
    return fe_discover_copy(dst, src);
}

fe_accumulator fe_discover_accumulator(void)
{
    fe_accumulator f = {
        .name = "discover",
        .acc_size = sizeof(fe_discover_acc),
        .obs_size = sizeof(fe_discover_row),
        .init = fe__discover_init_fn,
        .step = fe__discover_step_fn,
        .step_many = NULL,
        .merge = fe__discover_merge_fn,
        .copy = fe__discover_copy_fn,
        .ctx = NULL,
    };
    return f;
}
/* Fold rows that carry their index ends here */
/* [[file:../literate/discover.org::Workspace layout][Workspace layout]] */
typedef struct fe__ws {
    double *g;          /* M x M total Gram of fitted rows, full */
    double *css;        /* S x S Cholesky factor of G_SS */
    double *b;          /* S: G_SS^{-1} G_Sr */
    double *aj;         /* S x d: G_SS^{-1} G_SJ */
    double *sjj;        /* d x d Schur complement */
    double *cj;         /* d */
    double *ck;         /* K x d per-block shares */
    double *v;          /* d x d covariance of the shares */
    double *u;          /* K x S block gradients */
    double *omega;      /* S x S */
    double *tmp;        /* S x S */
    double *gt;         /* M x M prewhitened Gram matrix, full */
    double *inv;        /* S x S: its inverse on the model's columns */
    double *uv;         /* M: a series' weights on the columns */
    double *q;          /* P + 1 lagged sums of a series */
    double *acov;       /* P + 1 whitened autocovariances of a series */
    double *acov_e;     /* P + 1 those of the whitened residual */
    double *pair;       /* G x G, G = FE_DISCOVER_MAX_GROUPS: candidate
                           i's BIC change given candidate j, where it
                           passes (+inf where not): the pair step */
} fe__ws;

size_t fe_discover_workspace_doubles(size_t m, size_t blocks)
{
    size_t dim = m + 1, d = FE_DISCOVER_MAX_GROUP_SIZE;
    return dim * dim * 6 + dim * (d + 3) + d * d * 2 + d + blocks * d
           + blocks * dim + 3 * (FE_DISCOVER_LAGS + 1)
           + FE_DISCOVER_MAX_GROUPS * FE_DISCOVER_MAX_GROUPS + 64;
}

static int fe__ws_carve(fe__ws *w, double *work, size_t len, size_t m,
                        size_t blocks)
{
    size_t dim = m + 1, d = FE_DISCOVER_MAX_GROUP_SIZE;
    if (work == NULL || len < fe_discover_workspace_doubles(m, blocks))
        return FE_ESIZE;
    w->g = work;
    w->css = w->g + dim * dim;
    w->omega = w->css + dim * dim;
    w->tmp = w->omega + dim * dim;
    w->b = w->tmp + dim * dim;
    w->aj = w->b + dim;
    w->sjj = w->aj + dim * d;
    w->v = w->sjj + d * d;
    w->cj = w->v + d * d;
    w->ck = w->cj + d;
    w->u = w->ck + blocks * d;
    w->gt = w->u + blocks * dim;
    w->inv = w->gt + dim * dim;
    w->uv = w->inv + dim * dim;
    w->q = w->uv + dim;
    w->acov = w->q + FE_DISCOVER_LAGS + 1;
    w->acov_e = w->acov + FE_DISCOVER_LAGS + 1;
    w->pair = w->acov_e + FE_DISCOVER_LAGS + 1;
    return FE_OK;
}

/* Sum the fitted blocks into a full symmetric matrix. */
static void fe__total_gram(const fe_discover_acc *a, double *g)
{
    size_t dim = a->m + 1;
    memset(g, 0, dim * dim * sizeof *g);
    for (size_t k = 0; k < a->blocks; k++) {
        const double *gk = a->gram + k * dim * dim;
        for (size_t i = 0; i < dim; i++)
            for (size_t j = i; j < dim; j++)
                g[i * dim + j] += gk[i * dim + j];
    }
    for (size_t i = 0; i < dim; i++)
        for (size_t j = 0; j < i; j++)
            g[i * dim + j] = g[j * dim + i];
}
/* Workspace layout ends here */
/* [[file:../literate/discover.org::Factorise the model's Gram matrix][Factorise the model's Gram matrix]] */
typedef struct fe__model {
    size_t n;
    const size_t *cols;
    double *chol;       /* scaled Cholesky factor, n x n, row-major upper */
    double scale[FE_DISCOVER_MAX_COLUMNS];
} fe__model;

static int fe__factor(fe__model *mo, const double *g, size_t dim)
{
    for (size_t i = 0; i < mo->n; i++) {
        double d = g[mo->cols[i] * dim + mo->cols[i]];
        if (!(d > 0.0))
            return FE_ESINGULAR;
        mo->scale[i] = 1.0 / sqrt(d);
    }
    for (size_t i = 0; i < mo->n; i++)
        for (size_t j = 0; j < mo->n; j++)
            mo->chol[i * mo->n + j] = g[mo->cols[i] * dim + mo->cols[j]]
                                      * mo->scale[i] * mo->scale[j];
    if (mo->n == 0)
        return FE_OK;
    if (LAPACKE_dpotrf(LAPACK_ROW_MAJOR, 'U', (lapack_int)mo->n, mo->chol,
                       (lapack_int)mo->n) != 0)
        return FE_ESINGULAR;
    for (size_t i = 0; i < mo->n; i++)
        if (mo->chol[i * mo->n + i] < 1e-5)     /* pivot^2 < 1e-10 */
            return FE_ESINGULAR;
    return FE_OK;
}

/* x <- G_SS^{-1} x for `nrhs` right-hand sides stored as x[i * nrhs + r]. */
static void fe__solve(const fe__model *mo, double *x, size_t nrhs)
{
    if (mo->n == 0)
        return;
    for (size_t i = 0; i < mo->n; i++)
        for (size_t r = 0; r < nrhs; r++)
            x[i * nrhs + r] *= mo->scale[i]; /* NOLINT(clang-analyzer-core.uninitialized.Assign): callers fill x[0 .. n*nrhs) */
    LAPACKE_dpotrs(LAPACK_ROW_MAJOR, 'U', (lapack_int)mo->n, (lapack_int)nrhs,
                   mo->chol, (lapack_int)mo->n, x, (lapack_int)nrhs);
    for (size_t i = 0; i < mo->n; i++)
        for (size_t r = 0; r < nrhs; r++)
            x[i * nrhs + r] *= mo->scale[i];
}
/* Factorise the model's Gram matrix ends here */
/* [[file:../literate/discover.org::Fit a set of columns][Fit a set of columns]] */
static double fe__quad_resid(const double *m, size_t dim, const size_t *cols,
                             size_t n, const double *beta, size_t r, int sym)
{
    /* w^T X w with w = (-beta on cols, 1 on r); X full (sym = 0) or
       upper-triangle symmetric (sym = 1). */
    double s = sym ? fe__sym(m, dim, r, r) : m[r * dim + r];
    for (size_t i = 0; i < n; i++) {
        double xir = sym ? fe__sym(m, dim, cols[i], r) : m[cols[i] * dim + r];
        double xri = sym ? xir : m[r * dim + cols[i]];
        s -= beta[i] * (xir + xri);
        for (size_t j = 0; j < n; j++)
            s += beta[i] * beta[j]
                 * (sym ? fe__sym(m, dim, cols[i], cols[j]) : m[cols[i] * dim + cols[j]]);
    }
    return s;
}

/* The final model against the baseline on the held-out rows, as a z:
   with d = beta_final - beta_baseline (the baseline's columns come first),
   RSS_final - RSS_baseline = Q - 2 L, Q = d^T H d and L = d^T h, h the
   held-out rows' x_t e_t under the baseline.  Were the terms worth nothing
   there, L would be noise of variance sigma^2 Q over what a row is worth
   (the noise's correlation along a slow d^T x_t), so the difference is
   divided by 2 sigma sqrt(Q / worth). */
static double fe__heldout_z(const fe_discover_acc *a, const fe_discover_result *res)
{
    size_t dim = a->m + 1, K = a->blocks;
    const double *h = a->gram + K * dim * dim;
    const fe_discover_step *base = &res->path[0];
    double d[FE_DISCOVER_MAX_COLUMNS] = {0}, q = 0.0, n = a->counts[K], diff, sd, worth;
    if (!(n > 0) || res->steps == 0)
        return NAN;
    for (size_t i = 0; i < res->ncols; i++)
        d[i] = res->coef[i] - (i < base->ncols ? base->coef[i] : 0.0);
    for (size_t i = 0; i < res->ncols; i++)
        for (size_t j = 0; j < res->ncols; j++)
            q += d[i] * d[j] * fe__sym(h, dim, res->cols[i], res->cols[j]);
    diff = n * (res->final.heldout_rms * res->final.heldout_rms
                - res->baseline.heldout_rms * res->baseline.heldout_rms);
    worth = fe_discover_row_worth(&res->noise, res->final.n);
    sd = 2.0 * res->final.rms * sqrt((q > 0.0 ? q : 0.0) / worth);
    return sd > 0.0 ? diff / sd : NAN;
}

/* The held-out rows' RMS under the coefficients (NaN without any). */
static void fe__heldout(const fe_discover_acc *a, const size_t *cols, size_t ncols,
                        const double *coef, fe_discover_fit *fit)
{
    size_t dim = a->m + 1, K = a->blocks;
    fit->heldout_n = a->counts[K];
    if (a->counts[K] > 0) {
        double h = fe__quad_resid(a->gram + K * dim * dim, dim, cols, ncols, coef, a->m, 1);
        fit->heldout_rms = sqrt((h > 0 ? h : 0) / a->counts[K]);
    } else {
        fit->heldout_rms = NAN;
    }
}

/* What a fit of chosen columns needs: the columns below `limit`, the
   workspace carved, every block with rows, the total Gram matrix. */
static int fe__fit_prepare(const fe_discover_acc *a, const size_t *cols, size_t ncols,
                           size_t limit, fe__ws *w, double *work, size_t work_doubles)
{
    int rc;
    if (ncols > a->m)
        return FE_EINVAL;
    for (size_t i = 0; i < ncols; i++)
        if (cols[i] >= limit)
            return FE_EINVAL;
    rc = fe__ws_carve(w, work, work_doubles, a->m, a->blocks);
    if (rc != FE_OK)
        return rc;
    for (size_t k = 0; k < a->blocks; k++)
        if (a->counts[k] < 1.0)
            return FE_ETOOFEW;
    fe__total_gram(a, w->g);
    return FE_OK;
}

static int fe__fit(const fe_discover_acc *a, const fe__ws *w, const size_t *cols,
                   size_t ncols, double *coef, double *se, fe_discover_fit *fit)
{
    size_t dim = a->m + 1, r = a->m, K = a->blocks;
    fe__model mo = {ncols, cols, w->css, {0}};
    double n = 0, num, den, rho;
    int rc = fe__factor(&mo, w->g, dim);
    if (rc != FE_OK)
        return rc;
    for (size_t k = 0; k < K; k++)
        n += a->counts[k];
    for (size_t i = 0; i < ncols; i++)
        coef[i] = w->g[cols[i] * dim + r];
    fe__solve(&mo, coef, 1);
    fit->rss = fe__quad_resid(w->g, dim, cols, ncols, coef, r, 0);
    if (fit->rss < 0.0)
        fit->rss = 0.0;
    fit->n = n;
    fit->params = ncols;
    fit->rms = sqrt(fit->rss / n);
    num = fe__quad_resid(a->lag, dim, cols, ncols, coef, r, 0);
    den = fit->rss;
    rho = den > 0.0 ? num / den : 0.0;
    fit->lag1 = rho;
    fit->floor = sqrt(den > num ? (den - num) / n : 0.0);
    if (rho < 0.0)
        rho = 0.0;
    if (rho > 0.99)
        rho = 0.99;
    fit->n_eff = n * (1.0 - rho) / (1.0 + rho);
    fit->bic = fit->n_eff * log(fit->rss > 0 ? fit->rss / n : 1e-300)
               + (double)ncols * log(fit->n_eff);
    fe__heldout(a, cols, ncols, coef, fit);
    /* Block sandwich standard errors. */
    if (se != NULL && ncols > 0) {
        memset(w->omega, 0, ncols * ncols * sizeof *w->omega);
        for (size_t k = 0; k < K; k++) {
            const double *gk = a->gram + k * dim * dim;
            double *u = w->u;
            for (size_t i = 0; i < ncols; i++) {
                u[i] = fe__sym(gk, dim, cols[i], r);
                for (size_t j = 0; j < ncols; j++)
                    u[i] -= fe__sym(gk, dim, cols[i], cols[j]) * coef[j];
            }
            for (size_t i = 0; i < ncols; i++)
                for (size_t j = 0; j < ncols; j++)
                    w->omega[i * ncols + j] += u[i] * u[j];
        }
        for (size_t i = 0; i < ncols * ncols; i++)
            w->omega[i] *= (double)K / (double)(K - 1);
        /* tmp = G^{-1} Omega; then se_i^2 = (G^{-1} (G^{-1} Omega)^T)_ii. */
        memcpy(w->tmp, w->omega, ncols * ncols * sizeof *w->tmp);
        fe__solve(&mo, w->tmp, ncols);
        for (size_t i = 0; i < ncols; i++)
            for (size_t j = i + 1; j < ncols; j++) {
                double t = w->tmp[i * ncols + j];
                w->tmp[i * ncols + j] = w->tmp[j * ncols + i];
                w->tmp[j * ncols + i] = t;
            }
        fe__solve(&mo, w->tmp, ncols);
        for (size_t i = 0; i < ncols; i++)
            se[i] = sqrt(fabs(w->tmp[i * ncols + i]));
    }
    return FE_OK;
}

int fe_discover_fit_columns(const fe_discover_acc *a, const size_t *cols,
                            size_t ncols, double *coef, double *stderr_,
                            fe_discover_fit *fit, double *work,
                            size_t work_doubles)
{
    fe__ws w;
    int rc;
    if (a == NULL || fit == NULL || (ncols > 0 && (cols == NULL || coef == NULL)))
        return FE_EINVAL;
    /* From a screen, only its base columns (a->base_cols is a->m in a full
       accumulation). */
    rc = fe__fit_prepare(a, cols, ncols, a->base_cols, &w, work, work_doubles);
    return rc != FE_OK ? rc : fe__fit(a, &w, cols, ncols, coef, stderr_, fit);
}
/* Fit a set of columns ends here */
/* [[file:../literate/discover.org::Score a candidate against the model][Score a candidate against the model]] */
/* The drop in RSS, Delta_J = c^T S_JJ^{-1} c, of adding group `gr` to
   the model `mo` (factored from g, coefficients beta), all from the Gram
   matrix g (full, M x M): a_J, S_JJ and c_J are left in w.  Returns 0,
   and sets no drop, when the candidate is already expressible by the
   model (a tiny Schur complement). */
static int fe__drop(const double *g, size_t dim, const fe__ws *w, const fe__model *mo,
                    const double *beta, const fe_discover_group *gr, double *drop)
{
    size_t r = dim - 1, d = gr->count, s = mo->n;
    double sc[FE_DISCOVER_MAX_GROUP_SIZE * FE_DISCOVER_MAX_GROUP_SIZE];
    double x[FE_DISCOVER_MAX_GROUP_SIZE];
    /* a_J = G_SS^{-1} G_SJ. */
    for (size_t i = 0; i < s; i++)
        for (size_t q = 0; q < d; q++)
            w->aj[i * d + q] = g[mo->cols[i] * dim + gr->first + q];
    fe__solve(mo, w->aj, d);
    /* S_JJ and c_J. */
    for (size_t p = 0; p < d; p++) {
        size_t jp = gr->first + p;
        w->cj[p] = g[jp * dim + r];
        for (size_t i = 0; i < s; i++)
            w->cj[p] -= g[jp * dim + mo->cols[i]] * beta[i];
        for (size_t q = 0; q < d; q++) {
            double v = g[jp * dim + gr->first + q];
            for (size_t i = 0; i < s; i++)
                v -= g[jp * dim + mo->cols[i]] * w->aj[i * d + q];
            w->sjj[p * d + q] = v;
        }
    }
    for (size_t p = 0; p < d; p++) {
        double gjj = g[(gr->first + p) * dim + gr->first + p];
        if (!(w->sjj[p * d + p] > 1e-9 * gjj))
            return 0;
    }
    memcpy(sc, w->sjj, d * d * sizeof *sc);
    memcpy(x, w->cj, d * sizeof *x);
    if (LAPACKE_dposv(LAPACK_ROW_MAJOR, 'U', (lapack_int)d, 1, sc, (lapack_int)d,
                      x, 1) != 0)
        return 0;
    *drop = 0.0;
    for (size_t p = 0; p < d; p++)
        *drop += w->cj[p] * x[p];
    return 1;
}

static void fe__score(const fe_discover_acc *a, const fe__ws *w,
                      const fe__model *mo, const double *beta,
                      const fe_discover_group *gr, double rss,
                      const fe_discover_fit *cur, fe_discover_rank *out)
{
    size_t dim = a->m + 1, r = a->m, K = a->blocks, d = gr->count, s = mo->n;
    double drop = 0.0, t2 = 0.0;
    memset(out, 0, sizeof *out);
    out->p_value = 1.0;
    if (!fe__drop(w->g, dim, w, mo, beta, gr, &drop)) {
        out->redundant = 1;
        return;
    }
    /* Per-block shares c_{J,k}. */
    for (size_t k = 0; k < K; k++) {
        const double *gk = a->gram + k * dim * dim;
        for (size_t p = 0; p < d; p++) {
            size_t jp = gr->first + p;
            double v = fe__sym(gk, dim, jp, r);
            for (size_t i = 0; i < s; i++) {
                size_t ci = mo->cols[i];
                double gsr = fe__sym(gk, dim, ci, r), gjs = fe__sym(gk, dim, jp, ci);
                double gsb = 0.0;
                for (size_t l = 0; l < s; l++)
                    gsb += fe__sym(gk, dim, ci, mo->cols[l]) * beta[l];
                v += -w->aj[i * d + p] * gsr - gjs * beta[i] + w->aj[i * d + p] * gsb;
            }
            w->ck[k * d + p] = v;
        }
    }
    /* Hotelling's T^2 over the K shares. */
    {
        double mean[FE_DISCOVER_MAX_GROUP_SIZE] = {0};
        double vv[FE_DISCOVER_MAX_GROUP_SIZE * FE_DISCOVER_MAX_GROUP_SIZE] = {0};
        double x[FE_DISCOVER_MAX_GROUP_SIZE];
        for (size_t k = 0; k < K; k++)
            for (size_t p = 0; p < d; p++)
                mean[p] += w->ck[k * d + p] / (double)K;
        for (size_t k = 0; k < K; k++)
            for (size_t p = 0; p < d; p++)
                for (size_t q = 0; q < d; q++)
                    vv[p * d + q] += (w->ck[k * d + p] - mean[p])
                                     * (w->ck[k * d + q] - mean[q]) / (double)(K - 1);
        memcpy(x, mean, d * sizeof *x);
        if (K > d && LAPACKE_dposv(LAPACK_ROW_MAJOR, 'U', (lapack_int)d, 1, vv,
                                   (lapack_int)d, x, 1) == 0) {
            for (size_t p = 0; p < d; p++)
                t2 += (double)K * mean[p] * x[p];
            if (d == 1) {
                out->statistic = (mean[0] >= 0 ? 1.0 : -1.0) * sqrt(t2);
                out->p_value = fe_student_t_two_sided(out->statistic, (double)(K - 1));
            } else {
                out->statistic = (double)(K - d) / ((double)d * (double)(K - 1)) * t2;
                out->p_value = fe_f_upper(out->statistic, (double)d, (double)(K - d));
            }
        } else {
            /* Shares without spread: an exact fit; nothing to test. */
            out->statistic = 0.0;
            out->p_value = 1.0;
        }
    }
    out->rss_drop = drop > 0.0 ? drop : 0.0;
    {
        double after = rss - out->rss_drop;
        double n = cur->n, ne = cur->n_eff;
        if (after < 1e-300)
            after = 1e-300;
        out->delta_bic = ne * log(after / n) + (double)(cur->params + d) * log(ne)
                         - cur->bic;
    }
}
/* Score a candidate against the model ends here */
/* [[file:../literate/discover.org::Fit the noise model][Fit the noise model]] */
int fe_discover_noise_fit(const double *q, double n, size_t maxp,
                          fe_discover_noise *nz)
{
    double phi[FE_DISCOVER_LAGS], prev[FE_DISCOVER_LAGS], sig, best, sum = 0.0;
    if (q == NULL || nz == NULL || !(n >= 2.0) || maxp >= FE_DISCOVER_LAGS)
        return FE_EINVAL;
    memset(nz, 0, sizeof *nz);
    nz->kind = FE_DISCOVER_NOISE_AR;
    nz->portmanteau_p = NAN;
    nz->variance = q[0] / n;
    nz->innovation_variance = nz->variance;
    nz->n_eff = n;
    if (!(q[0] > 0.0) || !isfinite(q[0]))
        return FE_OK;
    sig = q[0];
    best = n * log(sig / n);
    for (size_t k = 1; k <= maxp; k++) {
        double acc = q[k], kappa, bic;
        for (size_t i = 1; i < k; i++)
            acc -= prev[i - 1] * q[k - i];
        kappa = acc / sig;
        if (!(fabs(kappa) < 1.0))
            break;
        for (size_t i = 1; i < k; i++)
            phi[i - 1] = prev[i - 1] - kappa * prev[k - i - 1];
        phi[k - 1] = kappa;
        sig *= 1.0 - kappa * kappa;
        memcpy(prev, phi, k * sizeof *phi);
        if (!(sig > 0.0))
            break;
        bic = n * log(sig / n) + (double)k * log(n);
        if (bic < best) {
            best = bic;
            nz->order = k;
            memcpy(nz->phi, phi, k * sizeof *phi);
            nz->innovation_variance = sig / n;
        }
    }
    for (size_t i = 0; i < nz->order; i++)
        sum += nz->phi[i];
    nz->n_eff = n * nz->variance * (1.0 - sum) * (1.0 - sum) / nz->innovation_variance;
    if (nz->n_eff < 1.0)
        nz->n_eff = 1.0;
    return FE_OK;
}

/* The whitening filter alpha (alpha_0 = 1, alpha_i = -phi_i) and its
   autocorrelation c_l = sum_i alpha_i alpha_{i+l}, l = 0 .. p. */
static void fe__whitening(const fe_discover_noise *nz, double *alpha, double *c)
{
    size_t p = nz->order;
    alpha[0] = 1.0;
    for (size_t i = 1; i <= p; i++)
        alpha[i] = -nz->phi[i - 1];
    for (size_t l = 0; l <= p; l++) {
        c[l] = 0.0;
        for (size_t i = 0; i + l <= p; i++)
            c[l] += alpha[i] * alpha[i + l];
    }
}

/* The lagged sums q_l = u^T Z_l u, l = 0 .. P, of the series u^T z_t
   (Z_0 = g, the total Gram matrix, full). */
static void fe__lagged_sums(const fe_discover_acc *a, const double *g,
                            const double *u, double *q)
{
    size_t dim = a->m + 1;
    for (size_t l = 0; l <= a->lags; l++) {
        const double *z = l == 0 ? g : a->zlag + (l - 1) * dim * dim;
        double s = 0.0;
        for (size_t i = 0; i < dim; i++) {
            double t = 0.0;
            if (u[i] == 0.0)
                continue;
            for (size_t j = 0; j < dim; j++)
                t += z[i * dim + j] * u[j];
            s += u[i] * t;
        }
        q[l] = s;
    }
}

/* gt -= v v^T. */
static void fe__drop_row(double *gt, size_t dim, const double *v)
{
    for (size_t i = 0; i < dim; i++)
        for (size_t j = 0; j < dim; j++)
            gt[i * dim + j] -= v[i] * v[j];
}

/* The transient rows of a recording's start, sum_{i <= t} alpha_i z_{t-i}
   for t < p, from its first `count` rows (zeros past them), out of gt. */
static void fe__drop_start(double *gt, size_t dim, const double *alpha, size_t p,
                           const double *rows, size_t count)
{
    double v[FE_DISCOVER_MAX_COLUMNS + 1];
    for (size_t t = 0; t < p; t++) {
        for (size_t k = 0; k < dim; k++) {
            v[k] = 0.0;
            for (size_t i = 0; i <= t; i++)
                if (t - i < count)
                    v[k] += alpha[i] * rows[(t - i) * dim + k];
        }
        fe__drop_row(gt, dim, v);
    }
}

/* The transient rows past a recording's end, sum_{i >= u} alpha_i
   z_{n-1+u-i} for u = 1 .. p, from its last `count` rows newest first
   (rows[j] = z_{n-1-j}), out of gt. */
static void fe__drop_end(double *gt, size_t dim, const double *alpha, size_t p,
                         const double *rows, size_t count)
{
    double v[FE_DISCOVER_MAX_COLUMNS + 1];
    for (size_t u = 1; u <= p; u++) {
        for (size_t k = 0; k < dim; k++) {
            v[k] = 0.0;
            for (size_t i = u; i <= p; i++)
                if (i - u < count)
                    v[k] += alpha[i] * rows[(i - u) * dim + k];
        }
        fe__drop_row(gt, dim, v);
    }
}

/* gt -= every recording's 2p transient rows: those of recordings closed
   in the fold from the stacked sums (block (x, y) of edge_start is
   sum z_x z_y^T over recordings), the first recording's start from head
   (when the accumulation begins it), the open one's from shead and hist. */
static void fe__drop_transients(const fe_discover_acc *a, const double *alpha, size_t p,
                                double *gt)
{
    size_t dim = a->m + 1, ne = FE_DISCOVER_EDGE * dim;
    if (p == 0)
        return;
    for (size_t t = 0; t < p; t++)
        for (size_t i = 0; i <= t; i++)
            for (size_t j = 0; j <= t; j++) {
                const double *S = a->edge_start + (t - i) * dim * ne + (t - j) * dim;
                for (size_t x = 0; x < dim; x++)
                    for (size_t y = 0; y < dim; y++)
                        gt[x * dim + y] -= alpha[i] * alpha[j] * S[x * ne + y];
            }
    for (size_t u = 1; u <= p; u++)
        for (size_t i = u; i <= p; i++)
            for (size_t j = u; j <= p; j++) {
                const double *S = a->edge_end + (i - u) * dim * ne + (j - u) * dim;
                for (size_t x = 0; x < dim; x++)
                    for (size_t y = 0; y < dim; y++)
                        gt[x * dim + y] -= alpha[i] * alpha[j] * S[x * ne + y];
            }
    if (a->nhead >= FE_DISCOVER_EDGE && (a->row0 == 0 || !a->first_linked))
        fe__drop_start(gt, dim, alpha, p, a->head, p);
    if (a->nhist >= FE_DISCOVER_EDGE)
        fe__drop_end(gt, dim, alpha, p, a->hist, p);
}

/* The prewhitened Gram matrix gt = c_0 g + sum_l c_l (Z_l + Z_l^T), less
   the 2p transient rows at every recording's two ends (see the text). */
static void fe__whiten_gram(const fe_discover_acc *a, const double *g,
                            const fe_discover_noise *nz, double *gt)
{
    size_t dim = a->m + 1, p = nz->order;
    double alpha[FE_DISCOVER_LAGS + 1], c[FE_DISCOVER_LAGS + 1];
    fe__whitening(nz, alpha, c);
    for (size_t i = 0; i < dim * dim; i++)
        gt[i] = c[0] * g[i];
    for (size_t l = 1; l <= p; l++) {
        const double *z = a->zlag + (l - 1) * dim * dim;
        for (size_t i = 0; i < dim; i++)
            for (size_t j = 0; j < dim; j++)
                gt[i * dim + j] += c[l] * (z[i * dim + j] + z[j * dim + i]);
    }
    fe__drop_transients(a, alpha, p, gt);
}

/* The whitened series' autocovariances (unnormalised) at lags h = 0 ..
   H = P - p from its lagged sums q_0 .. q_P: sum_{i,k} alpha_i alpha_k
   q_|h+k-i|.  Returns H. */
static size_t fe__white_acov(const double *q, size_t P, const fe_discover_noise *nz,
                             double *out)
{
    size_t p = nz->order, H = P - p;
    double alpha[FE_DISCOVER_LAGS + 1], c[FE_DISCOVER_LAGS + 1];
    fe__whitening(nz, alpha, c);
    for (size_t h = 0; h <= H; h++) {
        double s = 0.0;
        for (size_t i = 0; i <= p; i++)
            for (size_t k = 0; k <= p; k++) {
                size_t d = h + k >= i ? h + k - i : i - h - k;
                s += alpha[i] * alpha[k] * q[d];
            }
        out[h] = s;
    }
    return H;
}
/* Fit the noise model ends here */
/* [[file:../literate/discover.org::What a row is worth][What a row is worth]] */
double fe_discover_row_worth(const fe_discover_noise *nz, double n)
{
    double w;
    if (nz == NULL)
        return 1.0;
    w = n > 0 ? nz->n_eff / n : 1.0;
    if (nz->long_range)
        w /= nz->block_ratio;
    return w > 1.0 ? 1.0 : w < 1e-6 ? 1e-6 : w;
}
/* What a row is worth ends here */
/* [[file:../literate/discover.org::Fit by generalised least squares][Fit by generalised least squares]] */
/* u <- the weights of the residual r - sum coef_i z_cols[i] on the columns. */
static void fe__residual_weights(size_t dim, const size_t *cols, size_t ncols,
                                 const double *coef, double *u)
{
    memset(u, 0, dim * sizeof *u);
    u[dim - 1] = 1.0;
    for (size_t i = 0; i < ncols; i++)
        u[cols[i]] -= coef[i];
}

/* u^T g u for a full matrix g. */
static double fe__quad(const double *g, size_t dim, const double *u)
{
    double s = 0.0;
    for (size_t i = 0; i < dim; i++) {
        double t = 0.0;
        for (size_t j = 0; j < dim; j++)
            t += g[i * dim + j] * u[j];
        s += u[i] * t;
    }
    return s;
}

static double fe__fitted_rows(const fe_discover_acc *a)
{
    double n = 0.0;
    for (size_t k = 0; k < a->blocks; k++)
        n += a->counts[k];
    return n;
}

/* The whitened series x~ of x_t = u^T z_t summed over each fitted block,
   from the blocks' sums of rows: alpha(1) u^T s_k (the filter's edge rows
   aside), as deviations from the overall mean; their sum of squares
   divided by each block's rows: sum_k n_k xbar_k^2. */
static double fe__block_energy(const fe_discover_acc *a, const double *u,
                               const fe_discover_noise *nz)
{
    size_t dim = a->m + 1, K = a->blocks;
    double alpha1 = 1.0, n = fe__fitted_rows(a), mean = 0.0, e = 0.0;
    for (size_t i = 0; i < nz->order; i++)
        alpha1 -= nz->phi[i];
    for (size_t k = 0; k < K; k++)
        for (size_t c = 0; c < dim; c++)
            mean += alpha1 * u[c] * a->bsum[k * dim + c] / n;
    for (size_t k = 0; k < K; k++) {
        double b = 0.0;
        for (size_t c = 0; c < dim; c++)
            b += alpha1 * u[c] * a->bsum[k * dim + c];
        b -= a->counts[k] * mean;
        if (a->counts[k] > 0)
            e += b * b / a->counts[k];
    }
    return e;
}

/* R for the residual with weights u: the variance of the whitened
   residual's block means, times the block length, over its variance per
   row; tested against chi-square with K - 1 degrees of freedom.  Blocks
   shorter than 20 rows are too short to tell (R = 1, not tested). */
static void fe__block_ratio(const fe_discover_acc *a, const double *u, fe_discover_noise *nz)
{
    double n = fe__fitted_rows(a), K = (double)a->blocks;
    double var = nz->innovation_variance;
    nz->block_ratio = 1.0;
    nz->block_p = NAN;
    nz->long_range = 0;
    if (n / K < 20.0 || !(var > 0.0))
        return;
    nz->block_ratio = fe__block_energy(a, u, nz) / (K - 1.0) / var;
    nz->block_p = fe_chi2_upper((K - 1.0) * nz->block_ratio, K - 1.0);
    nz->long_range = nz->block_p < 0.05 && nz->block_ratio > 1.0;
}

/* The Haar energies of x[0 .. B-1], B = 2^J, overwriting x: e[j-1] for
   j = 1 .. J the sum of squares of level j's B / 2^j detail coefficients
   (each the difference of two sums of 2^(j-1) entries, over
   sqrt(2^j)), e[J] the square of the scaling coefficient sum x / sqrt(B).
   The transform is orthonormal: the energies add up to sum x^2. */
static size_t fe__haar(double *x, size_t B, double *e)
{
    size_t J = 0;
    for (size_t len = B; len > 1; len /= 2) {
        double s = 0.0;
        for (size_t i = 0; i < len / 2; i++) {
            double d = (x[2 * i] - x[2 * i + 1]) * 0.70710678118654752440;
            x[i] = (x[2 * i] + x[2 * i + 1]) * 0.70710678118654752440;
            s += d * d;
        }
        e[J++] = s;
    }
    e[J] = B > 0 ? x[0] * x[0] : 0.0;
    return J;
}

/* The fine-block sums of the series u^T z_t, over sqrt(L), L = n / B. */
static void fe__fine_series(const fe_discover_acc *a, const double *u, double *y)
{
    size_t dim = a->m + 1;
    double root = sqrt(fe__fitted_rows(a) / (double)a->fine);
    for (size_t k = 0; k < a->fine; k++) {
        double s = 0.0;
        for (size_t c = 0; c < dim; c++)
            if (u[c] != 0.0)
                s += u[c] * a->fsum[k * dim + c];
        y[k] = s / root;
    }
}

enum { FE__SCALE_TERMS = 1 << 22 };     /* most lags an AR sum follows */

/* The AR model's autocovariances per unit innovation variance at lags
   0 .. p, g_h = sum_i psi_i psi_{i+h}, from its impulse response psi. */
static void fe__ar_acov(const fe_discover_noise *nz, double *g)
{
    size_t p = nz->order;
    double psi[FE_DISCOVER_LAGS + 1] = {0};   /* psi_{t-i} at (t - i) mod (p + 1) */
    for (size_t h = 0; h <= p; h++)
        g[h] = 0.0;
    for (size_t t = 0; t < FE__SCALE_TERMS; t++) {
        double v = t == 0 ? 1.0 : 0.0, big = 0.0;
        for (size_t i = 1; i <= p && i <= t; i++)
            v += nz->phi[i - 1] * psi[(t - i) % (p + 1)];
        psi[t % (p + 1)] = v;
        for (size_t h = 0; h <= p && h <= t; h++)
            g[h] += v * psi[(t - h) % (p + 1)];
        for (size_t i = 0; i <= p; i++)
            big = fmax(big, fabs(psi[i]));
        if (t > p && big < 1e-12)
            break;
    }
}

/* v(m) = m g_0 + 2 sum_{h<m} (m - h) g_h, the variance of a sum of m
   consecutive rows of the AR model nz per unit innovation variance, for
   the `count` lengths m[] in increasing order, into v[]: a walk over the
   lags with c0 = sum g_h and c1 = sum h g_h so far, v(m) = m (g_0 + 2 c0)
   - 2 c1 at h = m; once g is negligible the sums stop changing and the
   rest are read at once. */
static void fe__ar_sum_variances(const fe_discover_noise *nz, const uint64_t *m,
                                 size_t count, double *v)
{
    size_t p = nz->order, next = 0;
    double g[FE_DISCOVER_LAGS + 1], hist[FE_DISCOVER_LAGS + 1], c0 = 0.0, c1 = 0.0;
    fe__ar_acov(nz, g);
    for (size_t i = 0; i <= p; i++)
        hist[i] = g[i];
    for (uint64_t h = 1; next < count; h++) {
        double gh = 0.0;
        while (next < count && m[next] <= h) {
            v[next] = (double)m[next] * (g[0] + 2.0 * c0) - 2.0 * c1;
            next++;
        }
        if (next == count)
            break;
        if (h <= p)
            gh = g[h];
        else
            for (size_t i = 1; i <= p; i++)
                gh += nz->phi[i - 1] * hist[(h - i) % (p + 1)];
        hist[h % (p + 1)] = gh;
        c0 += gh;
        c1 += (double)h * gh;
        if ((h > p && fabs(gh) < 1e-14 * g[0]) || h >= FE__SCALE_TERMS)
            for (; next < count; next++)
                v[next] = (double)m[next] * (g[0] + 2.0 * c0) - 2.0 * c1;
    }
}

/* m_j: the rows on either side of a Haar coefficient of level j of the
   fine blocks, n 2^(j-1) / B rounded, at least 1 (n the fitted rows). */
static double fe__level_rows(const fe_discover_acc *a, size_t j)
{
    double m = floor(fe__fitted_rows(a) * (double)((size_t)1 << (j - 1)) / (double)a->fine + 0.5);
    return m < 1.0 ? 1.0 : m;
}

/* nz->scale_model: the variance of a Haar coefficient of the fine block
   sums that the AR model nz predicts, per unit innovation variance, at
   each level j = 1 .. J of the B = 2^J blocks (two halves of m_j rows,
   m_j = n 2^(j-1) / B rounded): (4 v(m_j) - v(2 m_j)) / (2 m_j); and of
   the scaling coefficient, v(n) / n. */
static void fe__scale_model(const fe_discover_acc *a, fe_discover_noise *nz)
{
    size_t J = 0;
    double n = fe__fitted_rows(a), v[2 * FE_DISCOVER_SCALES + 1];
    uint64_t m[2 * FE_DISCOVER_SCALES + 1];
    for (size_t b = a->fine; b > 1; b /= 2)
        J++;
    nz->scales = J;
    if (J == 0)
        return;
    /* m_1, 2 m_1, m_2, 2 m_2, ..., n: increasing, as m_j >= 2 m_{j-1} - 1
       is not guaranteed by rounding, sorted below. */
    for (size_t j = 1; j <= J; j++) {
        m[2 * j - 2] = (uint64_t)fe__level_rows(a, j);
        m[2 * j - 1] = 2 * m[2 * j - 2];
    }
    m[2 * J] = (uint64_t)n;
    {
        uint64_t sorted[2 * FE_DISCOVER_SCALES + 1];
        double vs[2 * FE_DISCOVER_SCALES + 1];
        size_t count = 2 * J + 1;
        memcpy(sorted, m, count * sizeof *m);
        for (size_t i = 1; i < count; i++)         /* insertion sort */
            for (size_t k = i; k > 0 && sorted[k - 1] > sorted[k]; k--) {
                uint64_t t = sorted[k];
                sorted[k] = sorted[k - 1];
                sorted[k - 1] = t;
            }
        fe__ar_sum_variances(nz, sorted, count, vs);
        for (size_t i = 0; i < count; i++)
            for (size_t k = 0; k < count; k++)
                if (sorted[k] == m[i])
                    v[i] = vs[k];
    }
    for (size_t j = 1; j <= J; j++)
        nz->scale_model[j - 1] = (4.0 * v[2 * j - 2] - v[2 * j - 1]) / (2.0 * (double)m[2 * j - 2]);
    nz->scale_model[J] = v[2 * J] / (double)m[2 * J];
}

/* |alpha(e^{i w})|^2, the whitening filter's power at w radians a row. */
static double fe__filter_power(const fe_discover_noise *nz, double w)
{
    double re = 1.0, im = 0.0;
    for (size_t i = 1; i <= nz->order; i++) {
        re -= nz->phi[i - 1] * cos((double)i * w);
        im += nz->phi[i - 1] * sin((double)i * w);
    }
    return re * re + im * im;
}

/* The shares lambda_t, t = 1 .. J + 1, of a series' whitened energy
   `energy` in the Haar levels of its fine-block sums (level J + 1: the
   scaling coefficient), each level's raw energy scaled by the whitening
   filter's power at its frequency, pi / m_t radians a row for levels of
   m_t rows a side (the filter's gain at zero for the scaling
   coefficient).  Returns their sum (not clamped). */
static double fe__scale_shares(const fe_discover_acc *a, const fe_discover_noise *nz,
                               const double *u, double energy, double *lam)
{
    double y[FE_DISCOVER_FINE_BLOCKS] = {0}, e[FE_DISCOVER_SCALES + 1] = {0};
    double n = fe__fitted_rows(a), total = 0.0;
    size_t J = nz->scales;
    fe__fine_series(a, u, y);
    fe__haar(y, a->fine, e);
    for (size_t t = 1; t <= J + 1; t++) {
        double mt = n * (double)((size_t)1 << (t - 1)) / (double)a->fine;
        double w = t <= J ? 3.14159265358979323846 / mt : 0.0;
        lam[t - 1] = energy > 0.0 ? fe__filter_power(nz, w) * e[t - 1] / energy : 0.0;
        total += lam[t - 1];
    }
    return total;
}

/* nz->scale_used: the Haar coefficients of each level that the model's
   columns take up, sum_c lambda_t(q_c) over a basis q_c of the columns
   orthonormal in the whitened metric, read off the model's factor:
   with D G~ D = U^T U, the columns of X~ D U^{-1}. */
static void fe__scale_used(const fe_discover_acc *a, const fe__model *mo,
                           fe_discover_noise *nz)
{
    size_t dim = a->m + 1, s = mo->n;
    double u[FE_DISCOVER_MAX_COLUMNS + 1], v[FE_DISCOVER_MAX_COLUMNS];
    double lam[FE_DISCOVER_SCALES + 1] = {0};
    memset(nz->scale_used, 0, sizeof nz->scale_used);
    for (size_t c = 0; c < s && nz->scales > 0; c++) {
        for (size_t i = c + 1; i-- > 0;) {      /* U v = e_c, back substitution */
            double t = i == c ? 1.0 : 0.0;
            for (size_t k = i + 1; k <= c; k++)
                t -= mo->chol[i * s + k] * v[k];
            v[i] = t / mo->chol[i * s + i];
        }
        memset(u, 0, dim * sizeof *u);
        for (size_t i = 0; i <= c; i++)
            u[mo->cols[i]] = mo->scale[i] * v[i];
        fe__scale_shares(a, nz, u, 1.0, lam);
        for (size_t t = 0; t <= nz->scales; t++)
            nz->scale_used[t] += lam[t];
    }
}

/* The fit of the residual's level ratios V_t, t = 1 .. J + 1, to its
   fine-block sums.  Level i's B / 2^i Haar coefficients, less the d_i
   that the model takes up (`used`), give
   y_i = ln(E_i / (k_i var h_i)) less the chi-square bias of a log,
   psi(k_i/2) - ln(k_i/2), with k_i = B / 2^i - d_i, and variance
   psi'(k_i/2) (h_i the AR prediction nz->scale_model, var the innovation
   variance).  ln V_t is the line through the levels, weighted by
   1 / psi'(k_i/2), with slope >= 0 (their weighted mean otherwise).
   coef[t][i] holds the linear map ln V_t = sum_i coef y_i, which carries
   the variances of the y_i to any combination.  var[i] > 0 marks a level
   with coefficients of its own left free (k_i >= 1/2); the others, and
   the scaling coefficient, the line reaches only by extrapolation.
   shape, slope and walk say which fit it was (fe_discover_noise's
   scale_shape, scale_slope and walk_ratio). */
typedef struct fe__scalefit {
    size_t levels;                                      /* J (0: none) */
    double lnv[FE_DISCOVER_SCALES + 1];
    double coef[FE_DISCOVER_SCALES + 1][FE_DISCOVER_SCALES];
    double var[FE_DISCOVER_SCALES];
    int shape;
    double slope, walk;
} fe__scalefit;

/* A random walk beside the AR model: see the text.  Levels, the fewest
   for which the walk is tried, and the grid of its variance. */
enum { FE__WALK_LEVELS = 6, FE__WALK_GRID = 49 };
#define FE__WALK_GAIN 6.635     /* chi-square, one degree of freedom, 0.99 */
#define FE__WALK_FIT 0.05       /* the least p-value of the walk's own fit */

/* The weighted line c + b x through y (weights wt, levels x = 1 .. J),
   its slope at least 0 (the weighted mean otherwise); returns the
   weighted sum of squares left. */
static double fe__level_line(const double *y, const double *wt, size_t J, double *c,
                             double *b)
{
    double sw = 0.0, sx = 0.0, sxx = 0.0, sy = 0.0, sxy = 0.0, det, ssr = 0.0;
    for (size_t i = 1; i <= J; i++) {
        double x = (double)i;
        sw += wt[i - 1];
        sx += wt[i - 1] * x;
        sxx += wt[i - 1] * x * x;
        sy += wt[i - 1] * y[i - 1];
        sxy += wt[i - 1] * x * y[i - 1];
    }
    det = sw * sxx - sx * sx;
    *b = det > 1e-12 * sw * sxx ? (sw * sxy - sx * sy) / det : 0.0;
    if (!(*b > 0.0))
        *b = 0.0;
    *c = (sy - *b * sx) / sw;
    for (size_t i = 1; i <= J; i++) {
        double e = y[i - 1] - *c - *b * (double)i;
        ssr += wt[i - 1] * e * e;
    }
    return ssr;
}

/* The line through y_i - ln(1 + A r_i) (y: room for J values); returns
   its weighted sum of squares, the line in *c and *b. */
static double fe__walk_ssr(const double *ly, const double *wt, const double *r, size_t J,
                           double A, double *y, double *c, double *b)
{
    for (size_t i = 0; i < J; i++)
        y[i] = ly[i] - log1p(A * r[i]);
    return fe__level_line(y, wt, J, c, b);
}

/* r_t, t = 1 .. J + 1: a random walk's variance at each level (and at the
   scaling coefficient, t = J + 1) per unit variance of its steps, over
   the AR model's prediction nz->scale_model. */
static void fe__walk_shape(const fe_discover_acc *a, const fe_discover_noise *nz, double *r)
{
    size_t J = nz->scales;
    for (size_t t = 1; t <= J + 1; t++) {
        double m = t <= J ? fe__level_rows(a, t) : fe__fitted_rows(a), w;
        /* Haar: two adjacent sums of m rows differ by
           sum_s c_s eta_s, sum c_s^2 = m (2 m^2 + 1) / 3, over 2 m; the
           whole record: sum of n rows, n (n + 1) (2 n + 1) / 6, over n. */
        w = t <= J ? (2.0 * m * m + 1.0) / 6.0 : (m + 1.0) * (2.0 * m + 1.0) / 6.0;
        r[t - 1] = nz->scale_model[t - 1] > 0.0 ? w / nz->scale_model[t - 1] : 0.0;
    }
}

/* When a random walk beside the AR model, ln V_t = c + b t + ln(1 + A r_t),
   fits the levels' y better than the line by more than chi-square's 99 %
   point for its one more parameter, and fits them itself, it replaces
   the line in sf: ln V at every level and the scaling coefficient, and
   the linear map of the y_i (Gauss-Newton's, at the fitted A) for the
   degrees of freedom. */
static void fe__scale_walk(const fe_discover_acc *a, const fe_discover_noise *nz,
                           const double *ly, const double *wt, size_t usable,
                           fe__scalefit *sf)
{
    size_t J = nz->scales, np;
    double r[FE_DISCOVER_SCALES + 1] = {0}, y[FE_DISCOVER_SCALES], rmax = 0.0;
    double c, b, ssr0, best = 0.0, bc = 0.0, bb = 0.0, A = 0.0;
    double jt[FE_DISCOVER_SCALES][3], m[3][3] = {{0}}, inv[3][3], det;
    fe__walk_shape(a, nz, r);
    for (size_t i = 0; i < J; i++)
        if (wt[i] > 0.0 && r[i] > rmax)
            rmax = r[i];
    if (!(rmax > 0.0))
        return;
    ssr0 = fe__level_line(ly, wt, J, &c, &b);
    best = ssr0;
    for (int g = 0; g < FE__WALK_GRID; g++) {
        double u = -2.0 + 8.0 * (double)g / (FE__WALK_GRID - 1);
        double ssr = fe__walk_ssr(ly, wt, r, J, pow(10.0, u) / rmax, y, &c, &b);
        if (ssr < best) {
            best = ssr;
            A = pow(10.0, u) / rmax;
        }
    }
    if (A > 0.0) {
        /* Golden section on log10(A max r) between the best point's
           neighbours on the grid. */
        const double gr = 0.6180339887498949, step = 8.0 / (FE__WALK_GRID - 1);
        double u0 = log10(A * rmax), lo = u0 - step, hi = u0 + step, u1, u2, f1, f2;
        lo = lo < -2.0 ? -2.0 : lo;
        hi = hi > 6.0 ? 6.0 : hi;
        u1 = hi - gr * (hi - lo);
        u2 = lo + gr * (hi - lo);
        f1 = fe__walk_ssr(ly, wt, r, J, pow(10.0, u1) / rmax, y, &c, &b);
        f2 = fe__walk_ssr(ly, wt, r, J, pow(10.0, u2) / rmax, y, &c, &b);
        for (int it = 0; it < 60; it++) {
            if (f1 <= f2) {
                hi = u2;
                u2 = u1;
                f2 = f1;
                u1 = hi - gr * (hi - lo);
                f1 = fe__walk_ssr(ly, wt, r, J, pow(10.0, u1) / rmax, y, &c, &b);
            } else {
                lo = u1;
                u1 = u2;
                f1 = f2;
                u2 = lo + gr * (hi - lo);
                f2 = fe__walk_ssr(ly, wt, r, J, pow(10.0, u2) / rmax, y, &c, &b);
            }
        }
        if ((f1 <= f2 ? f1 : f2) < best)
            A = pow(10.0, f1 <= f2 ? u1 : u2) / rmax;
        best = fe__walk_ssr(ly, wt, r, J, A, y, &bc, &bb);
    }
    /* The walk must beat the line and describe the levels itself: a
       missing effect bends the levels too, but not as a walk does. */
    np = bb > 0.0 ? 3 : 2;
    if (!(ssr0 - best > FE__WALK_GAIN)
        || !(fe_chi2_upper(best, (double)(usable - np)) >= FE__WALK_FIT))
        return;
    /* Gauss-Newton's linear map at A: the columns 1, t (unless the slope
       is held at 0) and r_t / (1 + A r_t). */
    for (size_t i = 0; i < J; i++) {
        jt[i][0] = 1.0;
        jt[i][1] = (double)(i + 1);
        jt[i][2] = r[i] / (1.0 + A * r[i]);
        if (np == 2)
            jt[i][1] = jt[i][2];
        for (size_t p = 0; p < np; p++)
            for (size_t q = 0; q < np; q++)
                m[p][q] += wt[i] * jt[i][p] * jt[i][q];
    }
    if (np == 2) {
        det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
        if (!(det > 0.0))
            return;
        inv[0][0] = m[1][1] / det;
        inv[1][1] = m[0][0] / det;
        inv[0][1] = inv[1][0] = -m[0][1] / det;
    } else {
        det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
              - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
              + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
        if (!(det > 0.0))
            return;
        for (size_t p = 0; p < 3; p++)
            for (size_t q = 0; q < 3; q++) {
                size_t p1 = (q + 1) % 3, p2 = (q + 2) % 3, q1 = (p + 1) % 3,
                       q2 = (p + 2) % 3;
                inv[p][q] = (m[p1][q1] * m[p2][q2] - m[p1][q2] * m[p2][q1]) / det;
            }
    }
    sf->shape = FE_DISCOVER_SCALE_WALK;
    sf->slope = bb;
    sf->walk = A * exp(bc + bb * (double)(J + 1));
    for (size_t t = 1; t <= J + 1; t++) {
        double gt[3] = {1.0, (double)t, r[t - 1] / (1.0 + A * r[t - 1])};
        if (np == 2)
            gt[1] = gt[2];
        sf->lnv[t - 1] = bc + bb * (double)t + log1p(A * r[t - 1]);
        for (size_t i = 0; i < J; i++) {
            double s = 0.0;
            for (size_t p = 0; p < np; p++)
                for (size_t q = 0; q < np; q++)
                    s += gt[p] * inv[p][q] * jt[i][q];
            sf->coef[t - 1][i] = s * wt[i];
        }
    }
}

static void fe__scale_fit(const fe_discover_acc *a, const fe_discover_noise *nz,
                          const double *u, double var, const double *used, fe__scalefit *sf)
{
    double y[FE_DISCOVER_FINE_BLOCKS] = {0}, e[FE_DISCOVER_SCALES + 1] = {0};
    double ly[FE_DISCOVER_SCALES] = {0}, wt[FE_DISCOVER_SCALES] = {0};
    double sw = 0.0, sx = 0.0, sxx = 0.0, sy = 0.0, sxy = 0.0, det;
    size_t J = nz->scales, usable = 0;
    int line;
    memset(sf, 0, sizeof *sf);
    if (J < 1 || !(var > 0.0))
        return;
    fe__fine_series(a, u, y);
    fe__haar(y, a->fine, e);
    for (size_t i = 1; i <= J; i++) {
        double k = (double)(a->fine >> i) - used[i - 1];
        double pred = var * nz->scale_model[i - 1], x = (double)i;
        wt[i - 1] = 0.0;
        ly[i - 1] = 0.0;
        if (!(k >= 0.5) || !(e[i - 1] > 0.0) || !(pred > 0.0))
            continue;
        ly[i - 1] = log(e[i - 1] / (k * pred)) - (fe_digamma(k / 2.0) - log(k / 2.0));
        sf->var[i - 1] = fe_trigamma(k / 2.0);
        wt[i - 1] = 1.0 / sf->var[i - 1];
        sw += wt[i - 1];
        sx += wt[i - 1] * x;
        sxx += wt[i - 1] * x * x;
        sy += wt[i - 1] * ly[i - 1];
        sxy += wt[i - 1] * x * ly[i - 1];
        usable++;
    }
    if (usable == 0)
        return;
    sf->levels = J;
    det = sw * sxx - sx * sx;
    line = usable >= 2 && det > 1e-12 * sw * sxx && sw * sxy - sx * sy > 0.0;
    sf->shape = line ? FE_DISCOVER_SCALE_LINE : FE_DISCOVER_SCALE_FLAT;
    sf->slope = line ? (sw * sxy - sx * sy) / det : 0.0;
    for (size_t t = 1; t <= J + 1; t++)
        for (size_t i = 1; i <= J; i++) {
            double x = (double)i, x0 = (double)t, c;
            c = line ? wt[i - 1] * ((sxx - x0 * sx) + (x0 * sw - sx) * x) / det
                     : wt[i - 1] / sw;
            sf->coef[t - 1][i - 1] = c;
            sf->lnv[t - 1] += c * ly[i - 1];
        }
    if (usable >= FE__WALK_LEVELS)
        fe__scale_walk(a, nz, ly, wt, usable, sf);
}

/* The long-range part of a variance factor: sum_t lambda_t max(1, V_t)
   for the shares lam (clamped to add up to at most 1; their sum in
   *share), with the variance of its log in *lnvar.  A level the AR model
   overpredicts is left at the model's own variance: the long range only
   ever widens.  Floored, a level the residual shows adds nothing to
   *lnvar; one the line only extrapolates to (no sf->var) adds its
   uncertainty as if V_t were 1 (see the text). */
static double fe__scale_part(const fe__scalefit *sf, const double *lam_in, double *share,
                             double *lnvar)
{
    double lam[FE_DISCOVER_SCALES + 1] = {0}, total = 0.0, F = 0.0, g[FE_DISCOVER_SCALES + 1] = {0};
    size_t J = sf->levels;
    *share = 0.0;
    *lnvar = 0.0;
    if (J == 0)
        return 0.0;
    for (size_t t = 0; t <= J; t++)
        total += lam_in[t];
    for (size_t t = 0; t <= J; t++) {
        lam[t] = total > 1.0 ? lam_in[t] / total : lam_in[t];
        F += lam[t] * (sf->lnv[t] > 0.0 ? exp(sf->lnv[t]) : 1.0);
        g[t] = sf->lnv[t] > 0.0 ? lam[t] * exp(sf->lnv[t])   /* d F / d ln V_t */
               : t < J && sf->var[t] > 0.0 ? 0.0   /* a level the residual shows */
                                           : lam[t];
    }
    *share = total > 1.0 ? 1.0 : total;
    if (!(F > 0.0))
        return 0.0;
    for (size_t i = 0; i < J; i++) {
        double d = 0.0;
        for (size_t t = 0; t <= J; t++)
            d += g[t] / F * sf->coef[t][i];
        *lnvar += d * d * sf->var[i];
    }
    return F;
}

/* The factor by which the variance of sum_t x~_t e~_t exceeds the white
   noise value sigma^2 sum x~^2, for the series x_t = u^T z_t whitened by
   nz, and the degrees of freedom of that variance (nu for white noise):
   the short-lag factor f_s (Bartlett over the whitened residual's first H
   autocorrelations, when whiteness was rejected) for the share of x~'s
   energy within the fine blocks, and the scale fit sf for the shares
   lambda_j in the Haar levels of the fine blocks,
   f = f_s (1 - sum lambda_j) + sum lambda_j V_j, with Satterthwaite's
   degrees of freedom for the two parts (the second's from the variance of
   its log, 2 / Var ln).  Uses w->q and w->acov. */
static double fe__variance_factor(const fe_discover_acc *a, const fe__ws *w,
                                  const fe_discover_noise *nz, const double *u, double nu,
                                  const fe__scalefit *sf, double *dof)
{
    double fs = 1.0, share, lnvar, F, f, parts, lam[FE_DISCOVER_SCALES + 1] = {0};
    *dof = nu;
    if (!nz->long_run && sf->levels == 0)
        return 1.0;
    fe__lagged_sums(a, w->g, u, w->q);
    fe__white_acov(w->q, a->lags, nz, w->acov);
    if (!(w->acov[0] > 0.0) || !(w->acov_e[0] > 0.0))
        return 1.0;
    if (nz->long_run) {
        size_t H = nz->lags_tested;
        double sum = 0.0;
        for (size_t h = 1; h <= H; h++)
            sum += (1.0 - (double)h / (double)(H + 1)) * (w->acov_e[h] / w->acov_e[0])
                   * (w->acov[h] / w->acov[0]);
        fs = 1.0 + 2.0 * sum;
        if (fs < 1.0)
            fs = 1.0;
    }
    fe__scale_shares(a, nz, u, w->acov[0], lam);
    F = fe__scale_part(sf, lam, &share, &lnvar);
    f = fs * (1.0 - share) + F;
    parts = fs * (1.0 - share) * fs * (1.0 - share) / nu + F * F * lnvar / 2.0;
    if (parts > 0.0)
        *dof = f * f / parts;
    if (*dof > nu)
        *dof = nu;
    return f;
}

/* Ljung-Box over the nz->lags_tested autocovariances acov[1 ..] of a
   series of n rows (acov[0] its sum of squares), against chi-square with
   H - p degrees of freedom (at least 1). */
static void fe__ljung_box(fe_discover_noise *nz, const double *acov, double n)
{
    double q2 = 0.0;
    for (size_t h = 1; h <= nz->lags_tested && acov[0] > 0.0; h++)
        q2 += (acov[h] / acov[0]) * (acov[h] / acov[0]) / (n - (double)h);
    nz->portmanteau = n * (n + 2.0) * q2;
    nz->portmanteau_dof = nz->lags_tested > nz->order
                              ? (double)(nz->lags_tested - nz->order) : 1.0;
    nz->portmanteau_p = fe_chi2_upper(nz->portmanteau, nz->portmanteau_dof);
}

enum { FE__GLS_ROUNDS = 10 };   /* noise model, then GLS, ten times */

/* Feasible GLS of the columns `cols`: the coefficients, the summary and
   the noise model, leaving the prewhitened Gram matrix in w->gt, the
   factor of its model block in w->css and the whitened residual's
   autocovariances in w->acov_e. */
static int fe__gls(const fe_discover_acc *a, const fe__ws *w, const size_t *cols,
                   size_t ncols, size_t maxp, double *coef, fe_discover_fit *fit,
                   fe_discover_noise *nz)
{
    size_t dim = a->m + 1, r = a->m;
    fe__model mo = {ncols, cols, w->css, {0}};
    double n = fe__fitted_rows(a), rsst;
    int rc = fe__factor(&mo, w->g, dim);
    if (rc != FE_OK)
        return rc;
    for (size_t i = 0; i < ncols; i++)
        coef[i] = w->g[cols[i] * dim + r];
    fe__solve(&mo, coef, 1);
    memset(nz, 0, sizeof *nz);
    /* A fixed number of rounds, not a tolerance: the answer then depends
       smoothly on the sums, and a fold merged in another order (threads,
       MPI) gives it to rounding, not to the tolerance. */
    for (int round = 0; round < FE__GLS_ROUNDS; round++) {
        fe__residual_weights(dim, cols, ncols, coef, w->uv);
        fe__lagged_sums(a, w->g, w->uv, w->q);
        fe_discover_noise_fit(w->q, n, maxp, nz);
        fe__whiten_gram(a, w->g, nz, w->gt);
        for (size_t i = 0; i < dim * dim; i++)
            if (!isfinite(w->gt[i]))
                return FE_ENONFINITE;   /* sums too large to whiten */
        rc = fe__factor(&mo, w->gt, dim);
        if (rc != FE_OK)
            return rc;
        for (size_t i = 0; i < ncols; i++)
            coef[i] = w->gt[cols[i] * dim + r];
        fe__solve(&mo, coef, 1);
    }
    /* The summary: raw residual for the RMS, whitened for the BIC. */
    fe__residual_weights(dim, cols, ncols, coef, w->uv);
    fe__lagged_sums(a, w->g, w->uv, w->q);
    rsst = fe__quad(w->gt, dim, w->uv);
    fit->rss = w->q[0] > 0.0 ? w->q[0] : 0.0;
    fit->n = n;
    fit->params = ncols;
    fit->rms = sqrt(fit->rss / n);
    fit->lag1 = fit->rss > 0.0 ? w->q[1] / fit->rss : 0.0;
    fit->floor = sqrt(w->q[0] > w->q[1] ? (w->q[0] - w->q[1]) / n : 0.0);
    fit->n_eff = nz->n_eff;
    fit->bic = n * log(rsst > 0.0 ? rsst / n : 1e-300)
               + (double)(ncols + nz->order) * log(n);
    nz->innovation_variance = rsst / n;
    fe__heldout(a, cols, ncols, coef, fit);
    /* Whiteness of the whitened residual, from the zero-padded lagged
       sums (see the text for what that costs under red noise). */
    nz->lags_tested = fe__white_acov(w->q, a->lags, nz, w->acov_e);
    fe__ljung_box(nz, w->acov_e, n);
    nz->long_run = nz->portmanteau_p < 0.05;
    fe__block_ratio(a, w->uv, nz);
    fe__scale_model(a, nz);
    fe__scale_used(a, &mo, nz);
    {
        fe__scalefit sf;
        fe__scale_fit(a, nz, w->uv, nz->innovation_variance, nz->scale_used, &sf);
        for (size_t t = 0; t <= nz->scales; t++)
            nz->scale_ratio[t] = sf.levels > 0 ? exp(sf.lnv[t]) : 1.0;
        nz->scale_shape = sf.shape;
        nz->scale_slope = sf.slope;
        nz->walk_ratio = sf.walk;
    }
    return FE_OK;
}

/* Degrees of freedom of the whitened regression. */
static double fe__gls_dof(const fe_discover_fit *fit, const fe_discover_noise *nz)
{
    double nu = fit->n - (double)fit->params - (double)nz->order;
    return nu >= 1.0 ? nu : 1.0;
}

/* After fe__gls: the covariance of the coefficients, sigma^2 gt_SS^{-1}
   with each variance (and covariance) scaled by the long-run factors
   when nz->long_run, into w->inv (ncols x ncols), the standard errors
   into se and each one's degrees of freedom into dof (each if not
   NULL). */
static void fe__gls_cov(const fe_discover_acc *a, const fe__ws *w, const size_t *cols,
                        size_t ncols, const double *coef, const fe_discover_fit *fit,
                        const fe_discover_noise *nz, double *se, double *dof)
{
    size_t dim = a->m + 1;
    fe__model mo = {ncols, cols, w->css, {0}};
    double nu = fe__gls_dof(fit, nz), s2 = nz->innovation_variance * fit->n / nu;
    double f[FE_DISCOVER_MAX_COLUMNS];
    fe__scalefit sf;
    fe__residual_weights(dim, cols, ncols, coef, w->uv);
    fe__scale_fit(a, nz, w->uv, nz->innovation_variance, nz->scale_used, &sf);
    /* The factor of gt_SS is in w->css (scales recomputed). */
    for (size_t i = 0; i < ncols; i++)
        mo.scale[i] = 1.0 / sqrt(w->gt[cols[i] * dim + cols[i]]);
    for (size_t i = 0; i < ncols * ncols; i++)
        w->inv[i] = 0.0;
    for (size_t i = 0; i < ncols; i++)
        w->inv[i * ncols + i] = 1.0;
    fe__solve(&mo, w->inv, ncols);
    for (size_t i = 0; i < ncols; i++) {
        double di;
        memset(w->uv, 0, dim * sizeof *w->uv);
        for (size_t k = 0; k < ncols; k++)
            w->uv[cols[k]] = w->inv[k * ncols + i];
        f[i] = fe__variance_factor(a, w, nz, w->uv, nu, &sf, &di);
        if (dof != NULL)
            dof[i] = di < nu ? di : nu;
    }
    for (size_t i = 0; i < ncols; i++)
        for (size_t j = 0; j < ncols; j++)
            w->inv[i * ncols + j] *= s2 * sqrt(f[i] * f[j]);
    if (se != NULL)
        for (size_t i = 0; i < ncols; i++)
            se[i] = sqrt(fabs(w->inv[i * ncols + i]));
}

int fe_discover_fit_noise(const fe_discover_acc *a, const size_t *cols,
                          size_t ncols, size_t max_order, double *coef,
                          double *stderr_, fe_discover_fit *fit,
                          fe_discover_noise *noise, double *work,
                          size_t work_doubles)
{
    fe__ws w;
    int rc;
    if (a == NULL || fit == NULL || noise == NULL
        || (ncols > 0 && (cols == NULL || coef == NULL))
        || a->lags == 0 || max_order >= a->lags || max_order > FE_DISCOVER_EDGE)
        return FE_EINVAL;
    rc = fe__fit_prepare(a, cols, ncols, a->m, &w, work, work_doubles);
    if (rc != FE_OK)
        return rc;
    rc = fe__gls(a, &w, cols, ncols, max_order, coef, fit, noise);
    if (rc == FE_OK && ncols > 0)
        fe__gls_cov(a, &w, cols, ncols, coef, fit, noise, stderr_, NULL);
    return rc;
}

/* Test group gr against the model (cols, fitted by fe__gls: w->gt and
   w->css are its own, beta its coefficients, rsst its whitened RSS, nz its
   noise model) in the whitened regression: the partial t (or F) test of
   adding gr, with the drop Delta_J from fe__drop. */
static void fe__gls_score(const fe_discover_acc *a, const fe__ws *w, const fe__model *mo,
                          const double *beta, const fe_discover_group *gr,
                          const fe_discover_fit *cur, const fe_discover_noise *nz,
                          double rsst, fe_discover_rank *out)
{
    size_t dim = a->m + 1, d = gr->count, s = mo->n;
    double drop = 0.0, nu, s2, f = 1.0;
    memset(out, 0, sizeof *out);
    out->p_value = 1.0;
    if (!fe__drop(w->gt, dim, w, mo, beta, gr, &drop)) {
        out->redundant = 1;
        return;
    }
    out->rss_drop = drop > 0.0 ? drop : 0.0;
    nu = cur->n - (double)(s + d + nz->order);
    if (nu < 1.0)
        return;                 /* no degree of freedom left: nothing to test */
    s2 = (rsst - out->rss_drop) / nu;
    if (!(s2 > 0.0))
        return;                 /* an exact fit: nothing to test */
    /* The variance factor of the candidate made orthogonal to the model:
       its weights e_J - sum a_J,i e_cols[i] (a_J from fe__drop), the
       first column of a group standing for it. */
    memset(w->uv, 0, dim * sizeof *w->uv);
    w->uv[gr->first] = 1.0;
    for (size_t i = 0; i < s; i++)
        w->uv[mo->cols[i]] -= w->aj[i * d];
    /* The scale fit of the residual with the candidate in the model: a
       slow effect that is missing inflates the coarse levels of the
       residual without it, and must not hide itself. */
    {
        double ures[FE_DISCOVER_MAX_COLUMNS + 1];
        double used[FE_DISCOVER_SCALES + 1], lam[FE_DISCOVER_SCALES + 1] = {0};
        fe__scalefit sf;
        memcpy(used, nz->scale_used, sizeof used);
        fe__residual_weights(dim, mo->cols, s, beta, ures);
        if (d == 1 && w->sjj[0] > 0.0) {
            double gamma = w->cj[0] / w->sjj[0];
            for (size_t c = 0; c < dim; c++)
                ures[c] -= gamma * w->uv[c];
            fe__scale_shares(a, nz, w->uv, w->sjj[0], lam);
            for (size_t t = 0; t <= nz->scales; t++)
                used[t] += lam[t];
        }
        fe__scale_fit(a, nz, ures, s2 * nu / cur->n, used, &sf);
        f = fe__variance_factor(a, w, nz, w->uv, nu, &sf, &nu);
    }
    if (d == 1) {
        out->statistic = (w->cj[0] >= 0.0 ? 1.0 : -1.0) * sqrt(out->rss_drop / (s2 * f));
        out->p_value = fe_student_t_two_sided(out->statistic, nu);
    } else {
        out->statistic = out->rss_drop / ((double)d * s2 * f);
        out->p_value = fe_f_upper(out->statistic, (double)d, nu);
    }
    {
        double after = rsst - out->rss_drop;
        if (after < 1e-300)
            after = 1e-300;
        out->delta_bic = cur->n * log(after / rsst) + (double)d * log(cur->n);
    }
}
/* Fit by generalised least squares ends here */
/* [[file:../literate/discover.org::Select terms by forward selection][Select terms by forward selection]] */
fe_discover_options fe_discover_default_options(void)
{
    fe_discover_options o = {0.05, 8, NULL, 0, FE_DISCOVER_NOISE_AR, 4, 0};
    return o;
}

static int fe__in_model(const size_t *added, size_t nadded, const size_t *base,
                        size_t nbase, size_t g)
{
    for (size_t i = 0; i < nadded; i++)
        if (added[i] == g)
            return 1;
    for (size_t i = 0; i < nbase; i++)
        if (base[i] == g)
            return 1;
    return 0;
}

static size_t fe__model_columns(const fe_discover_group *groups,
                                const size_t *base, size_t nbase,
                                const size_t *added, size_t nadded, size_t *cols)
{
    size_t n = 0;
    for (size_t i = 0; i < nbase + nadded; i++) {
        const fe_discover_group *g = &groups[i < nbase ? base[i] : added[i - nbase]];
        for (size_t c = 0; c < g->count; c++)
            cols[n++] = g->first + c;
    }
    return n;
}

/* The batch-means summary of a fit as a noise record: no model, the
   portmanteau of the raw residual when the lagged products are there. */
static void fe__batch_noise(const fe_discover_acc *a, const fe__ws *w, const size_t *cols,
                            size_t ncols, const double *coef, const fe_discover_fit *fit,
                            fe_discover_noise *nz)
{
    memset(nz, 0, sizeof *nz);
    nz->kind = FE_DISCOVER_NOISE_BATCH;
    nz->variance = fit->rss / fit->n;
    nz->innovation_variance = nz->variance;
    nz->n_eff = fit->n_eff;
    nz->portmanteau_p = NAN;
    nz->block_ratio = 1.0;
    nz->block_p = NAN;
    if (a->lags > 0) {
        fe__residual_weights(a->m + 1, cols, ncols, coef, w->uv);
        fe__lagged_sums(a, w->g, w->uv, w->q);
        nz->lags_tested = fe__white_acov(w->q, a->lags, nz, w->acov_e);
        fe__ljung_box(nz, w->acov_e, fit->n);
    }
}

/* Fit the model of the current step, by the noise model or by batch
   means, with standard errors and noise record when `st` is not NULL. */
static int fe__fit_step(const fe_discover_acc *a, const fe__ws *w, int ar, size_t maxp,
                        const size_t *cols, size_t ncols, double *beta,
                        fe_discover_fit *fit, fe_discover_step *st)
{
    fe_discover_noise nz;
    int rc;
    if (ar) {
        rc = fe__gls(a, w, cols, ncols, maxp, beta, fit, &nz);
        if (rc == FE_OK && st != NULL && ncols > 0)
            fe__gls_cov(a, w, cols, ncols, beta, fit, &nz, st->stderr_, st->dof);
    } else {
        rc = fe__fit(a, w, cols, ncols, beta, st != NULL ? st->stderr_ : NULL, fit);
        if (rc == FE_OK && st != NULL) {
            fe__batch_noise(a, w, cols, ncols, beta, fit, &nz);
            for (size_t i = 0; i < ncols; i++)
                st->dof[i] = (double)(a->blocks - 1);
        }
    }
    if (rc == FE_OK && st != NULL) {
        st->ncols = ncols;
        memcpy(st->coef, beta, ncols * sizeof *beta);
        st->fit = *fit;
        st->noise = nz;
    }
    return rc;
}

/* Rank every group g0 <= g < g1 not in the model (the base and `added`)
   nor set aside against it (the model fitted by fe__fit_step just before,
   so that w holds its matrices). */
static size_t fe__rank_all(const fe_discover_acc *a, const fe__ws *w, int ar,
                           const fe_discover_group *groups, size_t g0, size_t g1,
                           const fe_discover_options *o, const size_t *added, size_t nadded,
                           const size_t *aside, size_t naside,
                           const size_t *cols, size_t ncols, const double *beta,
                           const fe_discover_fit *cur, const fe_discover_noise *nz,
                           fe_discover_rank *rk, int *rc)
{
    size_t dim = a->m + 1, nr = 0;
    fe__model mo = {ncols, cols, w->css, {0}};
    *rc = fe__factor(&mo, ar ? w->gt : w->g, dim);
    if (*rc != FE_OK)
        return 0;
    double rsst = 0.0;
    if (ar) {
        fe__residual_weights(dim, cols, ncols, beta, w->uv);
        rsst = fe__quad(w->gt, dim, w->uv);
    }
    for (size_t g = g0; g < g1; g++) {
        if (fe__in_model(added, nadded, o->base, o->nbase, g)
            || fe__in_model(aside, naside, NULL, 0, g))
            continue;
        if (ar)
            fe__gls_score(a, w, &mo, beta, &groups[g], cur, nz, rsst, &rk[nr]);
        else
            fe__score(a, w, &mo, beta, &groups[g], cur->rss, cur, &rk[nr]);
        rk[nr].group = g;
        nr++;
    }
    return nr;
}

/* Add the candidate of `rank` as the next step, with the test it passed
   and how it entered (res->paired: 0 alone, 1 or 2 with the step after or
   before it), and refit: the path's new step, cols, ncols, beta and cur
   are the new model's, and w holds its matrices. */
static int fe__add_step(const fe_discover_acc *a, const fe__ws *w, int ar,
                        const fe_discover_options *o, const fe_discover_group *groups,
                        fe_discover_result *res, const fe_discover_rank *rank, int paired,
                        size_t *cols, size_t *ncols, double *beta, fe_discover_fit *cur)
{
    res->added[res->steps] = rank->group;
    res->added_rank[res->steps] = *rank;
    res->paired[res->steps] = paired;
    res->steps++;
    *ncols = fe__model_columns(groups, o->base, o->nbase, res->added, res->steps, cols);
    res->path[res->steps].added = rank->group;
    return fe__fit_step(a, w, ar, o->max_order, cols, *ncols, beta, cur, &res->path[res->steps]);
}

int fe_discover_select(const fe_discover_acc *a,
                       const fe_discover_group *groups, size_t ngroups,
                       const fe_discover_options *options,
                       fe_discover_result *res, double *work,
                       size_t work_doubles)
{
    fe_discover_options o = options ? *options : fe_discover_default_options();
    fe__ws w;
    size_t cols[FE_DISCOVER_MAX_COLUMNS], ncols;
    double beta[FE_DISCOVER_MAX_COLUMNS] = {0};
    fe_discover_fit cur;
    int rc, ar;

    if (a == NULL || groups == NULL || res == NULL || ngroups == 0
        || ngroups > FE_DISCOVER_MAX_GROUPS || (o.nbase > 0 && o.base == NULL)
        || o.nprobes >= ngroups
        || (o.noise != FE_DISCOVER_NOISE_AR && o.noise != FE_DISCOVER_NOISE_BATCH))
        return FE_EINVAL;
    for (size_t i = 0; i < ngroups; i++)
        if (groups[i].count == 0 || groups[i].count > FE_DISCOVER_MAX_GROUP_SIZE
            || groups[i].first + groups[i].count > a->m)
            return FE_EINVAL;
    for (size_t i = 0; i < o.nbase; i++)
        if (o.base[i] >= ngroups - o.nprobes
            || groups[o.base[i]].first + groups[o.base[i]].count > a->base_cols)
            return FE_EINVAL;
    if (a->base_cols < a->m && o.max_steps > 0)
        return FE_EINVAL;       /* a screen ranks; the next step needs more */
    if (o.max_steps > FE_DISCOVER_MAX_STEPS)
        o.max_steps = FE_DISCOVER_MAX_STEPS;
    /* The noise model needs the lagged products: a screen has none. */
    ar = o.noise == FE_DISCOVER_NOISE_AR && a->lags > 0;
    if (ar && o.max_order > FE_DISCOVER_EDGE)
        return FE_EINVAL;
    if (ar && o.max_order >= a->lags)
        o.max_order = a->lags - 1;      /* the portmanteau needs a lag more */
    rc = fe__ws_carve(&w, work, work_doubles, a->m, a->blocks);
    if (rc != FE_OK)
        return rc;
    for (size_t k = 0; k < a->blocks; k++)
        if (a->counts[k] < 1.0)
            return FE_ETOOFEW;
    memset(res, 0, sizeof *res);
    fe__total_gram(a, w.g);
    for (;;) {
        {
            size_t naside = res->naside, aside[FE_DISCOVER_MAX_ASIDE];
            fe_discover_rank aside_rank[FE_DISCOVER_MAX_ASIDE];
            memcpy(aside, res->aside, sizeof aside);
            memcpy(aside_rank, res->aside_rank, sizeof aside_rank);
            memset(res, 0, sizeof *res);            /* a new run keeps only the set-aside */
            res->naside = naside;
            memcpy(res->aside, aside, sizeof aside);
            memcpy(res->aside_rank, aside_rank, sizeof aside_rank);
        }
        ncols = fe__model_columns(groups, o.base, o.nbase, res->added, 0, cols);
        res->path[0].added = (size_t)-1;
        rc = fe__fit_step(a, &w, ar, o.max_order, cols, ncols, beta, &res->baseline, &res->path[0]);
        if (rc != FE_OK)
            return rc;
        cur = res->baseline;
        for (size_t step = 0;; step++) {
            fe_discover_rank *rk = res->ranking[step];
            size_t nr, in_play = 0, best = (size_t)-1;
            nr = fe__rank_all(a, &w, ar, groups, 0, ngroups - o.nprobes, &o, res->added,
                              res->steps, res->aside, res->naside, cols, ncols, beta, &cur,
                              &res->path[res->steps].noise, rk, &rc);
            if (rc != FE_OK)
                return rc;
            res->nranked[step] = nr;
            for (size_t i = 0; i < nr; i++)
                in_play += !rk[i].redundant;
            for (size_t i = 0; i < nr; i++) {
                if (rk[i].redundant || !(rk[i].p_value < o.alpha / (double)in_play)
                    || !(rk[i].delta_bic < 0.0))
                    continue;
                if (best == (size_t)-1 || rk[i].delta_bic < rk[best].delta_bic)
                    best = i;
            }
            if (step > 0) {
                size_t prev = step - 1;
                const fe_discover_rank *before = res->ranking[prev];
                for (size_t i = 0; i < res->nranked[prev]; i++) {
                    size_t g = before[i].group;
                    if (g == res->added[prev] || before[i].redundant)
                        continue;
                    if (before[i].delta_bic - res->added_rank[prev].delta_bic >= 6.0)
                        continue;
                    for (size_t j = 0; j < nr; j++)
                        if (rk[j].group == g
                            && (rk[j].redundant || rk[j].rss_drop <= 0.1 * before[i].rss_drop))
                            res->alike[prev][res->nalike[prev]++] = g;
                }
            }
            if (best == (size_t)-1 && res->steps + 2 <= o.max_steps) {
                size_t pos[FE_DISCOVER_MAX_GROUPS], np = 0, pf = 0, ps = 0;
                double best_pair = INFINITY, pair_alpha;
                for (size_t i = 0; i < nr; i++)
                    if (!rk[i].redundant)
                        pos[np++] = i;
                pair_alpha = o.alpha / ((double)np * (double)(np > 1 ? np - 1 : 1) / 2.0);
                /* Each candidate in play as the partner j: the model with j fitted, every
                   other candidate ranked against it (into the next step's ranking, which
                   is scratch until a pair enters). */
                for (size_t j = 0; j < np && np > 1; j++) {
                    size_t with[FE_DISCOVER_MAX_STEPS + 1], c2[FE_DISCOVER_MAX_COLUMNS], nc2, ng;
                    double b2[FE_DISCOVER_MAX_COLUMNS] = {0};
                    fe_discover_fit f2;
                    fe_discover_step s2;
                    fe_discover_rank *given = res->ranking[step + 1];
                    memcpy(with, res->added, res->steps * sizeof *with);
                    with[res->steps] = rk[pos[j]].group;
                    nc2 = fe__model_columns(groups, o.base, o.nbase, with, res->steps + 1, c2);
                    rc = fe__fit_step(a, &w, ar, o.max_order, c2, nc2, b2, &f2, &s2);
                    ng = rc == FE_OK ? fe__rank_all(a, &w, ar, groups, 0, ngroups - o.nprobes, &o, with,
                                                    res->steps + 1, res->aside, res->naside, c2, nc2, b2, &f2,
                                                    &s2.noise, given, &rc)
                                     : 0;
                    if (rc != FE_OK && rc != FE_ESINGULAR && rc != FE_ENONFINITE)
                        return rc;
                    rc = FE_OK;         /* a model with j that cannot be fitted pairs j with none */
                    for (size_t i = 0; i < np; i++) {
                        double *cell = &w.pair[i * FE_DISCOVER_MAX_GROUPS + j];
                        *cell = INFINITY;
                        for (size_t k = 0; k < ng; k++)
                            if (given[k].group == rk[pos[i]].group && !given[k].redundant
                                && given[k].p_value < pair_alpha && given[k].delta_bic < 0.0)
                                *cell = given[k].delta_bic;
                    }
                }
                for (size_t i = 0; i < np; i++)
                    for (size_t j = i + 1; j < np; j++) {
                        double bij = w.pair[i * FE_DISCOVER_MAX_GROUPS + j],
                               bji = w.pair[j * FE_DISCOVER_MAX_GROUPS + i], both;
                        if (!(bij < INFINITY && bji < INFINITY))
                            continue;
                        both = 0.5 * (rk[pos[j]].delta_bic + bij + rk[pos[i]].delta_bic + bji);
                        if (both < best_pair) {
                            int i_first = rk[pos[i]].p_value <= rk[pos[j]].p_value;
                            best_pair = both;
                            pf = pos[i_first ? i : j];
                            ps = pos[i_first ? j : i];
                        }
                    }
                if (best_pair < INFINITY) {
                    size_t with[FE_DISCOVER_MAX_STEPS + 2], c2[FE_DISCOVER_MAX_COLUMNS], nc2;
                    double b2[FE_DISCOVER_MAX_COLUMNS] = {0};
                    fe_discover_fit f2;
                    memcpy(with, res->added, res->steps * sizeof *with);
                    with[res->steps] = rk[pf].group;
                    with[res->steps + 1] = rk[ps].group;
                    nc2 = fe__model_columns(groups, o.base, o.nbase, with, res->steps + 2, c2);
                    rc = fe__fit_step(a, &w, ar, o.max_order, c2, nc2, b2, &f2, NULL);
                    if (rc == FE_ESINGULAR || rc == FE_ENONFINITE) {
                        best_pair = INFINITY;
                        rc = FE_OK;
                    }
                    if (rc != FE_OK)
                        return rc;
                }
                if (best_pair < INFINITY) {
                    size_t gf = rk[pf].group, gs = rk[ps].group, with[FE_DISCOVER_MAX_STEPS + 1];
                    size_t c2[FE_DISCOVER_MAX_COLUMNS], nc2, k;
                    double b2[FE_DISCOVER_MAX_COLUMNS] = {0};
                    fe_discover_fit f2;
                    fe_discover_step s2;
                    fe_discover_rank given;
                    /* The first term's test: given the second. */
                    memcpy(with, res->added, res->steps * sizeof *with);
                    with[res->steps] = gs;
                    nc2 = fe__model_columns(groups, o.base, o.nbase, with, res->steps + 1, c2);
                    rc = fe__fit_step(a, &w, ar, o.max_order, c2, nc2, b2, &f2, &s2);
                    if (rc != FE_OK)
                        return rc;
                    if (fe__rank_all(a, &w, ar, groups, gf, gf + 1, &o, with, res->steps + 1, NULL, 0, c2, nc2,
                                     b2, &f2, &s2.noise, &given, &rc) != 1)
                        return rc != FE_OK ? rc : FE_EINVAL;
                    rc = fe__add_step(a, &w, ar, &o, groups, res, &given, 1, cols, &ncols, beta, &cur);
                    if (rc != FE_OK)
                        return rc;
                    /* The ranking after the first, and the second's test in it. */
                    step++;
                    res->nranked[step] = fe__rank_all(a, &w, ar, groups, 0, ngroups - o.nprobes, &o, res->added,
                                                      res->steps, res->aside, res->naside, cols, ncols, beta,
                                                      &cur, &res->path[res->steps].noise, res->ranking[step], &rc);
                    if (rc != FE_OK)
                        return rc;
                    for (k = 0; k < res->nranked[step] && res->ranking[step][k].group != gs; k++)
                        ;
                    if (k == res->nranked[step])
                        return FE_EINVAL;
                    rc = fe__add_step(a, &w, ar, &o, groups, res, &res->ranking[step][k], 2, cols, &ncols, beta,
                                      &cur);
                    if (rc != FE_OK)
                        return rc;
                    continue;
                }
                /* None passes: the current model's matrices back into the workspace, for
                   the set-aside and the probes that follow. */
                rc = fe__fit_step(a, &w, ar, o.max_order, cols, ncols, beta, &cur, NULL);
                if (rc != FE_OK)
                    return rc;
            }
            if (best == (size_t)-1 || step >= o.max_steps)
                break;
            rc = fe__add_step(a, &w, ar, &o, groups, res, &rk[best], 0, cols, &ncols, beta, &cur);
            if (rc != FE_OK)
                return rc;
        }
        {
            size_t worst = (size_t)-1, in_play = 1;
            fe_discover_rank worst_rank;
            memset(&worst_rank, 0, sizeof worst_rank);
            for (size_t i = 0; i < res->nranked[res->steps]; i++)
                in_play += !res->ranking[res->steps][i].redundant;
            for (size_t k = 0; k < res->steps && res->steps > 1 && res->naside < FE_DISCOVER_MAX_ASIDE;
                 k++) {
                size_t others[FE_DISCOVER_MAX_STEPS], n = 0, c2[FE_DISCOVER_MAX_COLUMNS], nc2;
                double b2[FE_DISCOVER_MAX_COLUMNS] = {0};
                fe_discover_fit f2;
                fe_discover_step s2;
                fe_discover_rank rk;
                for (size_t j = 0; j < res->steps; j++)
                    if (j != k)
                        others[n++] = res->added[j];
                nc2 = fe__model_columns(groups, o.base, o.nbase, others, n, c2);
                rc = fe__fit_step(a, &w, ar, o.max_order, c2, nc2, b2, &f2, &s2);
                if (rc != FE_OK)
                    return rc;
                if (fe__rank_all(a, &w, ar, groups, res->added[k], res->added[k] + 1, &o, others, n,
                                 NULL, 0, c2, nc2, b2, &f2, &s2.noise, &rk, &rc) != 1)
                    return rc != FE_OK ? rc : FE_EINVAL;
                if ((rk.redundant || !(rk.p_value < o.alpha / (double)in_play) || !(rk.delta_bic < 0.0))
                    && (worst == (size_t)-1 || rk.p_value > worst_rank.p_value)) {
                    worst = k;
                    worst_rank = rk;
                }
            }
            if (worst == (size_t)-1) {
                if (res->steps > 1 && res->naside < FE_DISCOVER_MAX_ASIDE) {
                    rc = fe__fit_step(a, &w, ar, o.max_order, cols, ncols, beta, &cur, NULL);
                    if (rc != FE_OK)
                        return rc;
                }
                break;
            }
            res->aside[res->naside] = res->added[worst];
            res->aside_rank[res->naside++] = worst_rank;
        }
    }
    res->probe_p = NAN;
    if (o.nprobes > 0) {
        fe_discover_rank pr[FE_DISCOVER_MAX_GROUPS];
        size_t np = fe__rank_all(a, &w, ar, groups, ngroups - o.nprobes, ngroups, &o, res->added,
                                 res->steps, res->aside, res->naside, cols, ncols, beta, &cur,
                                 &res->path[res->steps].noise, pr, &rc);
        if (rc != FE_OK)
            return rc;
        for (size_t i = 0; i < np; i++) {
            if (pr[i].redundant)
                continue;
            if (res->probes_tested == 0 || pr[i].p_value < res->probe.p_value)
                res->probe = pr[i];
            res->probes_tested++;
        }
        if (res->probes_tested > 0) {
            double p = res->probe.p_value * (double)res->probes_tested;
            res->probe_p = p < 1.0 ? p : 1.0;
        }
    }
    {
        const fe_discover_step *last = &res->path[res->steps];
        res->ncols = ncols;
        memcpy(res->cols, cols, ncols * sizeof *cols);
        memcpy(res->coef, last->coef, ncols * sizeof *res->coef);
        memcpy(res->stderr_, last->stderr_, ncols * sizeof *res->stderr_);
        res->final = last->fit;
        res->noise = last->noise;
        for (size_t i = 0; i < ncols; i++) {
            res->dof[i] = ar ? last->dof[i] : (double)(a->blocks - 1);
            res->t_critical[i] = fe_student_t_quantile(0.05, res->dof[i]);
        }
        res->heldout_z = fe__heldout_z(a, res);
        if (!ar) {
            double ne = res->final.n_eff, n = res->final.n;
            fe_discover_fit *f[2] = {&res->baseline, &res->final};
            for (int i = 0; i < 2; i++) {
                f[i]->bic = ne * log(f[i]->rss > 0 ? f[i]->rss / n : 1e-300)
                            + (double)f[i]->params * log(ne);
                f[i]->n_eff = ne;
            }
        }
    }
    return FE_OK;
}
/* Select terms by forward selection ends here */
