// stats_normal.h — normal and Student t helpers for the image z- and t-tests: the two-sided
// thresholds of a Šidák-corrected family of tests.
#pragma once

#include <cmath>

namespace gdpt::test {

// Two-sided standard-normal quantile: z such that P(|Z| > z) = alpha (bisection on erfc).
inline double twoSidedZ(double alpha) {
    double lo = 0.0, hi = 40.0;
    for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        if (std::erfc(mid / std::sqrt(2.0)) > alpha)
            lo = mid;
        else
            hi = mid;
    }
    return 0.5 * (lo + hi);
}

// Per-test significance such that a family of m independent tests has overall level alpha
// (Šidák 1967): 1 - (1 - alpha)^(1/m).
inline double sidakAlpha(double alpha, int m) {
    return 1.0 - std::pow(1.0 - alpha, 1.0 / m);
}

// Two-sided Student t quantile with `dof` degrees of freedom at level alpha: bisection on
// the tail probability, integrated from the density by Simpson's rule.
inline double twoSidedT(double alpha, int dof) {
    const double nu = dof;
    const double c = std::exp(std::lgamma((nu + 1) / 2) - std::lgamma(nu / 2)) / std::sqrt(nu * M_PI);
    const auto pdf = [&](double t) { return c * std::pow(1.0 + t * t / nu, -(nu + 1) / 2); };
    const auto centralMass = [&](double t) {  // P(|T| < t)
        const int n = 4000;
        const double h = t / n;
        double s = pdf(0) + pdf(t);
        for (int i = 1; i < n; ++i) s += (i % 2 ? 4.0 : 2.0) * pdf(i * h);
        return 2.0 * s * h / 3.0;
    };
    double lo = 0.0, hi = 200.0;
    for (int i = 0; i < 100; ++i) {
        const double mid = 0.5 * (lo + hi);
        (1.0 - centralMass(mid) > alpha ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

}  // namespace gdpt::test
