// exr_io.cpp — OpenEXR 3.1 reader/writer for named RGB layers.
#include "image/exr_io.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStdIO.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfThreading.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <thread>

#include "image/atomic_write.h"
#include "util/error.h"
#include "util/output_files.h"

namespace gdpt {
namespace {

// ": <the OS's reason>" when the last failed call set errno, else nothing.
std::string osReason() {
    return errno != 0 ? std::string(": ") + std::strerror(errno) : std::string();
}

// Refuse absurd data windows before allocating: a corrupt header must produce an error,
// not a multi-gigabyte allocation. 2^27 pixels = 1.5 GiB per RGB float layer.
constexpr std::int64_t kMaxPixels = std::int64_t{1} << 27;

std::string channelPrefix(const std::string& layer) {
    return layer.empty() ? "" : layer + ".";
}

// Channels of one layer found in the file, keyed by their suffix (R, G, B, Y).
struct LayerChannels {
    std::map<std::string, std::string> bySuffix;  // suffix -> full channel name
};

// Worker threads for OpenEXR's ZIP (de)compression of line blocks: one per core, so a
// G-PT result (a dozen RGB float layers) is not compressed on one core while the other idles.
int exrThreads() {
    static const int threads = [] {
        const int n = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
        Imf::setGlobalThreadCount(n);
        return n;
    }();
    return threads;
}

void writeLayers(const std::string& tmpPath, const std::vector<NamedLayer>& layers,
                 const ExrAttributes& attributes) {
    const int width = layers.front().image.width();
    const int height = layers.front().image.height();
    Imf::Header header(width, height);
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const auto& [name, value] : attributes) header.insert(name, Imf::StringAttribute(value));
    Imf::FrameBuffer frameBuffer;
    static const char* const kSuffix[3] = {"R", "G", "B"};
    const std::size_t xStride = sizeof(float);
    const std::size_t yStride = sizeof(float) * static_cast<std::size_t>(width);
    for (const NamedLayer& layer : layers) {
        for (int c = 0; c < 3; ++c) {
            const std::string name = channelPrefix(layer.name) + kSuffix[c];
            header.channels().insert(name, Imf::Channel(Imf::FLOAT));
            // OpenEXR's Slice takes a non-const pointer but only reads it when writing.
            char* base = reinterpret_cast<char*>(const_cast<float*>(layer.image.plane(c).data()));
            frameBuffer.insert(name, Imf::Slice(Imf::FLOAT, base, xStride, yStride));
        }
    }
    // We own the std::ofstream so that errors OpenEXR swallows in OutputFile's destructor
    // (it writes the line-offset table there and cannot throw) still show up as a failed
    // stream state, checked after the OutputFile is gone.
    errno = 0;
    std::ofstream os(tmpPath, std::ios::binary | std::ios::trunc);
    if (!os) throw Error("cannot open " + tmpPath + " for writing" + osReason());
    {
        Imf::StdOFStream stream(os, tmpPath.c_str());
        Imf::OutputFile file(stream, header, exrThreads());
        file.setFrameBuffer(frameBuffer);
        file.writePixels(height);
    }
    os.flush();
    if (!os) throw Error("write error on " + tmpPath + osReason());
    os.close();
    if (os.fail()) throw Error("cannot close " + tmpPath + osReason());
}

void validateLayers(const std::vector<NamedLayer>& layers) {
    if (layers.empty()) throw Error("no layers to write");
    std::set<std::string> names;
    for (const NamedLayer& layer : layers) {
        if (layer.image.empty()) throw Error("layer '" + layer.name + "' is empty");
        if (!layer.image.sameSize(layers.front().image))
            throw Error("layer '" + layer.name + "' is " + std::to_string(layer.image.width()) + "x" +
                        std::to_string(layer.image.height()) + ", expected " +
                        std::to_string(layers.front().image.width()) + "x" +
                        std::to_string(layers.front().image.height()));
        if (!names.insert(layer.name).second) throw Error("duplicate layer name '" + layer.name + "'");
    }
}

// Groups channel names by layer: "diffuse.R" -> layer "diffuse", suffix "R"; "R" -> "".
std::map<std::string, LayerChannels> groupChannels(const Imf::ChannelList& channels,
                                                   const std::string& path) {
    std::map<std::string, LayerChannels> groups;
    for (auto it = channels.begin(); it != channels.end(); ++it) {
        const std::string full = it.name();
        if (it.channel().xSampling != 1 || it.channel().ySampling != 1)
            throw Error(path + ": channel '" + full + "' is subsampled, which is not supported");
        const std::size_t dot = full.rfind('.');
        const std::string layer = dot == std::string::npos ? "" : full.substr(0, dot);
        const std::string suffix = dot == std::string::npos ? full : full.substr(dot + 1);
        groups[layer].bySuffix[suffix] = full;
    }
    return groups;
}

std::vector<NamedLayer> readLayers(const std::string& path) {
    Imf::InputFile file(path.c_str(), exrThreads());
    const Imf::Header& header = file.header();
    const Imath::Box2i dataWindow = header.dataWindow();
    const std::int64_t width = std::int64_t{dataWindow.max.x} - dataWindow.min.x + 1;
    const std::int64_t height = std::int64_t{dataWindow.max.y} - dataWindow.min.y + 1;
    if (width <= 0 || height <= 0) throw Error(path + ": empty data window");
    if (width * height > kMaxPixels)
        throw Error(path + ": data window " + std::to_string(width) + "x" + std::to_string(height) +
                    " is too large");

    std::vector<NamedLayer> layers;
    Imf::FrameBuffer frameBuffer;
    const std::size_t xStride = sizeof(float);
    const std::size_t yStride = sizeof(float) * static_cast<std::size_t>(width);
    std::vector<bool> grayOnly;
    const auto groups = groupChannels(header.channels(), path);
    layers.reserve(groups.size());  // the slices point into these images: no reallocation
    for (const auto& [name, group] : groups) {
        const auto& ch = group.bySuffix;
        const bool hasRgb = ch.count("R") || ch.count("G") || ch.count("B");
        const bool hasY = ch.count("Y") > 0;
        if (!hasRgb && !hasY) continue;
        layers.push_back({name, Image(static_cast<int>(width), static_cast<int>(height))});
        Image& image = layers.back().image;
        grayOnly.push_back(!hasRgb);
        static const char* const kSuffix[3] = {"R", "G", "B"};
        for (int c = 0; c < 3; ++c) {
            const std::string suffix = hasRgb ? kSuffix[c] : "Y";
            if (!hasRgb && c > 0) break;  // Y goes into plane 0, copied below
            // A channel missing from the file is filled with 0 by OpenEXR (fillValue).
            frameBuffer.insert(
                channelPrefix(name) + suffix,
                Imf::Slice::Make(Imf::FLOAT, image.plane(c).data(), dataWindow, xStride, yStride));
        }
    }
    if (layers.empty()) throw Error(path + ": no R, G, B or Y channels");
    file.setFrameBuffer(frameBuffer);
    file.readPixels(dataWindow.min.y, dataWindow.max.y);
    for (std::size_t i = 0; i < layers.size(); ++i) {
        if (!grayOnly[i]) continue;
        layers[i].image.plane(1) = layers[i].image.plane(0);
        layers[i].image.plane(2) = layers[i].image.plane(0);
    }
    return layers;
}

}  // namespace

void writeExr(const std::string& path, const std::vector<NamedLayer>& layers) {
    writeExr(path, layers, ExrAttributes{});
}

void writeExr(const std::string& path, const std::vector<NamedLayer>& layers,
              const ExrAttributes& attributes) {
    try {
        validateLayers(layers);
    } catch (const Error& e) {
        throw e.withContext(path);
    }
    writeFileAtomically(path, [&](const std::string& tmpPath) { writeLayers(tmpPath, layers, attributes); });
}

void writeExr(const StagedFile& file, const std::vector<NamedLayer>& layers,
              const ExrAttributes& attributes) {
    try {
        validateLayers(layers);
    } catch (const Error& e) {
        throw e.withContext(file.path());
    }
    writeStaged(file, [&](const std::string& tmpPath) { writeLayers(tmpPath, layers, attributes); });
}

void writeExr(const std::string& path, const Image& image) {
    writeExr(path, std::vector<NamedLayer>{{"", image}});
}

std::vector<NamedLayer> readExr(const std::string& path) {
    try {
        return readLayers(path);
    } catch (const Error&) {
        throw;  // already names the file
    } catch (const std::exception& e) {
        // Iex exceptions from OpenEXR (truncated data, bad magic, ...), bad_alloc, etc.
        throw Error(path + ": cannot read EXR: " + e.what());
    } catch (...) {
        throw Error(path + ": cannot read EXR: unknown error");
    }
}

ExrAttributes readExrAttributes(const std::string& path) {
    try {
        Imf::InputFile file(path.c_str());
        ExrAttributes out;
        for (auto it = file.header().begin(); it != file.header().end(); ++it)
            if (const auto* text = dynamic_cast<const Imf::StringAttribute*>(&it.attribute()))
                out[it.name()] = text->value();
        return out;
    } catch (const std::exception& e) {
        throw Error(path + ": cannot read EXR: " + e.what());
    }
}

Image readExrLayer(const std::string& path, const std::string& name) {
    std::vector<NamedLayer> layers = readExr(path);
    std::string available;
    for (NamedLayer& layer : layers) {
        if (layer.name == name) return std::move(layer.image);
        available += (available.empty() ? "'" : ", '") + layer.name + "'";
    }
    throw Error(path + ": no layer '" + name + "' (available: " + available + ")");
}

}  // namespace gdpt
