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

namespace {

// One render's device work and its stages (Kelemen et al. 2002): the bootstrap, the chains and
// the estimate. Each submission waits for the device and adds the pass's counters to the stats.
class MltRun {
public:
    MltRun(const vk::Context& ctx, const std::string& name, MltPass& pass, const MltPassOptions& po,
           const RenderOptions& options, RenderStats& stats, vk::GpuTimer* timer)
        : name_(name),
          pass_(pass),
          po_(po),
          options_(options),
          stats_(stats),
          timer_(timer),
          stream_(ctx, name),
          pixels_(std::uint64_t(options.scene.width) * std::uint64_t(options.scene.height)) {}

    [[nodiscard]] bool cancelled() const { return options_.cancel && options_.cancel->load(); }

    void submit(const std::string& what, const std::function<void(VkCommandBuffer)>& work) {
        VkCommandBuffer cmd = stream_.begin();
        if (timer_) timer_->reset(cmd);
        work(cmd);
        stream_.setWhat(what);
        stream_.submit();
        stream_.waitAll();
        if (timer_) timer_->collect();
        const gpu::Counters c = pass_.takeCounters();
        stats_.raysTraced += c.raysTraced;
        stats_.pathsCompleted += c.pathsCompleted;
        stats_.nanSamples += c.nanSamples;
    }

    // What the bootstrap leaves the chains.
    struct Starts {
        std::vector<std::uint32_t> chains;  // the bootstrap sample each chain starts from
        float misNormalisation = 0.0f;      // b' of the splat weights (mlt.glsl): the bootstrap's b̂
        TargetSums fresh;                   // the fresh states b̂ pools: the bootstrap's so far
    };

    // The bootstrap: max(W·H · per pixel, 16 · chains) fresh states, the target's divisors per
    // image block (mlt_estimate.h) from the even ones, b̂ from the others, and the chains'
    // starts drawn in proportion to the divided target (mltChainStarts).
    Starts bootstrap(const MltOptions& o) {
        const int width = options_.scene.width, height = options_.scene.height;
        const std::uint64_t count = std::max<std::uint64_t>(pixels_ * o.bootstrapPerPixel,
                                                            std::uint64_t{po_.chains} * kBootstrapPerChain);
        if (count > std::uint64_t{1} << 31)
            throw UsageError("--method " + name_ + ": " + std::to_string(count) +
                             " bootstrap samples are more than this renderer counts; use a smaller image");
        std::vector<gpu::MltBootstrapSample> samples;
        samples.reserve(count);
        for (std::uint64_t first = 0; first < count && !cancelled(); first += kBootstrapPerDispatch) {
            const auto n =
                static_cast<std::uint32_t>(std::min<std::uint64_t>(kBootstrapPerDispatch, count - first));
            submit(name_ + " bootstrap from sample " + std::to_string(first), [&](VkCommandBuffer cmd) {
                pass_.recordBootstrap(cmd, static_cast<std::uint32_t>(first), n, options_.seed, timer_);
            });
            const std::vector<gpu::MltBootstrapSample> part = pass_.bootstrapSamples(n);
            samples.insert(samples.end(), part.begin(), part.end());
        }
        // The chains walk the divided target, which the bootstrap's targets are then divided by too.
        const MltBlockNormaliser normaliser =
            mltBlockNormaliser(samples, std::uint32_t(width), std::uint32_t(height),
                               static_cast<std::uint32_t>(o.targetBlock), o.targetExponent);
        pass_.setNormaliser(normaliser.block, normaliser.divisors);
        Starts out;
        std::vector<float> targets(samples.size());
        TargetSums all;  // every bootstrap sample's target: b' and the starts' ESS
        for (std::size_t i = 0; i < samples.size(); ++i) {
            targets[i] = samples[i].target / normaliser.divisor(samples[i].pixel, std::uint32_t(width));
            all.add(targets[i]);
            // With blocks, the samples the divisors were built from are left out of b̂.
            if (normaliser.block == 0 || i % 2 == 1) out.fresh.add(targets[i]);
        }
        samples = {};
        stats_.mlt.bootstrapEss = all.effectiveSampleSize();
        out.misNormalisation = static_cast<float>(all.normalisation().b);
        pass_.setMisNormalisation(out.misNormalisation);
        stats_.mlt.chains = po_.chains;
        stats_.mlt.bootstrapSamples = targets.size();
        out.chains = mltChainStarts(targets, po_.chains, options_.seed);
        return out;
    }

    // The chains from `starts`: mutation steps in batches, each batch's records splatted into
    // `acc` by the host in record order while nothing else runs (the same order on every run),
    // until --spp mutations per pixel or the budget (`total`: the render's clock). Returns the
    // steps taken.
    std::uint64_t chains(const std::vector<std::uint32_t>& starts, MltAccumulator& acc, const Timer& total) {
        const bool timed = options_.timeBudget > 0.0;
        const double budget = options_.timeBudget - options_.elapsedBefore;
        const std::uint64_t wantedMutations = std::uint64_t{options_.spp} * pixels_;
        const std::uint64_t wantedSteps = (wantedMutations + po_.chains - 1) / po_.chains;
        std::uint64_t steps = 0;
        if (starts.empty() || cancelled()) return steps;
        submit(name_ + " chain start",
               [&](VkCommandBuffer cmd) { pass_.recordStart(cmd, starts, options_.seed, timer_); });
        Progress progress("render " + name_, timed ? budget : double(wantedSteps), options_.quiet);
        double secondsPerStep = 0.0;
        stats_.setupSeconds = options_.elapsedBefore + total.seconds();  // the bootstrap included
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
                       " (seed " + std::to_string(options_.seed) + ")",
                   [&](VkCommandBuffer cmd) {
                       pass_.recordMutations(cmd, static_cast<std::uint32_t>(steps), n, options_.seed,
                                             timer_);
                   });
            Timer splat;
            acc.add(pass_.records(n), std::size_t{2} * po_.chains * n);
            stats_.mlt.splatMs += splat.ms();
            steps += n;
            ++stats_.batches;
            secondsPerStep = batch.seconds() / n;
            if (stats_.firstBatchSeconds == 0.0) stats_.firstBatchSeconds = batch.seconds();
            char rate[64];
            std::snprintf(rate, sizeof rate, "%.1f mutations/pixel",
                          double(steps) * double(po_.chains) / double(pixels_));
            progress.update(timed ? total.seconds() : double(steps), rate);
        }
        progress.finish();
        const MltAcceptance a = pass_.acceptance();
        stats_.mlt.proposedSmall = a.proposedSmall;
        stats_.mlt.acceptedSmall = a.acceptedSmall;
        stats_.mlt.proposedLarge = a.proposedLarge;
        stats_.mlt.acceptedLarge = a.acceptedLarge;
        return steps;
    }

    // The scales of the estimate X(p) = W·H/N Σ (b̂·weight + largeWeight)·X (mlt_estimate.h),
    // with b̂ from every fresh state (Kelemen et al. 2002, §4): the bootstrap's and the large
    // steps'.
    MltScale scale(TargetSums fresh, const MltAccumulator& acc) {
        fresh.add(acc.largeSteps());
        const MltNormalisation norm = fresh.normalisation();
        stats_.mlt.normalisation = norm.b;
        stats_.mlt.normalisationStdErr = norm.standardError;
        stats_.mlt.normalisationSamples = norm.samples;
        MltScale scale;
        if (stats_.mlt.mutations) {
            scale.large = double(pixels_) / double(stats_.mlt.mutations);
            scale.metropolis = scale.large * norm.b;
        }
        return scale;
    }

private:
    const std::string& name_;
    MltPass& pass_;
    const MltPassOptions& po_;
    const RenderOptions& options_;
    RenderStats& stats_;
    vk::GpuTimer* timer_;
    vk::CommandStream stream_;
    std::uint64_t pixels_;
};

}  // namespace

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
    MltRun run(ctx, name_, pass, po, options, stats, timer);
    // The kernel's compile at its first dispatch: a fixed cost (time_s.kernel_compile), not
    // the very-direct light's (PixelSampling::run does the same for PT and G-PT).
    Timer compile;
    run.submit(name_ + " kernel's first dispatch", [&](VkCommandBuffer cmd) { pass.recordWarmUp(cmd); });
    stats.compileMs = compile.ms();
    Timer sampling;

    // Stage 1: the very-direct light, and the bootstrap: b and the chains' starts.
    run.submit(name_ + " direct light", [&](VkCommandBuffer cmd) {
        pass.recordDirect(cmd, options_.directSamples, options.seed, timer);
    });
    MltRun::Starts starts = run.bootstrap(options_);

    // Stage 2: the chains.
    MltAccumulator acc(width, height, starts.misNormalisation, po.largeStep);
    const std::uint64_t steps = run.chains(starts.chains, acc, total);
    stats.mlt.mutations = steps * po.chains;
    stats.spp = static_cast<std::uint32_t>(stats.mlt.mutations / pixels);
    stats.samplingMs = sampling.ms();
    stats.kernels = gpuTimer.totals();
    if (run.cancelled()) {
        stats.cancelled = true;
        return out;
    }
    if (stats.nanSamples > 0 && !options.quiet)
        std::fprintf(stderr, "gdpt: warning: %s: %llu samples were NaN/Inf and were counted as zero\n",
                     name_.c_str(), static_cast<unsigned long long>(stats.nanSamples));

    // Stage 3: the estimate; gmlt reconstructs.
    const MltScale scale = run.scale(std::move(starts.fresh), acc);
    Timer readback;
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
