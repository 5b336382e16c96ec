// G-PT sampling half against the path tracer: the mean gradients equal the differences of
// neighbouring PT pixel values, the primal equals the PT image, directly seen emission gives
// exactly zero gradients, no NaN samples, and renders are deterministic.
//
// Statistics. G-PT and PT renders use different seeds, so they are independent. Every
// tolerance is z standard errors, the standard error estimated from the per-pixel variances
// both renderers return (Welford M2 / (n-1) / n):
//  * dx(x,y) depends only on the samples of pixels (x,y) and (x+1,y) (gpt_resolve.comp), so
//    the dx values at even x are independent of each other, and so are the PT differences
//    I(x+1,y) − I(x,y) at even x. Region sums over those have variance = Σ varDx + Σ (v_pt(x)
//    + v_pt(x+1)). Likewise dy at even y.
//  * primal(p) depends on the samples of p and its 4 neighbours, so pixels on a lattice of
//    step 3 are independent; region sums over the lattice are tested the same way.
//  * PT's image contains the emission seen directly; G-PT keeps it in `direct`, so G-PT's
//    direct (and its variance) is added back. Its covariance with the primal / gradient of
//    the same pixel is neglected: a sample that sees an emitter first ends there (black
//    emitters), so the per-sample product is 0 and the covariance −E[d]E[g] is small.
// z is Šidák-corrected over all region × channel tests of a scene (family alpha 1e-3), and at
// least 4. Each test also checks its own power: the same statistic against a wrong
// expectation (the gradient of the mirrored sign, or the PT image of the neighbour) must be
// rejected somewhere, so a test that could not fail would fail.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

#include "gpu_fixture.h"
#include "integrator/gpt_sampler.h"
#include "integrator/pt_sampler.h"
#include "integrator/render_options.h"
#include "scene/gltf_loader.h"
#include "scene/procedural.h"
#include "scene_builders.h"
#include "stats_normal.h"

namespace gdpt {
namespace {

class GptRender : public test::GpuTest {};

// One z-test of a region sum: |sum of (estimate − expected)| <= z sqrt(sum of variances).
// Float32 rounding of the running means (~1e-6 relative, not noise) is allowed on top.
struct RegionTest {
    double diff = 0.0, var = 0.0, magnitude = 0.0;
    int count = 0;
    void add(double estimate, double expected, double variance) {
        diff += estimate - expected;
        var += variance;
        magnitude += std::abs(expected) + std::abs(estimate);
        ++count;
    }
    [[nodiscard]] double zScore() const {
        const double err = std::max(0.0, std::abs(diff) - 1e-5 * magnitude);
        return var > 0.0 ? err / std::sqrt(var) : (err == 0.0 ? 0.0 : 1e30);
    }
};

// Tests dx (axis 0) or dy (axis 1) of a G-PT render against PT finite differences over
// regions of `region` pixels. Returns the largest |z| found with the sign of the PT difference
// flipped (the power check).
double checkGradients(const RenderResultGpt& g, const RenderResult& pt, int axis, int region, double z,
                      const std::string& name) {
    const Image& grad = axis == 0 ? g.dx : g.dy;
    const Image& gvar = axis == 0 ? g.varDx : g.varDy;
    const int w = pt.image.width(), h = pt.image.height();
    double maxWrongZ = 0.0;
    for (int ry = 0; ry < h / region; ++ry)
        for (int rx = 0; rx < w / region; ++rx)
            for (int c = 0; c < 3; ++c) {
                RegionTest right, wrong;
                for (int y = ry * region; y < (ry + 1) * region; ++y)
                    for (int x = rx * region; x < (rx + 1) * region; ++x) {
                        if ((axis == 0 ? x : y) % 2 != 0) continue;  // independent terms only
                        const int x1 = axis == 0 ? x + 1 : x, y1 = axis == 0 ? y : y + 1;
                        if (x1 >= w || y1 >= h) continue;
                        const double ptDiff = pt.image.at(x1, y1, c) - pt.image.at(x, y, c);
                        // PT includes the very-direct light that G-PT keeps out of the
                        // gradients: add G-PT's direct difference back.
                        const double estimate =
                            grad.at(x, y, c) + g.direct.at(x1, y1, c) - g.direct.at(x, y, c);
                        const double v = gvar.at(x, y, c) + g.varDirect.at(x, y, c) +
                                         g.varDirect.at(x1, y1, c) + pt.varianceOfMean.at(x, y, c) +
                                         pt.varianceOfMean.at(x1, y1, c);
                        right.add(estimate, ptDiff, v);
                        wrong.add(estimate, -ptDiff, v);
                    }
                EXPECT_LE(right.zScore(), z)
                    << name << (axis == 0 ? " dx" : " dy") << " region " << rx << "," << ry << " channel "
                    << c << ": sum diff " << right.diff << " se " << std::sqrt(right.var);
                maxWrongZ = std::max(maxWrongZ, wrong.zScore());
            }
    return maxWrongZ;
}

// Tests the primal against PT on the step-3 lattice. Returns the largest |z| against the
// PT image shifted by one pixel (power check).
double checkPrimal(const RenderResultGpt& g, const RenderResult& pt, int region, double z,
                   const std::string& name) {
    const int w = pt.image.width(), h = pt.image.height();
    double maxWrongZ = 0.0;
    for (int ry = 0; ry < h / region; ++ry)
        for (int rx = 0; rx < w / region; ++rx)
            for (int c = 0; c < 3; ++c) {
                RegionTest right, wrong;
                for (int y = ry * region; y < (ry + 1) * region; ++y)
                    for (int x = rx * region; x < (rx + 1) * region; ++x) {
                        if (x % 3 != 0 || y % 3 != 0) continue;
                        // Very-direct emission is in g.direct, never in the primal.
                        const double estimate = g.primal.at(x, y, c) + g.direct.at(x, y, c);
                        const double gv = g.varPrimal.at(x, y, c) + g.varDirect.at(x, y, c);
                        right.add(estimate, pt.image.at(x, y, c), gv + pt.varianceOfMean.at(x, y, c));
                        const int xs = std::min(x + 1, w - 1);
                        wrong.add(estimate, pt.image.at(xs, y, c), gv + pt.varianceOfMean.at(xs, y, c));
                    }
                EXPECT_LE(right.zScore(), z)
                    << name << " primal region " << rx << "," << ry << " channel " << c << ": sum diff "
                    << right.diff << " se " << std::sqrt(right.var);
                maxWrongZ = std::max(maxWrongZ, wrong.zScore());
            }
    return maxWrongZ;
}

// Per-pixel z-tests of dx, dy and primal (+ direct) against PT, for errors confined to a few
// pixels (a highlight in a mirror) that region sums dilute. Šidák over all pixel tests of
// the image (the tests are not all independent; Šidák's bound stays conservative for the
// positive dependence here).
void checkPixels(const RenderResultGpt& g, const RenderResult& pt, const std::string& name) {
    const int w = pt.image.width(), h = pt.image.height();
    const double z = std::max(4.0, test::twoSidedZ(test::sidakAlpha(1e-3, 3 * 3 * w * h)));
    int failures = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) {
                // Float32 rounding of the running means (~1e-6 relative) is not noise: it is
                // subtracted before the z-score (noise-free pixels that see only the
                // constant environment differ by an ulp).
                auto test = [&](double estimate, double expected, double variance, const char* what) {
                    const double rounding = 1e-5 * (std::abs(pt.image.at(x, y, c)) + std::abs(expected));
                    const double err = std::max(0.0, std::abs(estimate - expected) - rounding);
                    const double zs = variance > 0.0 ? err / std::sqrt(variance) : (err == 0.0 ? 0.0 : 1e30);
                    if (zs > z && failures++ < 10)
                        ADD_FAILURE() << name << " " << what << " pixel " << x << "," << y << " channel " << c
                                      << ": G-PT " << estimate << " PT " << expected << " z " << zs;
                };
                test(g.primal.at(x, y, c) + g.direct.at(x, y, c), pt.image.at(x, y, c),
                     g.varPrimal.at(x, y, c) + g.varDirect.at(x, y, c) + pt.varianceOfMean.at(x, y, c),
                     "primal");
                if (x + 1 < w)
                    test(g.dx.at(x, y, c) + g.direct.at(x + 1, y, c) - g.direct.at(x, y, c),
                         pt.image.at(x + 1, y, c) - pt.image.at(x, y, c),
                         g.varDx.at(x, y, c) + g.varDirect.at(x, y, c) + g.varDirect.at(x + 1, y, c) +
                             pt.varianceOfMean.at(x, y, c) + pt.varianceOfMean.at(x + 1, y, c),
                         "dx");
                if (y + 1 < h)
                    test(g.dy.at(x, y, c) + g.direct.at(x, y + 1, c) - g.direct.at(x, y, c),
                         pt.image.at(x, y + 1, c) - pt.image.at(x, y, c),
                         g.varDy.at(x, y, c) + g.varDirect.at(x, y, c) + g.varDirect.at(x, y + 1, c) +
                             pt.varianceOfMean.at(x, y, c) + pt.varianceOfMean.at(x, y + 1, c),
                         "dy");
            }
    EXPECT_EQ(failures, 0) << name << ": pixels outside " << z << " standard errors";
}

void checkAgainstPt(const RenderResultGpt& g, const RenderResult& pt, int region, const std::string& name,
                    bool perPixel = true) {
    ASSERT_EQ(g.stats.nanSamples, 0u) << name;
    ASSERT_EQ(pt.stats.nanSamples, 0u) << name;
    const int w = pt.image.width(), h = pt.image.height();
    const int tests = 3 * (w / region) * (h / region) * 3;  // dx, dy, primal × regions × RGB
    const double z = std::max(4.0, test::twoSidedZ(test::sidakAlpha(1e-3, tests)));
    const double wrongDx = checkGradients(g, pt, 0, region, z, name);
    const double wrongDy = checkGradients(g, pt, 1, region, z, name);
    const double wrongPrimal = checkPrimal(g, pt, region, z, name);
    if (perPixel) checkPixels(g, pt, name);
    EXPECT_GT(std::max({wrongDx, wrongDy, wrongPrimal}), z) << name << ": the test has no power here";
    // Last column / row carry no gradient.
    for (int c = 0; c < 3; ++c) {
        for (int y = 0; y < h; ++y) EXPECT_EQ(g.dx.at(w - 1, y, c), 0.0f);
        for (int x = 0; x < w; ++x) EXPECT_EQ(g.dy.at(x, h - 1, c), 0.0f);
    }
}

// Diffuse Cornell box: reconnection shifts only, occlusion edges at the boxes and walls.
TEST_F(GptRender, DiffuseCornellGradientsAndPrimalMatchPathTracer) {
    const Scene scene = makeCornellBox();
    // Extra samples in edge pixels (edge_pass.h) are part of what is checked: the factor the
    // rule gives a 256² image of this scene (at 24² the edges are a third of the pixels).
    GptSamplingOptions edges;
    edges.edgeSamples = kAutoEdgeSamplesMax;
    const RenderResultGpt g = renderGpt(ctx(), scene, renderOptions(24, 24, 256, 101), edges);
    const RenderResult pt = renderPt(ctx(), scene, renderOptions(24, 24, 512, 202));
    EXPECT_EQ(g.stats.edgeSamples, kAutoEdgeSamplesMax);
    EXPECT_GT(g.stats.edgePixels, 0u);
    checkAgainstPt(g, pt, 6, "cornell");
}

// Glossy Cornell box: GGX 0.3 metal box (rough at the default threshold: reconnection) and a
// mirror sphere (Dirac: half-vector copies, specular chains, invertibility checks).
TEST_F(GptRender, GlossyCornellWithMirrorGradientsAndPrimalMatchPathTracer) {
    const Scene scene = loadGltf(std::string(GDPT_SOURCE_DIR) + "/scenes/glossy_cornell.gltf");
    const RenderResultGpt g = renderGpt(ctx(), scene, renderOptions(24, 24, 256, 103));
    const RenderResult pt = renderPt(ctx(), scene, renderOptions(24, 24, 512, 204));
    checkAgainstPt(g, pt, 6, "glossy cornell");
}

// The open scene: boxes on a floor under an emissive sky dome (320 large, distant emitter
// triangles) and a small lamp that light selection by power rarely picks.
TEST_F(GptRender, OpenSceneGradientsAndPrimalMatchPathTracer) {
    const Scene scene = loadGltf(std::string(GDPT_SOURCE_DIR) + "/scenes/open_scene.gltf");
    const RenderResultGpt g = renderGpt(ctx(), scene, renderOptions(24, 24, 256, 111));
    const RenderResult pt = renderPt(ctx(), scene, renderOptions(24, 24, 1024, 212));
    checkAgainstPt(g, pt, 6, "open scene", false);
}

// Same scene with a threshold above the metal's roughness: the GGX vertices become glossy
// and are shifted by half-vector copies of a smooth lobe (Jacobian |wo'·h| / |wo·h|).
TEST_F(GptRender, GlossyLobeHalfVectorShiftMatchesPathTracer) {
    const Scene scene = loadGltf(std::string(GDPT_SOURCE_DIR) + "/scenes/glossy_cornell.gltf");
    RenderOptions o = renderOptions(24, 24, 256, 105);
    o.scene.shiftThreshold = 0.5f;
    const RenderResultGpt g = renderGpt(ctx(), scene, o);
    const RenderResult pt = renderPt(ctx(), scene, renderOptions(24, 24, 512, 206));
    // Region sums only: half-vector copies through a GGX-0.3 lobe give heavy-tailed offset
    // contributions (rare large J·p'/p ratios), so single-pixel variance estimates at 256 spp
    // are unreliable there (measured: a pixel's standard error barely shrinks from 256 to
    // 2048 spp, in PT as well); region sums average the tails.
    checkAgainstPt(g, pt, 6, "glossy cornell, threshold 0.5", false);
}

// White surfaces with a mirror coat over the diffuse base (Dirac + Lambertian mixture):
// NEE through the diffuse lobe, half-vector copies through the Dirac one, specular chains
// between coated walls, and the pair's light strategy switched off where a vertex is glossy.
TEST_F(GptRender, MirrorCoatedDiffuseMatchesPathTracer) {
    Scene scene = makeCornellBox();
    gpu::Material& white = scene.materials[0];
    white.specular = 1.0f;
    white.roughness = 0.0f;
    white.ior = 1.5f;
    white.specularColor = glm::vec3(1.0f);
    const RenderResultGpt g = renderGpt(ctx(), scene, renderOptions(24, 24, 256, 109));
    const RenderResult pt = renderPt(ctx(), scene, renderOptions(24, 24, 512, 210));
    // Region sums only (heavy-tailed specular chains; see the threshold-0.5 test). They do
    // catch the double-counted NEE of the smooth-components light rule: region z of 6..9.
    checkAgainstPt(g, pt, 6, "mirror-coated cornell", false);
}

// Environment light (through the open front of the box; seen in the mirror sphere) and a
// point light next to the area light: the environment reconnection (J = 1, visibility from
// the offset vertex), environment/surface mismatch failures, and NEE to a punctual light
// (same light point, J = 1, no BSDF strategy).
TEST_F(GptRender, EnvironmentAndPointLightMatchPathTracer) {
    Scene scene = test::glossyCornellWithPointLight();
    RenderOptions o = renderOptions(24, 24, 256, 107);
    o.scene.envRadiance = glm::vec3(0.4f, 0.5f, 0.6f);
    const RenderResultGpt g = renderGpt(ctx(), scene, o);
    o.seed = 208;
    o.spp = 512;
    const RenderResult pt = renderPt(ctx(), scene, o);
    checkAgainstPt(g, pt, 6, "glossy cornell + environment + point light");
}

// An emitter filling the view: everything is very-direct light, so primal and gradients are
// exactly zero and direct is exactly the radiance.
TEST_F(GptRender, DirectlySeenEmitterHasExactlyZeroGradients) {
    const glm::vec3 le(3.0f, 2.0f, 0.5f);
    const RenderResultGpt g = renderGpt(ctx(), makeEmissiveQuad(le), renderOptions(16, 12, 8, 1));
    EXPECT_EQ(g.stats.nanSamples, 0u);
    for (int c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < g.primal.pixelCount(); ++i) {
            ASSERT_EQ(g.dx.plane(c)[i], 0.0f) << "pixel " << i;
            ASSERT_EQ(g.dy.plane(c)[i], 0.0f) << "pixel " << i;
            ASSERT_EQ(g.primal.plane(c)[i], 0.0f) << "pixel " << i;
            ASSERT_EQ(g.direct.plane(c)[i], le[c]) << "pixel " << i;
        }
}

// The split bounce loop (gpt.comp's gpt_split build: bounces after every offset reconnected
// run without the code for offsets with vertices of their own) is a schedule, not an
// estimator: both builds give the same bits, also where offsets keep their own vertices over
// several bounces (half-vector chains through glossy lobes and mirror coats), with the
// environment and a point light, and where they reconnect (the diffuse walls). Two scenes,
// because every render compiles its own pipeline (seconds each on a cold shader cache).
TEST_F(GptRender, SplitBounceLoopGivesTheSameBitsAsTheSingleLoop) {
    Scene glossy = test::glossyCornellWithPointLight();
    Scene coated = makeCornellBox();
    coated.materials[0].specular = 1.0f;
    coated.materials[0].roughness = 0.0f;
    coated.materials[0].ior = 1.5f;
    coated.materials[0].specularColor = glm::vec3(1.0f);
    struct Case {
        const char* name;
        const Scene* scene;
        float threshold;
        glm::vec3 env;
    };
    const Case cases[] = {{"glossy cornell, threshold 0.5, environment, point light", &glossy, 0.5f,
                           glm::vec3(0.4f, 0.5f, 0.6f)},
                          {"mirror-coated cornell", &coated, 0.001f, glm::vec3(0.0f)}};
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        RenderOptions o = renderOptions(20, 16, 6, 11);
        o.scene.shiftThreshold = c.threshold;
        o.scene.envRadiance = c.env;
        GptSamplingOptions split;
        split.splitBounce = GptPassOptions::SplitBounce::On;
        GptSamplingOptions single;
        single.splitBounce = GptPassOptions::SplitBounce::Off;
        const Scene& scene = *c.scene;
        const RenderResultGpt a = renderGpt(ctx(), scene, o, split);
        const RenderResultGpt b = renderGpt(ctx(), scene, o, single);
        EXPECT_TRUE(a.stats.gptSplitBounce);
        EXPECT_FALSE(b.stats.gptSplitBounce);
        EXPECT_EQ(a.stats.raysTraced, b.stats.raysTraced);
        EXPECT_EQ(a.stats.shiftFailures, b.stats.shiftFailures);
        const std::pair<const Image*, const Image*> images[] = {
            {&a.primal, &b.primal},       {&a.dx, &b.dx},       {&a.dy, &b.dy},      {&a.direct, &b.direct},
            {&a.varPrimal, &b.varPrimal}, {&a.varDx, &b.varDx}, {&a.varDy, &b.varDy}};
        for (const auto& [x, y] : images)
            for (int ch = 0; ch < 3; ++ch) ASSERT_EQ(x->plane(ch), y->plane(ch));
    }
}

// Same seed and spp give bit-identical images (no atomics in the accumulation).
TEST_F(GptRender, DeterministicPerSeed) {
    const Scene scene = makeCornellBox();
    const RenderResultGpt a = renderGpt(ctx(), scene, renderOptions(12, 12, 6, 3));
    const RenderResultGpt b = renderGpt(ctx(), scene, renderOptions(12, 12, 6, 3));
    for (int c = 0; c < 3; ++c) {
        ASSERT_EQ(a.primal.plane(c), b.primal.plane(c));
        ASSERT_EQ(a.dx.plane(c), b.dx.plane(c));
        ASSERT_EQ(a.dy.plane(c), b.dy.plane(c));
        ASSERT_EQ(a.varDx.plane(c), b.varDx.plane(c));
    }
}

}  // namespace
}  // namespace gdpt
