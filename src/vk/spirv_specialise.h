// spirv_specialise.h — a kernel's SPIR-V with its specialisation constants folded in before
// the driver sees it.
//
// Lavapipe's vkCreateComputePipelines inlines every function into the entry point and only
// then removes the code that the specialisation constants switch off, single-threaded: for
// G-PT's path kernel that is most of a render's set-up (bench/RESULTS.md, "Kernels specialised
// before the driver"). gdpt turns the constants into constants of their values, and SPIRV-Tools'
// optimizer folds what depends on them and removes the dead branches and code, which takes it
// a fraction of lavapipe's time on the same code; the result is kept on disk (util/cache_dir.h, spirv/), so
// a scene's kernels are specialised once per combination of constants. The driver then gets
// a module of the same meaning (the same image bits: tested) and about half the size.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <utility>
#include <vector>

namespace gdpt::vk {

struct DeviceInfo;

using SpecConstants = std::vector<std::pair<std::uint32_t, std::uint32_t>>;  // (id, 32-bit value)

// `words` with each constant of `constants` set to its value (bool constants: 0 = false),
// frozen and folded, and the code they make dead removed. The constants of `kept` stay
// specialisation constants (the pipeline still gives them their values); constants not listed
// in either keep their defaults, frozen as well. Throws gdpt::Error if the module is not
// SPIR-V or the optimizer fails (with its messages).
std::vector<std::uint32_t> specialiseSpirv(const std::uint32_t* words, std::size_t count,
                                           const SpecConstants& constants,
                                           const std::vector<std::uint32_t>& kept = {});

// What specialiseCached did.
enum class SpecialiseSource { Cache, Optimizer };

struct SpecialisedSpirv {
    std::vector<std::uint32_t> words;
    SpecialiseSource source = SpecialiseSource::Optimizer;
};

// specialiseSpirv through the cache in `directory` (empty: no cache). A file whose header does
// not match its name's key or whose words fail their checksum is ignored and rewritten; a
// directory that cannot be created or written costs the optimizer's time, nothing else.
SpecialisedSpirv specialiseCached(const std::uint32_t* words, std::size_t count,
                                  const SpecConstants& constants, const std::filesystem::path& directory,
                                  const std::vector<std::uint32_t>& kept = {});

// Kernels specialised so far in this process, by where their module came from.
struct SpecialiseCounts {
    std::uint64_t fromCache = 0;
    std::uint64_t byOptimizer = 0;
};
SpecialiseCounts specialiseCounts();

// The cache keeps at most this many modules (about 250 KB each for the G-PT kernel): past that,
// a write removes the least recently used (by modification time, which a read renews) down to
// three quarters of it.
constexpr std::size_t kSpecialiseCacheFiles = 256;

// The cache file of (words, constants) under `directory` (for tests and inspection).
std::filesystem::path specialisedCachePath(const std::uint32_t* words, std::size_t count,
                                           const SpecConstants& constants,
                                           const std::filesystem::path& directory,
                                           const std::vector<std::uint32_t>& kept = {});

// Kernels with at least this many words are specialised: a smaller kernel's pipeline takes
// lavapipe milliseconds, less than a cache lookup could save (bench/RESULTS.md).
constexpr std::size_t kSpecialiseMinWords = 8192;

// Whether this device's kernels are specialised by gdpt: on CPU devices (lavapipe 22.3 and 25
// create the G-PT pipeline in about 0.12-0.15 s less and run it as fast, with the traversal's
// register-stack constant left to the driver: KernelDesc::driverSpecConstants). Not on other
// devices, whose compilers fold the constants themselves and where it is not measured
// (bench/RESULTS.md, "Kernels specialised before the driver"). GDPT_SPECIALISE=on|off|auto
// overrides (util/env_choice.h).
bool useSpecialisedSpirv(const DeviceInfo& device);

}  // namespace gdpt::vk
