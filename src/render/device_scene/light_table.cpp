#include "render/device_scene/light_table.h"

#include <cmath>
#include <map>

#include "render/device_scene/features.h"
#include "util/parallel.h"

namespace gdpt {
namespace {
constexpr std::size_t kGrain = std::size_t{1} << 16;  // leaf positions per range of the scan

// The share of the selection probability spread uniformly over the emitters.
double uniformShare(LightSelection s) {
    switch (s) {
        case LightSelection::Power:
            return 0.0;
        case LightSelection::Uniform:
            return 1.0;
        case LightSelection::Mixed:
        case LightSelection::Probe:
            return 0.5;
    }
    return 0.5;
}

// Emitter shares as multiples of 1/kShareSteps where every share is at least half a step: the
// light choice is a stratified dimension (sampler.glsl: every aligned block of 16 samples of a
// pixel puts one point in each sixteenth of [0, 1)), so an emitter whose CDF interval starts
// and ends on sixteenths gets exactly its share of every such block instead of one sample
// more or less, which costs variance (bench/RESULTS.md, "The probe rule"). Rounding moves a
// share by at most half a step; the sum's rounding error goes to the largest share. Shares
// that would round to zero leave the table as it was.
constexpr double kShareSteps = 16.0;
std::map<std::uint32_t, double> alignedShares(const std::map<std::uint32_t, double>& shares) {
    std::map<std::uint32_t, double> out;
    double sum = 0.0;
    std::uint32_t largest = shares.begin()->first;
    for (const auto& [material, share] : shares) {
        const double q = std::round(share * kShareSteps) / kShareSteps;
        if (!(q > 0.0)) return shares;
        out[material] = q;
        sum += q;
        if (share > shares.at(largest)) largest = material;
    }
    out[largest] += 1.0 - sum;
    if (!(out[largest] > 0.0)) return shares;
    return out;
}

struct Emissive {
    std::uint32_t leaf;
    std::uint32_t material;
    double power;
};
}  // namespace

std::optional<LightSelection> parseLightSelection(const std::string& text) {
    if (text == "power") return LightSelection::Power;
    if (text == "uniform") return LightSelection::Uniform;
    if (text == "mixed") return LightSelection::Mixed;
    if (text == "probe") return LightSelection::Probe;
    return std::nullopt;
}

const char* toString(LightSelection s) {
    switch (s) {
        case LightSelection::Power:
            return "power";
        case LightSelection::Uniform:
            return "uniform";
        case LightSelection::Mixed:
            return "mixed";
        case LightSelection::Probe:
            return "probe";
    }
    return "?";
}

double emitterShare(LightSelection selection, double emitterPower, double totalPower,
                    std::uint32_t emitters) {
    const double u = uniformShare(selection);
    return (1.0 - u) * emitterPower / totalPower + u / double(emitters);
}

LightTable makeLightTable(const Scene& scene, const std::vector<std::uint32_t>& order,
                          LightSelection selection, const std::map<std::uint32_t, double>& probeWeights) {
    // Each range's emitters, found in parallel and joined in leaf order.
    std::vector<std::vector<Emissive>> found((order.size() + kGrain - 1) / kGrain);
    parallelRanges(0, order.size(), kGrain, [&](std::size_t begin, std::size_t end) {
        auto& range = found[begin / kGrain];
        for (std::size_t i = begin; i < end; ++i) {
            if (!materialIsEmissive(scene, order[i])) continue;
            const double p = emitterPower(scene, order[i], triangleArea(scene, order[i]));
            if (p > 0.0)
                range.push_back({static_cast<std::uint32_t>(i), scene.triangleMaterial[order[i]], p});
        }
    });
    LightTable t;
    std::map<std::uint32_t, double> emitterPowers;  // material -> its triangles' power
    for (const auto& range : found)
        for (const Emissive& e : range) {
            t.totalPower += e.power;
            emitterPowers[e.material] += e.power;
        }
    t.emitters = static_cast<std::uint32_t>(emitterPowers.size());
    // The probe's half: emitter e's share w_e / Σ w over the emitters of this table, counting
    // only positive, finite weights.
    const auto weight = [&](std::uint32_t material) {
        const auto w = probeWeights.find(material);
        return w != probeWeights.end() && w->second > 0.0 && std::isfinite(w->second) ? w->second : 0.0;
    };
    double weightSum = 0.0;
    if (selection == LightSelection::Probe && t.emitters > 1)
        for (const auto& [material, power] : emitterPowers) weightSum += weight(material);
    t.probed = weightSum > 0.0 && std::isfinite(weightSum);
    const double u = uniformShare(selection);
    if (!t.probed) {
        double running = 0.0;
        for (const auto& range : found)
            for (const Emissive& e : range) {
                const double pmf = (1.0 - u) * e.power / t.totalPower +
                                   u * e.power / (emitterPowers[e.material] * double(t.emitters));
                t.shares[e.material] += pmf;
                running += pmf;
                t.lights.push_back({e.leaf, static_cast<float>(running), static_cast<float>(pmf), 0.0f});
            }
    } else {
        // Half `mixed`, half the probe's weights, then in multiples of 1/kShareSteps
        // (alignedShares), each emitter's triangles contiguous from an aligned start.
        for (const auto& [material, power] : emitterPowers)
            t.shares[material] = 0.5 * emitterShare(selection, power, t.totalPower, t.emitters) +
                                 0.5 * weight(material) / weightSum;
        t.shares = alignedShares(t.shares);
        double running = 0.0;
        for (const auto& [material, share] : t.shares)
            for (const auto& range : found)
                for (const Emissive& e : range) {
                    if (e.material != material) continue;
                    const double pmf = share * e.power / emitterPowers[material];
                    running += pmf;
                    t.lights.push_back({e.leaf, static_cast<float>(running), static_cast<float>(pmf), 0.0f});
                }
    }
    if (!t.lights.empty()) t.lights.back().cdf = 1.0f;
    return t;
}

}  // namespace gdpt
