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

// Structured loops of a module: how many, and how many of them carry the Unroll control.
struct LoopCount {
    std::size_t loops = 0;
    std::size_t marked = 0;
};

LoopCount countLoops(const std::vector<std::uint32_t>& words) {
    LoopCount c;
    for (std::size_t i = 5; i < words.size();) {
        const std::uint32_t count = words[i] >> 16;
        const std::uint32_t op = words[i] & 0xffffu;
        if (count == 0 || i + count > words.size()) {
            ADD_FAILURE() << "malformed instruction at word " << i;
            break;
        }
        if (op == kOpLoopMerge && count >= 4) {
            ++c.loops;
            if (words[i + 3] & kLoopControlUnroll) ++c.marked;
        }
        i += count;
    }
    return c;
}

TEST(SpirvUnroll, TheKernelsMarkTheirOffsetLoops) {
    // The marks are in the source: glslang's form carries them (which is also what a driver
    // that unrolls by itself gets).
    for (const Module& m : modules()) {
        const LoopCount raw = countLoops(m.raw);
        EXPECT_GT(raw.marked, 0u) << m.name;
        EXPECT_LE(raw.marked, raw.loops) << m.name;
    }
}

TEST(SpirvUnroll, TheOptimisedFormsHoldNoMarkedLoop) {
    for (const Module& m : modules()) {
        if (m.opt == m.raw) GTEST_SKIP() << "built without spirv-opt (GDPT_SPIRV_OPT=OFF)";
        EXPECT_EQ(countLoops(m.opt).marked, 0u) << m.name << ": a loop marked [[unroll]] was left rolled";
    }
}

}  // namespace
}  // namespace gdpt
