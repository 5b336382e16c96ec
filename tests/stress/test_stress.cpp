// Numerical stress suite (ctest -L stress): extreme radiance and scene scales, tiny and
// thin images, long accumulation. Each case asserts finite output, the expected energy
// where it is known (in standard errors estimated from the per-pixel variance), and
// reports the NaN/Inf sample count. GDPT_STRESS_LONG=1 runs the long variants locally.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <utility>

#include "gpu_fixture.h"
#include "image/metrics.h"
#include "integrator/gpt_sampler.h"
#include "integrator/pt_sampler.h"
#include "integrator/render_options.h"
#include "render/device_scene/features.h"
#include "scene/gltf_loader.h"
#include "scene/procedural.h"

namespace gdpt {
namespace {

bool longMode() {
    return std::getenv("GDPT_STRESS_LONG") != nullptr;
}

class Stress : public test::GpuTest {
protected:
    RenderResult render(const Scene& s, int w, int h, std::uint32_t spp, std::uint32_t seed = 3) {
        return renderPt(ctx(), s, renderOptions(w, h, spp, seed));
    }
};

// Image mean of channel c and its standard error (from the per-pixel variance of the mean).
std::pair<double, double> meanAndSe(const RenderResult& r, int c) {
    double sum = 0.0, var = 0.0;
    for (std::size_t i = 0; i < r.image.pixelCount(); ++i) {
        sum += r.image.plane(c)[i];
        var += r.varianceOfMean.plane(c)[i];
    }
    const double n = static_cast<double>(r.image.pixelCount());
    return {sum / n, std::sqrt(var) / n};
}

void expectAllFinite(const Image& img) {
    for (int c = 0; c < 3; ++c)
        for (float v : img.plane(c)) ASSERT_TRUE(std::isfinite(v));
}

// White furnace with emission from 1e-6 to 1e6: L = Le / (1 - a) at every scale, within
// 4 standard errors, and no NaN/Inf samples.
TEST_F(Stress, FurnaceEmissionAcrossTwelveDecades) {
    for (const float le : {1e-6f, 1e-3f, 1.0f, 1e3f, 1e6f}) {
        const RenderResult r = render(makeFurnaceSphere(0.5f, glm::vec3(le), 2), 8, 8, 64);
        expectAllFinite(r.image);
        EXPECT_EQ(r.stats.nanSamples, 0u) << "Le " << le;
        const auto [mean, se] = meanAndSe(r, 1);
        const double expected = le / (1.0 - 0.5);
        EXPECT_LT(std::abs(mean - expected), 4.0 * se + 1e-6 * expected) << "Le " << le;
    }
}

Scene scaled(Scene s, float k) {
    for (auto& p : s.positions) p *= k;
    for (auto& c : s.cameras) c.position *= k;
    return s;
}

// The Cornell box scaled by 1e-4 .. 1e5 renders the same image (radiance is scale
// invariant); robust ray offsets must keep self-intersection away at every scale. The
// tolerance is relMSE against the unscaled render below 3x the expected noise-only value
// (2 x the render's own noise relMSE).
TEST_F(Stress, SceneScaleFromTenMicronsToHundredKilometres) {
    const Scene base = makeCornellBox();
    const RenderResult ref = render(base, 32, 32, 32, 9);
    double noise = 0.0;
    for (std::size_t i = 0; i < ref.image.pixelCount(); ++i) {
        const double g = (ref.image.plane(0)[i] + ref.image.plane(1)[i] + ref.image.plane(2)[i]) / 3.0;
        for (int c = 0; c < 3; ++c) noise += ref.varianceOfMean.plane(c)[i] / (1e-3 + g * g);
    }
    noise /= static_cast<double>(ref.image.pixelCount());
    for (const float k : {1e-4f, 1e-2f, 1e2f, 1e5f}) {
        const RenderResult r = render(scaled(base, k), 32, 32, 32, 10);
        expectAllFinite(r.image);
        EXPECT_EQ(r.stats.nanSamples, 0u);
        const double e = relMse(r.image, ref.image);
        EXPECT_LT(e, 3.0 * 2.0 * noise) << "scale " << k << " relMSE " << e << " noise " << noise;
    }
}

// 1x1, 1xN and Nx1 images render (dispatch bounds, tiling) with finite values.
TEST_F(Stress, DegenerateImageShapes) {
    const Scene s = makeCornellBox();
    for (const auto& [w, h] : std::vector<std::pair<int, int>>{{1, 1}, {1, 37}, {53, 1}, {3, 2}}) {
        const RenderResult r = render(s, w, h, 4);
        ASSERT_EQ(r.image.width(), w);
        ASSERT_EQ(r.image.height(), h);
        expectAllFinite(r.image);
    }
}

// Long accumulation does not drift: one pixel of the furnace with 2^16 samples (long mode
// 2^20) stays within 4 standard errors of Le / (1 - a); float32 Welford/Chan merging keeps
// the running mean's relative rounding error near 1e-6.
TEST_F(Stress, LongAccumulationDoesNotDrift) {
    const std::uint32_t spp = longMode() ? (1u << 20) : (1u << 16);
    const RenderResult r = render(makeFurnaceSphere(0.5f, glm::vec3(1.0f), 2), 1, 1, spp);
    for (int c = 0; c < 3; ++c) {
        const auto [mean, se] = meanAndSe(r, c);
        EXPECT_LT(std::abs(mean - 2.0), 4.0 * se + 2e-6) << "mean " << mean << " se " << se;
    }
}

// Very long paths: a furnace with albedo 0.99 (mean path length ~100 bounces, capped by
// max depth 1023) stays finite and within 4 standard errors of the truncated series.
TEST_F(Stress, VeryLongPaths) {
    RenderOptions o;
    o.scene.width = 4;
    o.scene.height = 4;
    o.scene.maxDepth = 1023;
    o.spp = 256;
    o.seed = 4;
    o.quiet = true;
    const RenderResult r = renderPt(ctx(), makeFurnaceSphere(0.99f, glm::vec3(0.01f), 2), o);
    expectAllFinite(r.image);
    const auto [mean, se] = meanAndSe(r, 0);
    const double expected = 0.01 * (1.0 - std::pow(0.99, 1024)) / (1.0 - 0.99);
    EXPECT_LT(std::abs(mean - expected), 4.0 * se) << mean << " vs " << expected;
}

// G-PT at extreme emitter scales: every output buffer finite, no NaN samples.
TEST_F(Stress, GradientDomainAtExtremeRadiance) {
    for (const float le : {1e-6f, 1e6f}) {
        Scene s = makeCornellBox();
        for (auto& m : s.materials) m.emissive *= le;
        RenderOptions o;
        o.scene.width = 16;
        o.scene.height = 16;
        o.spp = 4;
        o.seed = 8;
        o.quiet = true;
        const RenderResultGpt g = renderGpt(ctx(), s, o);
        EXPECT_EQ(g.stats.nanSamples, 0u) << "Le scale " << le;
        for (const Image* img : {&g.primal, &g.dx, &g.dy, &g.direct, &g.varPrimal, &g.varDx, &g.varDy})
            expectAllFinite(*img);
    }
}

// Camera inside closed geometry: the furnace sphere with its winding (and normals) turned
// outwards, so the camera at its centre sees only back faces, which are opaque black and
// emit nothing (one-sided materials), under a white environment that any ray leaking
// through the shell would see. Every PT pixel and every G-PT buffer is exactly 0.
TEST_F(Stress, CameraInsideClosedGeometrySeesBlack) {
    Scene s = makeFurnaceSphere(0.5f, glm::vec3(1.0f), 1);
    for (glm::uvec3& t : s.triangles) std::swap(t.y, t.z);
    for (glm::vec3& n : s.normals) n = -n;
    RenderOptions o;
    o.scene.width = 16;
    o.scene.height = 16;
    o.scene.envRadiance = glm::vec3(1.0f);
    o.spp = 4;
    o.quiet = true;
    const RenderResult pt = renderPt(ctx(), s, o);
    for (int c = 0; c < 3; ++c)
        for (float v : pt.image.plane(c)) ASSERT_EQ(v, 0.0f);
    EXPECT_EQ(pt.stats.nanSamples, 0u);
    o.spp = 2;
    const RenderResultGpt g = renderGpt(ctx(), s, o);
    for (const Image* img : {&g.primal, &g.dx, &g.dy, &g.direct})
        for (int c = 0; c < 3; ++c)
            for (float v : img->plane(c)) ASSERT_EQ(v, 0.0f);
}

// G-PT shift corner cases on the glossy Cornell box: the shift threshold exactly at the
// scene's smallest roughness (vertices on the reconnection / half-vector boundary), and a
// camera 1 cm above the floor looking along it (offset rays at grazing incidence). Every
// buffer finite and no NaN samples; the shift failure rate is reported, and must be a
// proper fraction of the shifts attempted (a count of zero attempts would mean the counter
// is broken, not that the case is easy).
TEST_F(Stress, GradientDomainShiftCornerCases) {
    const Scene glossy = loadGltf(std::string(GDPT_SOURCE_DIR) + "/scenes/glossy_cornell.gltf");
    const float atThreshold = analyzeScene(glossy, glm::vec3(0.0f)).minRoughness;
    Scene grazing = glossy;
    Camera& cam = grazing.cameras.at(0);
    cam.position = glm::vec3(0.0f, 0.01f, 0.9f);
    cam.forward = glm::normalize(glm::vec3(0.0f, -0.002f, -1.0f));
    const glm::vec3 right = glm::normalize(glm::cross(cam.forward, glm::vec3(0.0f, 1.0f, 0.0f)));
    cam.up = glm::cross(right, cam.forward);
    struct Case {
        const char* name;
        const Scene* scene;
        float threshold;
    };
    for (const Case& k : {Case{"threshold at the roughness", &glossy, atThreshold},
                          Case{"grazing camera", &grazing, 0.001f}}) {
        RenderOptions o;
        o.scene.width = 24;
        o.scene.height = 16;
        o.scene.shiftThreshold = k.threshold;
        o.spp = 4;
        o.seed = 9;
        o.quiet = true;
        const RenderResultGpt g = renderGpt(ctx(), *k.scene, o);
        EXPECT_EQ(g.stats.nanSamples, 0u) << k.name;
        for (const Image* img : {&g.primal, &g.dx, &g.dy, &g.direct, &g.varPrimal, &g.varDx, &g.varDy})
            expectAllFinite(*img);
        ASSERT_GT(g.stats.shiftPairs, 0u) << k.name;
        EXPECT_LE(g.stats.shiftFailures, g.stats.shiftPairs) << k.name;
        std::printf("[ stress ] %s: %llu shifts, failure rate %.4f\n", k.name,
                    static_cast<unsigned long long>(g.stats.shiftPairs),
                    double(g.stats.shiftFailures) / double(g.stats.shiftPairs));
    }
}

}  // namespace
}  // namespace gdpt
