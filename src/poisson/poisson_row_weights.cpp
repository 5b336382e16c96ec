// poisson_row_weights.cpp — the variance-weighted reconstructions' row weights (poisson_gpu.h):
// a row's inverse RGB-mean variance (WL2), and the box-filtered variances WL1 weights by.
#include <algorithm>
#include <cmath>

#include "poisson/poisson_gpu.h"

namespace gdpt {
namespace {

bool finite3(const Image& im, std::size_t i) {
    return std::isfinite(im.plane(0)[i]) && std::isfinite(im.plane(1)[i]) && std::isfinite(im.plane(2)[i]);
}

}  // namespace

double inverseVariance(const Image& var, std::size_t i, double eps, NonFiniteCounts& counts) {
    if (!finite3(var, i)) {
        ++counts.variance;
        return 0.0;
    }
    if (var.plane(0)[i] < 0.0f || var.plane(1)[i] < 0.0f || var.plane(2)[i] < 0.0f) {
        ++counts.negativeVariance;
        return 0.0;
    }
    const double v = (double(var.plane(0)[i]) + var.plane(1)[i] + var.plane(2)[i]) / 3.0;
    return 1.0 / (v + eps);
}

double inverseFilteredVariance(float filtered, double eps) {
    return filtered < 0.0f ? 0.0 : 1.0 / (double(filtered) + eps);
}

std::vector<float> boxFilteredVariance(const Image& var, int radius, std::size_t& nonFinite,
                                       std::size_t& negative) {
    const int w = var.width(), h = var.height();
    const std::size_t n = var.pixelCount();
    // Per-pixel RGB mean and validity, then running sums along x and along y.
    std::vector<double> value(n, 0.0), count(n, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
        const double v = (double(var.plane(0)[i]) + var.plane(1)[i] + var.plane(2)[i]) / 3.0;
        if (!finite3(var, i)) {
            ++nonFinite;
        } else if (var.plane(0)[i] < 0.0f || var.plane(1)[i] < 0.0f || var.plane(2)[i] < 0.0f) {
            ++negative;
        } else {
            value[i] = v;
            count[i] = 1.0;
        }
    }
    const auto pass = [&](std::vector<double>& a, std::vector<double>& c, bool alongX) {
        std::vector<double> sa(n, 0.0), sc(n, 0.0);
        const int len = alongX ? w : h, lines = alongX ? h : w;
        for (int line = 0; line < lines; ++line) {
            const auto at = [&](int k) {
                return alongX ? static_cast<std::size_t>(line) * static_cast<std::size_t>(w) +
                                    static_cast<std::size_t>(k)
                              : static_cast<std::size_t>(k) * static_cast<std::size_t>(w) +
                                    static_cast<std::size_t>(line);
            };
            double runA = 0.0, runC = 0.0;
            for (int k = 0; k < std::min(radius, len); ++k) {
                runA += a[at(k)];
                runC += c[at(k)];
            }
            for (int k = 0; k < len; ++k) {
                if (k + radius < len) {
                    runA += a[at(k + radius)];
                    runC += c[at(k + radius)];
                }
                if (k - radius - 1 >= 0) {
                    runA -= a[at(k - radius - 1)];
                    runC -= c[at(k - radius - 1)];
                }
                sa[at(k)] = runA;
                sc[at(k)] = runC;
            }
        }
        a.swap(sa);
        c.swap(sc);
    };
    pass(value, count, true);
    pass(value, count, false);
    // A running sum that has taken a large value (a firefly's variance) in and out again keeps
    // its rounding residue, which can be negative where every value left in the box is 0; a
    // negative average would read as "no variance" (weight 0), so it is clamped.
    std::vector<float> out(n);
    for (std::size_t i = 0; i < n; ++i)
        out[i] = count[i] > 0.5 ? static_cast<float>(std::max(0.0, value[i]) / count[i]) : -1.0f;
    return out;
}

}  // namespace gdpt
