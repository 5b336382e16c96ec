// main.cpp — gdpt entry point: parses the command line (CLI11) and dispatches to the
// subcommands. Exit codes: 0 success, 1 runtime or input error (one clear line on stderr),
// 2 usage error.
#include <cstdio>
#include <exception>

#include <CLI/CLI.hpp>

#include "app/cli.h"
#include "app/commands.h"
#include "util/error.h"

int main(int argc, char** argv) {
    using namespace gdpt;
    CLI::App app{"gdpt — headless gradient-domain path tracer (GLSL compute over Vulkan; lavapipe first)"};
    app.require_subcommand(1);
    app.set_help_all_flag("--help-all", "Print help for all subcommands");

    RenderArgs render;
    CLI::App* r = app.add_subcommand("render", "Render a glTF 2.0 scene to OpenEXR (+ PNG preview)");
    r->add_option("scene", render.scene, "glTF 2.0 scene (.gltf or .glb)")->required()->check(CLI::ExistingFile);
    r->add_option("-o,--output", render.output, "Output EXR; a tone-mapped PNG preview is written beside it")
        ->capture_default_str();
    r->add_option("--spp", render.spp, "Samples per pixel")->capture_default_str()->check(CLI::Range(1u, 1u << 24));
    r->add_option("--time", render.time,
                  "Time budget in seconds for the whole render (loading included); overrides --spp")
        ->check(CLI::Range(0.0, 1e7));
    r->add_option("--width", render.width, "Image width in pixels")->capture_default_str()->check(CLI::Range(1, 16384));
    r->add_option("--height", render.height, "Image height in pixels")->capture_default_str()->check(CLI::Range(1, 16384));
    r->add_option("--max-depth", render.maxDepth, "Maximum number of bounces (1 = direct lighting only)")
        ->capture_default_str()
        ->check(CLI::Range(0u, 1023u));
    r->add_option("--seed", render.seed, "Random seed (renders are deterministic per seed and device)")
        ->capture_default_str();
    r->add_option("--env", render.env, "Constant environment radiance R,G,B (W/m^2/sr)")->capture_default_str();
    r->add_option("--device", render.device, "Vulkan device index or name substring (default: lavapipe)");
    r->add_option("--camera", render.camera, "Camera index in the glTF (default: first camera, or a framing camera)")
        ->check(CLI::NonNegativeNumber);
    r->add_option("--method", render.method, "Rendering method")->capture_default_str()->check(CLI::IsMember({"pt"}));
    r->add_option("--workgroup", render.workgroup, "Compute workgroup size WxH")->capture_default_str();
    r->add_flag("--profile", render.profile, "Print GPU time per kernel (timestamp queries)");
    r->add_option("--json", render.json, "Write render statistics as JSON to this file");
    r->add_flag("--quiet", render.quiet, "No progress output");
    r->add_flag("--validate", render.validate, "Enable Vulkan validation layers (errors make the run fail)");

    DiffArgs diff;
    CLI::App* d = app.add_subcommand("diff", "Compare two EXR images: relMSE (Kettunen et al. 2015), MSE, MAE, max error");
    d->add_option("test", diff.test, "Image to evaluate")->required()->check(CLI::ExistingFile);
    d->add_option("reference", diff.reference, "Reference image")->required()->check(CLI::ExistingFile);
    d->add_option("--json", diff.json, "Write the metrics as JSON to this file ('-' = stdout)");

    InfoArgs info;
    CLI::App* i = app.add_subcommand("info", "Print a scene's features and the kernel variant gdpt will run");
    i->add_option("scene", info.scene, "glTF 2.0 scene")->required()->check(CLI::ExistingFile);
    i->add_option("--env", info.env, "Constant environment radiance R,G,B")->capture_default_str();

    DevicesArgs devices;
    CLI::App* v = app.add_subcommand("devices", "List Vulkan devices with the limits that matter to gdpt");
    v->add_flag("--json", devices.json, "Print JSON");

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e) == 0 ? 0 : 2;
    }
    try {
        if (*r) return runRender(render);
        if (*d) return runDiff(diff);
        if (*i) return runInfo(info);
        if (*v) return runDevices(devices);
    } catch (const UsageError& e) {
        std::fprintf(stderr, "gdpt: usage error: %s\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "gdpt: error: %s\n", e.what());
        return 1;
    }
    return 2;
}
