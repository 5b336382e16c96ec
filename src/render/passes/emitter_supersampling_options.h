// emitter_supersampling_options.h — the settings of emitter supersampling (emitter_supersampling_pass.h) that
// the command line needs without the Vulkan layer: the factor's default and bound, and
// whether a scene has anything the camera could see emit.
#pragma once

#include <cstdint>

#include "render/device_scene/features.h"

namespace gdpt {

// Default rays per camera sample in a refined pixel (`gdpt render --emitter-supersampling`).
// On the Cornell box G-PT at 4-16 spp, 16 took the light rim's share of relMSE from 40-60 %
// to a few percent at about 1 % more rays (bench/RESULTS.md, emitter supersampling).
constexpr std::uint32_t kDefaultEmitterSupersampling = 16;
// Upper bound of the factor: keeps the Sobol' index (factor × samples per pixel) within 32
// bits up to the 2^24 samples that PixelStats counts exactly.
constexpr std::uint32_t kMaxEmitterSupersampling = 64;

// The pass has work only where the camera can see emission: an emissive triangle or the
// environment.
inline bool emitterSupersamplingPossible(const SceneFeatures& f) {
    return f.hasLightTris || f.hasEnv;
}

}  // namespace gdpt
