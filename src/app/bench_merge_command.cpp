// bench_merge_command.cpp — `gdpt bench-merge`: what merging the parts of a distributed render
// costs (docs/distributed.md, the scaling model), as JSON. Per method and image size: the bytes
// of statistics a part sends or writes, and the median seconds to merge one part into rank 0's
// statistics. Run alone, that is the host merge (stats_merge.h); run under mpirun
// (`mpirun -n N gdpt bench-merge`), it is MpiWorld::combine itself: rank 0 receives every
// other rank's statistics in rank order and merges them, transfer included, and the figure is
// per part. The statistics are synthetic (deterministic values, every pixel counted), so
// sizes that do not render on this device yet are measured too.
#include <cstdio>
#include <cstring>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "app/bench_util.h"
#include "app/subcommand.h"
#include "distributed/mpi_world.h"
#include "integrator/stats_merge.h"
#include "util/error.h"
#include "util/interrupt.h"
#include "util/timer.h"

namespace gdpt {
namespace {

using nlohmann::json;

struct BenchMergeArgs {
    std::string methods = "pt,gpt";
    std::string sizes = "256,1920x1080,3840x2160";
    int repeats = 3;
    std::string output = "-";
};

// Statistics buffers of a method (sampler_state.h): PT 2, G-PT 11 (12 with demodulation).
std::size_t bufferCount(const std::string& method) {
    if (method == "pt") return 2;
    if (method == "gpt") return 11;
    throw UsageError("--methods: unknown method '" + method + "' (pt, gpt)");
}

// A part's statistics: every pixel with `spp` samples, means and M2 that vary per pixel.
SamplerState syntheticState(std::size_t buffers, std::size_t pixels, std::uint32_t spp, std::uint32_t part) {
    SamplerState s;
    s.spp = spp;
    std::vector<gpu::PixelStats> pattern(pixels);
    std::mt19937 rng(17 + part);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (auto& p : pattern) {
        p.count = spp;
        p.mean = glm::vec3(u(rng), u(rng), u(rng));
        p.m2 = glm::vec3(u(rng), u(rng), u(rng)) * float(spp);
    }
    s.buffers.assign(buffers, pattern);
    return s;
}

int runBenchMerge(const BenchMergeArgs& args) {
    installInterruptHandlers();
    MpiWorld* world = MpiWorld::get();
    const bool writes = !world || world->root();
    OutputSet outputs(std::vector<std::pair<std::string, std::string>>{});
    const TextOutput out(outputs, writes ? args.output : "", "-o");
    if (world)
        world->agree({{"command", "bench-merge"},
                      {"methods", args.methods},
                      {"sizes", args.sizes},
                      {"repeats", std::to_string(args.repeats)}},
                     "");
    const int parts = world ? world->size() : 2;
    json results = json::array();
    for (const std::string& method : splitList(args.methods)) {
        const std::size_t buffers = bufferCount(method);
        for (const std::string& sizeText : splitList(args.sizes)) {
            const auto [w, h] = parseSize(sizeText);
            const std::size_t pixels = std::size_t(w) * std::size_t(h);
            const std::uint32_t part = world ? static_cast<std::uint32_t>(world->rank()) : 1;
            const SamplerState mine = syntheticState(buffers, pixels, 4, part);
            std::vector<double> seconds;
            for (int r = 0; r < args.repeats; ++r) {
                throwIfInterrupted("benchmarking merges");
                if (world) {
                    // The real exchange: rank 0 receives and merges the other ranks' parts.
                    RenderStats stats;
                    (void)world->combine(mine, stats);  // a copy: the next repeat sends it again
                    seconds.push_back(stats.distributed.mergeMs * 1e-3 / double(parts - 1));
                } else {
                    SamplerState acc = syntheticState(buffers, pixels, 4, 0);
                    Timer t;
                    mergeStateInto(acc, mine);
                    seconds.push_back(t.seconds());
                }
            }
            const double bytes = double(buffers * pixels * sizeof(gpu::PixelStats));
            const double med = median(seconds);
            results.push_back({{"method", method},
                               {"width", w},
                               {"height", h},
                               {"buffers", buffers},
                               {"bytes_per_part", bytes},
                               {"merge_s_per_part", med},
                               {"merge_s_per_part_all", seconds},
                               {"bytes_per_s", med > 0.0 ? bytes / med : 0.0}});
            if (writes)
                std::fprintf(stderr, "bench-merge: %s %dx%d: %.1f MiB per part, %.3f s per part\n",
                             method.c_str(), w, h, bytes / (1024.0 * 1024.0), med);
        }
    }
    if (writes) {
        const json j = {
            {"command", "bench-merge"},
            {"ranks", world ? world->size() : 1},
            {"what", world ? "transfer + merge per part (MpiWorld::combine)" : "host merge per part"},
            {"results", results}};
        out.write(j.dump(2) + "\n");
        outputs.commit();
    }
    return 0;
}

}  // namespace

Subcommand addBenchMergeCommand(CLI::App& app) {
    auto args = std::make_shared<BenchMergeArgs>();
    CLI::App* b = app.add_subcommand("bench-merge",
                                     "JSON: bytes and seconds per part of merging a distributed render's "
                                     "statistics (alone: the host merge; "
                                     "under mpirun: transfer + merge on rank 0)");
    b->add_option("--methods", args->methods, "Comma-separated: pt, gpt")->capture_default_str();
    b->add_option("--sizes", args->sizes, "Comma-separated image sizes, N or WxH")->capture_default_str();
    b->add_option("--repeats", args->repeats, "Repeats per size (median reported)")
        ->capture_default_str()
        ->check(CLI::Range(1, 100));
    b->add_option("-o,--output", args->output, "Write the JSON here ('-' = stdout)")->capture_default_str();
    return {b, [args] { return runBenchMerge(*args); }};
}

}  // namespace gdpt
