#include "vk/spirv_specialise.h"

#include <spirv-tools/libspirv.h>

#include <algorithm>
#include <atomic>
#include <exception>
#include <fstream>
#include <spirv-tools/optimizer.hpp>
#include <string>
#include <system_error>
#include <unordered_map>

#include "util/env_choice.h"
#include "util/error.h"
#include "util/fnv1a.h"
#include "util/output_files.h"
#include "vk/context.h"

namespace gdpt::vk {
namespace {

// After the constants are frozen (freezeConstants), the passes fold the expressions of
// constants (OpSpecConstantOp) and merge equal constants, then drop the branches whose
// conditions became constant, the blocks and code left dead, and the functions no longer
// called. A change here or in freezeConstants changes kPassesTag, part of every cache key.
constexpr const char* kPassesTag =
    "freeze-except,fold,unify,dead-branches,merge-blocks,adce,dead-functions;v2";

std::atomic<std::uint64_t> gFromCache{0}, gByOptimizer{0};

std::uint64_t cacheKey(const std::uint32_t* words, std::size_t count, const SpecConstants& constants,
                       const std::vector<std::uint32_t>& kept) {
    Fnv1a h;
    h.text(kPassesTag);
    h.text(spvSoftwareVersionDetailsString());
    h.value(std::uint64_t{count});  // as Fnv1a::vector, without copying the words
    h.bytes(words, count * sizeof(std::uint32_t));
    for (const auto& [id, value] : constants) {
        h.value(id);
        h.value(value);
    }
    h.vector(kept);
    return h.hash();
}

// The checksum of a cached module's words.
std::uint64_t checksum(const std::vector<std::uint32_t>& words) {
    Fnv1a h;
    h.bytes(words.data(), words.size() * sizeof(std::uint32_t));
    return h.hash();
}

// A cache file: this header, then the specialised module's words.
struct CacheHeader {
    std::uint32_t magic = 0x43534447u;  // "GDSC"
    std::uint32_t version = 1u;
    std::uint64_t key = 0;       // cacheKey of the input (also the file's name)
    std::uint64_t words = 0;     // the module's length in words
    std::uint64_t checksum = 0;  // checksum() of the module's words
};

std::filesystem::path cachePath(const std::filesystem::path& directory, std::uint64_t key) {
    return directory / "spirv" / (hex(key) + ".spv");
}

// The cached module, or nothing if the file is missing, short, or not what the key names.
std::vector<std::uint32_t> readCached(const std::filesystem::path& path, std::uint64_t key) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return {};
    CacheHeader h;
    if (!in.read(reinterpret_cast<char*>(&h), sizeof h)) return {};
    const CacheHeader expected;
    if (h.magic != expected.magic || h.version != expected.version || h.key != key || h.words < 5 ||
        h.words > (std::uint64_t{1} << 26))
        return {};
    std::vector<std::uint32_t> words(static_cast<std::size_t>(h.words));
    if (!in.read(reinterpret_cast<char*>(words.data()),
                 static_cast<std::streamsize>(words.size() * sizeof(std::uint32_t))))
        return {};
    if (in.peek() != std::ifstream::traits_type::eof()) return {};  // trailing bytes
    if (checksum(words) != h.checksum) return {};
    if (words[0] != 0x07230203u) return {};  // SPIR-V's magic number
    return words;
}

void evictOldest(const std::filesystem::path& folder) {
    namespace fs = std::filesystem;
    std::error_code ec;
    std::vector<std::pair<fs::file_time_type, fs::path>> files;
    for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
        if (it->path().extension() != ".spv") continue;
        const fs::file_time_type t = it->last_write_time(ec);
        if (!ec) files.emplace_back(t, it->path());
    }
    if (files.size() <= kSpecialiseCacheFiles) return;
    std::sort(files.begin(), files.end());
    const std::size_t remove = files.size() - kSpecialiseCacheFiles * 3 / 4;
    for (std::size_t i = 0; i < remove; ++i) fs::remove(files[i].second, ec);
}

// Writes the module under its key, staged and renamed (concurrent runs each write a whole
// file); any failure leaves the cache as it was.
void writeCached(const std::filesystem::path& path, std::uint64_t key,
                 const std::vector<std::uint32_t>& words) {
    try {
        std::error_code ec;
        std::filesystem::create_directories(path.parent_path(), ec);
        if (ec) return;
        CacheHeader h;
        h.key = key;
        h.words = words.size();
        h.checksum = checksum(words);
        std::string bytes(reinterpret_cast<const char*>(&h), sizeof h);
        bytes.append(reinterpret_cast<const char*>(words.data()), words.size() * sizeof(std::uint32_t));
        StagedFile file(path.string());
        writeBytes(file.tmpPath(), bytes.data(), bytes.size());
        file.commit();
        evictOldest(path.parent_path());
    } catch (const std::exception&) {
        // An unwritable cache costs the next run the optimizer's time, nothing else.
    }
}

// SPIR-V opcodes and the decoration this file rewrites.
constexpr std::uint32_t kOpDecorate = 71, kDecorationSpecId = 1;
constexpr std::uint32_t kOpConstantTrue = 41, kOpConstantFalse = 42, kOpConstant = 43;
constexpr std::uint32_t kOpSpecConstantTrue = 48, kOpSpecConstantFalse = 49, kOpSpecConstant = 50;

// The module with every specialisation constant but those of `kept` turned into a constant:
// its value from `constants`, else its default; its SpecId decoration removed. (SPIRV-Tools'
// freeze pass freezes all of them.)
std::vector<std::uint32_t> freezeConstants(const std::uint32_t* words, std::size_t count,
                                           const SpecConstants& constants,
                                           const std::vector<std::uint32_t>& kept) {
    if (count < 5 || words[0] != 0x07230203u)
        throw Error("specialising a kernel's SPIR-V failed: not a SPIR-V module");
    // An instruction's word count, checked against the module's end.
    const auto length = [&](std::size_t i) {
        const std::uint32_t n = words[i] >> 16;
        if (n == 0 || i + n > count)
            throw Error("specialising a kernel's SPIR-V failed: a truncated instruction at word " +
                        std::to_string(i));
        return n;
    };
    std::unordered_map<std::uint32_t, std::uint32_t> specIdOf;  // result id -> SpecId
    for (std::size_t i = 5; i < count; i += length(i))
        if ((words[i] & 0xFFFFu) == kOpDecorate && (words[i] >> 16) >= 4 && words[i + 2] == kDecorationSpecId)
            specIdOf[words[i + 1]] = words[i + 3];
    // The SpecId of a result id that is to be frozen, if it is one.
    const auto frozenSpecId = [&](std::uint32_t result) -> const std::uint32_t* {
        const auto it = specIdOf.find(result);
        if (it == specIdOf.end() || std::find(kept.begin(), kept.end(), it->second) != kept.end())
            return nullptr;
        return &it->second;
    };
    const auto givenValue = [&](std::uint32_t specId) -> const std::uint32_t* {
        for (const auto& c : constants)
            if (c.first == specId) return &c.second;
        return nullptr;
    };
    std::vector<std::uint32_t> out(words, words + 5);
    out.reserve(count);
    for (std::size_t i = 5; i < count;) {
        const std::uint32_t n = length(i), op = words[i] & 0xFFFFu;
        if (op == kOpDecorate && n >= 4 && words[i + 2] == kDecorationSpecId && frozenSpecId(words[i + 1])) {
            i += n;  // a constant has no SpecId
            continue;
        }
        const std::uint32_t* spec =
            (op == kOpSpecConstantTrue || op == kOpSpecConstantFalse || op == kOpSpecConstant) && n >= 3
                ? frozenSpecId(words[i + 2])
                : nullptr;
        if (spec) {
            const std::uint32_t* given = givenValue(*spec);
            if (op == kOpSpecConstant) {
                if (given && n != 4)
                    throw Error("specialising a kernel's SPIR-V failed: constant " + std::to_string(*spec) +
                                " is not 32 bits wide");
                out.push_back((n << 16) | kOpConstant);
                out.insert(out.end(), words + i + 1, words + i + n);
                if (given) out.back() = *given;
            } else {
                const bool value = given ? *given != 0 : op == kOpSpecConstantTrue;
                out.push_back((3u << 16) | (value ? kOpConstantTrue : kOpConstantFalse));
                out.push_back(words[i + 1]);
                out.push_back(words[i + 2]);
            }
        } else {
            out.insert(out.end(), words + i, words + i + n);
        }
        i += n;
    }
    return out;
}

}  // namespace

std::vector<std::uint32_t> specialiseSpirv(const std::uint32_t* words, std::size_t count,
                                           const SpecConstants& constants,
                                           const std::vector<std::uint32_t>& kept) {
    const std::vector<std::uint32_t> frozen = freezeConstants(words, count, constants, kept);
    spvtools::Optimizer optimizer(SPV_ENV_VULKAN_1_2);
    std::string messages;
    optimizer.SetMessageConsumer(
        [&messages](spv_message_level_t level, const char*, const spv_position_t&, const char* message) {
            if (level <= SPV_MSG_ERROR) messages += std::string("\n  ") + message;
        });
    optimizer.RegisterPass(spvtools::CreateFoldSpecConstantOpAndCompositePass())
        .RegisterPass(spvtools::CreateUnifyConstantPass())
        .RegisterPass(spvtools::CreateDeadBranchElimPass())
        .RegisterPass(spvtools::CreateBlockMergePass())
        .RegisterPass(spvtools::CreateAggressiveDCEPass())
        .RegisterPass(spvtools::CreateEliminateDeadFunctionsPass());
    // The input comes from this build's shader compiler and spirv-opt, validated by their
    // runs (and by the validation layers in the tests); validating it again here would take
    // as long as the passes.
    spvtools::OptimizerOptions options;
    options.set_run_validator(false);
    std::vector<std::uint32_t> out;
    bool ok = false;
    try {
        ok = optimizer.Run(frozen.data(), frozen.size(), &out, options);
    } catch (const std::exception& e) {
        // Without its validator SPIRV-Tools may throw on a malformed module (a truncated one
        // threw std::out_of_range from a map lookup) rather than report it.
        messages += std::string("\n  ") + e.what();
    }
    if (!ok)
        throw Error("specialising a kernel's SPIR-V failed:" +
                    (messages.empty() ? std::string(" (no message)") : messages));
    return out;
}

std::filesystem::path specialisedCachePath(const std::uint32_t* words, std::size_t count,
                                           const SpecConstants& constants,
                                           const std::filesystem::path& directory,
                                           const std::vector<std::uint32_t>& kept) {
    return cachePath(directory, cacheKey(words, count, constants, kept));
}

SpecialisedSpirv specialiseCached(const std::uint32_t* words, std::size_t count,
                                  const SpecConstants& constants, const std::filesystem::path& directory,
                                  const std::vector<std::uint32_t>& kept) {
    SpecialisedSpirv result;
    if (directory.empty()) {
        result.words = specialiseSpirv(words, count, constants, kept);
        ++gByOptimizer;
        return result;
    }
    const std::uint64_t key = cacheKey(words, count, constants, kept);
    const std::filesystem::path path = cachePath(directory, key);
    result.words = readCached(path, key);
    if (!result.words.empty()) {
        std::error_code ec;  // marks it used for the eviction; a failure does not matter
        std::filesystem::last_write_time(path, std::filesystem::file_time_type::clock::now(), ec);
        result.source = SpecialiseSource::Cache;
        ++gFromCache;
        return result;
    }
    result.words = specialiseSpirv(words, count, constants, kept);
    ++gByOptimizer;
    writeCached(path, key, result.words);
    return result;
}

SpecialiseCounts specialiseCounts() {
    return {gFromCache.load(), gByOptimizer.load()};
}

bool useSpecialisedSpirv(const DeviceInfo& device) {
    return envChoice("GDPT_SPECIALISE", "off", "on", device.isCpu);
}

}  // namespace gdpt::vk
