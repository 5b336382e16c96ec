#include "distributed/shards.h"

#include <algorithm>
#include <optional>

#include "integrator/checkpoint.h"
#include "integrator/stats_merge.h"
#include "util/error.h"
#include "util/interrupt.h"
#include "util/timer.h"

namespace gdpt {
namespace {

struct Shard {
    std::string path;
    SampleShare part;
    Checkpoint checkpoint;
};

// The first difference between two renders' identities (the part aside), as
// "key a (b in other)", or "".
std::string identityDifference(const ExrAttributes& a, const ExrAttributes& b, const std::string& other) {
    for (const auto& [key, value] : b) {
        if (key == "share") continue;
        const auto it = a.find(key);
        if (it == a.end()) return key + " (none; " + value + " in " + other + ")";
        if (it->second != value) return key + " " + it->second + " (" + value + " in " + other + ")";
    }
    for (const auto& [key, value] : a)
        if (key != "share" && !b.count(key)) return key + " " + value + " (none in " + other + ")";
    return "";
}

std::uint32_t renderSpp(const Shard& s) {
    const auto it = s.checkpoint.info.find("render_spp");
    if (it == s.checkpoint.info.end())
        throw Error(s.path + ": shard does not record its render's spp (attribute gdpt.info.render_spp)");
    try {
        return static_cast<std::uint32_t>(std::stoul(it->second));
    } catch (const std::exception&) {
        throw Error(s.path + ": gdpt.info.render_spp '" + it->second + "' is not a number");
    }
}

}  // namespace

MergedShards mergeShards(const std::vector<std::string>& paths) {
    if (paths.empty()) throw UsageError("no shard files to merge");
    std::vector<Shard> shards;
    for (const std::string& path : paths) {
        throwIfInterrupted("reading the shards");
        Shard s{path, {}, readCheckpoint(path)};
        const auto share = s.checkpoint.identity.find("share");
        if (share == s.checkpoint.identity.end())
            throw Error(path +
                        ": not a shard (a checkpoint of a whole render; write shards with gdpt render "
                        "--shard I/N)");
        try {
            s.part = parseSampleShare(share->second, "gdpt.id.share");
        } catch (const UsageError& e) {
            throw Error(path + ": " + e.what());
        }
        shards.push_back(std::move(s));
    }
    const Shard& first = shards.front();
    const std::uint32_t parts = first.part.count;
    const std::uint32_t spp = renderSpp(first);
    for (const Shard& s : shards) {
        if (s.part.count != parts)
            throw Error(s.path + " is part " + s.part.text() + " of a render in " +
                        std::to_string(s.part.count) + " parts, " + first.path + " is part " +
                        first.part.text() + ": they belong to different renders");
        if (const std::string d =
                identityDifference(s.checkpoint.identity, first.checkpoint.identity, first.path);
            !d.empty())
            throw Error(s.path + " belongs to another render than " + first.path + ": " + d);
        if (renderSpp(s) != spp)
            throw Error(s.path + " is a part of a " + std::to_string(renderSpp(s)) + "-spp render, " +
                        first.path + " of a " + std::to_string(spp) + "-spp render");
    }
    // Part order (`first`, a reference into the vector, is not used past this point).
    std::sort(shards.begin(), shards.end(),
              [](const Shard& a, const Shard& b) { return a.part.index < b.part.index; });
    std::string missing;
    std::uint32_t missingCount = 0;
    std::size_t next = 0;
    for (std::uint32_t i = 0; i < parts; ++i) {
        if (next < shards.size() && shards[next].part.index == i) {
            if (next + 1 < shards.size() && shards[next + 1].part.index == i)
                throw Error(shards[next + 1].path + " and " + shards[next].path + " are both part " +
                            shards[next].part.text() + " (each part is merged once)");
            ++next;
            continue;
        }
        if (++missingCount <= 8) missing += (missing.empty() ? "" : ", ") + SampleShare{i, parts}.text();
    }
    if (missingCount > 0)
        throw Error(std::to_string(missingCount) + " of the " + std::to_string(parts) +
                    " parts are missing: " + missing + (missingCount > 8 ? ", ..." : "") +
                    " (render them with gdpt render --shard I/" + std::to_string(parts) + ")");
    for (const Shard& s : shards)
        if (spp > 0 && s.checkpoint.state.spp != s.part.localSpp(spp))
            throw Error(s.path + " has " + std::to_string(s.checkpoint.state.spp) + " spp; part " +
                        s.part.text() + " of a " + std::to_string(spp) + "-spp render takes " +
                        std::to_string(s.part.localSpp(spp)) +
                        " (an interrupted shard? resume it with --resume)");

    MergedShards out;
    Timer timer;
    const Shard& part0 = shards.front();
    out.identity = part0.checkpoint.identity;
    out.identity.erase("share");
    out.info = part0.checkpoint.info;
    out.stats.parts = parts;
    for (const auto& b : part0.checkpoint.state.buffers)
        out.stats.bytesPerPart += b.size() * sizeof(gpu::PixelStats);
    out.state = std::move(shards.front().checkpoint.state);
    out.stats.partSpp = {out.state.spp};
    for (std::size_t i = 1; i < shards.size(); ++i) {
        throwIfInterrupted("merging the shards");
        mergeStateInto(out.state, shards[i].checkpoint.state);
        out.stats.partSpp.push_back(shards[i].checkpoint.state.spp);
    }
    out.stats.mergeMs = timer.ms();
    return out;
}

}  // namespace gdpt
