// commands.cpp — the small subcommands: diff, diff-sequence, info, devices (render is render_command.cpp).
#include "app/commands.h"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <utility>

#include "app/bench_util.h"
#include "app/render_setup.h"
#include "app/subcommand.h"
#include "image/atomic_write.h"
#include "image/exr_io.h"
#include "image/finite_check.h"
#include "image/metrics.h"
#include "image/png_preview.h"
#include "integrator/gpt_alpha.h"
#include "integrator/gpt_reconstruction.h"
#include "integrator/gpt_sampler.h"
#include "render/device_scene/features.h"
#include "render/device_scene/scene_gpu.h"
#include "scene/gltf_loader.h"
#include "scene/light_sources.h"
#include "util/error.h"
#include "util/frame_pattern.h"
#include "util/output_files.h"
#include "vk/context.h"

namespace gdpt {

using nlohmann::json;

WorkgroupSize parseWorkgroup(const std::string& text) {
    unsigned x = 0, y = 0;
    char sep = 0;
    std::istringstream in(text);
    if (!(in >> x >> sep >> y) || sep != 'x' || x == 0 || y == 0 || x * y > 1024)
        throw UsageError("--workgroup '" + text + "' must be WxH with W*H <= 1024, e.g. 8x8");
    return {x, y};
}

glm::vec3 parseColor(const std::string& text, const std::string& flag) {
    std::vector<float> v;
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) {
        try {
            std::size_t used = 0;
            const float f = std::stof(item, &used);
            if (used != item.size() || !(f >= 0.0f) || f > 3.0e38f) throw std::invalid_argument(item);
            v.push_back(f);
        } catch (const std::exception&) {
            throw UsageError(flag + " '" + text + "': expected R,G,B with finite non-negative numbers");
        }
    }
    if (v.size() == 1) return glm::vec3(v[0]);
    if (v.size() != 3) throw UsageError(flag + " '" + text + "': expected R,G,B");
    return {v[0], v[1], v[2]};
}

int runDiff(const DiffArgs& args) {
    OutputSet outputs({{"test image", args.test}, {"reference", args.reference}});
    const TextOutput jsonOutput(outputs, args.json, "--json");
    const StagedFile* mapFile = args.errorMap.empty() ? nullptr : &outputs.add(args.errorMap, "--error-map");
    const StagedFile* mapPreview =
        args.errorMap.empty() ? nullptr
                              : &outputs.add(previewPath(args.errorMap), "PNG preview of --error-map");
    const Image test = readExrLayer(args.test);
    const Image reference = readExrLayer(args.reference);
    const auto size = [](const Image& im) {
        return std::to_string(im.width()) + "x" + std::to_string(im.height());
    };
    if (!test.sameSize(reference))
        throw Error("cannot compare " + args.test + " (" + size(test) + ") with the reference " +
                    args.reference + " (" + size(reference) + "): the sizes differ");
    // Pixels with a NaN or infinite value in either image are left out of every metric
    // (metrics.h); say which file has them, and fail when no pixel is left to compare.
    const PixelScan badTest = scanNonFinite(test), badReference = scanNonFinite(reference);
    const ImageErrorStats e = compareImages(test, reference);
    if (e.finitePixels == 0)
        throw Error("no pixel is finite in both " + args.test + " and " + args.reference +
                    " (NaN or infinite: " + badTest.describe() + " of " + args.test + ", " +
                    badReference.describe() + " of " + args.reference + "); nothing to compare");
    for (const auto& [file, bad] :
         {std::pair{&args.test, &badTest}, std::pair{&args.reference, &badReference}})
        if (bad->any())
            std::fprintf(stderr, "gdpt: warning: %s: NaN or infinite values in %s, left out of the metrics\n",
                         file->c_str(), bad->describe().c_str());
    json j = {{"test", args.test},
              {"reference", args.reference},
              {"relmse", e.relMse},
              {"mse", e.mse},
              {"mae", e.mae},
              {"max_abs_error", e.maxAbsError},
              {"mean_bias", e.meanBias},
              {"mean_test", e.meanTest},
              {"mean_reference", e.meanReference},
              {"finite_pixels", e.finitePixels},
              {"nonfinite_pixels", e.nonFinitePixels},
              {"relmse_by_brightness", e.relMseByQuarter}};
    jsonOutput.write(j.dump(2) + "\n");
    if (mapFile) {
        const Image map = relMseMap(test, reference);
        writeExr(*mapFile, {{"", map}});
        // Reinhard with the mean term at 1/2: the map's structure, whatever its scale.
        PreviewOptions preview;
        preview.toneMap = ToneMap::Reinhard;
        preview.exposure = e.relMse > 0.0 ? static_cast<float>(1.0 / e.relMse) : 1.0f;
        writePngPreview(*mapPreview, map, preview);
    }
    outputs.commit();
    if (args.json != "-") {
        std::printf("relMSE %.6g  MSE %.6g  MAE %.6g  max %.6g  bias %.3g  (%zu pixels, %zu non-finite)\n",
                    e.relMse, e.mse, e.mae, e.maxAbsError, e.meanBias, e.finitePixels, e.nonFinitePixels);
        const auto& q = e.relMseByQuarter;
        std::printf("relMSE by the reference's brightness, darkest quarter first: %.4g  %.4g  %.4g  %.4g\n",
                    q[0], q[1], q[2], q[3]);
    }
    return 0;
}

int runDiffSequence(const DiffSequenceArgs& args) {
    const FrameRange range = parseFrameRange(args.frames, "--frames");
    if (!hasFrameNumber(args.test, "test") || !hasFrameNumber(args.reference, "reference") ||
        (!args.motion.empty() && !hasFrameNumber(args.motion, "--motion")))
        throw UsageError(
            "diff-sequence compares sequences: every path takes a frame number (e.g. out/f_%04d.exr)");
    OutputSet outputs;
    const TextOutput jsonOutput(outputs, args.json, "--json");
    json frames = json::array();
    double relSum = 0.0, temporalSum = 0.0, alongSum = 0.0;
    Image testBefore, referenceBefore;
    for (int f = range.first; f <= range.last; ++f) {
        const std::string testPath = framePath(args.test, f), referencePath = framePath(args.reference, f);
        for (const std::string* p : {&testPath, &referencePath})
            if (!std::filesystem::is_regular_file(*p)) throw Error(*p + ": no such frame");
        Image test = readExrLayer(testPath), reference = readExrLayer(referencePath);
        if (!test.sameSize(reference))
            throw Error("cannot compare " + testPath + " with " + referencePath + ": the sizes differ");
        json j = {{"frame", f}, {"relmse", relMse(test, reference)}};
        relSum += j["relmse"].get<double>();
        if (f > range.first) {
            const double t = temporalRelMse(testBefore, test, referenceBefore, reference);
            j["temporal_relmse"] = t;  // of the change from the frame before
            temporalSum += t;
            if (!args.motion.empty()) {
                const std::string motionPath = framePath(args.motion, f);
                if (!std::filesystem::is_regular_file(motionPath))
                    throw Error(motionPath + ": no such frame");
                const Image motion = readExrLayer(motionPath, "motion");
                const double a = temporalRelMse(testBefore, test, referenceBefore, reference, &motion);
                j["temporal_relmse_along_motion"] = a;
                alongSum += a;
            }
        }
        frames.push_back(std::move(j));
        testBefore = std::move(test);
        referenceBefore = std::move(reference);
    }
    const double meanRel = relSum / range.count();
    const double meanTemporal = range.count() > 1 ? temporalSum / (range.count() - 1) : 0.0;
    const double meanAlong = range.count() > 1 ? alongSum / (range.count() - 1) : 0.0;
    json summary{{"test", args.test},
                 {"reference", args.reference},
                 {"frames", {{"first", range.first}, {"last", range.last}}},
                 {"mean_relmse", meanRel},
                 {"mean_temporal_relmse", meanTemporal}};
    if (!args.motion.empty()) {
        summary["motion"] = args.motion;
        summary["mean_temporal_relmse_along_motion"] = meanAlong;
    }
    summary["per_frame"] = std::move(frames);
    jsonOutput.write(summary.dump(2) + "\n");
    outputs.commit();
    if (args.json != "-") {
        std::printf("frames %d-%d: mean relMSE %.6g, mean temporal relMSE %.6g", range.first, range.last,
                    meanRel, meanTemporal);
        if (!args.motion.empty()) std::printf(", along the motion %.6g", meanAlong);
        std::printf("\n");
    }
    return 0;
}

int runInfo(const InfoArgs& args) {
    const GltfAsset asset(args.scene);
    const Scene scene = asset.instance();
    // The features the kernels are specialised for (SceneSpec: the light count is the light
    // table's, without emitters of zero area or power); a scene without triangles has none.
    SceneGpuOptions so;
    so.envRadiance = parseColor(args.env, "--env");
    std::unique_ptr<const SceneSpec> spec;
    if (!scene.triangles.empty()) spec = std::make_unique<const SceneSpec>(scene, so);
    const SceneFeatures f = spec ? spec->features() : analyzeScene(scene, so.envRadiance);
    std::printf("%s\n", describeScene(scene).c_str());
    // Animations (render them with gdpt render --frames; a plain render shows the rest pose).
    if (!asset.animations().empty()) std::printf("%s\n", describeAnimations(asset.animations()).c_str());
    for (const auto& [k, v] : describeFeatures(f)) std::printf("  %-26s %s\n", k.c_str(), v.c_str());
    // bvhRegisterStack: entries of the register traversal stack when the tree was built before
    // the pipelines (small scenes) and its traversals hold at most kBvhRegisterStackMax
    // (bvh_traverse.glsl); 0 = the stack in memory.
    if (spec && spec->bvh())
        std::printf("  %-26s %u (register stack up to %u)\n", "bvh traversal stack",
                    spec->bvh()->wide.maxStack, gpu::kBvhRegisterStackMax);
    else
        std::printf("  %-26s built with the scene upload (more than %zu triangles)\n", "bvh traversal stack",
                    kSpecBvhTriangles);
    // Next-event estimation's share of each emitter (light_table.h), by the default rule at the
    // default camera and image size.
    if (spec && f.emissiveTriangles > 0) {
        const std::shared_ptr<const SceneBvh> bvh =
            spec->bvh() ? spec->bvh() : std::make_shared<const SceneBvh>(buildSceneBvh(scene));
        const LightTable table = sceneLightTable(scene, *bvh, so);
        std::string shares;
        for (const auto& [material, p] : table.shares) {
            char item[64];
            std::snprintf(item, sizeof item, "%smaterial %u %.3f", shares.empty() ? "" : ", ", material, p);
            shares += item;
        }
        std::printf("  %-26s %s (%s%s)\n", "light shares", shares.c_str(), toString(so.lightSelection),
                    table.probed         ? ""
                    : table.emitters > 1 ? ", nothing probed: mixed"
                                         : "");
    }
    // visibleEmission: emitter supersampling (render/passes/emitter_supersampling_pass.h) at the default
    // factor, which needs something the camera can see emit.
    std::printf(
        "kernel variant: pt[textures=%d punctual=%d lightTris=%d env=%d glossy=%d alphaMask=%d "
        "shadingNormals=%d specularLobe=%d emitterSupersampling=%d bvhRegisterStack=%u]\n",
        f.hasTextures, f.hasPunctual, f.hasLightTris, f.hasEnv, f.hasGlossy, f.hasAlphaMask,
        f.hasShadingNormals, f.hasSpecularLayer, emitterSupersamplingPossible(f),
        spec ? spec->bvhRegisterStack() : 0u);
    // G-PT's first-hit texture demodulation as --demodulate auto chooses it (gpt_pass.h).
    std::printf("gpt variant: demodulate=%d\n", demodulationApplies(scene) ? 1 : 0);
    // G-PT's reconstruction and primal weight as render chooses them without --recon and --alpha
    // (gpt_reconstruction.h, gpt_alpha.h).
    std::printf("gpt reconstruction: %s (scene surfaces: %s), alpha %g (scene light: %s)\n",
                toString(gptDefaultReconstruction(gptSurfaces(f))), toString(gptSurfaces(f)),
                gptDefaultAlpha(gptLighting(f)), toString(gptLighting(f)));
    for (const auto& u : scene.unsupported) std::printf("  unsupported: %s\n", u.c_str());
    if (const auto black = blackImageWarning(scene, so.envRadiance))
        std::printf("warning: %s\n", black->c_str());
    return 0;
}

int runDevices(const DevicesArgs& args) {
    const auto devices = vk::Context::listDevices();
    json list = json::array();
    for (const auto& d : devices) {
        list.push_back({{"index", d.index},
                        {"name", d.name},
                        {"type", d.type},
                        {"driver", d.driverName},
                        {"driver_info", d.driverInfo},
                        {"api", std::to_string(VK_API_VERSION_MAJOR(d.apiVersion)) + "." +
                                    std::to_string(VK_API_VERSION_MINOR(d.apiVersion)) + "." +
                                    std::to_string(VK_API_VERSION_PATCH(d.apiVersion))},
                        {"max_storage_buffer_range", d.maxStorageBufferRange},
                        {"max_texel_buffer_elements", d.maxTexelBufferElements},
                        {"max_memory_allocation", d.maxMemoryAllocationSize},
                        {"max_push_constants", d.maxPushConstantsSize},
                        {"max_workgroup_invocations", d.maxComputeWorkGroupInvocations},
                        {"shared_memory", d.maxComputeSharedMemorySize},
                        {"subgroup_size", d.subgroupSize},
                        {"timestamps", d.timestamps},
                        {"device_local_heap", d.deviceLocalHeapBytes},
                        {"usable", d.unsuitable.empty()},
                        {"unsuitable_reason", d.unsuitable}});
    }
    if (args.json) {
        std::printf("%s\n", list.dump(2).c_str());
        return 0;
    }
    for (const auto& d : list)
        std::printf(
            "[%u] %s (%s, %s %s)\n    Vulkan %s, maxStorageBufferRange %llu MiB, maxTexelBufferElements %llu "
            "Mi, maxMemoryAllocationSize %llu MiB, push constants %u B, "
            "workgroup %u, shared %u KiB, subgroup %u, timestamps %s, heap %llu MiB%s\n",
            d["index"].get<unsigned>(), d["name"].get<std::string>().c_str(),
            d["type"].get<std::string>().c_str(), d["driver"].get<std::string>().c_str(),
            d["driver_info"].get<std::string>().c_str(), d["api"].get<std::string>().c_str(),
            static_cast<unsigned long long>(d["max_storage_buffer_range"].get<std::uint64_t>() >> 20),
            static_cast<unsigned long long>(d["max_texel_buffer_elements"].get<std::uint64_t>() >> 20),
            static_cast<unsigned long long>(d["max_memory_allocation"].get<std::uint64_t>() >> 20),
            d["max_push_constants"].get<unsigned>(), d["max_workgroup_invocations"].get<unsigned>(),
            d["shared_memory"].get<unsigned>() / 1024, d["subgroup_size"].get<unsigned>(),
            d["timestamps"].get<bool>() ? "yes" : "no",
            static_cast<unsigned long long>(d["device_local_heap"].get<std::uint64_t>() >> 20),
            d["usable"].get<bool>() ? ""
                                    : (" — unusable: " + d["unsuitable_reason"].get<std::string>()).c_str());
    return 0;
}

// ---- CLI registration ----------------------------------------------------------------

Subcommand addDiffCommand(CLI::App& app) {
    auto args = std::make_shared<DiffArgs>();
    auto& diff = *args;
    CLI::App* d = app.add_subcommand(
        "diff", "Compare two EXR images: relMSE (Kettunen et al. 2015), MSE, MAE, max error");
    d->add_option("test", diff.test, "Image to evaluate")->required()->check(InputFile);
    d->add_option("reference", diff.reference, "Reference image")->required()->check(InputFile);
    d->add_option("--json", diff.json,
                  "Write the metrics as JSON to this file ('-' = stdout); relmse_by_brightness splits relMSE "
                  "by quarters of the pixels ordered by the reference's brightness, darkest first");
    d->add_option(
        "--error-map", diff.errorMap,
        "Write each pixel's relMSE term to this EXR (their mean is relMSE; NaN where a value is not "
        "finite) and a PNG preview beside it (the mean term at mid-grey)");

    return {d, [args] { return runDiff(*args); }};
}

Subcommand addDiffSequenceCommand(CLI::App& app) {
    auto args = std::make_shared<DiffSequenceArgs>();
    auto& d = *args;
    CLI::App* c = app.add_subcommand(
        "diff-sequence",
        "Compare two EXR sequences frame by frame: each frame's relMSE and the temporal relMSE (the error of "
        "the frame-to-frame change; flicker)");
    c->add_option("test", d.test, "Frames to evaluate, with a frame number (e.g. out/f_%04d.exr)")
        ->required();
    c->add_option("reference", d.reference, "Reference frames, with a frame number")->required();
    c->add_option("--frames", d.frames, "A:B: the frames to compare")->required();
    c->add_option("--json", d.json, "Write the metrics as JSON to this file ('-' = stdout)");
    c->add_option("--motion", d.motion,
                  "Also the temporal relMSE along the motion: frames with a `motion` layer (a tgpt render of "
                  "the same sequence and size, e.g. tgpt/f_%04d.exr), whose offsets pair each pixel with "
                  "the pixel of the frame before its content came from");
    return {c, [args] { return runDiffSequence(*args); }};
}

Subcommand addInfoCommand(CLI::App& app) {
    auto args = std::make_shared<InfoArgs>();
    auto& info = *args;
    CLI::App* i = app.add_subcommand("info", "Print a scene's features and the kernel variant gdpt will run");
    i->add_option("scene", info.scene, "glTF 2.0 scene")->required()->check(InputFile);
    i->add_option("--env", info.env, "Constant environment radiance R,G,B")->capture_default_str();

    return {i, [args] { return runInfo(*args); }};
}

Subcommand addDevicesCommand(CLI::App& app) {
    auto args = std::make_shared<DevicesArgs>();
    auto& devices = *args;
    CLI::App* v = app.add_subcommand("devices", "List Vulkan devices with the limits that matter to gdpt");
    v->add_flag("--json", devices.json, "Print JSON");

    return {v, [args] { return runDevices(*args); }};
}

}  // namespace gdpt
