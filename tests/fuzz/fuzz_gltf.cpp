// fuzz_gltf.cpp — libFuzzer harness for the glTF loader. Any input must either load or
// throw gdpt::Error; a crash, hang, sanitizer report or other exception is a bug. The loader
// gets a small memory budget, so a scene it accepts is cheap by its own estimate: an
// allocation beyond scripts/fuzz.sh's -malloc_limit_mb, or memory beyond -rss_limit_mb,
// means something was materialised before it was checked (also a bug).
// Build: configure with clang and -DGDPT_FUZZ=ON (see tests/fuzz/README.md).
#include <cstdint>

#include "fuzz_input_file.h"
#include "scene/gltf_loader.h"
#include "util/error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    // The loader reads files (relative URIs resolve next to it); give it a private one.
    static const gdpt::fuzz::InputFile file("gdpt_fuzz_gltf", ".gltf");
    if (!file.write(data, size)) return 0;
    gdpt::LoadOptions options;
    options.memoryBudget = 64ull << 20;
    options.quiet = true;
    try {
        (void)gdpt::loadGltf(file.path(), options);
    } catch (const gdpt::Error&) {
        // The expected way to reject malformed input.
    }
    return 0;
}
