#include "app/render_checkpoint.h"

#include <cstdio>
#include <vector>

#include "render/gpt_renderer.h"

namespace gdpt {
namespace {

class Fnv1a {
public:
    void bytes(const void* data, std::size_t n) {
        const auto* p = static_cast<const unsigned char*>(data);
        for (std::size_t i = 0; i < n; ++i) hash_ = (hash_ ^ p[i]) * 1099511628211ull;
    }
    template <typename T>
    void vector(const std::vector<T>& v) {
        const std::uint64_t n = v.size();
        bytes(&n, sizeof n);  // so that moving an element between arrays changes the hash
        if (!v.empty()) bytes(v.data(), v.size() * sizeof(T));
    }
    template <typename T>
    void value(const T& v) {
        bytes(&v, sizeof v);
    }
    [[nodiscard]] std::uint64_t hash() const { return hash_; }

private:
    std::uint64_t hash_ = 1469598103934665603ull;
};

std::string hex(std::uint64_t v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
    return buf;
}

// Shortest text that reads back as the same float.
std::string exact(float v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", static_cast<double>(v));
    return buf;
}

}  // namespace

std::uint64_t sceneFingerprint(const Scene& scene) {
    // Every hashed type is a packed array of 32-bit scalars (the gpu:: structs are pinned
    // by static_asserts to their scalar layout), so no padding bytes enter the hash.
    Fnv1a h;
    h.vector(scene.positions);
    h.vector(scene.normals);
    h.vector(scene.uvs);
    h.vector(scene.triangles);
    h.vector(scene.triangleMaterial);
    h.vector(scene.materials);
    h.vector(scene.punctualLights);
    for (const Texture& t : scene.textures) {
        h.value(t.width);
        h.value(t.height);
        h.vector(t.texels);
    }
    for (const Camera& c : scene.cameras) {
        h.value(c.position);
        h.value(c.forward);
        h.value(c.up);
        h.value(c.yfov);
        h.value(c.aspectRatio);
    }
    return h.hash();
}

ExrAttributes renderIdentity(const RenderArgs& args, const Scene& scene, std::uint32_t maxBatchSpp) {
    const glm::vec3 env = parseColor(args.env, "--env");
    ExrAttributes id = {{"scene_fingerprint", hex(sceneFingerprint(scene))},
                        {"method", args.method},
                        {"width", std::to_string(args.width)},
                        {"height", std::to_string(args.height)},
                        {"seed", std::to_string(args.seed)},
                        {"max_depth", std::to_string(args.maxDepth)},
                        {"env", exact(env.x) + "," + exact(env.y) + "," + exact(env.z)},
                        {"camera", std::to_string(args.camera)},
                        {"schedule", args.schedule},
                        {"max_batch_spp", std::to_string(maxBatchSpp)},
                        {"emitter_supersampling", std::to_string(args.emitterSupersampling)}};
    if (args.method == "gpt") {
        id["shift_threshold"] = exact(args.shiftThreshold);
        id["edge_samples"] = std::to_string(args.edgeSamples);
        id["demodulate"] = demodulates(scene, parseDemodulation(args.demodulate)) ? "on" : "off";
    }
    return id;
}

}  // namespace gdpt
