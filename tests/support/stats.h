// stats.h — statistical helpers for tests: chi-square distribution, Pearson goodness of fit
// with pooling of low-expectation cells, Šidák correction, and running mean/variance.
//
// The goodness-of-fit procedure follows Mitsuba's chi2 test (mitsuba/python/chi2.py) and
// pbrt-v3's bsdfs_test.cpp: cells whose expected count is below a threshold are pooled into
// one cell, any observation in a cell of zero expectation fails outright, and the p-value of
// Pearson's statistic is compared with a Šidák-corrected significance level.
// Header-only, no dependencies beyond the standard library.
#ifndef GDPT_TESTS_SUPPORT_STATS_H
#define GDPT_TESTS_SUPPORT_STATS_H

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numeric>
#include <string>
#include <vector>

namespace gdpt::stats {

// Regularised lower incomplete gamma P(a, x) by its power series (Abramowitz & Stegun
// 6.5.29); converges quickly for x < a + 1.
inline double gammaPSeries(double a, double x) {
    double term = 1.0 / a;
    double sum = term;
    for (int n = 1; n < 100000; ++n) {
        term *= x / (a + n);
        sum += term;
        if (std::fabs(term) < std::fabs(sum) * 1e-15) {
            break;
        }
    }
    return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

// Regularised upper incomplete gamma Q(a, x) by its continued fraction (A&S 6.5.31),
// evaluated with the modified Lentz method; converges quickly for x >= a + 1.
inline double gammaQContinuedFraction(double a, double x) {
    const double tiny = 1e-300;
    double b = x + 1.0 - a;
    double c = 1.0 / tiny;
    double d = 1.0 / b;
    double h = d;
    for (int i = 1; i < 100000; ++i) {
        double an = -i * (i - a);
        b += 2.0;
        d = an * d + b;
        d = std::fabs(d) < tiny ? tiny : d;
        c = b + an / c;
        c = std::fabs(c) < tiny ? tiny : c;
        d = 1.0 / d;
        double delta = d * c;
        h *= delta;
        if (std::fabs(delta - 1.0) < 1e-15) {
            break;
        }
    }
    return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}

// Q(a, x) = 1 - P(a, x).
inline double gammaQ(double a, double x) {
    if (x <= 0.0) {
        return 1.0;
    }
    return x < a + 1.0 ? 1.0 - gammaPSeries(a, x) : gammaQContinuedFraction(a, x);
}

// Survival function of the chi-square distribution with `dof` degrees of freedom:
// P(X >= chi2) = Q(dof/2, chi2/2).
inline double chi2Survival(double chi2, int dof) {
    return gammaQ(0.5 * dof, 0.5 * chi2);
}

// Per-test significance so that `numTests` independent tests together have family-wise
// false-failure rate `alpha` (Šidák 1967): 1 - (1 - alpha)^(1/numTests).
inline double sidakAlpha(double alpha, int numTests) {
    return 1.0 - std::pow(1.0 - alpha, 1.0 / numTests);
}

struct Chi2Result {
    double statistic = 0.0;
    int dof = 0;
    double pValue = 1.0;
    int pooledCells = 0;
    std::string error;  // non-empty when the test failed for a structural reason
};

// Pearson chi-square test of observed counts against expected counts (same total up to
// integration error). Cells with expected < minExpected are pooled, smallest first, into one
// cell; if the pool is still below minExpected it is merged into the smallest remaining cell.
inline Chi2Result chi2Test(const std::vector<double>& observed, const std::vector<double>& expected,
                           double minExpected = 5.0) {
    Chi2Result res;
    std::vector<std::size_t> order(observed.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::sort(order.begin(), order.end(),
              [&](std::size_t a, std::size_t b) { return expected[a] < expected[b]; });
    double poolObs = 0.0;
    double poolExp = 0.0;
    std::vector<double> cellObs;
    std::vector<double> cellExp;
    for (std::size_t i : order) {
        if (expected[i] <= 0.0 && observed[i] > 0.0) {
            res.error = "observed " + std::to_string(observed[i]) + " samples in cell " + std::to_string(i) +
                        " whose expected count is " + std::to_string(expected[i]);
            res.pValue = 0.0;
            return res;
        }
        if (expected[i] < minExpected) {
            poolObs += observed[i];
            poolExp += expected[i];
            ++res.pooledCells;
        } else {
            cellObs.push_back(observed[i]);
            cellExp.push_back(expected[i]);
        }
    }
    if (poolExp > 0.0 || poolObs > 0.0) {
        if (poolExp < minExpected && !cellExp.empty()) {
            // cellExp is ascending (sorted order), so index 0 is the smallest remaining cell.
            cellObs[0] += poolObs;
            cellExp[0] += poolExp;
        } else {
            cellObs.push_back(poolObs);
            cellExp.push_back(poolExp);
        }
    }
    if (cellExp.size() < 2) {
        res.error = "fewer than two cells with enough expected samples";
        res.pValue = 0.0;
        return res;
    }
    for (std::size_t i = 0; i < cellExp.size(); ++i) {
        double d = cellObs[i] - cellExp[i];
        res.statistic += d * d / cellExp[i];
    }
    res.dof = static_cast<int>(cellExp.size()) - 1;
    res.pValue = chi2Survival(res.statistic, res.dof);
    return res;
}

// Welford running mean and variance (double precision).
struct RunningStats {
    double count = 0.0;
    double mean = 0.0;
    double m2 = 0.0;
    void add(double x) {
        count += 1.0;
        double d = x - mean;
        mean += d / count;
        m2 += d * (x - mean);
    }
    double variance() const { return count > 1.0 ? m2 / (count - 1.0) : 0.0; }
    double standardError() const { return count > 0.0 ? std::sqrt(variance() / count) : 0.0; }
};

}  // namespace gdpt::stats

#endif  // GDPT_TESTS_SUPPORT_STATS_H
