// emitter supersampling (emitter_supersampling.comp, render/passes/emitter_supersampling_pass.h) against the
// closed form: a black-backed emissive square parallel to the image plane projects to an axis-aligned
// rectangle, so each pixel's expected value is L × (the fraction of the pixel square it covers), and with one
// ray per camera sample the estimate's variance is c(1 − c)L²/N (less with the stratified samples of
// sampler.glsl). Checked for PT and for G-PT's very-direct layer, with the pass on (unbiased, far below that
// variance and below the path kernels' own estimate) and off (the kernels' own estimate, unbiased), plus the
// scenes where the pass must switch itself off.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "gpu_fixture.h"
#include "integrator/gpt_sampler.h"
#include "integrator/pt_sampler.h"
#include "integrator/render_options.h"
#include "render/device_scene/scene_gpu.h"
#include "render/passes/pt_pass.h"
#include "scene_builders.h"
#include "vk/commands.h"

namespace gdpt {
namespace {

// 96², the square about 22 pixels wide: few enough rim pixels that the pass's ray budget (a
// quarter ray per pixel and camera sample) leaves it 8 rays per sample there.
constexpr int kSize = 96;
constexpr float kCameraHeight = 3.0f;
constexpr float kFovDeg = 40.0f;
constexpr float kHalfSize = 0.25f;  // the square [-h, h]^2 at z = 0
const glm::vec3 kRadiance(3.0f, 2.0f, 1.0f);

// A black, emissive square seen head-on (albedo 0: nothing but the very-direct term).
Scene squareScene() {
    Scene s;
    s.materials.push_back(test::lambert(glm::vec3(0.0f), kRadiance));
    test::addQuadZ(s, 0.0f, kHalfSize, 0);
    s.cameras.push_back(test::lookDown(kCameraHeight, kFovDeg));
    return s;
}

// Pixel coordinate of the square's edge at world coordinate ±h (the camera maps the image
// plane linearly: x_pixel = (X / (H tan(fov/2)) + 1) / 2 · size; y is symmetric).
double edgePixel(double world) {
    const double t = std::tan(0.5 * glm::radians(double(kFovDeg)));
    return (world / (kCameraHeight * t) + 1.0) * 0.5 * kSize;
}

// Fraction of pixel (x, y) inside the projected square.
double coverage(int x, int y) {
    const double a = edgePixel(-kHalfSize), b = edgePixel(kHalfSize);
    const auto overlap = [&](int i) { return std::max(0.0, std::min(b, i + 1.0) - std::max(a, double(i))); };
    return overlap(x) * overlap(y);
}

struct RimErrors {
    double sumDiff = 0.0;     // Σ (estimate − expected) over rim pixels, channel 0
    double sumSquared = 0.0;  // Σ (estimate − expected)²
    double sumIidVar = 0.0;   // Σ c(1 − c)L²/N: the variance with one ray per camera sample
    int rimPixels = 0;
};

// Checks the pixels that the square covers fully or not at all (exact in every sample) and
// sums the errors of the rim pixels (0 < c < 1).
RimErrors rimErrors(const Image& image, std::uint32_t spp, const std::string& what) {
    RimErrors r;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            const double c = coverage(x, y);
            if (c == 0.0 || c == 1.0) {
                for (int ch = 0; ch < 3; ++ch)
                    EXPECT_EQ(image.at(x, y, ch), float(c * kRadiance[ch]))
                        << what << " pixel " << x << "," << y;
                continue;
            }
            const double d = image.at(x, y, 0) - c * kRadiance[0];
            r.sumDiff += d;
            r.sumSquared += d * d;
            r.sumIidVar += c * (1.0 - c) * kRadiance[0] * kRadiance[0] / spp;
            ++r.rimPixels;
        }
    return r;
}

class VisibleEmission : public test::GpuTest {
protected:
    static RenderOptions options(std::uint32_t spp, std::uint32_t supersampling, std::uint32_t seed) {
        RenderOptions o = renderOptions(kSize, kSize, spp, seed);
        o.emitterSupersampling = supersampling;
        return o;
    }
    // The very-direct image of `method`: PT's image, or G-PT's direct layer.
    static Image render(const std::string& method, const Scene& s, const RenderOptions& o,
                        RenderStats* stats) {
        if (method == "pt") {
            RenderResult r = renderPt(ctx(), s, o);
            *stats = r.stats;
            return r.image;
        }
        RenderResultGpt g = renderGpt(ctx(), s, o);
        *stats = g.stats;
        return g.direct;
    }
};

// Unbiased within e·c(1−c)L²/(N k): every scrambled point is uniform, and Owen 1997's bound
// on the variance of scrambled (0,m,2)-nets in base 2 (a factor of 2 over independent
// points; e covers it) bounds each estimate's variance; 4 standard deviations of the sum
// bound the sum of the rim's differences.
void expectUnbiased(const RimErrors& r, std::uint32_t raysPerSample, const std::string& what) {
    const double bound = std::sqrt(std::exp(1.0) * r.sumIidVar / raysPerSample);
    EXPECT_LE(std::abs(r.sumDiff), 4.0 * bound) << what;
}

TEST_F(VisibleEmission, RimPixelsAreUnbiasedAndFarBelowTheKernelsOwnEstimate) {
    const Scene s = squareScene();
    const std::uint32_t spp = 4, factor = 16;
    for (const std::string method : {"pt", "gpt"}) {
        RenderStats stats;
        const Image on = render(method, s, options(spp, factor, 11), &stats);
        EXPECT_EQ(stats.emitterSupersampling, factor) << method;
        const RimErrors r = rimErrors(on, spp, method);
        ASSERT_GT(r.rimPixels, 4 * 20) << "the square's rim crosses four rows of 20 pixels";
        // Every rim pixel is refined (the pass may refine a ring of neighbours as well), with
        // k = min(factor, budget / refined) rays per camera sample.
        EXPECT_GE(stats.emitterSupersampledPixels, std::uint32_t(r.rimPixels)) << method;
        EXPECT_LE(stats.emitterSupersampledPixels, std::uint32_t(3 * r.rimPixels)) << method;
        const std::uint32_t k = stats.emitterRaysPerSample;
        EXPECT_EQ(k, std::min(factor, std::uint32_t(kSize * kSize / 4) / stats.emitterSupersampledPixels))
            << method;
        ASSERT_GE(k, 8u) << method;
        expectUnbiased(r, k, method + " on");
        // Far below one ray per camera sample: the squared errors sum to under a quarter of
        // that estimator's variance (expected at most e/k of it; stratified edges do better
        // still), and to under a quarter of what the path kernels' own stratified camera
        // samples get (4 per pixel against 4k).
        EXPECT_LT(r.sumSquared, 0.25 * r.sumIidVar) << method;
        const RimErrors off = rimErrors(render(method, s, options(spp, 0, 11), &stats), spp, method + " off");
        EXPECT_LT(r.sumSquared, 0.25 * off.sumSquared) << method;
    }
}

// The refine phase runs one invocation per pixel of the count phase's list, which its atomic
// counter fills in whatever order the device's threads reach it: every refined pixel takes
// each camera sample of every batch exactly once (a pixel listed twice would count 2 × 5, one
// left out 0), no other pixel any, and the statistics are the same bits in a second pass over
// the same batches, whatever its list's order.
TEST_F(VisibleEmission, EveryRefinedPixelTakesEachCameraSampleOnce) {
    const Scene s = squareScene();
    SceneGpuOptions so;
    so.width = so.height = kSize;
    const SceneGpu scene(ctx(), s, so);
    const auto statistics = [&](gpu::VisibleCounter* counter) {
        PtPass pass(ctx(), scene, WorkgroupSize{}, 16);
        vk::CommandStream stream(ctx(), "emitter supersampling");
        pass.record(stream.begin(), 0, 2, 7, nullptr);
        stream.submitAndWait();
        pass.record(stream.begin(), 2, 3, 7, nullptr);
        stream.submitAndWait();
        *counter = pass.emitterSupersampling().report();
        return pass.emitterSupersampling().downloadStats();
    };
    gpu::VisibleCounter counter{}, again{};
    const std::vector<gpu::PixelStats> first = statistics(&counter), second = statistics(&again);
    ASSERT_EQ(first.size(), std::size_t{kSize} * kSize);
    std::uint32_t sampled = 0;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            const gpu::PixelStats& p = first[std::size_t(y) * kSize + x];
            const double c = coverage(x, y);
            if (p.count == 0 && (c == 0.0 || c == 1.0)) continue;  // not refined, and not on the rim
            ++sampled;
            EXPECT_EQ(p.count, 5u) << "pixel " << x << "," << y << ", coverage " << c;
        }
    EXPECT_EQ(sampled, counter.refinedPixels);
    EXPECT_EQ(again.refinedPixels, counter.refinedPixels);
    EXPECT_EQ(0, std::memcmp(first.data(), second.data(), first.size() * sizeof(gpu::PixelStats)));
}

// More refined pixels than 65,535 workgroups hold (the least maxComputeWorkGroupCount of a
// device): with one-invocation workgroups, a 256² image whose every pixel is refined needs
// 65,536 groups, which the indirect dispatch lays out in two rows. An emissive bar over the
// left half of every pixel column makes each pixel's probe mixed.
TEST_F(VisibleEmission, AListLongerThanOneRowOfWorkgroupsIsRefinedWhole) {
    constexpr int kBars = 256;
    Scene s;
    s.materials.push_back(test::lambert(glm::vec3(0.0f), kRadiance));
    const float half =
        kCameraHeight * std::tan(0.5f * glm::radians(kFovDeg));  // the view's half-width at z = 0
    const auto worldX = [&](double pixel) { return float((2.0 * pixel / kBars - 1.0) * half); };
    for (int i = 0; i < kBars; ++i) {
        const float x0 = worldX(i), x1 = worldX(i + 0.5), y = 1.1f * half;
        addQuad(s, {x0, -y, 0.0f}, {x1, -y, 0.0f}, {x1, y, 0.0f}, {x0, y, 0.0f}, 0);
    }
    s.cameras.push_back(test::lookDown(kCameraHeight, kFovDeg));
    SceneGpuOptions so;
    so.width = so.height = kBars;
    const SceneGpu scene(ctx(), s, so);
    PtPass pass(ctx(), scene, WorkgroupSize{1, 1}, 16);
    vk::CommandStream stream(ctx(), "emitter supersampling");
    pass.record(stream.begin(), 0, 2, 3, nullptr);
    stream.submitAndWait();
    EXPECT_EQ(pass.emitterSupersampling().report().refinedPixels, std::uint32_t(kBars * kBars));
    const std::vector<gpu::PixelStats> stats = pass.emitterSupersampling().downloadStats();
    std::size_t twice = 0;
    for (const gpu::PixelStats& p : stats) twice += p.count == 2u ? 1u : 0u;
    EXPECT_EQ(twice, stats.size()) << "pixels with both camera samples";
}

TEST_F(VisibleEmission, OffLeavesThePathKernelsOwnUnbiasedEstimate) {
    const Scene s = squareScene();
    const std::uint32_t spp = 16;
    for (const std::string method : {"pt", "gpt"}) {
        RenderStats stats;
        const Image off = render(method, s, options(spp, 0, 12), &stats);
        EXPECT_EQ(stats.emitterSupersampling, 0u) << method;
        EXPECT_EQ(stats.emitterSupersampledPixels, 0u) << method;
        const RimErrors r = rimErrors(off, spp, method);
        // One stratified ray per camera sample (sampler.glsl): unbiased within the same
        // bound, and no noisier than independent samples would be (4x is far outside the
        // spread of a sum of about 90 terms).
        expectUnbiased(r, 1, method + " off");
        EXPECT_LT(r.sumSquared, 4.0 * r.sumIidVar) << method;
    }
}

TEST_F(VisibleEmission, SwitchesItselfOffWhenNothingVisibleEmits) {
    // A Lambertian plane lit only by a point light: no emissive triangle, no environment.
    Scene s;
    s.materials.push_back(test::lambert(glm::vec3(0.5f)));
    test::addQuadZ(s, 0.0f, 50.0f, 0);
    gpu::PunctualLight l{};
    l.position = glm::vec3(0.0f, 0.0f, 1.0f);
    l.intensity = glm::vec3(1.0f);
    l.type = gpu::kPunctualPoint;
    l.cosInner = l.cosOuter = -1.0f;
    s.punctualLights.push_back(l);
    s.cameras.push_back(test::lookDown(kCameraHeight, kFovDeg));
    // PT only: the choice is EmitterSupersamplingPass's, the same object in both methods (and each new
    // G-PT variant costs lavapipe seconds to compile).
    EXPECT_EQ(renderPt(ctx(), s, options(2, 16, 13)).stats.emitterSupersampling, 0u);
    // With an environment the camera can see emission again.
    RenderOptions o = options(2, 16, 13);
    o.scene.envRadiance = glm::vec3(0.1f);
    EXPECT_EQ(renderPt(ctx(), s, o).stats.emitterSupersampling, 16u);
}

TEST_F(VisibleEmission, EnvironmentSilhouetteIsSupersampledToo) {
    // The square is black and not emissive now, in front of a constant sky: its rim pixels
    // see the sky with probability 1 − c.
    Scene s;
    s.materials.push_back(test::lambert(glm::vec3(0.0f)));
    test::addQuadZ(s, 0.0f, kHalfSize, 0);
    s.cameras.push_back(test::lookDown(kCameraHeight, kFovDeg));
    const glm::vec3 sky(2.0f);
    RenderOptions o = options(4, 16, 14);
    o.scene.envRadiance = sky;
    const RenderResult r = renderPt(ctx(), s, o);
    double sumSquared = 0.0, sumIidVar = 0.0, sumDiff = 0.0;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            const double c = coverage(x, y);
            const double expected = (1.0 - c) * sky.x;
            if (c == 0.0 || c == 1.0) {
                EXPECT_EQ(r.image.at(x, y, 0), float(expected)) << "pixel " << x << "," << y;
                continue;
            }
            const double d = r.image.at(x, y, 0) - expected;
            sumDiff += d;
            sumSquared += d * d;
            sumIidVar += c * (1.0 - c) * sky.x * sky.x / 4.0;
        }
    EXPECT_LE(std::abs(sumDiff), 4.0 * std::sqrt(std::exp(1.0) * sumIidVar / r.stats.emitterRaysPerSample));
    EXPECT_LT(sumSquared, 0.25 * sumIidVar);
}

}  // namespace
}  // namespace gdpt
