// Light and material features against closed-form answers: a point light over a
// Lambertian plane (L = rho/pi * I cos(theta) / r^2), a spot light's cone, a constant
// environment over a Lambertian plane (L = rho * L_env exactly, every sample) and alpha
// cutouts (a masked-out occluder lets an emitter through, an opaque one does not).
#include <gtest/gtest.h>

#include <cmath>

#include "gpu_fixture.h"
#include "integrator/pt_sampler.h"
#include "scene_builders.h"

namespace gdpt {
namespace {

using test::addQuadZ;
using test::lambert;
using test::lookDown;

class RenderLights : public test::GpuTest {
protected:
    RenderResult render(const Scene& s, int size, std::uint32_t spp, glm::vec3 env = glm::vec3(0.0f),
                        std::uint32_t maxDepth = 64) {
        RenderOptions o = renderOptions(size, size, spp, 5);
        o.scene.envRadiance = env;
        o.scene.maxDepth = maxDepth;
        return renderPt(ctx(), s, o);
    }
};

// World point seen through the centre of pixel (x, y) of a downward camera at height H.
glm::vec2 planePoint(int x, int y, int size, float height, float yfov) {
    const float t = std::tan(0.5f * yfov);
    const float nx = (2.0f * (float(x) + 0.5f) / float(size) - 1.0f) * t;
    const float ny = (1.0f - 2.0f * (float(y) + 0.5f) / float(size)) * t;
    return {nx * height, ny * height};
}

TEST_F(RenderLights, PointAndSpotLightsFollowTheInverseSquareCosineLaw) {
    const float rho = 0.5f, hLight = 1.0f, camH = 3.0f, fov = 40.0f;
    const glm::vec3 intensity(4.0f, 2.0f, 1.0f);
    for (const bool spot : {false, true}) {
        Scene s;
        s.materials.push_back(lambert(glm::vec3(rho)));
        addQuadZ(s, 0.0f, 50.0f, 0);
        gpu::PunctualLight l{};
        l.position = glm::vec3(0.0f, 0.0f, hLight);
        l.intensity = intensity;
        l.type = spot ? gpu::kPunctualSpot : gpu::kPunctualPoint;
        l.direction = glm::vec3(0.0f, 0.0f, -1.0f);
        const float inner = glm::radians(20.0f), outer = glm::radians(30.0f);
        l.cosInner = spot ? std::cos(inner) : -1.0f;
        l.cosOuter = spot ? std::cos(outer) : -1.0f;
        s.punctualLights.push_back(l);
        s.cameras.push_back(lookDown(camH, fov));
        const int size = 65;
        const RenderResult r = render(s, size, 64, glm::vec3(0.0f), 1);  // direct light only
        int checked = 0;
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x) {
                const glm::vec2 p = planePoint(x, y, size, camH, glm::radians(fov));
                const float r2 = glm::dot(p, p) + hLight * hLight;
                const float cosTheta = hLight / std::sqrt(r2);
                const float angle = std::acos(cosTheta);
                // Pixels straddling the spot's smooth-falloff band are not checked.
                if (spot && angle > inner - 0.03f && angle < outer + 0.03f) continue;
                const bool lit = !spot || angle < inner;
                for (int c = 0; c < 3; ++c) {
                    const float expected = lit ? rho / 3.14159265f * intensity[c] * cosTheta / r2 : 0.0f;
                    // 1.5%: the pixel footprint (0.034 m) averages a field whose relative
                    // slope is below 1 per metre; jitter noise is ~0.1% at 64 spp.
                    EXPECT_NEAR(r.image.at(x, y, c), expected, 0.015f * expected + 1e-7f)
                        << (spot ? "spot" : "point") << " pixel " << x << "," << y;
                }
                ++checked;
            }
        EXPECT_GT(checked, size * size / 2);
    }
}

TEST_F(RenderLights, ConstantEnvironmentOverLambertianPlaneIsExact) {
    Scene s;
    s.materials.push_back(lambert(glm::vec3(0.5f, 0.25f, 0.125f)));
    addQuadZ(s, 0.0f, 1e4f, 0);
    s.cameras.push_back(lookDown(2.0f, 30.0f));
    const glm::vec3 env(1.0f, 2.0f, 4.0f);
    const RenderResult r = render(s, 16, 8, env);
    // Every sample: cosine-sampled bounce (weight = albedo) escapes to the environment.
    const glm::vec3 albedo(0.5f, 0.25f, 0.125f);
    for (int c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < r.image.pixelCount(); ++i)
            ASSERT_FLOAT_EQ(r.image.plane(c)[i], env[c] * albedo[c]);
}

TEST_F(RenderLights, AlphaCutoutLetsTheEmitterThroughOnlyBelowTheCutoff) {
    for (const float alpha : {0.3f, 0.7f}) {
        Scene s;
        s.materials.push_back(lambert(glm::vec3(0.0f), glm::vec3(2.0f, 3.0f, 4.0f)));  // emitter
        gpu::Material occluder = lambert(glm::vec3(0.0f));
        occluder.baseColor.w = alpha;
        occluder.flags |= gpu::kMatFlagAlphaMask | gpu::kMatFlagDoubleSided;
        s.materials.push_back(occluder);
        addQuadZ(s, 0.0f, 100.0f, 0);
        addQuadZ(s, 1.0f, 100.0f, 1);
        s.cameras.push_back(lookDown(2.0f, 30.0f));
        const RenderResult r = render(s, 12, 2);
        const glm::vec3 expected = alpha < 0.5f ? glm::vec3(2.0f, 3.0f, 4.0f) : glm::vec3(0.0f);
        for (int c = 0; c < 3; ++c)
            for (std::size_t i = 0; i < r.image.pixelCount(); ++i)
                ASSERT_FLOAT_EQ(r.image.plane(c)[i], expected[c]) << "alpha " << alpha;
    }
}

}  // namespace
}  // namespace gdpt
