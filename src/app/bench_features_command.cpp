// bench_features_command.cpp — `gdpt bench-features SCENE...`: what each specialisation
// constant saves (JSON, not a test). For every scene and method (pt, gpt) it renders the
// kernel variant gdpt picks for the scene ("specialised"), the variant with one feature the
// scene lacks compiled in anyway (one per such feature), and the variant with every feature
// compiled in ("generic"). Repeats are interleaved across variants so that a load change on
// the shared machine hits all of them alike; each figure is the median samples/s over the
// repeats, and ratio = specialised samples/s / variant samples/s (> 1: the specialisation
// pays); an untimed 1-spp render of every variant comes first. image_rel_mse compares each variant's image
// with the specialised one rendered with the same seed (Kettunen relMSE): a feature that is absent must not
// change the estimator, so it is 0 or at the float-rounding level.
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "app/bench_util.h"
#include "app/subcommand.h"
#include "image/metrics.h"
#include "integrator/integrator.h"
#include "render/device_scene/features.h"
#include "scene/gltf_loader.h"
#include "util/error.h"
#include "vk/context.h"

namespace gdpt {
namespace {

struct BenchFeaturesArgs {
    std::vector<std::string> scenes;
    std::string methods = "pt,gpt";
    int width = 128;
    int height = 128;
    std::uint32_t spp = 4;
    int repeats = 3;
    std::string device;
    std::string output = "-";
};

struct Feature {
    const char* name;
    std::uint32_t specId;
    bool (*needed)(const SceneFeatures&, bool gpt);
};

// kHasGlossy only exists in the G-PT kernel (the half-vector shift); PT compiles the same
// code either way, so it is never "lacking" there. kMaxDepth is always specialised (the
// scene's own depth cap), so its generic variant is the 1024-bounce loop bound.
// memory_stack: the traversal stack in memory instead of registers (kSpecBvhRegisterStack;
// where the scene's tree is too large for the register stack, the same kernel).
const Feature kFeatures[] = {
    {"textures", gpu::kSpecHasTextures, [](const SceneFeatures& f, bool) { return f.hasTextures; }},
    {"punctual", gpu::kSpecHasPunctual, [](const SceneFeatures& f, bool) { return f.hasPunctual; }},
    {"light_tris", gpu::kSpecHasLightTris, [](const SceneFeatures& f, bool) { return f.hasLightTris; }},
    {"env", gpu::kSpecHasEnv, [](const SceneFeatures& f, bool) { return f.hasEnv; }},
    {"glossy", gpu::kSpecHasGlossy, [](const SceneFeatures& f, bool gpt) { return f.hasGlossy || !gpt; }},
    {"alpha_mask", gpu::kSpecHasAlphaMask, [](const SceneFeatures& f, bool) { return f.hasAlphaMask; }},
    {"shading_normals", gpu::kSpecHasShadingNormals,
     [](const SceneFeatures& f, bool) { return f.hasShadingNormals; }},
    {"specular_lobe", gpu::kSpecHasSpecularLobe,
     [](const SceneFeatures& f, bool) { return f.hasSpecularLayer; }},
    {"max_depth", gpu::kSpecMaxDepth, [](const SceneFeatures&, bool) { return false; }},
    {"memory_stack", gpu::kSpecBvhRegisterStack, [](const SceneFeatures&, bool) { return false; }},
};

struct Variant {
    std::string name;
    std::uint32_t generic = 0;  // SceneGpuOptions::genericFeatures
    std::vector<double> samplesPerS;
    Image image;  // first repeat's image (seed 0)
};

// One render of `method` with the variant's generic features; returns samples/s and the
// image (G-PT without reconstruction: primal + direct, the estimator the kernels compute).
double renderOnce(const vk::Context& ctx, const Scene& scene, const BenchFeaturesArgs& a,
                  const std::string& method, std::uint32_t generic, std::uint32_t seed, Image* image) {
    RenderOptions ro;
    ro.scene.width = a.width;
    ro.scene.height = a.height;
    ro.scene.genericFeatures = generic;
    ro.spp = a.spp;
    ro.seed = seed;
    ro.quiet = true;
    MethodOptions m;
    m.gpt.sampling.forceHalfVector = (generic & (1u << gpu::kSpecHasGlossy)) != 0;
    m.gpt.reconstructions.clear();
    RenderOutput out = makeIntegrator(method, m)->render(ctx, scene, ro);
    if (image) *image = std::move(out.layers.front().image);
    return static_cast<double>(out.stats.pathsCompleted) / (out.stats.samplingMs * 1e-3);
}

int runBenchFeatures(const BenchFeaturesArgs& a) {
    using nlohmann::json;
    const std::vector<std::string> methods = splitList(a.methods);
    for (const std::string& m : methods) (void)makeIntegrator(m);  // unknown names fail first
    OutputSet outputs;
    const TextOutput output(outputs, a.output, "-o");
    vk::ContextOptions co;
    co.device = a.device;
    vk::Context ctx(co);
    json out = {{"device", ctx.info().name},
                {"driver", ctx.info().driverInfo},
                {"width", a.width},
                {"height", a.height},
                {"spp", a.spp},
                {"repeats", a.repeats},
                {"results", json::array()}};
    for (const std::string& path : a.scenes) {
        const Scene scene = loadGltf(path);
        const SceneFeatures f = analyzeScene(scene, glm::vec3(0.0f));
        for (const std::string& method : methods) {
            const bool gpt = method == "gpt";
            std::vector<Variant> variants = {{"specialised", 0, {}, {}}};
            std::uint32_t all = 0;
            for (const Feature& feat : kFeatures) {
                if (feat.needed(f, gpt)) continue;
                variants.push_back({std::string("+") + feat.name, 1u << feat.specId, {}, {}});
                all |= 1u << feat.specId;
            }
            variants.push_back({"generic", all, {}, {}});
            // Untimed warm-up: lavapipe compiles a pipeline at its first dispatch (later
            // renders of the same variant hit Mesa's shader cache), which would otherwise
            // land in the first repeat's sampling time.
            BenchFeaturesArgs warm = a;
            warm.spp = 1;
            for (const Variant& v : variants) renderOnce(ctx, scene, warm, method, v.generic, 0, nullptr);
            for (int r = 0; r < a.repeats; ++r)
                for (Variant& v : variants) {
                    std::fprintf(stderr, "gdpt bench-features: %s %s %s (repeat %d)\n", path.c_str(),
                                 method.c_str(), v.name.c_str(), r + 1);
                    v.samplesPerS.push_back(renderOnce(ctx, scene, a, method, v.generic,
                                                       static_cast<std::uint32_t>(r),
                                                       r == 0 ? &v.image : nullptr));
                }
            const double base = median(variants[0].samplesPerS);
            json rows = json::array();
            for (const Variant& v : variants) {
                const double sps = median(v.samplesPerS);
                rows.push_back({{"variant", v.name},
                                {"samples_per_s", sps},
                                {"all_samples_per_s", v.samplesPerS},
                                {"ratio", base / sps},
                                {"image_rel_mse", relMse(v.image, variants[0].image)}});
            }
            out["results"].push_back({{"scene", path}, {"method", method}, {"variants", rows}});
        }
    }
    output.write(out.dump(2) + "\n");
    outputs.commit();
    return 0;
}

}  // namespace

Subcommand addBenchFeaturesCommand(CLI::App& app) {
    auto args = std::make_shared<BenchFeaturesArgs>();
    CLI::App* b = app.add_subcommand(
        "bench-features",
        "What each specialisation constant saves: samples/s of specialised vs generic kernels (JSON)");
    b->add_option("scenes", args->scenes, "glTF 2.0 scenes")->required()->check(InputFile);
    b->add_option("--methods", args->methods, "Comma-separated: pt, gpt")->capture_default_str();
    b->add_option("--width", args->width, "Image width")->capture_default_str()->check(CLI::Range(1, 4096));
    b->add_option("--height", args->height, "Image height")
        ->capture_default_str()
        ->check(CLI::Range(1, 4096));
    b->add_option("--spp", args->spp, "Samples per pixel per render")
        ->capture_default_str()
        ->check(CLI::Range(1u, 4096u));
    b->add_option("--repeats", args->repeats, "Interleaved repeats per variant (median reported)")
        ->capture_default_str()
        ->check(CLI::Range(1, 100));
    b->add_option("--device", args->device, "Vulkan device index or name substring");
    b->add_option("-o,--output", args->output, "Write the JSON here ('-' = stdout)")->capture_default_str();
    return {b, [args] { return runBenchFeatures(*args); }};
}

}  // namespace gdpt
