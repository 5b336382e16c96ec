// stats_normal.h — normal-distribution helpers for the image z-tests: the two-sided z
// threshold of a Šidák-corrected family of tests.
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

}  // namespace gdpt::test
