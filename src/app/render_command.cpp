// render_command.cpp — `gdpt render SCENE` (its options: render_cli.cpp): makes the integrator
// of --method, renders, and writes the EXR (every layer), the PNG preview and the JSON summary.
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
#include "app/render_setup.h"
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

namespace {

// A render split across processes: this process's share of the samples, as a shard run as a job
// of its own (distributed/shards.h) or a rank of mpirun (distributed/mpi_world.h).
void takeShare(const RenderArgs& args, MpiWorld* world, RenderOptions& options) {
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
}

// What the set-up leaves the render.
struct RenderSetup {
    std::optional<Scene> scene;
    std::optional<vk::Context> context;
    std::unique_ptr<Integrator> integrator;
    std::optional<Checkpoint> resumed;  // the checkpoint or the merged shards it continues
    ExrAttributes identity;             // of this render (render_identity.h)
    ReservedTime reserved, finishReserved;
    std::string finishKey;  // ReconTimeCache's key of what follows the sampling
    double loadSeconds = 0.0;
};

// Loads the scene, starts the device and makes the integrator; with --time, reserves what the
// method needs after sampling and what the rest took the last time; resumes a checkpoint or the
// merged shards; under mpirun, agrees with the other ranks.
void setUpRender(const RenderArgs& args, const MergedShards* merged, MpiWorld* world,
                 const ReconTimeCache& cache, const Timer& total, RenderOptions& options,
                 RenderSetup& setup) {
    const bool quiet = options.quiet;
    const bool timed = args.time > 0.0;
    enterPhase("loading");
    if (world) world->testFault("loading");
    Timer loadTimer;
    const GltfAsset asset(args.scene, deviceLoadOptions(args.device, quiet));
    const Scene& scene = setup.scene.emplace(asset.instance());
    setup.loadSeconds = loadTimer.seconds();
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
    const vk::Context& ctx = setup.context.emplace(ctxOptions);
    if (!quiet)
        std::fprintf(stderr, "gdpt: device '%s' (%s, %s)%s\n", ctx.info().name.c_str(),
                     ctx.info().type.c_str(), ctx.info().driverInfo.c_str(),
                     world ? (", rank 0 of " + std::to_string(world->size())).c_str() : "");
    // After the context: the integrator's device objects (G-PT's solver) go before it.
    setup.integrator = integratorFor(args, &cache);
    Integrator& integrator = *setup.integrator;

    // --time covers the whole render: sampling stops early by what the method needs after
    // it (G-PT: the reconstructions) and by what the rest took the last time for this
    // device, method, size and settings (readback, output layers, EXR + PNG; nothing the
    // first time).
    const std::string finishKeyMethod =
        args.method + (args.method == "gpt" ? "|" + std::to_string(args.allRecon ? 4 : 1) + " solves" : "") +
        (world ? "|" + std::to_string(world->size()) + " ranks" : "");
    setup.finishKey = "finish|" + reservationKey(ctx, args.width, args.height) + "|" + finishKeyMethod;
    if (timed) {
        setup.reserved = integrator.reserveAfterSampling(ctx, args.width, args.height);
        setup.finishReserved = cache.get(setup.finishKey).value_or(ReservedTime{});
        options.timeBudget =
            std::max(0.05 * args.time, args.time - setup.reserved.seconds - setup.finishReserved.seconds);
        // Each rank of a distributed render samples for rank 0's budget, as agreed below.
        if (!world) {
            options.reservedAfterSampling = {setup.reserved, setup.finishReserved};
            options.reconstructionDeadline =
                std::chrono::steady_clock::now() +
                std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(
                    args.time - total.seconds() - setup.finishReserved.seconds));
        }
    }
    options.elapsedBefore = total.seconds();

    // Checkpoints: the identity of this render is recorded in every checkpoint written, and
    // a checkpoint resumed from must have the same (render_identity.h).
    setup.identity = renderIdentity(integrator, scene, options);
    if (merged) {  // gdpt merge: the shards' statistics, merged
        setup.resumed = Checkpoint{merged->identity, merged->info, merged->state};
        checkIdentity("the shards", setup.resumed->identity, setup.identity);
        options.resume = &setup.resumed->state;
    } else if (!args.resume.empty()) {
        setup.resumed = readCheckpoint(args.resume);
        checkIdentity(args.resume, setup.resumed->identity, setup.identity);
        if (!timed && setup.resumed->state.spp > options.share.localSpp(args.spp))
            throw Error(args.resume + ": checkpoint already has " + std::to_string(setup.resumed->state.spp) +
                        " spp, more than --spp " + std::to_string(args.spp) +
                        (!args.shard.empty() ? " gives part " + options.share.text() : ""));
        if (!quiet && setup.resumed->info.count("device") && setup.resumed->info["device"] != ctx.info().name)
            std::fprintf(stderr,
                         "gdpt: warning: %s was rendered on '%s'; continuing on '%s' (same statistics, "
                         "not the same bits)\n",
                         args.resume.c_str(), setup.resumed->info["device"].c_str(), ctx.info().name.c_str());
        options.resume = &setup.resumed->state;
    }
    if (world) {
        ExrAttributes description = setup.identity;
        description.erase("share");
        description["spp"] = timed ? "--time " + std::to_string(args.time) : std::to_string(args.spp);
        // Every rank samples for rank 0's budget (its reservations: the reconstruction, and
        // what the last such render spent after sampling, the merge included).
        world->agree(description, "", timed ? &options.timeBudget : nullptr);
    }
}

// Where the sampler's state goes as the render runs: --checkpoint's file on its schedule, and
// for a render split across processes the merge of the ranks' states (mpirun) or this shard's
// state, kept in `shardState` for its file.
void routeSamplerState(const RenderArgs& args, MpiWorld* world, const ExrAttributes& identity,
                       const ExrAttributes& info, RenderOptions& options,
                       std::optional<SamplerState>& shardState) {
    if (!args.checkpoint.empty()) {
        options.checkpoint = [&args, identity, info](const SamplerState& state) {
            writeCheckpoint(args.checkpoint, identity, info, state);
        };
        options.checkpointEvery = args.checkpointEvery;
    }
    if (world) {
        options.combine = [world](SamplerState mine, RenderStats& stats) {
            world->testFault("sampling");
            return world->combine(std::move(mine), stats);
        };
    } else if (!args.shard.empty()) {
        options.combine = [&shardState](SamplerState mine,
                                        RenderStats& stats) -> std::optional<SamplerState> {
            if (!stats.cancelled) shardState = std::move(mine);
            return std::nullopt;
        };
    }
}

// The line on stderr that says what was written, and the budget's note.
void reportWritten(const RenderArgs& args, const RenderOptions& options, const Integrator& integrator,
                   const RenderStats& s, bool merged, double seconds, const BudgetReport& budget) {
    const bool shard = !args.shard.empty();
    const std::string partial =
        s.partialPassRows ? " + 1 in the top " + std::to_string(s.partialPassRows) + " rows" : "";
    std::string parts;
    if (s.distributed.parts > 1)
        parts = ", " + std::to_string(s.distributed.parts) + (merged ? " shards" : " ranks") + " merged in " +
                std::to_string(static_cast<long>(s.distributed.mergeMs)) + " ms";
    if (shard) parts = ", part " + options.share.text() + " of " + std::to_string(args.spp) + " spp";
    char sampling[160] = "";  // gdpt merge samples nothing itself
    if (!merged)
        std::snprintf(sampling, sizeof sampling,
                      ", BVH %.1f ms, sampling %.1f ms, %.2f Mrays/s, %.3f Msamples/s", s.bvhBuildMs,
                      s.samplingMs, double(s.raysTraced) / (s.samplingMs * 1e-3) * 1e-6,
                      double(s.pathsCompleted) / (s.samplingMs * 1e-3) * 1e-6);
    std::fprintf(stderr, "gdpt: wrote %s%s (%u spp%s%s%s, %.2f s total%s)\n", shard ? "shard " : "",
                 args.output.c_str(), s.spp, partial.c_str(), parts.c_str(), integrator.summary(s).c_str(),
                 seconds, sampling);
    if (args.time > 0.0)
        if (const std::optional<std::string> note = budgetNote(budget, s))
            std::fprintf(stderr, "gdpt: note: %s\n", note->c_str());
}

}  // namespace

int runRender(const RenderArgs& args, const MergedShards* merged) {
    installInterruptHandlers();
    checkArgs(args);
    checkImageMemory(args);
    Timer total;
    RenderOptions options = renderOptionsFor(args);
    // Remembered times per scene first (a reconstruction's time follows the image), else of the
    // last render of the same configuration.
    const ReconTimeCache cache(ReconTimeCache::defaultPath(), "scene " + absolutePath(args.scene));
    MpiWorld* world = MpiWorld::get();
    const bool shard = !args.shard.empty();
    takeShare(args, world, options);
    // Only rank 0 of mpirun writes, reports progress and finishes the render.
    const bool writes = !world || world->root();
    if (!writes) options.quiet = options.scene.quiet = true;
    const bool quiet = options.quiet;
    const bool timed = args.time > 0.0;

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

    RenderSetup setup;
    try {
        setUpRender(args, merged, world, cache, total, options, setup);
    } catch (const std::exception& e) {
        // Every rank takes part in the agreement, so that one rank's failure ends them all.
        if (world && !world->agreed()) world->agree({}, e.what());
        throw;
    }
    const Scene& scene = *setup.scene;
    const vk::Context& ctx = *setup.context;
    Integrator& integrator = *setup.integrator;

    const ExrAttributes info = {{"device", ctx.info().name}, {"scene_file", args.scene}};
    std::optional<SamplerState> shardState;
    routeSamplerState(args, world, setup.identity, info, options, shardState);
    const std::string checkpointNote = args.checkpoint.empty()
                                           ? ""
                                           : "; checkpoint written to " + args.checkpoint +
                                                 " (continue with --resume " + args.checkpoint + ")";
    enterPhase("sampling");
    RenderOutput out;
    try {
        out = integrator.render(ctx, scene, options);
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
        writeCheckpoint(*exrFile, setup.identity, shardInfo, *shardState);
    } else {
        checkFinite(out.layers, args.output);
        writeExr(*exrFile, out.layers);
        throwIfInterrupted("writing");
        writePngPreview(*pngFile, out.image());
    }
    throwIfInterrupted("writing");
    const double writeMs = writeTimer.ms();
    const double seconds = total.seconds();
    const double reserved = setup.reserved.seconds, finishReserved = setup.finishReserved.seconds;
    const BudgetReport budget =
        budgetReport(args.time, s, seconds, reserved + finishReserved, seconds - afterSampling);
    if (args.profile) printProfile(s.kernels);
    if (jsonOutput.wanted()) {
        json summary = summaryJson(args, ctx, integrator, s, seconds, reserved, finishReserved, writeMs);
        summary["time_s"]["load"] = setup.loadSeconds;
        summary["scene_size"] = sceneSizeJson(scene, s, summary["memory"]["host_peak_bytes"].get<double>());
        if (shard) summary["shard"] = options.share.text();
        if (timed) summary["budget"] = budgetJson(budget, s);
        jsonOutput.write(summary.dump(2) + "\n");
        throwIfInterrupted("writing");
    }
    outputs.commit();
    if (timed && !shard)
        cache.put(
            setup.finishKey,
            {std::max(0.0, total.seconds() - afterSampling - s.reconstructionMs * 1e-3), s.samplingLoad});
    if (!quiet) reportWritten(args, options, integrator, s, merged != nullptr, seconds, budget);
    return validationExitStatus(ctx);
}

int runRender(const RenderArgs& given) {
    RenderArgs args = given;
    args.recon = resolvedRecon(args.method, args.recon);  // as the render's settings record it
    if (!args.frames.empty()) return runSequence(args);
    return runRender(args, nullptr);
}

}  // namespace gdpt
