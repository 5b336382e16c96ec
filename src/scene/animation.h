// animation.h — glTF 2.0 keyframe animation (§3.11 "Animations"): channels that drive a node's
// translation, rotation or scale through a sampler (key times in seconds, LINEAR, STEP or
// CUBICSPLINE interpolation), evaluated at any time. The loader (gltf_loader.h, GltfAsset)
// reads and checks them; poseAt gives the local transforms that override a node's own TRS, and
// the node hierarchy is then composed as for a static scene.
//
// Interpolation follows the specification's Appendix C: LINEAR is component-wise linear for
// translation and scale and spherical linear (shortest arc) for rotation; STEP holds a key's
// value until the next key; CUBICSPLINE is the cubic Hermite spline through the keys with the
// file's in- and out-tangents scaled by the key interval (rotations normalised afterwards).
// Before the first key a channel holds its first value, after the last its last.
// CPU only (no Vulkan, no tinygltf): unit-tested against hand-computed transforms.
#pragma once

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace gdpt {

enum class AnimatedProperty { Translation, Rotation, Scale };
enum class Interpolation { Linear, Step, CubicSpline };

// "translation", "rotation", "scale"; "LINEAR", "STEP", "CUBICSPLINE" (the glTF spellings).
const char* propertyName(AnimatedProperty p);
const char* interpolationName(Interpolation i);

struct AnimationChannel {
    int node = -1;       // node index in the file
    std::string target;  // for messages and listings: "node 'Box' rotation"
    AnimatedProperty property = AnimatedProperty::Translation;
    Interpolation interpolation = Interpolation::Linear;
    std::vector<double> times;  // key times in seconds: >= 0, strictly increasing
    // Per key one value, or for CUBICSPLINE three (in-tangent, value, out-tangent), as the
    // file stores them. Translation and scale use xyz (w = 0); rotations are quaternions
    // (x, y, z, w) as glTF stores them (the node transform normalises them, as it does a
    // node's own rotation, so a pose at a key equals the static node with that rotation).
    std::vector<glm::dvec4> values;
};

struct Animation {
    std::string name;  // as in the file ("" if unnamed)
    std::vector<AnimationChannel> channels;
    // The time of the last key over all channels (an animation starts at time 0).
    [[nodiscard]] double duration() const;
};

// Checks a channel as the loader reads it: at least one key; times finite, >= 0 and strictly
// increasing; as many values as keys (three per key for CUBICSPLINE, which needs two keys);
// every value finite; rotation value keys not zero. Throws gdpt::Error
// naming the first problem (the caller adds which channel).
void checkChannel(AnimationChannel& channel);

// The channel's value at `time` seconds: (x, y, z, 0) for translation and scale, a quaternion
// (x, y, z, w) for rotation: a key as stored at or outside the keys and for STEP, else of unit
// length.
[[nodiscard]] glm::dvec4 sampleChannel(const AnimationChannel& channel, double time);

// What an animation sets of one node's local transform at a time; unset parts keep the node's
// own translation, rotation or scale.
struct NodePose {
    std::optional<glm::dvec3> translation;
    std::optional<glm::dquat> rotation;
    std::optional<glm::dvec3> scale;
};

// Every animated node's pose at `time`, by node index.
[[nodiscard]] std::map<int, NodePose> poseAt(const Animation& animation, double time);

// Spherical linear interpolation of unit quaternions along the shorter arc (glTF 2.0
// Appendix C): q and -q are the same rotation, so a key pair with a negative dot product is
// interpolated towards the negated second key.
[[nodiscard]] glm::dquat slerpShortest(const glm::dquat& a, const glm::dquat& b, double s);

}  // namespace gdpt
