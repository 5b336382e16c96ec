// mlt_estimate.h — the host's share of Metropolis light transport (mlt_integrator.h): the
// bootstrap's normalisation, the chains' starting states, and the splat of the kernel's
// records into images. Plain CPU code, tested on its own (tests/unit/sampling/test_mlt_chain.cpp).
//
// Estimator (Veach 1997 §11.3; Kelemen et al. 2002 §4): with T the target over the unit
// hypercube of decisions, b = ∫ T (the bootstrap's mean), and N mutations, a quantity X of
// pixel p is estimated by
//     X(p) ≈ (W·H) · b / N · Σ_records weight · X(record) · [record in p]
// (W·H because the film position is uniform over the whole image: a pixel's mean is W·H times
// the integral over its share of the hypercube).
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
};
MltNormalisation mltNormalisation(const std::vector<float>& targets);

// The bootstrap samples `chains` chains start from, drawn in proportion to their targets by
// systematic resampling (one uniform offset from `seed`): sample i is chosen about
// chains · T_i / Σ T times, never if T_i = 0. Empty if every target is 0 (or not finite).
std::vector<std::uint32_t> mltChainStarts(const std::vector<float>& targets, std::uint32_t chains,
                                          std::uint32_t seed);

// Per-pixel sums Σ weight · value of the records, in double, in the order they are added.
class MltAccumulator {
public:
    MltAccumulator(int width, int height);
    // Adds the records' splats, and the targets of the large steps' proposals to largeSteps().
    void add(const gpu::MltRecord* records, std::size_t count);
    [[nodiscard]] const TargetSums& largeSteps() const { return largeSteps_; }
    // The mean of quantity k (kMltCentral, kMltNeighbor + i, kMltGradient + i) per pixel,
    // scaled by `scale` (= W·H·b/N).
    [[nodiscard]] Image quantity(std::uint32_t k, double scale) const;

private:
    int width_, height_;
    std::vector<double> sums_;  // [pixel][k][channel]
    TargetSums largeSteps_;
};

// G-PT's resolve (gpt_resolve.comp) of per-pixel means: primal = the average of the pair
// estimators, dx and dy the gradients (zero in the last column / row).
struct MltImages {
    Image primal, dx, dy;
};
MltImages resolveGradientSamples(const MltAccumulator& acc, double scale);

}  // namespace gdpt
