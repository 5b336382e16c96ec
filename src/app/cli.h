// cli.h — the gdpt command line: subcommands, their options and defaults. Parsing only;
// each subcommand's work lives in commands.cpp.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <string>

#include "poisson/debias.h"
#include "render/device_scene/scene_spec.h"
#include "render/passes/edge_options.h"
#include "render/passes/emitter_supersampling_options.h"

namespace gdpt {

struct RenderArgs {
    std::string scene;
    std::string output = "render.exr";
    std::uint32_t spp = 64;
    double time = 0.0;
    int width = 256;
    int height = 256;
    std::uint32_t maxDepth = 64;
    std::uint32_t seed = 0;
    std::string env = "0,0,0";
    std::string device;
    int camera = -1;
    bool profile = false;
    std::string json;
    bool quiet = false;
    bool validate = false;
    std::string method = "gpt";
    std::string workgroup = "8x8";
    float shiftThreshold = 0.001f;
    std::string lightSelection = "probe";  // power, uniform, mixed, probe (LightSelection)
    std::string splitBounce = "auto";      // G-PT: auto, on, off (GptPassOptions::SplitBounce)
    std::uint32_t emitterSupersampling =
        kDefaultEmitterSupersampling;  // render/passes/emitter_supersampling_pass.h
    std::string edgeSamples = "auto";  // G-PT: "auto" or 0-64 (render/passes/edge_options.h)
    std::string demodulate = "auto";   // G-PT: auto, on, off (Demodulation, render/passes/gpt_pass.h)
    std::string recon = "auto";        // the final image's reconstruction; auto: resolvedRecon
    double alpha = -1.0;               // < 0: the method's own (GptOptions, MltOptions, TgptOptions::alpha)
    double tolerance = 1e-4;
    int debiasCells = kDefaultDebiasCells;  // poisson/debias.h
    std::string solver = "auto";            // the reconstructions' linear solver (parseSolverChoice)
    bool allRecon = false;
    std::string checkpoint;        // write the sampler state here on interrupt / periodically / at the end
    double checkpointEvery = 0.0;  // seconds between periodic checkpoints (0 = only at the end)
    std::string resume;            // continue from this checkpoint
    std::string shard;         // "I/N": render part I of N and write its statistics (distributed/shards.h)
    std::uint32_t chains = 0;  // pssmlt, gmlt: Markov chains (0 = per image size)
    float largeStep = -1.0f;   // pssmlt, gmlt: probability of a large step (< 0: the method's own)
    float targetExponent = -1.0f;  // pssmlt, gmlt: the target's exponent (< 0: the method's own)
    int targetBlock = -1;          // pssmlt, gmlt: the target's divisor blocks (< 0: the method's own)
    float targetAlpha = 0.25f;     // gmlt: weight of the radiance in the target
    std::string frames;            // "A:B": render frames A..B of an animation (sequence_command.cpp)
    double fps = 24.0;             // frames per second: frame k is the scene at time k / fps
    std::string animation;         // the animation's name or index ("" = the first)
    bool noVideo = false;          // no MP4 of the sequence even when ffmpeg is installed
    int window = 10;               // tgpt: frames reconstructed together
    double beta = 1.0;             // tgpt: weight of the temporal rows
    double gamma = -1.0;  // tgpt: weight of the mixed rows (< 0: 1, or 0 with the reconnection shift)
    std::string temporalShift = "motion";  // tgpt: motion | replay | reconnect
};

struct DiffArgs {
    std::string test;
    std::string reference;
    std::string json;
    std::string errorMap;  // EXR of each pixel's relMSE term, with a PNG preview beside it
};

struct DiffSequenceArgs {
    std::string test;       // frame pattern, e.g. out/f_%04d.exr
    std::string reference;  // frame pattern of the reference sequence
    std::string frames;     // "A:B"
    std::string json;
    std::string motion;  // frame pattern of EXRs with a `motion` layer (tgpt's), or empty
};

struct InfoArgs {
    std::string scene;
    std::string env = "0,0,0";
};

struct DevicesArgs {
    bool json = false;
};

// Parses "R,G,B" (or a single value for gray) into a colour; throws gdpt::UsageError.
glm::vec3 parseColor(const std::string& text, const std::string& flag);

// Parses --workgroup "WxH" (W*H <= 1024); throws gdpt::UsageError.
WorkgroupSize parseWorkgroup(const std::string& text);

}  // namespace gdpt
