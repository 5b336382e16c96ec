// The default reconstruction, WL1, on a firefly-heavy render: why its inverse-variance weights
// are bounded (SolveOptions::varianceWeightContrast). On the door ajar, where light arrives
// through a gap and a few samples carry most of it, the box-filtered variances span orders of
// magnitude; unbounded, the IRLS solves of WL1 take several times the iterations of L1 (the
// conjugate gradients see the weights' contrast), which a timed render pays out of its budget.
// Bounded to 4x of the median row's weight they stay within a few times L1's. The iteration
// counts are deterministic (fixed seed, host solver), so the comparison is exact, not timed.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "gpu_fixture.h"
#include "integrator/gpt_integrator.h"
#include "poisson/poisson_gpu.h"
#include "scene/gltf_loader.h"

namespace gdpt {
namespace {

class GptWl1 : public test::GpuTest {};

TEST_F(GptWl1, BoundedWeightsKeepAFireflyHeavySolveNearL1s) {
    const Scene scene = loadGltf(std::string(GDPT_SOURCE_DIR) + "/scenes/indirect_gap.gltf");
    GptOptions none;
    none.reconstructions = {};
    GptIntegrator integrator("gpt", none);
    const RenderOutput out = integrator.render(ctx(), scene, renderOptions(64, 64, 8, 3));
    PoissonInput in;
    in.primal = &out.layer("primal");
    in.dx = &out.layer("dx");
    in.dy = &out.layer("dy");
    in.varPrimal = &out.layer("var_primal");
    in.varDx = &out.layer("var_dx");
    in.varDy = &out.layer("var_dy");
    PoissonSolverGpu solver(ctx(), 64, 64);
    const auto iterations = [&](Reconstruction method, double contrast) {
        SolveOptions o;
        o.solver = GpuSolver::HostPcg;
        o.method = method;
        o.varianceWeightContrast = contrast;
        Image image;
        const SolveReport r = solver.solve(in, o, image);
        EXPECT_TRUE(r.converged) << toString(method) << ", contrast " << contrast;
        return r.iterations;
    };
    const int l1 = iterations(Reconstruction::L1, 0.0);
    const int bounded = iterations(Reconstruction::WeightedL1, kDefaultVarianceWeightContrast);
    const int unbounded = iterations(Reconstruction::WeightedL1, 0.0);
    std::printf("door ajar, 64x64, 8 spp: iterations L1 %d, WL1 bounded %d, unbounded %d\n", l1, bounded,
                unbounded);
    EXPECT_LE(bounded, 3 * l1) << "L1 " << l1 << ", unbounded WL1 " << unbounded;
    // Power: without the bound the same solve takes several times as many iterations.
    EXPECT_GT(unbounded, 3 * bounded) << "L1 " << l1 << ", bounded WL1 " << bounded;
}

}  // namespace
}  // namespace gdpt
