// sample_groups.h — a render's samples in groups of consecutive sample indices, kept as the
// cumulative means of its images at each group's end (its batch ends), and the per-pixel
// variance of a mean of paired differences between two renders with the same groups.
//
// Why: temporal G-PT's dt_f(p) = A(π(p)) − B(p) is the mean of n paired differences, sample i of
// B (frame f's second half) and sample i of A (frame f+1's first half) sharing their random
// numbers (tgpt_integrator.h). Its variance is Var A + Var B − 2 Cov(A, B), and the covariance,
// large where a path hardly changes between the frames, is not in the halves' own variances.
// With the samples split into G groups (the same indices in both renders), each group's mean
// difference d_j is an independent estimate of the same difference, and the between-group spread
//     s² = Σ_j m_j (d_j − d̄)² / (G − 1),   d̄ = Σ_j m_j d_j / n,   Var(dt) ≈ s² / n
// is unbiased for the per-sample variance σ² of the differences when the samples are
// independent (the one-way analysis of variance's between-groups mean square; any group sizes
// m_j, n = Σ m_j): E[Σ_j m_j (d_j − d̄)²] = (G − 1) σ². The samples of a pixel are a scrambled
// Sobol' sequence (sampler.glsl), so, as the halves' Welford variances, this errs on the high
// side. It has G − 1 degrees of freedom per pixel.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "image/image.h"

namespace gdpt {

struct SampleGroups {
    // Samples per pixel at the end of each group, increasing; group j holds the samples
    // [ends[j − 1], ends[j]) (ends[−1] = 0).
    std::vector<std::uint32_t> ends;
    // Per end: each recorded layer's mean over the samples [0, ends[j]).
    std::vector<std::vector<Image>> means;
};

// Records the cumulative means at batch ends (PixelSampling::run's afterBatch).
class SampleGroupRecorder {
public:
    // Every batch: records every batch end, keeping at most maxGroups (≥ 2) of them: one more, and
    // every other end counted back from the last is dropped (pairs of neighbouring groups
    // merge), so the groups stay between maxGroups / 2 and maxGroups in number whatever the
    // render's length. For a render whose length is not known in advance (a timed one).
    static SampleGroupRecorder everyBatch(std::size_t maxGroups);
    // At ends: records at exactly these ends (another render's SampleGroups::ends); the render
    // must end batches there (RenderOptions::batchStops = ends).
    static SampleGroupRecorder atEnds(std::vector<std::uint32_t> ends);

    // Whether the batch that ended at `done` samples per pixel is to be recorded.
    [[nodiscard]] bool wants(std::uint32_t done) const;
    // The layers' means over the samples [0, done).
    void record(std::uint32_t done, std::vector<Image> means);
    [[nodiscard]] const SampleGroups& groups() const { return groups_; }
    [[nodiscard]] SampleGroups take() { return std::move(groups_); }

private:
    std::size_t maxGroups_ = 0;          // everyBatch: the most ends kept
    std::vector<std::uint32_t> wanted_;  // atEnds: the ends to record
    SampleGroups groups_;
};

// The ends of min(groups, n) groups of n samples, as equal as whole samples allow: a render of
// known length records at these (SampleGroupRecorder::atEnds, RenderOptions::batchStops).
std::vector<std::uint32_t> equalGroupEnds(std::uint32_t n, std::size_t groups);

// Per pixel p of the earlier render's frame: the variance of the mean of the paired
// differences later(π(p)) − earlier(p) of layer `layer`, per channel, from the groups' spread
// (above); π = the same pixel if `partner` is empty, and 0 where partner[p] is
// kNoTemporalPartner. Both must have the same ends (throws gdpt::Error otherwise). Fewer than
// two groups give no spread: the result is empty.
Image pairedDifferenceVariance(const SampleGroups& later, const SampleGroups& earlier, std::size_t layer,
                               const std::vector<std::uint32_t>& partner);

}  // namespace gdpt
