// edge_options.h — the settings of G-PT's extra samples in the pixels that a geometric edge
// crosses (edge_pass.h) that the command line needs without the Vulkan layer.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "util/error.h"

namespace gdpt {

// The factor by default (`--edge-samples auto`): the extra camera samples per camera sample
// in the pixels of edgeSampleList (the edge pixels and their four neighbours) follow those
// pixels' share of the image,
//   K = min(kAutoEdgeSamplesMax, floor(kEdgeSampleShare / share)),
// so the edge samples add at most about 60 % of a sample pass. At equal time K = 2 was as low as
// 3 and 4 and below 1 on the set's scenes, on a 110,000-triangle engine (25 % of its pixels
// listed) and at 64² and 128² (10-17 %); above 30 % of the image K falls to 1, above 60 % to
// 0, where the list is most of the image and its samples are a denser pass everywhere
// (bench/RESULTS.md, "Edge samples for both pixels of a pair"). The choice depends on the
// geometry alone (the probe), so renders stay reproducible.
constexpr std::uint32_t kAutoEdgeSamplesMax = 2;
constexpr double kEdgeSampleShare = 0.6;
// The value that asks for that rule (EdgePass resolves it after its probe).
constexpr std::uint32_t kEdgeSamplesAuto = 0xFFFFFFFFu;
// Upper bound of an explicit factor: keeps the edge samples' Sobol' index ((sample + 1) ×
// factor) within 32 bits up to the 2^24 samples per pixel that PixelStats counts exactly.
constexpr std::uint32_t kMaxEdgeSamples = 64;

// The rule's factor for `listed` pixels (edgeSampleList's) of `pixels`.
inline std::uint32_t autoEdgeSamples(std::uint64_t listed, std::uint64_t pixels) {
    if (listed == 0) return kAutoEdgeSamplesMax;
    const double k = kEdgeSampleShare * static_cast<double>(pixels) / static_cast<double>(listed);
    return k >= kAutoEdgeSamplesMax ? kAutoEdgeSamplesMax : static_cast<std::uint32_t>(k);
}

// The pixels that get the extra samples, in ascending order: every pixel of `mask` (W·H, non-zero
// = a geometric edge crosses it) and its four neighbours. Each pair's gradient, and its part of
// the primal, is estimated from the samples of both of its pixels, each part averaged over its
// own pixel's samples (gpt_resolve.comp); extra samples at the edge pixel alone leave the
// neighbour's part of every pair it shares with the edge at the base rate, and that part's noise
// then dominated the pair when the MIS weights treated both ends alike, which is when this list
// was measured (the weights now count the two ends' samples, shift.glsl).
inline std::vector<std::uint32_t> edgeSampleList(const std::vector<std::uint32_t>& mask, std::uint32_t width,
                                                 std::uint32_t height) {
    std::vector<std::uint32_t> list;
    if (mask.size() != std::size_t{width} * height) return list;
    for (std::uint32_t y = 0; y < height; ++y)
        for (std::uint32_t x = 0; x < width; ++x) {
            const std::size_t i = std::size_t{y} * width + x;
            const bool listed = mask[i] != 0 || (x > 0 && mask[i - 1] != 0) ||
                                (x + 1 < width && mask[i + 1] != 0) || (y > 0 && mask[i - width] != 0) ||
                                (y + 1 < height && mask[i + width] != 0);
            if (listed) list.push_back(static_cast<std::uint32_t>(i));
        }
    return list;
}

// Each pixel's camera samples per camera sample of the image (kBindGptSampleRate): 1 + factor
// in the pixels of `list` (edgeSampleList's), 1 elsewhere. gpt.comp weighs each pair's two
// ends by these counts (shift.glsl, "sample counts in the weights").
inline std::vector<std::uint32_t> edgeSampleRates(const std::vector<std::uint32_t>& list,
                                                  std::uint32_t factor, std::uint32_t width,
                                                  std::uint32_t height) {
    std::vector<std::uint32_t> rates(std::size_t{width} * height, 1u);
    for (std::uint32_t p : list)
        if (p < rates.size()) rates[p] = 1u + factor;
    return rates;
}

// How G-PT's pair weights treat the two ends' sample counts, as checkpoints and shards record
// it (`pair_weights`): a checkpoint written before the counts entered the weights (2026-12-05)
// holds samples weighted otherwise, and resuming it would not be the render the output names.
inline constexpr const char* kPairWeights = "sample-counts";

// The rule of edgeSampleList as checkpoints and shards record it (`edge_sample_pixels`): one
// written with the edge pixels alone (before 2026-12-05) has other pixels' counts and is refused.
inline constexpr const char* kEdgeSamplePixels = "edges+neighbours";

// "auto" or the number, as the command line, `--json` and checkpoints write it.
inline std::string edgeSamplesText(std::uint32_t factor) {
    return factor == kEdgeSamplesAuto ? std::string("auto") : std::to_string(factor);
}

// What is wrong with a refused value (parseEdgeSamples's message, and the CLI's).
inline std::string edgeSamplesRefusal(const std::string& text) {
    return "'" + text + "' is not auto or a whole number from 0 to " + std::to_string(kMaxEdgeSamples);
}

// Parses "auto" or a whole number in [0, kMaxEdgeSamples]; throws gdpt::Error naming `what`.
inline std::uint32_t parseEdgeSamples(const std::string& text, const std::string& what) {
    if (text == "auto") return kEdgeSamplesAuto;
    std::uint32_t v = 0;
    bool ok = !text.empty() && text.size() <= 3;
    for (char c : text) {
        if (c < '0' || c > '9') ok = false;
        v = v * 10 + static_cast<std::uint32_t>(c - '0');
    }
    if (!ok || v > kMaxEdgeSamples) throw Error(what + ": " + edgeSamplesRefusal(text));
    return v;
}

}  // namespace gdpt
