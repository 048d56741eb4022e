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

START_TEST(chi_square_quantile_against_closed_forms)
{
    /* Two degrees of freedom: P(X <= x) = 1 - exp(-x/2), so the quantile
       is -2 log(1 - q), down to q = 1e-300.  One degree of freedom, small
       q: P(X <= x) = erf(sqrt(x/2)) = q gives x = (pi/2) q^2 (1 + x/3 +
       O(x^2)), to 1e-24 for q <= 1e-6.  The promise is about 1e-13
       relative. */
    static const double q2[] = {1e-300, 1e-100, 1e-30, 1e-12, 1e-6, 0.05, 0.5, 0.95, 0.999};
    static const double q1[] = {1e-30, 1e-12, 1e-6};
    for (size_t i = 0; i < sizeof q2 / sizeof q2[0]; i++) {
        double want = -2.0 * log1p(-q2[i]), got = fe_chi2_quantile(q2[i], 2.0);
        ck_assert_msg(fabs(got - want) <= 1e-13 * want, "dof 2, q %g: %.17g, want %.17g", q2[i],
                      got, want);
    }
    for (size_t i = 0; i < sizeof q1 / sizeof q1[0]; i++) {
        double x0 = M_PI / 2.0 * q1[i] * q1[i], want = x0 * (1.0 + x0 / 3.0);
        double got = fe_chi2_quantile(q1[i], 1.0);
        ck_assert_msg(fabs(got - want) <= 1e-13 * want, "dof 1, q %g: %.17g, want %.17g", q1[i],
                      got, want);
    }
}
END_TEST

START_TEST(normal_quantile_within_its_promised_error)
{
    /* References: Python's statistics.NormalDist().inv_cdf (Wichura's
       AS 241, about 1e-16), across the tails, the two switch points
       p = 0.02425 and 1 - 0.02425 (just below, at, just above) and the
       centre; the promise is a relative error below 1.2e-9. */
    static const double ref[][2] = {
        {1e-300, -37.047096299361201},
        {1e-10, -6.3613409024040557},
        {0.0001, -3.71901648545568},
        {0.01, -2.3263478740408408},
        {0.0242, -1.9738394633131993},
        {0.02425, -1.9729610513118845},
        {0.0243, -1.9720841590292884},
        {0.1, -1.2815515655446008},
        {0.3, -0.52440051270804067},
        {0.5, 0},
        {0.7, 0.52440051270804067},
        {0.9, 1.2815515655446008},
        {0.9757, 1.9720841590292884},
        {0.97575, 1.9729610513118847},
        {0.9758, 1.9738394633131993},
        {0.99, 2.3263478740408408},
        {0.9999, 3.7190164854557084},
        {0.9999999999, 6.3613408896974208},
    };
    for (size_t i = 0; i < sizeof ref / sizeof ref[0]; i++)
        FE_ASSERT_REL(fe_normal_quantile(ref[i][0]), ref[i][1], 1.2e-9);
}
END_TEST

START_TEST(digamma_and_trigamma_closed_forms)
{
    /* psi and psi' at points where they have closed forms (gamma is
       Euler's constant), on both sides of the switch to the asymptotic
       series at 6, and their recurrences across it. */
    const double gamma = 0.57721566490153286061, pi2 = 9.8696044010893586188;
    FE_ASSERT_REL(fe_digamma(1.0), -gamma, 1e-13);
    FE_ASSERT_REL(fe_digamma(0.5), -gamma - 2.0 * log(2.0), 1e-13);
    FE_ASSERT_REL(fe_digamma(2.0), 1.0 - gamma, 1e-13);
    FE_ASSERT_REL(fe_digamma(10.0), 2.8289682539682539683 - gamma, 1e-13);   /* H_9 - gamma */
    FE_ASSERT_REL(fe_digamma(100.0), 4.6001618527380874002, 1e-13);
    FE_ASSERT_REL(fe_trigamma(1.0), pi2 / 6.0, 1e-13);
    FE_ASSERT_REL(fe_trigamma(0.5), pi2 / 2.0, 1e-13);
    FE_ASSERT_REL(fe_trigamma(2.0), pi2 / 6.0 - 1.0, 1e-13);
    FE_ASSERT_REL(fe_trigamma(10.0), pi2 / 6.0 - 1.5397677311665406904, 1e-12);
    FE_ASSERT_REL(fe_trigamma(100.0), 0.010050166663333571395, 1e-12);
    for (double x = 0.25; x < 12.0; x += 0.75) {
        FE_ASSERT_REL(fe_digamma(x + 1.0) - fe_digamma(x), 1.0 / x, 1e-12);
        FE_ASSERT_REL(fe_trigamma(x) - fe_trigamma(x + 1.0), 1.0 / (x * x), 1e-11);
    }
    ck_assert(isnan(fe_digamma(0.0)));
    ck_assert(isnan(fe_trigamma(-1.0)));
    ck_assert(isnan(fe_digamma(NAN)));
    ck_assert(isnan(fe_trigamma(INFINITY)));
}
END_TEST

START_TEST(bad_arguments_give_nan)
{
    ck_assert(isnan(fe_beta_inc(-1, 1, 0.5)));
    ck_assert(isnan(fe_beta_inc(1, 1, 1.5)));
    ck_assert(isnan(fe_gamma_q(0, 1)));
    ck_assert(isnan(fe_chi2_upper(1.0, 0.0)));      /* k > 0 is the edge */
    ck_assert(isnan(fe_chi2_upper(1.0, -1.0)));
    ck_assert(isnan(fe_student_t_two_sided(1, 0)));
    ck_assert(isnan(fe_student_t_quantile(0, 3)));
    ck_assert_double_eq(fe_student_t_two_sided(INFINITY, 3), 0.0);
    ck_assert_double_eq(fe_f_upper(-1, 2, 3), 1.0);
}
END_TEST

/* The chi-square upper tail from 1 to 1e7 degrees of freedom, at the centre
   k and about 3 and 6 standard deviations sqrt(2k) either side.  Reference
   values: Q(k/2, x/2) computed with 50 digits by mpmath 1.3.0
   (mp.gammainc(k/2, x/2, mp.inf, regularized=True), mp.dps = 50) at the
   decimal x written here; printed to 17 digits.  Before the fix,
   fe_chi2_upper(1e6, 1e6) was 0.739 (0.512 at 1e5, 0.911 at 1e7). */
static const double chi2_reference[][3] = {
    {1.0, 1, 0.3173105078629141},
    {5.24264, 1, 0.022039803985687299},
    {9.48528, 1, 0.0020712700053132128},
    {2.0, 2, 0.36787944117144232},
    {8.0, 2, 0.01831563888873418},
    {14.0, 2, 0.00091188196555451621},
    {10.0, 10, 0.44049328506521241},
    {23.4164, 10, 0.0093096597023318951},
    {36.8328, 10, 6.0488691009749309e-5},
    {58.0, 100, 0.99975171267393628},
    {100.0, 100, 0.48119168452795672},
    {142.0, 100, 0.0036920523542641519},
    {185.0, 100, 5.0356524578869303e-7},
    {866.0, 1000, 0.999115897219802},
    {1000.0, 1000, 0.49405285382923964},
    {1134.0, 1000, 0.0019457873514089116},
    {1268.0, 1000, 1.4897902491933098e-8},
    {9576.0, 10000, 0.99880469938725861},
    {10000.0, 10000, 0.49811936596618264},
    {10424.0, 10000, 0.0015308473426415609},
    {10849.0, 10000, 2.5165951253542926e-9},
    {98658.0, 100000, 0.99870592549374574},
    {100000.0, 100000, 0.49940529189520669},
    {101342.0, 100000, 0.0013995852512145796},
    {102683.0, 100000, 1.3569624985612368e-9},
    {995757.0, 1000000, 0.99866788273472658},
    {1000000.0, 1000000, 0.4998119368033945},
    {1004243.0, 1000000, 0.0013655251244366811},
    {1008485.0, 1000000, 1.0927289165248974e-9},
    {9986584.0, 10000000, 0.99865497921736377},
    {10000000.0, 10000000, 0.49994052919606216},
    {10013416.0, 10000000, 0.0013555935230733283},
    {10026833.0, 10000000, 1.018479628954806e-9},
};

START_TEST(chi_square_quantile_far_in_the_lower_tail)
{
    /* Against 60-digit references (mpmath: the root of the regularised
       lower incomplete gamma, solved in log x), where the Wilson-Hilferty
       start fails: q far below the median, few and many degrees of
       freedom; a quantile below the smallest double is 0. */
    static const double ref[][3] = {
        {1e-100, 100, 0.39116223402411124654},   {1e-30, 30, 0.12898731599295860178},
        {1e-10, 1, 1.5707963267948966192e-20},   {1e-300, 2, 2.0e-300},
        {1e-12, 10, 0.020778689705003601115},    {1e-5, 1000, 820.6036570313778617},
    };
    for (size_t i = 0; i < sizeof ref / sizeof ref[0]; i++)
        FE_ASSERT_REL(fe_chi2_quantile(ref[i][0], ref[i][1]), ref[i][2], 1e-12);
    ck_assert(fe_chi2_quantile(1e-200, 0.5) == 0.0);         /* 1.35e-800 */
}
END_TEST

START_TEST(incomplete_beta_on_both_sides_of_its_switch)
{
    /* I_x(a, b) against mpmath 1.3 (betainc, regularized, 40 digits), at
       and above the mean (a + 1) / (a + b + 2), where the continued
       fraction is taken for 1 - I_x(b, a) and converges fast, and below
       it. */
    static const double ref[][4] = {
        {500, 500, 0.55, 0.99923632106047350918},
        {50, 3, 0.99, 0.98464737426634086262},
        {2000, 10, 0.998, 0.99169423191736340482},
        {0.5, 0.5, 0.9, 0.79516723530086657191},
        {30, 30, 0.7, 0.99936156208526031872},
        {30, 30, 0.3, 0.00063843791473967910199},
    };
    for (size_t i = 0; i < sizeof ref / sizeof ref[0]; i++)
        FE_ASSERT_REL(fe_beta_inc(ref[i][0], ref[i][1], ref[i][2]), ref[i][3], 1e-13);
}
END_TEST

START_TEST(chi2_upper_large_degrees_of_freedom)
{
    const double *c = chi2_reference[_i];
    FE_ASSERT_REL(fe_chi2_upper(c[0], c[1]), c[2], 1e-10);
}
END_TEST

Suite *fe_special_suite(void)
{
    Suite *s = suite_create("special");
    TCase *t = tcase_create("core");
    tcase_add_test(t, student_t_table_values);
    tcase_add_test(t, f_and_chi_square);
    tcase_add_test(t, chi_square_quantile_against_closed_forms);
    tcase_add_test(t, normal_quantile_within_its_promised_error);
    tcase_add_test(t, bad_arguments_give_nan);
    tcase_add_test(t, digamma_and_trigamma_closed_forms);
    tcase_add_test(t, chi_square_quantile_far_in_the_lower_tail);
    tcase_add_test(t, incomplete_beta_on_both_sides_of_its_switch);
    tcase_add_loop_test(t, chi2_upper_large_degrees_of_freedom, 0,
                        (int)(sizeof chi2_reference / sizeof chi2_reference[0]));
    suite_add_tcase(s, t);
    return s;
}
