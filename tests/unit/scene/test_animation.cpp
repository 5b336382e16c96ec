// Keyframe sampling (scene/animation.h) against values computed by hand from glTF 2.0
// Appendix C: LINEAR, STEP and CUBICSPLINE, before, at and after keys; quaternion slerp on
// the shorter arc, antipodal and nearly equal keys; and every malformed channel refused.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/constants.hpp>
#include <limits>

#include "scene/animation.h"
#include "util/error.h"

namespace gdpt {
namespace {

AnimationChannel channel(AnimatedProperty p, Interpolation i, std::vector<double> times,
                         std::vector<glm::dvec4> values) {
    AnimationChannel c;
    c.node = 0;
    c.property = p;
    c.interpolation = i;
    c.times = std::move(times);
    c.values = std::move(values);
    checkChannel(c);
    return c;
}

// (x, y, z, w) of the rotation by `angle` about the unit `axis`.
glm::dvec4 axisAngle(glm::dvec3 axis, double angle) {
    return {axis * std::sin(0.5 * angle), std::cos(0.5 * angle)};
}

void expectNear(const glm::dvec4& a, const glm::dvec4& b, double tol = 1e-12) {
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(a[i], b[i], tol) << "component " << i;
}

std::string checkError(AnimationChannel c) {
    try {
        checkChannel(c);
        return "";
    } catch (const Error& e) {
        return e.what();
    }
}

TEST(Animation, LinearTranslationAtBetweenBeforeAndAfterKeys) {
    const auto c = channel(AnimatedProperty::Translation, Interpolation::Linear, {0.0, 1.0, 3.0},
                           {{0, 0, 0, 0}, {2, 4, -2, 0}, {2, 0, 0, 0}});
    expectNear(sampleChannel(c, 0.25), {0.5, 1.0, -0.5, 0});
    expectNear(sampleChannel(c, 1.0), {2, 4, -2, 0});
    expectNear(sampleChannel(c, 2.0), {2, 2, -1, 0});  // halfway between keys 1 and 2
    expectNear(sampleChannel(c, -1.0), {0, 0, 0, 0});  // before the first key: the first value
    expectNear(sampleChannel(c, 7.0), {2, 0, 0, 0});   // after the last: the last value
}

TEST(Animation, LinearFirstKeyAfterZeroHoldsItsValueBefore) {
    const auto c =
        channel(AnimatedProperty::Scale, Interpolation::Linear, {1.0, 2.0}, {{1, 1, 1, 0}, {3, 1, 1, 0}});
    expectNear(sampleChannel(c, 0.0), {1, 1, 1, 0});
    expectNear(sampleChannel(c, 1.5), {2, 1, 1, 0});
}

TEST(Animation, StepHoldsEachKeyUntilTheNext) {
    const auto c = channel(AnimatedProperty::Translation, Interpolation::Step, {0.0, 1.0, 2.0},
                           {{1, 0, 0, 0}, {5, 0, 0, 0}, {9, 0, 0, 0}});
    expectNear(sampleChannel(c, 0.999), {1, 0, 0, 0});
    expectNear(sampleChannel(c, 1.0), {5, 0, 0, 0});
    expectNear(sampleChannel(c, 1.999), {5, 0, 0, 0});
    expectNear(sampleChannel(c, 2.5), {9, 0, 0, 0});
}

TEST(Animation, CubicSplineHermiteByHand) {
    // Keys at 0 and 2 (td = 2); values v0 = 0, v1 = (1, 0, 0); out-tangent b0 = (0, 4, 0),
    // in-tangent a1 = (0, 0, 8). At s = 1/2 the Hermite basis is h00 = 1/2, h10 = 1/8,
    // h01 = 1/2, h11 = -1/8: p = 0 + 2 (1/8) b0 + (1/2) v1 + 2 (-1/8) a1 = (0.5, 1, -2).
    const auto c =
        channel(AnimatedProperty::Translation, Interpolation::CubicSpline, {0.0, 2.0},
                {{9, 9, 9, 0}, {0, 0, 0, 0}, {0, 4, 0, 0}, {0, 0, 8, 0}, {1, 0, 0, 0}, {7, 7, 7, 0}});
    expectNear(sampleChannel(c, 1.0), {0.5, 1.0, -2.0, 0});
    // At s = 1/4: h00 = 27/32, h10 = 9/64, h01 = 5/32, h11 = -3/64.
    expectNear(sampleChannel(c, 0.5), {5.0 / 32, 2 * 9.0 / 64 * 4, 2 * -3.0 / 64 * 8, 0});
    // The first key's in-tangent and the last key's out-tangent are never used; outside the
    // keys the values hold.
    expectNear(sampleChannel(c, -3.0), {0, 0, 0, 0});
    expectNear(sampleChannel(c, 5.0), {1, 0, 0, 0});
    expectNear(sampleChannel(c, 2.0), {1, 0, 0, 0});
}

TEST(Animation, CubicSplineWithSecantTangentsIsLinear) {
    // Tangents equal to the secant slope (in units per second) reproduce linear motion.
    const auto c =
        channel(AnimatedProperty::Translation, Interpolation::CubicSpline, {0.5, 2.5},
                {{0.5, 0, 0, 0}, {1, 2, 3, 0}, {0.5, 0, 0, 0}, {0.5, 0, 0, 0}, {2, 2, 3, 0}, {0.5, 0, 0, 0}});
    for (double t = 0.5; t <= 2.5; t += 0.125)
        expectNear(sampleChannel(c, t), {1 + (t - 0.5) * 0.5, 2, 3, 0}, 1e-12);
}

TEST(Animation, SlerpHalfwayIsHalfTheAngle) {
    const glm::dvec3 y(0, 1, 0);
    const auto c = channel(AnimatedProperty::Rotation, Interpolation::Linear, {0.0, 1.0},
                           {axisAngle(y, 0.0), axisAngle(y, glm::half_pi<double>())});
    expectNear(sampleChannel(c, 0.5), axisAngle(y, glm::quarter_pi<double>()));
    // Slerp is uniform in angle: at s = 0.3, 0.3 of the way.
    expectNear(sampleChannel(c, 0.3), axisAngle(y, 0.3 * glm::half_pi<double>()));
}

TEST(Animation, SlerpTakesTheShorterArc) {
    // The second key negated is the same rotation; interpolation must not take the long way
    // (which would pass through a 225-degree rotation at s = 1/2).
    const glm::dvec3 y(0, 1, 0);
    const auto c = channel(AnimatedProperty::Rotation, Interpolation::Linear, {0.0, 1.0},
                           {axisAngle(y, 0.0), -axisAngle(y, glm::half_pi<double>())});
    const glm::dvec4 half = sampleChannel(c, 0.5);
    const glm::dvec4 expected = axisAngle(y, glm::quarter_pi<double>());
    // q and -q are one rotation: compare up to sign.
    const double sign = glm::dot(half, expected) < 0 ? -1.0 : 1.0;
    expectNear(sign * half, expected);
}

TEST(Animation, SlerpOfAntipodalKeysIsConstant) {
    const glm::dvec4 q = axisAngle(glm::normalize(glm::dvec3(1, 2, 3)), 1.0);
    const auto c = channel(AnimatedProperty::Rotation, Interpolation::Linear, {0.0, 1.0}, {q, -q});
    for (double t : {0.1, 0.5, 0.9}) {
        const glm::dvec4 v = sampleChannel(c, t);
        EXPECT_NEAR(std::abs(glm::dot(v, q)), 1.0, 1e-12) << t;
    }
}

TEST(Animation, SlerpHalfTurn) {
    // Identity to a half turn about Z (dot product 0): halfway is a quarter turn.
    const glm::dvec3 z(0, 0, 1);
    const auto c = channel(AnimatedProperty::Rotation, Interpolation::Linear, {0.0, 2.0},
                           {axisAngle(z, 0.0), axisAngle(z, glm::pi<double>())});
    expectNear(sampleChannel(c, 1.0), axisAngle(z, glm::half_pi<double>()));
}

TEST(Animation, SlerpOfNearlyEqualKeysIsFiniteAndUnit) {
    const glm::dvec3 x(1, 0, 0);
    const auto c = channel(AnimatedProperty::Rotation, Interpolation::Linear, {0.0, 1.0},
                           {axisAngle(x, 0.2), axisAngle(x, 0.2 + 1e-13)});
    const glm::dvec4 v = sampleChannel(c, 0.5);
    EXPECT_NEAR(glm::length(v), 1.0, 1e-12);
    expectNear(v, axisAngle(x, 0.2), 1e-12);
}

TEST(Animation, RotationKeysOfAnyLengthInterpolateAsUnitKeys) {
    // Keys are returned as stored (the node transform normalises them), and interpolated as
    // the unit quaternions they stand for.
    const glm::dvec3 y(0, 1, 0);
    const auto c = channel(AnimatedProperty::Rotation, Interpolation::Linear, {0.0, 1.0},
                           {2.0 * axisAngle(y, 0.0), 0.5 * axisAngle(y, glm::half_pi<double>())});
    expectNear(sampleChannel(c, 0.0), {0, 0, 0, 2});
    expectNear(sampleChannel(c, 0.5), axisAngle(y, glm::quarter_pi<double>()));
}

TEST(Animation, CubicSplineRotationIsUnit) {
    const glm::dvec3 y(0, 1, 0);
    const auto c = channel(
        AnimatedProperty::Rotation, Interpolation::CubicSpline, {0.0, 1.0},
        {{0, 0, 0, 0}, axisAngle(y, 0.0), {0, 0.3, 0, 0}, {0, 0.3, 0, 0}, axisAngle(y, 1.0), {0, 0, 0, 0}});
    for (double t = 0.0; t <= 1.0; t += 0.1) EXPECT_NEAR(glm::length(sampleChannel(c, t)), 1.0, 1e-12) << t;
}

TEST(Animation, PoseCombinesChannelsPerNode) {
    Animation a;
    a.channels.push_back(channel(AnimatedProperty::Translation, Interpolation::Linear, {0.0, 1.0},
                                 {{0, 0, 0, 0}, {4, 0, 0, 0}}));
    a.channels.push_back(
        channel(AnimatedProperty::Scale, Interpolation::Step, {0.0, 2.0}, {{1, 1, 1, 0}, {2, 2, 2, 0}}));
    a.channels[1].node = 3;
    EXPECT_DOUBLE_EQ(a.duration(), 2.0);
    const auto pose = poseAt(a, 0.5);
    ASSERT_EQ(pose.size(), 2u);
    EXPECT_EQ(pose.at(0).translation->x, 2.0);
    EXPECT_FALSE(pose.at(0).rotation.has_value());
    EXPECT_EQ(pose.at(3).scale->y, 1.0);
    EXPECT_FALSE(pose.at(3).translation.has_value());
}

TEST(Animation, MalformedChannelsAreRefused) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    AnimationChannel c;
    c.property = AnimatedProperty::Translation;
    c.times = {0.0, 1.0, 1.0};
    c.values = {{0, 0, 0, 0}, {1, 0, 0, 0}, {2, 0, 0, 0}};
    EXPECT_NE(checkError(c).find("not strictly increasing: key 2 at 1 s follows 1 s"), std::string::npos)
        << checkError(c);
    c.times = {0.0, 2.0, 1.0};
    EXPECT_NE(checkError(c).find("not strictly increasing"), std::string::npos);
    c.times = {-0.5, 1.0, 2.0};
    EXPECT_NE(checkError(c).find("key time 0 is -0.5, before 0"), std::string::npos) << checkError(c);
    c.times = {0.0, nan, 2.0};
    EXPECT_NE(checkError(c).find("key time 1 is nan"), std::string::npos) << checkError(c);
    c.times = {0.0, 1.0, 2.0};
    EXPECT_EQ(checkError(c), "");
    c.values[1].y = nan;
    EXPECT_NE(checkError(c).find("output value 1 has the component nan"), std::string::npos) << checkError(c);
    c.values.pop_back();
    EXPECT_NE(checkError(c).find("3 key times but 2 output values (LINEAR needs one per key, 3)"),
              std::string::npos)
        << checkError(c);
    c.interpolation = Interpolation::CubicSpline;
    c.values.assign(6, glm::dvec4(0.0));
    EXPECT_NE(checkError(c).find("needs 3 per key"), std::string::npos) << checkError(c);
    c.times = {0.0};
    c.values.assign(3, glm::dvec4(0.0));
    EXPECT_NE(checkError(c).find("at least 2 keys"), std::string::npos) << checkError(c);
    c.times.clear();
    c.values.clear();
    EXPECT_NE(checkError(c).find("no keys"), std::string::npos);
    c.interpolation = Interpolation::Linear;
    c.property = AnimatedProperty::Rotation;
    c.times = {0.0, 1.0};
    c.values = {{0, 0, 0, 1}, {0, 0, 0, 0}};
    EXPECT_NE(checkError(c).find("rotation key 1 is a zero quaternion"), std::string::npos) << checkError(c);
}

}  // namespace
}  // namespace gdpt
