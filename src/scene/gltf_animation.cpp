// gltf_animation.cpp — reads and checks a glTF file's animations (glTF 2.0 §3.11) into
// animation.h's channels: sampler inputs and outputs, interpolation, targets.
#include <set>
#include <utility>

#include "scene/gltf_internal.h"

namespace gdpt::gltf {
namespace {

Interpolation parseInterpolation(const std::string& text) {
    if (text == "LINEAR" || text.empty()) return Interpolation::Linear;  // the default (§3.11)
    if (text == "STEP") return Interpolation::Step;
    if (text == "CUBICSPLINE") return Interpolation::CubicSpline;
    throw Error("interpolation '" + text + "' is not LINEAR, STEP or CUBICSPLINE");
}

AnimationChannel readChannel(const tinygltf::Model& model, const tinygltf::Animation& animation,
                             const tinygltf::AnimationChannel& channel, AnimatedProperty property) {
    AnimationChannel out;
    out.node = channel.target_node;
    out.property = property;
    const tinygltf::Node& node = model.nodes[static_cast<std::size_t>(channel.target_node)];
    out.target = elementName("node", channel.target_node, node.name) + " " + propertyName(property);
    if (!node.matrix.empty())
        throw Error(elementName("node", channel.target_node, node.name) +
                    " is animated but has a matrix; animated nodes must use translation, rotation and "
                    "scale (glTF 2.0 §3.11)");
    if (channel.sampler < 0 || static_cast<std::size_t>(channel.sampler) >= animation.samplers.size())
        throw Error("sampler " + std::to_string(channel.sampler) + " out of range (the animation has " +
                    std::to_string(animation.samplers.size()) + " samplers)");
    const tinygltf::AnimationSampler& sampler = animation.samplers[static_cast<std::size_t>(channel.sampler)];
    try {
        out.interpolation = parseInterpolation(sampler.interpolation);
        for (const glm::dvec4& t : readKeyValues(model, sampler.input, "input", TINYGLTF_TYPE_SCALAR, false))
            out.times.push_back(t.x);
        const bool rotation = property == AnimatedProperty::Rotation;
        out.values = readKeyValues(model, sampler.output, "output",
                                   rotation ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3, rotation);
        checkChannel(out);
    } catch (const Error& e) {
        throw e.withContext("sampler " + std::to_string(channel.sampler));
    }
    return out;
}

}  // namespace

std::vector<Animation> readAnimations(Context& ctx) {
    const tinygltf::Model& model = ctx.model;
    std::vector<Animation> animations;
    for (std::size_t a = 0; a < model.animations.size(); ++a) {
        const tinygltf::Animation& animation = model.animations[a];
        const std::string label = elementName("animation", static_cast<int>(a), animation.name);
        Animation out;
        out.name = animation.name;
        std::set<std::pair<int, AnimatedProperty>> targets;
        for (std::size_t c = 0; c < animation.channels.size(); ++c) {
            const tinygltf::AnimationChannel& channel = animation.channels[c];
            const std::string channelLabel = label + " channel " + std::to_string(c);
            try {
                if (channel.target_node < 0) {  // targets defined by extensions (§3.11.1)
                    ctx.unsupported("animation channels without a target node");
                    continue;
                }
                if (static_cast<std::size_t>(channel.target_node) >= model.nodes.size())
                    throw Error("target node " + std::to_string(channel.target_node) +
                                " out of range (file has " + std::to_string(model.nodes.size()) + " nodes)");
                AnimatedProperty property;
                if (channel.target_path == "translation")
                    property = AnimatedProperty::Translation;
                else if (channel.target_path == "rotation")
                    property = AnimatedProperty::Rotation;
                else if (channel.target_path == "scale")
                    property = AnimatedProperty::Scale;
                else if (channel.target_path == "weights") {
                    ctx.unsupported("morph target weight animation (meshes keep their base shape)");
                    continue;
                } else
                    throw Error("target path '" + channel.target_path +
                                "' is not translation, rotation, scale or weights");
                if (!targets.emplace(channel.target_node, property).second)
                    throw Error(
                        "targets node " + std::to_string(channel.target_node) + " " + propertyName(property) +
                        ", which an earlier channel of the animation targets already (glTF 2.0 §3.11: "
                        "each target at most once per animation)");
                out.channels.push_back(readChannel(model, animation, channel, property));
            } catch (const Error& e) {
                throw e.withContext(channelLabel);
            }
        }
        animations.push_back(std::move(out));
    }
    return animations;
}

}  // namespace gdpt::gltf
