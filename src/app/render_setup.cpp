// render_setup.cpp — see render_setup.h.
#include "app/render_setup.h"

#include <sys/resource.h>

#include <cstdio>

#include "app/bench_util.h"
#include "integrator/gpt_reconstruction.h"
#include "integrator/recon_reserve.h"
#include "render/passes/edge_options.h"
#include "render/passes/pixel_buffers.h"
#include "scene/light_sources.h"
#include "util/error.h"
#include "util/interrupt.h"
#include "util/memory.h"
#include "vk/context.h"
#include "vk/spirv_specialise.h"

namespace gdpt {
namespace {

using nlohmann::json;

json kernelJson(const std::map<std::string, vk::KernelTime>& kernels, double frameMs) {
    json k = json::object();
    for (const auto& [name, t] : kernels)
        k[name] = {{"count", t.count},
                   {"total_ms", t.totalMs},
                   {"ms_per_call", t.count ? t.totalMs / double(t.count) : 0.0},
                   {"share", frameMs > 0 ? t.totalMs / frameMs : 0.0}};
    return k;
}

// Peak memory: the process's resident set (getrusage) and gdpt's device allocations; per
// megapixel of the image, which is how they grow (fixed costs, e.g. the scene, included).
json memoryJson(const vk::Context& ctx, int width, int height) {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    const double host = double(usage.ru_maxrss) * 1024.0;  // Linux reports KiB
    const double device = double(ctx.deviceBytesPeak());
    const double megapixels = double(width) * double(height) * 1e-6;
    return {{"host_peak_bytes", host},
            {"device_peak_bytes", device},
            {"megapixels", megapixels},
            {"host_peak_bytes_per_megapixel", host / megapixels},
            {"device_peak_bytes_per_megapixel", device / megapixels}};
}

}  // namespace

void checkImageMemory(const RenderArgs& args) {
    const std::string refusal = imageMemoryRefusal(args.method, static_cast<std::uint32_t>(args.width),
                                                   static_cast<std::uint32_t>(args.height), physicalMemory());
    if (!refusal.empty()) throw Error(refusal);
}

json sceneSizeJson(const Scene& scene, const RenderStats& s, double hostPeakBytes) {
    std::uint64_t texels = 0;
    for (const Texture& t : scene.textures) texels += t.texels.size();
    const double triangles = double(std::max<std::size_t>(scene.triangles.size(), 1));
    return {{"triangles", scene.triangles.size()},
            {"vertices", scene.positions.size()},
            {"textures", scene.textures.size()},
            {"texels", texels},
            {"device_bytes", s.sceneDeviceBytes},
            {"device_bytes_per_triangle", double(s.sceneDeviceBytes) / triangles},
            {"host_peak_bytes_per_triangle", hostPeakBytes / triangles}};
}

std::string previewPath(const std::string& exrPath) {
    const auto dot = exrPath.rfind('.');
    const auto slash = exrPath.rfind('/');
    const bool hasExt = dot != std::string::npos && (slash == std::string::npos || dot > slash);
    return (hasExt ? exrPath.substr(0, dot) : exrPath) + ".png";
}

void printProfile(const std::map<std::string, vk::KernelTime>& kernels) {
    double total = 0.0;
    for (const auto& [name, t] : kernels) total += t.totalMs;
    std::fprintf(stderr, "%-24s %8s %12s %12s %7s\n", "kernel", "count", "total ms", "ms/call", "share");
    for (const auto& [name, t] : kernels)
        std::fprintf(stderr, "%-24s %8llu %12.3f %12.3f %6.1f%%\n", name.c_str(),
                     static_cast<unsigned long long>(t.count), t.totalMs,
                     t.count ? t.totalMs / double(t.count) : 0.0,
                     total > 0 ? 100.0 * t.totalMs / total : 0.0);
}

// The integrator of args.method with the method options from the command line.
std::unique_ptr<Integrator> integratorFor(const RenderArgs& args, const ReconTimeCache* cache) {
    MethodOptions m;
    GptOptions& g = m.gpt;
    g.sampling.splitBounce = args.splitBounce == "on"    ? GptPassOptions::SplitBounce::On
                             : args.splitBounce == "off" ? GptPassOptions::SplitBounce::Off
                                                         : GptPassOptions::SplitBounce::Auto;
    m.mlt.splitBounce = g.sampling.splitBounce;
    g.sampling.edgeSamples = parseEdgeSamples(args.edgeSamples, "--edge-samples");
    g.sampling.demodulate = parseDemodulation(args.demodulate);
    // --recon auto (resolvedRecon keeps it for gpt): the scene's choice, made at render time
    // (gpt_reconstruction.h); GptOptions' first reconstruction holds its place until then.
    g.reconstructionByScene = args.recon == "auto";
    if (!g.reconstructionByScene) g.reconstructions = {parseReconstruction(args.recon)};
    if (args.allRecon)
        for (const Reconstruction other :
             {Reconstruction::L1, Reconstruction::L2, Reconstruction::WeightedL2, Reconstruction::WeightedL1})
            if (other != g.reconstructions.front()) g.reconstructions.push_back(other);
    if (args.alpha >= 0.0) g.alpha = args.alpha;
    g.tolerance = args.tolerance;
    g.debiasCells = args.debiasCells;
    g.solver = parseSolverChoice(args.solver);
    MltOptions& mlt = m.mlt;
    mlt.chains = args.chains;
    mlt.largeStep = args.largeStep;
    mlt.targetExponent = args.targetExponent;
    mlt.targetBlock = args.targetBlock;
    mlt.targetAlpha = args.targetAlpha;
    const std::string mltRecon = resolvedRecon("gmlt", args.recon);
    mlt.reconstructions = {parseReconstruction(mltRecon)};
    if (args.allRecon && mltRecon != "l2") mlt.reconstructions.push_back(Reconstruction::L2);
    if (args.allRecon && mltRecon != "l1") mlt.reconstructions.push_back(Reconstruction::L1);
    if (args.alpha >= 0.0) mlt.alpha = args.alpha;
    mlt.tolerance = args.tolerance;
    mlt.solver = parseSolverChoice(args.solver);
    TgptOptions& t = m.tgpt;
    t.sampling = g.sampling;
    t.window = args.window;
    t.l1 = args.recon == "l1" || args.recon == "wl1";
    t.weighted = args.recon == "wl1" || args.recon == "wl2";
    if (args.alpha >= 0.0) t.alpha = args.alpha;
    t.beta = args.beta;
    t.shift = parseTemporalShift(args.temporalShift);
    t.gamma = args.gamma >= 0.0 ? args.gamma : t.shift == TemporalShift::Reconnect ? 0.0 : 1.0;
    t.tolerance = args.tolerance;
    // Timed renders remember each configuration's reconstruction time.
    if (args.time > 0.0) g.reconCache = cache;
    return makeIntegrator(args.method, m);
}

RenderOptions renderOptionsFor(const RenderArgs& args) {
    RenderOptions o;
    o.scene.width = args.width;
    o.scene.height = args.height;
    o.scene.maxDepth = args.maxDepth;
    o.scene.envRadiance = parseColor(args.env, "--env");
    o.scene.camera = args.camera;
    o.scene.shiftThreshold = args.shiftThreshold;
    const std::optional<LightSelection> selection = parseLightSelection(args.lightSelection);
    if (!selection)
        throw Error("--light-selection: '" + args.lightSelection + "' is not power, uniform, mixed or probe");
    o.scene.lightSelection = *selection;
    o.spp = args.spp;
    o.timeBudget = args.time;
    o.seed = args.seed;
    o.profile = args.profile;
    o.quiet = args.quiet;
    o.scene.quiet = args.quiet;
    o.workgroup = parseWorkgroup(args.workgroup);
    o.emitterSupersampling = args.emitterSupersampling;
    o.cancel = &interruptFlag();
    return o;
}

namespace {

// Who folds the kernels' specialisation constants (vk/spirv_specialise.h), and where gdpt's
// modules came from.
json specialisationJson(const vk::Context& ctx) {
    const vk::SpecialiseCounts c = vk::specialiseCounts();
    return {{"by", vk::useSpecialisedSpirv(ctx.info()) ? "gdpt" : "driver"},
            {"from_cache", c.fromCache},
            {"by_optimizer", c.byOptimizer}};
}

}  // namespace

json summaryJson(const RenderArgs& args, const vk::Context& ctx, const Integrator& integrator,
                 const RenderStats& s, double seconds, double reserved, double finishReserved,
                 double writeMs) {
    json j = {{"scene", args.scene},
              {"output", args.output},
              {"method", args.method},
              {"device", ctx.info().name},
              {"driver", ctx.info().driverInfo},
              {"width", args.width},
              {"height", args.height},
              {"spp", s.spp},
              {"partial_pass_rows", s.partialPassRows},
              {"seed", args.seed},
              {"batches", s.batches},
              {"bvh_register_stack", s.bvhRegisterStack},
              {"bvh_steps", s.bvhUnitSteps ? "units" : "nodes"},
              {"light_selection", args.lightSelection},
              {"kernels_specialised", specialisationJson(ctx)},
              {"time_s",
               {{"total", seconds},
                {"bvh_build", s.bvhBuildMs * 1e-3},
                {"upload", s.uploadMs * 1e-3},
                {"pipeline_wait", s.pipelineWaitMs * 1e-3},
                {"kernel_compile", s.compileMs * 1e-3},
                {"setup", s.setupSeconds},
                {"sampling", s.samplingMs * 1e-3},
                {"readback", s.readbackMs * 1e-3},
                {"reconstruction", s.reconstructionMs * 1e-3},
                {"reconstruction_reserved", reserved},
                {"finish_reserved", finishReserved},
                {"write", writeMs * 1e-3}}},
              {"rays_traced", s.raysTraced},
              {"paths_completed", s.pathsCompleted},
              {"nan_samples", s.nanSamples},
              {"shift_pairs", s.shiftPairs},
              {"shift_failures", s.shiftFailures},
              {"shift_failure_rate", s.shiftPairs ? double(s.shiftFailures) / double(s.shiftPairs) : 0.0},
              {"rays_per_s", double(s.raysTraced) / (s.samplingMs * 1e-3)},
              {"samples_per_s", double(s.pathsCompleted) / (s.samplingMs * 1e-3)},
              {"kernels", kernelJson(s.kernels, s.samplingMs)},
              {"validation_errors", ctx.validationErrors()},
              {"memory", memoryJson(ctx, args.width, args.height)}};
    if (s.distributed.parts > 1)
        j["distributed"] = {{"parts", s.distributed.parts},
                            {"part_spp", s.distributed.partSpp},
                            {"bytes_per_part", s.distributed.bytesPerPart},
                            {"merge_s", s.distributed.mergeMs * 1e-3},
                            {"wait_s", s.distributed.waitMs * 1e-3}};
    integrator.describe(j, s);
    j["light_probe"] = s.lightProbed;
    json shares = json::array();
    for (const auto& [material, probability] : s.lightShares)
        shares.push_back({{"material", material}, {"probability", probability}});
    j["light_shares"] = shares;
    j["emitter_supersampling"] = {{"factor", s.emitterSupersampling},
                                  {"rays_per_sample", s.emitterRaysPerSample},
                                  {"pixels", s.emitterSupersampledPixels}};
    return j;
}

void warnAboutScene(const std::string& path, const Scene& scene, glm::vec3 envRadiance) {
    if (!scene.unsupported.empty()) {
        std::string list;
        for (const auto& u : scene.unsupported) list += (list.empty() ? "" : "; ") + u;
        std::fprintf(stderr, "gdpt: warning: %s: not rendered: %s\n", path.c_str(), list.c_str());
    }
    if (const auto black = blackImageWarning(scene, envRadiance))
        std::fprintf(stderr, "gdpt: warning: %s\n", black->c_str());
}

int validationExitStatus(const vk::Context& ctx) {
    if (ctx.validationErrors() == 0) return 0;
    std::fprintf(stderr, "gdpt: error: %u Vulkan validation error(s)\n", ctx.validationErrors());
    return 1;
}

std::string resolvedRecon(const std::string& method, const std::string& recon) {
    if (recon != "auto" || method == "gpt") return recon;
    return "l1";
}

std::string recordedRecon(const RenderArgs& args, const SceneFeatures& features) {
    const std::string recon = resolvedRecon(args.method, args.recon);
    if (recon != "auto") return recon;
    return toString(gptDefaultReconstruction(gptSurfaces(features)));
}

// Usage errors that the option checks alone cannot see (exit 2 before any work).
void checkArgs(const RenderArgs& args) {
    // (auto for gpt: wl1 on most scenes.)
    const bool l1 = args.recon == "l1" || args.recon == "wl1" || args.recon == "auto" || args.allRecon;
    const bool mlt = args.method == "pssmlt" || args.method == "gmlt";
    if (mlt && (!args.checkpoint.empty() || !args.resume.empty() || !args.shard.empty()))
        throw UsageError(
            "--method " + args.method +
            " keeps its state in its Markov chains: --checkpoint, --resume and --shard are for pt "
            "and gpt");
    if (args.method == "gmlt" && (args.recon == "wl1" || args.recon == "wl2"))
        throw UsageError(
            "--recon " + args.recon +
            " weights by per-pixel variances, which the correlated samples of Markov chains do not "
            "give; --method gmlt reconstructs with l1 or l2");
    if (args.method == "tgpt") {
        if (args.frames.empty())
            throw UsageError(
                "--method tgpt renders a sequence (temporal differences between frames): add --frames A:B");
        if (args.allRecon)
            throw UsageError(
                "--method tgpt reconstructs with one --recon (l1, l2, wl1 or wl2): one space-time solve per "
                "window");
        if (args.demodulate == "on")
            throw UsageError(
                "--method tgpt does not demodulate (a frame's texture modulation differs from the next one's "
                "where something moves)");
    }
    if ((args.method == "gpt" || args.method == "gmlt" || args.method == "tgpt") && l1 && args.alpha == 0.0)
        throw UsageError(
            "--alpha " + std::to_string(args.alpha) +
            ": the L1 reconstructions (--recon l1 or wl1, G-PT's auto, or --all-recon) need --alpha > 0 (the "
            "primal term anchors each reweighted solve); use --recon l2 for alpha 0");
}

}  // namespace gdpt
