/* Tangled from literate/special.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/special.org::Tail Probability Declarations][Tail Probability Declarations]] */
#ifndef FOLDEST_SPECIAL_H
#define FOLDEST_SPECIAL_H

/* fe_beta_inc: the regularised incomplete beta function I_x(a, b) for
   a, b > 0 and 0 <= x <= 1; NaN for other arguments. */
double fe_beta_inc(double a, double b, double x);

/* fe_gamma_q: the regularised upper incomplete gamma function Q(a, x)
   for a > 0, x >= 0; NaN for other arguments. */
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

#endif /* FOLDEST_SPECIAL_H */
/* Tail Probability Declarations ends here */
