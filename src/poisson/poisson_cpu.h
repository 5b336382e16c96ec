// poisson_cpu.h — double-precision CPU reference of every screened-Poisson operator and
// solver: the oracle the GPU solver is tested against. Kept deliberately naive:
// one small function per operator, each documented with its maths.
//
// Notation (see poisson_problem.h): A = Pᵀ W P is the weighted 5-point Laplacian plus the
// screening diagonal, (A x)_i = Σ_{j∈N(i)} c_ij (x_i − x_j) + cp_i x_i; D = diag(A) with
// D_i = Σ_j c_ij + cp_i. Images are planar, pixel i = y*width + x.
//
// Singular systems (α = 0, or every primal weight 0): A then annihilates constants (we assume
// the edge graph with c > 0 is connected, true for unit or IRLS weights). Every solver then
// projects b onto range(A) (subtracts its mean) and returns the zero-mean solution;
// solvePoissonL2() finally shifts that solution so that its (wp-weighted) mean equals the
// primal's. This is the α → 0 limit: for α > 0, summing the rows of A x = b gives
// Σ cp_i x_i = Σ cp_i t_i exactly (the Laplacian's columns sum to 0), i.e. the solution has
// the primal's weighted mean for every α.
#pragma once

#include <functional>
#include <vector>

#include "poisson/poisson_problem.h"

namespace gdpt {

using Field = std::vector<double>;

// ---- problem set-up -------------------------------------------------------------------

// Throws gdpt::Error if sizes disagree or weights/α are negative or non-finite.
void validateProblem(const PoissonProblem& problem);

// c = W restricted to the kept rows: cx_i = wdx_i (0 in the last column), cy_i = wdy_i
// (0 in the last row), cp_i = α² wp_i.
PoissonOperator makeOperator(const PoissonProblem& problem);

// b = Pᵀ W target: b_i = α² wp_i t_i + Σ over kept gradient rows of ±w·g, namely
//   dx row k (pixels k, k+1):  b_k −= wdx_k dx_k,  b_{k+1} += wdx_k dx_k
//   dy row k (pixels k, k+W):  b_k −= wdy_k dy_k,  b_{k+W} += wdy_k dy_k
// i.e. α² W_p t minus the weighted divergence of the gradient field (Pérez et al. 2003).
Field computeRhs(const PoissonProblem& problem);

// ---- operators --------------------------------------------------------------------------

// y = A x (see the notation above). y is resized.
void applyA(const PoissonOperator& op, const Field& x, Field& y);

// r = b − A x. r is resized.
void residual(const PoissonOperator& op, const Field& b, const Field& x, Field& r);

// D_i = Σ_j c_ij + cp_i (the diagonal of A).
Field diagonal(const PoissonOperator& op);

double dot(const Field& a, const Field& b);
double norm2(const Field& a);

// One damped (weighted) Jacobi sweep: x ← x + ω D⁻¹ (b − A x). Rows with D_i = 0 are left
// unchanged. ω = 4/5 is the smoothing-optimal damping for the 5-point Laplacian (Briggs,
// Henson & McCormick, "A Multigrid Tutorial", 2nd ed., ch. 2 and 4).
void jacobiSweep(const PoissonOperator& op, const Field& b, Field& x, double omega);

// One red-black Gauss-Seidel sweep: for colour k in order (red = (x+y) even first if
// redFirst, else black first), x_i ← (b_i + Σ_j c_ij x_j) / D_i. A red-first sweep followed by
// a black-first sweep is symmetric, which keeps a V-cycle usable as a CG preconditioner.
void gaussSeidelRedBlackSweep(const PoissonOperator& op, const Field& b, Field& x, bool redFirst = true);

// ---- multigrid (cell-centred, poisson_multigrid.cpp) -------------------------------------
//
// Coarse cell (X, Y) aggregates the fine cells {2X, 2X+1} x {2Y, 2Y+1} that exist; coarse
// size = ceil(n/2) per axis, so odd sizes give 1-wide (or 1x1) aggregates at the far edges
// and a 1-wide axis stays 1-wide.
// Prolongation P is piecewise constant (each fine cell takes its aggregate's value);
// restriction R = ¼ Pᵀ (the average of a 2x2 aggregate: cell-centred full weighting); the
// coarse operator is Galerkin, A_H = R A P. Why piecewise constant: with it, A_H is again a
// 5-point weighted Laplacian + diagonal with summed ("coarsened") weights, for ANY weights —
// so IRLS weights that vary by orders of magnitude coarsen consistently, odd sizes need no
// special stencils, A_H stays SPD, and every level runs the same operator (one GPU kernel).
// The price is a V-cycle convergence rate that degrades slowly with the number of levels
// (bilinear P would keep it level-independent but make A_H a 9-point stencil); we therefore
// use the V-cycle mainly as a CG preconditioner (solvePcgMultigrid).

enum class Smoother { RedBlackGaussSeidel, Jacobi };

struct MultigridOptions {
    Smoother smoother = Smoother::RedBlackGaussSeidel;
    int preSmooth = 2;         // sweeps before the coarse-grid correction
    int postSmooth = 2;        // sweeps after it (use preSmooth == postSmooth for PCG)
    double jacobiOmega = 0.8;  // damping for Smoother::Jacobi
};

struct MultigridHierarchy {
    std::vector<PoissonOperator> levels;  // levels[0] = finest; the last one is ≤ 2x2
    Field coarsestPseudoInverse;          // dense n x n pseudo-inverse of the last level
};

// A_H = R A P for the piecewise-constant P above: coarse edge weights are ¼ of the sum of the
// fine edge weights crossing between the two aggregates, cp_H = ¼ Σ_children cp.
PoissonOperator coarsenOperator(const PoissonOperator& fine);

// coarse = R fine = ¼ Σ_children fine (sizes from the fine grid). coarse is resized.
void restrictFullWeighting(int fineWidth, int fineHeight, const Field& fine, Field& coarse);

// fine += P coarse (each fine cell adds its aggregate's value).
void prolongate(int fineWidth, int fineHeight, const Field& coarse, Field& fine);

MultigridHierarchy buildHierarchy(const PoissonOperator& op);

// One V-cycle on level `level` for A_level x = b, improving x in place: pre-smooth, restrict
// the residual, recurse with zero initial guess, prolongate-add, post-smooth (RB-GS
// post-sweeps run black-first, mirroring the pre-sweeps). The coarsest level is solved with
// the dense pseudo-inverse (exact, also for singular systems).
void vcycle(const MultigridHierarchy& hierarchy, int level, const Field& b, Field& x,
            const MultigridOptions& options = {});

// ---- solvers (poisson_solvers.cpp) -----------------------------------------------------

struct IterativeOptions {
    int maxIterations = 1000;
    double tolerance = 1e-10;  // stop when ‖b − A x‖₂ ≤ tolerance·‖b‖₂ (0: run all)
    // Called after every iteration with the iteration number (1-based) and the iterate.
    std::function<void(int, const Field&)> onIterate;
};

// Conjugate gradient (Hestenes & Stiefel 1952), warm-started from x, the method of the
// published G-PT solver (Kettunen et al. 2015, §4). Minimises ‖x − x*‖_A over growing
// Krylov spaces, so that error norm never increases.
SolveStats solveCg(const PoissonOperator& op, const Field& b, Field& x, const IterativeOptions& options = {});

// CG preconditioned with one symmetric V-cycle (zero initial guess) per iteration.
SolveStats solvePcgMultigrid(const PoissonOperator& op, const Field& b, Field& x,
                             const IterativeOptions& options = {}, const MultigridOptions& mg = {});

// Stand-alone multigrid: repeated V-cycles.
SolveStats solveMultigrid(const PoissonOperator& op, const Field& b, Field& x,
                          const IterativeOptions& options = {}, const MultigridOptions& mg = {});

// Stand-alone damped Jacobi (slow; for tests and as the GPU's simplest kernel).
SolveStats solveJacobi(const PoissonOperator& op, const Field& b, Field& x,
                       const IterativeOptions& options = {}, double omega = 0.8);

// Exact solve with Eigen's SimplicialLDLT on the sparse normal matrix (small images: the
// factorisation's fill-in grows like n^1.5). Singular systems: zero-mean solution.
Field solveExact(const PoissonOperator& op, const Field& b);

enum class L2Method { Exact, Cg, PcgMultigrid, Multigrid, Jacobi };

// Whole L2 reconstruction of one channel: operator, rhs, warm start from the primal, solve,
// and the mean fix for singular systems (see the top of this header).
Field solvePoissonL2(const PoissonProblem& problem, L2Method method, const IterativeOptions& options = {},
                     SolveStats* stats = nullptr);

}  // namespace gdpt
