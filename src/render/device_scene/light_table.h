// light_table.h — the emissive triangles as next-event estimation chooses among them: one
// record per emissive triangle (in the BVH's leaf order; under the probe rule grouped by
// emitter, each group starting on a sixteenth of the CDF) with its selection probability and
// the running CDF that shaders/lib/scene_access.glsl searches.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "gdpt_shared.h"
#include "scene/scene.h"

namespace gdpt {

// How NEE picks an emissive triangle. An emitter is the set of triangles of one emissive
// material; within an emitter a triangle is always picked in proportion to its power.
//  - Power: every triangle in proportion to its power (area · luminance · π), over the whole
//    scene. Optimal for one emitter, poor when most of the power leaves the scene: a sky dome
//    holding 99 % of it takes 99 % of the samples from a lamp that outshines it locally.
//  - Uniform: each emitter with the same probability, as Mitsuba 0.5 picks its emitters.
//  - Mixed: half of each, a defensive mixture (Hesterberg 1995): no triangle
//    gets less than half the probability either rule gives it, so it costs at most 2x the
//    variance of the better rule and avoids the worse one's failures.
//  - Probe (the default): half `mixed`, half each emitter in proportion to the square root of its second
//    moment at the surfaces the camera sees (light_probe.h), the share that minimises the
//    variance of next-event estimation there. `mixed` where the probe has nothing to say
//    (one emitter, none seen, more than kLightProbeMaxEmitters). The shares are rounded to
//    sixteenths where none rounds to zero, so that the stratified light choice gives each
//    emitter exactly its share of every 16 samples of a pixel (light_table.cpp).
enum class LightSelection { Power, Uniform, Mixed, Probe };

// The names of the rules (toString), for --light-selection.
inline constexpr const char* kLightSelectionChoices[] = {"power", "uniform", "mixed", "probe"};
std::optional<LightSelection> parseLightSelection(const std::string& text);
const char* toString(LightSelection s);

struct LightTable {
    std::vector<gpu::LightTriangle> lights;  // triangle = leaf position; pmf, cdf
    double totalPower = 0.0;                 // of every emissive triangle
    std::uint32_t emitters = 0;              // emissive materials with a light triangle
    // Emissive material -> the probability that NEE picks one of its triangles.
    std::map<std::uint32_t, double> shares;
    // Probe: whether the probe's weights were used (false: the table is `mixed`'s).
    bool probed = false;
};

// The probability that a fixed rule (Power, Uniform, Mixed) gives an emitter of power
// `emitterPower` among `emitters` emitters of total power `totalPower`.
double emitterShare(LightSelection selection, double emitterPower, double totalPower, std::uint32_t emitters);

// `order`: the BVH's leaf order (leaf position -> scene triangle). Triangles without area or
// power are no lights. `probeWeights` (Probe only): emissive material -> a weight ∝ the
// probability the probe's half gives it (√M_e, light_probe.h); without a positive weight
// for some emitter the table is `mixed`'s, bit for bit.
LightTable makeLightTable(const Scene& scene, const std::vector<std::uint32_t>& order,
                          LightSelection selection, const std::map<std::uint32_t, double>& probeWeights = {});

}  // namespace gdpt
