/* SPDX-License-Identifier: MIT */
/* Tangled from literate/special.org: do not edit; edit the .org and run make tangle. */
/* [[file:../literate/special.org::Special Function Includes][Special Function Includes]] */
#include <float.h>
#include <math.h>

#include "foldest/special.h"

enum { FE__SPECIAL_ITERATIONS = 500 };
#define FE__SPECIAL_EPS 1e-15
#define FE__SPECIAL_TINY 1e-300
/* Special Function Includes ends here */
/* [[file:../literate/special.org::Evaluate the incomplete beta continued fraction][Evaluate the incomplete beta continued fraction]] */
/* I_x(a, b) divided by the prefactor x^a y^b / B(a, b), for
   lambda = a y - b x >= 0 (DiDonato and Morris's contracted fraction,
   with x and y = 1 - x each given accurately); NaN when it has not
   converged within 500 + 16 sqrt(max(a, b)) + 200 / min(a, b) steps. */
static double fe__beta_fraction(double a, double b, double x, double y, double lambda)
{
    double c = 1.0 + lambda, c0 = b / a, c1 = 1.0 + 1.0 / a, yp1 = y + 1.0;
    double p = 1.0, s = a + 1.0, an = 0.0, bn = 1.0, anp1 = 1.0, bnp1 = c / c1, r = c1 / c;
    int budget = FE__SPECIAL_ITERATIONS
                 + (int)fmin(16.0 * sqrt(fmax(a, b)) + 200.0 / fmin(a, b), 1e8);
    for (int n = 1; n <= budget; n++) {
        double t = n / a, w = n * (b - n) * x, e = a / s, alpha, beta, next, r0 = r;
        alpha = p * (p + c0) * e * e * (w * x);
        e = (1.0 + t) / (c1 + t + t);
        beta = n + w / s + e * (c + n * yp1);
        p = 1.0 + t;
        s += 2.0;
        next = alpha * an + beta * anp1;
        an = anp1;
        anp1 = next;
        next = alpha * bn + beta * bnp1;
        bn = bnp1;
        bnp1 = next;
        r = anp1 / bnp1;
        if (fabs(r - r0) <= FE__SPECIAL_EPS * r)
            return r;
        an /= bnp1;             /* rescale: the recurrences grow geometrically */
        bn /= bnp1;
        anp1 = r;
        bnp1 = 1.0;
    }
    return NAN;
}
/* Evaluate the incomplete beta continued fraction ends here */
/* [[file:../literate/special.org::Compute the incomplete beta function][Compute the incomplete beta function]] */
/* log(1 + u) - u, for u > -1, to full relative precision near u = 0. */
static double fe__log1p_minus(double u)
{
    double s, s2, pow, sum = 0.0;
    if (fabs(u) > 0.25)
        return log1p(u) - u;
    s = u / (2.0 + u);
    s2 = s * s;
    pow = s * s2;
    for (int k = 3; k <= 25; k += 2) {
        sum += pow / k;
        pow *= s2;
    }
    return -u * s + 2.0 * sum;
}


/* Stirling's remainder mu(z) = log Gamma(z) - (z - 1/2) log z + z
   - log(2 pi) / 2: its series to the z^-11 term for z >= 10 (the first
   term left out, 1 / (156 z^13), is below 7e-16 there), the difference
   of log Gamma and the main terms below. */
static double fe__stirling_rest(double z)
{
    double f;
    if (z < 10.0)
        return fe_log_gamma(z) - ((z - 0.5) * log(z) - z + 0.9189385332046728);
    f = 1.0 / (z * z);
    return (1.0 / 12.0
            - f * (1.0 / 360.0
                   - f * (1.0 / 1260.0 - f * (1.0 / 1680.0 - f * (1.0 / 1188.0 - f * 691.0 / 360360.0)))))
           / z;
}

/* a (log(1 + u) - u) for u = (x b - y a) / a, with log(1 + u) taken as
   log x + log1p(b / a) away from u = 0. */
static double fe__beta_prefix_term(double a, double b, double x, double u)
{
    if (fabs(u) > 0.25)
        return a * (log(x) + log1p(b / a) - u);
    return a * fe__log1p_minus(u);
}

/* log(x^a y^b / B(a, b)), y = 1 - x, in Stirling's form: nothing of the
   size of a log a is left to cancel. */
static double fe__beta_prefix_log(double a, double b, double x, double y)
{
    double n = a + b, dxy = x * b - y * a;
    return fe__beta_prefix_term(a, b, x, dxy / a) + fe__beta_prefix_term(b, a, y, -dxy / b)
           + 0.5 * log(a / n * b / (2.0 * 3.14159265358979323846))
           + fe__stirling_rest(n) - fe__stirling_rest(a) - fe__stirling_rest(b);
}

/* I_x(a, b) with y = 1 - x given too (each from its own formula), a,
   b > 0; NaN when the fraction does not converge. */
static double fe__beta_inc_xy(double a, double b, double x, double y)
{
    double lbt, lambda;
    if (x == 0.0 || y == 0.0)
        return x == 0.0 ? 0.0 : 1.0;
    lbt = fe__beta_prefix_log(a, b, x, y);
    lambda = a * y - b * x;
    if (lambda >= 0.0)
        return exp(lbt) * fe__beta_fraction(a, b, x, y, lambda);
    return 1.0 - exp(lbt) * fe__beta_fraction(b, a, y, x, -lambda);
}

double fe_beta_inc(double a, double b, double x)
{
    if (!(a > 0.0) || !(b > 0.0) || !(x >= 0.0) || !(x <= 1.0))
        return NAN;
    if (x == 0.0 || x == 1.0)
        return x;
    return fe__beta_inc_xy(a, b, x, 1.0 - x);
}
/* Compute the incomplete beta function ends here */
/* [[file:../literate/special.org::Evaluate the incomplete gamma function][Evaluate the incomplete gamma function]] */
double fe_log_gamma(double x)
{
    static const double c[9] = {0.99999999999980993, 676.5203681218851,
                                -1259.1392167224028, 771.32342877765313,
                                -176.61502916214059, 12.507343278686905,
                                -0.13857109526572012, 9.9843695780195716e-6,
                                1.5056327351493116e-7};
    double s, t;
    if (x < 0.5)
        return fe_log_gamma(x + 1.0) - log(x);
    x -= 1.0;
    s = c[0];
    for (int i = 1; i < 9; i++)
        s += c[i] / (x + (double)i);
    t = x + 7.5;
    return 0.9189385332046728 + (x + 0.5) * log(t) - t + log(s);
}
/* Evaluate the incomplete gamma function ends here */
/* [[file:../literate/special.org::Evaluate the digamma and trigamma functions][Evaluate the digamma and trigamma functions]] */
double fe_digamma(double x)
{
    double r = 0.0, f;
    if (!(x > 0.0) || !isfinite(x))
        return NAN;
    while (x < 10.0) {
        r -= 1.0 / x;
        x += 1.0;
    }
    f = 1.0 / (x * x);
    return r + log(x) - 0.5 / x
           - f * (1.0 / 12.0 - f * (1.0 / 120.0 - f * (1.0 / 252.0 - f * (1.0 / 240.0
                                                                          - f / 132.0))));
}

double fe_trigamma(double x)
{
    double r = 0.0, f;
    if (!(x > 0.0) || !isfinite(x))
        return NAN;
    while (x < 10.0) {
        r += 1.0 / (x * x);
        x += 1.0;
    }
    f = 1.0 / (x * x);
    return r + 1.0 / x + 0.5 * f
           + f / x * (1.0 / 6.0 - f * (1.0 / 30.0 - f * (1.0 / 42.0 - f * (1.0 / 30.0
                                                                          - f * 5.0 / 66.0))));
}

/* log(x^a e^-x / Gamma(a)), the factor in front of the series and the
   fraction.  For a >= 10, Stirling's series for log Gamma(a) with the
   large terms gathered into a (log1p(t) - t), t = (x - a) / a: nothing of
   the size of a log x is left to cancel. */
static double fe__gamma_prefix_log(double a, double x)
{
    double t;
    if (a < 10.0)
        return -x + a * log(x) - fe_log_gamma(a);
    t = (x - a) / a;
    return a * (log1p(t) - t) + 0.5 * log(a / (2.0 * 3.14159265358979323846))
           - fe__stirling_rest(a);
}

/* P(a, x) and Q(a, x), each of the pair computed directly where it is the
   smaller, the other as its complement.  Near x = a both the series and
   the fraction need about 10 sqrt(a) terms: the budget grows with a. */
static void fe__gamma_pq(double a, double x, double *p, double *q)
{
    double lpre = fe__gamma_prefix_log(a, x);
    int budget = FE__SPECIAL_ITERATIONS + (int)fmin(16.0 * sqrt(a), 1e8);
    if (x < a + 1.0) {                  /* series for P */
        double ap = a, sum = 1.0 / a, del = sum;
        for (int n = 0; n < budget; n++) {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if (fabs(del) < fabs(sum) * FE__SPECIAL_EPS)
                break;
        }
        *p = sum * exp(lpre);
        *q = 1.0 - *p;
    } else {                            /* continued fraction for Q */
        double b = x + 1.0 - a, c = 1.0 / FE__SPECIAL_TINY, d = 1.0 / b, h = d;
        for (int i = 1; i <= budget; i++) {
            double an = -i * (i - a), delta;
            b += 2.0;
            d = an * d + b;
            d = fabs(d) < FE__SPECIAL_TINY ? FE__SPECIAL_TINY : d;
            c = b + an / c;
            c = fabs(c) < FE__SPECIAL_TINY ? FE__SPECIAL_TINY : c;
            d = 1.0 / d;
            delta = d * c;
            h *= delta;
            if (fabs(delta - 1.0) < FE__SPECIAL_EPS)
                break;
        }
        *q = exp(lpre) * h;
        *p = 1.0 - *q;
    }
}

double fe_gamma_p(double a, double x)
{
    double p, q;
    if (!(a > 0.0) || !(x >= 0.0))
        return NAN;
    if (x == 0.0)
        return 0.0;
    fe__gamma_pq(a, x, &p, &q);
    return p;
}

double fe_gamma_q(double a, double x)
{
    double p, q;
    if (!(a > 0.0) || !(x >= 0.0))
        return NAN;
    if (x == 0.0)
        return 1.0;
    fe__gamma_pq(a, x, &p, &q);
    return q;
}
/* Evaluate the digamma and trigamma functions ends here */
/* [[file:../literate/special.org::Tails of t, F and chi-square][Tails of t, F and chi-square]] */
double fe_student_t_two_sided(double t, double nu)
{
    if (!(nu > 0.0) || isnan(t))
        return NAN;
    if (isinf(t))
        return 0.0;
    return fe__beta_inc_xy(0.5 * nu, 0.5, nu / (nu + t * t), 1.0 / (1.0 + nu / (t * t)));
}

double fe_student_t_quantile(double p, double nu)
{
    double lo = 0.0, hi = 1.0;
    if (!(p > 0.0) || !(p < 1.0) || !(nu > 0.0))
        return NAN;
    while (fe_student_t_two_sided(hi, nu) > p && hi < 1e300)
        hi *= 2.0;
    for (int i = 0; i < 200 && hi - lo > 1e-13 * (1.0 + hi); i++) {
        double mid = 0.5 * (lo + hi);
        if (fe_student_t_two_sided(mid, nu) > p)
            lo = mid;
        else
            hi = mid;
    }
    return 0.5 * (lo + hi);
}

double fe_f_upper(double f, double d1, double d2)
{
    if (!(d1 > 0.0) || !(d2 > 0.0) || isnan(f))
        return NAN;
    if (f <= 0.0)
        return 1.0;
    if (isinf(f))
        return 0.0;
    return fe__beta_inc_xy(0.5 * d2, 0.5 * d1, d2 / (d2 + d1 * f), 1.0 / (1.0 + d2 / (d1 * f)));
}

double fe_chi2_upper(double x, double k)
{
    if (!(k > 0.0) || isnan(x))
        return NAN;
    if (x <= 0.0)
        return 1.0;
    if (isinf(x))
        return 0.0;
    return fe_gamma_q(0.5 * k, 0.5 * x);
}
/* Tails of t, F and chi-square ends here */
/* [[file:../literate/special.org::Compute normal and chi-square quantiles][Compute normal and chi-square quantiles]] */
double fe_normal_quantile(double p)
{
    static const double a[6] = {-3.969683028665376e+01, 2.209460984245205e+02,
                                -2.759285104469687e+02, 1.383577518672690e+02,
                                -3.066479806614716e+01, 2.506628277459239e+00};
    static const double b[5] = {-5.447609879822406e+01, 1.615858368580409e+02,
                                -1.556989798598866e+02, 6.680131188771972e+01,
                                -1.328068155288572e+01};
    static const double c[6] = {-7.784894002430293e-03, -3.223964580411365e-01,
                                -2.400758277161838e+00, -2.549732539343734e+00,
                                4.374664141464968e+00, 2.938163982698783e+00};
    static const double d[4] = {7.784695709041462e-03, 3.224671290700398e-01,
                                2.445134137142996e+00, 3.754408661907416e+00};
    const double plow = 0.02425;
    double q, r;
    if (p < plow) {
        q = sqrt(-2.0 * log(p));
        return (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5])
             / ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
    }
    if (p > 1.0 - plow) {
        q = sqrt(-2.0 * log(1.0 - p));
        return -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5])
             / ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
    }
    q = p - 0.5;
    r = q * q;
    return (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q
         / (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
}

double fe_chi2_quantile(double q, double dof)
{
    double a, h, t, x, lo, hi = INFINITY, lognorm, logq;
    int lower;
    if (!(q > 0.0 && q < 1.0) || !(dof > 0.0) || !isfinite(dof))
        return NAN;
    a = 0.5 * dof;
    h = 2.0 / (9.0 * dof);
    t = 1.0 - h + fe_normal_quantile(q) * sqrt(h);
    x = t > 0.0 ? dof * t * t * t : 0.0;
    lognorm = a * log(2.0) + fe_log_gamma(a);
    logq = log(q);
    /* P(a, y) <= y^a / Gamma(a + 1): the quantile is at least this. */
    lo = 2.0 * exp((logq + fe_log_gamma(a + 1.0)) / a);
    if (!(lo > 0.0))
        return 0.0;                     /* below the smallest double */
    if (!(x > lo))
        x = lo;
    lower = q < 0.5;
    for (int it = 0; it < 400; it++) {
        double P = fe_gamma_p(a, 0.5 * x);
        double f = exp((a - 1.0) * log(x) - 0.5 * x - lognorm);
        double g = lower ? log(P) - logq : P - q, d = lower ? f / P : f, xn;
        if (P < q)
            lo = x;
        else
            hi = x;
        xn = d > 0.0 && isfinite(g) ? x - g / d : NAN;
        if (!(xn > lo && xn < hi))
            xn = !isfinite(hi) ? 2.0 * x : hi > 4.0 * lo ? sqrt(lo * hi) : 0.5 * (lo + hi);
        if (fabs(xn - x) <= 1e-15 * x)
            return xn;
        x = xn;
    }
    return x;
}
/* Compute normal and chi-square quantiles ends here */
