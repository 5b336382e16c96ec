#include "integrator/mlt_integrator.h"

#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <utility>

#include "integrator/gpt_sampler.h"
#include "integrator/mlt_estimate.h"
#include "integrator/render_identity.h"
#include "render/device_scene/scene_gpu.h"
#include "scene/radiance_range.h"
#include "util/error.h"
#include "util/interrupt.h"
#include "util/progress.h"
#include "util/timer.h"
#include "vk/commands.h"
#include "vk/context.h"
#include "vk/timing.h"

namespace gdpt {
namespace {
// Mutation steps a batch records: 2 records per chain and step (mlt_shared.h MltRecord).
constexpr std::uint32_t kStepsPerBatch = 8;
// Bootstrap samples per dispatch.
constexpr std::uint32_t kBootstrapPerDispatch = 1u << 16;
// Bootstrap samples per chain at least, so that the starts are drawn from many more states.
constexpr std::uint32_t kBootstrapPerChain = 16;
// The options with the method's own defaults where they are left to it.
MltOptions withMethodDefaults(const std::string& method, MltOptions o) {
    if (o.largeStep < 0.0f) o.largeStep = method == "gmlt" ? kGmltLargeStep : kPssmltLargeStep;
    if (o.targetExponent < 0.0f) o.targetExponent = method == "gmlt" ? kGmltTargetExponent : 1.0f;
    if (o.targetBlock < 0) o.targetBlock = method == "gmlt" ? kGmltTargetBlock : 0;
    return o;
}
}  // namespace

std::uint32_t defaultMltChains(int width, int height) {
    const std::uint64_t pixels = std::uint64_t(std::max(width, 1)) * std::uint64_t(std::max(height, 1));
    return static_cast<std::uint32_t>(std::clamp<std::uint64_t>(pixels / 16, 1024, 65536));
}

MltIntegrator::MltIntegrator(std::string name, MltOptions options)
    : name_(std::move(name)),
      options_(withMethodDefaults(name_, std::move(options))),
      // pssmlt has no gradients to reconstruct: its image is the splatted primal.
      stage_(name_ == "gmlt" ? options_.reconstructions : std::vector<Reconstruction>{}, options_.alpha,
             options_.tolerance, 0, options_.solver) {}

MltIntegrator::~MltIntegrator() = default;

std::uint32_t MltIntegrator::maxBatchSpp(int, int) const {
    return 1;
}

ExrAttributes MltIntegrator::identity(const Scene&, const RenderOptions& options) const {
    return {{"chains",
             std::to_string(options_.chains ? options_.chains
                                            : defaultMltChains(options.scene.width, options.scene.height))},
            {"large_step", exactFloat(options_.largeStep)},
            {"target_alpha", exactFloat(options_.targetAlpha)},
            {"target_exponent", exactFloat(options_.targetExponent)},
            {"target_block", std::to_string(options_.targetBlock)},
            {"shift_threshold", exactFloat(options.scene.shiftThreshold)}};
}

ReservedTime MltIntegrator::reserveAfterSampling(const vk::Context& ctx, int width, int height) {
    return stage_.reserve(ctx, width, height, nullptr);
}

RenderOutput MltIntegrator::render(const vk::Context& ctx, const Scene& scene, const RenderOptions& options) {
    if (options.resume || options.checkpoint || options.share.split() || options.combine)
        throw UsageError("--method " + name_ +
                         " keeps its state in its Markov chains: checkpoints, --resume, --shard and mpirun "
                         "are for pt and gpt");
    checkRadianceRange(scene, options.scene.envRadiance);
    Timer total;
    RenderOutput out;
    RenderStats& stats = out.stats;
    const int width = options.scene.width, height = options.scene.height;
    const std::uint64_t pixels = std::uint64_t(width) * std::uint64_t(height);

    // Set-up: the kernel compiles on a worker thread while the scene is built and uploaded.
    MltPassOptions po;
    po.baseOnly = !gradients();
    po.chains = options_.chains ? options_.chains : defaultMltChains(width, height);
    po.stepsPerBatch = kStepsPerBatch;
    po.largeStep = options_.largeStep;
    po.targetAlpha = options_.targetAlpha;
    po.targetExponent = options_.targetExponent;
    po.emitterSupersampling = options.emitterSupersampling;
    po.splitBounce = options_.splitBounce;
    SceneSpec spec(scene, options.scene);
    MltPass pass(ctx, spec, options.workgroup, po, vk::PipelineCreation::Background);
    SceneGpu sceneGpu(ctx, scene, options.scene, std::move(spec));
    pass.attach(sceneGpu);
    stats.bvhBuildMs = sceneGpu.bvhInfo().buildMs;
    stats.sceneDeviceBytes = sceneGpu.deviceBytes();
    stats.bvhRegisterStack = sceneGpu.spec().bvhRegisterStack();
    stats.bvhUnitSteps = sceneGpu.spec().bvhUnitSteps(ctx.info());
    stats.gptSplitBounce = pass.splitBounceCompiled();
    stats.lightShares = sceneGpu.lightShares();
    stats.lightProbed = sceneGpu.lightProbed();
    stats.features = sceneGpu.features();
    if (options.whileCompiling) options.whileCompiling();
    if (!stage_.empty()) stage_.solver(ctx, width, height).preparePipelines(stage_.solves());
    stats.pipelineWaitMs = 1e3 * pass.waitForPipelines();
    stats.uploadMs = total.ms() - stats.bvhBuildMs;

    vk::GpuTimer gpuTimer(ctx);
    vk::GpuTimer* timer = options.profile ? &gpuTimer : nullptr;
    vk::CommandStream stream(ctx, name_);
    const auto submit = [&](const std::string& what, const std::function<void(VkCommandBuffer)>& work) {
        VkCommandBuffer cmd = stream.begin();
        if (timer) timer->reset(cmd);
        work(cmd);
        stream.setWhat(what);
        stream.submit();
        stream.waitAll();
        if (timer) timer->collect();
        const gpu::Counters c = pass.takeCounters();
        stats.raysTraced += c.raysTraced;
        stats.pathsCompleted += c.pathsCompleted;
        stats.nanSamples += c.nanSamples;
    };
    const auto cancelled = [&] { return options.cancel && options.cancel->load(); };
    // The kernel's compile at its first dispatch: a fixed cost (time_s.kernel_compile), not
    // the very-direct light's (PixelSampling::run does the same for PT and G-PT).
    Timer compile;
    submit(name_ + " kernel's first dispatch", [&](VkCommandBuffer cmd) { pass.recordWarmUp(cmd); });
    stats.compileMs = compile.ms();
    Timer sampling;

    // Stage 1: the very-direct light, and the bootstrap: b and the chains' starts.
    submit(name_ + " direct light",
           [&](VkCommandBuffer cmd) { pass.recordDirect(cmd, options_.directSamples, options.seed, timer); });
    const std::uint64_t bootstrapCount = std::max<std::uint64_t>(
        pixels * options_.bootstrapPerPixel, std::uint64_t{po.chains} * kBootstrapPerChain);
    if (bootstrapCount > std::uint64_t{1} << 31)
        throw UsageError("--method " + name_ + ": " + std::to_string(bootstrapCount) +
                         " bootstrap samples are more than this renderer counts; use a smaller image");
    std::vector<gpu::MltBootstrapSample> bootstrap;
    bootstrap.reserve(bootstrapCount);
    for (std::uint64_t first = 0; first < bootstrapCount && !cancelled(); first += kBootstrapPerDispatch) {
        const auto n = static_cast<std::uint32_t>(
            std::min<std::uint64_t>(kBootstrapPerDispatch, bootstrapCount - first));
        submit(name_ + " bootstrap from sample " + std::to_string(first), [&](VkCommandBuffer cmd) {
            pass.recordBootstrap(cmd, static_cast<std::uint32_t>(first), n, options.seed, timer);
        });
        const std::vector<gpu::MltBootstrapSample> part = pass.bootstrapSamples(n);
        bootstrap.insert(bootstrap.end(), part.begin(), part.end());
    }
    // The target's divisors per image block (mlt_estimate.h), from the even bootstrap samples;
    // the chains walk the divided target, which the bootstrap's targets are then divided by too.
    const MltBlockNormaliser normaliser =
        mltBlockNormaliser(bootstrap, std::uint32_t(width), std::uint32_t(height),
                           static_cast<std::uint32_t>(options_.targetBlock), options_.targetExponent);
    pass.setNormaliser(normaliser.block, normaliser.divisors);
    std::vector<float> targets(bootstrap.size());
    TargetSums bootstrapSums;  // every bootstrap sample's target: b' and the starts' ESS
    TargetSums fresh;          // the fresh states that b̂ pools: the bootstrap's, then the large steps'
    for (std::size_t i = 0; i < bootstrap.size(); ++i) {
        targets[i] = bootstrap[i].target / normaliser.divisor(bootstrap[i].pixel, std::uint32_t(width));
        bootstrapSums.add(targets[i]);
        // With blocks, the samples the divisors were built from are left out of b̂.
        if (normaliser.block == 0 || i % 2 == 1) fresh.add(targets[i]);
    }
    bootstrap = {};
    stats.mlt.bootstrapEss = bootstrapSums.effectiveSampleSize();
    // b' of the splat weights (mlt.glsl): the bootstrap's b̂.
    const auto misNormalisation = static_cast<float>(bootstrapSums.normalisation().b);
    pass.setMisNormalisation(misNormalisation);
    stats.mlt.chains = po.chains;
    stats.mlt.bootstrapSamples = targets.size();
    const std::vector<std::uint32_t> starts = mltChainStarts(targets, po.chains, options.seed);
    targets = {};

    // Stage 2: the chains. Mutation steps in batches; the host splats each batch's records
    // in record order while nothing else runs (the same order on every run).
    MltAccumulator acc(width, height, misNormalisation, po.largeStep);
    const bool timed = options.timeBudget > 0.0;
    const double budget = options.timeBudget - options.elapsedBefore;
    const std::uint64_t wantedMutations = std::uint64_t{options.spp} * pixels;
    const std::uint64_t wantedSteps = (wantedMutations + po.chains - 1) / po.chains;
    std::uint64_t steps = 0;
    if (!starts.empty() && !cancelled()) {
        submit(name_ + " chain start",
               [&](VkCommandBuffer cmd) { pass.recordStart(cmd, starts, options.seed, timer); });
        Progress progress("render " + name_, timed ? budget : double(wantedSteps), options.quiet);
        double secondsPerStep = 0.0;
        stats.setupSeconds = options.elapsedBefore + total.seconds();  // the bootstrap included
        while (!cancelled()) {
            std::uint32_t n = kStepsPerBatch;
            if (!timed) {
                if (steps >= wantedSteps) break;
                n = static_cast<std::uint32_t>(std::min<std::uint64_t>(n, wantedSteps - steps));
            } else if (steps == 0) {
                n = 1;  // measures a step; the set-up may have used the budget already
            } else {
                const double left = budget - total.seconds();
                const auto fits =
                    static_cast<std::uint64_t>(std::max(0.0, left / std::max(secondsPerStep, 1e-9)));
                if (fits == 0) break;
                n = static_cast<std::uint32_t>(std::min<std::uint64_t>(n, fits));
            }
            if (steps + n > UINT32_MAX) break;  // step indices are 32-bit
            Timer batch;
            submit(name_ + " mutation steps " + std::to_string(steps) + ".." + std::to_string(steps + n - 1) +
                       " (seed " + std::to_string(options.seed) + ")",
                   [&](VkCommandBuffer cmd) {
                       pass.recordMutations(cmd, static_cast<std::uint32_t>(steps), n, options.seed, timer);
                   });
            Timer splat;
            acc.add(pass.records(n), std::size_t{2} * po.chains * n);
            stats.mlt.splatMs += splat.ms();
            steps += n;
            ++stats.batches;
            secondsPerStep = batch.seconds() / n;
            if (stats.firstBatchSeconds == 0.0) stats.firstBatchSeconds = batch.seconds();
            char rate[64];
            std::snprintf(rate, sizeof rate, "%.1f mutations/pixel",
                          double(steps) * double(po.chains) / double(pixels));
            progress.update(timed ? total.seconds() : double(steps), rate);
        }
        progress.finish();
        const MltAcceptance a = pass.acceptance();
        stats.mlt.proposedSmall = a.proposedSmall;
        stats.mlt.acceptedSmall = a.acceptedSmall;
        stats.mlt.proposedLarge = a.proposedLarge;
        stats.mlt.acceptedLarge = a.acceptedLarge;
    }
    stats.mlt.mutations = steps * po.chains;
    stats.spp = static_cast<std::uint32_t>(stats.mlt.mutations / pixels);
    stats.samplingMs = sampling.ms();
    stats.kernels = gpuTimer.totals();
    if (cancelled()) {
        stats.cancelled = true;
        return out;
    }
    if (stats.nanSamples > 0 && !options.quiet)
        std::fprintf(stderr, "gdpt: warning: %s: %llu samples were NaN/Inf and were counted as zero\n",
                     name_.c_str(), static_cast<unsigned long long>(stats.nanSamples));

    // Stage 3: the estimate, X(p) = W·H/N Σ (b̂·weight + largeWeight)·X (mlt_estimate.h), with
    // b̂ from every fresh state (Kelemen et al. 2002, §4); gmlt reconstructs.
    fresh.add(acc.largeSteps());
    const MltNormalisation norm = fresh.normalisation();
    stats.mlt.normalisation = norm.b;
    stats.mlt.normalisationStdErr = norm.standardError;
    stats.mlt.normalisationSamples = norm.samples;
    Timer readback;
    MltScale scale;
    if (stats.mlt.mutations) {
        scale.large = double(pixels) / double(stats.mlt.mutations);
        scale.metropolis = scale.large * norm.b;
    }
    Image direct = pass.directImage();
    stats.readbackMs = readback.ms();
    const gpu::VisibleCounter visible = pass.emitterSupersampling().report();
    stats.emitterSupersampling = pass.emitterSupersampling().samplesPerSpp();
    stats.emitterRaysPerSample = visible.raysPerSample;
    stats.emitterSupersampledPixels = visible.refinedPixels;
    if (!gradients()) {
        Image primal = acc.quantity(gpu::kMltCentral, scale);
        out.layers.push_back({"", gptFinal(primal, nullptr, &direct)});
        out.layers.push_back({"primal", std::move(primal)});
        out.layers.push_back({"direct", std::move(direct)});
        return out;
    }
    MltImages g = resolveGradientSamples(acc, scale);
    PoissonInput input;
    input.primal = &g.primal;
    input.dx = &g.dx;
    input.dy = &g.dy;
    std::vector<NamedLayer> recons = stage_.run(input, options, stats, nullptr);
    out.layers.push_back({"", gptFinal(recons.empty() ? g.primal : recons.front().image, nullptr, &direct)});
    for (NamedLayer& r : recons) out.layers.push_back(std::move(r));
    Image primalPlusDirect = gptFinal(g.primal, nullptr, &direct);
    out.layers.push_back({"primal", std::move(g.primal)});
    out.layers.push_back({"dx", std::move(g.dx)});
    out.layers.push_back({"dy", std::move(g.dy)});
    out.layers.push_back({"direct", std::move(direct)});
    out.layers.push_back({"primal_plus_direct", std::move(primalPlusDirect)});
    return out;
}

void MltIntegrator::describe(nlohmann::json& j, const RenderStats& s) const {
    const MltStats& m = s.mlt;
    const auto rate = [](std::uint64_t accepted, std::uint64_t proposed) {
        return proposed ? double(accepted) / double(proposed) : 0.0;
    };
    j["mlt"] = {{"chains", m.chains},
                {"mutations", m.mutations},
                {"large_step_probability", options_.largeStep},
                {"target_exponent", options_.targetExponent},
                {"target_block", options_.targetBlock},
                {"acceptance_small", rate(m.acceptedSmall, m.proposedSmall)},
                {"acceptance_large", rate(m.acceptedLarge, m.proposedLarge)},
                {"proposed_small", m.proposedSmall},
                {"proposed_large", m.proposedLarge},
                {"bootstrap_samples", m.bootstrapSamples},
                {"bootstrap_ess", m.bootstrapEss},
                {"normalisation", m.normalisation},
                {"normalisation_stderr", m.normalisationStdErr},
                {"normalisation_samples", m.normalisationSamples},
                {"splat_s", m.splatMs * 1e-3}};
    if (gradients()) {
        j["mlt"]["target_alpha"] = options_.targetAlpha;
        j["mlt"]["split_bounce"] = s.gptSplitBounce;
    }
    j["reconstructions"] = reconstructionsJson(s);
}

std::string MltIntegrator::summary(const RenderStats& s) const {
    const MltStats& m = s.mlt;
    char text[160];
    std::snprintf(text, sizeof text, ", %u chains, acceptance %.0f %% small / %.0f %% large", m.chains,
                  m.proposedSmall ? 100.0 * double(m.acceptedSmall) / double(m.proposedSmall) : 0.0,
                  m.proposedLarge ? 100.0 * double(m.acceptedLarge) / double(m.proposedLarge) : 0.0);
    return text;
}

}  // namespace gdpt
