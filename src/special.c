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
static double fe__beta_fraction(double a, double b, double x)
{
    double qab = a + b, qap = a + 1.0, qam = a - 1.0;
    double c = 1.0, d = 1.0 - qab * x / qap, h;
    if (fabs(d) < FE__SPECIAL_TINY)
        d = FE__SPECIAL_TINY;
    d = 1.0 / d;
    h = d;
    for (int m = 1; m <= FE__SPECIAL_ITERATIONS; m++) {
        double m2 = 2.0 * m, aa, delta;
        aa = m * (b - m) * x / ((qam + m2) * (a + m2));
        d = 1.0 + aa * d;
        d = fabs(d) < FE__SPECIAL_TINY ? FE__SPECIAL_TINY : d;
        c = 1.0 + aa / c;
        c = fabs(c) < FE__SPECIAL_TINY ? FE__SPECIAL_TINY : c;
        d = 1.0 / d;
        h *= d * c;
        aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
        d = 1.0 + aa * d;
        d = fabs(d) < FE__SPECIAL_TINY ? FE__SPECIAL_TINY : d;
        c = 1.0 + aa / c;
        c = fabs(c) < FE__SPECIAL_TINY ? FE__SPECIAL_TINY : c;
        d = 1.0 / d;
        delta = d * c;
        h *= delta;
        if (fabs(delta - 1.0) < FE__SPECIAL_EPS)
            break;
    }
    return h;
}

double fe_beta_inc(double a, double b, double x)
{
    double lbt;
    if (!(a > 0.0) || !(b > 0.0) || !(x >= 0.0) || !(x <= 1.0))
        return NAN;
    if (x == 0.0 || x == 1.0)
        return x;
    lbt = lgamma(a + b) - lgamma(a) - lgamma(b) + a * log(x) + b * log1p(-x);
    if (x < (a + 1.0) / (a + b + 2.0))
        return exp(lbt) * fe__beta_fraction(a, b, x) / a;
    return 1.0 - exp(lbt) * fe__beta_fraction(b, a, 1.0 - x) / b;
}
/* Evaluate the incomplete beta continued fraction ends here */
/* [[file:../literate/special.org::Evaluate the incomplete gamma function][Evaluate the incomplete gamma function]] */
double fe_gamma_q(double a, double x)
{
    double lpre;
    if (!(a > 0.0) || !(x >= 0.0))
        return NAN;
    if (x == 0.0)
        return 1.0;
    lpre = -x + a * log(x) - lgamma(a);
    if (x < a + 1.0) {                  /* series for P, then Q = 1 - P */
        double ap = a, sum = 1.0 / a, del = sum;
        for (int n = 0; n < FE__SPECIAL_ITERATIONS; n++) {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if (fabs(del) < fabs(sum) * FE__SPECIAL_EPS)
                break;
        }
        return 1.0 - sum * exp(lpre);
    } else {                            /* continued fraction for Q */
        double b = x + 1.0 - a, c = 1.0 / FE__SPECIAL_TINY, d = 1.0 / b, h = d;
        for (int i = 1; i <= FE__SPECIAL_ITERATIONS; i++) {
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
        return exp(lpre) * h;
    }
}
/* Evaluate the incomplete gamma function ends here */
/* [[file:../literate/special.org::Tails of t, F and chi-square][Tails of t, F and chi-square]] */
double fe_student_t_two_sided(double t, double nu)
{
    if (!(nu > 0.0) || isnan(t))
        return NAN;
    if (isinf(t))
        return 0.0;
    return fe_beta_inc(0.5 * nu, 0.5, nu / (nu + t * t));
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
    return fe_beta_inc(0.5 * d2, 0.5 * d1, d2 / (d2 + d1 * f));
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
