/* SPDX-License-Identifier: MIT */
/* Tail probabilities against table values and identities. */
#define _DEFAULT_SOURCE
#include "foldest.h"
#include "foldest/special.h"
#include "testutil.h"

START_TEST(student_t_table_values)
{
    /* Two-sided 5% and 1% critical values (standard tables). */
    ck_assert_double_eq_tol(fe_student_t_two_sided(2.093024, 19), 0.05, 1e-6);
    ck_assert_double_eq_tol(fe_student_t_two_sided(2.860935, 19), 0.01, 1e-6);
    ck_assert_double_eq_tol(fe_student_t_two_sided(12.706205, 1), 0.05, 1e-6);
    ck_assert_double_eq_tol(fe_student_t_two_sided(1.959964, 1e9), 0.05, 1e-6);
    ck_assert_double_eq_tol(fe_student_t_two_sided(0.0, 5), 1.0, 1e-15);
    ck_assert_double_eq_tol(fe_student_t_quantile(0.05, 19), 2.093024, 1e-6);
    ck_assert_double_eq_tol(fe_student_t_quantile(0.01, 9), 3.249836, 1e-6);
    /* Cauchy (nu = 1) in closed form: P(|T| > t) = 1 - 2 atan(t)/pi. */
    for (double t = 0.1; t < 50; t *= 1.7)
        ck_assert_double_eq_tol(fe_student_t_two_sided(t, 1), 1 - 2 * atan(t) / M_PI, 1e-13);
}
END_TEST

START_TEST(f_and_chi_square)
{
    ck_assert_double_eq_tol(fe_f_upper(3.238872, 3, 16), 0.05, 1e-6);
    ck_assert_double_eq_tol(fe_f_upper(4.493998, 1, 16), 0.05, 1e-6);
    /* F(1, nu) is t^2. */
    ck_assert_double_eq_tol(fe_f_upper(2.5 * 2.5, 1, 12), fe_student_t_two_sided(2.5, 12), 1e-13);
    ck_assert_double_eq_tol(fe_chi2_upper(3.841459, 1), 0.05, 1e-6);
    ck_assert_double_eq_tol(fe_chi2_upper(18.307038, 10), 0.05, 1e-6);
    ck_assert_double_eq_tol(fe_chi2_upper(124.342113, 100), 0.05, 1e-6);
    /* chi-square with 2 degrees of freedom: exp(-x/2). */
    ck_assert_double_eq_tol(fe_chi2_upper(7.0, 2), exp(-3.5), 1e-14);
}
END_TEST

START_TEST(bad_arguments_give_nan)
{
    ck_assert(isnan(fe_beta_inc(-1, 1, 0.5)));
    ck_assert(isnan(fe_beta_inc(1, 1, 1.5)));
    ck_assert(isnan(fe_gamma_q(0, 1)));
    ck_assert(isnan(fe_student_t_two_sided(1, 0)));
    ck_assert(isnan(fe_student_t_quantile(0, 3)));
    ck_assert_double_eq(fe_student_t_two_sided(INFINITY, 3), 0.0);
    ck_assert_double_eq(fe_f_upper(-1, 2, 3), 1.0);
}
END_TEST

Suite *fe_special_suite(void)
{
    Suite *s = suite_create("special");
    TCase *t = tcase_create("core");
    tcase_add_test(t, student_t_table_values);
    tcase_add_test(t, f_and_chi_square);
    tcase_add_test(t, bad_arguments_give_nan);
    suite_add_tcase(s, t);
    return s;
}
