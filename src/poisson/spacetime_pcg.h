// spacetime_pcg.h — preconditioned conjugate gradients on the space-time normal equations
// (spacetime_operator.h), the three channels in lockstep. Internal to the solver (gdpt_poisson_cpu).
#pragma once

#include <array>
#include <chrono>
#include <functional>
#include <optional>

#include "poisson/spacetime_frame_blocks.h"
#include "poisson/spacetime_operator.h"

namespace gdpt::spacetime {

// One channel's solve: its iterations, ‖b‖ and ‖b − A x‖ at the end, and how it ended.
struct ChannelSolve {
    int iterations = 0;
    double rhsNorm = 0.0, residualNorm = 0.0;
    bool converged = false;
    bool stoppedAtDeadline = false;
};

// CG's vectors, kept across the IRLS rounds (allocating them anew each round cost more than
// the iterations on a machine where page faults are slow).
struct CgVectors {
    std::array<Field, 3> r, p, q, z;  // z: multigrid only
    MixedRowValues rows;              // with mixed rows only
};

// Preconditioned CG from x until ‖b − A x‖ ≤ tolerance ‖b‖, the three channels in
// lockstep (each stops where it converges), pixel ranges over `threads`. A is SPD (α > 0).
// Jacobi: z = r / d is not stored (p ← r/d + β p). Multigrid (`mg`: a V-cycle per frame,
// spacetime_frame_blocks.h, coupled over the frames with `coupleFrames`): z = M⁻¹ r,
// p ← z + β p. `every16`: called after every 16th iteration with the iterations so far (may
// throw); `deadline`: no iteration starts after it.
std::array<ChannelSolve, 3> pcg(const Operator& op, const std::array<Field, 3>& b, std::array<Field, 3>& x,
                                double tolerance, int maxIterations, std::uint32_t threads, CgVectors& v,
                                const std::function<void(int)>& every16,
                                std::optional<std::chrono::steady_clock::time_point> deadline,
                                FrameBlocks* mg, bool coupleFrames);

}  // namespace gdpt::spacetime
