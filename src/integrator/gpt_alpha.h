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
// The scene's light is what the choice reads: deterministic, before any sample, and the same
// on every run. A sky of emissive triangles is not told apart from other emitters (the open
// scene's dome gained at 0.4-0.8, the furnace's enclosing sphere lost). `--alpha` overrides
// the choice; the other methods keep their own defaults (T-GPT's flicker rose at 0.4).
#pragma once

#include "render/device_scene/features.h"

namespace gdpt {

// How a scene is lit, as the choice of α sees it.
enum class GptLighting {
    Emitters,                // emissive triangles and punctual lights, no environment
    EnvironmentAndEmitters,  // a non-black environment and some other light
    Environment,             // a non-black environment only
};

inline constexpr double kGptAlphaEmitters = 0.2;  // Kettunen et al. 2015's α
inline constexpr double kGptAlphaEnvironmentAndEmitters = 0.4;
inline constexpr double kGptAlphaEnvironment = 0.8;

GptLighting gptLighting(const SceneFeatures& features);
double gptDefaultAlpha(GptLighting lighting);
const char* toString(GptLighting lighting);

}  // namespace gdpt
