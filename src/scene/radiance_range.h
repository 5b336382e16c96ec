// radiance_range.h — the radiance gdpt can represent, and the check that refuses a scene (or
// an environment) whose emission lies outside it, before any sample is taken.
//
// Why a bound far below float's 3.4e38: every estimator keeps per-pixel Welford statistics in
// float32 (pixel_stats.glsl), whose M2 is a sum of squared deviations, about n·x² for n
// samples of size x, and the Poisson reconstruction sums squares over the image. With up to
// 2^24 samples per pixel times 65 (G-PT's edge samples), x² · 1.1e9 must stay below 3.4e38,
// so x below about 5e14; a path's throughput can exceed 1 (next-event estimation of a near
// light, Russian roulette's 1/q), so emission is held two orders of magnitude below that.
// A sample that still overflows is counted as non-finite and zero (pixel_stats.glsl), and
// an output layer with a non-finite value is refused (image/finite_check.h).
#pragma once

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace gdpt {

// Largest emitted radiance (W/(m²·sr)) or punctual intensity (W/sr) per channel.
inline constexpr float kMaxRadiance = 1e12f;

// Throws gdpt::Error when some emission the renderer would use is not finite, negative or
// above kMaxRadiance: the emission of a material on some triangle (emissiveFactor × emissive
// strength × the largest texel of its emissive texture), a punctual light's intensity, or
// envRadiance (--env). The message names the scene file, the material or light (or --env),
// the value and the representable range.
void checkRadianceRange(const Scene& scene, glm::vec3 envRadiance);

}  // namespace gdpt
