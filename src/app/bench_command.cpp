// bench_command.cpp — `gdpt bench`: prints machine-readable throughput figures (JSON): BVH
// build ms (binary build and four-wide collapse), primary and incoherent (4-segment diffuse)
// rays/s, path-tracing samples/s and rays/s, and per-kernel GPU ms, on the Cornell box,
// procedural scenes of ~10k, 100k and 1M triangles (same camera) and any glTF file. Built with
// -DGDPT_EMBREE=ON it measures Embree 3 on the same triangles and the same rays
// (baseline/embree_scene.h), interleaved with gdpt's figures, and prints the ratios. Every
// figure is the median over --repeats runs; compare figures as ratios within one run (the
// machines are shared and noisy).
#include <algorithm>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "app/bench_util.h"
#include "app/cli.h"
#include "app/subcommand.h"
#include "bvh/builder.h"
#include "bvh/wide_bvh.h"
#include "integrator/pt_sampler.h"
#include "render/passes/bench_pass.h"
#include "scene/gltf_loader.h"
#include "scene/procedural.h"
#include "util/cpu_share.h"
#include "util/error.h"
#include "util/timer.h"
#include "vk/context.h"

#if defined(GDPT_HAVE_EMBREE)
#include "baseline/embree_scene.h"
#endif

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
    bool embree = false;
};

Scene benchScene(const std::string& name) {
    if (name == "cbox") return makeCornellBox();
    if (name == "10k") return makeTriangleScene(10'000, 1);
    if (name == "100k") return makeTriangleScene(100'000, 1);
    if (name == "1m") return makeTriangleScene(1'000'000, 1);
    const auto endsWith = [&](const char* ext) {
        const std::string e(ext);
        return name.size() > e.size() && name.compare(name.size() - e.size(), e.size(), e) == 0;
    };
    if (endsWith(".gltf") || endsWith(".glb")) return loadGltf(name);
    throw UsageError("--scenes: unknown scene '" + name + "' (cbox, 10k, 100k, 1m, or a .gltf/.glb file)");
}

constexpr bool kHaveEmbree =
#if defined(GDPT_HAVE_EMBREE)
    true;
#else
    false;
#endif

double ratio(double a, double b) {
    return b > 0.0 ? a / b : 0.0;
}

int runBench(const BenchArgs& a) {
    using nlohmann::json;
    OutputSet outputs;
    const TextOutput output(outputs, a.output, "-o");
    vk::ContextOptions co;
    co.device = a.device;
    vk::Context ctx(co);
    const WorkgroupSize wg = parseWorkgroup(a.workgroup);
    if (a.embree && !kHaveEmbree)
        throw UsageError(
            "--embree: this gdpt was built without the Embree baseline (configure with "
            "-DGDPT_EMBREE=ON after installing libembree-dev; scripts/bench-embree.sh does both)");
    // Embree builds and traces on as many threads as lavapipe renders with: every usable core.
    const std::uint32_t threads = usableProcessors();
    json out = {{"device", ctx.info().name},
                {"driver", ctx.info().driverInfo},
                {"width", a.width},
                {"height", a.height},
                {"spp", a.spp},
                {"repeats", a.repeats},
                {"workgroup", a.workgroup},
                {"threads", threads},
                {"scenes", json::array()}};
    std::stringstream list(a.scenes);
    std::string name;
    while (std::getline(list, name, ',')) {
        std::fprintf(stderr, "gdpt bench: %s\n", name.c_str());
        const Scene scene = benchScene(name);
        std::vector<double> buildMs, collapseMs, embreeBuildMs;
        BvhStats bvhStats;
        for (int r = 0; r < a.repeats; ++r) {
            const Bvh bvh = buildBvh(scene.positions, scene.triangles);
            Timer collapse;
            const WideBvh wide = collapseToWide(bvh.nodes);
            collapseMs.push_back(collapse.ms());
            buildMs.push_back(bvh.stats.buildMs);
            bvhStats = bvh.stats;
#if defined(GDPT_HAVE_EMBREE)
            if (a.embree)
                embreeBuildMs.push_back(EmbreeScene(scene.positions, scene.triangles, threads).buildMs());
#endif
        }

        SceneGpuOptions so;
        so.width = a.width;
        so.height = a.height;
        std::vector<double> primary, incoherent, primaryCpu, incoherentCpu;
        std::vector<double> embreePrimary, embreeIncoherent, embreePrimaryCpu, embreeIncoherentCpu;
        std::uint32_t registerStack = 0;
        bool unitSteps = false;
        {
            SceneGpu sceneGpu(ctx, scene, so);
            registerStack = sceneGpu.spec().bvhRegisterStack();
            unitSteps = sceneGpu.spec().bvhUnitSteps(ctx.info());
            BenchRaysPass pass(ctx, sceneGpu, wg);
            pass.run(1, false, 99);  // warm-up: pipeline compilation happens lazily on some drivers
#if defined(GDPT_HAVE_EMBREE)
            std::optional<EmbreeScene> embree;
            if (a.embree) embree.emplace(scene.positions, scene.triangles, threads);
#endif
            // One camera ray per sample: the counters miss none (and incoherent paths add bounces).
            const std::uint64_t cameraRays = std::uint64_t(a.width) * std::uint64_t(a.height) * a.spp;
            for (int r = 0; r < a.repeats; ++r) {
                const auto seed = static_cast<std::uint32_t>(r);
                for (const bool inc : {false, true}) {
                    const auto p = pass.run(a.spp, inc, seed);
                    GDPT_CHECK(inc ? p.rays >= cameraRays : p.rays == cameraRays);
                    (inc ? incoherent : primary).push_back(static_cast<double>(p.rays) / p.seconds);
                    (inc ? incoherentCpu : primaryCpu).push_back(static_cast<double>(p.rays) / p.cpuSeconds);
#if defined(GDPT_HAVE_EMBREE)
                    // The same paths right after gdpt's (interleaved, so both see the same load).
                    if (embree) {
                        const auto e =
                            embree->traceBenchPaths(sceneGpu.constants(), a.spp, inc, seed, threads);
                        GDPT_CHECK(inc ? e.count.rays >= cameraRays : e.count.rays == cameraRays);
                        (inc ? embreeIncoherent : embreePrimary)
                            .push_back(static_cast<double>(e.count.rays) / e.seconds);
                        (inc ? embreeIncoherentCpu : embreePrimaryCpu)
                            .push_back(static_cast<double>(e.count.rays) / e.cpuSeconds);
                    }
#endif
                }
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
        json entry = {{"scene", name},
                      {"triangles", scene.triangles.size()},
                      {"bvh_build_ms", median(buildMs)},
                      {"bvh_collapse_ms", median(collapseMs)},
                      {"bvh_sah_cost", bvhStats.sahCost},
                      {"bvh_nodes", bvhStats.nodeCount},
                      {"bvh_register_stack", registerStack},
                      {"bvh_steps", unitSteps ? "units" : "nodes"},
                      {"primary_rays_per_s", median(primary)},
                      {"incoherent_rays_per_s", median(incoherent)},
                      {"primary_rays_per_cpu_s", median(primaryCpu)},
                      {"incoherent_rays_per_cpu_s", median(incoherentCpu)},
                      {"pt_samples_per_s", median(ptSamples)},
                      {"pt_rays_per_s", median(ptRays)},
                      {"pt_rays_per_cpu_s", median(ptRaysCpu)},
                      {"pt_sampling_ms", median(ptMs)},
                      {"pt_kernels", kernels}};
        if (!embreeBuildMs.empty()) {
            // Ratios of gdpt to Embree: build time (binary build + collapse, what the kernels
            // need, against rtcCommitScene) and rays/s; < 1 means gdpt is slower.
            const double gdptBuild = median(buildMs) + median(collapseMs);
            entry["embree"] = {{"build_ms", median(embreeBuildMs)},
                               {"primary_rays_per_s", median(embreePrimary)},
                               {"incoherent_rays_per_s", median(embreeIncoherent)},
                               {"primary_rays_per_cpu_s", median(embreePrimaryCpu)},
                               {"incoherent_rays_per_cpu_s", median(embreeIncoherentCpu)}};
            entry["gdpt_over_embree"] = {
                {"build_time", ratio(gdptBuild, median(embreeBuildMs))},
                {"primary_rays", ratio(median(primary), median(embreePrimary))},
                {"incoherent_rays", ratio(median(incoherent), median(embreeIncoherent))},
                {"primary_rays_cpu", ratio(median(primaryCpu), median(embreePrimaryCpu))},
                {"incoherent_rays_cpu", ratio(median(incoherentCpu), median(embreeIncoherentCpu))}};
        }
        out["scenes"].push_back(entry);
    }
    output.write(out.dump(2) + "\n");
    outputs.commit();
    return 0;
}

}  // namespace

Subcommand addBenchCommand(CLI::App& app) {
    auto args = std::make_shared<BenchArgs>();
    CLI::App* b = app.add_subcommand("bench", "Throughput benchmark: BVH build, rays/s, PT samples/s (JSON)");
    b->add_option("--scenes", args->scenes,
                  "Comma-separated scenes: cbox, 10k, 100k, 1m, or .gltf/.glb files")
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
    b->add_flag("--embree", args->embree,
                "Also measure Embree 3 on the same triangles and rays, interleaved, and print gdpt/Embree "
                "ratios (needs a build with -DGDPT_EMBREE=ON)");
    b->add_option("-o,--output", args->output, "Write the JSON here ('-' = stdout)")->capture_default_str();
    return {b, [args] { return runBench(*args); }};
}

}  // namespace gdpt
