// spacetime_frame_blocks.h — CG's multigrid preconditioner for the space-time solve: a V-cycle
// per frame of the window (host_vcycle.h). Internal to the solver (gdpt_poisson_cpu).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "poisson/host_vcycle.h"
#include "poisson/spacetime_operator.h"

namespace gdpt::spacetime {

// CG's multigrid preconditioner: one V-cycle per frame (host_vcycle.h), as block Jacobi or block
// Gauss-Seidel over the frames. Each frame's diagonal block of A is a 5-point graph Laplacian
// (its dx, dy rows, and the halves of the mixed rows inside one frame: a mixed row joins m with
// m+s and π(m) with π(m)+s by edges of its weight) plus the diagonal; the rows between frames
// (dt, the mixed rows' cross terms) are left to CG (block Jacobi) or applied between the
// frames' cycles (block Gauss-Seidel). One frame is HostVcycle on the operator itself.
class FrameBlocks {
public:
    // The frames' blocks of op and their hierarchies, on `threads`.
    void build(const Operator& op, std::uint32_t threads);

    // z = M⁻¹ r for the channels in `which`: block Jacobi (a V-cycle per frame), or with
    // `coupled` and several frames symmetric block Gauss-Seidel (applyCoupled).
    void apply(const Operator& op, const std::array<Field, 3>& r, std::array<Field, 3>& z,
               const std::array<bool, 3>& which, std::uint32_t threads, bool coupled);

private:
    void applyCoupled(const Operator& op, const std::array<Field, 3>& r, std::array<Field, 3>& z,
                      const std::array<bool, 3>& which, std::uint32_t threads);
    void forwardLinked(const Operator& op, const Field& r, const Field& t, std::size_t base, std::size_t lo,
                       std::size_t end, bool mixed, int c);
    void backwardLinked(const Operator& op, const Field& z, std::size_t base, std::size_t lo, std::size_t end,
                        bool mixed, int c);

    std::vector<HostVcycle> cycles_;
    std::vector<Field> cx_, cy_, diag_;     // the frames' blocks (several frames only)
    std::array<Field, 3> s_, e_, rx_, ry_;  // applyCoupled's, one frame each
};

}  // namespace gdpt::spacetime
