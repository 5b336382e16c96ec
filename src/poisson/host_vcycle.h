// host_vcycle.h — one multigrid V-cycle as the preconditioner of the host's conjugate
// gradients (spacetime_pcg.h; one-frame windows: G-PT's reconstruction on a CPU device).
// The hierarchy is poisson_multigrid.cpp's (piecewise-constant prolongation, restriction ¼Pᵀ,
// Galerkin coarse operators, the coarsest ≤ 2×2 level solved by its pseudo-inverse); this is
// its fast form: the three channels at once, rows over the host's threads, one red-black
// Gauss-Seidel sweep before the coarse correction (red, then black) and one after (black, then
// red), so that M⁻¹ is symmetric, as CG needs (Tatebe 1993, "The multigrid preconditioned
// conjugate gradient method"). Every pixel of a colour reads only the other colour, so the
// result does not depend on the number of threads.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "poisson/poisson_cpu.h"

namespace gdpt {

class HostVcycle {
public:
    // The fine level: the 5-point weights cx (0 in the last column), cy (0 in the last row) and
    // the diagonal d of the CG operator (the screening and any other diagonal term is d minus
    // the edges), which must outlive the uses of apply. Builds the coarse levels.
    void build(int width, int height, const Field& cx, const Field& cy, const Field& diag,
               std::uint32_t threads);

    // z[c] = M⁻¹ r[c] for the channels with active[c]: one V-cycle from zero.
    void apply(const std::array<const Field*, 3>& r, const std::array<Field*, 3>& z,
               const std::array<bool, 3>& active, std::uint32_t threads);
    // The same on W·H values at each pointer (e.g. one frame of a window's fields).
    void applyTo(const std::array<const double*, 3>& r, const std::array<double*, 3>& z,
                 const std::array<bool, 3>& active, std::uint32_t threads);

    [[nodiscard]] int levels() const { return static_cast<int>(levels_.size()); }

private:
    struct Level {
        std::size_t width = 0, height = 0;
        const double *cx = nullptr, *cy = nullptr, *diag = nullptr;  // this level's operator
        Field ownCx, ownCy, ownDiag;  // the coarse levels' (the fine one's are the caller's)
        Field invDiag;
        std::array<Field, 3> b, x;  // the coarse levels' right-hand sides and iterates
    };
    void cycle(std::size_t level, const std::array<const double*, 3>& b, const std::array<double*, 3>& x,
               const std::array<bool, 3>& active, std::uint32_t threads);

    // Kept from one build to the next (the IRLS rounds of a solve have the same sizes): fresh
    // memory costs a page fault per 4 KiB, which on a virtual machine is more than the cycle.
    std::vector<Level> levels_;
    Field coarsestPseudoInverse_;
};

}  // namespace gdpt
