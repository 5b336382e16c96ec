// shift.glsl: Jacobians of the reconnection and half-vector shifts against finite-difference
// determinants of the shift maps, invertibility (shift ∘ reverse shift = identity,
// J·J_rev = 1), MIS weights of a pixel pair summing to one, and the vertex classification.
// Every test runs the very functions gpt.comp runs (shaders/lib/shift.glsl compiled as C++).
#include <gtest/gtest.h>

#include <cmath>
#include <glm/glm.hpp>
#include <random>

#include "gdpt_shared.h"
#include "lib/shift.glsl"

namespace {

using namespace gdpt::gpu;
using glm::dvec3;

// Fixed-seed source of test configurations.
class Source {
public:
    explicit Source(std::uint32_t seed) : gen_(seed) {}
    double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(gen_); }
    // Unit vector in the upper hemisphere with cos(theta) >= minCos.
    dvec3 hemisphere(double minCos) {
        const double z = uniform(minCos, 1.0);
        const double phi = uniform(0.0, 2.0 * 3.14159265358979323846);
        const double r = std::sqrt(1.0 - z * z);
        return dvec3(r * std::cos(phi), r * std::sin(phi), z);
    }
    dvec3 point(double extent) {
        return dvec3(uniform(-extent, extent), uniform(-extent, extent), uniform(-extent, extent));
    }

private:
    std::mt19937 gen_;
};

vec3 toF(dvec3 v) {
    return vec3(v);
}
dvec3 toD(vec3 v) {
    return dvec3(v);
}

// Two unit vectors orthogonal to unit w (tangent plane of the sphere of directions at w).
void tangents(dvec3 w, dvec3& t1, dvec3& t2) {
    const dvec3 a = std::abs(w.x) < 0.9 ? dvec3(1, 0, 0) : dvec3(0, 1, 0);
    t1 = glm::normalize(glm::cross(w, a));
    t2 = glm::cross(w, t1);
}

// Solid-angle ratio |dω'/dω| of a map of directions by central differences: the area on the
// unit sphere spanned by the images of two small orthogonal tangent displacements of ω,
// divided by the area they span at ω itself. `map` returns the image direction (unit).
template <class Map>
double finiteDifferenceJacobian(dvec3 w, double eps, Map map) {
    dvec3 t1, t2;
    tangents(w, t1, t2);
    auto at = [&](double s, double u) { return glm::normalize(w + s * t1 + u * t2); };
    const dvec3 ds = (map(at(eps, 0)) - map(at(-eps, 0))) / (2 * eps);
    const dvec3 du = (map(at(0, eps)) - map(at(0, -eps))) / (2 * eps);
    const dvec3 ds0 = (at(eps, 0) - at(-eps, 0)) / (2 * eps);
    const dvec3 du0 = (at(0, eps) - at(0, -eps)) / (2 * eps);
    return glm::length(glm::cross(ds, du)) / glm::length(glm::cross(ds0, du0));
}

// ---------------------------------------------------------------------------------------------
// Reconnection shift
// ---------------------------------------------------------------------------------------------

// The base leaves `a` in direction ω and hits the plane (y0, n) at y(ω); the offset
// reconnects from `aOffset` to that same y. J must equal |dω'/dω| of ω → normalize(y(ω) − a').
TEST(ShiftReconnection, JacobianEqualsFiniteDifferenceDeterminant) {
    Source src(11);
    int tested = 0;
    for (int i = 0; i < 200; ++i) {
        const dvec3 y0 = src.point(1.0);
        const dvec3 n = glm::normalize(src.point(1.0) + dvec3(0, 0, 1e-3));
        const dvec3 a = y0 + src.uniform(0.5, 3.0) * glm::normalize(n + 0.8 * src.point(1.0));
        const dvec3 aOffset = a + 0.3 * src.point(1.0);
        // Both vertices on the same side of the plane, away from grazing (FD is ill-posed there).
        const double cosBase = glm::dot(glm::normalize(a - y0), n);
        const double cosOffset = glm::dot(glm::normalize(aOffset - y0), n);
        if (cosBase < 0.15 || cosOffset < 0.15) continue;
        const dvec3 w0 = glm::normalize(y0 - a);
        auto shift = [&](dvec3 w) {
            const double t = glm::dot(y0 - a, n) / glm::dot(w, n);
            return glm::normalize(a + t * w - aOffset);
        };
        const double fd = finiteDifferenceJacobian(w0, 1e-5, shift);
        const float j = reconnectionJacobian(toF(a), toF(aOffset), toF(y0), toF(n));
        EXPECT_NEAR(j / fd, 1.0, 2e-4) << "config " << i << " J " << j << " fd " << fd;
        ++tested;
    }
    EXPECT_GT(tested, 50);
}

// Reconnecting back from the offset to the base is the inverse map: J·J_rev = 1.
TEST(ShiftReconnection, ReverseJacobianIsReciprocal) {
    Source src(12);
    for (int i = 0; i < 100; ++i) {
        const dvec3 y = src.point(1.0);
        const dvec3 n = glm::normalize(src.point(1.0) + dvec3(0, 0, 1e-3));
        const dvec3 a = y + src.uniform(0.5, 3.0) * glm::normalize(n + 0.5 * src.point(1.0));
        const dvec3 b = y + src.uniform(0.5, 3.0) * glm::normalize(n + 0.5 * src.point(1.0));
        const float j = reconnectionJacobian(toF(a), toF(b), toF(y), toF(n));
        const float jRev = reconnectionJacobian(toF(b), toF(a), toF(y), toF(n));
        EXPECT_NEAR(j * jRev, 1.0f, 1e-5f) << "config " << i;
    }
}

TEST(ShiftReconnection, DegenerateConfigurationsGiveZero) {
    const vec3 n(0, 0, 1);
    EXPECT_EQ(reconnectionJacobian(vec3(0), vec3(1, 0, 1), vec3(0), n), 0.0f);        // base at target
    EXPECT_EQ(reconnectionJacobian(vec3(1, 0, 0), vec3(0, 0, 1), vec3(0), n), 0.0f);  // grazing base edge
    EXPECT_EQ(reconnectionJacobian(vec3(0, 0, 1), vec3(0), vec3(0), n), 0.0f);        // offset at target
}

// ---------------------------------------------------------------------------------------------
// Half-vector copy shift (reflection)
// ---------------------------------------------------------------------------------------------

TEST(ShiftHalfVector, JacobianEqualsFiniteDifferenceDeterminant) {
    Source src(21);
    for (int i = 0; i < 200; ++i) {
        const dvec3 woBase = src.hemisphere(0.2);
        const dvec3 wiBase = src.hemisphere(0.2);
        const dvec3 woOffset = glm::normalize(woBase + 0.4 * src.point(1.0));
        vec3 wiOffset;
        float j = 0.0f;
        if (!halfVectorReflect(toF(woBase), toF(wiBase), toF(woOffset), wiOffset, j)) continue;
        // Keep away from near-singular maps, where float finite differences lose their digits.
        if (j < 0.2f || j > 5.0f) continue;
        auto shift = [&](dvec3 w) {
            vec3 out;
            float unused = 0.0f;
            halfVectorReflect(toF(woBase), toF(w), toF(woOffset), out, unused);
            return toD(out);
        };
        const double fd = finiteDifferenceJacobian(wiBase, 2e-3, shift);
        EXPECT_NEAR(j / fd, 1.0, 3e-3) << "config " << i << " J " << j << " fd " << fd;
    }
}

// Applying the shift from the offset back to the base returns the base direction and the
// reverse Jacobian is the reciprocal: without both, the MIS weights of a pixel pair would not
// sum to one.
TEST(ShiftHalfVector, ReverseShiftIsIdentityAndJacobiansMultiplyToOne) {
    Source src(22);
    for (int i = 0; i < 500; ++i) {
        const vec3 woBase = toF(src.hemisphere(0.05));
        const vec3 wiBase = toF(src.hemisphere(0.05));
        const vec3 woOffset = toF(src.hemisphere(0.05));
        // Float32 keeps ~1e-5 of the direction only where h is well conditioned: skip
        // configurations with a half-vector cosine below 0.1 on either side.
        const vec3 h = glm::normalize(woBase + wiBase);
        if (glm::dot(wiBase, h) < 0.1f || std::abs(glm::dot(woOffset, h)) < 0.1f) continue;
        vec3 wiOffset, back;
        float j = 0.0f, jRev = 0.0f;
        ASSERT_TRUE(halfVectorReflect(woBase, wiBase, woOffset, wiOffset, j)) << i;
        ASSERT_TRUE(halfVectorReflect(woOffset, wiOffset, woBase, back, jRev)) << i;
        EXPECT_NEAR(back.x, wiBase.x, 2e-5f) << i;
        EXPECT_NEAR(back.y, wiBase.y, 2e-5f) << i;
        EXPECT_NEAR(back.z, wiBase.z, 2e-5f) << i;
        EXPECT_NEAR(j * jRev, 1.0f, 1e-4f) << i;
    }
}

// The copy preserves the half vector: the offset's own (wo', wi') has the base's h.
TEST(ShiftHalfVector, PreservesHalfVectorAndIsIdentityForEqualWo) {
    const vec3 wo = glm::normalize(vec3(0.3f, -0.2f, 0.9f));
    const vec3 wi = glm::normalize(vec3(-0.5f, 0.1f, 0.7f));
    const vec3 woOffset = glm::normalize(vec3(0.1f, 0.25f, 0.8f));
    vec3 wiOffset;
    float j = 0.0f;
    ASSERT_TRUE(halfVectorReflect(wo, wi, woOffset, wiOffset, j));
    const vec3 h = glm::normalize(wo + wi);
    const vec3 hOffset = glm::normalize(woOffset + wiOffset);
    EXPECT_NEAR(glm::dot(h, hOffset), 1.0f, 1e-6f);
    ASSERT_TRUE(halfVectorReflect(wo, wi, wo, wiOffset, j));
    EXPECT_NEAR(glm::length(wiOffset - wi), 0.0f, 1e-6f);
    EXPECT_NEAR(j, 1.0f, 1e-6f);
    // wo = -wi: no half vector.
    EXPECT_FALSE(halfVectorReflect(wo, -wo, woOffset, wiOffset, j));
}

// ---------------------------------------------------------------------------------------------
// Shift mappings as gpt.comp calls them (result structs)
// ---------------------------------------------------------------------------------------------

// shiftReconnect: the direction and distance to the target, the Jacobian of the finite
// difference of ω → normalize(y(ω) − a') as above, and success exactly when the connection
// leaves above the offset's surface and arrives at the target's side that the base saw.
TEST(ShiftMappings, ReconnectionResultMatchesGeometryAndFiniteDifferences) {
    Source src(41);
    int tested = 0;
    for (int i = 0; i < 200; ++i) {
        const dvec3 y0 = src.point(1.0);
        const dvec3 n = glm::normalize(src.point(1.0) + dvec3(0, 0, 1e-3));
        const dvec3 a = y0 + src.uniform(0.5, 3.0) * glm::normalize(n + 0.8 * src.point(1.0));
        const dvec3 aOffset = a + 0.3 * src.point(1.0);
        const dvec3 offsetNormal = glm::normalize(src.point(1.0) + dvec3(0, 0, 1e-3));
        // The target's normal faces the base (the base arrives at its front side).
        const dvec3 targetNormal = glm::dot(a - y0, n) > 0.0 ? n : -n;
        const ConnectionShift c =
            shiftReconnect(toF(a), toF(aOffset), toF(offsetNormal), toF(y0), toF(targetNormal));
        const dvec3 e = y0 - aOffset;
        EXPECT_NEAR(c.dist, glm::length(e), 1e-5 * glm::length(e)) << i;
        EXPECT_NEAR(glm::length(toD(c.wi) - glm::normalize(e)), 0.0, 1e-5) << i;
        const bool above = glm::dot(glm::normalize(e), offsetNormal) > 1e-4;
        const bool sameSide = glm::dot(glm::normalize(e), targetNormal) < -1e-4;
        if (above && sameSide) {
            EXPECT_TRUE(c.ok) << i;
        }
        if (glm::dot(glm::normalize(e), offsetNormal) < -1e-4 ||
            glm::dot(glm::normalize(e), targetNormal) > 1e-4) {
            EXPECT_FALSE(c.ok) << i;
        }
        const double cosBase = std::abs(glm::dot(glm::normalize(a - y0), n));
        const double cosOffset = std::abs(glm::dot(glm::normalize(aOffset - y0), n));
        if (!c.ok || cosBase < 0.15 || cosOffset < 0.15 || !sameSide) continue;
        auto shift = [&](dvec3 w) {
            const double t = glm::dot(y0 - a, n) / glm::dot(w, n);
            return glm::normalize(a + t * w - aOffset);
        };
        const double fd = finiteDifferenceJacobian(glm::normalize(y0 - a), 1e-5, shift);
        EXPECT_NEAR(c.jacobian / fd, 1.0, 2e-4) << "config " << i;
        ++tested;
    }
    EXPECT_GT(tested, 20);
}

// shiftEnvironment: the identity on directions (a finite-difference Jacobian of exactly 1),
// failing below the offset's geometric surface.
TEST(ShiftMappings, EnvironmentShiftIsTheIdentityAboveTheOffsetSurface) {
    Source src(42);
    for (int i = 0; i < 100; ++i) {
        const dvec3 w = glm::normalize(src.point(1.0) + dvec3(0, 0, 1e-3));
        const dvec3 n = glm::normalize(src.point(1.0) + dvec3(0, 0, 1e-3));
        const ConnectionShift c = shiftEnvironment(toF(w), toF(n));
        EXPECT_EQ(c.wi, toF(w));
        EXPECT_EQ(c.jacobian, 1.0f);
        EXPECT_EQ(c.ok, glm::dot(toF(w), toF(n)) > 0.0f);
        const double fd = finiteDifferenceJacobian(w, 1e-4, [](dvec3 v) { return v; });
        EXPECT_NEAR(fd, 1.0, 1e-9);
    }
}

// shiftHalfVector, smooth lobe: the direction and Jacobian of halfVectorReflect (checked
// against finite differences of the map), the offset BSDF's value and density there, and
// forward ∘ reverse = identity with J·J_rev = 1, so the pair's two MIS weights (ratio form,
// r = p'·J/p forward and p·J_rev/p' reverse) sum to one.
TEST(ShiftMappings, HalfVectorResultEvaluatesTheOffsetBsdfAndInverts) {
    Source src(43);
    const BsdfParams glossy = makeBsdfParams(vec3(0.6f), 1.0f, 0.2f, 1.0f, vec3(1.0f), 1.5f);
    const BsdfParams plastic = makeBsdfParams(vec3(0.4f), 0.0f, 0.3f, 1.0f, vec3(1.0f), 1.5f);
    int tested = 0;
    for (int i = 0; i < 300; ++i) {
        const vec3 woBase = toF(src.hemisphere(0.2));
        const vec3 wiBase = toF(src.hemisphere(0.2));
        const vec3 woOffset = toF(glm::normalize(toD(woBase) + 0.4 * src.point(1.0)));
        const BsdfParams& ob = (i % 2) ? glossy : plastic;
        const HalfVectorShift h = shiftHalfVector(ob, woBase, wiBase, false, woOffset);
        vec3 wiRef;
        float jRef = 0.0f;
        const bool refOk = halfVectorReflect(woBase, wiBase, woOffset, wiRef, jRef);
        if (!refOk || wiRef.z <= 0.0f || woOffset.z <= 0.0f) {
            EXPECT_FALSE(h.ok && wiRef.z <= 0.0f) << i;
            continue;
        }
        ASSERT_TRUE(h.ok) << i;
        EXPECT_EQ(h.wiLocal, wiRef);
        EXPECT_EQ(h.jacobian, jRef);
        EXPECT_EQ(h.f, bsdfEval(ob, woOffset, h.wiLocal));
        EXPECT_EQ(h.pdf, bsdfPdf(ob, woOffset, h.wiLocal));
        if (h.jacobian > 0.2f && h.jacobian < 5.0f) {
            auto map = [&](dvec3 w) {
                return toD(shiftHalfVector(ob, woBase, toF(w), false, woOffset).wiLocal);
            };
            EXPECT_NEAR(h.jacobian / finiteDifferenceJacobian(toD(wiBase), 2e-3, map), 1.0, 3e-3) << i;
        }
        const HalfVectorShift back = shiftHalfVector(ob, woOffset, h.wiLocal, false, woBase);
        const vec3 hv = glm::normalize(woBase + wiBase);
        if (glm::dot(wiBase, hv) < 0.1f || std::abs(glm::dot(woOffset, hv)) < 0.1f || !back.ok) continue;
        EXPECT_NEAR(glm::length(back.wiLocal - wiBase), 0.0f, 5e-5f) << i;
        EXPECT_NEAR(h.jacobian * back.jacobian, 1.0f, 1e-4f) << i;
        const float p = bsdfPdf(ob, woBase, wiBase);
        const float rForward = shiftSegment(h.f, h.pdf, h.jacobian, 1.0f, p).pdfRatio;
        const float rReverse = shiftSegment(vec3(1.0f), p, back.jacobian, 1.0f, h.pdf).pdfRatio;
        EXPECT_NEAR(gptMisWeightPair(rForward) + gptMisWeightPair(rReverse), 1.0f, 1e-4f) << i;
        ++tested;
    }
    EXPECT_GT(tested, 50);
}

// shiftHalfVector, Dirac lobe: the offset's mirror direction with its Fresnel weight and lobe
// selection probability, Jacobian 1; Dirac and smooth never shift into each other.
TEST(ShiftMappings, HalfVectorDiracAndLobeMismatch) {
    const vec3 c(0.5f);
    const BsdfParams mirror = makeBsdfParams(c, 1.0f, 0.0f, 1.0f, vec3(1.0f), 1.5f);
    const BsdfParams coatedMirror = makeBsdfParams(c, 0.0f, 0.0f, 1.0f, vec3(1.0f), 1.5f);
    const BsdfParams lambert = makeBsdfParams(c, 0.0f, 1.0f, 0.0f, vec3(1.0f), 1.5f);
    const vec3 woBase = glm::normalize(vec3(0.3f, -0.2f, 0.9f));
    const vec3 wiBase(-woBase.x, -woBase.y, woBase.z);
    const vec3 woOffset = glm::normalize(vec3(-0.4f, 0.1f, 0.8f));
    for (const BsdfParams& ob : {mirror, coatedMirror}) {
        const HalfVectorShift h = shiftHalfVector(ob, woBase, wiBase, true, woOffset);
        ASSERT_TRUE(h.ok);
        EXPECT_EQ(h.wiLocal, vec3(-woOffset.x, -woOffset.y, woOffset.z));
        EXPECT_EQ(h.jacobian, 1.0f);
        EXPECT_EQ(h.f, glossyFresnel(ob, woOffset.z));
        EXPECT_EQ(h.pdf, glossySelectProb(ob, woOffset));
    }
    // A base mirror sample at an offset without a Dirac lobe, a smooth base sample at a
    // Dirac-only offset, and an offset seen from below: the shift fails.
    EXPECT_FALSE(shiftHalfVector(lambert, woBase, wiBase, true, woOffset).ok);
    EXPECT_FALSE(shiftHalfVector(mirror, woBase, glm::normalize(vec3(0.1f, 0.2f, 0.9f)), false, woOffset).ok);
    EXPECT_FALSE(shiftHalfVector(mirror, woBase, wiBase, true, vec3(woOffset.x, woOffset.y, -woOffset.z)).ok);
}

// shiftSegment: the ratio-form update factors f·J·rrInv/p and p'·J/p.
TEST(ShiftMappings, SegmentFactorsOfTheRatioForm) {
    const SegmentShift s = shiftSegment(vec3(0.5f, 0.25f, 1.0f), 3.0f, 2.0f, 4.0f, 8.0f);
    EXPECT_EQ(s.throughput, vec3(0.5f, 0.25f, 1.0f));
    EXPECT_EQ(s.pdfRatio, 0.75f);
    // Jacobian 1 (a shared vertex): exactly f·rrInv/p and p'/p.
    const SegmentShift t = shiftSegment(vec3(0.3f), 0.7f, 1.0f, 1.0f / 0.9f, 1.3f);
    EXPECT_EQ(t.throughput, vec3(0.3f) * ((1.0f / 0.9f) / 1.3f));
    EXPECT_EQ(t.pdfRatio, 0.7f / 1.3f);
}

// ---------------------------------------------------------------------------------------------
// MIS of a pixel pair
// ---------------------------------------------------------------------------------------------

// Two-strategy pair (half-vector branch): the forward weight p²/(p² + (J p')²) and the
// reverse technique's weight p'²/(p'² + (p/J)²) of the same pair of paths sum to one, also
// for pdf magnitudes whose squares over/underflow float32.
TEST(ShiftMis, PairWeightsSumToOne) {
    Source src(31);
    for (int i = 0; i < 2000; ++i) {
        const float p = static_cast<float>(std::pow(10.0, src.uniform(-30, 30)));
        const float pOffset = static_cast<float>(std::pow(10.0, src.uniform(-30, 30)));
        const float j = static_cast<float>(std::pow(10.0, src.uniform(-3, 3)));
        const float forward = gptMisWeightPair(j * pOffset / p);
        const float reverse = gptMisWeightPair((1.0f / j) * p / pOffset);
        EXPECT_NEAR(forward + reverse, 1.0f, 1e-5f) << p << " " << pOffset << " " << j;
        EXPECT_GE(forward, 0.0f);
        EXPECT_LE(forward, 1.0f);
    }
}

// Four strategies at a reconnected light vertex: {BSDF, light} × {base, offset}, on real
// geometry. The base vertex a and offset vertex a' (Lambertian, cosine-weighted BSDF pdf)
// both connect to the light point y (area pdf pArea). Forward weights use the offset pdfs
// times the prefix ratio and the reconnection Jacobian J(a→a'); the reverse technique (base
// at a', offset a) uses the reciprocal ratio and J(a'→a). All four weights sum to one.
TEST(ShiftMis, FourStrategyWeightsOfForwardAndReverseSumToOne) {
    Source src(32);
    for (int i = 0; i < 500; ++i) {
        const dvec3 y = src.point(1.0);
        const dvec3 nLight = glm::normalize(dvec3(0.2, -0.1, -1.0));
        const dvec3 a = y - src.uniform(0.5, 3.0) * glm::normalize(-nLight + 0.4 * src.point(1.0));
        const dvec3 aOffset = y - src.uniform(0.5, 3.0) * glm::normalize(-nLight + 0.4 * src.point(1.0));
        const dvec3 nSurf(0, 0, 1);
        auto pdfs = [&](dvec3 from, double& pBsdf, double& pLight) {
            const dvec3 d = y - from;
            const double dist2 = glm::dot(d, d);
            const dvec3 w = d / std::sqrt(dist2);
            pBsdf = std::max(glm::dot(w, nSurf), 0.0) / 3.14159265358979323846;
            const double pArea = 0.37;
            pLight = pArea * dist2 / std::abs(glm::dot(nLight, w));
        };
        double pB, pL, pBo, pLo;
        pdfs(a, pB, pL);
        pdfs(aOffset, pBo, pLo);
        if (!(pB > 0.01 && pBo > 0.01)) continue;
        const float prefixRatio = static_cast<float>(std::pow(10.0, src.uniform(-4, 4)));
        const float j = reconnectionJacobian(toF(a), toF(aOffset), toF(y), toF(nLight));
        const float jRev = reconnectionJacobian(toF(aOffset), toF(a), toF(y), toF(nLight));
        const float fB =
            gptMisWeight(float(pB), float(pL), prefixRatio * j * float(pBo), prefixRatio * j * float(pLo));
        const float fL =
            gptMisWeight(float(pL), float(pB), prefixRatio * j * float(pLo), prefixRatio * j * float(pBo));
        const float rB = gptMisWeight(float(pBo), float(pLo), jRev * float(pB) / prefixRatio,
                                      jRev * float(pL) / prefixRatio);
        const float rL = gptMisWeight(float(pLo), float(pBo), jRev * float(pL) / prefixRatio,
                                      jRev * float(pB) / prefixRatio);
        EXPECT_NEAR(fB + fL + rB + rL, 1.0f, 2e-5f) << "config " << i;
        // The light pdf in the base's measure is the same for both (same light point):
        // pL' J = pL (the offset reconnects to the base's light point; the identity gpt.comp
        // relies on).
        EXPECT_NEAR(float(pLo) * j / float(pL), 1.0f, 1e-4f) << "config " << i;
    }
}

// Pixels with different sample counts (edge samples): the forward weights with c = n_q / n_p
// times the offset's densities and the reverse ones with 1 / c still sum to one (so any fixed
// counts keep a pair unbiased), and they are Veach's multi-sample power heuristic with the
// counts, (n_p p)² / Σ (n_k p_k)², computed here in double precision.
TEST(ShiftMis, SampleCountsKeepTheWeightsSummingToOneAsVeachsMultiSampleHeuristic) {
    Source src(33);
    const double counts[][2] = {{3, 1}, {1, 3}, {65, 1}, {2, 5}, {1, 1}};
    for (const auto& n : counts) {
        const float c = static_cast<float>(n[1] / n[0]);  // n_q / n_p, p the base's pixel
        for (int i = 0; i < 500; ++i) {
            const double pB = std::pow(10.0, src.uniform(-3, 3)), pL = std::pow(10.0, src.uniform(-3, 3));
            const double qB = std::pow(10.0, src.uniform(-3, 3)), qL = std::pow(10.0, src.uniform(-3, 3));
            // Four strategies: base BSDF and light at p's rate, the offset's at q's.
            const float fB = gptMisWeight(float(pB), float(pL), c * float(qB), c * float(qL));
            const float fL = gptMisWeight(float(pL), float(pB), c * float(qL), c * float(qB));
            const float rB = gptMisWeight(float(qB), float(qL), float(pB) / c, float(pL) / c);
            const float rL = gptMisWeight(float(qL), float(qB), float(pL) / c, float(pB) / c);
            EXPECT_NEAR(fB + fL + rB + rL, 1.0f, 2e-5f) << c << " " << i;
            const auto sq = [](double v) { return v * v; };
            const double all = sq(n[0] * pB) + sq(n[0] * pL) + sq(n[1] * qB) + sq(n[1] * qL);
            EXPECT_NEAR(fB, sq(n[0] * pB) / all, 1e-5) << c << " " << i;
            // Two strategies (half-vector branch, environment): r = J p' / p.
            const float r = static_cast<float>(qB / pB);
            EXPECT_NEAR(gptMisWeightPair(c * r) + gptMisWeightPair((1.0f / c) / r), 1.0f, 1e-5f);
        }
    }
    // Equal densities, three samples at p for one at q: p's paths carry 0.9 of the pair.
    EXPECT_NEAR(gptMisWeightPair(1.0f / 3.0f), 0.9f, 1e-6f);
}

TEST(ShiftMis, RatioFormSurvivesExtremePdfsAndRejectsBadInput) {
    EXPECT_NEAR(gptMisWeight(1e30f, 1e25f, 1e20f, 0.0f), 1.0f, 1e-6f);
    EXPECT_NEAR(gptMisWeight(1e-30f, 1e-30f, 1e-30f, 1e-30f), 0.25f, 1e-6f);
    EXPECT_NEAR(gptMisWeight(3e25f, 0.0f, 3e25f, 0.0f), 0.5f, 1e-6f);
    EXPECT_EQ(gptMisWeight(0.0f, 1.0f, 1.0f, 1.0f), 0.0f);
    EXPECT_EQ(gptMisWeight(std::nanf(""), 1.0f, 1.0f, 1.0f), 0.0f);
    EXPECT_EQ(gptMisWeight(1.0f, std::nanf(""), 1.0f, 1.0f), 0.0f);
    EXPECT_EQ(gptMisWeight(1.0f, 1.0f / 0.0f, 1.0f, 1.0f), 0.0f);
    EXPECT_EQ(gptMisWeight(1.0f / 0.0f, 1.0f, 1.0f, 1.0f), 1.0f);
    EXPECT_EQ(gptMisWeightPair(0.0f), 1.0f);
    EXPECT_EQ(gptMisWeightPair(1.0f / 0.0f), 0.0f);
}

// ---------------------------------------------------------------------------------------------
// Vertex classification
// ---------------------------------------------------------------------------------------------

TEST(ShiftClassification, ByLowestRoughnessOverAllComponents) {
    const vec3 c(0.5f);
    const BsdfParams lambertRough0 = makeBsdfParams(c, 0.0f, 0.0f, 0.0f, vec3(1.0f), 1.5f);
    const BsdfParams metal = makeBsdfParams(c, 1.0f, 0.3f, 1.0f, vec3(1.0f), 1.5f);
    const BsdfParams coatedMirror = makeBsdfParams(c, 0.0f, 0.0f, 1.0f, vec3(1.0f), 1.5f);
    const float thr = 0.001f;
    // Lambertian: rough even with roughnessFactor 0.
    EXPECT_TRUE(shiftIsRough(shiftRoughnessAll(lambertRough0), thr));
    // GGX 0.3 metal: rough at the default threshold, glossy above 0.3.
    EXPECT_FLOAT_EQ(shiftRoughnessAll(metal), 0.3f);
    EXPECT_TRUE(shiftIsRough(shiftRoughnessAll(metal), thr));
    EXPECT_FALSE(shiftIsRough(shiftRoughnessAll(metal), 0.3f));
    // Coated mirror: its diffuse lobe is rough, the vertex as a whole is not.
    EXPECT_FALSE(shiftIsRough(shiftRoughnessAll(coatedMirror), thr));
    // Black emitter material: nothing to shift through, counts as rough.
    EXPECT_TRUE(
        shiftIsRough(shiftRoughnessAll(makeBsdfParams(vec3(0.0f), 0.0f, 1.0f, 0.0f, vec3(1.0f), 1.5f)), thr));
}

TEST(ShiftClassification, ReconnectionAndInvertibilityRules) {
    EXPECT_TRUE(shiftUseReconnection(true, true, true));
    EXPECT_FALSE(shiftUseReconnection(false, true, true));
    EXPECT_FALSE(shiftUseReconnection(true, false, true));
    EXPECT_FALSE(shiftUseReconnection(true, true, false));
    // Half-vector step is invertible unless the reverse would reconnect.
    EXPECT_FALSE(shiftHalfVectorInvertible(true, true, true));
    EXPECT_TRUE(shiftHalfVectorInvertible(false, true, true));
    EXPECT_TRUE(shiftHalfVectorInvertible(true, false, true));
    EXPECT_TRUE(shiftHalfVectorInvertible(true, true, false));
}

}  // namespace
