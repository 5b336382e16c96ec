// edge_samples_option.h — `--edge-samples auto|K` of `gdpt render` and `gdpt converge`
// (render/passes/edge_options.h holds the rule).
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "render/passes/edge_options.h"
#include "util/error.h"

namespace gdpt {

inline constexpr const char* kEdgeSamplesHelp =
    "G-PT: extra camera samples per camera sample in the pixels a geometric edge crosses and their "
    "four neighbours: auto (2, fewer where those pixels are more than 30 % of the image: "
    "floor(0.6 / their share), so that they add at most about 60 % to a sample pass), or 0 to 64 "
    "(0 = off)";

// Accepts what parseEdgeSamples accepts.
inline CLI::Validator edgeSamplesValidator() {
    return CLI::Validator(
        [](std::string& text) -> std::string {
            try {
                (void)parseEdgeSamples(text, "value");
            } catch (const Error&) {
                return edgeSamplesRefusal(text);
            }
            return {};
        },
        "auto|0..64");
}

}  // namespace gdpt
