// animation.cpp — keyframe sampling of glTF 2.0 animation channels (animation.h).
#include "scene/animation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "util/error.h"

namespace gdpt {
namespace {

std::string number(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", v);
    return text;
}

glm::dquat toQuat(const glm::dvec4& v) {
    return glm::dquat(v.w, v.x, v.y, v.z);  // glm's constructor takes (w, x, y, z)
}

glm::dvec4 fromQuat(const glm::dquat& q) {
    return {q.x, q.y, q.z, q.w};
}

// A rotation result of unit length; a degenerate spline value (possible only with wild
// tangents) falls back to `fallback`.
glm::dvec4 normalisedRotation(const glm::dvec4& v, const glm::dvec4& fallback) {
    const double len = glm::length(v);
    return len > 1e-12 && std::isfinite(len) ? v / len : fallback;
}

// Index of the key value for key k: the value itself, or the middle of the CUBICSPLINE triple.
std::size_t valueIndex(const AnimationChannel& c, std::size_t k) {
    return c.interpolation == Interpolation::CubicSpline ? 3 * k + 1 : k;
}

}  // namespace

const char* propertyName(AnimatedProperty p) {
    switch (p) {
        case AnimatedProperty::Translation:
            return "translation";
        case AnimatedProperty::Rotation:
            return "rotation";
        case AnimatedProperty::Scale:
            return "scale";
    }
    return "?";
}

const char* interpolationName(Interpolation i) {
    switch (i) {
        case Interpolation::Linear:
            return "LINEAR";
        case Interpolation::Step:
            return "STEP";
        case Interpolation::CubicSpline:
            return "CUBICSPLINE";
    }
    return "?";
}

double Animation::duration() const {
    double end = 0.0;
    for (const auto& c : channels)
        if (!c.times.empty()) end = std::max(end, c.times.back());
    return end;
}

void checkChannel(AnimationChannel& c) {
    const std::size_t keys = c.times.size();
    const bool cubic = c.interpolation == Interpolation::CubicSpline;
    if (keys == 0) throw Error("the sampler has no keys");
    if (cubic && keys < 2) throw Error("a CUBICSPLINE sampler needs at least 2 keys, this one has 1");
    const std::size_t wanted = cubic ? 3 * keys : keys;
    if (c.values.size() != wanted)
        throw Error("the sampler has " + std::to_string(keys) + " key times but " +
                    std::to_string(c.values.size()) + " output values (" +
                    interpolationName(c.interpolation) + " needs " +
                    (cubic ? "3 per key: in-tangent, value, out-tangent" : "one per key") + ", " +
                    std::to_string(wanted) + ")");
    for (std::size_t k = 0; k < keys; ++k) {
        const double t = c.times[k];
        if (!std::isfinite(t)) throw Error("key time " + std::to_string(k) + " is " + number(t));
        if (t < 0.0) throw Error("key time " + std::to_string(k) + " is " + number(t) + ", before 0");
        if (k > 0 && !(t > c.times[k - 1]))
            throw Error("key times are not strictly increasing: key " + std::to_string(k) + " at " +
                        number(t) + " s follows " + number(c.times[k - 1]) + " s");
    }
    for (std::size_t i = 0; i < c.values.size(); ++i) {
        const glm::dvec4& v = c.values[i];
        for (int j = 0; j < 4; ++j)
            if (!std::isfinite(v[j]))
                throw Error("output value " + std::to_string(i) + " has the component " + number(v[j]));
    }
    if (c.property == AnimatedProperty::Rotation)
        for (std::size_t k = 0; k < keys; ++k)
            if (!(glm::length(c.values[valueIndex(c, k)]) > 1e-12))
                throw Error("rotation key " + std::to_string(k) + " is a zero quaternion");
}

glm::dquat slerpShortest(const glm::dquat& a, const glm::dquat& bIn, double s) {
    glm::dquat b = bIn;
    double d = glm::dot(a, b);
    if (d < 0.0) {
        b = -b;
        d = -d;
    }
    // Nearly equal keys: sin(theta) vanishes; the normalised linear blend is the limit.
    if (d > 1.0 - 1e-12) return glm::normalize(a * (1.0 - s) + b * s);
    const double theta = std::acos(std::min(d, 1.0));
    const double sinTheta = std::sin(theta);
    return a * (std::sin((1.0 - s) * theta) / sinTheta) + b * (std::sin(s * theta) / sinTheta);
}

glm::dvec4 sampleChannel(const AnimationChannel& c, double time) {
    const std::size_t keys = c.times.size();
    const bool rotation = c.property == AnimatedProperty::Rotation;
    if (time <= c.times.front() || keys == 1) return c.values[valueIndex(c, 0)];
    if (time >= c.times.back()) return c.values[valueIndex(c, keys - 1)];
    // Key k with times[k] <= time < times[k + 1].
    const std::size_t k = static_cast<std::size_t>(std::upper_bound(c.times.begin(), c.times.end(), time) -
                                                   c.times.begin() - 1);
    // On a key, its value as stored (no interpolation arithmetic), so that a pose at a key
    // time equals the static node with that key's transform bit for bit.
    if (time == c.times[k]) return c.values[valueIndex(c, k)];
    const double t0 = c.times[k], t1 = c.times[k + 1];
    const double td = t1 - t0;
    const double s = (time - t0) / td;
    switch (c.interpolation) {
        case Interpolation::Step:
            return c.values[k];
        case Interpolation::Linear:
            if (rotation)
                return fromQuat(slerpShortest(glm::normalize(toQuat(c.values[k])),
                                              glm::normalize(toQuat(c.values[k + 1])), s));
            return c.values[k] * (1.0 - s) + c.values[k + 1] * s;
        case Interpolation::CubicSpline: {
            // glTF 2.0 Appendix C: p(s) = (2s^3 - 3s^2 + 1) v_k + td (s^3 - 2s^2 + s) b_k
            //                            + (-2s^3 + 3s^2) v_k+1 + td (s^3 - s^2) a_k+1,
            // with a the in-tangents and b the out-tangents.
            const glm::dvec4& vk = c.values[3 * k + 1];
            const glm::dvec4& bk = c.values[3 * k + 2];
            const glm::dvec4& ak1 = c.values[3 * (k + 1)];
            const glm::dvec4& vk1 = c.values[3 * (k + 1) + 1];
            const double s2 = s * s, s3 = s2 * s;
            const glm::dvec4 p = (2 * s3 - 3 * s2 + 1) * vk + td * (s3 - 2 * s2 + s) * bk +
                                 (-2 * s3 + 3 * s2) * vk1 + td * (s3 - s2) * ak1;
            return rotation ? normalisedRotation(p, vk / glm::length(vk)) : p;
        }
    }
    return c.values[valueIndex(c, k)];
}

std::map<int, NodePose> poseAt(const Animation& animation, double time) {
    std::map<int, NodePose> pose;
    for (const auto& c : animation.channels) {
        const glm::dvec4 v = sampleChannel(c, time);
        NodePose& p = pose[c.node];
        switch (c.property) {
            case AnimatedProperty::Translation:
                p.translation = glm::dvec3(v);
                break;
            case AnimatedProperty::Rotation:
                p.rotation = toQuat(v);
                break;
            case AnimatedProperty::Scale:
                p.scale = glm::dvec3(v);
                break;
        }
    }
    return pose;
}

}  // namespace gdpt
