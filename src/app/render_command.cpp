// render_command.cpp — `gdpt render SCENE`: parses the options, makes the integrator of
// --method, renders, and writes the EXR (every layer), the PNG preview and the JSON summary.
// Time budgets, checkpoints and interrupts are handled here; the method is the integrator's.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "app/bench_util.h"
#include "app/commands.h"
#include "app/edge_samples_option.h"
#include "app/input_file.h"
#include "app/render_setup.h"
#include "app/subcommand.h"
#include "distributed/mpi_world.h"
#include "distributed/shards.h"
#include "image/atomic_write.h"
#include "image/exr_io.h"
#include "image/finite_check.h"
#include "image/png_preview.h"
#include "integrator/budget_report.h"
#include "integrator/checkpoint.h"
#include "integrator/integrator.h"
#include "integrator/recon_reserve.h"
#include "integrator/render_identity.h"
#include "render/device_scene/scene_gpu.h"
#include "scene/gltf_loader.h"
#include "util/error.h"
#include "util/interrupt.h"
#include "util/output_files.h"
#include "util/timer.h"
#include "vk/context.h"

namespace gdpt {
namespace {

using nlohmann::json;

std::string absolutePath(const std::string& path) {
    std::error_code ec;
    const std::filesystem::path p = std::filesystem::absolute(path, ec);
    return ec ? path : p.lexically_normal().string();
}

}  // namespace

std::string renderArgsJson(const RenderArgs& a) {
    const json j = {{"method", a.method},
                    {"width", a.width},
                    {"height", a.height},
                    {"camera", a.camera},
                    {"env", a.env},
                    {"spp", a.spp},
                    {"time", a.time},
                    {"seed", a.seed},
                    {"max_depth", a.maxDepth},
                    {"emitter_supersampling", a.emitterSupersampling},
                    {"light_selection", a.lightSelection},
                    {"shift_threshold", a.shiftThreshold},
                    {"edge_samples", a.edgeSamples},
                    {"demodulate", a.demodulate},
                    {"split_bounce", a.splitBounce},
                    {"recon", a.recon},
                    {"all_recon", a.allRecon},
                    {"alpha", a.alpha},
                    {"tolerance", a.tolerance},
                    {"debias_cells", a.debiasCells},
                    {"workgroup", a.workgroup}};
    return j.dump();
}

RenderArgs renderArgsFromJson(const std::string& text, const std::string& where) {
    RenderArgs a;
    try {
        const json j = json::parse(text);
        a.method = j.at("method").get<std::string>();
        a.width = j.at("width").get<int>();
        a.height = j.at("height").get<int>();
        a.camera = j.at("camera").get<int>();
        a.env = j.at("env").get<std::string>();
        a.spp = j.at("spp").get<std::uint32_t>();
        a.time = j.at("time").get<double>();
        a.seed = j.at("seed").get<std::uint32_t>();
        a.maxDepth = j.at("max_depth").get<std::uint32_t>();
        a.emitterSupersampling = j.at("emitter_supersampling").get<std::uint32_t>();
        // Renders written before the choice picked lights by power.
        a.lightSelection = j.value("light_selection", std::string("power"));
        a.shiftThreshold = j.at("shift_threshold").get<float>();
        // A number, or "auto" (earlier renders wrote numbers only).
        const json& edge = j.at("edge_samples");
        a.edgeSamples =
            edge.is_string() ? edge.get<std::string>() : std::to_string(edge.get<std::uint32_t>());
        (void)parseEdgeSamples(a.edgeSamples, "edge_samples");
        a.demodulate = j.at("demodulate").get<std::string>();
        a.splitBounce = j.at("split_bounce").get<std::string>();
        a.recon = j.at("recon").get<std::string>();
        a.allRecon = j.at("all_recon").get<bool>();
        a.alpha = j.at("alpha").get<double>();
        a.tolerance = j.at("tolerance").get<double>();
        // Renders written before the debiasing had none.
        a.debiasCells = j.value("debias_cells", 0);
        a.workgroup = j.at("workgroup").get<std::string>();
    } catch (const json::exception& e) {
        throw Error(where + ": the render's settings (gdpt.info.render_args) cannot be read: " + e.what());
    }
    return a;
}

int runRender(const RenderArgs& args, const MergedShards* merged) {
    installInterruptHandlers();
    checkArgs(args);
    checkImageMemory(args);
    Timer total;
    RenderOptions options = renderOptionsFor(args);
    // Remembered times per scene first (a reconstruction's time follows the image), else of the
    // last render of the same configuration.
    const ReconTimeCache cache(ReconTimeCache::defaultPath(), "scene " + absolutePath(args.scene));

    // A render split across processes: the ranks of mpirun (distributed/mpi_world.h), or a
    // shard run as a job of its own (distributed/shards.h).
    MpiWorld* world = MpiWorld::get();
    const bool shard = !args.shard.empty();
    if (shard) options.share = parseSampleShare(args.shard, "--shard");
    if (world) {
        if (shard)
            throw UsageError(
                "--shard splits a render into independent jobs; under mpirun the ranks split it");
        if (!args.checkpoint.empty() || !args.resume.empty())
            throw UsageError("--checkpoint and --resume are per process: under mpirun with " +
                             std::to_string(world->size()) +
                             " ranks, render shards instead (--shard I/N, each with its own checkpoint)");
        options.share = world->share();
    }
    if (options.share.split() && args.time <= 0.0 && args.spp < options.share.count)
        throw UsageError("--spp " + std::to_string(args.spp) + " cannot be split into " +
                         std::to_string(options.share.count) +
                         " parts: every part takes at least one sample "
                         "per pixel");
    // Only rank 0 of mpirun writes, reports progress and finishes the render.
    const bool writes = !world || world->root();
    if (!writes) options.quiet = options.scene.quiet = true;
    const bool quiet = options.quiet;

    // Every output is checked (and its temporary file created) before the scene is loaded,
    // so that a long render never fails at the end on a bad path, and no output may
    // overwrite an input or another output. They are committed together at the end.
    OutputSet outputs({{"scene", args.scene}, {"--resume checkpoint", args.resume}});
    const StagedFile* exrFile = writes ? &outputs.add(args.output, shard ? "-o (the shard)" : "-o") : nullptr;
    const StagedFile* pngFile =
        writes && !shard ? &outputs.add(previewPath(args.output), "PNG preview of -o") : nullptr;
    const TextOutput jsonOutput(outputs, writes ? args.json : "", "--json");
    // A checkpoint is written on its own schedule; it may continue the one resumed from.
    if (!args.checkpoint.empty()) outputs.checkSeparate(args.checkpoint, "--checkpoint", {args.resume});

    std::optional<Scene> loaded;
    std::optional<vk::Context> context;
    std::unique_ptr<Integrator> integrator;
    std::optional<Checkpoint> resumed;
    ExrAttributes identity;
    ReservedTime reserved, finishReserved;
    const bool timed = args.time > 0.0;
    const std::string finishKeyMethod =
        args.method + (args.method == "gpt" ? "|" + std::to_string(args.allRecon ? 4 : 1) + " solves" : "") +
        (world ? "|" + std::to_string(world->size()) + " ranks" : "");
    std::string finishKey;
    double loadSeconds = 0.0;
    try {
        enterPhase("loading");
        if (world) world->testFault("loading");
        Timer loadTimer;
        const GltfAsset asset(args.scene, deviceLoadOptions(args.device, quiet));
        loaded.emplace(asset.instance());
        loadSeconds = loadTimer.seconds();
        const Scene& scene = *loaded;
        if (!asset.animations().empty() && !quiet)
            std::fprintf(
                stderr,
                "gdpt: note: %s has %zu animation(s); the rest pose is rendered (--frames renders them)\n",
                args.scene.c_str(), asset.animations().size());
        throwIfInterrupted("loading");
        if (!quiet) warnAboutScene(args.scene, scene, options.scene.envRadiance);
        vk::ContextOptions ctxOptions;
        ctxOptions.device = args.device;
        ctxOptions.validation = args.validate;
        const vk::Context& ctx = context.emplace(ctxOptions);
        if (!quiet)
            std::fprintf(stderr, "gdpt: device '%s' (%s, %s)%s\n", ctx.info().name.c_str(),
                         ctx.info().type.c_str(), ctx.info().driverInfo.c_str(),
                         world ? (", rank 0 of " + std::to_string(world->size())).c_str() : "");
        // After the context: the integrator's device objects (G-PT's solver) go before it.
        integrator = integratorFor(args, &cache);

        // --time covers the whole render: sampling stops early by what the method needs after
        // it (G-PT: the reconstructions) and by what the rest took the last time for this
        // device, method, size and settings (readback, output layers, EXR + PNG; nothing the
        // first time).
        finishKey = "finish|" + reservationKey(ctx, args.width, args.height) + "|" + finishKeyMethod;
        if (timed) {
            reserved = integrator->reserveAfterSampling(ctx, args.width, args.height);
            finishReserved = cache.get(finishKey).value_or(ReservedTime{});
            options.timeBudget =
                std::max(0.05 * args.time, args.time - reserved.seconds - finishReserved.seconds);
            // Each rank of a distributed render samples for rank 0's budget, as agreed below.
            if (!world) {
                options.reservedAfterSampling = {reserved, finishReserved};
                options.reconstructionDeadline =
                    std::chrono::steady_clock::now() +
                    std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                        std::chrono::duration<double>(args.time - total.seconds() - finishReserved.seconds));
            }
        }
        options.elapsedBefore = total.seconds();

        // Checkpoints: the identity of this render is recorded in every checkpoint written, and
        // a checkpoint resumed from must have the same (render_identity.h).
        identity = renderIdentity(*integrator, scene, options);
        if (merged) {  // gdpt merge: the shards' statistics, merged
            resumed = Checkpoint{merged->identity, merged->info, merged->state};
            checkIdentity("the shards", resumed->identity, identity);
            options.resume = &resumed->state;
        } else if (!args.resume.empty()) {
            resumed = readCheckpoint(args.resume);
            checkIdentity(args.resume, resumed->identity, identity);
            if (!timed && resumed->state.spp > options.share.localSpp(args.spp))
                throw Error(args.resume + ": checkpoint already has " + std::to_string(resumed->state.spp) +
                            " spp, more than --spp " + std::to_string(args.spp) +
                            (shard ? " gives part " + options.share.text() : ""));
            if (!quiet && resumed->info.count("device") && resumed->info["device"] != ctx.info().name)
                std::fprintf(stderr,
                             "gdpt: warning: %s was rendered on '%s'; continuing on '%s' (same statistics, "
                             "not the same bits)\n",
                             args.resume.c_str(), resumed->info["device"].c_str(), ctx.info().name.c_str());
            options.resume = &resumed->state;
        }
        if (world) {
            ExrAttributes description = identity;
            description.erase("share");
            description["spp"] = timed ? "--time " + std::to_string(args.time) : std::to_string(args.spp);
            // Every rank samples for rank 0's budget (its reservations: the reconstruction, and
            // what the last such render spent after sampling, the merge included).
            world->agree(description, "", timed ? &options.timeBudget : nullptr);
        }
    } catch (const std::exception& e) {
        // Every rank takes part in the agreement, so that one rank's failure ends them all.
        if (world && !world->agreed()) world->agree({}, e.what());
        throw;
    }
    const Scene& scene = *loaded;
    const vk::Context& ctx = *context;

    const ExrAttributes info = {{"device", ctx.info().name}, {"scene_file", args.scene}};
    if (!args.checkpoint.empty()) {
        options.checkpoint = [&args, identity, info](const SamplerState& state) {
            writeCheckpoint(args.checkpoint, identity, info, state);
        };
        options.checkpointEvery = args.checkpointEvery;
    }
    std::optional<SamplerState> shardState;
    if (world) {
        options.combine = [world](SamplerState mine, RenderStats& stats) {
            world->testFault("sampling");
            return world->combine(std::move(mine), stats);
        };
    } else if (shard) {
        options.combine = [&shardState](SamplerState mine,
                                        RenderStats& stats) -> std::optional<SamplerState> {
            if (!stats.cancelled) shardState = std::move(mine);
            return std::nullopt;
        };
    }
    const std::string checkpointNote = args.checkpoint.empty()
                                           ? ""
                                           : "; checkpoint written to " + args.checkpoint +
                                                 " (continue with --resume " + args.checkpoint + ")";
    enterPhase("sampling");
    RenderOutput out;
    try {
        out = integrator->render(ctx, scene, options);
    } catch (const Interrupted& e) {  // building the BVH, or a stage after sampling
        if (world) world->fail(e.what(), true);
        if (e.phase() != "reconstructing") throw;
        throw Interrupted(e.phase(), checkpointNote);  // sampling ended: the checkpoint is written
    } catch (const std::exception& e) {
        if (world) world->fail(e.what(), interruptRequested());
        throw;
    }
    RenderStats& s = out.stats;
    if (merged) s.distributed = merged->stats;
    // The merge of a distributed render happens after sampling too.
    const double afterSampling =
        total.seconds() -
        (s.readbackMs + s.reconstructionMs + (merged ? 0.0 : s.distributed.mergeMs + s.distributed.waitMs)) *
            1e-3;
    if (s.cancelled) {
        if (!quiet)
            std::fprintf(stderr, "gdpt: interrupted after %u spp; no output written%s\n", s.spp,
                         checkpointNote.c_str());
        return 130;
    }
    if (s.handedOff && !shard) return 0;  // a rank other than 0: rank 0 finishes the render
    enterPhase("writing");
    Timer writeTimer;
    if (shard) {
        ExrAttributes shardInfo = info;
        shardInfo["render_spp"] = std::to_string(timed ? 0u : args.spp);
        RenderArgs recorded = args;  // naming the reconstruction that gpt's auto chose
        recorded.recon = recordedRecon(args, s.features);
        shardInfo["render_args"] = renderArgsJson(recorded);
        shardInfo["scene_path"] = absolutePath(args.scene);
        writeCheckpoint(*exrFile, identity, shardInfo, *shardState);
    } else {
        checkFinite(out.layers, args.output);
        writeExr(*exrFile, out.layers);
        throwIfInterrupted("writing");
        writePngPreview(*pngFile, out.image());
    }
    throwIfInterrupted("writing");
    const double writeMs = writeTimer.ms();
    const double seconds = total.seconds();
    const BudgetReport budget = budgetReport(args.time, s, seconds, reserved.seconds + finishReserved.seconds,
                                             seconds - afterSampling);
    if (args.profile) printProfile(s.kernels);
    if (jsonOutput.wanted()) {
        json summary = summaryJson(args, ctx, *integrator, s, seconds, reserved.seconds,
                                   finishReserved.seconds, writeMs);
        summary["time_s"]["load"] = loadSeconds;
        summary["scene_size"] = sceneSizeJson(scene, s, summary["memory"]["host_peak_bytes"].get<double>());
        if (shard) summary["shard"] = options.share.text();
        if (timed) summary["budget"] = budgetJson(budget, s);
        jsonOutput.write(summary.dump(2) + "\n");
        throwIfInterrupted("writing");
    }
    outputs.commit();
    if (timed && !shard)
        cache.put(finishKey, {std::max(0.0, total.seconds() - afterSampling - s.reconstructionMs * 1e-3),
                              s.samplingLoad});
    if (!quiet) {
        const std::string partial =
            s.partialPassRows ? " + 1 in the top " + std::to_string(s.partialPassRows) + " rows" : "";
        std::string parts;
        if (s.distributed.parts > 1)
            parts = ", " + std::to_string(s.distributed.parts) + (merged ? " shards" : " ranks") +
                    " merged in " + std::to_string(static_cast<long>(s.distributed.mergeMs)) + " ms";
        if (shard) parts = ", part " + options.share.text() + " of " + std::to_string(args.spp) + " spp";
        char sampling[160] = "";  // gdpt merge samples nothing itself
        if (!merged)
            std::snprintf(sampling, sizeof sampling,
                          ", BVH %.1f ms, sampling %.1f ms, %.2f Mrays/s, %.3f Msamples/s", s.bvhBuildMs,
                          s.samplingMs, double(s.raysTraced) / (s.samplingMs * 1e-3) * 1e-6,
                          double(s.pathsCompleted) / (s.samplingMs * 1e-3) * 1e-6);
        std::fprintf(stderr, "gdpt: wrote %s%s (%u spp%s%s%s, %.2f s total%s)\n", shard ? "shard " : "",
                     args.output.c_str(), s.spp, partial.c_str(), parts.c_str(),
                     integrator->summary(s).c_str(), seconds, sampling);
        if (timed)
            if (const std::optional<std::string> note = budgetNote(budget, s))
                std::fprintf(stderr, "gdpt: note: %s\n", note->c_str());
    }
    return validationExitStatus(ctx);
}

int runRender(const RenderArgs& given) {
    RenderArgs args = given;
    args.recon = resolvedRecon(args.method, args.recon);  // as the render's settings record it
    if (!args.frames.empty()) return runSequence(args);
    return runRender(args, nullptr);
}

}  // namespace gdpt

namespace gdpt {

Subcommand addRenderCommand(CLI::App& app) {
    auto args = std::make_shared<RenderArgs>();
    RenderArgs& a = *args;
    CLI::App* r =
        app.add_subcommand("render", "Render a glTF 2.0 scene to OpenEXR (every layer) + a PNG preview");
    r->add_option("scene", a.scene, "glTF 2.0 scene (.gltf or .glb)")->required()->check(InputFile);

    const char* image = "Scene and image";
    r->add_option("-o,--output", a.output, "Output EXR; the PNG preview is written beside it")
        ->capture_default_str()
        ->group(image);
    r->add_option("--width", a.width, "Image width in pixels")
        ->capture_default_str()
        ->check(CLI::Range(1, 16384))
        ->group(image);
    r->add_option("--height", a.height, "Image height in pixels")
        ->capture_default_str()
        ->check(CLI::Range(1, 16384))
        ->group(image);
    r->add_option("--camera", a.camera,
                  "Camera index in the glTF (default: the first, else a framing camera)")
        ->check(CLI::NonNegativeNumber)
        ->group(image);
    r->add_option("--env", a.env, "Constant environment radiance R,G,B (or one value for grey)")
        ->capture_default_str()
        ->group(image);

    const char* sampling = "Sampling";
    r->add_option(
         "--method", a.method,
         "gpt: gradient-domain path tracing; pt: path tracing (docs/gpt.md); gmlt: gradient-domain "
         "Metropolis; pssmlt: primary-sample-space Metropolis (docs/mlt.md); tgpt: temporal G-PT of a "
         "sequence (--frames; docs/animation.md)")
        ->capture_default_str()
        ->check(CLI::IsMember(methodNames()))
        ->group(sampling);
    r->add_option("--spp", a.spp,
                  "Samples per pixel (G-PT: camera samples, each a base + 4 offset paths; MLT: mutations per "
                  "pixel on average)")
        ->capture_default_str()
        ->check(CLI::Range(1u, 1u << 24))
        ->group(sampling);
    r->add_option("--seed", a.seed, "Random seed; renders are bit-reproducible per seed and device")
        ->capture_default_str()
        ->group(sampling);
    r->add_option("--max-depth", a.maxDepth, "Maximum bounces (1 = direct light only)")
        ->capture_default_str()
        ->check(CLI::Range(0u, 1023u))
        ->group(sampling);
    r->add_option("--emitter-supersampling", a.emitterSupersampling,
                  "Rays per camera sample for directly seen emission at the edges of lights (pt, gpt; pssmlt "
                  "and gmlt per camera sample of their very-direct image; 0 = off)")
        ->capture_default_str()
        ->check(CLI::Range(0u, kMaxEmitterSupersampling))
        ->group(sampling);
    r->add_option(
         "--light-selection", a.lightSelection,
         "How next-event estimation picks an emitter (the triangles of one emissive material; within it, "
         "by power): power (in proportion to emitted power), uniform (each emitter alike), mixed (half "
         "of each: robust where most power is far away, e.g. a sky beside a lamp), probe (half mixed, half "
         "by what each emitter gives the surfaces the camera sees, from a fixed probe of rays)")
        ->capture_default_str()
        ->check(CLI::IsMember(
            std::vector<std::string>(std::begin(kLightSelectionChoices), std::end(kLightSelectionChoices))))
        ->group(sampling);

    const char* gpt = "G-PT";
    r->add_option(
         "--recon", a.recon,
         "Reconstruction of the final image: auto (gpt by the scene's surfaces: wl1, or wl2 where some "
         "vertex is glossy, e.g. a mirror; l1 for gmlt and tgpt), l1, l2, wl2 or "
         "wl1 (docs/reconstruction.md; for tgpt the space-time solve's, its wl* weighting dt by the "
         "paired samples' variance: docs/animation.md)")
        ->capture_default_str()
        ->check(CLI::IsMember({"auto", "l1", "l2", "wl2", "wl1"}))
        ->group(gpt);
    r->add_flag("--all-recon", a.allRecon, "Also write the other reconstructions as layers recon_*")
        ->group(gpt);
    r->add_option(
         "--alpha", a.alpha,
         "Weight of the primal term of the screened Poisson energy (default: gpt by the scene's light, "
         "0.2 without --env, 0.4 with --env and emissive surfaces or punctual lights, 0.8 with --env "
         "alone, 0.4 under a sky of emissive triangles around the scene (docs/reconstruction.md); "
         "tgpt 0.2; gmlt 0.05, whose splatted primal is blotchier than its gradients)")
        ->check(CLI::Range(0.0, 1e3))
        ->group(gpt);
    r->add_option("--tolerance", a.tolerance, "Relative residual at which the solver stops")
        ->capture_default_str()
        ->check(CLI::Range(1e-9, 1.0))
        ->group(gpt);
    r->add_option("--debias-cells", a.debiasCells, kDebiasCellsHelp)
        ->capture_default_str()
        ->check(CLI::Range(0, kMaxDebiasCells))
        ->group(gpt);
    r->add_option("--solver", a.solver, kSolverHelp)
        ->capture_default_str()
        ->check(CLI::IsMember(std::vector<std::string>(std::begin(kSolverChoices), std::end(kSolverChoices))))
        ->group(gpt);
    r->add_option("--shift-threshold", a.shiftThreshold,
                  "Roughness at or below which a vertex takes the half-vector shift instead of reconnection")
        ->capture_default_str()
        ->check(CLI::Range(0.0f, 1.0f))
        ->group(gpt);
    r->add_option("--edge-samples", a.edgeSamples, kEdgeSamplesHelp)
        ->capture_default_str()
        ->check(edgeSamplesValidator())
        ->group(gpt);
    r->add_option("--demodulate", a.demodulate,
                  "First-hit texture demodulation: auto (on for textured Lambertian scenes), on, off")
        ->capture_default_str()
        ->check(CLI::IsMember({"auto", "on", "off"}))
        ->group(gpt);
    r->add_option("--split-bounce", a.splitBounce,
                  "Split bounce loop of the G-PT sample, gpt and gmlt (same image): auto = on for lavapipe "
                  "before Mesa 23, on, off")
        ->capture_default_str()
        ->check(CLI::IsMember({"auto", "on", "off"}))
        ->group(gpt);

    const char* mlt = "Metropolis (pssmlt, gmlt; docs/mlt.md)";
    r->add_option("--chains", a.chains, "Markov chains run at once (0 = one per 16 pixels, 1024 to 65536)")
        ->capture_default_str()
        ->check(CLI::Range(0u, 65536u))
        ->group(mlt);
    r->add_option("--large-step", a.largeStep,
                  "Probability of a large step (a fresh path) per mutation (default: pssmlt 0.5, gmlt 0.7)")
        ->check(CLI::Range(0.0f, 1.0f))
        ->group(mlt);
    r->add_option("--target-exponent", a.targetExponent,
                  "The chains walk the method's target to this power: below 1 they mix faster, splat fewer "
                  "blotches and importance-sample less (default: pssmlt 1, gmlt 0.25)")
        ->check(CLI::Range(0.01f, 4.0f))
        ->group(mlt);
    r->add_option("--target-block", a.targetBlock,
                  "The chains walk the target divided by its image block's mean (from the bootstrap), blocks "
                  "of this many pixels square: their samples go where the relative error is; 0 = undivided "
                  "(default: pssmlt 0, gmlt 16)")
        ->check(CLI::Range(0, 4096))
        ->group(mlt);
    r->add_option("--target-alpha", a.targetAlpha,
                  "gmlt: weight of the path's radiance beside its gradients in the chains' target")
        ->capture_default_str()
        ->check(CLI::Range(1e-4f, 1e3f))
        ->group(mlt);

    const char* animation = "Animation (docs/animation.md)";
    CLI::Option* frames =
        r->add_option(
             "--frames", a.frames,
             "A:B: render frames A to B of an animation, frame k at time k/fps; -o takes a frame number "
             "(e.g. out/frame_%04d.exr, directory created); each frame's EXR + PNG is written when it is "
             "done, and an MP4 of the PNGs when ffmpeg is installed. --time is the whole sequence's")
            ->group(animation);
    r->add_option("--fps", a.fps, "Frames per second of --frames")
        ->capture_default_str()
        ->check(CLI::Range(1e-3, 1e4))
        ->needs(frames)
        ->group(animation);
    r->add_option("--animation", a.animation,
                  "The animation to render, by name or index (default: the first)")
        ->needs(frames)
        ->group(animation);
    r->add_flag("--no-video", a.noVideo, "No MP4 of the sequence even when ffmpeg is installed")
        ->needs(frames)
        ->group(animation);
    r->add_option("--window", a.window,
                  "tgpt: frames reconstructed together by one space-time solve (each window tied to the one "
                  "before)")
        ->capture_default_str()
        ->check(CLI::Range(1, 256))
        ->needs(frames)
        ->group(animation);
    r->add_option("--beta", a.beta, "tgpt: weight of the temporal rows of the space-time solve")
        ->capture_default_str()
        ->check(CLI::Range(0.0, 1e3))
        ->needs(frames)
        ->group(animation);
    r->add_option("--gamma", a.gamma,
                  "tgpt: weight of the mixed rows of the space-time solve (the change of dx and dy along "
                  "the motion, Manzi et al. 2016's mixed differences); 0 = none. Default 1; 0 (and only 0) "
                  "with --temporal-shift reconnect, which has no paired halves to take them from")
        ->check(CLI::Range(0.0, 1e3))
        ->needs(frames)
        ->group(animation);
    r->add_option(
         "--temporal-shift", a.temporalShift,
         "tgpt: how a frame's paths are paired with the next frame's: motion = replayed in the pixel "
         "the scene's motion carries their primary hit to (motion vectors), replay = in the same "
         "pixel, reconnect = shifted into the next frame by the reconnection shift (each path's offset "
         "starts in that pixel and reconnects to the path's vertices carried by the animation, both "
         "directions combined by MIS; a pass of its own per frame: docs/animation.md)")
        ->capture_default_str()
        ->check(CLI::IsMember({"motion", "replay", "reconnect"}))
        ->needs(frames)
        ->group(animation);

    const char* budget = "Time budget and checkpoints";
    r->add_option(
         "--time", a.time,
         "Seconds for the whole render, reconstruction included; overrides --spp. If the fixed costs "
         "alone (set-up, the kernels' first compile, one sample per pixel, reconstruction) exceed "
         "it, renders that minimum and says so")
        ->check(CLI::Range(1e-3, 1e7))
        ->group(budget);
    CLI::Option* checkpoint =
        r->add_option("--checkpoint", a.checkpoint,
                      "Write the samples so far to this EXR on interrupt, periodically and at the end")
            ->group(budget);
    r->add_option("--checkpoint-every", a.checkpointEvery, "Seconds between periodic checkpoints (0 = none)")
        ->capture_default_str()
        ->check(CLI::Range(0.0, 1e7))
        ->needs(checkpoint)
        ->group(budget);
    r->add_option("--resume", a.resume, "Continue a checkpoint of the same render; --spp counts the total")
        ->check(InputFile)
        ->group(budget);

    const char* split = "Distributed rendering (docs/distributed.md)";
    r->add_option(
         "--shard", a.shard,
         "I/N: render part I (from 0) of N of the samples and write their statistics to -o (no PNG); "
         "gdpt merge finishes the render. Under mpirun the ranks split the render instead")
        ->group(split);

    const char* diagnostics = "Device and diagnostics";
    r->add_option("--device", a.device, "Vulkan device index or name substring (default: lavapipe)")
        ->group(diagnostics);
    r->add_option("--workgroup", a.workgroup, "Compute workgroup size WxH")
        ->capture_default_str()
        ->group(diagnostics);
    r->add_flag("--profile", a.profile, "Print GPU time per kernel (timestamp queries)")->group(diagnostics);
    r->add_option("--json", a.json, "Write the render's statistics as JSON to this file ('-' = stdout)")
        ->group(diagnostics);
    r->add_flag("--quiet", a.quiet, "No progress or summary output")->group(diagnostics);
    r->add_flag("--validate", a.validate, "Enable Vulkan validation layers (errors fail the run)")
        ->group(diagnostics);

    return {r, [args] { return runRender(*args); }};
}

}  // namespace gdpt
