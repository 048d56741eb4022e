/* SPDX-License-Identifier: MIT */
/* Helpers shared by the test suites. */
#ifndef FE_TESTUTIL_H
#define FE_TESTUTIL_H

#include <check.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "foldest/random.h"

/* Assert |got - want| <= rel * max(|want|, tiny): a relative tolerance. */
#define FE_ASSERT_REL(got, want, rel)                                        \
    do {                                                                     \
        double fe_g_ = (got), fe_w_ = (want);                                \
        double fe_s_ = fabs(fe_w_) > 1e-300 ? fabs(fe_w_) : 1e-300;          \
        ck_assert_msg(fabs(fe_g_ - fe_w_) <= (rel) * fe_s_,                  \
                      "%s = %.17g, want %.17g (relative error %.3g > %.3g)", \
                      #got, fe_g_, fe_w_, fabs(fe_g_ - fe_w_) / fe_s_,      \
                      (double)(rel));                                        \
    } while (0)

/* Nonzero under valgrind (FE_TEST_QUICK=1): heavy loops run smaller. */
static inline int fe_test_quick(void)
{
    const char *q = getenv("FE_TEST_QUICK");
    return q != NULL && *q != '\0' && *q != '0';
}

/* Directory of the real recordings (FOLDEST_DATA, else ../shared/data), or
   NULL with a visible message when it is missing: tests then skip. */
static inline const char *fe_test_data_dir(const char *why)
{
    const char *d = getenv("FOLDEST_DATA");
    char probe[4096];
    FILE *f;
    if (d == NULL || *d == '\0')
        d = "../shared/data";
    snprintf(probe, sizeof probe, "%s/README.md", d);
    f = fopen(probe, "r");
    if (f == NULL) {
        fprintf(stderr, "SKIP %s: no recordings at %s (set FOLDEST_DATA)\n", why, d);
        return NULL;
    }
    fclose(f);
    return d;
}

/* n samples x[3i..3i+2] on the axis-aligned ellipsoid with centre c and
   semi-axes r, plus normal noise of standard deviation `noise`. */
static inline void fe_test_ellipsoid_points(double *x, size_t n, const double c[3],
                                            const double r[3], double noise, uint64_t seed)
{
    fe_rng g = fe_rng_seed(seed);
    for (size_t i = 0; i < n; i++) {
        double v[3];
        fe_rng_unit_vector(&g, v);
        for (int j = 0; j < 3; j++)
            x[3 * i + j] = c[j] + r[j] * v[j] + noise * fe_rng_normal(&g);
    }
}

/* Read at most len - 1 bytes of the file at `path` into buf, NUL-terminated;
   the count.  The test fails when the file cannot be opened. */
static inline size_t fe_test_read_file(const char *path, char *buf, size_t len)
{
    FILE *f = fopen(path, "rb");
    size_t got;
    ck_assert_msg(f != NULL, "cannot open %s", path);
    got = fread(buf, 1, len - 1, f);
    buf[got] = '\0';
    fclose(f);
    return got;
}

/* Write `text` to dir/name; the test fails when it cannot. */
static inline void fe_test_write_file(const char *dir, const char *name, const char *text)
{
    char path[512];
    FILE *f;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    f = fopen(path, "w");
    ck_assert_msg(f != NULL, "cannot write %s", path);
    fputs(text, f);
    ck_assert_int_eq(fclose(f), 0);
}

/* Remove the folder `dir` (made by mkdtemp) and everything in it. */
static inline void fe_test_remove_dir(const char *dir)
{
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    ck_assert_int_eq(system(cmd), 0);
}

/* Solve the n x n system A x = b in place (Gauss-Jordan with partial
   pivoting, long double; A is destroyed, b receives x), for nb right-hand
   sides stored as the columns of b (n x nb, row-major). */
static inline void fe_test_solve(size_t n, long double *A, long double *b, size_t nb)
{
    for (size_t k = 0; k < n; k++) {
        size_t piv = k;
        for (size_t i = k + 1; i < n; i++)
            if (fabsl(A[i * n + k]) > fabsl(A[piv * n + k]))
                piv = i;
        for (size_t j = 0; j < n; j++) {
            long double t = A[k * n + j];
            A[k * n + j] = A[piv * n + j];
            A[piv * n + j] = t;
        }
        for (size_t j = 0; j < nb; j++) {
            long double t = b[k * nb + j];
            b[k * nb + j] = b[piv * nb + j];
            b[piv * nb + j] = t;
        }
        for (size_t i = 0; i < n; i++) {
            long double f;
            if (i == k)
                continue;
            f = A[i * n + k] / A[k * n + k];
            for (size_t j = 0; j < n; j++)
                A[i * n + j] -= f * A[k * n + j];
            for (size_t j = 0; j < nb; j++)
                b[i * nb + j] -= f * b[k * nb + j];
        }
    }
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < nb; j++)
            b[i * nb + j] /= A[i * n + i];
}

/* Inv <- M^{-1} for an n x n row-major M (destroyed): the system solved
   for the columns of the identity. */
static inline void fe_test_inverse(size_t n, long double *M, long double *Inv)
{
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < n; j++)
            Inv[i * n + j] = i == j;
    fe_test_solve(n, M, Inv, n);
}

#endif /* FE_TESTUTIL_H */
