// Warps of sampling.glsl: inversion round trips, pdf normalisation, pdf = 1/|det J| by finite
// differences (Lajolla materials tests), chi-square fits, orthonormal basis, power heuristic.
#include <gtest/gtest.h>

#include <cmath>

#include "gdpt_shared.h"
#include "lib/sampling.glsl"
#include "sampling_test_util.h"
#include "stats.h"

namespace {

using namespace gdpt::gpu;
using gdpt::test::DirHistogram;
using gdpt::test::kPiD;
using gdpt::test::Uniform;

constexpr int kRoundTrips = 100000;

TEST(Warps, ConcentricDiskRoundTrip) {
    Uniform rnd(1u);
    for (int i = 0; i < kRoundTrips; ++i) {
        vec2 u = rnd.next2();
        vec2 p = sampleConcentricDisk(u);
        ASSERT_LE(p.x * p.x + p.y * p.y, 1.0f + 1e-6f);
        vec2 v = invertConcentricDisk(p);
        // Forward map has Lipschitz constant ~pi/2, float atan/cos/sin a few ulps.
        ASSERT_NEAR(v.x, u.x, 2e-6f) << "u=(" << u.x << "," << u.y << ")";
        ASSERT_NEAR(v.y, u.y, 2e-6f) << "u=(" << u.x << "," << u.y << ")";
    }
}

TEST(Warps, CosineHemisphereRoundTrip) {
    Uniform rnd(2u);
    for (int i = 0; i < kRoundTrips; ++i) {
        vec2 u = rnd.next2();
        vec3 w = sampleCosineHemisphere(u);
        ASSERT_GE(w.z, 0.0f);
        ASSERT_NEAR(length(w), 1.0f, 1e-6f);
        vec2 v = invertCosineHemisphere(w);
        ASSERT_NEAR(v.x, u.x, 2e-6f);
        ASSERT_NEAR(v.y, u.y, 2e-6f);
    }
}

TEST(Warps, UniformSphereRoundTrip) {
    Uniform rnd(3u);
    for (int i = 0; i < kRoundTrips; ++i) {
        vec2 u = rnd.next2();
        vec3 w = sampleUniformSphere(u);
        ASSERT_NEAR(length(w), 1.0f, 1e-6f);
        vec2 v = invertUniformSphere(w);
        ASSERT_NEAR(v.x, u.x, 2e-6f);
        // phi is ill-defined at the poles (|z| -> 1); elsewhere atan2 is accurate.
        if (std::fabs(w.z) < 0.999f) {
            ASSERT_NEAR(v.y, u.y, 2e-6f);
        }
    }
}

TEST(Warps, UniformTriangleRoundTrip) {
    Uniform rnd(4u);
    for (int i = 0; i < kRoundTrips; ++i) {
        vec2 u = rnd.next2();
        vec3 b = sampleUniformTriangle(u);
        ASSERT_GE(minComponent(b), 0.0f);
        ASSERT_NEAR(b.x + b.y + b.z, 1.0f, 1e-6f);
        vec2 v = invertUniformTriangle(b);
        ASSERT_NEAR(v.x, u.x, 2e-6f);
        ASSERT_NEAR(v.y, u.y, 2e-6f);
    }
}

// Midpoint rule on a (theta, phi) grid: error O(h^2) ~ 1e-6 at 1000 x 100 cells for these
// smooth integrands; tolerance 1e-4.
template <class Pdf>
double integrateSphere(Pdf pdf, double thetaMax) {
    const int nt = 1000;
    const int np = 100;
    double sum = 0.0;
    for (int i = 0; i < nt; ++i) {
        double theta = (i + 0.5) * thetaMax / nt;
        for (int j = 0; j < np; ++j) {
            double phi = (j + 0.5) * 2.0 * kPiD / np;
            vec3 w(static_cast<float>(std::sin(theta) * std::cos(phi)),
                   static_cast<float>(std::sin(theta) * std::sin(phi)), static_cast<float>(std::cos(theta)));
            sum += static_cast<double>(pdf(w)) * std::sin(theta);
        }
    }
    return sum * (thetaMax / nt) * (2.0 * kPiD / np);
}

TEST(Warps, PdfsIntegrateToOne) {
    EXPECT_NEAR(integrateSphere([](vec3 w) { return cosineHemispherePdf(w.z); }, kPiD), 1.0, 1e-4);
    EXPECT_NEAR(integrateSphere([](vec3) { return uniformSpherePdf(); }, kPiD), 1.0, 1e-4);
    EXPECT_NEAR(integrateSphere([](vec3) { return uniformHemispherePdf(); }, kPiD / 2), 1.0, 1e-4);
}

// pdf = 1/|det J|: central differences (step 1e-3 in double-evaluated float maps give a
// relative error ~1e-3) against the documented densities.
TEST(Warps, PdfMatchesJacobian) {
    Uniform rnd(5u);
    const float h = 1e-3f;
    for (int i = 0; i < 2000; ++i) {
        vec2 u = vec2(0.01f) + 0.98f * rnd.next2();
        // Disk: area map, |det J| = pi (pdf 1/pi on the unit disk). The map has kinks along
        // the diagonals |ox| = |oy|; skip points whose stencil straddles them.
        float ox = 2.0f * u.x - 1.0f;
        float oy = 2.0f * u.y - 1.0f;
        if (std::fabs(std::fabs(ox) - std::fabs(oy)) > 4.0f * h) {
            vec2 dx = (sampleConcentricDisk(u + vec2(h, 0.0f)) - sampleConcentricDisk(u - vec2(h, 0.0f))) /
                      (2.0f * h);
            vec2 dy = (sampleConcentricDisk(u + vec2(0.0f, h)) - sampleConcentricDisk(u - vec2(0.0f, h))) /
                      (2.0f * h);
            EXPECT_NEAR(std::fabs(dx.x * dy.y - dx.y * dy.x), kPiD, 1e-2 * kPiD);
        }
        // Sphere: |dw/du0 x dw/du1| = 1/pdf = 4 pi.
        vec3 sx =
            (sampleUniformSphere(u + vec2(h, 0.0f)) - sampleUniformSphere(u - vec2(h, 0.0f))) / (2.0f * h);
        vec3 sy =
            (sampleUniformSphere(u + vec2(0.0f, h)) - sampleUniformSphere(u - vec2(0.0f, h))) / (2.0f * h);
        EXPECT_NEAR(length(cross(sx, sy)) * uniformSpherePdf(), 1.0f, 1e-2f);
        // Triangle: barycentric (b1, b2) area map, |det J| = 1/2 (area of the unit simplex).
        vec3 tx = (sampleUniformTriangle(u + vec2(h, 0.0f)) - sampleUniformTriangle(u - vec2(h, 0.0f))) /
                  (2.0f * h);
        vec3 ty = (sampleUniformTriangle(u + vec2(0.0f, h)) - sampleUniformTriangle(u - vec2(0.0f, h))) /
                  (2.0f * h);
        EXPECT_NEAR(std::fabs(tx.y * ty.z - tx.z * ty.y), 0.5f, 1e-2f);
    }
}

template <class Sampler, class Pdf>
gdpt::stats::Chi2Result warpChi2(Sampler sample, Pdf pdf, double thetaMax, std::uint32_t seed) {
    const int n = 400000;
    DirHistogram hist(20, 40, thetaMax);
    Uniform rnd(seed);
    int outside = 0;
    for (int i = 0; i < n; ++i) {
        outside += hist.add(sample(rnd.next2())) ? 0 : 1;
    }
    EXPECT_EQ(outside, 0);
    return gdpt::stats::chi2Test(hist.counts, hist.expected(pdf, n));
}

TEST(Warps, CosineHemisphereChi2) {
    auto r = warpChi2([](vec2 u) { return sampleCosineHemisphere(u); },
                      [](vec3 w) { return cosineHemispherePdf(w.z); }, kPiD / 2, 6u);
    EXPECT_TRUE(r.error.empty()) << r.error;
    EXPECT_GT(r.pValue, gdpt::test::chi2Alpha()) << "chi2=" << r.statistic << " dof=" << r.dof;
}

TEST(Warps, UniformSphereChi2) {
    auto r = warpChi2([](vec2 u) { return sampleUniformSphere(u); }, [](vec3) { return uniformSpherePdf(); },
                      kPiD, 7u);
    EXPECT_TRUE(r.error.empty()) << r.error;
    EXPECT_GT(r.pValue, gdpt::test::chi2Alpha()) << "chi2=" << r.statistic << " dof=" << r.dof;
}

// The test must be able to fail: cosine-distributed samples against the uniform pdf.
TEST(Warps, Chi2RejectsWrongPdf) {
    auto r = warpChi2([](vec2 u) { return sampleCosineHemisphere(u); },
                      [](vec3) { return uniformHemispherePdf(); }, kPiD / 2, 8u);
    EXPECT_LT(r.pValue, 1e-10);
}

TEST(Basis, OrthonormalRightHanded) {
    Uniform rnd(9u);
    vec3 special[4] = {vec3(0, 0, 1), vec3(0, 0, -1), normalize(vec3(1e-4f, 0, -1)), vec3(1, 0, 0)};
    for (int i = 0; i < 20000; ++i) {
        vec3 n = i < 4 ? special[i] : sampleUniformSphere(rnd.next2());
        vec3 t;
        vec3 b;
        makeBasis(n, t, b);
        ASSERT_NEAR(length(t), 1.0f, 1e-5f);
        ASSERT_NEAR(length(b), 1.0f, 1e-5f);
        ASSERT_NEAR(dot(t, b), 0.0f, 1e-5f);
        ASSERT_NEAR(dot(t, n), 0.0f, 1e-5f);
        ASSERT_NEAR(dot(b, n), 0.0f, 1e-5f);
        ASSERT_NEAR(length(cross(t, b) - n), 0.0f, 1e-5f) << "not right-handed";
        vec3 v = sampleUniformSphere(rnd.next2());
        ASSERT_NEAR(length(toWorld(toLocal(v, t, b, n), t, b, n) - v), 0.0f, 1e-5f);
        ASSERT_NEAR(toLocal(n, t, b, n).z, 1.0f, 1e-5f);
    }
}

TEST(Mis, PowerHeuristic) {
    // Agrees with the textbook form where that form is safe, and weights are complementary.
    for (float f : {0.1f, 1.0f, 3.0f, 100.0f}) {
        for (float g : {0.2f, 1.0f, 7.0f}) {
            float ref = (f * f) / (f * f + 4.0f * g * g);
            EXPECT_NEAR(powerHeuristic(1.0f, f, 2.0f, g), ref, 1e-6f);
            EXPECT_NEAR(powerHeuristic(1.0f, f, 2.0f, g) + powerHeuristic(2.0f, g, 1.0f, f), 1.0f, 1e-6f);
            EXPECT_NEAR(powerHeuristicRatio(2.0f * g / f), ref, 1e-6f);
        }
    }
    // Where squaring overflows (1e30^2) or underflows (1e-30^2) the naive form gives NaN.
    EXPECT_FLOAT_EQ(powerHeuristic(1.0f, 1e30f, 1.0f, 1e30f), 0.5f);
    EXPECT_FLOAT_EQ(powerHeuristic(1.0f, 1e-30f, 1.0f, 1e-30f), 0.5f);
    EXPECT_NEAR(powerHeuristic(1.0f, 3e30f, 1.0f, 1e30f), 0.9f, 1e-6f);
    EXPECT_FLOAT_EQ(powerHeuristic(1.0f, 0.0f, 1.0f, 1.0f), 0.0f);
    EXPECT_FLOAT_EQ(powerHeuristic(1.0f, 1.0f, 1.0f, 0.0f), 1.0f);
    EXPECT_FLOAT_EQ(powerHeuristic(1.0f, INFINITY, 1.0f, 1.0f), 1.0f);
    EXPECT_FLOAT_EQ(powerHeuristic(1.0f, NAN, 1.0f, 1.0f), 0.0f);
    EXPECT_FLOAT_EQ(powerHeuristicRatio(INFINITY), 0.0f);
    EXPECT_FLOAT_EQ(powerHeuristicRatio(0.0f), 1.0f);
    EXPECT_FLOAT_EQ(powerHeuristicRatio(NAN), 0.0f);
}

}  // namespace
