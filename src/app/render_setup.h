// render_setup.h — what `gdpt render` needs for every image it renders, whether one or a
// sequence of frames (render_command.cpp, sequence_command.cpp): the integrator and render
// options from the command line, the usage checks, the output names and the JSON summary.
#pragma once

#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "app/cli.h"
#include "integrator/integrator.h"
#include "vk/timing.h"

namespace gdpt {

class ReconTimeCache;
namespace vk {
class Context;
}

// The PNG preview beside an EXR: its path with the extension replaced by .png.
std::string previewPath(const std::string& exrPath);

// --profile: GPU time per kernel on stderr.
void printProfile(const std::map<std::string, vk::KernelTime>& kernels);

// The integrator of args.method with the method options from the command line; timed renders
// remember reconstruction times in `cache`.
std::unique_ptr<Integrator> integratorFor(const RenderArgs& args, const ReconTimeCache* cache);

// The render options of the command line (image, sampling, budget, cancellation by SIGINT).
RenderOptions renderOptionsFor(const RenderArgs& args);

// A render's JSON summary (--json): settings, times, counters, kernels, memory, the method's
// own keys.
// Throws gdpt::Error, before any work, if a PT or G-PT render of args.width x args.height
// would need more memory than the machine has (imageMemoryRefusal against physicalMemory),
// naming the largest image of the same shape that fits.
void checkImageMemory(const RenderArgs& args);

// --json's "scene_size": the scene's triangles, vertices, textures and texels, its device
// tables' bytes, and those bytes and the process's peak resident set per triangle.
nlohmann::json sceneSizeJson(const Scene& scene, const RenderStats& s, double hostPeakBytes);

nlohmann::json summaryJson(const RenderArgs& args, const vk::Context& ctx, const Integrator& integrator,
                           const RenderStats& s, double seconds, double reserved, double finishReserved,
                           double writeMs);

// The warnings about a loaded scene, on stderr: what the file holds that is not rendered, and
// that the image would be black (nothing emits).
void warnAboutScene(const std::string& path, const Scene& scene, glm::vec3 envRadiance);

// A render's exit status once its outputs are written: 1 (said on stderr) if Vulkan validation
// reported errors, else 0.
int validationExitStatus(const vk::Context& ctx);

// Usage errors that the option checks alone cannot see (throws gdpt::UsageError, exit 2,
// before any work).
void checkArgs(const RenderArgs& args);
// --recon auto: the method's default reconstruction, l1 for gmlt (its chains give no per-pixel
// variances) and tgpt (its space-time solve's default); for gpt `auto` stays, the scene's choice
// at render time (gpt_reconstruction.h: wl1, or wl2 where some vertex is glossy); any other value
// as it is.
std::string resolvedRecon(const std::string& method, const std::string& recon);
// The reconstruction a render's recorded settings name (a shard's, which gdpt merge
// reconstructs with): resolvedRecon's, with gpt's auto as the scene chose it.
std::string recordedRecon(const RenderArgs& args, const SceneFeatures& features);

}  // namespace gdpt
