// merge_command.cpp — `gdpt merge SHARD... -o OUT.exr`: the shards of a render split into
// independent jobs (`gdpt render --shard I/N`; distributed/shards.h) checked, merged in part
// order and finished as the render they belong to (G-PT: reconstructed), with the same outputs
// as `gdpt render`: equal to `mpirun -n N gdpt render` with the same settings.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "app/commands.h"
#include "app/input_file.h"
#include "app/subcommand.h"
#include "distributed/shards.h"
#include "util/interrupt.h"

namespace gdpt {
namespace {

struct MergeArgs {
    std::vector<std::string> shards;
    std::string output = "render.exr";
    std::string scene;  // default: the path the shards recorded
    std::string device;
    std::string json;
    bool quiet = false;
    bool validate = false;
};

int runMerge(const MergeArgs& m) {
    installInterruptHandlers();
    const MergedShards merged = mergeShards(m.shards);
    const std::string& first = m.shards.front();
    const auto setting = [&](const char* key) {
        const auto it = merged.info.find(key);
        if (it == merged.info.end())
            throw Error(first + ": shard does not record " + key + " (gdpt.info." + key + ")");
        return it->second;
    };
    RenderArgs args = renderArgsFromJson(setting("render_args"), first);
    args.scene = m.scene.empty() ? setting("scene_path") : m.scene;
    if (const std::string problem = inputFileProblem(args.scene); !problem.empty())
        throw Error("the shards' scene " + args.scene + ": " + problem +
                    (m.scene.empty() ? " (moved? give its path with --scene)" : ""));
    // Every sample is in the shards: the render continues with none more.
    args.spp = merged.state.spp;
    args.time = 0.0;
    args.output = m.output;
    args.json = m.json;
    args.device = m.device;
    args.quiet = m.quiet;
    args.validate = m.validate;
    if (!m.quiet)
        std::fprintf(stderr, "gdpt: merged %u shards (%u spp) in %.1f ms\n", merged.stats.parts,
                     merged.state.spp, merged.stats.mergeMs);
    return runRender(args, &merged);
}

}  // namespace

Subcommand addMergeCommand(CLI::App& app) {
    auto args = std::make_shared<MergeArgs>();
    CLI::App* c = app.add_subcommand("merge",
                                     "Merge the shards of a render (gdpt render --shard I/N) and finish it: "
                                     "reconstruct and write the EXR, PNG "
                                     "and JSON as gdpt render does (docs/distributed.md)");
    c->add_option("shards", args->shards, "Every shard file of the render, in any order")
        ->required()
        ->check(InputFile);
    c->add_option("-o,--output", args->output, "Output EXR; the PNG preview is written beside it")
        ->capture_default_str();
    c->add_option(
         "--scene", args->scene,
         "The render's glTF scene, if it moved since the shards were rendered (default: the path the "
         "shards recorded; its fingerprint must match)")
        ->check(InputFile);
    c->add_option("--device", args->device, "Vulkan device index or name substring (default: lavapipe)");
    c->add_option("--json", args->json, "Write the render's statistics as JSON to this file ('-' = stdout)");
    c->add_flag("--quiet", args->quiet, "No progress or summary output");
    c->add_flag("--validate", args->validate, "Enable Vulkan validation layers (errors fail the run)");
    return {c, [args] { return runMerge(*args); }};
}

}  // namespace gdpt
