/* SPDX-License-Identifier: MIT */
/* Tail probabilities against table values and identities. */
#define _DEFAULT_SOURCE
#include "foldest.h"
#include "foldest/special.h"
#include "testutil.h"

#include <float.h>
/* libquadmath, declared here rather than through <quadmath.h>: that header
   lies in GCC's own include directory, where clang does not look. */
__float128 acosq(__float128);
__float128 atanq(__float128);
__float128 cosq(__float128);
__float128 expq(__float128);
__float128 fabsq(__float128);
__float128 lgammaq(__float128);
__float128 log1pq(__float128);
__float128 logq(__float128);
__float128 sinq(__float128);
__float128 sqrtq(__float128);

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
    /* x = 0, the edge of the incomplete gamma's domain: P = 0 and Q = 1
       exactly, for a below, at and above 1 (special:521 of seed 4's
       sample left x = 0 to the series); just below 0, NaN. */
    {
        static const double a[] = {0.25, 1.0, 3.0, 200.0};
        for (size_t i = 0; i < sizeof a / sizeof a[0]; i++) {
            ck_assert_double_eq(fe_gamma_p(a[i], 0.0), 0.0);
            ck_assert_double_eq(fe_gamma_q(a[i], 0.0), 1.0);
            ck_assert(isnan(fe_gamma_p(a[i], -DBL_TRUE_MIN)));
            ck_assert(isnan(fe_gamma_q(a[i], -DBL_TRUE_MIN)));
        }
    }
    ck_assert(isnan(fe_chi2_upper(1.0, 0.0)));      /* k > 0 is the edge */
    ck_assert(isnan(fe_chi2_upper(1.0, -1.0)));
    ck_assert(isnan(fe_student_t_two_sided(1, 0)));
    ck_assert(isnan(fe_student_t_quantile(0, 3)));
    ck_assert_double_eq(fe_student_t_two_sided(INFINITY, 3), 0.0);
    ck_assert_double_eq(fe_f_upper(-1, 2, 3), 1.0);
    /* I_x(a, b): each argument alone at the edge of its domain (a, b > 0,
       0 <= x <= 1), just outside it NaN, on it or just inside a value. */
    {
        const double tiny = 1e-300, below0 = -DBL_TRUE_MIN, above1 = nextafter(1.0, 2.0);
        ck_assert(isnan(fe_beta_inc(0.0, 2.0, 0.5)));
        ck_assert(isnan(fe_beta_inc(2.0, 0.0, 0.5)));
        ck_assert(isnan(fe_beta_inc(2.0, 2.0, below0)));
        ck_assert(isnan(fe_beta_inc(2.0, 2.0, above1)));
        ck_assert(isnan(fe_beta_inc(NAN, 2.0, 0.5)));
        ck_assert(isnan(fe_beta_inc(2.0, NAN, 0.5)));
        ck_assert(isnan(fe_beta_inc(2.0, 2.0, NAN)));
        ck_assert_double_eq(fe_beta_inc(2.0, 2.0, 0.0), 0.0);
        ck_assert_double_eq(fe_beta_inc(2.0, 2.0, 1.0), 1.0);
        /* I_x(2, 2) = x^2 (3 - 2 x) */
        ck_assert_double_eq_tol(fe_beta_inc(2.0, 2.0, 0.25), 0.0625 * 2.5, 1e-15);
        ck_assert(!isnan(fe_beta_inc(tiny, 2.0, 0.5)) && !isnan(fe_beta_inc(2.0, tiny, 0.5)));
    }
    /* P(F > f): d1, d2 > 0 (fractional, under 1, too), f not NaN; with d1 = 2 it is
       (1 + 2 f / d2)^(-d2 / 2) exactly, and for d1 = 1/2 it is the beta
       tail I_{d2 / (d2 + d1 f)}(d2 / 2, d1 / 2). */
    ck_assert(isnan(fe_f_upper(1.0, 0.0, 3.0)));
    ck_assert(isnan(fe_f_upper(1.0, 3.0, 0.0)));
    ck_assert(isnan(fe_f_upper(NAN, 3.0, 3.0)));
    ck_assert_double_eq_tol(fe_f_upper(1.5, 2.0, 6.0), pow(1.0 + 2.0 * 1.5 / 6.0, -3.0), 1e-14);
    ck_assert_double_eq_tol(fe_f_upper(1.5, 0.5, 6.0),
                            fe_beta_inc(3.0, 0.25, 6.0 / (6.0 + 0.5 * 1.5)), 1e-14);
    ck_assert(fe_f_upper(1.5, 0.5, 6.0) > 0.0 && fe_f_upper(1.5, 0.5, 6.0) < 1.0);
    ck_assert_double_eq_tol(fe_f_upper(1.5, 2.0, 0.5),
                            fe_beta_inc(0.25, 1.0, 0.5 / (0.5 + 2.0 * 1.5)), 1e-14);
    /* I_y(d2/2, 1) = y^(d2/2) for d1 = 2 */
    ck_assert_double_eq_tol(fe_f_upper(1.5, 2.0, 0.5), pow(0.5 / 3.5, 0.25), 1e-14);
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


/* Independent references for the incomplete beta at many degrees of
   freedom.  No arbitrary-precision library is at hand, so the tails are
   integrated from their densities in __float128 (113-bit significand,
   libquadmath): 20-point Gauss-Legendre panels, nodes found here by
   Newton's method on P_20, walking away from the mode until the density
   has fallen by e^-110.  The normalising constants come from libquadmath's
   lgammaq, whose terms of size a log a (1e10 at a = 5e8) keep about 24
   digits in quadruple precision.  Nothing here shares a line with the
   library's continued fraction or its Stirling prefactor.  A panel is an
   eighth of a standard deviation wide, so the quadrature error is far
   below 1e-25; the references are rounded to double once, at the end. */
enum { REF_GL = 20 };
static __float128 ref_gl_x[REF_GL], ref_gl_w[REF_GL];

static void ref_gl_init(void)
{
    static int done;
    __float128 pi = acosq(-1);
    if (done)
        return;
    for (int i = 0; i < REF_GL; i++) {
        __float128 x = cosq(pi * (i + 0.75) / (REF_GL + 0.5)), dp = 1;
        for (int it = 0; it < 100; it++) {
            __float128 p0 = 1, p1 = x, dx;
            for (int k = 2; k <= REF_GL; k++) {
                __float128 p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            dp = REF_GL * (x * p1 - p0) / (x * x - 1);
            dx = p1 / dp;
            x -= dx;
            if (fabsq(dx) < 1e-32)
                break;
        }
        ref_gl_x[i] = x;
        ref_gl_w[i] = 2 / ((1 - x * x) * dp * dp);
    }
    done = 1;
}

typedef __float128 (*ref_log_density)(__float128 s, const __float128 *par);

static __float128 ref_panel(ref_log_density g, const __float128 *par, __float128 lo, __float128 hi)
{
    __float128 c = (lo + hi) / 2, r = (hi - lo) / 2, sum = 0;
    for (int i = 0; i < REF_GL; i++)
        sum += ref_gl_w[i] * expq(g(c + r * ref_gl_x[i], par));
    return sum * r;
}

/* The integral of exp(g) from s0 in direction dir (+1 or -1), in panels
   of width h, until g has fallen by 110 below g(s0) or s reaches 0. */
static __float128 ref_tail(ref_log_density g, const __float128 *par, __float128 s0, int dir,
                           __float128 h)
{
    __float128 g0 = g(s0, par), sum = 0, s = s0;
    while (g(s, par) > g0 - 110) {
        __float128 next = s + dir * h;
        if (next <= 0) {
            sum += ref_panel(g, par, 0, s);
            break;
        }
        sum += dir > 0 ? ref_panel(g, par, s, next) : ref_panel(g, par, next, s);
        s = next;
    }
    return sum;
}

/* Student's t density, par = {nu, log normaliser}. */
static __float128 ref_t_log_density(__float128 s, const __float128 *par)
{
    return par[1] - (par[0] + 1) / 2 * log1pq(s * s / par[0]);
}

/* P(|T| > t) for nu >= 1e4 (a light enough tail for the walk above). */
static double ref_t_two_sided(double t, double nu)
{
    __float128 par[2], q = nu, pi = acosq(-1), sum = 0;
    ref_gl_init();
    par[0] = q;
    par[1] = lgammaq((q + 1) / 2) - lgammaq(q / 2) - logq(q * pi) / 2;
    t = fabs(t);
    if (t > 1)
        return (double)(2 * ref_tail(ref_t_log_density, par, t, 1, 0.125));
    for (int k = 0; k < 8; k++)         /* 1 - 2 * integral over [0, t] */
        sum += ref_panel(ref_t_log_density, par, t * k / 8, t * (k + 1) / 8);
    return (double)(1 - 2 * sum);
}

/* Fisher's F density, par = {d1, d2, log normaliser}. */
static __float128 ref_f_log_density(__float128 f, const __float128 *par)
{
    return par[2] + (par[0] / 2 - 1) * logq(f) - (par[0] + par[1]) / 2 * logq(par[1] + par[0] * f);
}

/* P(F > f) for d1, d2 >= 1e3 (no singularity at 0 within reach), and in
   *fg the density times f: the change of P when f moves by a relative 1. */
static double ref_f_upper(double f, double d1, double d2, double *fg)
{
    __float128 par[3], a = d1, b = d2, mode, h;
    ref_gl_init();
    par[0] = a;
    par[1] = b;
    par[2] = a / 2 * logq(a) + b / 2 * logq(b)
           - (lgammaq(a / 2) + lgammaq(b / 2) - lgammaq((a + b) / 2));
    mode = (a - 2) / a * b / (b + 2);
    h = sqrtq(2 / a + 2 / b) / 8;
    *fg = (double)(f * expq(ref_f_log_density(f, par)));
    if (f >= mode)
        return (double)ref_tail(ref_f_log_density, par, f, 1, h);
    return (double)(1 - ref_tail(ref_f_log_density, par, f, -1, h));
}

/* P(|T| > t) for integer nu in closed form (Abramowitz and Stegun 26.7.3
   and 26.7.4: with theta = atan(t / sqrt(nu)), a finite sum of powers of
   cos(theta)), summed in __float128 so that the complement 1 - A keeps
   its relative accuracy down to 1e-15. */
static double ref_t_closed_form(double t, int nu)
{
    __float128 th = atanq(t / sqrtq(nu)), s = sinq(th), c = cosq(th), c2 = c * c, pi = acosq(-1);
    __float128 term = 1, sum = 1, a;
    if (nu % 2 == 0) {
        for (int k = 2; k <= nu - 2; k += 2) {
            term *= c2 * (k - 1) / k;
            sum += term;
        }
        a = s * sum;
    } else {
        for (int k = 3; k <= nu - 2; k += 2) {
            term *= c2 * (k - 1) / k;
            sum += term;
        }
        a = 2 / pi * (th + (nu > 1 ? s * c * sum : 0));
    }
    return (double)(1 - a);
}

/* With d1 = d2 the F distribution of 1/F is that of F, so f = 1 is its
   median: P(F > 1) = I_{1/2}(d/2, d/2) = 1/2 exactly.  Near the centre
   with both degrees of freedom large the continued fraction needs
   O(sqrt(d)) steps; a budget fixed at 500 gave 0.4999993 at 1e7 and 0.4886
   at 1e8 (and 0.18 at 1e9).  A converged fraction is off by rounding
   only: the prefactor and the fraction each carry a few 1e-16, and the
   fraction's 4000 steps at 1e9 add up to a few 1e-15 (measured: 2.6e-15);
   1e-13 absolute.  Beyond any sensible number of degrees of freedom, where
   the fraction cannot settle within its budget (a + m rounds to a), the
   answer is NaN, not a number; that case costs 10^8 steps (a second),
   skipped under valgrind. */
START_TEST(f_median_at_equal_large_dof)
{
    static const double dof[] = {1e5, 1e6, 1e7, 1e8, 1e9};
    for (size_t i = 0; i < sizeof dof / sizeof dof[0]; i++) {
        double got = fe_f_upper(1.0, dof[i], dof[i]);
        ck_assert_msg(fabs(got - 0.5) <= 1e-13, "P(F(%g, %g) > 1) = %.17g, want 1/2", dof[i],
                      dof[i], got);
    }
    if (!fe_test_quick())
        ck_assert_msg(isnan(fe_beta_inc(1e30, 1e30, 0.5)), "I_1/2(1e30, 1e30) = %.17g, want NaN",
                      fe_beta_inc(1e30, 1e30, 0.5));
}
END_TEST

/* The F upper tail with large and unequal degrees of freedom, near the
   centre and several standard deviations sqrt(2/d1 + 2/d2) out, against
   the quadrature reference above.  Before the fix: 2e-6 relative at
   (1, 1e5, 1e9), 2e-7 at (1.0002, 1e8, 1e8), 3e-9 at (1.01, 1e6, 3e6).
   A correct result carries the rounding of its arguments, x = d2 / (d2 +
   d1 f) and its complement (each within an ulp, so their ratio within 2
   ulps: a relative change of f by 2 epsilon, which moves P by 2 epsilon f
   g(f), g the density; f g(f) / P is 6000 at (1.001, 1e9, 1e7)), and
   that of the prefactor and the fraction: 1e-13 relative. */
static const double f_large_dof[][3] = {
    {1.0, 1e5, 1e9},        {1.0, 1e9, 1e5},        {1.001, 1e7, 1e7},     {0.999, 1e7, 1e7},
    {1.01, 1e6, 3e6},       {0.99, 1e8, 1e5},       {1.05, 1e4, 1e4},      {1.0002, 1e8, 1e8},
    {1.0012, 1e8, 1e8},     {0.9997, 1e9, 1e9},     {1.02, 1e5, 1e6},      {1.001, 1e9, 1e7},
};

START_TEST(f_upper_large_dof_against_quadrature)
{
    const double *c = f_large_dof[_i];
    double fg, want = ref_f_upper(c[0], c[1], c[2], &fg), got = fe_f_upper(c[0], c[1], c[2]);
    double tol = 1e-13 * want + 2.0 * DBL_EPSILON * fg;
    ck_assert_msg(fabs(got - want) <= tol, "P(F(%g, %g) > %g) = %.17g, want %.17g (%.2e, tolerance %.2e)",
                  c[1], c[2], c[0], got, want, fabs(got - want) / want, tol / want);
}
END_TEST

/* Student's t from 1e5 to 1e9 degrees of freedom, near 0 and out to
   t = 8 (P = 1.2e-15), against the quadrature reference.  The reference
   is checked first against what is known of the limit: P(|T| > t) =
   erfc(t / sqrt 2) + 2 phi(t) (t^3 + t) / (4 nu) + R, with the next term
   R = 2 phi(t) (3t^7 + 19t^5 + 17t^3 - 15t) / (96 nu^2) (Abramowitz and
   Stegun 26.7.5, Fisher's expansion); the reference must lie within 2|R|
   (plus 1e-15 relative for erfc) of the two terms, which a wrong
   normaliser or a lost panel would not.  Before the fix the library was off
   by 4e-9 (1e6), 1e-8 (1e7), 7e-7 (1e8) and 5e-6 (1e9) relative: the
   log-Gamma terms of its prefactor, of size a log a, cancelled, and the
   fraction, fed x = 1 - 4e-9 at t = 2, lost as many digits to 1 - x.  A
   correct result carries the rounding of x = nu / (nu + t^2) and its
   complement (relative sensitivity about t^2 epsilon, 1.4e-14 at t = 8)
   and of a prefactor whose terms are at most t^2 / 2: 1e-13 relative
   (measured after the fix: at most 1.3e-14). */
static const double t_large_dof[] = {1e5, 1e6, 1e7, 1e8, 1e9};

START_TEST(student_t_large_dof_against_quadrature)
{
    static const double ts[] = {1e-3, 0.01, 0.3, 0.5, 1.0, 1.2, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0};
    double nu = t_large_dof[_i];
    for (size_t j = 0; j < sizeof ts / sizeof ts[0]; j++) {
        double t = ts[j], want = ref_t_two_sided(t, nu), got = fe_student_t_two_sided(t, nu);
        double phi2 = 2.0 * exp(-0.5 * t * t) / sqrt(2.0 * M_PI), t2 = t * t;
        double two = erfc(t / sqrt(2.0)) + phi2 * (t2 * t + t) / (4.0 * nu);
        double r = phi2 * fabs(((3.0 * t2 + 19.0) * t2 + 17.0) * t2 * t - 15.0 * t) / (96.0 * nu * nu);
        ck_assert_msg(fabs(want - two) <= 2.0 * r + 1e-15 * want,
                      "reference %.17g at nu %g, t %g: expansion %.17g +- %.2g", want, nu, t, two,
                      2.0 * r);
        ck_assert_msg(fabs(got - want) <= 1e-13 * want,
                      "P(|T_%g| > %g) = %.17g, want %.17g (%.2e)", nu, t, got, want,
                      fabs(got - want) / want);
        ck_assert_msg(fabs(fe_f_upper(t * t, 1.0, nu) - want) <= 1e-13 * want,
                      "P(F(1, %g) > %g^2) = %.17g, want %.17g", nu, t, fe_f_upper(t * t, 1.0, nu),
                      want);
    }
}
END_TEST

/* The t quantile at many degrees of freedom: the two-sided tail of the
   returned t, by the quadrature reference, is the p asked for; bisection
   stops at 1e-13 (1 + t) in t, where the density (0.058 at t = 1.96)
   moves P by 2e-14.  Before the fix the tail of the returned t was off by
   4e-7 at p = 1/2 and 1e9 degrees of freedom (8e-10 at p = 0.05). */
START_TEST(student_t_quantile_large_dof)
{
    static const double ps[] = {0.5, 0.05, 1e-4};
    double nu = t_large_dof[_i];
    for (size_t j = 0; j < sizeof ps / sizeof ps[0]; j++) {
        double q = fe_student_t_quantile(ps[j], nu), back = ref_t_two_sided(q, nu);
        ck_assert_msg(fabs(back - ps[j]) <= 1e-12 * ps[j], "nu %g: quantile %.17g of %g has tail %.17g",
                      nu, q, ps[j], back);
    }
}
END_TEST

/* Integer degrees of freedom from 1 to 300 against the closed forms: here
   the prefactor's small-argument path (log Gamma below 10) and its Stirling
   path meet, and the rewrite must agree with the finite sums to rounding
   (1e-13 relative, P down to 1e-10). */
START_TEST(student_t_integer_dof_closed_forms)
{
    static const int nus[] = {1, 2, 3, 4, 7, 10, 19, 20, 21, 31, 50, 101, 300};
    static const double ts[] = {0.01, 0.5, 1.0, 2.0, 3.0, 5.0, 8.0};
    for (size_t i = 0; i < sizeof nus / sizeof nus[0]; i++)
        for (size_t j = 0; j < sizeof ts / sizeof ts[0]; j++) {
            double want = ref_t_closed_form(ts[j], nus[i]);
            double got = fe_student_t_two_sided(ts[j], nus[i]);
            if (want < 1e-10)
                continue;
            ck_assert_msg(fabs(got - want) <= 1e-13 * want,
                          "P(|T_%d| > %g) = %.17g, want %.17g (%.2e)", nus[i], ts[j], got, want,
                          fabs(got - want) / want);
        }
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
    tcase_add_test(t, f_median_at_equal_large_dof);
    tcase_add_loop_test(t, f_upper_large_dof_against_quadrature, 0,
                        (int)(sizeof f_large_dof / sizeof f_large_dof[0]));
    tcase_add_loop_test(t, student_t_large_dof_against_quadrature, 0,
                        (int)(sizeof t_large_dof / sizeof t_large_dof[0]));
    tcase_add_loop_test(t, student_t_quantile_large_dof, 0,
                        (int)(sizeof t_large_dof / sizeof t_large_dof[0]));
    tcase_add_test(t, student_t_integer_dof_closed_forms);
    suite_add_tcase(s, t);
    return s;
}
