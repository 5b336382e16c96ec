// metrics.h — image error metrics against a reference.
//
// relMSE is computed exactly as Kettunen et al. 2015 computed it (the errata on their project
// page: Sec. 6 of the paper describes it differently; this is the computation behind its
// numbers, their calculateRelMSE.m):
//     relMSE = 3 · mean over pixels p and channels c of (I_pc − R_pc)² / (1e-3 + gray(R_p)²)
//            = mean over pixels of Σ_c (I_pc − R_pc)² / (1e-3 + gray(R_p)²),
// with gray(R_p) = (R_pr + R_pg + R_pb) / 3 taken from the reference pixel.
//
// Non-finite values: a pixel whose test or reference value is NaN or ±inf in any channel
// is excluded from every metric and counted in nonFinitePixels; all metrics are then
// computed over the remaining ("finite") pixels. A NaN therefore never propagates into the
// numbers silently: check nonFinitePixels. If no pixel is finite, every metric is NaN.
#pragma once

#include <array>
#include <cstddef>

#include "image/image.h"

namespace gdpt {

struct ImageErrorStats {
    double relMse = 0.0;                    // Kettunen et al. 2015 relMSE (see above)
    double mse = 0.0;                       // mean over pixel-channels of (I − R)²
    double mae = 0.0;                       // mean over pixel-channels of |I − R|
    double maxAbsError = 0.0;               // max over pixel-channels of |I − R|
    double meanBias = 0.0;                  // mean over pixel-channels of (I − R)
    std::array<double, 3> meanTest{};       // per-channel mean of I (finite pixels)
    std::array<double, 3> meanReference{};  // per-channel mean of R (finite pixels)
    std::size_t finitePixels = 0;           // pixels used
    std::size_t nonFinitePixels = 0;        // pixels excluded (NaN/inf in I or R)
    // relMSE's sum split by the reference's brightness: the finite pixels ordered by gray(R)
    // (ties by index) and cut into quarters, darkest first; each the quarter's share of
    // relMse (their sum), so where the error lies shows at a glance.
    std::array<double, 4> relMseByQuarter{};
};

// All metrics of `test` against `reference`. Throws gdpt::Error if the sizes differ.
ImageErrorStats compareImages(const Image& test, const Image& reference);

// Each pixel's term of relMSE, Σ_c (I_pc − R_pc)² / (1e-3 + gray(R_p)²), in all three
// channels (their mean over the finite pixels is relMse); NaN where compareImages leaves the
// pixel out. Throws gdpt::Error if the sizes differ.
Image relMseMap(const Image& test, const Image& reference);

// The temporal error of a sequence between two consecutive frames: the relMSE of the test's
// frame-to-frame change against the reference's change,
//     mean over pixels of Σ_c ((T1 − T0)_pc − (R1 − R0)_pc)² / (1e-3 + gray((R0 + R1)/2)_p²),
// the relMSE above applied to the differences (normalised by the reference's mean value at
// the pixel, as relMSE is). Flicker (independent noise per frame) shows here even where each
// frame alone is close to its reference. Pixels with a non-finite value in any of the four
// images are left out. Throws gdpt::Error if the sizes differ.
//
// With `motion` (temporal G-PT's `motion` layer of frame 1: per pixel q the offset (R, G) to the
// pixel s(q) of frame 0 its content came from, and B = 1 where it has one): the same along the
// motion, T1(q) − T0(s(q)) against R1(q) − R0(s(q)), over the pixels with a source. Under a
// moving camera this is the flicker of what stays on a surface; the same-pixel form also
// counts an error pattern that moves with the content.
double temporalRelMse(const Image& test0, const Image& test1, const Image& reference0,
                      const Image& reference1, const Image* motion = nullptr);

// Shorthands for compareImages(test, reference).<metric>.
double relMse(const Image& test, const Image& reference);
double mse(const Image& test, const Image& reference);
double mae(const Image& test, const Image& reference);

}  // namespace gdpt
