// bench_poisson_command.cpp — `gdpt bench-poisson`: JSON timings of the Poisson solvers (not
// a test). Per size and method (l2-mg-pcg, l2-cg, l2-jacobi, l2-mg, l1: the GPU solver;
// st-l2, st-l1: the space-time solver of temporal G-PT over --frames frames of that size):
// median wall ms over --repeats solves (GPU: upload to download; pipelines and buffers are
// created once per size, outside the timing), iterations, final relative residual and ms per
// Mpixel (of the whole window for st-*).
// Input: exact forward differences of a procedural image plus its primal with Gaussian noise
// (σ = 0.1, fixed seed), so every method solves the same well-defined problem; for st-* the
// image moves one pixel to the right per frame, the temporal rows follow that motion (the
// last column has none) and their targets are exact.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "app/bench_util.h"
#include "app/subcommand.h"
#include "poisson/poisson_gpu.h"
#include "poisson/poisson_spacetime.h"
#include "util/error.h"
#include "util/parallel.h"
#include "vk/context.h"

namespace gdpt {
namespace {

struct BenchPoissonArgs {
    std::string sizes = "256,512,1024,2048,1280x720";
    std::string methods = "l2-mg-pcg,l2-cg,l2-jacobi,l2-mg,l1";
    int repeats = 3;
    double alpha = 0.2;
    double tolerance = 1e-4;
    int maxIterations = 5000;
    std::string workgroup = "16x16";
    int preSmooth = 1;
    int postSmooth = 1;
    bool jacobiSmoother = false;
    std::string device;
    bool profile = false;
    std::string addressing = "auto";
    int frames = 10;                             // st-*: frames of the window
    int threads = 0;                             // st-*: solver threads (0 = the machine's cores)
    double gamma = 0.0;                          // st-*: weight of the mixed rows (0: none)
    std::string hostPreconditioner = "coupled";  // st-*: coupled, multigrid or jacobi
};

// Smooth shading, hard-edged discs and fine stripes: content with every frequency.
Image proceduralImage(int w, int h) {
    Image im(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const double u = double(x) / w, v = double(y) / h;
            for (int c = 0; c < 3; ++c) {
                double val = 0.4 + 0.3 * std::sin(6.0 * u + c) * std::cos(4.0 * v);
                const double dxc = u - 0.3 - 0.2 * c, dyc = v - 0.5;
                if (dxc * dxc + dyc * dyc < 0.02) val += 1.5;
                if (y % 16 < 2) val += 0.2;
                im.at(x, y, c) = static_cast<float>(val);
            }
        }
    return im;
}

// st-l2 / st-l1: the space-time solve of --frames frames of w x h, the procedural image
// moving one pixel to the right per frame.
nlohmann::json benchSpaceTime(const BenchPoissonArgs& a, int w, int h, const std::string& sizeText,
                              const std::string& method) {
    if (method != "st-l2" && method != "st-l1")
        throw UsageError("--methods: unknown method '" + method + "'");
    const Image truth = proceduralImage(w + a.frames, h);
    SpaceTimeProblem p;
    p.width = w;
    p.height = h;
    p.frames = a.frames;
    p.alpha = a.alpha;
    const std::size_t np = p.pixels();
    std::mt19937 rng(1234);
    std::normal_distribution<double> noise(0.0, 0.1);
    for (int c = 0; c < 3; ++c) {
        p.primal[c].resize(p.size());
        p.dx[c].assign(p.size(), 0.0);
        p.dy[c].assign(p.size(), 0.0);
        p.dt[c].assign(np * std::size_t(a.frames - 1), 0.0);
        for (int f = 0; f < a.frames; ++f)
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    // Frame f shows the image shifted right by f pixels.
                    const auto value = [&](int px, int py) {
                        return double(truth.at(px - f + a.frames, py, c));
                    };
                    const std::size_t i =
                        std::size_t(f) * np + std::size_t(y) * std::size_t(w) + std::size_t(x);
                    if (x + 1 < w) p.dx[c][i] = value(x + 1, y) - value(x, y);
                    if (y + 1 < h) p.dy[c][i] = value(x, y + 1) - value(x, y);
                    p.primal[c][i] = value(x, y) + noise(rng);
                }
    }
    p.temporalPartner.resize(np * std::size_t(a.frames - 1));
    for (std::size_t i = 0; i < p.temporalPartner.size(); ++i) {
        const std::size_t pixel = i % np;
        p.temporalPartner[i] =
            pixel % std::size_t(w) + 1 < std::size_t(w) ? std::uint32_t(pixel + 1) : kNoTemporalPartner;
    }
    // Mixed rows: the translation keeps every spatial difference along the motion (targets 0).
    p.gamma = a.gamma;
    if (p.gamma > 0.0)
        for (int c = 0; c < 3; ++c) {
            p.dxt[c].assign(p.dt[c].size(), 0.0);
            p.dyt[c].assign(p.dt[c].size(), 0.0);
        }
    SpaceTimeOptions o;
    o.l1 = method == "st-l1";
    o.tolerance = a.tolerance;
    o.maxIterations = a.maxIterations;
    o.threads = a.threads;
    o.multigrid = a.hostPreconditioner != "jacobi";
    o.coupleFrames = a.hostPreconditioner == "coupled";
    std::fprintf(stderr, "gdpt bench-poisson: %d frames of %dx%d %s\n", a.frames, w, h, method.c_str());
    std::vector<double> ms;
    SpaceTimeStats stats;
    for (int r = 0; r < a.repeats; ++r) {
        (void)solveSpaceTime(p, o, &stats);
        ms.push_back(stats.ms);
    }
    const double med = median(ms);
    return {{"size", sizeText},
            {"width", w},
            {"height", h},
            {"frames", a.frames},
            {"gamma", a.gamma},
            {"method", method},
            {"preconditioner", stats.coupledFrames ? "coupled"
                               : stats.multigrid   ? "multigrid"
                                                   : "jacobi"},
            {"median_ms", med},
            {"all_ms", ms},
            {"iterations", stats.iterations},
            {"irls_iterations", stats.irlsIterations},
            {"residual", stats.residual},
            {"converged", stats.converged},
            {"ms_per_mpixel", med / (double(w) * h * a.frames * 1e-6)}};
}

int runBenchPoisson(const BenchPoissonArgs& a) {
    using nlohmann::json;
    unsigned gx = 0, gy = 0;
    char sep = 0;
    std::istringstream wg(a.workgroup);
    if (!(wg >> gx >> sep >> gy) || sep != 'x') throw UsageError("--workgroup must be WxH, e.g. 16x16");
    std::optional<PoissonAddressing> addressing;
    if (a.addressing == "descriptors")
        addressing = PoissonAddressing::Descriptors;
    else if (a.addressing == "device-address")
        addressing = PoissonAddressing::DeviceAddress;
    else if (a.addressing != "auto")
        throw UsageError("--addressing must be auto, descriptors or device-address");
    const std::vector<std::string> methods = splitList(a.methods);
    const bool gpu = std::any_of(methods.begin(), methods.end(),
                                 [](const std::string& m) { return m.rfind("st-", 0) != 0; });
    // The space-time solver runs on the host: no Vulkan device for st-* alone.
    std::unique_ptr<vk::Context> ctxOwned;
    std::unique_ptr<PoissonKernels> kernelsOwned;
    std::unique_ptr<vk::GpuTimer> timer;
    if (gpu) {
        vk::ContextOptions co;
        co.device = a.device;
        ctxOwned = std::make_unique<vk::Context>(co);
        kernelsOwned = std::make_unique<PoissonKernels>(*ctxOwned, gx, gy);
        if (a.profile) timer = std::make_unique<vk::GpuTimer>(*ctxOwned, 16384);
    }
    json out = {{"device", gpu ? ctxOwned->info().name : std::string("host")},
                {"driver", gpu ? ctxOwned->info().driverInfo : std::string()},
                {"repeats", a.repeats},
                {"alpha", a.alpha},
                {"tolerance", a.tolerance},
                {"workgroup", a.workgroup},
                {"pre_smooth", a.preSmooth},
                {"post_smooth", a.postSmooth},
                {"smoother", a.jacobiSmoother ? "jacobi" : "rb-gs"},
                {"addressing", a.addressing},
                {"frames", a.frames},
                {"threads", defaultThreads(static_cast<std::uint32_t>(a.threads))},
                {"results", json::array()}};
    for (const std::string& sizeText : splitList(a.sizes)) {
        const auto [w, h] = parseSize(sizeText);
        const Image truth = proceduralImage(w, h);
        Image dx(w, h), dy(w, h), primal = truth;
        std::mt19937 rng(1234);
        std::normal_distribution<float> noise(0.0f, 0.1f);
        for (int c = 0; c < 3; ++c)
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    if (x + 1 < w) dx.at(x, y, c) = truth.at(x + 1, y, c) - truth.at(x, y, c);
                    if (y + 1 < h) dy.at(x, y, c) = truth.at(x, y + 1, c) - truth.at(x, y, c);
                    primal.at(x, y, c) += noise(rng);
                }
        std::unique_ptr<PoissonSolverGpu> solverOwned;
        if (gpu)
            solverOwned = std::make_unique<PoissonSolverGpu>(*ctxOwned, w, h, kernelsOwned.get(), addressing);
        PoissonInput in;
        in.primal = &primal;
        in.dx = &dx;
        in.dy = &dy;
        for (const std::string& method : methods) {
            if (method.rfind("st-", 0) == 0) {
                out["results"].push_back(benchSpaceTime(a, w, h, sizeText, method));
                continue;
            }
            PoissonSolverGpu& solver = *solverOwned;
            SolveOptions o;
            o.alpha = a.alpha;
            o.tolerance = a.tolerance;
            o.maxIterations = a.maxIterations;
            o.vcycle.preSmooth = a.preSmooth;
            o.vcycle.postSmooth = a.postSmooth;
            o.vcycle.jacobi = a.jacobiSmoother;
            if (method == "l1") {
                o.method = Reconstruction::L1;
            } else if (method.rfind("l2-", 0) == 0) {
                o.solver = parseGpuSolver(method.substr(3));
            } else {
                throw UsageError("--methods: unknown method '" + method + "'");
            }
            std::fprintf(stderr, "gdpt bench-poisson: %dx%d %s\n", w, h, method.c_str());
            std::vector<double> ms;
            SolveReport report;
            Image result;
            for (int r = 0; r < a.repeats; ++r) {
                o.timer = (timer && r + 1 == a.repeats) ? timer.get() : nullptr;
                report = solver.solve(in, o, result);
                ms.push_back(report.ms);
            }
            const double med = median(ms);
            json entry = {{"size", sizeText},
                          {"width", w},
                          {"height", h},
                          {"method", method},
                          {"addressing", solver.engine().addressing() == PoissonAddressing::DeviceAddress
                                             ? "device-address"
                                             : "descriptors"},
                          {"median_ms", med},
                          {"all_ms", ms},
                          {"iterations", report.iterations},
                          {"irls_iterations", report.irlsIterations},
                          {"batches", report.batches},
                          {"residual", report.residual},
                          {"converged", report.converged},
                          {"ms_per_mpixel", med / (double(w) * h * 1e-6)}};
            if (timer) {
                json k = json::object();
                for (const auto& [name, t] : report.kernels)
                    k[name] = {{"count", t.count}, {"total_ms", t.totalMs}};
                entry["kernels"] = k;
                timer = std::make_unique<vk::GpuTimer>(*ctxOwned, 16384);
            }
            out["results"].push_back(entry);
        }
    }
    std::printf("%s\n", out.dump(2).c_str());
    return 0;
}

}  // namespace

Subcommand addBenchPoissonCommand(CLI::App& app) {
    auto args = std::make_shared<BenchPoissonArgs>();
    CLI::App* sub =
        app.add_subcommand("bench-poisson", "Time the GPU Poisson solver on synthetic inputs (JSON)");
    sub->add_option("--sizes", args->sizes, "Comma-separated sizes, N or WxH")->capture_default_str();
    sub->add_option(
           "--methods", args->methods,
           "Comma-separated: l2-mg-pcg, l2-cg, l2-jacobi, l2-mg, l1 (GPU); st-l2, st-l1 (the space-time "
           "solver of temporal G-PT, on the host, over --frames frames of each size)")
        ->capture_default_str();
    sub->add_option("--frames", args->frames, "st-*: frames of the space-time window")
        ->check(CLI::Range(1, 1000))
        ->capture_default_str();
    sub->add_option("--gamma", args->gamma,
                    "st-*: weight of the mixed rows (the change of dx, dy along the motion)")
        ->check(CLI::Range(0.0, 1e3))
        ->capture_default_str();
    sub->add_option("--threads", args->threads, "st-*: host threads of the space-time solver (0 = all cores)")
        ->check(CLI::Range(0, 1024))
        ->capture_default_str();
    sub->add_option("--host-preconditioner", args->hostPreconditioner,
                    "st-*: CG's preconditioner for one frame and for windows with mixed rows (others always "
                    "take jacobi): coupled (a V-cycle per frame in block Gauss-Seidel over the frames), "
                    "multigrid (a V-cycle per frame, block Jacobi) or jacobi (the diagonal)")
        ->check(CLI::IsMember({"coupled", "multigrid", "jacobi"}))
        ->capture_default_str();
    sub->add_option("--repeats", args->repeats, "Solves per size and method (median reported)")
        ->check(CLI::Range(1, 100))
        ->capture_default_str();
    sub->add_option("--alpha", args->alpha, "Primal weight alpha")
        ->check(CLI::Range(0.0, 1e6))
        ->capture_default_str();
    sub->add_option("--tolerance", args->tolerance, "Relative residual tolerance")
        ->check(CLI::Range(1e-12, 0.5))
        ->capture_default_str();
    sub->add_option("--max-iterations", args->maxIterations, "Iteration cap per solve")
        ->check(CLI::Range(1, 1000000))
        ->capture_default_str();
    sub->add_option("--workgroup", args->workgroup, "Workgroup WxH (power-of-two size <= 256)")
        ->capture_default_str();
    sub->add_option("--pre-smooth", args->preSmooth, "V-cycle sweeps before the coarse correction")
        ->check(CLI::Range(0, 8))
        ->capture_default_str();
    sub->add_option("--post-smooth", args->postSmooth, "V-cycle sweeps after it")
        ->check(CLI::Range(1, 8))
        ->capture_default_str();
    sub->add_flag("--jacobi-smoother", args->jacobiSmoother,
                  "Damped Jacobi smoother instead of red-black Gauss-Seidel");
    sub->add_option("--device", args->device, "Vulkan device index or name substring");
    sub->add_flag("--profile", args->profile, "Add per-kernel GPU ms (last repeat) to the JSON");
    sub->add_option("--addressing", args->addressing,
                    "How kernels reach the fields: auto (descriptors unless a field exceeds "
                    "maxStorageBufferRange), descriptors, device-address")
        ->capture_default_str();
    return {sub, [args] { return runBenchPoisson(*args); }};
}

}  // namespace gdpt
