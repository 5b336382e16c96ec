// debias.h — takes a reconstruction's coarse scales from an unbiased estimate.
//
// The L1 reconstruction (and the variance-weighted ones) are biased: at low sample counts the
// per-pixel noise is skewed (most samples miss the rare bright paths), and an L1 fit follows
// its median, so the image comes out darker -- by 1 % on a diffuse box, by 10 % and more where
// light arrives through a gap (bench/RESULTS.md, "Bias of the reconstructions"). The primal
// estimate is unbiased but noisy; its noise is almost all at fine scales. So the debiased
// reconstruction is
//
//   R' = R + Π(t − R),
//
// with Π the least-squares projection onto the bilinear functions of a coarse grid (nodes
// every `scale` pixels, tensor-product hat functions φ_k): R' keeps R's fine detail, and its
// coarse content Π R' = Π t is an unbiased estimate (Π is linear and t is unbiased). By
// Galerkin orthogonality Σ_p φ_k(p) (R' − t)(p) = 0 for every node k, and since the hats sum
// to 1, the image sum of R' is the primal's exactly. The correction's own noise is the
// primal's averaged over a hat's footprint (about scale² pixels), small against R's error for a
// scale of 16 or more. This is the "correct the low frequencies of the L1 result with an
// unbiased estimate" reading of the control-variate view of gradient-domain reconstruction
// (Rousselle, Jarosz, Novák 2016, "Image-space control variates for rendering": the screened
// Poisson solution is a control-variate estimator, unbiased only while it is linear).
//
// The projection's normal equations are the Kronecker product of two tridiagonal 1D mass
// matrices, solved directly (Thomas) in double: O(pixels), a few ms at 1024².
#pragma once

#include <string>
#include <vector>

#include "image/image.h"

namespace gdpt {

// A render's coarse grid has `cells` cells across the image's shorter side (`--debias-cells`),
// so that it covers the same part of the scene at any resolution: nodes every
// ceil(min(width, height) / cells) pixels. The default, 8 (32 px at 256²), was chosen by
// measurement on the scene set: the lowest relMSE of 4, 8, 16 and 32 px at 256², and at 64²
// (8 px) 16×16 blocks unbiased within their noise over 24 seeds, which 16 px at 64² are not
// (bench/RESULTS.md, "Bias of the reconstructions").
inline constexpr int kDefaultDebiasCells = 8;
// The largest --debias-cells a command accepts (a grid finer than a pixel changes nothing).
inline constexpr int kMaxDebiasCells = 1 << 20;
// The --debias-cells option's help, for every command that has it.
inline constexpr const char* kDebiasCellsHelp =
    "Cells across the image's shorter side of the coarse grid whose bilinear functions the biased "
    "reconstructions (l1, wl1, wl2) take from the unbiased primal, so that their mean and coarse content "
    "are unbiased (0 = off: the published reconstruction)";

// The node spacing in pixels of a width x height image's grid of `cells` (> 0) cells.
[[nodiscard]] int debiasScale(int width, int height, int cells);

// What a debiasing changed (over the channels of an image: means of the channels' figures).
struct DebiasReport {
    double meanBefore = 0.0;      // mean of the reconstruction before
    double meanCorrection = 0.0;  // mean of the correction added (the coarse bias removed)
    double maxCorrection = 0.0;   // largest |correction| of any pixel (and channel)
    int scale = 0;                // node spacing in pixels
    // The correction relative to the mean before (0 when that mean is not positive).
    [[nodiscard]] double relativeMeanChange() const {
        return meanBefore > 0.0 ? meanCorrection / meanBefore : 0.0;
    }
};

// Replaces the coarse scales of one channel: recon += Π(primal − recon), `scale` pixels
// between the coarse grid's nodes (>= 1; a scale at least the image's size leaves one bilinear
// function over the image). A pixel whose primal or reconstruction is not finite adds nothing
// to the projection (its difference counts as 0). Throws gdpt::Error on sizes that do not
// match or a scale < 1.
DebiasReport debiasChannel(int width, int height, std::vector<float>& recon, const std::vector<float>& primal,
                           int scale);

// debiasChannel on each channel of `recon` against `primal` (same size, else gdpt::Error) at the
// scale of `cells` cells (debiasScale).
DebiasReport debiasImage(Image& recon, const Image& primal, int cells);

// One line on what a debiasing did, e.g. "debiased at 32 px: mean +3.1 % (largest change 0.42)".
[[nodiscard]] std::string describeDebias(const DebiasReport& report);

// The coarse projection Π d of a width x height field (exposed for the tests).
[[nodiscard]] std::vector<double> coarseProjection(int width, int height, const std::vector<double>& d,
                                                   int scale);

}  // namespace gdpt
