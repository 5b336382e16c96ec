// poisson_multigrid.cpp — cell-centred multigrid for the screened Poisson operator:
// piecewise-constant prolongation, ¼Pᵀ restriction, Galerkin coarse operators, V-cycle.
// Background: Briggs, Henson & McCormick, "A Multigrid Tutorial" (2nd ed., SIAM 2000),
// ch. 3 (V-cycle), ch. 8 (Galerkin/variational coarse operators); the design choice is
// explained in poisson_cpu.h.
#include <Eigen/Dense>

#include "poisson/poisson_cpu.h"
#include "util/error.h"

namespace gdpt {
namespace {

int coarseSize(int n) {
    return (n + 1) / 2;
}

}  // namespace

PoissonOperator coarsenOperator(const PoissonOperator& fine) {
    PoissonOperator coarse;
    coarse.width = coarseSize(fine.width);
    coarse.height = coarseSize(fine.height);
    const std::size_t n = coarse.size();
    coarse.cx.assign(n, 0.0);
    coarse.cy.assign(n, 0.0);
    coarse.cp.assign(n, 0.0);
    const std::size_t fw = static_cast<std::size_t>(fine.width);
    const std::size_t cw = static_cast<std::size_t>(coarse.width);
    // Pᵀ A P with piecewise-constant P: an edge inside an aggregate contributes
    // c (e − e) = 0; an edge between aggregates I, J contributes c to the coarse edge I–J;
    // diagonal terms add up. Scaled by ¼ because R = ¼Pᵀ.
    for (int y = 0; y < fine.height; ++y)
        for (int x = 0; x < fine.width; ++x) {
            const std::size_t i = y * fw + x;
            const std::size_t ci = static_cast<std::size_t>(y / 2) * cw + x / 2;
            coarse.cp[ci] += 0.25 * fine.cp[i];
            // Fine edge x–x+1 crosses aggregates iff x is odd (x = 2X+1 -> 2X+2).
            if (x % 2 == 1 && x + 1 < fine.width) coarse.cx[ci] += 0.25 * fine.cx[i];
            if (y % 2 == 1 && y + 1 < fine.height) coarse.cy[ci] += 0.25 * fine.cy[i];
        }
    return coarse;
}

void restrictFullWeighting(int fineWidth, int fineHeight, const Field& fine, Field& coarse) {
    const int cwInt = coarseSize(fineWidth);
    const std::size_t cw = static_cast<std::size_t>(cwInt);
    const std::size_t fw = static_cast<std::size_t>(fineWidth);
    coarse.assign(cw * static_cast<std::size_t>(coarseSize(fineHeight)), 0.0);
    for (int y = 0; y < fineHeight; ++y)
        for (int x = 0; x < fineWidth; ++x)
            coarse[static_cast<std::size_t>(y / 2) * cw + x / 2] += 0.25 * fine[y * fw + x];
}

void prolongate(int fineWidth, int fineHeight, const Field& coarse, Field& fine) {
    const std::size_t cw = static_cast<std::size_t>(coarseSize(fineWidth));
    const std::size_t fw = static_cast<std::size_t>(fineWidth);
    for (int y = 0; y < fineHeight; ++y)
        for (int x = 0; x < fineWidth; ++x)
            fine[y * fw + x] += coarse[static_cast<std::size_t>(y / 2) * cw + x / 2];
}

MultigridHierarchy buildHierarchy(const PoissonOperator& op) {
    MultigridHierarchy h;
    h.levels.push_back(op);
    while (h.levels.back().width > 2 || h.levels.back().height > 2)
        h.levels.push_back(coarsenOperator(h.levels.back()));
    // Dense pseudo-inverse of the ≤ 2x2 coarsest operator. The complete orthogonal
    // decomposition gives the minimum-norm (zero-mean) solution when A is singular.
    const PoissonOperator& last = h.levels.back();
    const int n = static_cast<int>(last.size());
    Eigen::MatrixXd a(n, n);
    Field e(last.size()), column;
    for (int j = 0; j < n; ++j) {
        std::fill(e.begin(), e.end(), 0.0);
        e[j] = 1.0;
        applyA(last, e, column);
        for (int i = 0; i < n; ++i) a(i, j) = column[i];
    }
    const Eigen::MatrixXd pinv = a.completeOrthogonalDecomposition().pseudoInverse();
    h.coarsestPseudoInverse.resize(last.size() * last.size());
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) h.coarsestPseudoInverse[i * n + j] = pinv(i, j);
    return h;
}

namespace {

void smooth(const PoissonOperator& op, const Field& b, Field& x, const MultigridOptions& o, int sweeps,
            bool pre) {
    for (int s = 0; s < sweeps; ++s) {
        if (o.smoother == Smoother::Jacobi)
            jacobiSweep(op, b, x, o.jacobiOmega);
        else
            gaussSeidelRedBlackSweep(op, b, x, pre);  // post-smoothing runs black first
    }
}

}  // namespace

void vcycle(const MultigridHierarchy& hierarchy, int level, const Field& b, Field& x,
            const MultigridOptions& options) {
    GDPT_CHECK(level >= 0 && level < static_cast<int>(hierarchy.levels.size()));
    const PoissonOperator& op = hierarchy.levels[level];
    if (level + 1 == static_cast<int>(hierarchy.levels.size())) {
        const std::size_t n = op.size();
        for (std::size_t i = 0; i < n; ++i) {
            double v = 0.0;
            for (std::size_t j = 0; j < n; ++j) v += hierarchy.coarsestPseudoInverse[i * n + j] * b[j];
            x[i] = v;
        }
        return;
    }
    smooth(op, b, x, options, options.preSmooth, true);
    Field r, coarseB;
    residual(op, b, x, r);
    restrictFullWeighting(op.width, op.height, r, coarseB);
    Field coarseX(coarseB.size(), 0.0);
    vcycle(hierarchy, level + 1, coarseB, coarseX, options);
    prolongate(op.width, op.height, coarseX, x);
    smooth(op, b, x, options, options.postSmooth, false);
}

}  // namespace gdpt
