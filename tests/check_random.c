/* SPDX-License-Identifier: MIT */
/* The generator: reproducible, uniform in [0,1), normal with the right
   moments, independent streams for different seeds. */
#include <stdint.h>

#include "foldest.h"
#include "testutil.h"

START_TEST(same_seed_same_stream)
{
    fe_rng a = fe_rng_seed(7), b = fe_rng_seed(7), c = fe_rng_seed(8);
    int differ = 0;
    for (int i = 0; i < 1000; i++) {
        uint64_t x = fe_rng_next(&a);
        ck_assert_uint_eq(x, fe_rng_next(&b));
        differ += x != fe_rng_next(&c);
    }
    ck_assert_int_gt(differ, 990);
}
END_TEST

START_TEST(known_first_values)
{
    /* Pinned so that a change of algorithm cannot go unnoticed: the
       synthetic data of tests and demo depend on this sequence. */
    fe_rng r = fe_rng_seed(0);
    uint64_t first = fe_rng_next(&r);
    fe_rng again = fe_rng_seed(0);
    ck_assert_uint_eq(first, fe_rng_next(&again));
    ck_assert_uint_ne(first, 0);
}
END_TEST

START_TEST(uniform_and_normal_moments)
{
    enum { N = 200000 };
    fe_rng r = fe_rng_seed(1);
    fe_meanvar u = FE_MEANVAR_EMPTY, z = FE_MEANVAR_EMPTY;
    int out_of_range = 0;
    for (int i = 0; i < N; i++) {
        double x = fe_rng_uniform(&r);
        out_of_range += !(x >= 0.0 && x < 1.0);
        fe_meanvar_add(&u, x);
        fe_meanvar_add(&z, fe_rng_normal(&r));
    }
    ck_assert_int_eq(out_of_range, 0);
    /* Tolerances are 5 standard errors. */
    ck_assert_double_eq_tol(u.mean, 0.5, 5 * sqrt(1.0 / 12 / N));
    /* Var of the sample variance of U(0,1): (1/80 - 1/144)/N. */
    ck_assert_double_eq_tol(fe_meanvar_variance(&u), 1.0 / 12, 5 * sqrt((1.0 / 80 - 1.0 / 144) / N));
    ck_assert_double_eq_tol(z.mean, 0.0, 5 * sqrt(1.0 / N));
    ck_assert_double_eq_tol(fe_meanvar_variance(&z), 1.0, 5 * sqrt(2.0 / N));
}
END_TEST

START_TEST(unit_vectors_are_unit_and_uniform)
{
    /* Length 1, and each coordinate's mean 0 and variance 1/3 (uniform on
       the sphere), within 5 standard errors. */
    enum { N = 100000 };
    fe_rng r = fe_rng_seed(3);
    fe_meanvar c[3] = {FE_MEANVAR_EMPTY, FE_MEANVAR_EMPTY, FE_MEANVAR_EMPTY};
    double worst = 0.0;
    for (int i = 0; i < N; i++) {
        double u[3], len;
        fe_rng_unit_vector(&r, u);
        len = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
        worst = fabs(len - 1.0) > worst ? fabs(len - 1.0) : worst;
        for (int j = 0; j < 3; j++)
            fe_meanvar_add(&c[j], u[j]);
    }
    ck_assert_double_le(worst, 1e-15);
    {
        /* u[0..2] and nothing past them: three normal deviates of the same
           stream, divided by their length. */
        fe_rng a = fe_rng_seed(5), b = fe_rng_seed(5);
        double u[4] = {0, 0, 0, 7.0}, z[3], len;
        fe_rng_unit_vector(&a, u);
        for (int j = 0; j < 3; j++)
            z[j] = fe_rng_normal(&b);
        len = sqrt(z[0] * z[0] + z[1] * z[1] + z[2] * z[2]);
        for (int j = 0; j < 3; j++)
            ck_assert_double_eq_tol(u[j], z[j] / len, 1e-15);
        ck_assert_double_eq(u[3], 7.0);
    }
    for (int j = 0; j < 3; j++) {
        ck_assert_double_eq_tol(c[j].mean, 0.0, 5 * sqrt(1.0 / 3 / N));
        /* Var(u^2) = E u^4 - 1/9 = 1/5 - 1/9 for a uniform direction. */
        ck_assert_double_eq_tol(fe_meanvar_variance(&c[j]), 1.0 / 3, 5 * sqrt((0.2 - 1.0 / 9) / N));
    }
}
END_TEST

/* Blackman and Vigna's xoshiro256** and Vigna's splitmix64 as published
   (prng.di.unimi.it), written here apart from the library. */
static uint64_t ref_splitmix64(uint64_t *x)
{
    uint64_t z = (*x += UINT64_C(0x9e3779b97f4a7c15));
    z = (z ^ (z >> 30)) * UINT64_C(0xbf58476d1ce4e5b9);
    z = (z ^ (z >> 27)) * UINT64_C(0x94d049bb133111eb);
    return z ^ (z >> 31);
}

static uint64_t ref_rotl(uint64_t x, int k)
{
    return (x << k) | (x >> (64 - k));
}

static uint64_t ref_next(uint64_t s[4])
{
    const uint64_t result = ref_rotl(s[1] * 5, 7) * 9, t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = ref_rotl(s[3], 45);
    return result;
}

START_TEST(the_published_generator)
{
    /* splitmix64 from 0 gives e220a8397b1dcdaf, 6e789e6aa1b965f4,
       06c45d188009454f (its published first values); the state is its
       first four outputs from the seed, and the stream is xoshiro256**'s:
       the first values for seeds 0 and 12345 (computed with Python's
       integers, not with this library), then 2000 values for several
       seeds against the reference above; uniforms are the top 53 bits
       times 2^-53; normals come in Box-Muller pairs, r cos(2 pi u2) then
       r sin(2 pi u2) with r = sqrt(-2 ln(1 - u1)), u1 and u2 the next two
       uniforms; a unit vector is three normals over their norm. */
    static const uint64_t seeds[] = {0, 1, 12345, UINT64_C(0xffffffffffffffff),
                                     UINT64_C(0x0123456789abcdef)};
    uint64_t x = 0;
    ck_assert_uint_eq(ref_splitmix64(&x), UINT64_C(0xe220a8397b1dcdaf));
    ck_assert_uint_eq(ref_splitmix64(&x), UINT64_C(0x6e789e6aa1b965f4));
    ck_assert_uint_eq(ref_splitmix64(&x), UINT64_C(0x06c45d188009454f));
    {
        fe_rng a = fe_rng_seed(0), b = fe_rng_seed(12345);
        ck_assert_uint_eq(fe_rng_next(&a), UINT64_C(0x99ec5f36cb75f2b4));
        ck_assert_uint_eq(fe_rng_next(&a), UINT64_C(0xbf6e1f784956452a));
        ck_assert_uint_eq(fe_rng_next(&a), UINT64_C(0x1a5f849d4933e6e0));
        ck_assert_uint_eq(fe_rng_next(&b), UINT64_C(0xbe6a36374160d49b));
        ck_assert_uint_eq(fe_rng_next(&b), UINT64_C(0x214aaa0637a688c6));
        ck_assert_uint_eq(fe_rng_next(&b), UINT64_C(0xf69d16de9954d388));
    }
    for (size_t k = 0; k < sizeof seeds / sizeof seeds[0]; k++) {
        uint64_t st[4], sd = seeds[k];
        fe_rng r = fe_rng_seed(seeds[k]);
        ck_assert_int_eq(r.has_spare, 0);
        for (int i = 0; i < 4; i++)
            st[i] = ref_splitmix64(&sd);
        for (int i = 0; i < 4; i++)
            ck_assert_uint_eq(r.s[i], st[i]);
        for (int i = 0; i < 2000; i++) {
            int kind = i % 4;
            if (kind == 0) {
                ck_assert_uint_eq(fe_rng_next(&r), ref_next(st));
            } else if (kind == 1) {
                double u = (double)(ref_next(st) >> 11) * 0x1.0p-53;
                ck_assert_double_eq(fe_rng_uniform(&r), u);
            } else if (kind == 2) {
                double u1 = 1.0 - (double)(ref_next(st) >> 11) * 0x1.0p-53;
                double u2 = (double)(ref_next(st) >> 11) * 0x1.0p-53;
                double rad = sqrt(-2.0 * log(u1)), a = 6.283185307179586476925286766559 * u2;
                ck_assert_double_eq_tol(fe_rng_normal(&r), rad * cos(a), 1e-15 * (1 + rad));
                ck_assert_int_eq(r.has_spare, 1);
                ck_assert_double_eq_tol(fe_rng_normal(&r), rad * sin(a), 1e-15 * (1 + rad));
                ck_assert_int_eq(r.has_spare, 0);
            } else {
                double u[3], z[3], n = 0.0;
                fe_rng copy = r;
                fe_rng_unit_vector(&r, u);
                for (int j = 0; j < 3; j++) {
                    z[j] = fe_rng_normal(&copy);
                    n += z[j] * z[j];
                }
                n = sqrt(n);
                for (int j = 0; j < 3; j++)
                    ck_assert_double_eq_tol(u[j], z[j] / n, 1e-15);
                /* The copy drew what the vector drew: the streams agree. */
                ck_assert_uint_eq(fe_rng_next(&copy), fe_rng_next(&r));
                ck_assert_double_eq(copy.spare, r.spare);
                ck_assert_int_eq(copy.has_spare, r.has_spare);
                /* Keep the reference in step: unit vectors drew normals
                   (in pairs, with the odd one's spare kept), and one
                   more value each. */
                memcpy(st, r.s, sizeof st);
                if (r.has_spare) {
                    double sp = fe_rng_normal(&r);
                    ck_assert_double_eq(sp, copy.spare);
                    ck_assert_int_eq(r.has_spare, 0);
                }
            }
        }
    }
}
END_TEST

Suite *fe_random_suite(void)
{
    Suite *s = suite_create("random");
    TCase *t = tcase_create("core");
    tcase_add_test(t, same_seed_same_stream);
    tcase_add_test(t, known_first_values);
    tcase_add_test(t, uniform_and_normal_moments);
    tcase_add_test(t, unit_vectors_are_unit_and_uniform);
    tcase_add_test(t, the_published_generator);
    suite_add_tcase(s, t);
    return s;
}
