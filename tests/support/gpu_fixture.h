// gpu_fixture.h — base fixture of every GPU test: one Vulkan context per test process on the
// default device (lavapipe in CI) with validation layers on. A test fails if validation
// reported any error while it ran.
#pragma once

#include <memory>

#include <gtest/gtest.h>

#include "vk/context.h"

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

private:
    std::uint32_t errorsBefore_ = 0;
};

}  // namespace gdpt::test
