#include "render/device_scene/light_probe.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "bvh/builder.h"
#include "bvh/traverse_cpu.h"
#include "lib/ray.glsl"
#include "lib/sampling.glsl"
#include "render/device_scene/camera_ray.h"
#include "render/device_scene/features.h"
#include "render/device_scene/light_table.h"
#include "util/parallel.h"

namespace gdpt {
namespace {

// One emitter: its triangles (scene indices) with the running share of the emitter's power,
// as the light table picks them within it, and its luminance on the side(s) it emits.
struct Emitter {
    std::uint32_t material = 0;
    std::vector<std::uint32_t> triangles;
    std::vector<double> cdf;  // running power share, the last entry 1
    float luminance = 0.0f;
    bool doubleSided = false;
    double power = 0.0;      // of its triangles (emitterPower)
    double selection = 0.0;  // `mixed`'s probability of picking it, for the MIS weights
};

std::vector<Emitter> collectEmitters(const Scene& scene) {
    std::map<std::uint32_t, Emitter> byMaterial;
    for (std::size_t t = 0; t < scene.triangles.size(); ++t) {
        if (!materialIsEmissive(scene, t)) continue;
        const double power = emitterPower(scene, t, triangleArea(scene, t));
        if (!(power > 0.0)) continue;
        Emitter& e = byMaterial[scene.triangleMaterial[t]];
        e.triangles.push_back(static_cast<std::uint32_t>(t));
        e.cdf.push_back((e.cdf.empty() ? 0.0 : e.cdf.back()) + power);
    }
    std::vector<Emitter> out;
    for (auto& [material, e] : byMaterial) {
        const gpu::Material& m = scene.materials[material];
        e.material = material;
        e.luminance = std::max(gpu::luminance(m.emissive), gpu::maxComponent(m.emissive) * 1e-3f);
        e.doubleSided = (m.flags & gpu::kMatFlagDoubleSided) != 0;
        e.power = e.cdf.back();
        for (double& c : e.cdf) c /= e.power;
        e.cdf.back() = 1.0;
        out.push_back(std::move(e));
    }
    double total = 0.0;
    for (const Emitter& e : out) total += e.power;
    for (Emitter& e : out)
        e.selection =
            emitterShare(LightSelection::Mixed, e.power, total, static_cast<std::uint32_t>(out.size()));
    return out;
}

// The radical inverse of i in base b (Halton's sequence): the probe's fixed points.
double radicalInverse(std::uint32_t i, std::uint32_t base) {
    double inv = 1.0 / base, f = inv, r = 0.0;
    for (; i > 0; i /= base, f *= inv) r += f * double(i % base);
    return r;
}

// One light point's estimate: g, the direct light a white Lambertian at x (unit normal n facing
// the camera) receives from point y of triangle `tri` over the area density of picking y
// within the emitter, and `weighted`, g times the power-heuristic weight that the kernels
// give next-event estimation against BSDF sampling there (with `mixed`'s probability of the
// emitter): the part of g that the light sample carries. Zero where the light faces away or
// something is in between.
struct LightTerm {
    double g = 0.0;
    double weighted = 0.0;
};

LightTerm lightTerm(const Scene& scene, const SceneBvh& bvh, const std::vector<gpu::TriangleGeom>& geoms,
                    const Emitter& e, std::size_t pick, glm::vec2 u, glm::vec3 x, glm::vec3 n,
                    float sceneRadius) {
    const std::uint32_t tri = e.triangles[pick];
    const glm::vec3 v0 = scene.positions[scene.triangles[tri].x];
    const glm::vec3 e1 = scene.positions[scene.triangles[tri].y] - v0;
    const glm::vec3 e2 = scene.positions[scene.triangles[tri].z] - v0;
    const glm::vec3 bary = gpu::sampleUniformTriangle(u);  // as the kernels' sampleLight
    const glm::vec3 y = v0 + bary.y * e1 + bary.z * e2;
    const glm::vec3 c = glm::cross(e1, e2);
    const float area = 0.5f * glm::length(c);
    if (!(area > 0.0f)) return {};
    const glm::vec3 nl = c / (2.0f * area);
    const glm::vec3 d = y - x;
    const float dist2 = glm::dot(d, d);
    if (!(dist2 > 0.0f)) return {};
    const float dist = std::sqrt(dist2);
    const glm::vec3 wi = d / dist;
    const float cosX = glm::dot(n, wi);
    float cosL = -glm::dot(nl, wi);
    if (e.doubleSided) cosL = std::abs(cosL);
    if (!(cosX > 0.0f) || !(cosL > 0.0f)) return {};
    const glm::vec3 origin = gpu::offsetRayOriginScaled(x, n, sceneRadius);
    const glm::vec3 towards = y - origin;
    const float len = glm::length(towards);
    if (len > 0.0f &&
        traceAnyWideCpu(bvh.wide.nodes, geoms, origin, towards / len, 0.0f, len * (1.0f - 1e-4f)))
        return {};
    constexpr double kPi = 3.14159265358979;
    const double share = e.cdf[pick] - (pick > 0 ? e.cdf[pick - 1] : 0.0);
    const double pdfArea = share / double(area);
    LightTerm t;
    t.g = double(e.luminance) * double(cosX) * double(cosL) / (double(dist2) * kPi) / pdfArea;
    const double pdfLight = e.selection * pdfArea * double(dist2) / double(cosL);  // solid angle
    const double pdfBsdf = double(cosX) / kPi;
    t.weighted = t.g * pdfLight * pdfLight / (pdfLight * pdfLight + pdfBsdf * pdfBsdf);
    return t;
}

}  // namespace

EmitterProbe probeEmitters(const Scene& scene, const SceneBvh& bvh, const gpu::SceneConstants& camera,
                           float sceneRadius) {
    EmitterProbe probe;
    const std::vector<Emitter> emitters = collectEmitters(scene);
    if (emitters.size() < 2 || emitters.size() > kLightProbeMaxEmitters) return probe;  // nothing to choose
    const std::vector<gpu::TriangleGeom> geoms =
        makeTriangleGeoms(scene.positions, scene.triangles, bvh.binary.triangleOrder);
    const std::uint32_t gx = std::min(kLightProbeGrid, camera.width);
    const std::uint32_t gy = std::min(kLightProbeGrid, camera.height);
    // Per grid row: each emitter's sum of the points' weighted second moments; summed in row
    // order afterwards.
    std::vector<std::vector<double>> rowSums(gy, std::vector<double>(emitters.size(), 0.0));
    std::vector<std::uint32_t> rowHits(gy, 0);
    parallelFor(defaultThreads(), gy, [&](std::size_t j) {
        std::vector<double> mean(emitters.size()), moment(emitters.size());
        for (std::uint32_t i = 0; i < gx; ++i) {
            const glm::vec2 pos((float(i) + 0.5f) * float(camera.width) / float(gx),
                                (float(j) + 0.5f) * float(camera.height) / float(gy));
            const glm::vec3 dir = cameraRay(camera, pos);
            const gpu::Hit h = traceClosestWideCpu(bvh.wide.nodes, geoms, camera.camPosition, dir, 0.0f,
                                                   std::numeric_limits<float>::infinity());
            if (h.triangle == gpu::kInvalidIndex) continue;
            const gpu::TriangleGeom& g = geoms[h.triangle];
            const glm::vec3 x = g.v0 + h.u * g.e1 + h.v * g.e2;
            glm::vec3 n = glm::normalize(glm::cross(g.e1, g.e2));
            if (glm::dot(n, dir) > 0.0f) n = -n;
            if (!std::isfinite(n.x)) continue;
            ++rowHits[j];
            const std::uint32_t point = std::uint32_t(j) * gx + i;
            double direct = 0.0;  // the point's direct light, all emitters
            for (std::size_t k = 0; k < emitters.size(); ++k) {
                const Emitter& e = emitters[k];
                mean[k] = moment[k] = 0.0;
                for (std::uint32_t s = 0; s < kLightProbeSamples; ++s) {
                    const std::uint32_t index = point * kLightProbeSamples + s + 1;
                    const double pickU = radicalInverse(index, 2);
                    const auto pick = static_cast<std::size_t>(
                        std::lower_bound(e.cdf.begin(), e.cdf.end(), pickU) - e.cdf.begin());
                    const glm::vec2 u(float(radicalInverse(index, 3)), float(radicalInverse(index, 5)));
                    const LightTerm t = lightTerm(scene, bvh, geoms, e, std::min(pick, e.cdf.size() - 1), u,
                                                  x, n, sceneRadius);
                    mean[k] += t.g / kLightProbeSamples;
                    moment[k] += t.weighted * t.weighted / kLightProbeSamples;
                }
                direct += mean[k];
            }
            // relMSE's weight of the point (Kettunen et al. 2015's metric: error² / (I² + 0.01)).
            const double w = 1.0 / (direct * direct + 0.01);
            for (std::size_t k = 0; k < emitters.size(); ++k) rowSums[j][k] += w * moment[k];
        }
    });
    std::vector<double> sums(emitters.size(), 0.0);
    for (std::uint32_t j = 0; j < gy; ++j) {
        probe.points += rowHits[j];
        for (std::size_t k = 0; k < emitters.size(); ++k) sums[k] += rowSums[j][k];
    }
    const double n = double(std::max(probe.points, 1u));
    for (std::size_t k = 0; k < emitters.size(); ++k) probe.secondMoment[emitters[k].material] = sums[k] / n;
    return probe;
}

}  // namespace gdpt
