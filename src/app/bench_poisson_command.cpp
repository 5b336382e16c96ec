// bench_poisson_command.cpp — `gdpt bench-poisson`: JSON timings of the GPU Poisson solver
// (not a test). Per size and method (l2-mg-pcg, l2-cg, l2-jacobi, l2-mg, l1): median wall
// ms over --repeats solves (upload to download; pipelines and buffers are created once per
// size, outside the timing), iterations, final relative residual and ms per Mpixel.
// Input: exact forward differences of a procedural image plus its primal with Gaussian noise
// (σ = 0.1, fixed seed), so every method solves the same well-defined problem.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "app/bench_util.h"
#include "app/subcommand.h"
#include "poisson/poisson_gpu.h"
#include "util/error.h"
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
    vk::ContextOptions co;
    co.device = a.device;
    vk::Context ctx(co);
    PoissonKernels kernels(ctx, gx, gy);
    std::unique_ptr<vk::GpuTimer> timer;
    if (a.profile) timer = std::make_unique<vk::GpuTimer>(ctx, 16384);
    json out = {{"device", ctx.info().name},
                {"driver", ctx.info().driverInfo},
                {"repeats", a.repeats},
                {"alpha", a.alpha},
                {"tolerance", a.tolerance},
                {"workgroup", a.workgroup},
                {"pre_smooth", a.preSmooth},
                {"post_smooth", a.postSmooth},
                {"smoother", a.jacobiSmoother ? "jacobi" : "rb-gs"},
                {"addressing", a.addressing},
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
        PoissonSolverGpu solver(ctx, w, h, &kernels, addressing);
        PoissonInput in;
        in.primal = &primal;
        in.dx = &dx;
        in.dy = &dy;
        for (const std::string& method : splitList(a.methods)) {
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
                timer = std::make_unique<vk::GpuTimer>(ctx, 16384);
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
    sub->add_option("--methods", args->methods, "Comma-separated: l2-mg-pcg, l2-cg, l2-jacobi, l2-mg, l1")
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
