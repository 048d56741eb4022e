/* SPDX-License-Identifier: MIT */
/* Tangled from literate/special.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/special.org::Tail Probability Declarations][Tail Probability Declarations]] */
#ifndef FOLDEST_SPECIAL_H
#define FOLDEST_SPECIAL_H

#ifdef __cplusplus
extern "C" {
#endif

/* fe_beta_inc: the regularised incomplete beta function I_x(a, b) for
   a, b > 0 and 0 <= x <= 1; NaN for other arguments, and NaN when its
   continued fraction does not converge within 500 + 16 sqrt(max(a, b))
   + 200 / min(a, b) steps, at most 1e8 (none found for a, b from 1e-3 to
   1e12).
   The tails of t and F below inherit this. */
double fe_beta_inc(double a, double b, double x);

/* fe_log_gamma: log Gamma(x) for x > 0 (Lanczos; thread-safe, unlike
   lgamma). */
double fe_log_gamma(double x);

/* fe_digamma, fe_trigamma: psi(x) = d ln Gamma(x) / dx and its derivative
   psi'(x) for x > 0, to about 1e-13 relative (near psi's zero at 1.4616,
   to about 1e-15 absolute); NaN for other arguments.
   They are the mean and variance of the log of a chi-square: for k degrees
   of freedom, E ln(chi2_k / k) = psi(k/2) - ln(k/2) and Var ln chi2_k =
   psi'(k/2). */
double fe_digamma(double x);
double fe_trigamma(double x);

/* fe_gamma_p, fe_gamma_q: the regularised lower and upper incomplete gamma
   functions P(a, x) and Q(a, x) = 1 - P(a, x) for a > 0, x >= 0; NaN for
   other arguments. */
double fe_gamma_p(double a, double x);
double fe_gamma_q(double a, double x);

/* fe_student_t_two_sided: P(|T| > |t|) for Student's t with nu > 0
   degrees of freedom. */
double fe_student_t_two_sided(double t, double nu);

/* fe_student_t_quantile: the t with P(|T| > t) = p, 0 < p < 1, by
   bisection on the tail (about 1e-12 absolute). */
double fe_student_t_quantile(double p, double nu);

/* fe_f_upper: P(F > f) for Fisher's F with (d1, d2) degrees of freedom. */
double fe_f_upper(double f, double d1, double d2);

/* fe_chi2_upper: P(X > x) for chi-square with k degrees of freedom. */
double fe_chi2_upper(double x, double k);

/* fe_normal_quantile: the p-quantile of the standard normal, 0 < p < 1
   (Acklam's rational approximation, relative error below 1.2e-9). */
double fe_normal_quantile(double p);

/* fe_chi2_quantile: the q-quantile of chi-square with dof > 0 degrees of
   freedom, 0 < q < 1, to about 1e-13 relative: a Wilson-Hilferty start
   refined by Newton's method on P(dof/2, x/2) inside a kept bracket.
   NaN for other arguments. */
double fe_chi2_quantile(double q, double dof);

#ifdef __cplusplus
}
#endif

#endif /* FOLDEST_SPECIAL_H */
/* Tail Probability Declarations ends here */
