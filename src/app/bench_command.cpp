// bench_command.cpp — `gdpt bench`: prints machine-readable throughput figures (JSON): BVH
// build ms, primary and incoherent (4-segment diffuse) rays/s, path-tracing samples/s and
// rays/s, and per-kernel GPU ms, on the Cornell box and procedural scenes of ~10k, 100k and
// 1M triangles (same camera). Every figure is the median over --repeats runs; compare
// figures as ratios within one run (the machines are shared and noisy).
#include <algorithm>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/bench_util.h"
#include "app/cli.h"
#include "app/subcommand.h"
#include "bvh/builder.h"
#include "integrator/pt_sampler.h"
#include "render/passes/bench_pass.h"
#include "scene/procedural.h"
#include "util/error.h"
#include "util/timer.h"
#include "vk/context.h"

namespace gdpt {
namespace {

struct BenchArgs {
    std::string scenes = "cbox,10k,100k,1m";
    int width = 256;
    int height = 256;
    std::uint32_t spp = 4;
    int repeats = 3;
    std::string workgroup = "8x8";
    std::string device;
    std::string output = "-";
};

Scene benchScene(const std::string& name) {
    if (name == "cbox") return makeCornellBox();
    if (name == "10k") return makeTriangleScene(10'000, 1);
    if (name == "100k") return makeTriangleScene(100'000, 1);
    if (name == "1m") return makeTriangleScene(1'000'000, 1);
    throw UsageError("--scenes: unknown scene '" + name + "' (cbox, 10k, 100k, 1m)");
}

int runBench(const BenchArgs& a) {
    using nlohmann::json;
    OutputSet outputs;
    const TextOutput output(outputs, a.output, "-o");
    vk::ContextOptions co;
    co.device = a.device;
    vk::Context ctx(co);
    const WorkgroupSize wg = parseWorkgroup(a.workgroup);
    json out = {{"device", ctx.info().name},
                {"driver", ctx.info().driverInfo},
                {"width", a.width},
                {"height", a.height},
                {"spp", a.spp},
                {"repeats", a.repeats},
                {"workgroup", a.workgroup},
                {"scenes", json::array()}};
    std::stringstream list(a.scenes);
    std::string name;
    while (std::getline(list, name, ',')) {
        std::fprintf(stderr, "gdpt bench: %s\n", name.c_str());
        const Scene scene = benchScene(name);
        std::vector<double> buildMs;
        for (int r = 0; r < a.repeats; ++r)
            buildMs.push_back(buildBvh(scene.positions, scene.triangles).stats.buildMs);

        SceneGpuOptions so;
        so.width = a.width;
        so.height = a.height;
        std::vector<double> primary, incoherent, primaryCpu, incoherentCpu;
        std::uint32_t registerStack = 0;
        {
            SceneGpu sceneGpu(ctx, scene, so);
            registerStack = sceneGpu.spec().bvhRegisterStack();
            BenchRaysPass pass(ctx, sceneGpu, wg);
            pass.run(1, false, 99);  // warm-up: pipeline compilation happens lazily on some drivers
            for (int r = 0; r < a.repeats; ++r) {
                const auto p = pass.run(a.spp, false, static_cast<std::uint32_t>(r));
                primary.push_back(static_cast<double>(p.rays) / p.seconds);
                primaryCpu.push_back(static_cast<double>(p.rays) / p.cpuSeconds);
                const auto i = pass.run(a.spp, true, static_cast<std::uint32_t>(r));
                incoherent.push_back(static_cast<double>(i.rays) / i.seconds);
                incoherentCpu.push_back(static_cast<double>(i.rays) / i.cpuSeconds);
            }
        }
        std::vector<double> ptSamples, ptRays, ptMs, ptRaysCpu;
        json kernels = json::object();
        for (int r = 0; r < a.repeats; ++r) {
            RenderOptions ro;
            ro.scene = so;
            ro.spp = a.spp;
            ro.seed = static_cast<std::uint32_t>(r);
            ro.quiet = true;
            ro.profile = true;
            ro.workgroup = wg;
            const double cpu0 = processCpuSeconds();
            const RenderResult res = renderPt(ctx, scene, ro);
            const double cpu = processCpuSeconds() - cpu0;
            const double s = res.stats.samplingMs * 1e-3;
            ptSamples.push_back(static_cast<double>(res.stats.pathsCompleted) / s);
            ptRays.push_back(static_cast<double>(res.stats.raysTraced) / s);
            ptMs.push_back(res.stats.samplingMs);
            ptRaysCpu.push_back(static_cast<double>(res.stats.raysTraced) / cpu);
            for (const auto& [k, t] : res.stats.kernels)
                kernels[k] = {{"count", t.count},
                              {"total_ms", t.totalMs},
                              {"ms_per_call", t.totalMs / double(t.count)}};
        }
        out["scenes"].push_back({{"scene", name},
                                 {"triangles", scene.triangles.size()},
                                 {"bvh_build_ms", median(buildMs)},
                                 {"bvh_register_stack", registerStack},
                                 {"primary_rays_per_s", median(primary)},
                                 {"incoherent_rays_per_s", median(incoherent)},
                                 {"primary_rays_per_cpu_s", median(primaryCpu)},
                                 {"incoherent_rays_per_cpu_s", median(incoherentCpu)},
                                 {"pt_samples_per_s", median(ptSamples)},
                                 {"pt_rays_per_s", median(ptRays)},
                                 {"pt_rays_per_cpu_s", median(ptRaysCpu)},
                                 {"pt_sampling_ms", median(ptMs)},
                                 {"pt_kernels", kernels}});
    }
    output.write(out.dump(2) + "\n");
    outputs.commit();
    return 0;
}

}  // namespace

Subcommand addBenchCommand(CLI::App& app) {
    auto args = std::make_shared<BenchArgs>();
    CLI::App* b = app.add_subcommand("bench", "Throughput benchmark: BVH build, rays/s, PT samples/s (JSON)");
    b->add_option("--scenes", args->scenes, "Comma-separated scenes: cbox, 10k, 100k, 1m")
        ->capture_default_str();
    b->add_option("--width", args->width, "Image width")->capture_default_str()->check(CLI::Range(1, 8192));
    b->add_option("--height", args->height, "Image height")
        ->capture_default_str()
        ->check(CLI::Range(1, 8192));
    b->add_option("--spp", args->spp, "Samples per pixel per measurement")
        ->capture_default_str()
        ->check(CLI::Range(1u, 4096u));
    b->add_option("--repeats", args->repeats, "Repeats (the median is reported)")
        ->capture_default_str()
        ->check(CLI::Range(1, 100));
    b->add_option("--workgroup", args->workgroup, "Compute workgroup size WxH")->capture_default_str();
    b->add_option("--device", args->device, "Vulkan device index or name substring");
    b->add_option("-o,--output", args->output, "Write the JSON here ('-' = stdout)")->capture_default_str();
    return {b, [args] { return runBench(*args); }};
}

}  // namespace gdpt
