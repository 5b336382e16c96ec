// sequence_command.cpp — `gdpt render SCENE --frames A:B`: the frames of an animation, each
// rendered like a single image (render_setup.h) at time frame / fps of the chosen animation
// and written, EXR + PNG, as soon as it is done; then a video of the PNGs when ffmpeg is
// installed, and the sequence's JSON summary. The file is parsed once (GltfAsset); the device,
// the integrator and its reconstruction solver are made once for the whole sequence.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>

#include "app/bench_util.h"
#include "app/commands.h"
#include "app/render_setup.h"
#include "app/video_preview.h"
#include "distributed/mpi_world.h"
#include "image/exr_io.h"
#include "image/finite_check.h"
#include "image/png_preview.h"
#include "integrator/recon_reserve.h"
#include "render/device_scene/scene_gpu.h"
#include "scene/gltf_loader.h"
#include "util/error.h"
#include "util/frame_pattern.h"
#include "util/interrupt.h"
#include "util/output_files.h"
#include "util/timer.h"
#include "vk/context.h"

namespace gdpt {
namespace {

using nlohmann::json;

// Usage errors of a sequence (exit 2 before any work).
void checkSequenceArgs(const RenderArgs& args, const FrameRange& range) {
    if (!args.checkpoint.empty() || !args.resume.empty())
        throw UsageError(
            "--checkpoint and --resume are for one image; a sequence writes each frame when it is done, so "
            "an interrupted sequence continues with --frames FROM:" +
            std::to_string(range.last) + " from the first frame missing");
    if (!args.shard.empty())
        throw UsageError("--shard splits one image; split a sequence by its frames (--frames A:B per job)");
    if (MpiWorld::get())
        throw UsageError(
            "a sequence under mpirun is not supported; run one gdpt per range of --frames instead");
    if (!hasFrameNumber(args.output, "-o") && range.count() > 1)
        throw UsageError("-o " + args.output + ": " + std::to_string(range.count()) +
                         " frames need a frame number in the output name, e.g. -o frames/frame_%04d.exr");
}

// Creates the directory of the frames (a sequence usually goes to a fresh one).
void makeOutputDirectory(const std::string& path) {
    const std::filesystem::path dir = std::filesystem::path(path).parent_path();
    if (dir.empty()) return;
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw Error(path + ": cannot create the directory " + dir.string() + ": " + ec.message());
}

std::string seconds(double s) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f s", s);
    return text;
}

// One sequence's frames, rendered in order on one device by one integrator (made once), each
// written when it is done.
class SequenceRender {
public:
    SequenceRender(const RenderArgs& args, const FrameRange& range, const RenderOptions& options,
                   const GltfAsset& asset, int animation, const vk::Context& ctx, Integrator& integrator,
                   const Timer& total, const TextOutput& jsonOutput)
        : args_(args),
          range_(range),
          options_(options),
          asset_(asset),
          animation_(animation),
          ctx_(ctx),
          integrator_(integrator),
          total_(total),
          jsonOutput_(jsonOutput),
          quiet_(options.quiet),
          timed_(args.time > 0.0),
          reserved_(timed_ ? integrator.reserveAfterSampling(ctx, args.width, args.height).seconds : 0.0),
          frame_(range.first) {}

    // An interrupt ends the sequence with exit 130; the frames before the current one are
    // written whole, the current one not at all.
    int interrupted(const std::string& phase) const {
        const std::string written =
            frame_ == range_.first ? "no frame written"
            : frame_ == range_.first + 1
                ? "frame " + std::to_string(range_.first) + " written"
                : "frames " + std::to_string(range_.first) + " to " + std::to_string(frame_ - 1) + " written";
        if (frame_ > range_.last)
            std::fprintf(stderr, "gdpt: interrupted while %s; all %d frames written\n", phase.c_str(),
                         range_.count());
        else
            std::fprintf(stderr, "gdpt: interrupted while %s frame %d; %s (continue with --frames %d:%d)\n",
                         phase.c_str(), frame_, written.c_str(), frame_, range_.last);
        return 130;
    }

    // Timed: the kernels compile once for the sequence (the context keeps them), before the
    // frames' shares are set, by a one-sample render of the first frame at 8x8 pixels (the
    // pipelines do not depend on the image size). Else the first frame compiled them inside its
    // own share and had a sample or two per pixel where the others have dozens. Returns 130
    // (interrupted) or 0.
    int compileKernels() {
        Timer warmUp;
        RenderOptions warm = options_;
        warm.scene.width = warm.scene.height = 8;
        warm.spp = 1;
        warm.timeBudget = 0.0;
        warm.quiet = true;
        const char* phase = "compiling the kernels for";
        bool cancelled = false;
        try {
            enterPhase(phase);
            if (integrator_.windowFrames() > 0) {
                const std::vector<RenderOutput> outs =
                    integrator_.renderWindow(ctx_, windowOf(frame_, 1), warm);
                cancelled = outs.empty() || outs.back().stats.cancelled;
            } else {
                cancelled = integrator_.render(ctx_, sceneAt(frame_), warm).stats.cancelled;
            }
        } catch (const Interrupted&) {
            cancelled = true;
        }
        if (cancelled || interruptRequested()) return interrupted(phase);
        if (!quiet_)
            std::fprintf(stderr, "gdpt: kernels ready for the sequence in %s\n",
                         seconds(warmUp.seconds()).c_str());
        return 0;
    }

    // Every frame of the range, each written when done (a temporal method's in windows).
    // Returns 130 (interrupted) or 0.
    int renderFrames() {
        const int window = integrator_.windowFrames();
        while (frame_ <= range_.last) {
            try {
                if (window > 0) {
                    // A temporal method: a window of frames sampled and reconstructed together.
                    Timer windowTimer;
                    const FrameWindow w = windowOf(frame_, std::min(window, range_.last - frame_ + 1));
                    RenderOptions windowOptions = options_;
                    if (timed_) windowOptions.timeBudget = budgetFor(w.count);
                    enterPhase("sampling");
                    std::vector<RenderOutput> outs = integrator_.renderWindow(ctx_, w, windowOptions);
                    if (outs.empty() || outs.back().stats.cancelled) return interrupted("sampling");
                    const double each = windowTimer.seconds() / double(outs.size());
                    for (RenderOutput& out : outs) {
                        writeFrame(out, each, each - out.stats.reconstructionMs * 1e-3);
                        ++frame_;
                    }
                    continue;
                }
                Timer frameTimer;
                const Scene scene = sceneAt(frame_);
                RenderOptions frameOptions = options_;
                frameOptions.seed = sequenceFrameSeed(args_.seed, frame_);
                if (timed_) frameOptions.timeBudget = budgetFor(1);
                frameOptions.elapsedBefore = frameTimer.seconds();
                enterPhase("sampling");
                RenderOutput out = integrator_.render(ctx_, scene, frameOptions);
                if (out.stats.cancelled) return interrupted("sampling");
                const double sampledAt =
                    frameTimer.seconds() - (out.stats.readbackMs + out.stats.reconstructionMs) * 1e-3;
                writeFrame(out, frameTimer.seconds(), sampledAt);
                ++frame_;
            } catch (const Interrupted& e) {
                return interrupted(e.phase());
            } catch (const std::exception&) {
                if (interruptRequested()) return interrupted("rendering");  // a layer re-wrapped it
                throw;
            }
        }
        return 0;
    }

    // The frames' JSON summaries (--json), in order.
    nlohmann::json takeFrameSummaries() { return std::move(frames_); }

private:
    // The scene of a frame (the first one also says what the scene cannot show).
    Scene sceneAt(int f) {
        enterPhase("loading");
        Scene scene = asset_.instance(animation_, double(f) / args_.fps);
        if (!warned_ && !quiet_) warnAboutScene(args_.scene, scene, options_.scene.envRadiance);
        warned_ = true;
        return scene;
    }

    // Frames first .. first + count - 1 as a temporal method's window.
    FrameWindow windowOf(int first, int count) {
        FrameWindow w;
        w.first = first;
        w.count = count;
        w.scene = [this](int f) { return sceneAt(f); };
        w.seed = [this](int f) { return sequenceFrameSeed(args_.seed, f); };
        w.startsSequence = first == range_.first;
        return w;
    }

    // --time is the whole sequence's: each frame gets an equal share of what is left, less what
    // the method reserves after sampling and the last frame needed to be written; a window of
    // `count` frames gets their shares.
    double budgetFor(int count) const {
        const int left = range_.last - frame_ + 1;
        const double share = std::max(0.0, args_.time - total_.seconds()) / double(left);
        return std::max(0.05 * args_.time / double(range_.count()),
                        double(count) * (share - afterSamplingSeconds_) - reserved_);
    }

    // Writes the current frame's EXR and PNG (together, whole or not at all), its summary and
    // progress. `frameSeconds` is what the frame cost (a window's frames share its time),
    // `sampledAt` when its sampling ended.
    void writeFrame(RenderOutput& out, double frameSeconds, double sampledAt) {
        enterPhase("writing");
        const RenderStats& s = out.stats;
        const std::string exrPath = framePath(args_.output, frame_);
        const double time = double(frame_) / args_.fps;
        Timer writeTimer;
        OutputSet outputs({{"scene", args_.scene}});
        const StagedFile& exrFile = outputs.add(exrPath, "-o (frame " + std::to_string(frame_) + ")");
        const StagedFile& pngFile = outputs.add(previewPath(exrPath), "PNG preview of -o");
        checkFinite(out.layers, exrPath);
        writeExr(exrFile, out.layers);
        throwIfInterrupted("writing");
        writePngPreview(pngFile, out.image());
        throwIfInterrupted("writing");
        outputs.commit();
        const double writeMs = writeTimer.ms();
        frameSeconds += writeMs * 1e-3;
        afterSamplingSeconds_ = std::max(0.0, frameSeconds - sampledAt - s.reconstructionMs * 1e-3);
        if (jsonOutput_.wanted()) {
            RenderArgs frameArgs = args_;
            frameArgs.output = exrPath;
            frameArgs.seed = sequenceFrameSeed(args_.seed, frame_);
            json j = summaryJson(frameArgs, ctx_, integrator_, s, frameSeconds, reserved_,
                                 afterSamplingSeconds_, writeMs);
            j["frame"] = frame_;
            j["time"] = time;
            frames_.push_back(std::move(j));
        }
        if (!quiet_) {
            const int done = frame_ - range_.first + 1, left = range_.last - frame_;
            const double elapsed = total_.seconds();
            const double remaining = elapsed / double(done) * double(left);
            std::fprintf(
                stderr, "gdpt: frame %d (%d/%d, t = %.4g s): wrote %s (%u spp%s, %s); sequence %s, %s\n",
                frame_, done, range_.count(), time, exrPath.c_str(), s.spp, integrator_.summary(s).c_str(),
                seconds(frameSeconds).c_str(), seconds(elapsed).c_str(),
                left > 0 ? ("about " + seconds(remaining) + " left").c_str() : "done");
        }
        if (args_.profile) printProfile(s.kernels);
    }

    const RenderArgs& args_;
    const FrameRange& range_;
    const RenderOptions& options_;
    const GltfAsset& asset_;
    int animation_;
    const vk::Context& ctx_;
    Integrator& integrator_;
    const Timer& total_;
    const TextOutput& jsonOutput_;
    bool quiet_, timed_;
    double reserved_;  // what the method reserves after each frame's sampling (timed)
    int frame_;        // the frame being rendered
    json frames_ = json::array();
    double afterSamplingSeconds_ = 0.0;  // the last frame's time after its sampling (reconstruction aside)
    bool warned_ = false;
};

// The animation --animation names, else the file's first; -1 for a file without animations.
int chosenAnimation(const GltfAsset& asset, const RenderArgs& args, bool quiet) {
    int animation = -1;
    if (!args.animation.empty())
        animation = asset.findAnimation(args.animation);
    else if (!asset.animations().empty())
        animation = 0;
    if (animation < 0 && !quiet)
        std::fprintf(stderr, "gdpt: note: %s has no animations; every frame is the same still scene\n",
                     args.scene.c_str());
    return animation;
}

}  // namespace

int runSequence(const RenderArgs& args) {
    installInterruptHandlers();
    checkArgs(args);
    const FrameRange range = parseFrameRange(args.frames, "--frames");
    checkSequenceArgs(args, range);
    Timer total;
    RenderOptions options = renderOptionsFor(args);
    const bool quiet = options.quiet;
    const ReconTimeCache cache(ReconTimeCache::defaultPath());

    // The outputs that exist once per sequence, and the first frame's, are checked before
    // anything is loaded; each frame's EXR and PNG are staged when the frame is rendered and
    // committed together, so an interrupted sequence leaves only complete frames.
    makeOutputDirectory(args.output);
    OutputSet sequenceOutputs({{"scene", args.scene}});
    const TextOutput jsonOutput(sequenceOutputs, args.json, "--json");
    {
        OutputSet probe({{"scene", args.scene}});
        probe.add(framePath(args.output, range.first), "-o");
        probe.add(previewPath(framePath(args.output, range.first)), "PNG preview of -o");
    }
    const std::optional<std::string> ffmpeg = args.noVideo || range.count() < 2 ? std::nullopt : findFfmpeg();
    const std::string video = ffmpeg ? sequenceVideoPath(args.output, ".mp4") : "";
    if (ffmpeg) sequenceOutputs.checkSeparate(video, "the sequence's video");

    enterPhase("loading");
    const GltfAsset asset(args.scene, deviceLoadOptions(args.device, quiet));
    const int animation = chosenAnimation(asset, args, quiet);
    const double duration =
        animation >= 0 ? asset.animations()[static_cast<std::size_t>(animation)].duration() : 0.0;
    throwIfInterrupted("loading");

    vk::ContextOptions ctxOptions;
    ctxOptions.device = args.device;
    ctxOptions.validation = args.validate;
    ctxOptions.keepPipelines = true;  // every frame's kernels compile once (vk/pipeline_cache.h)
    const vk::Context ctx(ctxOptions);
    if (!quiet)
        std::fprintf(
            stderr, "gdpt: device '%s' (%s, %s); %d frames at %g fps%s\n", ctx.info().name.c_str(),
            ctx.info().type.c_str(), ctx.info().driverInfo.c_str(), range.count(), args.fps,
            animation >= 0
                ? (", animation " + std::to_string(animation) + " (" + seconds(duration) + ")").c_str()
                : "");
    std::unique_ptr<Integrator> integrator = integratorFor(args, &cache);
    SequenceRender sequence(args, range, options, asset, animation, ctx, *integrator, total, jsonOutput);
    if (args.time > 0.0)
        if (const int status = sequence.compileKernels()) return status;
    if (const int status = sequence.renderFrames()) return status;

    std::string videoNote;
    if (ffmpeg) {
        enterPhase("writing");
        const std::string pngPattern = previewPath(args.output);
        const std::string failure =
            encodeVideo(*ffmpeg, pngPattern, range.first, range.count(), args.fps, video);
        if (interruptRequested()) return sequence.interrupted("writing the video");
        if (!failure.empty()) {
            if (!quiet)
                std::fprintf(stderr, "gdpt: warning: no video of the sequence: %s\n", failure.c_str());
        } else {
            videoNote = ", video " + video;
        }
    }
    if (jsonOutput.wanted()) {
        json summary = {
            {"scene", args.scene},
            {"output", args.output},
            {"method", args.method},
            {"device", ctx.info().name},
            {"frames", {{"first", range.first}, {"last", range.last}, {"count", range.count()}}},
            {"fps", args.fps},
            {"animation", animation >= 0
                              ? json{{"index", animation},
                                     {"name", asset.animations()[static_cast<std::size_t>(animation)].name},
                                     {"duration", duration}}
                              : json(nullptr)},
            {"time_budget", args.time},
            {"time_s", total.seconds()},
            {"video", videoNote.empty() ? json(nullptr) : json(video)},
            {"validation_errors", ctx.validationErrors()},
            {"frame_summaries", sequence.takeFrameSummaries()}};
        jsonOutput.write(summary.dump(2) + "\n");
        if (interruptRequested()) return sequence.interrupted("writing the summary");
    }
    sequenceOutputs.commit();
    if (!quiet)
        std::fprintf(stderr, "gdpt: wrote %d frames %s%s in %s\n", range.count(), args.output.c_str(),
                     videoNote.c_str(), seconds(total.seconds()).c_str());
    return validationExitStatus(ctx);
}

}  // namespace gdpt
