// poisson_clone.h — seamless cloning (Pérez, Gangnet & Blake, "Poisson Image Editing",
// SIGGRAPH 2003) with the GPU screened-Poisson solver.
//
// Inside the mask Ω (placed at `offset` in the target) the result f solves Pérez's discrete
// eq. (7): for every p ∈ Ω, |N_p| f_p − Σ_{q∈N_p∩Ω} f_q = Σ_{q∈N_p∩∂Ω} f*_q + Σ_q v_pq, with
// guidance v = ∇source (or, with `mixed`, whichever of ∇source and ∇target is longer per
// edge, eq. 13) and the Dirichlet boundary f = f* (target) outside Ω. We express it as a
// weighted screened Poisson problem for the correction y = f − target: primal 0 with primal
// weight 0 inside Ω and kClonePinWeight outside (α = 1), gradient rows v − ∇target with
// weight 1 (zero away from Ω, so the relative residual measures the cloning problem). The pinned
// pixels move by O(|flux| / kClonePinWeight) ≈ 1e-6 relative, which the solve's
// multigrid smoother absorbs without conditioning trouble (diagonal dominance); the output
// then copies the target exactly outside Ω.
#pragma once

#include "image/image.h"
#include "poisson/poisson_gpu.h"

namespace gdpt {

constexpr double kClonePinWeight = 1e6;

struct CloneOptions {
    int offsetX = 0;  // target pixel of source pixel (0, 0)
    int offsetY = 0;
    bool mixed = false;  // mixed gradients (Pérez et al. 2003, §3.2)
    double tolerance = 1e-5;
    GpuSolver solver = GpuSolver::MgPcg;
};

// `mask` has the source's size; a source pixel belongs to Ω when mask channel 0 > 0.5 and no
// channel of it is NaN or infinite, and it lands inside the target. Where a source gradient
// touches a NaN or infinite source pixel, the guidance is the target's gradient. Returns an
// image of the target's size. Throws gdpt::Error on size mismatches and on a target with
// NaN or infinite values (it is copied outside Ω).
Image seamlessClone(const vk::Context& ctx, const Image& source, const Image& target, const Image& mask,
                    const CloneOptions& options, SolveReport* report = nullptr);

}  // namespace gdpt
