// poisson_problem.h — the screened Poisson reconstruction problem of gradient-domain
// rendering (Kettunen et al. 2015, §4), one colour channel at a time.
//
// For a W x H image with pixel i = y*W + x, the unknown image I minimises
//     E(I) = Σ_i wdx_i (I_{i+1} − I_i − dx_i)²      (rows with x < W−1 only)
//          + Σ_i wdy_i (I_{i+W} − I_i − dy_i)²      (rows with y < H−1 only)
//          + α² Σ_i wp_i (I_i − t_i)²              (t = primal / "throughput" image)
// Forward differences; dx rows in the last column and dy rows in the last row are dropped
// (natural boundary, no wrap-around). With the stacked row operator P and W = diag(w) this
// is the weighted least-squares problem min ‖W^½ (P I − target)‖², whose normal equations
// A I = b have A = Pᵀ W P and b = Pᵀ W target (see poisson_cpu.h).
//
// Note on α: the published solver writes the primal rows as α(I − t), so the energy weight is
// α² (0.04 for the default α = 0.2). We keep that convention.
#pragma once

#include <cstddef>
#include <vector>

namespace gdpt {

struct PoissonProblem {
    int width = 0;
    int height = 0;
    double alpha = 0.2;
    std::vector<double> primal;  // t, width*height
    std::vector<double> dx;      // target of I(x+1,y) − I(x,y); last column ignored
    std::vector<double> dy;      // target of I(x,y+1) − I(x,y); last row ignored
    // Optional per-row energy weights (e.g. inverse variances, IRLS weights). Empty = all 1.
    std::vector<double> weightPrimal;
    std::vector<double> weightDx;
    std::vector<double> weightDy;

    [[nodiscard]] std::size_t size() const {
        return static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    }
};

// The normal-equation matrix A = Pᵀ W P of a PoissonProblem in "graph" form: a weighted
// 5-point Laplacian plus a diagonal,
//     (A x)_i = Σ_{j ∈ N(i)} c_ij (x_i − x_j) + cp_i x_i,
// where c is the weight of the edge i–j. This form is closed under Galerkin coarsening with
// piecewise-constant prolongation (poisson_multigrid.cpp), so every multigrid level uses the
// same operator code (and later the same GPU kernel).
struct PoissonOperator {
    int width = 0;
    int height = 0;
    std::vector<double> cx;  // weight of edge (x,y)–(x+1,y); 0 in the last column
    std::vector<double> cy;  // weight of edge (x,y)–(x,y+1); 0 in the last row
    std::vector<double> cp;  // screening term α² wp_i

    [[nodiscard]] std::size_t size() const {
        return static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    }
    // True if the screening term vanishes everywhere: A is then singular (constants are in
    // its null space) and solvers fix the mean instead (see poisson_cpu.h).
    [[nodiscard]] bool singular() const {
        for (double v : cp)
            if (v > 0.0) return false;
        return true;
    }
};

// Result of an iterative solve.
struct SolveStats {
    int iterations = 0;         // iterations (CG steps, sweeps or V-cycles) performed
    double residualNorm = 0.0;  // ‖b − A x‖₂ at exit
    double rhsNorm = 0.0;       // ‖b‖₂
    bool converged = false;     // residualNorm ≤ tolerance · rhsNorm
};

}  // namespace gdpt
