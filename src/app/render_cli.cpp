// render_cli.cpp — `gdpt render`'s command line: every option, its help, default and check,
// grouped by purpose (--help). runRender (render_command.cpp) renders what it parsed.
#include <CLI/CLI.hpp>
#include <iterator>
#include <memory>

#include "app/cli.h"
#include "app/commands.h"
#include "app/edge_samples_option.h"
#include "app/input_file.h"
#include "app/subcommand.h"
#include "integrator/integrator.h"
#include "poisson/debias.h"
#include "poisson/poisson_gpu.h"
#include "render/device_scene/light_table.h"
#include "render/passes/emitter_supersampling_options.h"

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
