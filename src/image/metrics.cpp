// metrics.cpp — relMSE (Kettunen et al. 2015), MSE, MAE, max error, bias.
#include "image/metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "util/error.h"

namespace gdpt {
namespace {
// Kettunen et al.'s regulariser in the relMSE denominator (calculateRelMSE.m).
constexpr double kRelMseEpsilon = 1e-3;

void checkSameSize(const Image& test, const Image& reference) {
    if (!test.sameSize(reference))
        throw Error("cannot compare a " + std::to_string(test.width()) + "x" + std::to_string(test.height()) +
                    " image with a " + std::to_string(reference.width()) + "x" +
                    std::to_string(reference.height()) + " reference");
}

// Pixel i's values of both images; false if one is not finite.
bool finitePixel(const Image& test, const Image& reference, std::size_t i, double t[3], double r[3]) {
    bool finite = true;
    for (int c = 0; c < 3; ++c) {
        t[c] = test.plane(c)[i];
        r[c] = reference.plane(c)[i];
        finite = finite && std::isfinite(t[c]) && std::isfinite(r[c]);
    }
    return finite;
}

double grayOf(const double r[3]) {
    return (r[0] + r[1] + r[2]) / 3.0;
}

// A finite pixel's relMSE term, Σ_c (t_c − r_c)² / (ε + gray(r)²).
double relMseTerm(const double t[3], const double r[3]) {
    const double denominator = kRelMseEpsilon + grayOf(r) * grayOf(r);
    double sum = 0.0;
    for (int c = 0; c < 3; ++c) sum += (t[c] - r[c]) * (t[c] - r[c]) / denominator;
    return sum;
}

// relMSE's sum by quarters of the (gray, term) pairs of the finite pixels ordered by gray.
std::array<double, 4> relMseQuarters(std::vector<std::pair<double, double>> byGray) {
    std::stable_sort(byGray.begin(), byGray.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    std::array<double, 4> q{};
    for (std::size_t k = 0; k < byGray.size(); ++k) q[k * 4 / byGray.size()] += byGray[k].second;
    for (double& v : q) v /= double(std::max<std::size_t>(byGray.size(), 1));
    return q;
}
}  // namespace

Image relMseMap(const Image& test, const Image& reference) {
    checkSameSize(test, reference);
    Image out(test.width(), test.height());
    for (std::size_t i = 0; i < test.pixelCount(); ++i) {
        double t[3], r[3];
        const auto term = static_cast<float>(finitePixel(test, reference, i, t, r)
                                                 ? relMseTerm(t, r)
                                                 : std::numeric_limits<double>::quiet_NaN());
        for (int c = 0; c < 3; ++c) out.plane(c)[i] = term;
    }
    return out;
}

ImageErrorStats compareImages(const Image& test, const Image& reference) {
    checkSameSize(test, reference);
    ImageErrorStats s;
    double relSum = 0.0, sqSum = 0.0, absSum = 0.0, biasSum = 0.0;
    std::vector<std::pair<double, double>> byGray;  // (gray, relMSE term) of the finite pixels
    byGray.reserve(test.pixelCount());
    for (std::size_t i = 0; i < test.pixelCount(); ++i) {
        double t[3], r[3];
        if (!finitePixel(test, reference, i, t, r)) {
            ++s.nonFinitePixels;
            continue;
        }
        ++s.finitePixels;
        const double term = relMseTerm(t, r);
        relSum += term;
        byGray.emplace_back(grayOf(r), term);
        for (int c = 0; c < 3; ++c) {
            const double d = t[c] - r[c];
            sqSum += d * d;
            absSum += std::abs(d);
            biasSum += d;
            s.maxAbsError = std::max(s.maxAbsError, std::abs(d));
            s.meanTest[c] += t[c];
            s.meanReference[c] += r[c];
        }
    }
    if (s.finitePixels == 0) {
        const double nan = std::numeric_limits<double>::quiet_NaN();
        s.relMse = s.mse = s.mae = s.maxAbsError = s.meanBias = nan;
        s.meanTest = s.meanReference = {nan, nan, nan};
        return s;
    }
    const double pixels = static_cast<double>(s.finitePixels);
    const double pixelChannels = 3.0 * pixels;
    s.relMse = relSum / pixels;  // = 3 · (relSum / pixelChannels)
    s.mse = sqSum / pixelChannels;
    s.mae = absSum / pixelChannels;
    s.meanBias = biasSum / pixelChannels;
    for (int c = 0; c < 3; ++c) {
        s.meanTest[c] /= pixels;
        s.meanReference[c] /= pixels;
    }
    s.relMseByQuarter = relMseQuarters(std::move(byGray));
    return s;
}

double temporalRelMse(const Image& test0, const Image& test1, const Image& reference0,
                      const Image& reference1, const Image* motion) {
    for (const Image* im : {&test1, &reference0, &reference1, motion})
        if (im && !im->sameSize(test0)) throw Error("cannot compare frames of different sizes");
    const int width = test0.width(), height = test0.height();
    double sum = 0.0;
    std::size_t pixels = 0;
    for (std::size_t i = 0; i < test0.pixelCount(); ++i) {
        // The pixel of frame 0 that pixel i of frame 1 is compared with.
        std::size_t s = i;
        if (motion) {
            if (motion->plane(2)[i] != 1.0f) continue;
            const float dx = motion->plane(0)[i], dy = motion->plane(1)[i];
            const long sx = long(i % std::size_t(width)) + long(std::lround(dx));
            const long sy = long(i / std::size_t(width)) + long(std::lround(dy));
            if (!std::isfinite(dx) || !std::isfinite(dy) || sx < 0 || sy < 0 || sx >= width || sy >= height)
                continue;
            s = std::size_t(sy) * std::size_t(width) + std::size_t(sx);
        }
        double d[3], gray = 0.0;
        bool finite = true;
        for (int c = 0; c < 3; ++c) {
            const double t0 = test0.plane(c)[s], t1 = test1.plane(c)[i];
            const double r0 = reference0.plane(c)[s], r1 = reference1.plane(c)[i];
            finite =
                finite && std::isfinite(t0) && std::isfinite(t1) && std::isfinite(r0) && std::isfinite(r1);
            d[c] = (t1 - t0) - (r1 - r0);
            gray += 0.5 * (r0 + r1) / 3.0;
        }
        if (!finite) continue;
        ++pixels;
        sum += (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) / (kRelMseEpsilon + gray * gray);
    }
    return pixels ? sum / double(pixels) : std::numeric_limits<double>::quiet_NaN();
}

double relMse(const Image& test, const Image& reference) {
    return compareImages(test, reference).relMse;
}
double mse(const Image& test, const Image& reference) {
    return compareImages(test, reference).mse;
}
double mae(const Image& test, const Image& reference) {
    return compareImages(test, reference).mae;
}

}  // namespace gdpt
