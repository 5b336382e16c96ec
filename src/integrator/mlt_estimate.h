// mlt_estimate.h — the host's share of Metropolis light transport (mlt_integrator.h): the
// bootstrap's normalisation, the chains' starting states, and the splat of the kernel's
// records into images. Plain CPU code, tested on its own (tests/unit/mlt/test_mlt_chain.cpp).
//
// Estimator (Veach 1997 §11.3; Kelemen et al. 2002 §4, whose multiple importance sampling of
// the Metropolis samples and the large steps' uniform ones mlt.glsl derives): with T the
// target over the unit hypercube of decisions, b = ∫ T, N mutations and b' the b̂ the splat
// weights were computed with, a quantity X of pixel p is estimated by
//     X(p) ≈ (W·H) / N · Σ_records [b̂ · weight + largeWeight] · X(record) · [record in p]
// (weight: the record's Metropolis share, mltSplatWeight; largeWeight: mltLargeStepWeight for
// a large step's proposal, else 0; W·H because the film position is uniform over the whole
// image: a pixel's mean is W·H times the integral over its share of the hypercube). The two
// sums are kept apart, since b̂ is final only after the last large step.
#pragma once

#include <cstdint>
#include <vector>

#include "image/image.h"
#include "mlt_shared.h"

namespace gdpt {

// b̂ = the mean of targets of fresh uniform states (the bootstrap's and the large steps'
// proposals) and its standard error (sd / √n), in double.
struct MltNormalisation {
    double b = 0.0;
    double standardError = 0.0;
    std::uint64_t samples = 0;
};

// Running sums of such targets; a negative or non-finite target counts as 0 (the kernel's
// policy for a non-finite sample).
struct TargetSums {
    double sum = 0.0, sumSquares = 0.0;
    std::uint64_t count = 0;
    void add(float target);
    void add(const TargetSums& other);
    [[nodiscard]] MltNormalisation normalisation() const;
    // (Σ T)² / Σ T² (Kish's effective sample size of weights T): how many equally weighted
    // samples a resampling in proportion to T draws from; 0 without a positive target.
    [[nodiscard]] double effectiveSampleSize() const;
};
MltNormalisation mltNormalisation(const std::vector<float>& targets);

// The bootstrap samples `chains` chains start from, drawn in proportion to their targets by
// systematic resampling (one uniform offset from `seed`): sample i is chosen about
// chains · T_i / Σ T times, never if T_i = 0. Empty if every target is 0 (or not finite).
std::vector<std::uint32_t> mltChainStarts(const std::vector<float>& targets, std::uint32_t chains,
                                          std::uint32_t seed);

// A target divided by its image block's brightness: any positive function is a valid target
// (Hoberock and Hart 2010, "Arbitrary Importance Functions for Metropolis Light Transport",
// Computer Graphics Forum 29(6), whose multi-stage MLT divides by a first estimate of the image
// so that the chains go where the relative error is): the chains walk
//     T'(x) = T(x)^γ / D_k,   D_k = (B_k + kMltBlockFloor · B̄)^γ
// for a state x whose film position lies in block k (blocks of `block` pixels square, row
// major), where B_k is the mean untempered target T of the bootstrap samples in block k and B̄
// their mean over the image. With γ = 1 each block then holds about the same share of the
// chains' samples whatever its brightness, and within a block they follow T; the floor keeps a
// block whose bootstrap found nothing from drawing every chain that finds a path in it. D is
// fixed before the chains start, so it is a target like any other (the estimate stays
// unbiased); it is built from the bootstrap samples of even index only, and b̂ pools the odd
// ones, which D does not depend on.
inline constexpr double kMltBlockFloor = 0.1;

struct MltBlockNormaliser {
    std::uint32_t block = 0;  // pixels per block side; 0: no division
    std::uint32_t columns = 0, rows = 0;
    std::vector<float> divisors;  // D_k, columns × rows, row major
    // D of the block that holds `pixel` (y·width + x); 1 without blocks.
    [[nodiscard]] float divisor(std::uint32_t pixel, std::uint32_t width) const;
};

// D from bootstrap samples whose targets are T^exponent (mlt.comp's bootstrap phase); every
// divisor 1 if no even-indexed sample has a positive target. block 0: no division.
MltBlockNormaliser mltBlockNormaliser(const std::vector<gpu::MltBootstrapSample>& samples,
                                      std::uint32_t width, std::uint32_t height, std::uint32_t block,
                                      float exponent);

// The factors of the two sums: metropolis = W·H·b̂/N, large = W·H/N.
struct MltScale {
    double metropolis = 0.0, large = 0.0;
};

// Per-pixel sums Σ weight · value and Σ largeWeight · value of the records, in double, in the
// order they are added. `misNormalisation` and `largeStep`: b' and p of the weights.
class MltAccumulator {
public:
    MltAccumulator(int width, int height, float misNormalisation, float largeStep);
    // Adds the records' splats, and the targets of the large steps' proposals to largeSteps().
    void add(const gpu::MltRecord* records, std::size_t count);
    [[nodiscard]] const TargetSums& largeSteps() const { return largeSteps_; }
    // The mean of quantity k (kMltCentral, kMltNeighbor + i, kMltGradient + i) per pixel.
    [[nodiscard]] Image quantity(std::uint32_t k, MltScale scale) const;

private:
    int width_, height_;
    float misNormalisation_, largeStep_;
    std::vector<double> sums_;       // [pixel][k][channel], Metropolis shares
    std::vector<double> largeSums_;  // the same, large steps' shares
    TargetSums largeSteps_;
};

// G-PT's resolve (gpt_resolve.comp) of per-pixel means: primal = the average of the pair
// estimators, dx and dy the gradients (zero in the last column / row).
struct MltImages {
    Image primal, dx, dy;
};
MltImages resolveGradientSamples(const MltAccumulator& acc, MltScale scale);

}  // namespace gdpt
