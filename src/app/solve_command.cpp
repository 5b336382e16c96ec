// solve_command.cpp — `gdpt solve`: screened Poisson reconstruction of a gradient-domain
// render, on the device or the host's threads (--solver). Reads the primal/dx/dy (and optional direct, var_*)
// layers of a gdpt EXR, or separate --primal/--dx/--dy EXR files, and writes the final image (reconstruction
// + direct; modulation × reconstruction + direct where the EXR has the `modulation` layer of a
// demodulated render) in the default channels plus a `recon` layer (tmp + rename).
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>

#include "app/subcommand.h"
#include "image/exr_io.h"
#include "image/finite_check.h"
#include "integrator/gpt_sampler.h"
#include "poisson/debias.h"
#include "poisson/poisson_gpu.h"
#include "util/error.h"
#include "util/interrupt.h"
#include "util/output_files.h"
#include "util/progress.h"
#include "util/timer.h"
#include "vk/context.h"

namespace gdpt {
namespace {

struct SolveArgs {
    std::string input;
    std::string output = "solved.exr";
    std::string recon = "l2";
    std::string solver = "auto";
    double alpha = 0.2;
    double tolerance = 1e-4;
    int maxIterations = 2000;
    int irlsIterations = SolveOptions{}.irlsIterations;
    double irlsRegInit = SolveOptions{}.irlsRegInit;
    double irlsRegIter = SolveOptions{}.irlsRegIter;
    double irlsInnerTolerance = 0.0;  // 0: the solver's default
    int debiasCells = kDefaultDebiasCells;
    double weightContrast = kDefaultVarianceWeightContrast;
    std::string primal, dx, dy;
    std::string device;
    bool quiet = false;
};

const Image* findLayer(const std::vector<NamedLayer>& layers, const std::string& name) {
    for (const NamedLayer& l : layers)
        if (l.name == name) return &l.image;
    return nullptr;
}

// Invalid input values, one policy for every layer (what the solver does with them,
// poisson_gpu.h): NaN or infinite values in primal, dx or dy leave their rows out of the
// solve (weight 0); non-finite or negative values in a variance the reconstruction uses
// leave the rows they weight out; non-finite values in direct or modulation count as zero.
// Each is reported with the layer (or file), how many pixels and the first of them. A layer
// with no usable pixel at all is refused: the solve would silently return something else
// (the primal, or an image without its primal).
class InputCheck {
public:
    explicit InputCheck(bool quiet) : quiet_(quiet) {}

    // A layer whose non-finite values leave its rows out of the solve.
    void rows(const std::string& what, const Image& im) {
        const PixelScan bad = scanNonFinite(im);
        if (bad.all())
            throw Error(what + " has no finite pixel (NaN or infinite everywhere); nothing to solve");
        warn(what, "NaN or infinite values", bad, "their rows are left out of the solve (weight 0)");
    }
    // A variance layer that weights rows: non-finite and negative values leave them out.
    void variance(const std::string& what, const Image& im, const char* recon) {
        const PixelScan bad = scanNonFinite(im), negative = scanNegative(im);
        if (bad.pixels + negative.pixels >= im.pixelCount())
            throw Error(what + " has no valid variance (finite and >= 0; " + std::to_string(bad.pixels) +
                        " pixels NaN or infinite, " + std::to_string(negative.pixels) +
                        " negative): --recon " + recon +
                        " cannot weight its rows (--recon l2 does not use it)");
        warn(what, "NaN or infinite values", bad,
             "the rows they weight are left out of the solve (weight 0)");
        warn(what, "negative values (not a variance)", negative,
             "the rows they weight are left out of the solve (weight 0)");
    }
    // A layer applied after the solve (direct, modulation): non-finite values become 0.
    Image zeroed(const std::string& what, const Image& im) {
        const PixelScan bad = scanNonFinite(im);
        warn(what, "NaN or infinite values", bad, "they are counted as zero");
        Image out = im;
        if (bad.any())
            for (int c = 0; c < 3; ++c)
                for (float& v : out.plane(c))
                    if (!std::isfinite(v)) v = 0.0f;
        return out;
    }

private:
    void warn(const std::string& what, const char* found, const PixelScan& s, const char* done) const {
        if (s.any() && !quiet_)
            std::fprintf(stderr, "gdpt: warning: %s: %s in %s; %s\n", what.c_str(), found,
                         s.describe().c_str(), done);
    }
    bool quiet_;
};

int runSolve(const SolveArgs& a) {
    const bool separate = !a.primal.empty() || !a.dx.empty() || !a.dy.empty();
    if (separate && !a.input.empty())
        throw UsageError("give either INPUT.exr or --primal/--dx/--dy, not both");
    if (separate && (a.primal.empty() || a.dx.empty() || a.dy.empty()))
        throw UsageError("--primal, --dx and --dy must be given together");
    if (!separate && a.input.empty()) throw UsageError("missing INPUT.exr (or --primal/--dx/--dy)");
    installInterruptHandlers();
    OutputSet outputs(
        {{"input", a.input}, {"--primal input", a.primal}, {"--dx input", a.dx}, {"--dy input", a.dy}});
    const StagedFile& outFile = outputs.add(a.output, "-o");
    SolveOptions o;
    o.method = parseReconstruction(a.recon);
    const std::optional<GpuSolver> solverChoice = parseSolverChoice(a.solver);
    o.alpha = a.alpha;
    o.tolerance = a.tolerance;
    o.maxIterations = a.maxIterations;
    o.irlsIterations = a.irlsIterations;
    o.irlsRegInit = a.irlsRegInit;
    o.irlsRegIter = a.irlsRegIter;
    o.varianceWeightContrast = a.weightContrast;
    if (a.irlsInnerTolerance > 0.0) o.irlsInnerTolerance = a.irlsInnerTolerance;

    std::vector<NamedLayer> layers;
    Image primal, dx, dy;
    const Image *direct = nullptr, *modulation = nullptr, *varP = nullptr, *varX = nullptr, *varY = nullptr;
    if (separate) {
        primal = readExrLayer(a.primal);
        dx = readExrLayer(a.dx);
        dy = readExrLayer(a.dy);
        if (!primal.sameSize(dx) || !primal.sameSize(dy))
            throw Error(a.primal + ", " + a.dx + ", " + a.dy + ": images differ in size");
    } else {
        layers = readExr(a.input);
        auto need = [&](const char* name) -> const Image& {
            const Image* im = findLayer(layers, name);
            if (!im)
                throw Error(a.input + ": no layer '" + name +
                            "' (a gdpt gradient-domain EXR has primal, dx, dy)");
            return *im;
        };
        primal = need("primal");
        dx = need("dx");
        dy = need("dy");
        direct = findLayer(layers, "direct");
        modulation = findLayer(layers, "modulation");
        varP = findLayer(layers, "var_primal");
        varX = findLayer(layers, "var_dx");
        varY = findLayer(layers, "var_dy");
        for (const Image* im : {direct, modulation, varP, varX, varY})
            if (im && !im->sameSize(primal)) throw Error(a.input + ": layers differ in size");
    }
    if (needsVariance(o.method) && !(varP && varX && varY))
        throw Error((separate ? a.primal : a.input) + ": --recon " + toString(o.method) +
                    " needs the layers var_primal, var_dx and var_dy");
    // What each input is called in messages: its file, or the layer of INPUT.exr.
    const auto named = [&](const std::string& layer, const std::string& file) {
        return separate ? file : a.input + ": layer '" + layer + "'";
    };
    InputCheck check(a.quiet);
    check.rows(named("primal", a.primal), primal);
    check.rows(named("dx", a.dx), dx);
    check.rows(named("dy", a.dy), dy);
    if (needsVariance(o.method)) {
        check.variance(named("var_primal", ""), *varP, toString(o.method));
        check.variance(named("var_dx", ""), *varX, toString(o.method));
        check.variance(named("var_dy", ""), *varY, toString(o.method));
    }
    Image directValid, modulationValid;
    if (direct) {
        directValid = check.zeroed(named("direct", ""), *direct);
        direct = &directValid;
    }
    if (modulation) {
        modulationValid = check.zeroed(named("modulation", ""), *modulation);
        modulation = &modulationValid;
    }

    vk::ContextOptions co;
    co.device = a.device;
    vk::Context ctx(co);
    o.solver = resolveSolver(solverChoice, ctx);
    SolveReport report;
    // Progress once a solve has run for 2 s (a 4096x4096 L1 solve takes about a minute).
    Progress progress("gdpt: solve", 1.0, a.quiet);
    Timer started;
    bool shown = false;
    o.progress = [&](int roundsDone, int rounds, int iterations) {
        throwIfInterrupted("solving");
        if (started.seconds() < 2.0) return;
        shown = true;
        progress.update(double(roundsDone) / rounds,
                        (isIrls(o.method) ? "IRLS round " + std::to_string(roundsDone) + "/" +
                                                std::to_string(rounds) + ", "
                                          : std::string()) +
                            std::to_string(iterations) + " iterations");
    };
    Image recon = reconstruct(ctx, primal, dx, dy, varP, varX, varY, o, &report);
    std::optional<DebiasReport> debiased;
    if (debiases(o.method, a.debiasCells)) debiased = debiasImage(recon, primal, a.debiasCells);
    if (shown) {
        progress.update(1.0);
        progress.finish(std::to_string(report.iterations) + " iterations");
    }
    // The last guard: nothing non-finite is written (e.g. a final image that overflows).
    const std::vector<NamedLayer> result = {{"", gptFinal(recon, modulation, direct)}, {"recon", recon}};
    checkFinite(result, a.output);
    writeExr(outFile, result);
    throwIfInterrupted("writing");
    outputs.commit();
    if (!a.quiet) {
        std::fprintf(
            stderr,
            "gdpt: wrote %s (%dx%d, %s/%s, alpha %g: %d iterations, %d IRLS, residual %.3g%s, %.1f ms)\n",
            a.output.c_str(), primal.width(), primal.height(), toString(o.method), toString(o.solver),
            o.alpha, report.iterations, report.irlsIterations, report.residual,
            report.converged ? "" : " NOT converged", report.ms);
        if (report.scaleExponent > 0)
            std::fprintf(
                stderr,
                "gdpt: note: inputs above %g were scaled by 2^-%d for the solve (its float32 sums of "
                "squares would overflow) and the result by 2^%d\n",
                kSolveMaxMagnitude, report.scaleExponent, report.scaleExponent);
        if (debiased) std::fprintf(stderr, "gdpt: %s\n", describeDebias(*debiased).c_str());
    }
    return 0;
}

}  // namespace

Subcommand addSolveCommand(CLI::App& app) {
    auto a = std::make_shared<SolveArgs>();
    CLI::App* sub = app.add_subcommand(
        "solve", "Screened Poisson reconstruction of a gradient-domain EXR (device or host: --solver)");
    sub->add_option("input", a->input,
                    "gdpt EXR with layers primal, dx, dy [, direct, var_primal, var_dx, var_dy]")
        ->check(InputFile);
    sub->add_option("-o,--output", a->output, "Output EXR (final image + 'recon' layer)")
        ->capture_default_str();
    sub->add_option(
           "--recon", a->recon,
           "Reconstruction: l1, l2, wl2 (inverse-variance weighted L2) or wl1 (L1 with inverse-variance "
           "weights from a 7x7 box of the variance)")
        ->check(CLI::IsMember({"l1", "l2", "wl2", "wl1"}))
        ->capture_default_str();
    sub->add_option("--debias-cells", a->debiasCells, kDebiasCellsHelp)
        ->check(CLI::Range(0, kMaxDebiasCells))
        ->capture_default_str();
    sub->add_option("--weight-contrast", a->weightContrast, kVarianceWeightContrastHelp)
        ->check(CLI::Range(1.0, 1e12) | CLI::IsMember({0.0}))
        ->capture_default_str();
    sub->add_option("--solver", a->solver, kSolverHelp)
        ->check(CLI::IsMember(std::vector<std::string>(std::begin(kSolverChoices), std::end(kSolverChoices))))
        ->capture_default_str();
    sub->add_option("--alpha", a->alpha, "Weight of the primal rows (energy weight alpha^2)")
        ->check(CLI::Range(0.0, 1e6))
        ->capture_default_str();
    sub->add_option("--tolerance", a->tolerance, "Relative residual tolerance")
        ->check(CLI::Range(1e-12, 0.5))
        ->capture_default_str();
    sub->add_option("--max-iterations", a->maxIterations, "Iteration cap per linear solve")
        ->check(CLI::Range(1, 10000000))
        ->capture_default_str();
    sub->add_option("--irls-iterations", a->irlsIterations, "IRLS rounds for --recon l1 and wl1")
        ->check(CLI::Range(1, 1000))
        ->capture_default_str();
    sub->add_option("--irls-reg-init", a->irlsRegInit,
                    "IRLS: regulariser of the second round's weights 1/(|e| + reg), in radiance units")
        ->check(CLI::Range(1e-12, 1e6))
        ->capture_default_str();
    sub->add_option("--irls-reg-iter", a->irlsRegIter,
                    "IRLS: factor applied to the regulariser every later round")
        ->check(CLI::Range(1e-6, 1.0))
        ->capture_default_str();
    sub->add_option(
           "--irls-inner-tolerance", a->irlsInnerTolerance,
           "IRLS: relative residual of the inner solves before the last round (the last uses --tolerance); "
           "0 = the solver's default (0.02 on the device, 0.005 for host-pcg)")
        ->check(CLI::Range(0.0, 0.5))
        ->capture_default_str();
    sub->add_option("--primal", a->primal, "Primal EXR (instead of INPUT)")->check(InputFile);
    sub->add_option("--dx", a->dx, "Horizontal-gradient EXR (instead of INPUT)")->check(InputFile);
    sub->add_option("--dy", a->dy, "Vertical-gradient EXR (instead of INPUT)")->check(InputFile);
    sub->add_option("--device", a->device, "Vulkan device index or name substring");
    sub->add_flag("--quiet", a->quiet, "No summary on stderr");
    return {sub, [a] { return runSolve(*a); }};
}

}  // namespace gdpt
