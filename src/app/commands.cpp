#include "app/commands.h"

#include <memory>

#include "app/bench_util.h"
#include "app/recon_reserve.h"
#include "app/subcommand.h"

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "app/render_checkpoint.h"
#include "image/exr_io.h"
#include "image/metrics.h"
#include "image/png_preview.h"
#include "render/checkpoint.h"
#include "render/features.h"
#include "poisson/poisson_gpu.h"
#include "render/gpt_renderer.h"
#include "render/renderer.h"
#include "scene/gltf_loader.h"
#include "scene/light_sources.h"
#include "util/error.h"
#include "util/timer.h"
#include "vk/context.h"

namespace gdpt {
namespace {

using nlohmann::json;

// Set by SIGINT/SIGTERM; the render loops stop at the next batch boundary.
std::atomic<bool> gInterrupted{false};

extern "C" void onInterrupt(int) { gInterrupted.store(true); }

WorkgroupSize parseWorkgroup(const std::string& text) {
    unsigned x = 0, y = 0;
    char sep = 0;
    std::istringstream in(text);
    if (!(in >> x >> sep >> y) || sep != 'x' || x == 0 || y == 0 || x * y > 1024)
        throw UsageError("--workgroup '" + text + "' must be WxH with W*H <= 1024, e.g. 8x8");
    return {x, y};
}

std::string previewPath(const std::string& exrPath) {
    const auto dot = exrPath.rfind('.');
    const auto slash = exrPath.rfind('/');
    const bool hasExt = dot != std::string::npos && (slash == std::string::npos || dot > slash);
    return (hasExt ? exrPath.substr(0, dot) : exrPath) + ".png";
}

json kernelJson(const std::map<std::string, vk::KernelTime>& kernels, double frameMs) {
    json k = json::object();
    for (const auto& [name, t] : kernels)
        k[name] = {{"count", t.count},
                   {"total_ms", t.totalMs},
                   {"ms_per_call", t.count ? t.totalMs / double(t.count) : 0.0},
                   {"share", frameMs > 0 ? t.totalMs / frameMs : 0.0}};
    return k;
}

void printProfile(const std::map<std::string, vk::KernelTime>& kernels) {
    double total = 0.0;
    for (const auto& [name, t] : kernels) total += t.totalMs;
    std::fprintf(stderr, "%-24s %8s %12s %12s %7s\n", "kernel", "count", "total ms", "ms/call", "share");
    for (const auto& [name, t] : kernels)
        std::fprintf(stderr, "%-24s %8llu %12.3f %12.3f %6.1f%%\n", name.c_str(),
                     static_cast<unsigned long long>(t.count), t.totalMs, t.count ? t.totalMs / double(t.count) : 0.0,
                     total > 0 ? 100.0 * t.totalMs / total : 0.0);
}

}  // namespace

glm::vec3 parseColor(const std::string& text, const std::string& flag) {
    std::vector<float> v;
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) {
        try {
            std::size_t used = 0;
            const float f = std::stof(item, &used);
            if (used != item.size() || !(f >= 0.0f) || f > 3.0e38f) throw std::invalid_argument(item);
            v.push_back(f);
        } catch (const std::exception&) {
            throw UsageError(flag + " '" + text + "': expected R,G,B with finite non-negative numbers");
        }
    }
    if (v.size() == 1) return glm::vec3(v[0]);
    if (v.size() != 3) throw UsageError(flag + " '" + text + "': expected R,G,B");
    return {v[0], v[1], v[2]};
}

int runRender(const RenderArgs& args) {
    Timer total;
    RenderOptions options;
    options.scene.width = args.width;
    options.scene.height = args.height;
    options.scene.maxDepth = args.maxDepth;
    options.scene.envRadiance = parseColor(args.env, "--env");
    options.scene.camera = args.camera;
    options.spp = args.spp;
    options.timeBudget = args.time;
    options.seed = args.seed;
    options.profile = args.profile;
    options.quiet = args.quiet;
    options.workgroup = parseWorkgroup(args.workgroup);
    options.schedule = args.schedule == "wavefront" ? Schedule::Wavefront : Schedule::Megakernel;
    options.visibleSupersampling = args.emitterSupersampling;
    options.edgeSamples = args.edgeSamples;
    options.demodulate = parseDemodulation(args.demodulate);

    Scene scene = loadGltf(args.scene);
    if (!scene.unsupported.empty() && !args.quiet) {
        std::string list;
        for (const auto& u : scene.unsupported) list += (list.empty() ? "" : "; ") + u;
        std::fprintf(stderr, "gdpt: warning: %s: not rendered: %s\n", args.scene.c_str(), list.c_str());
    }
    if (const auto black = blackImageWarning(scene, options.scene.envRadiance); black && !args.quiet)
        std::fprintf(stderr, "gdpt: warning: %s\n", black->c_str());
    vk::ContextOptions ctxOptions;
    ctxOptions.device = args.device;
    ctxOptions.validation = args.validate;
    vk::Context ctx(ctxOptions);
    if (!args.quiet)
        std::fprintf(stderr, "gdpt: device '%s' (%s, %s)\n", ctx.info().name.c_str(), ctx.info().type.c_str(),
                     ctx.info().driverInfo.c_str());
    // G-PT with --time: the reconstructions after sampling are part of the budget, so
    // sampling stops early by their expected time (remembered from the last render of this
    // configuration, else measured now on a synthetic problem; recon_reserve.h).
    const bool gpt = args.method == "gpt";
    std::vector<std::string> recons = {args.recon};
    if (args.allRecon)
        for (const char* other : {"l1", "l2", "wl2", "wl1"})
            if (args.recon != other) recons.push_back(other);
    std::vector<SolveOptions> solves;
    for (const std::string& name : recons) {
        SolveOptions so;
        so.method = parseReconstruction(name);
        so.alpha = args.alpha;
        so.tolerance = args.tolerance;
        solves.push_back(so);
    }
    std::unique_ptr<PoissonSolverGpu> solver;
    if (gpt) solver = std::make_unique<PoissonSolverGpu>(ctx, args.width, args.height);
    const ReconTimeCache reconCache(ReconTimeCache::defaultPath());
    ReconReservation reserve;
    if (gpt && args.time > 0.0) reserve = reserveReconstruction(ctx, *solver, solves, reconCache);
    // The rest after sampling (resolve and readback, output layers, EXR + PNG) is waited for
    // too: reserve what it took the last time for this device, method, size and solves (the
    // first run of a configuration reserves nothing for it).
    const std::string finishKey = "finish|" + reservationKey(ctx, args.width, args.height) + "|" + args.method +
                                  (gpt ? "|" + std::to_string(recons.size()) + " solves" : "");
    const double finishReserved = args.time > 0.0 ? reconCache.get(finishKey).value_or(0.0) : 0.0;
    if (args.time > 0.0)
        options.timeBudget = std::max(0.05 * args.time, args.time - reserve.seconds - finishReserved);
    // The reconstruction's pipelines are created while the path kernels compile.
    if (gpt) options.whileCompiling = [&] { solver->preparePipelines(solves); };
    options.elapsedBefore = total.seconds();
    options.scene.shiftThreshold = args.shiftThreshold;
    options.maxBatchSpp = batchLimit(args.width, args.height, gpt);
    options.cancel = &gInterrupted;

    // Checkpoints: the identity of this render is recorded in every checkpoint written, and a
    // checkpoint resumed from must have the same (render_checkpoint.h).
    const ExrAttributes identity = renderIdentity(args, scene, options.maxBatchSpp);
    std::optional<Checkpoint> resumed;
    if (!args.resume.empty()) {
        resumed = readCheckpoint(args.resume);
        checkIdentity(args.resume, resumed->identity, identity);
        if (args.time <= 0.0 && resumed->state.spp > args.spp)
            throw Error(args.resume + ": checkpoint already has " + std::to_string(resumed->state.spp) +
                        " spp, more than --spp " + std::to_string(args.spp));
        if (!args.quiet && resumed->info.count("device") && resumed->info["device"] != ctx.info().name)
            std::fprintf(stderr,
                         "gdpt: warning: %s was rendered on '%s'; continuing on '%s' (same statistics, "
                         "not the same bits)\n",
                         args.resume.c_str(), resumed->info["device"].c_str(), ctx.info().name.c_str());
        options.resume = &resumed->state;
    }
    if (!args.checkpoint.empty()) {
        const ExrAttributes info = {{"device", ctx.info().name}, {"scene_file", args.scene}};
        options.checkpoint = [&args, identity, info](const SamplerState& state) {
            writeCheckpoint(args.checkpoint, identity, info, state);
        };
        options.checkpointEvery = args.checkpointEvery;
    }
    std::signal(SIGINT, onInterrupt);
    std::signal(SIGTERM, onInterrupt);

    // Sample, then assemble the output layers. PT: the image and its variance. G-PT: the
    // final image in the default channels (primal + direct until a reconstruction is
    // chosen), plus every buffer the sampler produced as a named layer.
    std::vector<NamedLayer> layers;
    RenderStats stats;
    double afterSampling = 0.0;  // total.seconds() when the batch loop ended (about)
    if (args.method == "gpt") {
        GptPassOptions gptOptions;
        gptOptions.shiftThreshold = args.shiftThreshold;
        gptOptions.splitBounce = args.splitBounce == "on"    ? GptPassOptions::SplitBounce::On
                                 : args.splitBounce == "off" ? GptPassOptions::SplitBounce::Off
                                                             : GptPassOptions::SplitBounce::Auto;
        RenderResultGpt g = renderGpt(ctx, scene, options, gptOptions);
        afterSampling = total.seconds() - g.stats.readbackMs * 1e-3;
        stats = g.stats;
        // Screened Poisson reconstruction of the indirect image from primal + gradients;
        // the final image is reconstruction + very-direct light (Kettunen et al. 2015 §5).
        PoissonInput input;
        input.primal = &g.primal;
        input.dx = &g.dx;
        input.dy = &g.dy;
        input.varPrimal = &g.varPrimal;
        input.varDx = &g.varDx;
        input.varDy = &g.varDy;
        auto solve = [&](std::size_t k) {
            const std::string& name = recons[k];
            Image recon;
            const SolveReport report = solver->solve(input, solves[k], recon);
            if (!args.quiet)
                std::fprintf(stderr, "gdpt: %s reconstruction: %d iterations (%d IRLS), residual %.2g, %.1f ms\n",
                             name.c_str(), report.iterations, report.irlsIterations, report.residual, report.ms);
            stats.reconstructionMs += report.ms;
            return recon;
        };
        const Image recon = solve(0);
        layers = {{"", gptFinal(g, recon)}, {"recon_" + args.recon, recon}};
        for (std::size_t k = 1; k < recons.size(); ++k) layers.push_back({"recon_" + recons[k], solve(k)});
        if (!reserve.key.empty()) reconCache.put(reserve.key, stats.reconstructionMs * 1e-3);
        const std::vector<NamedLayer> buffers = {
            {"primal", g.primal}, {"dx", g.dx},         {"dy", g.dy},         {"direct", g.direct},
            {"var_primal", g.varPrimal}, {"var_dx", g.varDx}, {"var_dy", g.varDy}, {"var_direct", g.varDirect},
            {"primal_plus_direct", gptFinal(g, g.primal)}};
        layers.insert(layers.end(), buffers.begin(), buffers.end());
        if (g.stats.demodulated) layers.push_back({"modulation", g.modulation});
    } else {
        RenderResult r = renderPt(ctx, scene, options);
        afterSampling = total.seconds() - r.stats.readbackMs * 1e-3;
        layers = {{"", r.image}, {"variance", r.varianceOfMean}};
        stats = r.stats;
    }

    if (stats.cancelled) {
        if (args.checkpoint.empty())
            std::fprintf(stderr, "gdpt: interrupted after %u spp; no output written\n", stats.spp);
        else
            std::fprintf(
                stderr,
                "gdpt: interrupted after %u spp; checkpoint written to %s (continue with --resume %s)\n",
                stats.spp, args.checkpoint.c_str(), args.checkpoint.c_str());
        return 130;
    }
    Timer writeTimer;
    writeExr(args.output, layers);
    writePngPreview(previewPath(args.output), layers.front().image);
    const double writeMs = writeTimer.ms();
    const RenderStats& s = stats;
    const double seconds = total.seconds();
    if (args.time > 0.0) reconCache.put(finishKey, std::max(0.0, seconds - afterSampling - s.reconstructionMs * 1e-3));
    if (args.profile) printProfile(s.kernels);
    if (!args.quiet)
        std::fprintf(stderr,
                     "gdpt: wrote %s (%u spp%s%s%s, %.2f s total, BVH %.1f ms, sampling %.1f ms, %.2f Mrays/s, %.3f Msamples/s)\n",
                     args.output.c_str(), s.spp,
                     s.partialPassRows ? (" + 1 in the top " + std::to_string(s.partialPassRows) + " rows").c_str() : "",
                     s.edgePixels ? (", x" + std::to_string(1 + s.edgeSamples) + " in " + std::to_string(s.edgePixels) +
                                     " edge pixels").c_str()
                                  : "",
                     s.demodulated ? (", demodulated in " + std::to_string(s.demodulatedPixels) + " pixels").c_str() : "",
                     seconds, s.bvhBuildMs, s.samplingMs,
                     double(s.raysTraced) / (s.samplingMs * 1e-3) * 1e-6,
                     double(s.pathsCompleted) / (s.samplingMs * 1e-3) * 1e-6);
    if (!args.json.empty()) {
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
                  {"time_s", {{"total", seconds},
                              {"bvh_build", s.bvhBuildMs * 1e-3},
                              {"upload", s.uploadMs * 1e-3},
                              {"pipeline_wait", s.pipelineWaitMs * 1e-3},
                              {"sampling", s.samplingMs * 1e-3},
                              {"readback", s.readbackMs * 1e-3},
                              {"reconstruction", s.reconstructionMs * 1e-3},
                              {"reconstruction_reserved", reserve.seconds},
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
                  {"validation_errors", ctx.validationErrors()}};
        if (args.method == "gpt") {
            j["gpt_split_bounce"] = s.gptSplitBounce;
            j["edge_samples"] = {{"factor", s.edgeSamples}, {"pixels", s.edgePixels}};
            j["demodulation"] = {{"on", s.demodulated}, {"pixels", s.demodulatedPixels}};
        }
        j["emitter_supersampling"] = {{"factor", s.visibleSupersampling},
                                      {"rays_per_sample", s.visibleRaysPerSample},
                                      {"pixels", s.visibleRefinedPixels}};
        writeTextOutput(args.json, j.dump(2) + "\n");
    }
    if (ctx.validationErrors() > 0) {
        std::fprintf(stderr, "gdpt: error: %u Vulkan validation error(s)\n", ctx.validationErrors());
        return 1;
    }
    return 0;
}

int runDiff(const DiffArgs& args) {
    const Image test = readExrLayer(args.test);
    const Image reference = readExrLayer(args.reference);
    const ImageErrorStats e = compareImages(test, reference);
    json j = {{"test", args.test},
              {"reference", args.reference},
              {"relmse", e.relMse},
              {"mse", e.mse},
              {"mae", e.mae},
              {"max_abs_error", e.maxAbsError},
              {"mean_bias", e.meanBias},
              {"mean_test", e.meanTest},
              {"mean_reference", e.meanReference},
              {"finite_pixels", e.finitePixels},
              {"nonfinite_pixels", e.nonFinitePixels}};
    if (!args.json.empty()) writeTextOutput(args.json, j.dump(2) + "\n");
    if (args.json != "-")
        std::printf("relMSE %.6g  MSE %.6g  MAE %.6g  max %.6g  bias %.3g  (%zu pixels, %zu non-finite)\n", e.relMse,
                    e.mse, e.mae, e.maxAbsError, e.meanBias, e.finitePixels, e.nonFinitePixels);
    return 0;
}

int runInfo(const InfoArgs& args) {
    const Scene scene = loadGltf(args.scene);
    // The features the kernels are specialised for (SceneSpec: the light count is the light
    // table's, without emitters of zero area or power); a scene without triangles has none.
    SceneGpuOptions so;
    so.envRadiance = parseColor(args.env, "--env");
    std::unique_ptr<const SceneSpec> spec;
    if (!scene.triangles.empty()) spec = std::make_unique<const SceneSpec>(scene, so);
    const SceneFeatures f = spec ? spec->features() : analyzeScene(scene, so.envRadiance);
    std::printf("%s\n", describeScene(scene).c_str());
    for (const auto& [k, v] : describeFeatures(f)) std::printf("  %-26s %s\n", k.c_str(), v.c_str());
    // bvhRegisterStack: entries of the register traversal stack when the tree was built before
    // the pipelines (small scenes) and its traversals hold at most kBvhRegisterStackMax
    // (bvh_traverse.glsl); 0 = the stack in memory.
    if (spec && spec->bvh())
        std::printf("  %-26s %u (register stack up to %u)\n", "bvh traversal stack", spec->bvh()->wide.maxStack,
                    gpu::kBvhRegisterStackMax);
    else
        std::printf("  %-26s built with the scene upload (more than %zu triangles)\n", "bvh traversal stack",
                    kSpecBvhTriangles);
    // visibleEmission: emitter-silhouette supersampling (render/visible_pass.h) at the default
    // factor, which needs something the camera can see emit.
    std::printf("kernel variant: pt[textures=%d punctual=%d lightTris=%d env=%d glossy=%d alphaMask=%d "
                "shadingNormals=%d specularLobe=%d visibleEmission=%d bvhRegisterStack=%u]\n",
                f.hasTextures, f.hasPunctual, f.hasLightTris, f.hasEnv, f.hasGlossy, f.hasAlphaMask,
                f.hasShadingNormals, f.hasSpecularLayer, visibleEmissionPossible(f),
                spec ? spec->bvhRegisterStack() : 0u);
    // G-PT's first-hit texture demodulation as --demodulate auto chooses it (gpt_pass.h).
    std::printf("gpt variant: demodulate=%d\n", demodulationApplies(scene) ? 1 : 0);
    for (const auto& u : scene.unsupported) std::printf("  unsupported: %s\n", u.c_str());
    if (const auto black = blackImageWarning(scene, so.envRadiance))
        std::printf("warning: %s\n", black->c_str());
    return 0;
}

int runDevices(const DevicesArgs& args) {
    const auto devices = vk::Context::listDevices();
    json list = json::array();
    for (const auto& d : devices) {
        list.push_back({{"index", d.index},
                        {"name", d.name},
                        {"type", d.type},
                        {"driver", d.driverName},
                        {"driver_info", d.driverInfo},
                        {"api", std::to_string(VK_API_VERSION_MAJOR(d.apiVersion)) + "." +
                                    std::to_string(VK_API_VERSION_MINOR(d.apiVersion)) + "." +
                                    std::to_string(VK_API_VERSION_PATCH(d.apiVersion))},
                        {"max_storage_buffer_range", d.maxStorageBufferRange},
                        {"max_texel_buffer_elements", d.maxTexelBufferElements},
                        {"max_memory_allocation", d.maxMemoryAllocationSize},
                        {"max_push_constants", d.maxPushConstantsSize},
                        {"max_workgroup_invocations", d.maxComputeWorkGroupInvocations},
                        {"shared_memory", d.maxComputeSharedMemorySize},
                        {"subgroup_size", d.subgroupSize},
                        {"timestamps", d.timestamps},
                        {"device_local_heap", d.deviceLocalHeapBytes},
                        {"usable", d.unsuitable.empty()},
                        {"unsuitable_reason", d.unsuitable}});
    }
    if (args.json) {
        std::printf("%s\n", list.dump(2).c_str());
        return 0;
    }
    for (const auto& d : list)
        std::printf("[%u] %s (%s, %s %s)\n    Vulkan %s, maxStorageBufferRange %llu MiB, maxTexelBufferElements %llu Mi, maxMemoryAllocationSize %llu MiB, push constants %u B, "
                    "workgroup %u, shared %u KiB, subgroup %u, timestamps %s, heap %llu MiB%s\n",
                    d["index"].get<unsigned>(), d["name"].get<std::string>().c_str(), d["type"].get<std::string>().c_str(),
                    d["driver"].get<std::string>().c_str(), d["driver_info"].get<std::string>().c_str(),
                    d["api"].get<std::string>().c_str(),
                    static_cast<unsigned long long>(d["max_storage_buffer_range"].get<std::uint64_t>() >> 20),
                    static_cast<unsigned long long>(d["max_texel_buffer_elements"].get<std::uint64_t>() >> 20),
                    static_cast<unsigned long long>(d["max_memory_allocation"].get<std::uint64_t>() >> 20),
                    d["max_push_constants"].get<unsigned>(), d["max_workgroup_invocations"].get<unsigned>(),
                    d["shared_memory"].get<unsigned>() / 1024, d["subgroup_size"].get<unsigned>(),
                    d["timestamps"].get<bool>() ? "yes" : "no",
                    static_cast<unsigned long long>(d["device_local_heap"].get<std::uint64_t>() >> 20),
                    d["usable"].get<bool>() ? "" : (" — unusable: " + d["unsuitable_reason"].get<std::string>()).c_str());
    return 0;
}

// ---- CLI registration ----------------------------------------------------------------

Subcommand addRenderCommand(CLI::App& app) {
    auto args = std::make_shared<RenderArgs>();
    auto& render = *args;
    CLI::App* r = app.add_subcommand("render", "Render a glTF 2.0 scene to OpenEXR (+ PNG preview)");
    r->add_option("scene", render.scene, "glTF 2.0 scene (.gltf or .glb)")->required()->check(InputFile);
    r->add_option("-o,--output", render.output, "Output EXR; a tone-mapped PNG preview is written beside it")
        ->capture_default_str();
    r->add_option("--spp", render.spp, "Samples per pixel")->capture_default_str()->check(CLI::Range(1u, 1u << 24));
    r->add_option("--time", render.time,
                  "Time budget in seconds for the whole render (loading and, for G-PT, the reconstructions included); overrides --spp")
        ->check(CLI::Range(0.0, 1e7));
    r->add_option("--width", render.width, "Image width in pixels")->capture_default_str()->check(CLI::Range(1, 16384));
    r->add_option("--height", render.height, "Image height in pixels")->capture_default_str()->check(CLI::Range(1, 16384));
    r->add_option("--max-depth", render.maxDepth, "Maximum number of bounces (1 = direct lighting only)")
        ->capture_default_str()
        ->check(CLI::Range(0u, 1023u));
    r->add_option("--seed", render.seed, "Random seed (renders are deterministic per seed and device)")
        ->capture_default_str();
    r->add_option("--env", render.env, "Constant environment radiance R,G,B (W/m^2/sr)")->capture_default_str();
    r->add_option("--device", render.device, "Vulkan device index or name substring (default: lavapipe)");
    r->add_option("--camera", render.camera, "Camera index in the glTF (default: first camera, or a framing camera)")
        ->check(CLI::NonNegativeNumber);
    r->add_option("--method", render.method,
                  "pt: path tracing; gpt: gradient-domain path tracing (base + 4 shifted offset paths, "
                  "Kettunen et al. 2015), writes primal/dx/dy/direct/variance layers")
        ->capture_default_str()
        ->check(CLI::IsMember({"pt", "gpt"}));
    r->add_option("--recon", render.recon,
                  "G-PT reconstruction in the default channels: l1 (IRLS), l2 (unbiased), wl2 (inverse-variance "
                  "weighted L2), wl1 (L1 with inverse-variance weights from a 7x7 box of the variance)")
        ->capture_default_str()
        ->check(CLI::IsMember({"l1", "l2", "wl2", "wl1"}));
    r->add_flag("--all-recon", render.allRecon, "G-PT: also write the other reconstructions as layers recon_*");
    r->add_option("--alpha", render.alpha, "G-PT: weight of the primal term in the screened Poisson energy")
        ->capture_default_str()
        ->check(CLI::Range(0.0, 1e3));
    r->add_option("--tolerance", render.tolerance, "G-PT: relative residual at which the solver stops")
        ->capture_default_str()
        ->check(CLI::Range(1e-9, 1.0));
    r->add_option("--shift-threshold", render.shiftThreshold,
                  "G-PT: roughness at or below which a vertex is glossy (half-vector shift) instead of "
                  "reconnectable")
        ->capture_default_str()
        ->check(CLI::Range(0.0f, 1.0f));
    r->add_option("--split-bounce", render.splitBounce,
                  "G-PT: once every offset path has reconnected, trace the remaining bounces in a second, "
                  "smaller kernel loop (same image). auto: on for lavapipe with Mesa < 23, where it is "
                  "15-25% faster; off elsewhere, where it measured no faster and lengthens pipeline creation")
        ->capture_default_str()
        ->check(CLI::IsMember({"auto", "on", "off"}));
    r->add_option("--emitter-supersampling", render.emitterSupersampling,
                  "Rays per camera sample for the emission seen directly by the camera, in the pixels at the "
                  "edges of visible lights, sky or emissive texture (found by a 4-ray probe per pixel); "
                  "stratified, unbiased, for pt and gpt alike. The rim of a bright light otherwise dominates "
                  "a G-PT image's error, since the reconstruction does not touch this term. 0 = off")
        ->capture_default_str()
        ->check(CLI::Range(0u, kMaxVisibleSupersampling));
    r->add_option("--edge-samples", render.edgeSamples,
                  "G-PT: extra camera samples per camera sample in the pixels that a geometric edge "
                  "crosses (a silhouette, a crease, a change of material; found once by a 4-ray probe "
                  "per pixel at fixed positions, so unbiased). Their pixel-coverage noise is in the "
                  "gradients too, so the reconstruction cannot remove it and they hold most of a G-PT "
                  "image's error. 0 = off")
        ->capture_default_str()
        ->check(CLI::Range(0u, kMaxEdgeSamples));
    r->add_option("--demodulate", render.demodulate,
                  "G-PT: first-hit texture demodulation. In the pixels away from geometric edges (found by "
                  "the edge probe inside a pixel or between neighbouring pixels), each path divides its contributions by the base-colour texture at "
                  "its first hit (Lambertian materials), so the gradients carry the lighting differences "
                  "instead of the texture's times the lighting noise; the reconstruction is multiplied by "
                  "the pixel-mean texture (the `modulation` layer; primal/dx/dy are then divided by it). "
                  "auto: on when some Lambertian material has a base-colour texture")
        ->capture_default_str()
        ->check(CLI::IsMember({"auto", "on", "off"}));
    r->add_option("--workgroup", render.workgroup, "Compute workgroup size WxH")->capture_default_str();
    r->add_option("--schedule", render.schedule,
                  "Kernel schedule: megakernel (one kernel per path batch) or wavefront (kernel per bounce stage)")
        ->capture_default_str()
        ->check(CLI::IsMember({"megakernel", "wavefront"}));
    r->add_flag("--profile", render.profile, "Print GPU time per kernel (timestamp queries)");
    r->add_option("--json", render.json, "Write render statistics as JSON to this file");
    r->add_flag("--quiet", render.quiet, "No progress output");
    r->add_flag("--validate", render.validate, "Enable Vulkan validation layers (errors make the run fail)");
    CLI::Option* checkpoint = r->add_option(
        "--checkpoint", render.checkpoint,
        "Write the samples so far and the state to continue them to this EXR (tmp + rename) when "
        "interrupted (SIGINT/SIGTERM, exit 130), every --checkpoint-every seconds, and at the end");
    r->add_option(
         "--checkpoint-every", render.checkpointEvery,
         "Seconds between periodic checkpoints, at batch boundaries (0 = only on interrupt and at the end)")
        ->capture_default_str()
        ->check(CLI::Range(0.0, 1e7))
        ->needs(checkpoint);
    r->add_option("--resume", render.resume,
                  "Continue from a checkpoint of the same scene, method, size, seed, depth, env, camera and "
                  "schedule; --spp is the total including its samples (bit-identical to an uninterrupted run "
                  "when it was written by an interrupt or a periodic checkpoint)")
        ->check(InputFile);

    return {r, [args] { return runRender(*args); }};
}

Subcommand addDiffCommand(CLI::App& app) {
    auto args = std::make_shared<DiffArgs>();
    auto& diff = *args;
    CLI::App* d = app.add_subcommand("diff", "Compare two EXR images: relMSE (Kettunen et al. 2015), MSE, MAE, max error");
    d->add_option("test", diff.test, "Image to evaluate")->required()->check(InputFile);
    d->add_option("reference", diff.reference, "Reference image")->required()->check(InputFile);
    d->add_option("--json", diff.json, "Write the metrics as JSON to this file ('-' = stdout)");

    return {d, [args] { return runDiff(*args); }};
}

Subcommand addInfoCommand(CLI::App& app) {
    auto args = std::make_shared<InfoArgs>();
    auto& info = *args;
    CLI::App* i = app.add_subcommand("info", "Print a scene's features and the kernel variant gdpt will run");
    i->add_option("scene", info.scene, "glTF 2.0 scene")->required()->check(InputFile);
    i->add_option("--env", info.env, "Constant environment radiance R,G,B")->capture_default_str();

    return {i, [args] { return runInfo(*args); }};
}

Subcommand addDevicesCommand(CLI::App& app) {
    auto args = std::make_shared<DevicesArgs>();
    auto& devices = *args;
    CLI::App* v = app.add_subcommand("devices", "List Vulkan devices with the limits that matter to gdpt");
    v->add_flag("--json", devices.json, "Print JSON");

    return {v, [args] { return runDevices(*args); }};
}

}  // namespace gdpt
