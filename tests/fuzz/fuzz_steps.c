/* SPDX-License-Identifier: MIT */
/* libFuzzer harness: every public step function fed arbitrary bytes as
   observations.  The first byte picks the estimator and its shape; the rest
   is decoded into doubles (raw IEEE bits, small integers, or scaled values,
   chosen per value so that the fuzzer reaches both garbage and plausible
   data).  Each step must either succeed, leaving every number of the
   accumulation finite, or refuse with a status and leave the accumulation's
   bytes exactly as they were.  Merges are checked the same way.  A broken
   promise aborts (libFuzzer saves the input). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "foldest.h"

typedef struct in { const uint8_t *p; size_t n; } in;

static unsigned byte(in *s)
{
    if (s->n == 0)
        return 0;
    s->n--;
    return *s->p++;
}

/* One double: raw bits, a small integer, or m * 2^e with a wide exponent. */
static double number(in *s)
{
    unsigned tag = byte(s);
    if ((tag & 3) == 0 && s->n >= 8) {
        double v;
        memcpy(&v, s->p, 8);
        s->p += 8;
        s->n -= 8;
        return v;
    }
    if ((tag & 3) == 1)
        return (double)(int8_t)byte(s);
    {
        int m = (int)(int16_t)(byte(s) | byte(s) << 8);
        int e = (int)(int8_t)byte(s) * 9;       /* 2^-1152 .. 2^1143: denormals, overflow */
        return ldexp((double)m, e);
    }
}

static void fill(in *s, double *x, size_t n)
{
    for (size_t i = 0; i < n; i++)
        x[i] = number(s);
}

static int finite_all(const double *x, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(x[i]))
            return 0;
    return 1;
}

#include "fuzz_require.h"

/* Step with a snapshot of `bytes` bytes at `mem`: refused means unchanged. */
#define STEP(call, mem, bytes, snap)                                           \
    do {                                                                       \
        memcpy((snap), (mem), (bytes));                                        \
        rc = (call);                                                           \
        if (rc != FE_OK)                                                       \
            REQUIRE(memcmp((snap), (mem), (bytes)) == 0);                      \
        REQUIRE(fe_strerror(rc) != NULL);                                      \
    } while (0)

static void fuzz_meanvar(in *s)
{
    fe_meanvar a = FE_MEANVAR_EMPTY, b = FE_MEANVAR_EMPTY, snap;
    int rc;
    while (s->n > 0) {
        double x = number(s);
        fe_meanvar *t = byte(s) & 1 ? &a : &b;
        STEP(fe_meanvar_add(t, x), t, sizeof *t, &snap);
        if (rc == FE_OK)
            REQUIRE(isfinite(fe_meanvar_mean(t)) && isfinite(fe_meanvar_population_variance(t)));
    }
    STEP(fe_meanvar_merge(&a, &b), &a, sizeof a, &snap);
    if (rc == FE_OK)
        REQUIRE(isfinite(fe_meanvar_mean(&a)) && isfinite(fe_meanvar_population_variance(&a)));
}

static void fuzz_quadric(in *s, unsigned shape)
{
    fe_quadric a, b, snap;
    double c[3];
    int rc;
    fill(s, c, 3);
    rc = fe_quadric_init(&a, shape & 1 ? c : NULL);
    if (rc != FE_OK)
        return;
    fe_quadric_init(&b, shape & 1 ? c : NULL);
    while (s->n > 0) {
        double x[3];
        fe_quadric *t = byte(s) & 1 ? &a : &b;
        fill(s, x, 3);
        STEP(fe_quadric_add(t, x), t, sizeof *t, &snap);
        if (rc == FE_OK)
            REQUIRE(finite_all(t->m, FE_QUADRIC_MOMENTS));
    }
    STEP(fe_quadric_merge(&a, &b), &a, sizeof a, &snap);
    if (rc == FE_OK)
        REQUIRE(finite_all(a.m, FE_QUADRIC_MOMENTS));
}

static void fuzz_lsq(in *s, unsigned shape)
{
    size_t p = shape % 5, sz = fe_lsq_storage(p);
    double ga[36], gb[36], snap[36 + 8], j[5];
    fe_lsq a, b;
    int rc;
    fe_lsq_init(&a, p, ga);
    fe_lsq_init(&b, p, gb);
    while (s->n > 0) {
        unsigned how = byte(s);
        fe_lsq *t = how & 1 ? &a : &b;
        double r, w;
        fill(s, j, p);
        r = number(s);
        w = how & 2 ? number(s) : 1.0;
        memcpy(snap + sz, t, sizeof *t);
        if (how & 4) {
            size_t idx[2] = {byte(s) % (p + 1), byte(s) % (p + 1)};
            STEP(fe_lsq_add_sparse(t, idx, j, p < 2 ? p : 2, r, w), t->g, sz * sizeof *t->g, snap);
        } else {
            STEP(fe_lsq_add(t, j, r, w), t->g, sz * sizeof *t->g, snap);
        }
        if (rc != FE_OK)
            REQUIRE(memcmp(snap + sz, t, sizeof *t) == 0);
        else
            REQUIRE(finite_all(t->g, sz) && isfinite(t->wsum));
    }
    STEP(fe_lsq_merge(&a, &b), a.g, sz * sizeof *a.g, snap);
    if (rc == FE_OK && p > 0 && a.n > 0) {
        double x[4], rss, work[25];
        rc = fe_lsq_solve(&a, NULL, p, x, &rss, NULL, work);
        if (rc == FE_OK)
            REQUIRE(finite_all(x, p) && isfinite(rss));
    }
}

static void fuzz_schur(in *s, unsigned shape)
{
    size_t ng = shape % 3, nl = 1 + (shape >> 2) % 2, nb = 2;
    size_t sz = fe_schur_storage(ng, nl, nb);
    double mem[64], snap[64], jg[2], jl[2];
    fe_schur a;
    int rc;
    if (sz > 64 || fe_schur_init(&a, ng, nl, nb, mem) != FE_OK)
        return;
    while (s->n > 0) {
        unsigned how = byte(s);
        size_t block = how & 1 ? FE_SCHUR_NONE : (size_t)(how >> 1) % 3;
        fill(s, jg, ng);
        fill(s, jl, nl);
        double r = number(s), w = how & 8 ? number(s) : 1.0;
        STEP(fe_schur_add(&a, jg, block, jl, r, w), mem, sz * sizeof *mem, snap);
        if (rc == FE_OK)
            REQUIRE(finite_all(mem, sz));
    }
}

static void fuzz_kalman(in *s, unsigned shape)
{
    size_t n = 1 + shape % 4, bmax = 1 + (shape >> 2) % 3;
    size_t len = fe_kalman_doubles(n, bmax), ilen = fe_kalman_info_doubles(n, bmax);
    double *mem = calloc(len, sizeof *mem), *snap = calloc(len > ilen ? len : ilen, sizeof *snap);
    double *imem = calloc(ilen, sizeof *imem);
    double A[12], z[3], Z[9], nis_w[3];
    fe_kalman k;
    fe_kalman_info info;
    fe_kalman_monitor mon, msnap;
    int fast = (shape >> 4) & 1, rc;
    if (mem == NULL || snap == NULL || imem == NULL)
        goto done;
    if (fe_kalman_init(&k, n, bmax, mem, len) != FE_OK
        || fe_kalman_info_init(&info, n, bmax, imem, ilen) != FE_OK)
        goto done;
    if (fe_kalman_set_prior_scaled(&k, NULL, fabs(number(s))) != FE_OK)
        fe_kalman_set_prior_scaled(&k, NULL, 1.0);
    fe_kalman_monitor_init(&mon, NULL);
    while (s->n > 0) {
        fe_kalman_obs o;
        fe_kalman_report r = {0, 0, 0, NULL, nis_w, NULL};
        o.b = 1 + byte(s) % bmax;
        fill(s, A, o.b * n);
        fill(s, z, o.b);
        fill(s, Z, o.b * o.b);
        o.A = A;
        o.z = z;
        o.Z = Z;
        /* x and P: the first n + n*n doubles of mem; count beside them. */
        {
            uint64_t count = k.count;
            memcpy(snap, k.x, n * sizeof *snap);
            memcpy(snap + n, k.P, n * n * sizeof *snap);
            rc = fast ? fe_kalman_update_fast(&k, &o, &r) : fe_kalman_update(&k, &o, &r);
            if (rc != FE_OK) {
                REQUIRE(memcmp(snap, k.x, n * sizeof *snap) == 0);
                REQUIRE(memcmp(snap + n, k.P, n * n * sizeof *snap) == 0);
                REQUIRE(count == k.count);
            } else {
                REQUIRE(finite_all(k.x, n) && finite_all(k.P, n * n));
                REQUIRE(isfinite(r.nis) && r.nis >= 0 && isfinite(r.log_det_D));
                memcpy(&msnap, &mon, sizeof mon);
                rc = fe_kalman_monitor_add(&mon, &r);
                if (rc != FE_OK)
                    REQUIRE(memcmp(&msnap, &mon, sizeof mon) == 0);
            }
        }
        {
            uint64_t count = info.count;
            memcpy(snap, info.eta, n * sizeof *snap);
            memcpy(snap + n, info.Lambda, n * n * sizeof *snap);
            rc = fe_kalman_info_update(&info, &o);
            if (rc != FE_OK) {
                REQUIRE(memcmp(snap, info.eta, n * sizeof *snap) == 0);
                REQUIRE(memcmp(snap + n, info.Lambda, n * n * sizeof *snap) == 0);
                REQUIRE(count == info.count);
            } else {
                REQUIRE(finite_all(info.eta, n) && finite_all(info.Lambda, n * n));
            }
        }
    }
    {
        fe_kalman k2;
        double *m2 = calloc(len, sizeof *m2);
        if (m2 != NULL && fe_kalman_init(&k2, n, bmax, m2, len) == FE_OK
            && fe_kalman_info_to_kalman(&info, &k2) == FE_OK)
            REQUIRE(finite_all(k2.x, n) && finite_all(k2.P, n * n));
        free(m2);
    }
done:
    free(mem);
    free(snap);
    free(imem);
}

static void fuzz_discover(in *s, unsigned shape)
{
    size_t m = 1 + shape % 3, K = 2;
    size_t nd = fe_discover_acc_doubles(m, K);
    double *mem = calloc(nd, sizeof *mem), *snap = calloc(nd, sizeof *snap), phi[3];
    fe_discover_acc a, as;
    int rc;
    if (mem == NULL || snap == NULL
        || fe_discover_acc_init(&a, m, K, 8, 0, mem, nd) != FE_OK)
        goto done;
    while (s->n > 0) {
        double r;
        fill(s, phi, m);
        r = number(s);
        memcpy(&as, &a, sizeof a);
        STEP(fe_discover_add(&a, phi, r), mem, nd * sizeof *mem, snap);
        if (rc != FE_OK)
            REQUIRE(memcmp(&as, &a, sizeof a) == 0);
        else
            REQUIRE(finite_all(mem, nd));
        if (byte(s) == 0xff)
            fe_discover_break(&a);
    }
done:
    free(mem);
    free(snap);
}

/* Discovery by columns: panels of up to 40 rows into a screen or a full
   accumulation (narrow: lane kernels; wide: the dsyrk panel), each call
   against the same rows folded one by one: the same status and count, a
   call that folds nothing leaves the values' bytes as they were, and every
   value stays finite.  (The storage's tail, from FE_DISCOVER_ACC_VALUES,
   is the array paths' scratch, not the accumulation: a panel refused by
   its sums leaves them there.) */
static void fuzz_discover_columns(in *s, unsigned shape)
{
    size_t m = 1 + shape % 10, nb = shape & 16 ? (shape >> 5) % (m + 1) : m, K = 2;
    size_t nd = fe_discover_acc_doubles(m, K), nv = FE_DISCOVER_ACC_VALUES(m, K);
    double *mem = calloc(nd, sizeof *mem), *ref = calloc(nd, sizeof *ref);
    double *snap = calloc(nd, sizeof *snap), col[10 * 40], r[40], row[10];
    fe_discover_acc a, b, as;
    int rc;
    if (mem == NULL || ref == NULL || snap == NULL
        || fe_discover_screen_init(&a, m, nb, K, 8 + byte(s), 0, mem, nd) != FE_OK
        || fe_discover_screen_init(&b, m, nb, K, a.fit_rows, 0, ref, nd) != FE_OK)
        goto done;
    while (s->n > 0) {
        size_t q = 1 + byte(s) % 40, done = 0, want = 0;
        int want_rc = FE_OK;
        for (size_t t = 0; t < q; t++) {
            for (size_t c = 0; c < m; c++)
                col[c * q + t] = number(s);
            r[t] = number(s);
        }
        memcpy(&as, &a, sizeof a);
        memcpy(snap, mem, nd * sizeof *mem);
        rc = fe_discover_add_columns(&a, col, q, r, q, &done);
        REQUIRE(fe_strerror(rc) != NULL);
        for (size_t t = 0; t < q && want_rc == FE_OK; t++) {
            for (size_t c = 0; c < m; c++)
                row[c] = col[c * q + t];
            want_rc = fe_discover_add(&b, row, r[t]);
            want += want_rc == FE_OK;
        }
        REQUIRE(rc == want_rc && done == want && a.n == b.n);
        if (done == 0)
            REQUIRE(memcmp(&as, &a, sizeof a) == 0 && memcmp(snap, mem, nv * sizeof *mem) == 0);
        REQUIRE(finite_all(mem, nv));
        if (byte(s) == 0xff) {
            fe_discover_break(&a);
            fe_discover_break(&b);
        }
    }
done:
    free(mem);
    free(ref);
    free(snap);
}

/* Discovery's generic-fold path: rows that carry their index, in order or
   not, starting recordings now and then. */
static void fuzz_discover_rows(in *s, unsigned shape)
{
    size_t m = 1 + shape % 3, K = 2;
    size_t nd = fe_discover_acc_doubles(m, K);
    double *mem = calloc(nd, sizeof *mem), *snap = calloc(nd, sizeof *snap), phi[3];
    fe_discover_acc a, as;
    uint64_t next = byte(s);
    int rc;
    if (mem == NULL || snap == NULL
        || fe_discover_acc_init(&a, m, K, 8, FE_DISCOVER_ROW_UNKNOWN, mem, nd) != FE_OK)
        goto done;
    while (s->n > 0) {
        fe_discover_row row;
        unsigned how = byte(s);
        fill(s, phi, m);
        row.phi = phi;
        row.r = number(s);
        row.index = (how & 3) == 3 ? next + byte(s) : next;  /* sometimes out of order */
        row.starts_recording = (how & 4) != 0;
        memcpy(&as, &a, sizeof a);
        STEP(fe_discover_add_row(&a, &row), mem, nd * sizeof *mem, snap);
        if (rc != FE_OK) {
            REQUIRE(memcmp(&as, &a, sizeof a) == 0);
        } else {
            REQUIRE(finite_all(mem, nd));
            next = row.index + 1;
        }
    }
done:
    free(mem);
    free(snap);
}

/* A Kalman filter's reports folded by time block, then located. */
static void fuzz_innovations(in *s, unsigned shape)
{
    fe_innovations a, as;
    fe_located out[8];
    double w[3];
    size_t nout = 0;
    int rc;
    if (fe_innovations_init(&a, 2 + shape % 3, 64, 0) != FE_OK)
        return;
    while (s->n > 0) {
        fe_kalman_report r = {0, 0, 0, NULL, NULL, NULL};
        unsigned how = byte(s);
        double t = number(s);
        r.b = how % 4;                       /* 0 is refused */
        r.nis = number(s);
        fill(s, w, 3);
        r.whitened = (how & 4) ? w : NULL;
        memcpy(&as, &a, sizeof a);
        rc = fe_innovations_add(&a, t, &r);
        if (rc != FE_OK)
            REQUIRE(memcmp(&as, &a, sizeof a) == 0);
        REQUIRE(fe_strerror(rc) != NULL);
        if ((how & 8) && rc == FE_OK)
            fe_innovations_break(&a);
    }
    rc = fe_innovations_locate(&a, 0.05, out, 8, &nout);
    REQUIRE(fe_strerror(rc) != NULL);
    if (rc == FE_OK)
        for (size_t i = 0; i < nout && i < 8; i++)
            REQUIRE(out[i].p_value >= 0.0 && out[i].p_value <= 1.0 && isfinite(out[i].n)
                    && isfinite(out[i].t0) && isfinite(out[i].t1));
}

/* Residuals folded into a residual map by block and region, then
   located and judged. */
static void fuzz_residual_map(in *s, unsigned shape)
{
    fe_residual_map *a = malloc(sizeof *a), *as = malloc(sizeof *as);
    fe_located out[8];
    double lo[3], hi[3];
    size_t nout = 0;
    int rc;
    fill(s, lo, 3);
    fill(s, hi, 3);
    if (a == NULL || as == NULL
        || fe_residual_map_init(a, 2 + shape % 3, 64, 0, shape >> 2, lo, hi) != FE_OK)
        goto done;
    while (s->n > 0) {
        fe_sample x;
        double before = number(s), after = number(s);
        unsigned how = byte(s);
        memset(&x, 0, sizeof x);
        x.t = number(s);
        x.position = number(s);
        x.velocity = (how & 1) ? 0.0 : number(s);
        x.temperature = number(s);
        memcpy(as, a, sizeof *a);
        rc = fe_residual_map_add(a, &x, before, after);
        if (rc != FE_OK)
            REQUIRE(memcmp(as, a, sizeof *a) == 0);
        REQUIRE(fe_strerror(rc) != NULL);
        if ((how & 8) && rc == FE_OK)
            fe_residual_map_break(a);
    }
    rc = fe_residual_map_locate(a, 1.0, 0.05, out, 8, &nout);
    REQUIRE(rc == FE_OK);
    for (size_t i = 0; i < nout && i < 8; i++) {
        char json[1024];
        REQUIRE(out[i].p_value >= 0.0 && out[i].p_value <= 1.0 && isfinite(out[i].n));
        REQUIRE(fe_located_json(&out[i], json, sizeof json) == FE_OK);
    }
    REQUIRE(!isnan(fe_residual_map_largest_after(a, 0.5)));
done:
    free(a);
    free(as);
}

/* A model given as callbacks: y = th0 + th1 u + th2 exp(x), which
   overflows for large positions; analytic or finite-difference Jacobian. */
static int model_predict(const fe_sample *x, const double *th, double *y, void *user)
{
    (void)user;
    *y = th[0] + th[1] * x->input + th[2] * exp(x->position);
    return FE_OK;
}

static int model_jacobian(const fe_sample *x, const double *th, double *jac, void *user)
{
    (void)th;
    (void)user;
    jac[0] = 1.0;
    jac[1] = x->input;
    jac[2] = exp(x->position);
    return FE_OK;
}

static void fuzz_model(in *s, unsigned shape)
{
    static const double theta0[3] = {0.5, 1.0, 0.1};
    fe_catalog_scale sc;
    fe_catalog c;
    fe_model md;
    fe_model_acc a, *as = malloc(sizeof *as);
    fe_sample x0 = {0, 0, 0, 0, 0.1, 0.2, 20, 20, 1}, x1 = {1, 0, 0, 0, -0.1, -0.3, 21, 20, 0};
    size_t nd;
    double *mem = NULL, *snap = NULL;
    int rc;
    memset(&sc, 0, sizeof sc);
    memset(&md, 0, sizeof md);
    if (as == NULL || fe_catalog_scale_add(&sc, &x0) != FE_OK
        || fe_catalog_scale_add(&sc, &x1) != FE_OK
        || fe_catalog_init(&c, FE_ROLE_POSITION | FE_ROLE_VELOCITY | FE_ROLE_INPUT, &sc) != FE_OK)
        goto done;
    md.p = 3;
    md.theta0 = theta0;
    md.predict = model_predict;
    md.jacobian = (shape & 1) ? model_jacobian : NULL;
    md.forward = (shape >> 1) & 1;
    nd = fe_model_acc_doubles(3, c.count, 2);
    mem = calloc(nd, sizeof *mem);
    snap = calloc(nd, sizeof *snap);
    if (nd == 0 || mem == NULL || snap == NULL
        || fe_model_acc_init(&a, &md, &c, 2, 8, mem, nd) != FE_OK)
        goto done;
    while (s->n > 0) {
        fe_sample x;
        memset(&x, 0, sizeof x);
        x.t = number(s);
        x.real = number(s);
        x.position = number(s);
        x.velocity = number(s);
        x.input = number(s);
        memcpy(as, &a, sizeof a);
        STEP(fe_model_add(&a, &x), mem, nd * sizeof *mem, snap);
        if (rc != FE_OK)
            REQUIRE(memcmp(as, &a, sizeof a) == 0);
        else
            REQUIRE(finite_all(mem, nd));
        if (byte(s) == 0xff)
            fe_model_break(&a);
    }
done:
    free(as);
    free(mem);
    free(snap);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    in s = {data, size};
    unsigned which = byte(&s), shape = byte(&s);
    switch (which % 11) {
    case 0: fuzz_meanvar(&s); break;
    case 1: fuzz_quadric(&s, shape); break;
    case 2: fuzz_lsq(&s, shape); break;
    case 3: fuzz_schur(&s, shape); break;
    case 4: fuzz_kalman(&s, shape); break;
    case 5: fuzz_discover(&s, shape); break;
    case 6: fuzz_discover_rows(&s, shape); break;
    case 7: fuzz_innovations(&s, shape); break;
    case 8: fuzz_model(&s, shape); break;
    case 10: fuzz_residual_map(&s, shape); break;
    default: fuzz_discover_columns(&s, shape); break;
    }
    return 0;
}
