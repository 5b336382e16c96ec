// integrator.h — one interface for every rendering method. A method is an object made by
// name (makeIntegrator); the commands (render, converge, bench-features) parse options and
// call it, and never assemble a method themselves. Its render() reads as the method's
// stages: for PT "sample"; for G-PT "sample base and offset paths, reconstruct, compose".
// docs/integrators.md says how the coming methods (temporal G-PT, gradient-domain MLT,
// distributed rendering) plug in.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <vector>

#include "image/exr_io.h"
#include "integrator/gpt_sampler.h"
#include "integrator/render_options.h"
#include "poisson/debias.h"
#include "poisson/poisson_gpu.h"
#include "scene/scene.h"
#include "util/error.h"

namespace gdpt {

namespace vk {
class Context;
}
class ReconTimeCache;

// What a render produces: named layers, the first being the final image (an EXR's default
// channels, the PNG preview), then the method's own (e.g. G-PT's primal, dx, dy); and the
// statistics of its sampling.
struct RenderOutput {
    std::vector<NamedLayer> layers;
    RenderStats stats;
    [[nodiscard]] const Image& image() const { return layers.front().image; }
    // The layer called `name` ("" = the final image); throws gdpt::Error if there is none.
    [[nodiscard]] const Image& layer(const std::string& name) const {
        for (const NamedLayer& l : layers)
            if (l.name == name) return l.image;
        throw Error("the render has no layer '" + name + "'");
    }
};

// Consecutive frames of an animation, as a temporal method renders them at once
// (Integrator::renderWindow).
struct FrameWindow {
    int first = 0;  // frames first .. first + count - 1
    int count = 0;
    std::function<Scene(int frame)> scene;         // the scene at a frame's time
    std::function<std::uint32_t(int frame)> seed;  // a frame's seed (frame_pattern.h sequenceFrameSeed)
    bool startsSequence = true;                    // no frame before it (else the method's last window)
};

class Integrator {
public:
    virtual ~Integrator() = default;

    // The method's name as the command line spells it ("pt", "gpt").
    [[nodiscard]] virtual std::string name() const = 0;
    // Largest batch of the sampling schedule for this image size (fixes the merge order of
    // the per-pixel statistics, hence the bits of the result).
    [[nodiscard]] virtual std::uint32_t maxBatchSpp(int width, int height) const = 0;
    // The checkpoint identity entries of the method's own settings (the common ones, scene,
    // size, seed, ..., are added by renderIdentity).
    [[nodiscard]] virtual ExrAttributes identity(const Scene& scene, const RenderOptions& options) const = 0;
    // The time a timed render of this size must leave after sampling for the method's own
    // later stages (G-PT: the reconstructions); measured or remembered, see the method.
    virtual ReservedTime reserveAfterSampling(const vk::Context& ctx, int width, int height) {
        (void)ctx, (void)width, (void)height;
        return {};
    }
    // Renders: samples with `options` (spp or time budget, checkpoints, cancellation), then
    // runs the method's later stages, unless sampling was cancelled (stats.cancelled; then
    // the layers are empty).
    virtual RenderOutput render(const vk::Context& ctx, const Scene& scene, const RenderOptions& options) = 0;
    // Adds the method's own keys to a render's JSON summary.
    virtual void describe(nlohmann::json& summary, const RenderStats& stats) const {
        (void)summary, (void)stats;
    }
    // Temporal methods: frames per window (renderWindow renders them at once); 0 for the
    // methods that render one image at a time (render), which a sequence calls per frame.
    [[nodiscard]] virtual int windowFrames() const { return 0; }
    // Renders the frames of `window` (windowFrames() > 0 only): one output per frame in order,
    // or, if sampling was cancelled, what was rendered before (the last stats.cancelled, no
    // layers). `options` is for the whole window (its time budget included). Windows of one
    // sequence come in order: a method may carry state from one to the next.
    virtual std::vector<RenderOutput> renderWindow(const vk::Context& ctx, const FrameWindow& window,
                                                   const RenderOptions& options);
    // A phrase for the render's one-line summary ("" if none): what the method adapted.
    [[nodiscard]] virtual std::string summary(const RenderStats& stats) const {
        (void)stats;
        return "";
    }
};

// The settings of G-PT beyond sampling.
struct GptOptions {
    GptSamplingOptions sampling;
    // Screened Poisson reconstructions (Kettunen et al. 2015, §4): the first gives the final
    // image; each is written as layer recon_<name>. Empty: none; the final image is then the
    // primal (× modulation) + direct, the estimate before reconstruction. The default, WL1
    // (L1 whose rows are weighted by their box-filtered inverse variances, bounded to 4x of the
    // median's), had 4-14 % lower relMSE than L1 on every scene of the set at equal samples and
    // lower at equal time (bench/RESULTS.md, "Weighted L1 with bounded weights").
    std::vector<Reconstruction> reconstructions = {Reconstruction::WeightedL1};
    // Whether the final reconstruction is the scene's choice (gpt_reconstruction.h: WL1, or WL2
    // where some vertex is glossy), made at render time: it takes the first place of
    // `reconstructions`. False: `reconstructions` as given (`--recon`, `gpt-<name>`).
    bool reconstructionByScene = true;
    // Weight of the primal term; nullopt: by the scene's light (gpt_alpha.h), 0.2 without an
    // environment.
    std::optional<double> alpha;
    double tolerance = 1e-4;  // relative residual at which each solve stops
    // Cells across the image's shorter side of the coarse grid whose scales the biased
    // reconstructions take from the primal (poisson/debias.h); 0 = the published reconstruction.
    int debiasCells = kDefaultDebiasCells;
    // The linear solver of the reconstructions; nullopt: the device's default (host-pcg on a CPU
    // device, mg-pcg on a GPU; poisson_gpu.h resolveSolver).
    std::optional<GpuSolver> solver;
    // Timed renders: the reconstruction time remembered per configuration (recon_reserve.h);
    // null: measured once per integrator and raised to its longest real reconstruction.
    const ReconTimeCache* reconCache = nullptr;
};

// The settings of Metropolis light transport (pssmlt, gmlt; mlt_integrator.h).
// The methods' large-step probabilities (MltOptions::largeStep). gmlt's is higher: with the
// large steps' MIS its chains gained from more fresh samples on the door scene and the Cornell
// box (bench/RESULTS.md, "G-MLT's large-step probability").
inline constexpr float kPssmltLargeStep = 0.5f;
inline constexpr float kGmltLargeStep = 0.7f;
// gmlt's chains walk its gradient target to this power (mlt.glsl mltTemperedTarget); pssmlt
// keeps Kelemen's target (1). On the door scene at 256² and 16 s the tempered target's chains
// splat fewer blotches (bench/RESULTS.md, "A tempered target for G-MLT's chains").
inline constexpr float kGmltTargetExponent = 0.25f;
// gmlt's chains walk its target divided by its image block's mean, blocks of this many pixels
// square (mlt_estimate.h MltBlockNormaliser); pssmlt walks Kelemen's target undivided (0).
// On the door scene at 256² the chains' samples then go where the relative error is
// (bench/RESULTS.md, "G-MLT's target per image block").
inline constexpr int kGmltTargetBlock = 16;

struct MltOptions {
    std::uint32_t chains = 0;  // Markov chains at once; 0 = per image size (defaultMltChains)
    // Probability of a large step (a fresh state) per mutation; < 0: the method's own
    // (kPssmltLargeStep, kGmltLargeStep).
    float largeStep = -1.0f;
    float targetAlpha = 0.25f;  // gmlt: weight of the radiance in the target (mlt.glsl gmltTarget)
    // The chains walk the method's target to this power (mlt.glsl mltTemperedTarget); < 0: the
    // method's own (pssmlt 1, gmlt kGmltTargetExponent).
    float targetExponent = -1.0f;
    // The chains' target is divided by its image block's mean target, blocks of this many pixels
    // square (mlt_estimate.h MltBlockNormaliser); 0: not; < 0: the method's own (pssmlt 0,
    // gmlt kGmltTargetBlock).
    int targetBlock = -1;
    std::uint32_t bootstrapPerPixel = 1;  // bootstrap samples per pixel (at least 16 per chain)
    std::uint32_t directSamples = 16;     // camera samples per pixel of the very-direct image
    // gmlt: the split bounce loop of G-PT's sample (the same values; MltPassOptions::splitBounce).
    GptPassOptions::SplitBounce splitBounce = GptPassOptions::SplitBounce::Auto;
    // gmlt: the reconstructions (L1, L2; the variance-weighted ones need per-pixel variances,
    // which a chain's correlated samples do not give), the first gives the final image.
    std::vector<Reconstruction> reconstructions = {Reconstruction::L1};
    // Weight of the primal term of the screened Poisson energy. Lower than G-PT's 0.2: the chains'
    // splatted primal is blotchy where its gradients are not; on the door scene at 256² 0.05
    // gave 10-24 % lower relMSE at 16 s and 7-9 % at 64 s than 0.2, on the Cornell box 1-5 %
    // higher at 16 s (bench/RESULTS.md, "G-MLT's primal weight").
    double alpha = 0.05;
    double tolerance = 1e-4;          // relative residual at which each solve stops
    std::optional<GpuSolver> solver;  // as GptOptions::solver
};

// How temporal G-PT pairs a frame's paths with the next frame's (tgpt_integrator.h): Motion
// replays each path in the pixel the scene's motion carries its primary hit to (motion_map.h),
// Replay in the same pixel.
enum class TemporalShift { Motion, Replay, Reconnect };

// "motion" | "replay" | "reconnect"; throws gdpt::UsageError otherwise.
TemporalShift parseTemporalShift(const std::string& text);
const char* temporalShiftName(TemporalShift shift);

// The settings of temporal G-PT (tgpt; tgpt_integrator.h).
struct TgptOptions {
    GptSamplingOptions sampling;  // of each frame's two half renders (demodulation off)
    TemporalShift shift = TemporalShift::Motion;
    int window = 10;          // frames reconstructed at once (Manzi et al. 2016 use about 10)
    bool l1 = true;           // the space-time reconstruction: L1 (IRLS) or L2
    bool weighted = false;    // rows weighted by their inverse variances (wl1, wl2; spacetime_weights.h)
    double alpha = 0.2;       // weight of the primal rows
    double beta = 1.0;        // weight of the temporal rows
    double gamma = 1.0;       // weight of the mixed rows (∂x∂t, ∂y∂t); 0: none (Reconnect: always)
    double tolerance = 1e-4;  // relative residual of the last solve
};

// Every method's own settings; each integrator reads its part.
struct MethodOptions {
    GptOptions gpt;
    MltOptions mlt;
    TgptOptions tgpt;
};

// Makes the integrator of `name`: a method name ("pt", "gpt", "pssmlt", "gmlt", "tgpt"), or
// "gpt-<reconstruction>" (gpt-l1, gpt-l2, gpt-wl1, gpt-wl2: G-PT with that reconstruction alone, as
// `converge` names its methods). Throws gdpt::UsageError naming the known methods otherwise.
std::unique_ptr<Integrator> makeIntegrator(const std::string& name, const MethodOptions& options = {});

// The method names makeIntegrator knows, and with the gpt-<reconstruction> forms.
const std::vector<std::string>& methodNames();
const std::vector<std::string>& methodVariantNames();

}  // namespace gdpt
