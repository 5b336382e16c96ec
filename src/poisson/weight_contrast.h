// weight_contrast.h — bounds the contrast of a reconstruction's row weights (WL1's inverse
// variances, 2D and space-time): every positive weight is clamped into [m/K, m·K], m the
// median of the positive weights of all the given families together (the upper middle one of
// an even count) and K the contrast (1 makes every positive weight the median; 0 or any K
// below 1 changes nothing); zeros stay zero.
// Why: the inverse variances of a firefly-heavy render span orders of magnitude, and the
// conjugate gradients then need many times the iterations of unweighted rows, while the
// extremes add nothing to the accuracy (bench/RESULTS.md, "Weighted L1 with bounded weights").
#pragma once

#include <algorithm>
#include <cstddef>
#include <initializer_list>
#include <vector>

namespace gdpt {

// SolveOptions::varianceWeightContrast's default, and the help of the options that set it.
inline constexpr double kDefaultVarianceWeightContrast = 4.0;
inline constexpr const char* kVarianceWeightContrastHelp =
    "wl1: the largest factor by which a row's inverse-variance weight may differ from the median row's "
    "(0 = unbounded); bounded weights keep wl1's lower error and its solve near l1's time";

template <class T>
void boundWeightContrast(std::initializer_list<std::vector<T>*> families, double contrast) {
    if (!(contrast >= 1.0)) return;
    std::vector<T> positive;
    for (const std::vector<T>* f : families)
        for (T w : *f)
            if (w > T(0)) positive.push_back(w);
    if (positive.empty()) return;
    const auto middle = positive.begin() + static_cast<std::ptrdiff_t>(positive.size() / 2);
    std::nth_element(positive.begin(), middle, positive.end());
    const double median = double(*middle);
    const auto lo = static_cast<T>(median / contrast), hi = static_cast<T>(median * contrast);
    for (std::vector<T>* f : families)
        for (T& w : *f)
            if (w > T(0)) w = std::clamp(w, lo, hi);
}

template <class T>
void boundWeightContrast(std::vector<T>& weights, double contrast) {
    boundWeightContrast({&weights}, contrast);
}

}  // namespace gdpt
