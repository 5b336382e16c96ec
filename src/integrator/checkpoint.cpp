// checkpoint.cpp — the gdpt-checkpoint-1 EXR layout (see checkpoint.h).
#include "integrator/checkpoint.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "render/passes/edge_options.h"
#include "util/error.h"
#include "util/output_files.h"

namespace gdpt {
namespace {

const char* const kFormat = "gdpt-checkpoint-1";
constexpr std::uint32_t kMaxBuffers = 16;
constexpr std::uint32_t kMaxSpp = 1u << 24;  // counts above this are not exact in float32

std::string bufferLayer(std::size_t k, const char* what) {
    return "state" + std::to_string(k) + "." + what;
}

std::uint32_t parseCount(const std::string& path, const ExrAttributes& a, const std::string& key,
                         std::uint32_t max) {
    const auto it = a.find(key);
    if (it == a.end()) throw Error(path + ": checkpoint attribute " + key + " is missing");
    const std::string& text = it->second;
    std::size_t used = 0;
    unsigned long value = 0;
    try {
        value = std::stoul(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used == 0 || used != text.size() || text[0] == '-' || value > max)
        throw Error(path + ": checkpoint attribute " + key + " = '" + text +
                    "' is not a whole number <= " + std::to_string(max));
    return static_cast<std::uint32_t>(value);
}

// What a checkpoint's statistics buffer holds (sampler_state.h), which fixes how its sample
// counts relate to gdpt.spp. A checkpoint is written at a batch boundary of a run without a
// partial pass (sampling_loop.h), so every pixel has had the same camera samples:
//   Path     the path kernels' statistics: spp samples in every pixel, and in the pixels of
//            G-PT's edge samples (the edge pixels and their neighbours)
//            spp x (1 + edge_samples) (edge_pass.h); every Path buffer of a pixel
//            merged the same samples, so they all hold the same count;
//   Visible  emitter supersampling's: spp samples in the pixels it refines, 0 elsewhere.
enum class BufferKind { Path, Visible };

struct BufferRole {
    BufferKind kind;
    const char* name;
};

// The buffers of a checkpoint of `method` (the order of the passes' downloadStats()).
std::vector<BufferRole> bufferLayout(const std::string& path, const ExrAttributes& identity) {
    const auto method = identity.find("method");
    if (method == identity.end())
        throw Error(path + ": checkpoint does not record its method (attribute gdpt.id.method)");
    const BufferRole visible = {BufferKind::Visible, "visible emission"};
    if (method->second == "pt") return {{BufferKind::Path, "path samples"}, visible};
    if (method->second.rfind("gpt", 0) == 0) {
        std::vector<BufferRole> roles = {{BufferKind::Path, "gpt central"},
                                         {BufferKind::Path, "gpt neighbor right"},
                                         {BufferKind::Path, "gpt neighbor down"},
                                         {BufferKind::Path, "gpt neighbor left"},
                                         {BufferKind::Path, "gpt neighbor up"},
                                         {BufferKind::Path, "gpt gradient right"},
                                         {BufferKind::Path, "gpt gradient down"},
                                         {BufferKind::Path, "gpt gradient left"},
                                         {BufferKind::Path, "gpt gradient up"},
                                         {BufferKind::Path, "gpt direct"},
                                         visible};
        const auto demodulate = identity.find("demodulate");
        if (demodulate != identity.end() && demodulate->second == "on")
            roles.push_back({BufferKind::Path, "gpt modulation"});
        return roles;
    }
    throw Error(path + ": checkpoint of method '" + method->second + "', which gdpt does not know");
}

std::string pixelName(std::size_t i, int width) {
    const auto w = static_cast<std::size_t>(width);
    return "pixel (" + std::to_string(i % w) + ", " + std::to_string(i / w) + ")";
}

std::string countText(double n) {
    return std::to_string(static_cast<std::uint64_t>(n));
}

}  // namespace

namespace {

// The checkpoint's layers and header; `path` names the file in errors.
std::pair<std::vector<NamedLayer>, ExrAttributes> checkpointContents(const std::string& path,
                                                                     const ExrAttributes& identity,
                                                                     const ExrAttributes& info,
                                                                     const SamplerState& state) {
    const int w = state.preview.width(), h = state.preview.height();
    ExrAttributes attributes = {{"gdpt.format", kFormat},
                                {"gdpt.spp", std::to_string(state.spp)},
                                {"gdpt.next_batch", std::to_string(state.nextBatch)},
                                {"gdpt.batches", std::to_string(state.batches)},
                                {"gdpt.buffers", std::to_string(state.buffers.size())}};
    for (const auto& [key, value] : identity) attributes["gdpt.id." + key] = value;
    for (const auto& [key, value] : info) attributes["gdpt.info." + key] = value;
    std::vector<NamedLayer> layers = {{"", state.preview}};
    for (std::size_t k = 0; k < state.buffers.size(); ++k) {
        const auto& stats = state.buffers[k];
        if (stats.size() != state.preview.pixelCount())
            throw Error(path + ": statistics buffer " + std::to_string(k) + " does not match the image size");
        Image mean(w, h), m2(w, h), count(w, h);
        for (std::size_t i = 0; i < stats.size(); ++i)
            for (int c = 0; c < 3; ++c) {
                mean.plane(c)[i] = stats[i].mean[c];
                m2.plane(c)[i] = stats[i].m2[c];
                count.plane(c)[i] = static_cast<float>(stats[i].count);
            }
        layers.push_back({bufferLayer(k, "mean"), std::move(mean)});
        layers.push_back({bufferLayer(k, "m2"), std::move(m2)});
        layers.push_back({bufferLayer(k, "count"), std::move(count)});
    }
    return {std::move(layers), std::move(attributes)};
}

}  // namespace

void writeCheckpoint(const std::string& path, const ExrAttributes& identity, const ExrAttributes& info,
                     const SamplerState& state) {
    const auto [layers, attributes] = checkpointContents(path, identity, info, state);
    writeExr(path, layers, attributes);
}

void writeCheckpoint(const StagedFile& file, const ExrAttributes& identity, const ExrAttributes& info,
                     const SamplerState& state) {
    const auto [layers, attributes] = checkpointContents(file.path(), identity, info, state);
    writeExr(file, layers, attributes);
}

Checkpoint readCheckpoint(const std::string& path) {
    const ExrAttributes attributes = readExrAttributes(path);
    const auto format = attributes.find("gdpt.format");
    if (format == attributes.end())
        throw Error(path + ": not a gdpt checkpoint (no gdpt.format attribute; write one with --checkpoint)");
    if (format->second != kFormat)
        throw Error(path + ": checkpoint format '" + format->second + "' is not supported (expected " +
                    kFormat + ")");
    Checkpoint cp;
    SamplerState& s = cp.state;
    s.spp = parseCount(path, attributes, "gdpt.spp", kMaxSpp);
    s.nextBatch = parseCount(path, attributes, "gdpt.next_batch", kMaxSpp);
    s.batches = parseCount(path, attributes, "gdpt.batches", kMaxSpp);
    const std::uint32_t buffers = parseCount(path, attributes, "gdpt.buffers", kMaxBuffers);
    if (buffers == 0 || s.nextBatch == 0)
        throw Error(path + ": checkpoint has no statistics buffers or an empty next batch");
    for (const auto& [key, value] : attributes) {
        if (key.rfind("gdpt.id.", 0) == 0) cp.identity[key.substr(8)] = value;
        if (key.rfind("gdpt.info.", 0) == 0) cp.info[key.substr(10)] = value;
    }
    const std::vector<BufferRole> roles = bufferLayout(path, cp.identity);
    const std::string method = cp.identity.at("method");

    // The pixels of G-PT's edge samples hold edge_samples more samples per camera sample
    // (edge_pass.h). With "auto" the render's probe chose the factor (at most
    // kAutoEdgeSamplesMax): the first such pixel's count says which, and every other one must
    // have the same.
    const double spp = s.spp;
    double edgeCount = spp;
    bool edgeFactorOpen = false;
    if (attributes.count("gdpt.id.edge_samples")) {
        if (attributes.at("gdpt.id.edge_samples") == "auto")
            edgeFactorOpen = true;
        else
            edgeCount *= 1.0 + parseCount(path, attributes, "gdpt.id.edge_samples", kMaxEdgeSamples);
    }

    std::map<std::string, Image> layers;
    for (NamedLayer& layer : readExr(path)) layers[layer.name] = std::move(layer.image);
    const auto layer = [&](std::size_t k, const char* what) -> const Image& {
        const std::string name = bufferLayer(k, what);
        const auto it = layers.find(name);
        if (it == layers.end())
            throw Error(path + ": checkpoint layer '" + name + "' (" +
                        (k < roles.size() ? roles[k].name : "an extra buffer") + ") is missing");
        return it->second;
    };
    const auto preview = layers.find("");
    if (preview == layers.end()) throw Error(path + ": checkpoint layer '' (the preview image) is missing");
    s.preview = preview->second;
    // A buffer the header leaves out is named by its first layer (a pt checkpoint has 2,
    // a gpt one 11, or 12 with demodulation).
    if (buffers != roles.size()) {
        if (buffers < roles.size()) (void)layer(buffers, "mean");
        throw Error(path + ": checkpoint has " + std::to_string(buffers) +
                    " statistics buffers (gdpt.buffers), a " + method + " checkpoint has " +
                    std::to_string(roles.size()));
    }
    const int width = s.preview.width();
    const std::size_t pixels = s.preview.pixelCount();
    for (std::uint32_t k = 0; k < buffers; ++k) {
        const Image& mean = layer(k, "mean");
        const Image& m2 = layer(k, "m2");
        const Image& count = layer(k, "count");
        for (const Image* im : {&mean, &m2, &count})
            if (!im->sameSize(s.preview))
                throw Error(path + ": state " + std::to_string(k) + " (" + roles[k].name +
                            ") differs in size from the image");
        const std::string where = ": layer " + bufferLayer(k, "count") + " (" + roles[k].name + "): ";
        std::vector<gpu::PixelStats> stats(pixels);
        for (std::size_t i = 0; i < pixels; ++i) {
            const float n = count.plane(0)[i];
            if (!(n >= 0.0f && n == std::floor(n)) || count.plane(1)[i] != n || count.plane(2)[i] != n)
                throw Error(path + where + pixelName(i, width) + " has sample count " + std::to_string(n) +
                            ", expected a whole number, the same in R, G and B");
            // The counts the schedule allows (BufferKind); every path statistic of a pixel
            // counts what the first one (central, or PT's accumulation) counts.
            const double got = n;
            if (roles[k].kind == BufferKind::Visible) {
                if (got != 0.0 && got != spp)
                    throw Error(path + where + pixelName(i, width) + " has sample count " + countText(got) +
                                ", expected 0 or " + countText(spp) + " (gdpt.spp)");
            } else if (k == 0) {
                if (edgeFactorOpen && spp > 0 && got > spp && std::fmod(got, spp) == 0.0 &&
                    got / spp - 1.0 <= kAutoEdgeSamplesMax) {
                    edgeCount = got;
                    edgeFactorOpen = false;
                }
                if (got != spp && got != edgeCount)
                    throw Error(path + where + pixelName(i, width) + " has sample count " + countText(got) +
                                ", expected " + countText(spp) + " (gdpt.spp)" +
                                (edgeCount != spp
                                     ? " or " + countText(edgeCount) +
                                           " (gdpt.spp x (1 + edge_samples) in an edge-sample pixel)"
                                 : edgeFactorOpen ? " or gdpt.spp x (1 + K), K from 1 to " +
                                                        std::to_string(kAutoEdgeSamplesMax) +
                                                        " (edge_samples auto, in an edge-sample pixel)"
                                                  : std::string()));
            } else if (got != s.buffers[0][i].count) {
                throw Error(path + where + pixelName(i, width) + " has sample count " + countText(got) +
                            ", but " + bufferLayer(0, "count") + " has " +
                            std::to_string(s.buffers[0][i].count) +
                            " there (every path statistic of a pixel counts the same samples)");
            }
            stats[i].count = static_cast<std::uint32_t>(n);
            for (int c = 0; c < 3; ++c) {
                stats[i].mean[c] = mean.plane(c)[i];
                stats[i].m2[c] = m2.plane(c)[i];
                if (!std::isfinite(stats[i].mean[c]))
                    throw Error(path + ": layer " + bufferLayer(k, "mean") + " (" + roles[k].name +
                                "): " + pixelName(i, width) + " has a non-finite mean");
                // M2 is a sum of squared deviations: finite and >= 0.
                if (!(stats[i].m2[c] >= 0.0f) || !std::isfinite(stats[i].m2[c]))
                    throw Error(path + ": layer " + bufferLayer(k, "m2") + " (" + roles[k].name +
                                "): " + pixelName(i, width) + " has M2 " + std::to_string(stats[i].m2[c]) +
                                ", expected a finite value >= 0 (a sum of squared deviations)");
            }
            stats[i].pad = 0;
        }
        s.buffers.push_back(std::move(stats));
    }
    return cp;
}

void checkIdentity(const std::string& path, const ExrAttributes& recorded, const ExrAttributes& expected) {
    // The keys that name a cause first: another scene, method or size changes other keys
    // too (the largest batch depends on method and size), which would then be reported
    // instead. The rest in the map's order.
    std::vector<std::string> keys = {"scene_fingerprint", "method", "width", "height"};
    for (const auto& entry : expected)
        if (std::find(keys.begin(), keys.end(), entry.first) == keys.end()) keys.push_back(entry.first);
    // Differing values first: they name the cause (another method, say) better than a key
    // that only one of the two methods records.
    for (const std::string& key : keys) {
        const auto want = expected.find(key);
        const auto it = recorded.find(key);
        if (want != expected.end() && it != recorded.end() && it->second != want->second)
            throw Error(path + ": checkpoint was rendered with " + key + " " + it->second +
                        ", this render has " + key + " " + want->second + "; it cannot be resumed");
    }
    for (const std::string& key : keys) {
        const auto want = expected.find(key);
        if (want != expected.end() && !recorded.count(key))
            throw Error(path + ": checkpoint does not record " + key + " (this render: " + want->second +
                        ")");
    }
    for (const auto& [key, value] : recorded)
        if (!expected.count(key))
            throw Error(path + ": checkpoint records " + key + " " + value +
                        ", which this render does not have");
}

}  // namespace gdpt
