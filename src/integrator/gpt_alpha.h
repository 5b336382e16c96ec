// gpt_alpha.h — the primal weight α of G-PT's reconstruction when `--alpha` is not given,
// chosen from how the scene is lit.
//
// The screened Poisson energy weighs the primal rows by α against the gradient rows (Kettunen
// et al. 2015, §4, eq. 2, α = 0.2). That value is the best or within 2 % of it on the rooms lit
// by emissive surfaces (the Cornell box, its small-light, textured and glossy variants),
// but every scene measured with a constant environment (`--env`) gave its lowest relMSE at a
// larger α, at equal samples and so at equal time (the solve costs no more): lit by the
// environment alone (a 110,000-triangle engine) α = 0.8, 16–18 % below α = 0.2; by the
// environment and emissive surfaces (the Cornell box open to a sky, a terrain with a small
// sun, the small-light box under a dim sky) α = 0.4, 4–15 % below, where α = 0.8 was 1–5 %
// better or up to 12 % worse (bench/RESULTS.md, "The primal weight α by the scene's light").
// A sky made of emissive triangles (SceneFeatures::hasEmissiveEnclosure: an emissive material
// whose bounding box holds every other material's) is lit like a sky too and gets α = 0.4:
// 8–14 % below α = 0.2 on the open scene's dome with and without its lamp and on the Cornell box
// inside an emissive box, where α = 0.8 was up to 2 % worse or 4 % better than 0.4; the white
// furnace, a sphere of emission alone, lost 6 % at 0.4 and 44 % at 0.8 (bench/RESULTS.md,
// "A sky of emissive triangles").
// The scene's light is what the choice reads: deterministic, before any sample, and the same
// on every run. `--alpha` overrides the choice; the other methods keep their own defaults
// (T-GPT's flicker rose at 0.4).
#pragma once

#include "render/device_scene/features.h"

namespace gdpt {

// How a scene is lit, as the choice of α sees it.
enum class GptLighting {
    Emitters,                // emissive triangles and punctual lights, no environment
    EnvironmentAndEmitters,  // a non-black environment and some other light
    Environment,             // a non-black environment only
    EmissiveSky,             // no environment, but emissive triangles around the scene
};

inline constexpr double kGptAlphaEmitters = 0.2;  // Kettunen et al. 2015's α
inline constexpr double kGptAlphaEnvironmentAndEmitters = 0.4;
inline constexpr double kGptAlphaEnvironment = 0.8;
inline constexpr double kGptAlphaEmissiveSky = 0.4;

GptLighting gptLighting(const SceneFeatures& features);
double gptDefaultAlpha(GptLighting lighting);
const char* toString(GptLighting lighting);

}  // namespace gdpt
