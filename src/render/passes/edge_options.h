// edge_options.h — the settings of G-PT's extra samples in the pixels that a geometric edge
// crosses (edge_pass.h) that the command line needs without the Vulkan layer.
#pragma once

#include <cstdint>
#include <string>

#include "util/error.h"

namespace gdpt {

// The factor by default (`--edge-samples auto`): the extra camera samples per camera sample
// in an edge pixel follow the edge pixels' share of the image,
//   K = min(kAutoEdgeSamplesMax, floor(kEdgeSampleShare / share)),
// so the edge samples add at most about 15 % to a sample pass. The Cornell box (2 % edge
// pixels at 256²) and the open scene (3.3 %) keep 4, where 2, 4 and 8 were level and 4 paid
// over none; a detailed asset (2CylinderEngine, 8.9 %) gets 1, where 4 was the worst factor
// and 1 the best at equal time (bench/RESULTS.md, "The factor on a detailed asset"). The
// choice depends on the geometry alone (the probe), so renders stay reproducible.
constexpr std::uint32_t kAutoEdgeSamplesMax = 4;
constexpr double kEdgeSampleShare = 0.15;
// The value that asks for that rule (EdgePass resolves it after its probe).
constexpr std::uint32_t kEdgeSamplesAuto = 0xFFFFFFFFu;
// Upper bound of an explicit factor: keeps the edge samples' Sobol' index ((sample + 1) ×
// factor) within 32 bits up to the 2^24 samples per pixel that PixelStats counts exactly.
constexpr std::uint32_t kMaxEdgeSamples = 64;

// The rule's factor for `edgePixels` of `pixels`.
inline std::uint32_t autoEdgeSamples(std::uint64_t edgePixels, std::uint64_t pixels) {
    if (edgePixels == 0) return kAutoEdgeSamplesMax;
    const double k = kEdgeSampleShare * static_cast<double>(pixels) / static_cast<double>(edgePixels);
    return k >= kAutoEdgeSamplesMax ? kAutoEdgeSamplesMax : static_cast<std::uint32_t>(k);
}

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
