// render_checkpoint.h — `gdpt render --checkpoint/--resume`: what identifies a render for a
// checkpoint (everything that changes the estimator or its random streams), so that a
// resumed run continues the same estimate or refuses with an error naming the difference.
#pragma once

#include <cstdint>
#include <string>

#include "app/cli.h"
#include "image/exr_io.h"
#include "scene/scene.h"

namespace gdpt {

// FNV-1a over the loaded scene: geometry, materials, textures, lights and cameras (so a
// change in a referenced .bin or image file counts, and re-saving the same glTF does not).
std::uint64_t sceneFingerprint(const Scene& scene);

// The identity a checkpoint records and a resume must match: scene fingerprint, method,
// image size, seed, max depth, environment, camera, schedule, largest batch and (G-PT) the
// shift threshold. Workgroup size, device and output options are not part of it.
ExrAttributes renderIdentity(const RenderArgs& args, const Scene& scene, std::uint32_t maxBatchSpp);

}  // namespace gdpt
