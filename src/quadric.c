/* SPDX-License-Identifier: MIT */
/* Tangled from literate/quadric.org: do not edit; edit the .org and run make tangle. */
/* [[file:../literate/quadric.org::Quadric Includes][Quadric Includes]] */
#include "foldest/error.h"
#include "foldest/quadric.h"
#include "lanes.h"
#if defined(FE__LANES_X86)
#include <immintrin.h>
#endif

enum { FE__QUADRIC_BLOCK = 512 };

/* The exponents (a, b, c) of moment k, in the order of m[]. */
static const unsigned char fe__quadric_exp[FE_QUADRIC_MOMENTS][3] = {
    {0,0,0},
    {1,0,0},{0,1,0},{0,0,1},
    {2,0,0},{1,1,0},{1,0,1},{0,2,0},{0,1,1},{0,0,2},
    {3,0,0},{2,1,0},{2,0,1},{1,2,0},{1,1,1},{1,0,2},{0,3,0},{0,2,1},{0,1,2},{0,0,3},
    {4,0,0},{3,1,0},{3,0,1},{2,2,0},{2,1,1},{2,0,2},{1,3,0},{1,2,1},{1,1,2},{1,0,3},
    {0,4,0},{0,3,1},{0,2,2},{0,1,3},{0,0,4}
};

static int fe__finite(double x)
{
    return x - x == 0.0;
}
/* Quadric Includes ends here */
/* [[file:../literate/quadric.org::Compute the monomials of one sample][Compute the monomials of one sample]] */
static void fe__quadric_monomials(double x, double y, double z, double p[35])
{
    double xx = x * x, xy = x * y, xz = x * z, yy = y * y, yz = y * z,
           zz = z * z;
    p[0] = 1.0;
    p[1] = x; p[2] = y; p[3] = z;
    p[4] = xx; p[5] = xy; p[6] = xz; p[7] = yy; p[8] = yz; p[9] = zz;
    p[10] = xx * x; p[11] = xx * y; p[12] = xx * z; p[13] = xy * y;
    p[14] = xy * z; p[15] = xz * z; p[16] = yy * y; p[17] = yy * z;
    p[18] = yz * z; p[19] = zz * z;
    p[20] = xx * xx; p[21] = xx * xy; p[22] = xx * xz; p[23] = xx * yy;
    p[24] = xx * yz; p[25] = xx * zz; p[26] = xy * yy; p[27] = xy * yz;
    p[28] = xy * zz; p[29] = xz * zz; p[30] = yy * yy; p[31] = yy * yz;
    p[32] = yy * zz; p[33] = yz * zz; p[34] = zz * zz;
}
/* Compute the monomials of one sample ends here */
/* [[file:../literate/quadric.org::Find the region of a direction][Find the region of a direction]] */
static const double fe__quadric_band[9] = {
    -0.64, -0.36, -0.16, -0.04, 0.0, 0.04, 0.16, 0.36, 0.64 /* t|t| */
};
static const double fe__quadric_sector[5][2] = {   /* cos, sin of 36 k deg */
    {1.0, 0.0},
    {0.80901699437494742, 0.58778525229247314},
    {0.30901699437494742, 0.95105651629515357},
    {-0.30901699437494742, 0.95105651629515357},
    {-0.80901699437494742, 0.58778525229247314}
};

static int fe__quadric_region(double x, double y, double z)
{
    double r2 = x * x + y * y + z * z, zz = z * (z < 0.0 ? -z : z);
    int band = 0, c = 0, north;
    for (int j = 0; j < 9; j++)
        band += zz >= fe__quadric_band[j] * r2;
    for (int k = 0; k < 5; k++)
        c += fe__quadric_sector[k][0] * y - fe__quadric_sector[k][1] * x >= 0.0;
    north = y >= 0.0;
    if (!(r2 > 0.0) || !fe__finite(r2))
        return -1;
    return 10 * band + (north ? c - 1 : 9 - c);
}

int fe_quadric_region(const double v[3])
{
    if (v == NULL)
        return -1;
    return fe__quadric_region(v[0], v[1], v[2]);
}
/* Find the region of a direction ends here */
/* [[file:../literate/quadric.org::Mark the region of a sample][Mark the region of a sample]] */
/* The centre for coverage and the box size, from the current box. */
static float fe__quadric_frame(const fe_quadric *q, double c[3])
{
    double size = 0.0;
    for (int j = 0; j < 3; j++) {
        double h = 0.5 * (q->hi[j] - q->lo[j]);
        c[j] = (q->flags & FE_QUADRIC_FIXED_REF) ? q->ref[j]
                                                 : 0.5 * (q->lo[j] + q->hi[j]);
        size = h > size ? h : size;
    }
    return (float)size;
}

static int fe__quadric_full(const fe_quadric *q)
{
    double c[3];
    float size = fe__quadric_frame(q, c);
    int stale = 0;
    for (int r = 0; r < FE_QUADRIC_REGIONS; r++)  /* no early exit: vectorises */
        stale |= q->seen[r] < size;
    return !stale;
}

static void fe__quadric_mark(fe_quadric *q, int region, float size)
{
    if (region >= 0 && q->seen[region] < size)
        q->seen[region] = size;
}
/* Mark the region of a sample ends here */
/* [[file:../literate/quadric.org::Fold one sample into the moments][Fold one sample into the moments]] */
int fe_quadric_add(fe_quadric *q, const double x[3])
{
    double ref[3], p[FE_QUADRIC_MOMENTS], m[FE_QUADRIC_MOMENTS];
    int first;

    if (q == NULL || x == NULL)
        return FE_EINVAL;
    if (!fe__finite(x[0]) || !fe__finite(x[1]) || !fe__finite(x[2]))
        return FE_ENONFINITE;
    for (int j = 0; j < 3; j++)
        ref[j] = (q->flags & FE_QUADRIC_HAS_REF) ? q->ref[j] : x[j];
    fe__quadric_monomials(x[0] - ref[0], x[1] - ref[1], x[2] - ref[2], p);
    for (int k = 0; k < FE_QUADRIC_MOMENTS; k++) {
        m[k] = q->m[k] + p[k];
        if (!fe__finite(m[k]))
            return FE_ENONFINITE;
    }
    first = q->m[0] == 0.0;
    for (int k = 0; k < FE_QUADRIC_MOMENTS; k++)
        q->m[k] = m[k];
    for (int j = 0; j < 3; j++) {
        q->ref[j] = ref[j];
        if (first || x[j] < q->lo[j])
            q->lo[j] = x[j];
        if (first || x[j] > q->hi[j])
            q->hi[j] = x[j];
    }
    q->flags |= FE_QUADRIC_HAS_REF;
    {
        double c[3];
        float size = fe__quadric_frame(q, c);
        fe__quadric_mark(q, fe__quadric_region(x[0] - c[0], x[1] - c[1],
                                               x[2] - c[2]), size);
    }
    return FE_OK;
}
/* Fold one sample into the moments ends here */
/* [[file:../literate/quadric.org::Compile the kernel for four and eight lanes][Compile the kernel for four and eight lanes]] */
#define FE__L 4
#define FE__QUADRIC_BLOCK_FN fe__quadric_block4
FE__LANES_CLONES
static void FE__QUADRIC_BLOCK_FN(const double *b, int n, const double ref[3],
                                 const double *next, int nnext,
                                 double out[35], double rlo[3], double rhi[3])
{
    double X[FE__QUADRIC_BLOCK], Y[FE__QUADRIC_BLOCK], Z[FE__QUADRIC_BLOCK];
    double a[9][FE__L] = {{0}}, c[9][FE__L] = {{0}}, q[8][FE__L] = {{0}},
           r[8][FE__L] = {{0}}, lo[3][FE__L], hi[3][FE__L];
    int i, l, k;

    /* Copy relative to the reference; extremes of the samples
       themselves, in lanes. */
    for (l = 0; l < FE__L; l++) {
        lo[0][l] = hi[0][l] = b[0];
        lo[1][l] = hi[1][l] = b[1];
        lo[2][l] = hi[2][l] = b[2];
    }
    for (i = 0; i + FE__L <= n; i += FE__L)
        for (l = 0; l < FE__L; l++) {
            double x = b[3 * (i + l)], y = b[3 * (i + l) + 1],
                   z = b[3 * (i + l) + 2];
            X[i + l] = x - ref[0];
            Y[i + l] = y - ref[1];
            Z[i + l] = z - ref[2];
            lo[0][l] = x < lo[0][l] ? x : lo[0][l];
            hi[0][l] = x > hi[0][l] ? x : hi[0][l];
            lo[1][l] = y < lo[1][l] ? y : lo[1][l];
            hi[1][l] = y > hi[1][l] ? y : hi[1][l];
            lo[2][l] = z < lo[2][l] ? z : lo[2][l];
            hi[2][l] = z > hi[2][l] ? z : hi[2][l];
        }
    for (; i < n; i++) {
        double x = b[3 * i], y = b[3 * i + 1], z = b[3 * i + 2];
        X[i] = x - ref[0];
        Y[i] = y - ref[1];
        Z[i] = z - ref[2];
        lo[0][0] = x < lo[0][0] ? x : lo[0][0];
        hi[0][0] = x > hi[0][0] ? x : hi[0][0];
        lo[1][0] = y < lo[1][0] ? y : lo[1][0];
        hi[1][0] = y > hi[1][0] ? y : hi[1][0];
        lo[2][0] = z < lo[2][0] ? z : lo[2][0];
        hi[2][0] = z > hi[2][0] ? z : hi[2][0];
    }
    for (int j = 0; j < 3; j++) {
        rlo[j] = lo[j][0];
        rhi[j] = hi[j][0];
        for (l = 1; l < FE__L; l++) {
            rlo[j] = lo[j][l] < rlo[j] ? lo[j][l] : rlo[j];
            rhi[j] = hi[j][l] > rhi[j] ? hi[j][l] : rhi[j];
        }
    }
    /* The moments, in four groups of lanes; each group asks for every
       fourth cache line of the next block (eight doubles a line). */
#define FE__QUADRIC_AHEAD(g) \
    if (8 * (4 * (i / FE__L) + (g)) < 3 * nnext) \
        FE__PREFETCH(next + 8 * (4 * (i / FE__L) + (g)))
    for (i = 0; i + FE__L <= n; i += FE__L) {
        FE__QUADRIC_AHEAD(0);
        for (l = 0; l < FE__L; l++) {
            double x = X[i + l], y = Y[i + l], z = Z[i + l];
            a[0][l] += x; a[1][l] += y; a[2][l] += z;
            a[3][l] += x * x; a[4][l] += x * y; a[5][l] += x * z;
            a[6][l] += y * y; a[7][l] += y * z; a[8][l] += z * z;
        }
    }
    for (i = 0; i + FE__L <= n; i += FE__L) {
        FE__QUADRIC_AHEAD(1);
        for (l = 0; l < FE__L; l++) {
            double x = X[i + l], y = Y[i + l], z = Z[i + l];
            double xx = x * x, xy = x * y, xz = x * z, yy = y * y,
                   yz = y * z;
            c[0][l] += xx * x; c[1][l] += xx * y; c[2][l] += xx * z;
            c[3][l] += xy * y; c[4][l] += xy * z; c[5][l] += xz * z;
            c[6][l] += yy * y; c[7][l] += yy * z; c[8][l] += yz * z;
        }
    }
    for (i = 0; i + FE__L <= n; i += FE__L) {
        FE__QUADRIC_AHEAD(2);
        for (l = 0; l < FE__L; l++) {
            double x = X[i + l], y = Y[i + l], z = Z[i + l];
            double xx = x * x, xy = x * y, xz = x * z, yy = y * y,
                   yz = y * z, zz = z * z;
            q[0][l] += xx * xx; q[1][l] += xx * xy; q[2][l] += xx * xz;
            q[3][l] += xx * yy; q[4][l] += xx * yz; q[5][l] += xx * zz;
            q[6][l] += xy * yy; q[7][l] += xy * yz;
        }
    }
    for (i = 0; i + FE__L <= n; i += FE__L) {
        FE__QUADRIC_AHEAD(3);
        for (l = 0; l < FE__L; l++) {
            double x = X[i + l], y = Y[i + l], z = Z[i + l];
            double xy = x * y, xz = x * z, yy = y * y, yz = y * z,
                   zz = z * z;
            r[0][l] += xy * zz; r[1][l] += xz * zz; r[2][l] += yy * yy;
            r[3][l] += yy * yz; r[4][l] += yy * zz; r[5][l] += yz * zz;
            r[6][l] += zz * zz; r[7][l] += zz * z;
        }
    }
#undef FE__QUADRIC_AHEAD
    for (k = 0; k < 35; k++)
        out[k] = 0.0;
    out[0] = (double)n;
    for (l = 0; l < FE__L; l++) {
        for (k = 0; k < 9; k++)
            out[1 + k] += a[k][l];
        for (k = 0; k < 9; k++)
            out[10 + k] += c[k][l];
        out[19] += r[7][l];             /* the ninth of r is the tenth cubic */
        for (k = 0; k < 8; k++)
            out[20 + k] += q[k][l];
        for (k = 0; k < 7; k++)
            out[28 + k] += r[k][l];
    }
    /* The tail that does not fill the lanes. */
    for (; i < n; i++) {
        double p[35];
        fe__quadric_monomials(X[i], Y[i], Z[i], p);
        for (k = 1; k < 35; k++)
            out[k] += p[k];
    }
}
#undef FE__L
#undef FE__QUADRIC_BLOCK_FN

#if defined(FE__LANES_X86)
FE__LANES_WIDE
static void fe__quadric_block8(const double *b, int n, const double ref[3],
                               const double *next, int nnext, double out[35],
                               double rlo[3], double rhi[3])
{
    _Alignas(64) double X[FE__QUADRIC_BLOCK], Y[FE__QUADRIC_BLOCK],
        Z[FE__QUADRIC_BLOCK];
    /* Lane l of x gathers element 3 l of the 24 doubles v0 v1 v2: first
       from v0 and v1 (table indices 0 to 15), then from v2 (8 to 15). */
    const __m512i x01 = _mm512_set_epi64(0, 0, 15, 12, 9, 6, 3, 0),
                  x2 = _mm512_set_epi64(13, 10, 5, 4, 3, 2, 1, 0),
                  y01 = _mm512_set_epi64(0, 0, 0, 13, 10, 7, 4, 1),
                  y2 = _mm512_set_epi64(14, 11, 8, 4, 3, 2, 1, 0),
                  z01 = _mm512_set_epi64(0, 0, 0, 14, 11, 8, 5, 2),
                  z2 = _mm512_set_epi64(15, 12, 9, 4, 3, 2, 1, 0);
    const __m512d rx = _mm512_set1_pd(ref[0]), ry = _mm512_set1_pd(ref[1]),
                  rz = _mm512_set1_pd(ref[2]);
    __m512d lx = _mm512_set1_pd(b[0]), ly = _mm512_set1_pd(b[1]),
            lz = _mm512_set1_pd(b[2]), hx = lx, hy = ly, hz = lz;
    const __m512d zero = _mm512_setzero_pd();
    __m512d s[34];                      /* the 34 sums, in the order of m[] */
    int nl = n - n % 8, i, k;

    /* First pass: three loads hold eight samples; the permutations put
       their x, y and z in lanes, relative to the reference, into X, Y, Z;
       extremes, and the sums of degree one and two.  It asks for the
       first of the three cache lines of the next block that these eight
       samples' place covers, into the second-level cache. */
    {
        __m512d a0 = zero, a1 = zero, a2 = zero, a3 = zero, a4 = zero,
                a5 = zero, a6 = zero, a7 = zero, a8 = zero;
        for (i = 0; i < nl; i += 8) {
            __m512d v0 = _mm512_loadu_pd(b + 3 * i),
                    v1 = _mm512_loadu_pd(b + 3 * i + 8),
                    v2 = _mm512_loadu_pd(b + 3 * i + 16);
            __m512d ux = _mm512_permutex2var_pd(
                        _mm512_permutex2var_pd(v0, x01, v1), x2, v2),
                    uy = _mm512_permutex2var_pd(
                        _mm512_permutex2var_pd(v0, y01, v1), y2, v2),
                    uz = _mm512_permutex2var_pd(
                        _mm512_permutex2var_pd(v0, z01, v1), z2, v2),
                    x = _mm512_sub_pd(ux, rx), y = _mm512_sub_pd(uy, ry),
                    z = _mm512_sub_pd(uz, rz);
            if (3 * i < 3 * nnext)
                _mm_prefetch((const char *)(next + 3 * i), _MM_HINT_T1);
            _mm512_store_pd(X + i, x);
            _mm512_store_pd(Y + i, y);
            _mm512_store_pd(Z + i, z);
            lx = _mm512_min_pd(ux, lx); hx = _mm512_max_pd(ux, hx);
            ly = _mm512_min_pd(uy, ly); hy = _mm512_max_pd(uy, hy);
            lz = _mm512_min_pd(uz, lz); hz = _mm512_max_pd(uz, hz);
            a0 = _mm512_add_pd(a0, x); a1 = _mm512_add_pd(a1, y);
            a2 = _mm512_add_pd(a2, z);
            a3 = _mm512_fmadd_pd(x, x, a3); a4 = _mm512_fmadd_pd(x, y, a4);
            a5 = _mm512_fmadd_pd(x, z, a5); a6 = _mm512_fmadd_pd(y, y, a6);
            a7 = _mm512_fmadd_pd(y, z, a7); a8 = _mm512_fmadd_pd(z, z, a8);
        }
        s[0] = a0; s[1] = a1; s[2] = a2; s[3] = a3; s[4] = a4;
        s[5] = a5; s[6] = a6; s[7] = a7; s[8] = a8;
    }
    /* Second pass: the six products of degree two, and from them the ten
       sums of degree three and the fifteen of degree four (25 sums in
       registers of the 32); the other two cache lines of the next block. */
    {
        __m512d c0 = zero, c1 = zero, c2 = zero, c3 = zero, c4 = zero,
                c5 = zero, c6 = zero, c7 = zero, c8 = zero, c9 = zero,
                q0 = zero, q1 = zero, q2 = zero, q3 = zero, q4 = zero,
                q5 = zero, q6 = zero, q7 = zero, q8 = zero, q9 = zero,
                q10 = zero, q11 = zero, q12 = zero, q13 = zero, q14 = zero;
        for (i = 0; i < nl; i += 8) {
            __m512d x = _mm512_load_pd(X + i), y = _mm512_load_pd(Y + i),
                    z = _mm512_load_pd(Z + i), xx = _mm512_mul_pd(x, x),
                    xy = _mm512_mul_pd(x, y), xz = _mm512_mul_pd(x, z),
                    yy = _mm512_mul_pd(y, y), yz = _mm512_mul_pd(y, z),
                    zz = _mm512_mul_pd(z, z);
            if (3 * i + 8 < 3 * nnext)
                _mm_prefetch((const char *)(next + 3 * i + 8), _MM_HINT_T1);
            if (3 * i + 16 < 3 * nnext)
                _mm_prefetch((const char *)(next + 3 * i + 16), _MM_HINT_T1);
            c0 = _mm512_fmadd_pd(xx, x, c0); c1 = _mm512_fmadd_pd(xx, y, c1);
            c2 = _mm512_fmadd_pd(xx, z, c2); c3 = _mm512_fmadd_pd(xy, y, c3);
            c4 = _mm512_fmadd_pd(xy, z, c4); c5 = _mm512_fmadd_pd(xz, z, c5);
            c6 = _mm512_fmadd_pd(yy, y, c6); c7 = _mm512_fmadd_pd(yy, z, c7);
            c8 = _mm512_fmadd_pd(yz, z, c8); c9 = _mm512_fmadd_pd(zz, z, c9);
            q0 = _mm512_fmadd_pd(xx, xx, q0); q1 = _mm512_fmadd_pd(xx, xy, q1);
            q2 = _mm512_fmadd_pd(xx, xz, q2); q3 = _mm512_fmadd_pd(xx, yy, q3);
            q4 = _mm512_fmadd_pd(xx, yz, q4); q5 = _mm512_fmadd_pd(xx, zz, q5);
            q6 = _mm512_fmadd_pd(xy, yy, q6); q7 = _mm512_fmadd_pd(xy, yz, q7);
            q8 = _mm512_fmadd_pd(xy, zz, q8); q9 = _mm512_fmadd_pd(xz, zz, q9);
            q10 = _mm512_fmadd_pd(yy, yy, q10); q11 = _mm512_fmadd_pd(yy, yz, q11);
            q12 = _mm512_fmadd_pd(yy, zz, q12); q13 = _mm512_fmadd_pd(yz, zz, q13);
            q14 = _mm512_fmadd_pd(zz, zz, q14);
        }
        s[9] = c0; s[10] = c1; s[11] = c2; s[12] = c3; s[13] = c4;
        s[14] = c5; s[15] = c6; s[16] = c7; s[17] = c8; s[18] = c9;
        s[19] = q0; s[20] = q1; s[21] = q2; s[22] = q3; s[23] = q4;
        s[24] = q5; s[25] = q6; s[26] = q7; s[27] = q8; s[28] = q9;
        s[29] = q10; s[30] = q11; s[31] = q12; s[32] = q13; s[33] = q14;
    }
    rlo[0] = _mm512_reduce_min_pd(lx); rhi[0] = _mm512_reduce_max_pd(hx);
    rlo[1] = _mm512_reduce_min_pd(ly); rhi[1] = _mm512_reduce_max_pd(hy);
    rlo[2] = _mm512_reduce_min_pd(lz); rhi[2] = _mm512_reduce_max_pd(hz);
    out[0] = (double)n;
    for (k = 0; k < 34; k++)
        out[1 + k] = _mm512_reduce_add_pd(s[k]);
    /* The tail that does not fill the lanes. */
    for (i = nl; i < n; i++) {
        double p[35], x = b[3 * i], y = b[3 * i + 1], z = b[3 * i + 2];
        fe__quadric_monomials(x - ref[0], y - ref[1], z - ref[2], p);
        for (k = 1; k < 35; k++)
            out[k] += p[k];
        rlo[0] = x < rlo[0] ? x : rlo[0];
        rhi[0] = x > rhi[0] ? x : rhi[0];
        rlo[1] = y < rlo[1] ? y : rlo[1];
        rhi[1] = y > rhi[1] ? y : rhi[1];
        rlo[2] = z < rlo[2] ? z : rlo[2];
        rhi[2] = z > rhi[2] ? z : rhi[2];
    }
}
#endif

/* The block's moment sums about ref and the extremes of its samples;
   next (nnext samples, or NULL and 0) is the block to prefetch. */
static void fe__quadric_block(const double *b, int n, const double ref[3],
                              const double *next, int nnext, double out[35],
                              double rlo[3], double rhi[3])
{
#if defined(FE__LANES_X86)
    if (FE__LANES_HAVE_WIDE()) {
        fe__quadric_block8(b, n, ref, next, nnext, out, rlo, rhi);
        return;
    }
#endif
    fe__quadric_block4(b, n, ref, next, nnext, out, rlo, rhi);
}
/* Compile the kernel for four and eight lanes ends here */
/* [[file:../literate/quadric.org::Fold an array block by block][Fold an array block by block]] */
int fe_quadric_add_many(fe_quadric *q, const double *x, size_t n,
                        size_t *done)
{
    size_t k = 0;
    int rc = FE_OK;

    if (done != NULL)
        *done = 0;
    if (q == NULL || (x == NULL && n > 0))
        return FE_EINVAL;
    while (k < n) {
        size_t m = n - k < FE__QUADRIC_BLOCK ? n - k : FE__QUADRIC_BLOCK;
        const double *b = x + 3 * k;
        double rlo[3], rhi[3], sums[35], next[35];
        int fast = (q->flags & FE_QUADRIC_HAS_REF) && q->m[0] > 0.0, grows = 0;

        if (fast) {             /* a non-finite sample makes a sum non-finite */
            size_t rest = n - k - m;
            int nnext = rest < FE__QUADRIC_BLOCK ? (int)rest : FE__QUADRIC_BLOCK;
            fe__quadric_block(b, (int)m, q->ref, nnext > 0 ? b + 3 * m : NULL,
                              nnext, sums, rlo, rhi);
            for (int j = 0; j < FE_QUADRIC_MOMENTS; j++) {
                next[j] = q->m[j] + sums[j];
                fast = fast && fe__finite(next[j]);
            }
        }
        if (fast) {
            for (int j = 0; j < FE_QUADRIC_MOMENTS; j++)
                q->m[j] = next[j];
            for (int j = 0; j < 3; j++)
                grows = grows || rlo[j] < q->lo[j] || rhi[j] > q->hi[j];
            if (!grows && !fe__quadric_full(q)) {
                double c[3];
                float size = fe__quadric_frame(q, c);
                for (size_t i = 0; i < m; i++)
                    fe__quadric_mark(q, fe__quadric_region(
                        b[3 * i] - c[0], b[3 * i + 1] - c[1], b[3 * i + 2] - c[2]),
                        size);
            }
            if (grows) {
                /* The box and the marks sample by sample, as the step
                   does them; the frame and the test whether every region
                   was visited only where the box moved. */
                double c[3];
                float size = fe__quadric_frame(q, c);
                int full = fe__quadric_full(q);
                for (size_t i = 0; i < m; i++) {
                    const double *v = b + 3 * i;
                    int moved = 0;
                    for (int j = 0; j < 3; j++) {
                        if (v[j] < q->lo[j]) {
                            q->lo[j] = v[j];
                            moved = 1;
                        }
                        if (v[j] > q->hi[j]) {
                            q->hi[j] = v[j];
                            moved = 1;
                        }
                    }
                    if (moved) {
                        size = fe__quadric_frame(q, c);
                        full = fe__quadric_full(q);
                    }
                    if (!full)
                        fe__quadric_mark(q, fe__quadric_region(
                            v[0] - c[0], v[1] - c[1], v[2] - c[2]), size);
                }
            }
            k += m;
            continue;
        }
        for (size_t end = k + m; k < end; k++) {
            rc = fe_quadric_add(q, x + 3 * k);
            if (rc != FE_OK)
                break;
        }
        if (rc != FE_OK)
            break;
    }
    if (done != NULL)
        *done = k;
    return rc;
}
/* Fold an array block by block ends here */
/* [[file:../literate/quadric.org::Move moments to another reference][Move moments to another reference]] */
int fe_quadric_index(int a, int b, int c)
{
    if (a < 0 || b < 0 || c < 0 || a + b + c > 4)
        return -1;
    for (int k = 0; k < FE_QUADRIC_MOMENTS; k++)
        if (fe__quadric_exp[k][0] == a && fe__quadric_exp[k][1] == b
            && fe__quadric_exp[k][2] == c)
            return k;
    return -1;
}

void fe_quadric_exponents(int k, int e[3])
{
    for (int j = 0; j < 3; j++)
        e[j] = (k >= 0 && k < FE_QUADRIC_MOMENTS) ? fe__quadric_exp[k][j] : 0;
}

/* out = the moments m moved by delta (u' = u + delta). */
static int fe__quadric_shift(const double m[35], const double delta[3],
                             double out[35])
{
    static const double binom[5][5] = {
        {1, 0, 0, 0, 0}, {1, 1, 0, 0, 0}, {1, 2, 1, 0, 0}, {1, 3, 3, 1, 0},
        {1, 4, 6, 4, 1}
    };
    double pw[3][5];
    int index[5][5][5];

    for (int j = 0; j < 3; j++) {
        pw[j][0] = 1.0;
        for (int e = 1; e < 5; e++)
            pw[j][e] = pw[j][e - 1] * delta[j];
    }
    for (int k = 0; k < FE_QUADRIC_MOMENTS; k++)
        index[fe__quadric_exp[k][0]][fe__quadric_exp[k][1]][fe__quadric_exp[k][2]] = k;
    for (int k = 0; k < FE_QUADRIC_MOMENTS; k++) {
        int a = fe__quadric_exp[k][0], b = fe__quadric_exp[k][1],
            c = fe__quadric_exp[k][2];
        double s = 0.0;
        for (int p = 0; p <= a; p++)
            for (int r = 0; r <= b; r++)
                for (int t = 0; t <= c; t++)
                    s += binom[a][p] * binom[b][r] * binom[c][t]
                       * pw[0][a - p] * pw[1][b - r] * pw[2][c - t]
                       * m[index[p][r][t]];
        if (!fe__finite(s))
            return FE_ENONFINITE;
        out[k] = s;
    }
    return FE_OK;
}

int fe_quadric_recentre(fe_quadric *q, const double ref[3])
{
    double delta[3], out[FE_QUADRIC_MOMENTS];
    int rc;
    if (q == NULL || ref == NULL)
        return FE_EINVAL;
    if (!fe__finite(ref[0]) || !fe__finite(ref[1]) || !fe__finite(ref[2]))
        return FE_ENONFINITE;
    for (int j = 0; j < 3; j++)
        delta[j] = q->ref[j] - ref[j];
    rc = fe__quadric_shift(q->m, delta, out);
    if (rc != FE_OK)
        return rc;
    for (int k = 0; k < FE_QUADRIC_MOMENTS; k++)
        q->m[k] = out[k];
    for (int j = 0; j < 3; j++)
        q->ref[j] = ref[j];
    q->flags |= FE_QUADRIC_HAS_REF;
    return FE_OK;
}
/* Move moments to another reference ends here */
/* [[file:../literate/quadric.org::Merge two accumulations][Merge two accumulations]] */
int fe_quadric_merge(fe_quadric *a, const fe_quadric *b)
{
    double delta[3], moved[FE_QUADRIC_MOMENTS], sum[FE_QUADRIC_MOMENTS];
    int rc;

    if (a == NULL || b == NULL)
        return FE_EINVAL;
    if (b->m[0] == 0.0)
        return FE_OK;
    if (a->m[0] == 0.0 && !(a->flags & FE_QUADRIC_FIXED_REF)) {
        *a = *b;
        return FE_OK;
    }
    for (int j = 0; j < 3; j++)
        delta[j] = b->ref[j] - a->ref[j];
    rc = fe__quadric_shift(b->m, delta, moved);
    if (rc != FE_OK)
        return rc;
    for (int k = 0; k < FE_QUADRIC_MOMENTS; k++) {
        sum[k] = a->m[k] + moved[k];
        if (!fe__finite(sum[k]))
            return FE_ENONFINITE;
    }
    for (int j = 0; j < 3; j++) {
        int first = a->m[0] == 0.0;
        a->lo[j] = first || b->lo[j] < a->lo[j] ? b->lo[j] : a->lo[j];
        a->hi[j] = first || b->hi[j] > a->hi[j] ? b->hi[j] : a->hi[j];
    }
    for (int k = 0; k < FE_QUADRIC_MOMENTS; k++)
        a->m[k] = sum[k];
    for (int r = 0; r < FE_QUADRIC_REGIONS; r++)
        a->seen[r] = b->seen[r] > a->seen[r] ? b->seen[r] : a->seen[r];
    return FE_OK;
}
/* Merge two accumulations ends here */
/* [[file:../literate/quadric.org::Compare two accumulations][Compare two accumulations]] */
int fe_quadric_compare(const fe_quadric *a, const fe_quadric *b, double *apart)
{
    double s = 0.0, worst = 0.0;
    if (a == NULL || b == NULL || apart == NULL)
        return FE_EINVAL;
    if (a->m[0] != b->m[0])
        return FE_EMISMATCH;
    for (int j = 0; j < 3; j++) {
        double up = b->hi[j] - b->ref[j], down = b->ref[j] - b->lo[j];
        if (a->ref[j] != b->ref[j] || a->lo[j] != b->lo[j] || a->hi[j] != b->hi[j])
            return FE_EMISMATCH;
        s = up > s ? up : s;
        s = down > s ? down : s;
    }
    for (int k = 1; k < FE_QUADRIC_MOMENTS && b->m[0] > 0.0; k++) {
        double size = b->m[0], d = a->m[k] - b->m[k];
        for (int e = 0; e < fe__quadric_exp[k][0] + fe__quadric_exp[k][1]
                            + fe__quadric_exp[k][2]; e++)
            size *= s;
        d = d < 0.0 ? -d : d;
        if (size > 0.0 && d / size > worst)
            worst = d / size;
        else if (!(size > 0.0) && d > 0.0)
            worst = d;                  /* a box of one point: absolute */
    }
    *apart = worst;
    return FE_OK;
}
/* Compare two accumulations ends here */
/* [[file:../literate/quadric.org::Read out the count and the coverage][Read out the count and the coverage]] */
int fe_quadric_init(fe_quadric *q, const double *centre)
{
    fe_quadric e = FE_QUADRIC_EMPTY;
    if (q == NULL)
        return FE_EINVAL;
    if (centre != NULL) {
        for (int j = 0; j < 3; j++) {
            if (!fe__finite(centre[j]))
                return FE_ENONFINITE;
            e.ref[j] = centre[j];
        }
        e.flags = FE_QUADRIC_HAS_REF | FE_QUADRIC_FIXED_REF;
    }
    *q = e;
    return FE_OK;
}

uint64_t fe_quadric_count(const fe_quadric *q)
{
    return q != NULL ? (uint64_t)q->m[0] : 0;
}

int fe_quadric_regions(const fe_quadric *q)
{
    double c[3];
    float half;
    int n = 0;
    if (q == NULL || q->m[0] == 0.0)
        return 0;
    half = 0.5f * fe__quadric_frame(q, c);
    for (int r = 0; r < FE_QUADRIC_REGIONS; r++)
        n += q->seen[r] > 0.0f && q->seen[r] >= half;
    return n;
}

double fe_quadric_coverage(const fe_quadric *q)
{
    return (double)fe_quadric_regions(q) / FE_QUADRIC_REGIONS;
}
/* Read out the count and the coverage ends here */
/* [[file:../literate/quadric.org::Moments as an accumulator][Moments as an accumulator]] */
static int fe__quadric_init_fn(void *acc, void *ctx)
{
    return fe_quadric_init(acc, ctx);
}

static int fe__quadric_step(void *acc, const void *obs, void *ctx)
{
    (void)ctx;
    return fe_quadric_add(acc, obs);
}

static int fe__quadric_step_many(void *acc, const void *obs, size_t n,
                                 size_t *done, void *ctx)
{
    (void)ctx;
    return fe_quadric_add_many(acc, obs, n, done);
}

static int fe__quadric_merge_fn(void *acc, const void *other, void *ctx)
{
    (void)ctx;
    return fe_quadric_merge(acc, other);
}

fe_accumulator fe_quadric_accumulator(const double *centre)
{
    fe_accumulator f = {
        .name = "quadric",
        .acc_size = sizeof(fe_quadric),
        .obs_size = 3 * sizeof(double),
        .init = fe__quadric_init_fn,
        .step = fe__quadric_step,
        .step_many = fe__quadric_step_many,
        .merge = fe__quadric_merge_fn,
        .copy = 0,
        /* read, never written, by the functions above */
        .ctx = (void *)(uintptr_t)centre,
    };
    return f;
}
/* Moments as an accumulator ends here */
/* [[file:../literate/quadric.org::Fold in blocks of consecutive samples][Fold in blocks of consecutive samples]] */
int fe_quadric_blocks_init(fe_quadric_blocks *qb)
{
    if (qb == NULL)
        return FE_EINVAL;
    *qb = (fe_quadric_blocks){.all = FE_QUADRIC_EMPTY, .block_len = 1};
    return FE_OK;
}

/* Merge neighbours pairwise: blocks 2k and 2k+1 become block k. */
static int fe__quadric_blocks_halve(fe_quadric_blocks *qb)
{
    uint32_t n = qb->nblocks, k;
    for (k = 0; 2 * k < n; k++) {
        fe_quadric pair = qb->block[2 * k];
        if (2 * k + 1 < n) {
            int rc = fe_quadric_merge(&pair, &qb->block[2 * k + 1]);
            if (rc != FE_OK)
                return rc;
        }
        qb->block[k] = pair;
    }
    for (uint32_t j = k; j < n; j++)
        qb->block[j] = (fe_quadric)FE_QUADRIC_EMPTY;
    qb->nblocks = k;
    qb->block_len = (qb->block_len ? qb->block_len : 1) * 2;
    return FE_OK;
}

int fe_quadric_blocks_add(fe_quadric_blocks *qb, const double x[3])
{
    fe_quadric cur = FE_QUADRIC_EMPTY, all;
    uint64_t len;
    int fresh, rc;
    if (qb == NULL || x == NULL)
        return FE_EINVAL;
    len = qb->block_len ? qb->block_len : 1;
    fresh = qb->nblocks == 0 || qb->block[qb->nblocks - 1].m[0] >= (double)len;
    if (!fresh)
        cur = qb->block[qb->nblocks - 1];
    rc = fe_quadric_add(&cur, x);
    if (rc != FE_OK)
        return rc;
    all = qb->all;
    rc = fe_quadric_add(&all, x);
    if (rc != FE_OK)
        return rc;
    if (fresh && qb->nblocks == FE_QUADRIC_BLOCKS) {
        fe_quadric_blocks keep = *qb;
        rc = fe__quadric_blocks_halve(qb);
        if (rc != FE_OK) {
            *qb = keep;
            return rc;
        }
    }
    qb->all = all;
    if (fresh)
        qb->nblocks++;
    qb->block[qb->nblocks - 1] = cur;
    return FE_OK;
}

/* Many samples: each run up to the end of the current block is folded
   into a copy of the block and of `all` with fe_quadric_add_many; when
   either refuses a sample, the run is folded again up to the first sample
   both accepted, so that the blocks and `all` hold the same samples. */
int fe_quadric_blocks_add_many(fe_quadric_blocks *qb, const double *x, size_t n,
                               size_t *done)
{
    size_t i = 0;
    if (done != NULL)
        *done = 0;
    if (qb == NULL || (x == NULL && n > 0))
        return FE_EINVAL;
    while (i < n) {
        fe_quadric_blocks keep;
        fe_quadric cur = FE_QUADRIC_EMPTY, all = qb->all;
        uint64_t len = qb->block_len ? qb->block_len : 1, room;
        size_t m, got_cur = 0, got_all = 0;
        int fresh = qb->nblocks == 0 || qb->block[qb->nblocks - 1].m[0] >= (double)len;
        int halved = 0, rc_cur, rc_all;
        if (fresh && qb->nblocks == FE_QUADRIC_BLOCKS) {
            int rc;
            keep = *qb;
            rc = fe__quadric_blocks_halve(qb);
            if (rc != FE_OK) {
                *qb = keep;
                return rc;
            }
            halved = 1;
            len = qb->block_len;
        }
        if (!fresh)
            cur = qb->block[qb->nblocks - 1];
        room = fresh ? len : len - (uint64_t)cur.m[0];
        m = (uint64_t)(n - i) < room ? n - i : (size_t)room;
        rc_cur = fe_quadric_add_many(&cur, x + 3 * i, m, &got_cur);
        rc_all = fe_quadric_add_many(&all, x + 3 * i, m, &got_all);
        if (rc_cur != FE_OK || rc_all != FE_OK) {
            size_t d = got_cur < got_all ? got_cur : got_all;
            int rc = rc_cur != FE_OK && got_cur == d ? rc_cur : rc_all;
            if (d == 0) {
                if (halved)
                    *qb = keep;
                if (done != NULL)
                    *done = i;
                return rc;
            }
            cur = fresh ? (fe_quadric)FE_QUADRIC_EMPTY : qb->block[qb->nblocks - 1];
            all = qb->all;
            fe_quadric_add_many(&cur, x + 3 * i, d, NULL);
            fe_quadric_add_many(&all, x + 3 * i, d, NULL);
            qb->all = all;
            if (fresh)
                qb->nblocks++;
            qb->block[qb->nblocks - 1] = cur;
            if (done != NULL)
                *done = i + d;
            return rc;
        }
        qb->all = all;
        if (fresh)
            qb->nblocks++;
        qb->block[qb->nblocks - 1] = cur;
        i += m;
    }
    if (done != NULL)
        *done = n;
    return FE_OK;
}

int fe_quadric_blocks_merge(fe_quadric_blocks *a, const fe_quadric_blocks *b)
{
    fe_quadric_blocks x, y;
    int rc;
    if (a == NULL || b == NULL)
        return FE_EINVAL;
    if (b->nblocks == 0)
        return FE_OK;
    x = *a;
    y = *b;
    if (x.block_len == 0)
        x.block_len = 1;
    if (y.block_len == 0)
        y.block_len = 1;
    rc = fe_quadric_merge(&x.all, &y.all);
    while (rc == FE_OK && x.nblocks > 0 && x.block_len < y.block_len)
        rc = fe__quadric_blocks_halve(&x);
    while (rc == FE_OK && x.nblocks > 0 && y.block_len < x.block_len)
        rc = fe__quadric_blocks_halve(&y);
    if (x.nblocks == 0)
        x.block_len = y.block_len;
    while (rc == FE_OK && x.nblocks + y.nblocks > FE_QUADRIC_BLOCKS) {
        rc = fe__quadric_blocks_halve(&x);
        if (rc == FE_OK)
            rc = fe__quadric_blocks_halve(&y);
    }
    if (rc != FE_OK)
        return rc;
    for (uint32_t k = 0; k < y.nblocks; k++)
        x.block[x.nblocks + k] = y.block[k];
    x.nblocks += y.nblocks;
    *a = x;
    return FE_OK;
}
/* Fold in blocks of consecutive samples ends here */
/* [[file:../literate/quadric.org::Compute the monomials of one sample in float][Compute the monomials of one sample in float]] */
static int fe__finite_f32(float x)
{
    return x - x == 0.0f;
}

/* 4 * parent + axis of each monomial: u^alpha_k = u^alpha_parent * u_axis. */
static const unsigned char fe__quadric_parent[FE_QUADRIC_MOMENTS] = {
    0,
    0 * 4 + 0, 0 * 4 + 1, 0 * 4 + 2,
    1 * 4 + 0, 1 * 4 + 1, 1 * 4 + 2, 2 * 4 + 1, 2 * 4 + 2, 3 * 4 + 2,
    4 * 4 + 0, 4 * 4 + 1, 4 * 4 + 2, 5 * 4 + 1, 5 * 4 + 2, 6 * 4 + 2,
    7 * 4 + 1, 7 * 4 + 2, 8 * 4 + 2, 9 * 4 + 2,
    10 * 4 + 0, 10 * 4 + 1, 10 * 4 + 2, 11 * 4 + 1, 11 * 4 + 2, 12 * 4 + 2,
    13 * 4 + 1, 13 * 4 + 2, 14 * 4 + 2, 15 * 4 + 2, 16 * 4 + 1, 16 * 4 + 2,
    17 * 4 + 2, 18 * 4 + 2, 19 * 4 + 2
};

static void fe__quadric_monomials_f32(const float d[3], float p[35])
{
    p[0] = 1.0f;
    for (int k = 1; k < FE_QUADRIC_MOMENTS; k++)
        p[k] = p[fe__quadric_parent[k] >> 2] * d[fe__quadric_parent[k] & 3];
}
/* Compute the monomials of one sample in float ends here */
/* [[file:../literate/quadric.org::Move float moments to another reference][Move float moments to another reference]] */
static int fe__quadric_at(int a, int b, int c)
{
    int d = a + b + c;
    return d * (d + 1) * (d + 2) / 6 + (d - a) * (d - a + 1) / 2 + (d - a - b);
}

static int fe__quadric_shift_f32(const float m[35], const float delta[3],
                                 float out[35])
{
    for (int k = 0; k < FE_QUADRIC_MOMENTS; k++)
        out[k] = m[k];
    for (int j = 0; j < 3; j++)
        for (int i = 1; i <= 4; i++)
            for (int k = FE_QUADRIC_MOMENTS - 1; k > 0; k--) {
                int e[3] = {fe__quadric_exp[k][0], fe__quadric_exp[k][1],
                            fe__quadric_exp[k][2]};
                if (e[j] < i)
                    continue;
                e[j]--;
                out[k] += delta[j] * out[fe__quadric_at(e[0], e[1], e[2])];
            }
    for (int k = 0; k < FE_QUADRIC_MOMENTS; k++)
        if (!fe__finite_f32(out[k]))
            return FE_ENONFINITE;
    return FE_OK;
}

int fe_quadric_f32_recentre(fe_quadric_f32 *q, const float ref[3])
{
    float delta[3], out[FE_QUADRIC_MOMENTS];
    int rc;
    if (q == NULL || ref == NULL)
        return FE_EINVAL;
    if (!fe__finite_f32(ref[0]) || !fe__finite_f32(ref[1])
        || !fe__finite_f32(ref[2]))
        return FE_ENONFINITE;
    for (int j = 0; j < 3; j++)
        delta[j] = q->ref[j] - ref[j];
    rc = fe__quadric_shift_f32(q->m, delta, out);
    if (rc != FE_OK)
        return rc;
    for (int k = 0; k < FE_QUADRIC_MOMENTS; k++)
        q->m[k] = out[k];
    for (int j = 0; j < 3; j++)
        q->ref[j] = ref[j];
    q->flags |= FE_QUADRIC_HAS_REF;
    return FE_OK;
}
/* Move float moments to another reference ends here */
/* [[file:../literate/quadric.org::Fold one sample in float][Fold one sample in float]] */
int fe_quadric_f32_init(fe_quadric_f32 *q, const float *centre)
{
    fe_quadric_f32 e = FE_QUADRIC_F32_EMPTY;
    if (q == NULL)
        return FE_EINVAL;
    if (centre != NULL) {
        for (int j = 0; j < 3; j++) {
            if (!fe__finite_f32(centre[j]))
                return FE_ENONFINITE;
            e.ref[j] = centre[j];
        }
        e.flags = FE_QUADRIC_HAS_REF;
    }
    *q = e;
    return FE_OK;
}

int fe_quadric_f32_add(fe_quadric_f32 *q, const float x[3])
{
    float ref[3], d[3], p[FE_QUADRIC_MOMENTS], m[FE_QUADRIC_MOMENTS];
    int first;

    if (q == NULL || x == NULL)
        return FE_EINVAL;
    if (!fe__finite_f32(x[0]) || !fe__finite_f32(x[1]) || !fe__finite_f32(x[2]))
        return FE_ENONFINITE;
    if (q->n == UINT32_MAX)
        return FE_ESIZE;
    for (int j = 0; j < 3; j++)
        ref[j] = (q->flags & FE_QUADRIC_HAS_REF) ? q->ref[j] : x[j];
    for (int j = 0; j < 3; j++)
        d[j] = x[j] - ref[j];
    fe__quadric_monomials_f32(d, p);
    m[0] = (float)(q->n + 1);
    for (int k = 1; k < FE_QUADRIC_MOMENTS; k++) {
        m[k] = q->m[k] + p[k];
        if (!fe__finite_f32(m[k]))
            return FE_ENONFINITE;
    }
    first = q->n == 0;
    for (int k = 0; k < FE_QUADRIC_MOMENTS; k++)
        q->m[k] = m[k];
    for (int j = 0; j < 3; j++) {
        q->ref[j] = ref[j];
        if (first || x[j] < q->lo[j])
            q->lo[j] = x[j];
        if (first || x[j] > q->hi[j])
            q->hi[j] = x[j];
    }
    q->n++;
    q->flags |= FE_QUADRIC_HAS_REF;
    /* Move the reference to the mean when it has drifted */
    {
        float mean[3], size = 0.0f, drift = 0.0f;
        for (int j = 0; j < 3; j++) {
            float h = 0.5f * (q->hi[j] - q->lo[j]), d;
            mean[j] = q->ref[j] + q->m[1 + j] / q->m[0];
            d = mean[j] - q->ref[j];
            d = d < 0.0f ? -d : d;
            size = h > size ? h : size;
            drift = d > drift ? d : drift;
        }
        if (10.0f * drift > size && fe_quadric_f32_recentre(q, mean) == FE_OK)
            q->recentres++;
    }
    return FE_OK;
}
/* Fold one sample in float ends here */
/* [[file:../literate/quadric.org::Widen a float accumulation][Widen a float accumulation]] */
int fe_quadric_from_f32(fe_quadric *q, const fe_quadric_f32 *f)
{
    fe_quadric e = FE_QUADRIC_EMPTY;
    if (q == NULL || f == NULL)
        return FE_EINVAL;
    e.m[0] = (double)f->n;
    for (int k = 1; k < FE_QUADRIC_MOMENTS; k++)
        e.m[k] = (double)f->m[k];
    for (int j = 0; j < 3; j++) {
        e.ref[j] = (double)f->ref[j];
        e.lo[j] = (double)f->lo[j];
        e.hi[j] = (double)f->hi[j];
    }
    e.flags = f->flags & FE_QUADRIC_HAS_REF;
    *q = e;
    return FE_OK;
}
/* Widen a float accumulation ends here */
