// fuzz_exr.cpp — libFuzzer harness for the EXR reader (gdpt solve/diff/converge read EXRs
// from users and other renderers). Any input must either load or throw gdpt::Error.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "image/exr_io.h"
#include "util/error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const std::string path = "/tmp/gdpt_fuzz_exr_" + std::to_string(getpid()) + ".exr";
    FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) return 0;
    std::fwrite(data, 1, size, f);
    std::fclose(f);
    try {
        (void)gdpt::readExr(path);
    } catch (const gdpt::Error&) {
    }
    return 0;
}
