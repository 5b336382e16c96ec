// light_probe.h — how much each emitter matters to next-event estimation where the camera
// looks: the probe behind `--light-selection probe` (light_table.h).
//
// Next-event estimation picks emitter e with probability P_e and a point y on it, and
// estimates the direct light g_e(y) / (P_e p_e(y)). Summed over the shading points x_k, the
// variance of that one-sample estimator is Σ_e M_e / P_e − const with M_e = Σ_k E[g_e²], the
// second moment of emitter e's own estimator, and Σ_e M_e / P_e under Σ_e P_e = 1 is least
// at P_e ∝ √M_e (a Lagrange multiplier; the same argument as for the optimal mixture weights
// of Veach 1997, §9.2). The probe estimates M_e at the surfaces the camera sees: a fixed grid
// of primary rays (no random numbers: the same table on every run and every rank), and at
// each hit a fixed set of points on every emitter, each with its shadow ray.
//
// What it leaves out, and why that is bounded: the light reaching later vertices of a path
// (an emitter that lights the camera's room only through a gap scores nothing), the BSDFs
// (every point is a white Lambertian) and the MIS with BSDF sampling. The light table
// therefore mixes the probe's rule half and half with `mixed` (Hesterberg 1995's defensive
// mixture): no emitter gets less than half of what `mixed` gives it, less at most the
// rounding of the shares to sixteenths (light_table.cpp).
#pragma once

#include <cstdint>
#include <map>

#include "gdpt_shared.h"
#include "render/device_scene/scene_spec.h"
#include "scene/scene.h"

namespace gdpt {

// Probe rays per image axis (at most; fewer in a smaller image) and points per emitter at
// each hit.
inline constexpr std::uint32_t kLightProbeGrid = 32;
inline constexpr std::uint32_t kLightProbeSamples = 4;
// Scenes with more emissive materials than this are not probed (`mixed` instead): the probe's
// shadow rays grow with their number.
inline constexpr std::uint32_t kLightProbeMaxEmitters = 64;

struct EmitterProbe {
    // Emissive material -> M_e / (probe points × samples): the mean of g_e² over the probe
    // points that hit a surface (luminance units squared).
    std::map<std::uint32_t, double> secondMoment;
    std::uint32_t points = 0;  // probe rays that hit a surface
};

// The probe for the camera of `camera` (the scene constants' camera and image size). `bvh`
// is the scene's (its wide tree and leaf order); `sceneRadius` scales the shadow rays' origin
// offset as in the kernels. Emitters are the emissive materials with a triangle of positive
// power (light_table.h). Deterministic for any number of threads. Empty (no emitter) with
// fewer than two emitters or more than kLightProbeMaxEmitters.
EmitterProbe probeEmitters(const Scene& scene, const SceneBvh& bvh, const gpu::SceneConstants& camera,
                           float sceneRadius);

}  // namespace gdpt
