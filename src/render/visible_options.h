// visible_options.h — the settings of emitter-silhouette supersampling (visible_pass.h) that
// the command line needs without the Vulkan layer: the factor's default and bound, and
// whether a scene has anything the camera could see emit.
#pragma once

#include <cstdint>

#include "render/features.h"

namespace gdpt {

// Default rays per camera sample in a refined pixel (`gdpt render --emitter-supersampling`).
// On the Cornell box G-PT at 4-16 spp, 16 took the light rim's share of relMSE from 40-60 %
// to a few percent at about 1 % more rays (bench/RESULTS.md, fifth session).
constexpr std::uint32_t kDefaultVisibleSupersampling = 16;
// Upper bound of the factor: keeps the Sobol' index (factor × samples per pixel) within 32
// bits up to the 2^24 samples that PixelStats counts exactly.
constexpr std::uint32_t kMaxVisibleSupersampling = 64;

// The pass has work only where the camera can see emission: an emissive triangle or the
// environment.
inline bool visibleEmissionPossible(const SceneFeatures& f) { return f.hasLightTris || f.hasEnv; }

}  // namespace gdpt
