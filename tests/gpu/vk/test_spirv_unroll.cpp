// test_spirv_unroll.cpp — the loops the path kernels mark [[unroll]] (the loops over the four
// offsets, a wide node's four children) are unrolled in the build's spirv-opt form, which
// lavapipe before Mesa 23 gets, so that its NIR optimisation loop does not unroll them one
// nesting level per round (cmake/GdptSpirvEmbed.cmake; bench/RESULTS.md, "Offset loops
// unrolled before the driver"). spirv-opt leaves a marked loop as it is, mark included, when it
// cannot unroll it (a `continue` or a second exit in its body): these tests fail then.
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "gpt.spv.h"
#include "gpt_split.spv.h"
#include "gpt_split_units.spv.h"
#include "gpt_units.spv.h"
#include "mlt.spv.h"
#include "mlt_split.spv.h"
#include "mlt_split_units.spv.h"
#include "mlt_units.spv.h"
#include "spirv_words.h"

namespace gdpt {
namespace {

constexpr std::uint32_t kOpLoopMerge = 246;
constexpr std::uint32_t kLoopControlUnroll = 0x1;

struct Module {
    std::string name;
    std::vector<std::uint32_t> raw;
    std::vector<std::uint32_t> opt;
};

template <std::size_t R, std::size_t O>
Module module(const char* name, const std::uint32_t (&raw)[R], const std::uint32_t (&opt)[O]) {
    return {name, std::vector<std::uint32_t>(raw, raw + R), std::vector<std::uint32_t>(opt, opt + O)};
}

std::vector<Module> modules() {
    return {module("gpt", kSpv_gpt, kSpv_gpt_opt),
            module("gpt_units", kSpv_gpt_units, kSpv_gpt_units_opt),
            module("gpt_split", kSpv_gpt_split, kSpv_gpt_split_opt),
            module("gpt_split_units", kSpv_gpt_split_units, kSpv_gpt_split_units_opt),
            module("mlt", kSpv_mlt, kSpv_mlt_opt),
            module("mlt_units", kSpv_mlt_units, kSpv_mlt_units_opt),
            module("mlt_split", kSpv_mlt_split, kSpv_mlt_split_opt),
            module("mlt_split_units", kSpv_mlt_split_units, kSpv_mlt_split_units_opt)};
}

// The structured loops of a module that carry the Unroll control.
std::size_t markedLoops(const std::vector<std::uint32_t>& words) {
    std::size_t marked = 0;
    test::forEachSpirvInstruction(words, [&](std::uint32_t op, const std::uint32_t* in, std::uint32_t count) {
        if (op == kOpLoopMerge && count >= 4 && (in[3] & kLoopControlUnroll) != 0) ++marked;
    });
    return marked;
}

TEST(SpirvUnroll, TheKernelsMarkTheirOffsetLoops) {
    // The marks are in the source: glslang's form carries them (which is also what a driver
    // that unrolls by itself gets).
    for (const Module& m : modules()) EXPECT_GT(markedLoops(m.raw), 0u) << m.name;
}

TEST(SpirvUnroll, TheOptimisedFormsHoldNoMarkedLoop) {
    for (const Module& m : modules()) {
        if (m.opt == m.raw) GTEST_SKIP() << "built without spirv-opt (GDPT_SPIRV_OPT=OFF)";
        EXPECT_EQ(markedLoops(m.opt), 0u) << m.name << ": a loop marked [[unroll]] was left rolled";
    }
}

}  // namespace
}  // namespace gdpt
