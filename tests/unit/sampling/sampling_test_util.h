// sampling_test_util.h — helpers shared by the sampling unit tests: an independent uniform
// source (so the RNG under test does not test itself), a (theta, phi) direction histogram
// with cell-integrated expectations, and the suite-wide Šidák-corrected significance.
#ifndef GDPT_TESTS_UNIT_SAMPLING_TEST_UTIL_H
#define GDPT_TESTS_UNIT_SAMPLING_TEST_UTIL_H

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "gdpt_shared.h"
#include "lib/sampling.glsl"
#include "stats.h"

namespace gdpt::test {

// Every chi-square test in gdpt_unit_sampling that is expected to pass; together they may
// fail spuriously with probability kFamilyAlpha (Šidák correction, as Mitsuba's chi2 test).
constexpr double kPiD = 3.14159265358979323846;
constexpr double kFamilyAlpha = 0.01;
constexpr int kNumChi2Tests = 18;  // 11 BSDF configs, 5 RNG, 2 warps
inline double chi2Alpha() {
    return stats::sidakAlpha(kFamilyAlpha, kNumChi2Tests);
}

// Uniform floats in [0,1) from mt19937 (top 24 bits, so 1.0 never occurs), fixed seed.
class Uniform {
public:
    explicit Uniform(std::uint32_t seed) : gen_(seed) {}
    float next() { return static_cast<float>(gen_() >> 8) * (1.0f / 16777216.0f); }
    gpu::vec2 next2() {
        float a = next();
        return gpu::vec2(a, next());
    }
    gpu::vec3 next3() {
        float a = next();
        float b = next();
        return gpu::vec3(a, b, next());
    }

private:
    std::mt19937 gen_;
};

// Histogram over directions, cells uniform in theta in [0, thetaMax] and phi in [0, 2 pi).
struct DirHistogram {
    int nTheta;
    int nPhi;
    double thetaMax;
    std::vector<double> counts;

    DirHistogram(int nt, int np, double tmax)
        : nTheta(nt), nPhi(np), thetaMax(tmax), counts(static_cast<size_t>(nt * np), 0.0) {}

    // Returns false for directions outside the histogram's theta range.
    bool add(gpu::vec3 w) {
        double theta = std::acos(std::clamp(static_cast<double>(w.z), -1.0, 1.0));
        double phi = std::atan2(static_cast<double>(w.y), static_cast<double>(w.x));
        if (phi < 0.0) {
            phi += 2.0 * kPiD;
        }
        int it = static_cast<int>(theta / thetaMax * nTheta);
        if (it < 0 || it > nTheta || (it == nTheta && theta > thetaMax)) {
            return false;
        }
        it = std::min(it, nTheta - 1);
        int ip = std::min(static_cast<int>(phi / (2.0 * kPiD) * nPhi), nPhi - 1);
        counts[static_cast<size_t>(it * nPhi + ip)] += 1.0;
        return true;
    }

    // Integral of pdfSolidAngle over cell (it, ip) by the composite Simpson rule with `sub`
    // (even) intervals per axis in (theta, phi), dOmega = sin(theta) dtheta dphi.
    template <class Pdf>
    double cellIntegral(Pdf& pdfSolidAngle, int it, int ip, int sub) const {
        double ht = thetaMax / nTheta / sub;
        double hp = 2.0 * kPiD / nPhi / sub;
        double sum = 0.0;
        for (int a = 0; a <= sub; ++a) {
            double wa = (a == 0 || a == sub) ? 1.0 : (a % 2 ? 4.0 : 2.0);
            double theta = (it * sub + a) * ht;
            double st = std::sin(theta);
            double ct = std::cos(theta);
            for (int b = 0; b <= sub; ++b) {
                double wb = (b == 0 || b == sub) ? 1.0 : (b % 2 ? 4.0 : 2.0);
                double phi = (ip * sub + b) * hp;
                gpu::vec3 w(static_cast<float>(st * std::cos(phi)), static_cast<float>(st * std::sin(phi)),
                            static_cast<float>(ct));
                sum += wa * wb * static_cast<double>(pdfSolidAngle(w)) * st;
            }
        }
        return sum * ht * hp / 9.0;
    }

    // Expected counts n * (integral of the pdf over each cell). Each cell's Simpson rule is
    // refined (sub = minSub, 2 minSub, ... 256) until two successive estimates differ by at
    // most 1e-4 relative or 0.01 counts, far below the Poisson error sqrt(expected). Sharp
    // GGX lobes squeezed against the horizon need the refinement; smooth cells stop at once.
    template <class Pdf>
    std::vector<double> expected(Pdf pdfSolidAngle, double n, int minSub = 8) const {
        std::vector<double> e(counts.size(), 0.0);
        for (int it = 0; it < nTheta; ++it) {
            for (int ip = 0; ip < nPhi; ++ip) {
                int sub = minSub;
                double prev = cellIntegral(pdfSolidAngle, it, ip, sub);
                double cur = prev;
                while (sub < 256) {
                    sub *= 2;
                    cur = cellIntegral(pdfSolidAngle, it, ip, sub);
                    if (std::fabs(cur - prev) * n <= std::max(1e-4 * cur * n, 0.01)) {
                        break;
                    }
                    prev = cur;
                }
                e[static_cast<size_t>(it * nPhi + ip)] = n * cur;
            }
        }
        return e;
    }
};

}  // namespace gdpt::test

#endif  // GDPT_TESTS_UNIT_SAMPLING_TEST_UTIL_H
