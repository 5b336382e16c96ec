// poisson_solvers.cpp — CG, multigrid-preconditioned CG, stand-alone multigrid and Jacobi,
// the exact sparse LDLᵀ solve, and the whole-channel L2 reconstruction.
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <cmath>
#include <string>

#include "poisson/poisson_cpu.h"
#include "util/error.h"

namespace gdpt {
namespace {

// For singular A (null space = constants) the consistent part of b is b − mean(b).
void removeMean(Field& v) {
    if (v.empty()) return;
    double mean = 0.0;
    for (double value : v) mean += value;
    mean /= static_cast<double>(v.size());
    for (double& value : v) value -= mean;
}

Field projectedRhs(const PoissonOperator& op, const Field& b) {
    GDPT_CHECK_OP(b.size(), ==, op.size());
    Field rhs = b;
    if (op.singular()) removeMean(rhs);
    return rhs;
}

// Shared loop of the stationary solvers: x ← step(x) until the residual is small enough.
template <typename Step>
SolveStats iterateStationary(const PoissonOperator& op, const Field& b, Field& x,
                             const IterativeOptions& options, Step step) {
    const Field rhs = projectedRhs(op, b);
    SolveStats stats;
    stats.rhsNorm = norm2(rhs);
    Field r;
    residual(op, rhs, x, r);
    stats.residualNorm = norm2(r);
    while (stats.residualNorm > options.tolerance * stats.rhsNorm &&
           stats.iterations < options.maxIterations) {
        step(rhs, x);
        ++stats.iterations;
        residual(op, rhs, x, r);
        stats.residualNorm = norm2(r);
        if (options.onIterate) options.onIterate(stats.iterations, x);
    }
    if (op.singular()) removeMean(x);
    stats.converged = stats.residualNorm <= options.tolerance * stats.rhsNorm;
    return stats;
}

// Preconditioned CG (Saad, "Iterative Methods for Sparse Linear Systems", alg. 9.1);
// precondition(r, z) computes z = M⁻¹ r for an SPD M, or z = r for plain CG.
template <typename Preconditioner>
SolveStats conjugateGradient(const PoissonOperator& op, const Field& b, Field& x,
                             const IterativeOptions& options, Preconditioner precondition) {
    const bool singular = op.singular();
    const Field rhs = projectedRhs(op, b);
    SolveStats stats;
    stats.rhsNorm = norm2(rhs);
    GDPT_CHECK_OP(x.size(), ==, op.size());
    Field r, z, p, ap;
    residual(op, rhs, x, r);
    stats.residualNorm = norm2(r);
    precondition(r, z);
    if (singular) removeMean(z);
    p = z;
    double rz = dot(r, z);
    while (stats.residualNorm > options.tolerance * stats.rhsNorm &&
           stats.iterations < options.maxIterations) {
        applyA(op, p, ap);
        const double pap = dot(p, ap);
        if (!(pap > 0.0)) break;  // exact solution reached (p = 0) or breakdown
        const double step = rz / pap;
        for (std::size_t i = 0; i < x.size(); ++i) {
            x[i] += step * p[i];
            r[i] -= step * ap[i];
        }
        if (singular) removeMean(r);  // keep rounding errors out of the null space
        ++stats.iterations;
        stats.residualNorm = norm2(r);
        if (options.onIterate) options.onIterate(stats.iterations, x);
        precondition(r, z);
        if (singular) removeMean(z);
        const double rzNew = dot(r, z);
        const double beta = rzNew / rz;
        rz = rzNew;
        for (std::size_t i = 0; i < p.size(); ++i) p[i] = z[i] + beta * p[i];
    }
    // Report the true residual, not the recursively updated one.
    residual(op, rhs, x, r);
    stats.residualNorm = norm2(r);
    if (singular) removeMean(x);
    stats.converged = stats.residualNorm <= options.tolerance * stats.rhsNorm;
    return stats;
}

}  // namespace

SolveStats solveCg(const PoissonOperator& op, const Field& b, Field& x, const IterativeOptions& options) {
    return conjugateGradient(op, b, x, options, [](const Field& r, Field& z) { z = r; });
}

SolveStats solvePcgMultigrid(const PoissonOperator& op, const Field& b, Field& x,
                             const IterativeOptions& options, const MultigridOptions& mg) {
    const MultigridHierarchy hierarchy = buildHierarchy(op);
    return conjugateGradient(op, b, x, options, [&](const Field& r, Field& z) {
        z.assign(r.size(), 0.0);
        vcycle(hierarchy, 0, r, z, mg);
    });
}

SolveStats solveMultigrid(const PoissonOperator& op, const Field& b, Field& x,
                          const IterativeOptions& options, const MultigridOptions& mg) {
    const MultigridHierarchy hierarchy = buildHierarchy(op);
    return iterateStationary(op, b, x, options,
                             [&](const Field& rhs, Field& v) { vcycle(hierarchy, 0, rhs, v, mg); });
}

SolveStats solveJacobi(const PoissonOperator& op, const Field& b, Field& x, const IterativeOptions& options,
                       double omega) {
    return iterateStationary(op, b, x, options,
                             [&](const Field& rhs, Field& v) { jacobiSweep(op, rhs, v, omega); });
}

Field solveExact(const PoissonOperator& op, const Field& b) {
    const bool singular = op.singular();
    const Field rhs = projectedRhs(op, b);
    const int n = static_cast<int>(op.size());
    const int w = op.width;
    // Assemble A from its graph form; for a singular A pin pixel 0 (row and column of the
    // identity, b_0 = 0): with b in range(A) the pinned system's solution solves A x = b,
    // and removing its mean then gives the zero-mean solution.
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(op.size() * 5);
    const Field d = diagonal(op);
    auto add = [&](int i, int j, double v) {
        if (singular && (i == 0 || j == 0)) return;
        triplets.emplace_back(i, j, v);
    };
    for (int i = 0; i < n; ++i) {
        add(i, i, d[i]);
        if (i % w + 1 < w && op.cx[i] != 0.0) {
            add(i, i + 1, -op.cx[i]);
            add(i + 1, i, -op.cx[i]);
        }
        if (i + w < n && op.cy[i] != 0.0) {
            add(i, i + w, -op.cy[i]);
            add(i + w, i, -op.cy[i]);
        }
    }
    if (singular) triplets.emplace_back(0, 0, 1.0);
    Eigen::SparseMatrix<double> a(n, n);
    a.setFromTriplets(triplets.begin(), triplets.end());
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(a);
    if (ldlt.info() != Eigen::Success)
        throw Error("Poisson exact solve: LDLT factorisation of the " + std::to_string(n) +
                    "-pixel system failed (disconnected zero-weight regions?)");
    Eigen::VectorXd bv(n);
    for (int i = 0; i < n; ++i) bv[i] = rhs[i];
    if (singular) bv[0] = 0.0;
    const Eigen::VectorXd xv = ldlt.solve(bv);
    Field x(xv.data(), xv.data() + n);
    if (singular) removeMean(x);
    return x;
}

Field solvePoissonL2(const PoissonProblem& problem, L2Method method, const IterativeOptions& options,
                     SolveStats* stats) {
    const PoissonOperator op = makeOperator(problem);
    const Field b = computeRhs(problem);
    Field x = problem.primal;  // warm start from the primal, as the published solver does
    SolveStats s;
    switch (method) {
        case L2Method::Exact:
            x = solveExact(op, b);
            s.converged = true;
            break;
        case L2Method::Cg:
            s = solveCg(op, b, x, options);
            break;
        case L2Method::PcgMultigrid:
            s = solvePcgMultigrid(op, b, x, options);
            break;
        case L2Method::Multigrid:
            s = solveMultigrid(op, b, x, options);
            break;
        case L2Method::Jacobi:
            s = solveJacobi(op, b, x, options);
            break;
    }
    if (op.singular()) {
        // Solvers returned a solution up to a constant: choose the constant so that the
        // wp-weighted mean equals the primal's, Σ wp (x + s) = Σ wp t (plain means if every
        // primal weight is 0).
        double sumW = 0.0, sumWDiff = 0.0, sumDiff = 0.0;
        for (std::size_t i = 0; i < x.size(); ++i) {
            const double wp = problem.weightPrimal.empty() ? 1.0 : problem.weightPrimal[i];
            sumW += wp;
            sumWDiff += wp * (problem.primal[i] - x[i]);
            sumDiff += problem.primal[i] - x[i];
        }
        const double shift = sumW > 0.0 ? sumWDiff / sumW : sumDiff / static_cast<double>(x.size());
        for (double& v : x) v += shift;
    }
    if (stats) *stats = s;
    return x;
}

}  // namespace gdpt
