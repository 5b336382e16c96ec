// gpu_fixture.h — base fixture of every GPU test: one Vulkan context per test process on the
// default device (lavapipe in CI) with validation layers on. A test fails if validation
// reported any error while it ran.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "integrator/render_options.h"
#include "vk/commands.h"
#include "vk/context.h"
#include "vk/kernel.h"

namespace gdpt::test {

inline vk::Context& gpuContext() {
    static std::unique_ptr<vk::Context> ctx = [] {
        vk::ContextOptions o;
        o.validation = true;
        return std::make_unique<vk::Context>(o);
    }();
    return *ctx;
}

class GpuTest : public ::testing::Test {
protected:
    void SetUp() override { errorsBefore_ = gpuContext().validationErrors(); }
    void TearDown() override {
        EXPECT_EQ(gpuContext().validationErrors(), errorsBefore_)
            << "Vulkan validation reported errors during this test";
    }
    static vk::Context& ctx() { return gpuContext(); }
    // Runs one workgroup of `kernel` (bound already) and waits for it (probe kernels).
    static void dispatchOnce(vk::Kernel& kernel, const std::string& what) {
        vk::CommandStream cmd(ctx(), what);
        kernel.dispatch(cmd.begin(), 1, 1, 1);
        vk::computeBarrier(cmd.cmd());
        cmd.submitAndWait();
    }
    // The render settings every GPU test starts from: size, samples, seed, no progress output.
    static RenderOptions renderOptions(int w, int h, std::uint32_t spp, std::uint32_t seed) {
        RenderOptions o;
        o.scene.width = w;
        o.scene.height = h;
        o.spp = spp;
        o.seed = seed;
        o.quiet = true;
        return o;
    }

private:
    std::uint32_t errorsBefore_ = 0;
};

// A second context besides the default one, made with the options `Configure` sets on top of
// validation (on), its validation errors checked after every test like the default's.
template <void (*Configure)(vk::ContextOptions&)>
class SecondContextTest : public GpuTest {
protected:
    static vk::Context& second() {
        static std::unique_ptr<vk::Context> ctx = [] {
            vk::ContextOptions o;
            o.validation = true;
            Configure(o);
            return std::make_unique<vk::Context>(o);
        }();
        return *ctx;
    }
    void SetUp() override {
        GpuTest::SetUp();
        secondErrorsBefore_ = second().validationErrors();
    }
    void TearDown() override {
        EXPECT_EQ(second().validationErrors(), secondErrorsBefore_) << "Vulkan validation reported errors";
        GpuTest::TearDown();
    }

private:
    std::uint32_t secondErrorsBefore_ = 0;
};

inline void keepPipelines(vk::ContextOptions& o) {
    o.keepPipelines = true;
}

// For tests of many short renders of the same kernels: a second context that keeps its
// pipelines (as a sequence's does).
class KeptPipelinesTest : public SecondContextTest<keepPipelines> {
protected:
    static vk::Context& keeping() { return second(); }
};

}  // namespace gdpt::test
