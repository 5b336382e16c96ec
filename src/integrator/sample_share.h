// sample_share.h — which camera samples of every pixel this process renders when a render
// is split across processes (MPI ranks, or shards started as independent jobs;
// docs/distributed.md). Part I of N takes the samples s with s ≡ I (mod N): its local sample
// j is the render's sample I + N·j, so every part covers the whole image, and a timed render's
// parts progress through the samples at the same pace. Sample s of pixel p always uses the
// random stream (p, s, seed), so the parts together take exactly the samples of a
// single-process render.
#pragma once

#include <cstdint>
#include <string>

namespace gdpt {

struct SampleShare {
    std::uint32_t index = 0;  // this part, 0 .. count-1
    std::uint32_t count = 1;  // number of parts (1: not split)

    [[nodiscard]] bool split() const { return count > 1; }
    // The render's sample index of this part's local sample j.
    [[nodiscard]] std::uint64_t globalSample(std::uint32_t local) const {
        return std::uint64_t(index) + std::uint64_t(count) * local;
    }
    // Samples per pixel this part takes of a render of `total` spp: those s < total with
    // s ≡ index (mod count).
    [[nodiscard]] std::uint32_t localSpp(std::uint32_t total) const {
        return total > index ? (total - index + count - 1) / count : 0;
    }
    // "I/N".
    [[nodiscard]] std::string text() const { return std::to_string(index) + "/" + std::to_string(count); }
};

// Parses "I/N" (0 <= I < N, 1 <= N <= kMaxShares); throws gdpt::UsageError naming `what`.
SampleShare parseSampleShare(const std::string& text, const std::string& what);

// The most parts a render may be split into (a part takes at least one sample per pixel, and a
// sample index stays below 2^24).
constexpr std::uint32_t kMaxShares = 1u << 16;

}  // namespace gdpt
