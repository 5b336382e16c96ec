// Pipelines kept by the context (ContextOptions::keepPipelines, vk/pipeline_cache.h): a second
// render of the same scene finds every pipeline it needs instead of compiling it again, renders
// the same bits as a context that keeps none, and nothing is reported by validation; a kernel
// of other specialisation constants gets a pipeline of its own.
#include <gtest/gtest.h>

#include "gpu_fixture.h"
#include "integrator/gpt_sampler.h"
#include "integrator/pt_sampler.h"
#include "same_bits.h"
#include "scene/procedural.h"
#include "vk/pipeline_cache.h"

namespace gdpt {
namespace {

class PipelineCacheTest : public test::GpuTest {};

TEST_F(PipelineCacheTest, RepeatedRendersReuseEveryPipelineAndKeepTheBits) {
    vk::ContextOptions o;
    o.validation = true;
    o.keepPipelines = true;
    vk::Context keeping(o);
    ASSERT_NE(keeping.pipelineCache(), nullptr);
    EXPECT_EQ(ctx().pipelineCache(), nullptr);  // off by default
    const Scene scene = makeCornellBox();
    const RenderOptions options = renderOptions(24, 16, 2, 7);

    const RenderResult first = renderPt(keeping, scene, options);
    const std::size_t kept = keeping.pipelineCache()->size();
    EXPECT_GT(kept, 0u);
    const std::size_t hitsBefore = keeping.pipelineCache()->hits();
    const RenderResult second = renderPt(keeping, scene, options);
    EXPECT_EQ(keeping.pipelineCache()->size(), kept) << "the second render compiled a pipeline again";
    EXPECT_GE(keeping.pipelineCache()->hits() - hitsBefore, kept);
    const RenderResult plain = renderPt(ctx(), scene, options);
    test::expectSameBits(second.image, first.image, "second render");
    test::expectSameBits(second.image, plain.image, "against a context that keeps no pipelines");

    // G-PT needs kernels of its own; another seed needs none.
    const RenderResultGpt g1 = renderGpt(keeping, scene, options, {});
    const std::size_t withGpt = keeping.pipelineCache()->size();
    EXPECT_GT(withGpt, kept);
    RenderOptions other = options;
    other.seed = 8;
    (void)renderGpt(keeping, scene, other, {});
    EXPECT_EQ(keeping.pipelineCache()->size(), withGpt);
    test::expectSameGptBits(g1, renderGpt(ctx(), scene, options, {}), "G-PT against no kept pipelines");
    EXPECT_EQ(keeping.validationErrors(), 0u);
}

}  // namespace
}  // namespace gdpt
