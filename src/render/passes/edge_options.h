// edge_options.h — the settings of G-PT's extra samples in the pixels that a geometric edge
// crosses (edge_pass.h) that the command line needs without the Vulkan layer.
#pragma once

#include <cstdint>

namespace gdpt {

// Default extra camera samples per camera sample in an edge pixel (`gdpt render
// --edge-samples`): the Cornell box at 16 spp, 2 % of the pixels, relMSE 0.0039 -> 0.0031
// for 8 % more samples (13 % more time); at 8 s, 2 / 4 / 8 gave 0.00184 / 0.00181 / 0.00194
// (bench/RESULTS.md, edge samples).
constexpr std::uint32_t kDefaultEdgeSamples = 4;
// Upper bound: keeps the edge samples' Sobol' index ((sample + 1) × factor) within 32 bits up
// to the 2^24 samples per pixel that PixelStats counts exactly.
constexpr std::uint32_t kMaxEdgeSamples = 64;

}  // namespace gdpt
