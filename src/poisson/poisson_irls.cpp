// poisson_irls.cpp — IRLS L1 reconstruction (see poisson_irls.h).
#include "poisson/poisson_irls.h"

#include <cmath>

#include "util/error.h"

namespace gdpt {

IrlsOptions irlsPresetL1D() {
    return IrlsOptions{};
}

IrlsOptions irlsPresetL2D() {
    IrlsOptions o;
    o.iterations = 1;
    return o;
}

namespace {

PoissonProblem channelProblem(const RgbPoissonProblem& p, int c) {
    PoissonProblem q;
    q.width = p.width;
    q.height = p.height;
    q.alpha = p.alpha;
    q.primal = p.primal[c];
    q.dx = p.dx[c];
    q.dy = p.dy[c];
    return q;
}

}  // namespace

IrlsWeights computeIrlsWeights(const RgbPoissonProblem& p, const std::array<Field, 3>& x, double reg) {
    const std::size_t n = static_cast<std::size_t>(p.width) * static_cast<std::size_t>(p.height);
    const std::size_t w = static_cast<std::size_t>(p.width);
    IrlsWeights weights{Field(n, 0.0), Field(n, 0.0), Field(n, 0.0)};
    double sum = 0.0;
    std::size_t rows = 0;
    auto weightOf = [&](double e0, double e1, double e2) {
        const double weight = 1.0 / (std::sqrt(e0 * e0 + e1 * e1 + e2 * e2) + reg);
        sum += weight;
        ++rows;
        return weight;
    };
    for (int y = 0; y < p.height; ++y)
        for (int xPix = 0; xPix < p.width; ++xPix) {
            const std::size_t i = y * w + xPix;
            double e[3];
            for (int c = 0; c < 3; ++c) e[c] = p.alpha * (x[c][i] - p.primal[c][i]);
            weights.primal[i] = weightOf(e[0], e[1], e[2]);
            if (xPix + 1 < p.width) {
                for (int c = 0; c < 3; ++c) e[c] = x[c][i + 1] - x[c][i] - p.dx[c][i];
                weights.dx[i] = weightOf(e[0], e[1], e[2]);
            }
            if (y + 1 < p.height) {
                for (int c = 0; c < 3; ++c) e[c] = x[c][i + w] - x[c][i] - p.dy[c][i];
                weights.dy[i] = weightOf(e[0], e[1], e[2]);
            }
        }
    // Mean 1 over kept rows: does not change the minimiser, keeps A's scale near the L2
    // one so tolerances and the CG behaviour stay comparable between iterations.
    const double scale = static_cast<double>(rows) / sum;
    for (Field* f : {&weights.primal, &weights.dx, &weights.dy})
        for (double& v : *f) v *= scale;
    return weights;
}

std::array<Field, 3> solveL1Irls(const RgbPoissonProblem& problem, const IrlsOptions& options,
                                 IrlsStats* stats) {
    if (options.iterations < 1 || options.innerIterations < 1)
        throw Error("IRLS: iterations and innerIterations must be >= 1");
    if (!(options.regInit > 0.0) || !(options.regIter > 0.0) || !(options.regScale > 0.0))
        throw Error("IRLS: regInit, regIter and regScale must be > 0");
    // As in the published solver, α must be > 0: the primal rows anchor each IRLS iterate.
    if (!(problem.alpha > 0.0)) throw Error("IRLS: alpha must be > 0");
    std::array<PoissonProblem, 3> channels;
    for (int c = 0; c < 3; ++c) {
        channels[c] = channelProblem(problem, c);
        validateProblem(channels[c]);
    }
    std::array<Field, 3> x = problem.primal;  // warm start from the primal
    IrlsStats s;
    IterativeOptions inner;
    inner.maxIterations = options.innerIterations;
    inner.tolerance = options.innerTolerance;
    double reg = options.regInit * options.regScale;
    for (int k = 0; k < options.iterations; ++k) {
        if (k > 0) {
            const IrlsWeights weights = computeIrlsWeights(problem, x, reg);
            reg *= options.regIter;
            for (PoissonProblem& q : channels) {
                q.weightPrimal = weights.primal;
                q.weightDx = weights.dx;
                q.weightDy = weights.dy;
            }
        }
        // Shared weights: one operator for all three channels.
        const PoissonOperator op = makeOperator(channels[0]);
        for (int c = 0; c < 3; ++c) {
            const Field b = computeRhs(channels[c]);
            const SolveStats cs = options.inner == InnerSolver::Cg ? solveCg(op, b, x[c], inner)
                                                                   : solvePcgMultigrid(op, b, x[c], inner);
            s.innerIterations += cs.iterations;
        }
        ++s.irlsIterations;
    }
    if (stats) *stats = s;
    return x;
}

}  // namespace gdpt
