// render_identity.h — what identifies a render for a checkpoint (everything that changes the
// estimator or its random streams), so that a resumed run continues the same estimate or
// refuses with an error naming the difference.
#pragma once

#include <cstdint>
#include <string>

#include "image/exr_io.h"
#include "integrator/render_options.h"
#include "scene/scene.h"

namespace gdpt {

class Integrator;

// FNV-1a over the loaded scene: geometry, materials, textures, lights and cameras (so a
// change in a referenced .bin or image file counts, and re-saving the same glTF does not).
std::uint64_t sceneFingerprint(const Scene& scene);

// The identity a checkpoint records and a resume must match: scene fingerprint, method,
// image size, seed, max depth, environment, camera, largest batch, emitter supersampling,
// and the method's own (Integrator::identity; G-PT: shift threshold, edge samples,
// demodulation), and the part of a split render ("share" = "I/N", sample_share.h). Workgroup
// size, device and output options are not part of it.
ExrAttributes renderIdentity(const Integrator& integrator, const Scene& scene, const RenderOptions& options);

// Shortest text that reads back as the same float.
std::string exactFloat(float v);

}  // namespace gdpt
