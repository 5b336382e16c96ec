// poisson_test_util.h — test images and an explicit (dense) row operator P for the Poisson
// tests. The dense P is built straight from the energy's definition (poisson_problem.h), so
// it checks applyA/computeRhs independently of their stencil code.
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include "poisson/poisson_problem.h"

namespace gdpt::test {

inline std::vector<double> randomField(int w, int h, unsigned seed, double lo = 0.0, double hi = 1.0) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(lo, hi);
    std::vector<double> v(static_cast<std::size_t>(w) * h);
    for (double& x : v) x = u(rng);
    return v;
}

// A structured image: smooth gradient + a sharp-edged box + a thin line.
inline std::vector<double> structuredField(int w, int h) {
    std::vector<double> v(static_cast<std::size_t>(w) * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double value = 0.5 + 0.3 * std::sin(0.7 * x) * std::cos(0.4 * y);
            if (x >= w / 4 && x < w / 2 && y >= h / 3 && y < (2 * h) / 3) value += 2.0;
            if (x == w / 2) value += 0.7;
            v[static_cast<std::size_t>(y) * w + x] = value;
        }
    return v;
}

// Problem whose gradients and primal are those of `image` exactly.
inline PoissonProblem exactProblem(const std::vector<double>& image, int w, int h, double alpha) {
    PoissonProblem p;
    p.width = w;
    p.height = h;
    p.alpha = alpha;
    p.primal = image;
    p.dx.assign(image.size(), 0.0);
    p.dy.assign(image.size(), 0.0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = static_cast<std::size_t>(y) * w + x;
            if (x + 1 < w) p.dx[i] = image[i + 1] - image[i];
            if (y + 1 < h) p.dy[i] = image[i + w] - image[i];
        }
    return p;
}

// Dense rows of the least-squares system: each row has coefficients over the n pixels, a
// target and an energy weight, energy = Σ weight (coeffs·x − target)².
struct DenseRows {
    std::vector<std::vector<double>> coeffs;
    std::vector<double> target, weight;
};

inline DenseRows denseRows(const PoissonProblem& p) {
    DenseRows rows;
    const int n = p.width * p.height;
    auto weightOf = [](const std::vector<double>& w, int i) { return w.empty() ? 1.0 : w[i]; };
    for (int i = 0; i < n; ++i) {
        const int x = i % p.width, y = i / p.width;
        std::vector<double> c(n, 0.0);
        c[i] = 1.0;  // primal row (I_i − t_i), energy weight α² wp
        rows.coeffs.push_back(c);
        rows.target.push_back(p.primal[i]);
        rows.weight.push_back(p.alpha * p.alpha * weightOf(p.weightPrimal, i));
        if (x + 1 < p.width) {
            std::vector<double> d(n, 0.0);
            d[i] = -1.0;
            d[i + 1] = 1.0;
            rows.coeffs.push_back(d);
            rows.target.push_back(p.dx[i]);
            rows.weight.push_back(weightOf(p.weightDx, i));
        }
        if (y + 1 < p.height) {
            std::vector<double> d(n, 0.0);
            d[i] = -1.0;
            d[i + p.width] = 1.0;
            rows.coeffs.push_back(d);
            rows.target.push_back(p.dy[i]);
            rows.weight.push_back(weightOf(p.weightDy, i));
        }
    }
    return rows;
}

inline double relativeError(const std::vector<double>& a, const std::vector<double>& b) {
    double num = 0.0, den = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        num += (a[i] - b[i]) * (a[i] - b[i]);
        den += b[i] * b[i];
    }
    return den > 0.0 ? std::sqrt(num / den) : std::sqrt(num);
}

}  // namespace gdpt::test
