// checkpoint.cpp — the gdpt-checkpoint-1 EXR layout (see checkpoint.h).
#include "integrator/checkpoint.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <map>

#include "render/passes/edge_options.h"
#include "util/error.h"

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

}  // namespace

void writeCheckpoint(const std::string& path, const ExrAttributes& identity, const ExrAttributes& info,
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
    writeExr(path, layers, attributes);
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

    // G-PT's edge pixels hold edge_samples more samples per camera sample (edge_pass.h).
    double maxCount = s.spp;
    if (attributes.count("gdpt.id.edge_samples"))
        maxCount *= 1.0 + parseCount(path, attributes, "gdpt.id.edge_samples", kMaxEdgeSamples);

    std::map<std::string, Image> layers;
    for (NamedLayer& layer : readExr(path)) layers[layer.name] = std::move(layer.image);
    const auto layer = [&](const std::string& name) -> const Image& {
        const auto it = layers.find(name);
        if (it == layers.end()) throw Error(path + ": checkpoint layer '" + name + "' is missing");
        return it->second;
    };
    s.preview = layer("");
    for (std::uint32_t k = 0; k < buffers; ++k) {
        const Image& mean = layer(bufferLayer(k, "mean"));
        const Image& m2 = layer(bufferLayer(k, "m2"));
        const Image& count = layer(bufferLayer(k, "count"));
        std::vector<gpu::PixelStats> stats(mean.pixelCount());
        for (std::size_t i = 0; i < stats.size(); ++i) {
            const float n = count.plane(0)[i];
            if (!(n >= 0.0f && double(n) <= maxCount && n == std::floor(n)) || count.plane(1)[i] != n ||
                count.plane(2)[i] != n)
                throw Error(path + ": layer " + bufferLayer(k, "count") + ": pixel " + std::to_string(i) +
                            " has sample count " + std::to_string(n) + ", expected a whole number <= " +
                            std::to_string(static_cast<std::uint64_t>(maxCount)) +
                            (maxCount == s.spp ? " (gdpt.spp)" : " (gdpt.spp x (1 + edge_samples))"));
            stats[i].count = static_cast<std::uint32_t>(n);
            for (int c = 0; c < 3; ++c) {
                stats[i].mean[c] = mean.plane(c)[i];
                stats[i].m2[c] = m2.plane(c)[i];
                if (!std::isfinite(stats[i].mean[c]) || !std::isfinite(stats[i].m2[c]))
                    throw Error(path + ": state " + std::to_string(k) + ": pixel " + std::to_string(i) +
                                " has a non-finite mean or M2");
            }
            stats[i].pad = 0;
        }
        s.buffers.push_back(std::move(stats));
    }
    return cp;
}

void checkIdentity(const std::string& path, const ExrAttributes& recorded, const ExrAttributes& expected) {
    // Differing values first: they name the cause (another method, say) better than a key
    // that only one of the two methods records.
    for (const auto& [key, value] : expected) {
        const auto it = recorded.find(key);
        if (it != recorded.end() && it->second != value)
            throw Error(path + ": checkpoint was rendered with " + key + " " + it->second +
                        ", this render has " + key + " " + value + "; it cannot be resumed");
    }
    for (const auto& [key, value] : expected)
        if (!recorded.count(key))
            throw Error(path + ": checkpoint does not record " + key + " (this render: " + value + ")");
    for (const auto& [key, value] : recorded)
        if (!expected.count(key))
            throw Error(path + ": checkpoint records " + key + " " + value +
                        ", which this render does not have");
}

}  // namespace gdpt
