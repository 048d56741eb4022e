/* SPDX-License-Identifier: MIT */
/* foldest from C++17: built by `make check-install` with g++ -std=c++17
   -Wall -Wextra -Werror -pedantic against an installed copy (pkg-config),
   and run.  It includes the umbrella header, so every public header must
   compile as C++ and give its functions C linkage (extern "C"), or the link
   fails.  Exits nonzero when a result is wrong. */
#include <foldest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

namespace {

int failures = 0;

void expect(bool ok, const char *what)
{
    if (!ok) {
        std::fprintf(stderr, "use_from_cxx: FAILED: %s\n", what);
        ++failures;
    }
}

/* The mean and variance of 55, 89, 144 by the generic fold. */
void meanvar()
{
    const double z[3] = {55, 89, 144};
    fe_accumulator mv = fe_meanvar_accumulator();
    fe_meanvar a = FE_MEANVAR_EMPTY;
    size_t done = 0;
    int rc = fe_fold(&mv, &a, z, 3, &done);
    expect(rc == FE_OK && done == 3, "fe_fold of the mean and variance");
    expect(fe_meanvar_mean(&a) == 96.0, "mean 96");
    expect(std::fabs(fe_meanvar_variance(&a) - 2017.0) < 1e-9, "variance 2017");
}

/* One Kalman step of a scalar state: prior 0 with variance 4, measurement 1
   with variance 4: the estimate is 0.5 with variance 2. */
void kalman()
{
    std::vector<double> mem(fe_kalman_doubles(1, 1));
    fe_kalman k;
    expect(fe_kalman_init(&k, 1, 1, mem.data(), mem.size()) == FE_OK, "fe_kalman_init");
    expect(fe_kalman_set_prior_scaled(&k, nullptr, 4.0) == FE_OK, "fe_kalman_set_prior_scaled");
    const double A = 1.0, z = 1.0, Z = 4.0;
    fe_kalman_obs o = {1, &A, &z, &Z};
    expect(fe_kalman_update(&k, &o, nullptr) == FE_OK, "fe_kalman_update");
    expect(std::fabs(k.x[0] - 0.5) < 1e-15, "Kalman estimate 0.5");
    expect(std::fabs(k.P[0] - 2.0) < 1e-15, "Kalman variance 2");
}

/* A sphere of radius 2 about (1, -2, 3), sampled on a spiral: the fit
   finds the centre. */
void sphere()
{
    fe_quadric q = FE_QUADRIC_EMPTY;
    expect(fe_quadric_init(&q, nullptr) == FE_OK, "fe_quadric_init");
    const int n = 400;
    const double pi = std::acos(-1.0);
    for (int i = 0; i < n; ++i) {
        double t = (i + 0.5) / n, zc = 1.0 - 2.0 * t, r = std::sqrt(1.0 - zc * zc);
        double phi = i * pi * (3.0 - std::sqrt(5.0));
        const double x[3] = {1.0 + 2.0 * r * std::cos(phi), -2.0 + 2.0 * r * std::sin(phi),
                             3.0 + 2.0 * zc};
        expect(fe_quadric_add(&q, x) == FE_OK, "fe_quadric_add");
    }
    fe_sphere_options opt = fe_sphere_default_options();
    fe_sphere_fit fit;
    int rc = fe_sphere_fit_moments(&q, FE_FIT_SPHERE, &opt, &fit);
    expect(rc == FE_OK, "fe_sphere_fit_moments");
    expect(std::fabs(fit.offset[0] - 1.0) < 1e-9 && std::fabs(fit.offset[1] + 2.0) < 1e-9
               && std::fabs(fit.offset[2] - 3.0) < 1e-9,
           "sphere centre (1, -2, 3)");
    expect(std::fabs(fit.radius - 2.0) < 1e-9, "sphere radius 2");
}

void strerror_()
{
    const char *ok = fe_strerror(FE_OK), *bad = fe_strerror(FE_ENONFINITE);
    expect(ok != nullptr && bad != nullptr && std::strcmp(ok, bad) != 0, "fe_strerror");
}

} // namespace

int main()
{
    meanvar();
    kalman();
    sphere();
    strerror_();
    if (failures == 0)
        std::printf("use_from_cxx: foldest %s from C++17: mean and variance, Kalman step, "
                    "sphere fit, fe_strerror: ok\n", FE_VERSION);
    return failures == 0 ? 0 : 1;
}
