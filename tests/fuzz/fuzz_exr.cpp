// fuzz_exr.cpp — libFuzzer harness for the EXR reader (gdpt solve/diff/converge read EXRs
// from users and other renderers). Any input must either load or throw gdpt::Error.
#include <cstdint>

#include "fuzz_input_file.h"
#include "image/exr_io.h"
#include "util/error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const gdpt::fuzz::InputFile file("gdpt_fuzz_exr", ".exr");
    if (!file.write(data, size)) return 0;
    try {
        (void)gdpt::readExr(file.path());
    } catch (const gdpt::Error&) {
    }
    return 0;
}
