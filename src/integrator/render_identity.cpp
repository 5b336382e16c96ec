#include "integrator/render_identity.h"

#include <cstdio>
#include <vector>

#include "integrator/integrator.h"
#include "util/fnv1a.h"

namespace gdpt {

std::string exactFloat(float v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", static_cast<double>(v));
    return buf;
}

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

ExrAttributes renderIdentity(const Integrator& integrator, const Scene& scene, const RenderOptions& options) {
    const SceneGpuOptions& so = options.scene;
    const glm::vec3 env = so.envRadiance;
    const std::uint32_t maxBatch =
        options.maxBatchSpp ? options.maxBatchSpp : integrator.maxBatchSpp(so.width, so.height);
    ExrAttributes id = {{"scene_fingerprint", hex(sceneFingerprint(scene))},
                        {"method", integrator.name()},
                        {"width", std::to_string(so.width)},
                        {"height", std::to_string(so.height)},
                        {"seed", std::to_string(options.seed)},
                        {"max_depth", std::to_string(so.maxDepth)},
                        {"env", exactFloat(env.x) + "," + exactFloat(env.y) + "," + exactFloat(env.z)},
                        {"camera", std::to_string(so.camera)},
                        // One kernel schedule exists; the key stays so that checkpoints
                        // written when there were two still resume.
                        {"schedule", "megakernel"},
                        {"max_batch_spp", std::to_string(maxBatch)},
                        {"emitter_supersampling", std::to_string(options.emitterSupersampling)}};
    for (auto& [key, value] : integrator.identity(scene, options)) id[key] = value;
    // A part of a split render takes other samples than the whole render (sample_share.h).
    if (options.share.split()) id["share"] = options.share.text();
    return id;
}

}  // namespace gdpt
