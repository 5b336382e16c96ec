// poisson_spacetime.cpp — the space-time screened Poisson reconstruction (poisson_spacetime.h).
#include "poisson/poisson_spacetime.h"

#include <Eigen/Sparse>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <tuple>
#include <vector>

#include "poisson/spacetime_irls.h"
#include "poisson/spacetime_pcg.h"
#include "util/error.h"
#include "util/parallel.h"
#include "util/timer.h"

namespace gdpt {

// The solver's parts (spacetime_*.h) are its own; this file puts them together.
using namespace spacetime;

namespace {

void check(const SpaceTimeProblem& p) {
    if (p.width < 1 || p.height < 1 || p.frames < 1) throw Error("space-time Poisson: empty window");
    if (!(p.alpha > 0.0) || !std::isfinite(p.alpha)) throw Error("space-time Poisson: alpha must be > 0");
    if (!(p.beta >= 0.0) || !std::isfinite(p.beta)) throw Error("space-time Poisson: beta must be >= 0");
    if (!(p.gamma >= 0.0) || !std::isfinite(p.gamma)) throw Error("space-time Poisson: gamma must be >= 0");
    const std::size_t n = p.size(), nt = p.pixels() * std::size_t(p.frames - 1);
    for (int c = 0; c < 3; ++c) {
        const auto sized = [&](const Field& f, std::size_t want, const char* what) {
            if (f.size() != want)
                throw Error(std::string("space-time Poisson: ") + what + " has " + std::to_string(f.size()) +
                            " values, expected " + std::to_string(want));
            for (double v : f)
                if (!std::isfinite(v))
                    throw Error(std::string("space-time Poisson: ") + what + " is not finite");
        };
        sized(p.primal[c], n, "primal");
        sized(p.dx[c], n, "dx");
        sized(p.dy[c], n, "dy");
        sized(p.dt[c], nt, "dt");
        if (p.gamma > 0.0) {
            sized(p.dxt[c], nt, "dxt");
            sized(p.dyt[c], nt, "dyt");
        }
        if (!p.initial[c].empty()) sized(p.initial[c], n, "initial");
        if (!p.previous[c].empty() || !p.dtPrevious[c].empty()) {
            sized(p.previous[c], p.pixels(), "previous");
            sized(p.dtPrevious[c], p.pixels(), "dtPrevious");
        }
        if (!p.dxtPrevious[c].empty() || !p.dytPrevious[c].empty()) {
            if (p.previous[c].empty() || !(p.gamma > 0.0))
                throw Error(
                    "space-time Poisson: mixed rows to the previous frame need the previous frame and gamma "
                    "> 0");
            sized(p.dxtPrevious[c], p.pixels(), "dxtPrevious");
            sized(p.dytPrevious[c], p.pixels(), "dytPrevious");
        }
    }
    if (p.previous[0].empty() != p.previous[1].empty() || p.previous[0].empty() != p.previous[2].empty())
        throw Error("space-time Poisson: previous is given for some channels only");
    const auto partners = [&](const std::vector<std::uint32_t>& v, std::size_t want, const char* what) {
        if (v.empty()) return;
        if (v.size() != want)
            throw Error(std::string("space-time Poisson: ") + what + " has " + std::to_string(v.size()) +
                        " entries, expected " + std::to_string(want));
        for (std::uint32_t j : v)
            if (j != kNoTemporalPartner && j >= p.pixels())
                throw Error(std::string("space-time Poisson: ") + what + " names pixel " + std::to_string(j) +
                            " of a frame of " + std::to_string(p.pixels()));
    };
    const std::size_t nb = p.previous[0].empty() ? 0 : p.pixels();
    const std::size_t nbm = p.dxtPrevious[0].empty() ? 0 : p.pixels();
    for (const auto& [field, what, want] :
         {std::tuple<const Field*, const char*, std::size_t>{&p.weightPrimal, "weightPrimal", n},
          {&p.weightDx, "weightDx", n},
          {&p.weightDy, "weightDy", n},
          {&p.weightDt, "weightDt", nt},
          {&p.weightDxt, "weightDxt", p.gamma > 0.0 ? nt : 0},
          {&p.weightDyt, "weightDyt", p.gamma > 0.0 ? nt : 0},
          {&p.weightDtPrevious, "weightDtPrevious", nb},
          {&p.weightDxtPrevious, "weightDxtPrevious", nbm},
          {&p.weightDytPrevious, "weightDytPrevious", nbm}}) {
        if (field->empty()) continue;
        if (field->size() != want)
            throw Error(std::string("space-time Poisson: ") + what + " has " + std::to_string(field->size()) +
                        " values, expected " + std::to_string(want));
        for (double v : *field)
            if (!std::isfinite(v) || v < 0.0)
                throw Error(std::string("space-time Poisson: ") + what + " must be finite and >= 0");
    }
    partners(p.temporalPartner, nt, "temporalPartner");
    partners(p.previousPartner, p.previous[0].empty() ? 0 : p.pixels(), "previousPartner");
}

}  // namespace

struct SpaceTimeWorkspace::State {
    Operator op;
    Weights kept;
    std::array<Field, 3> b;
    CgVectors vectors;
    FrameBlocks vcycle;
};

SpaceTimeWorkspace::SpaceTimeWorkspace() : state_(std::make_unique<State>()) {}
SpaceTimeWorkspace::~SpaceTimeWorkspace() = default;
SpaceTimeWorkspace::SpaceTimeWorkspace(SpaceTimeWorkspace&&) noexcept = default;
SpaceTimeWorkspace& SpaceTimeWorkspace::operator=(SpaceTimeWorkspace&&) noexcept = default;

std::array<Field, 3> solveSpaceTime(const SpaceTimeProblem& problem, const SpaceTimeOptions& options,
                                    SpaceTimeStats* stats, SpaceTimeWorkspace* workspace) {
    check(problem);
    Timer timer;
    std::optional<SpaceTimeWorkspace> own;
    if (!workspace) workspace = &own.emplace();
    SpaceTimeWorkspace::State& ws = *workspace->state_;
    std::array<Field, 3> x;
    for (int c = 0; c < 3; ++c)
        copied(x[c], problem.initial[c].empty() ? problem.primal[c] : problem.initial[c]);
    const int rounds = options.l1 ? std::max(1, options.irlsIterations) : 1;
    const std::uint32_t threads = defaultThreads(static_cast<std::uint32_t>(std::max(0, options.threads)));
    Operator& op = ws.op;
    makeStructure(problem, op);
    Weights& kept = ws.kept;
    unitWeights(problem, kept);
    std::array<Field, 3>& b = ws.b;
    CgVectors& vectors = ws.vectors;
    SpaceTimeStats s;
    std::array<int, 3> iterations{};
    const auto iterationsSoFar = [&] { return *std::max_element(iterations.begin(), iterations.end()); };
    int roundsDone = 0;
    // Multigrid: a V-cycle per frame (FrameBlocks; rows to a previous frame only add to the
    // diagonal, which the V-cycle takes as it is), where it pays (measured, `gdpt bench-poisson
    // --methods st-l1 --gamma G`, 10 frames of 256²): one frame, and windows with mixed rows
    // (133 -> 46 iterations at γ = 1). Without mixed rows the diagonal takes 52 iterations where
    // the V-cycles take 31, each iteration costing more than twice as much.
    const bool multigrid = options.multigrid && (problem.frames == 1 || problem.gamma > 0.0);
    FrameBlocks& vcycle = ws.vcycle;
    for (int round = 0; round < rounds; ++round) {
        if (round > 0 && options.deadline && std::chrono::steady_clock::now() >= *options.deadline) {
            s.stoppedAtDeadline = true;
            break;
        }
        Weights wt = takeWeightStorage(op);
        if (round == 0) {
            copyWeights(kept, wt);
        } else {
            irlsWeights(problem, op, x, options.regInit * std::pow(options.regIter, round - 1), kept, wt,
                        threads);
        }
        setWeights(problem, std::move(wt), op, threads);
        const bool last = round + 1 == rounds;
        const double tolerance = last ? options.tolerance : options.innerTolerance;
        rhs(problem, op, b, vectors.rows, threads);  // (the rows' scratch is free until pcg)
        std::function<void(int)> every16;
        if (options.progress)
            every16 = [&](int k) { options.progress(roundsDone, rounds, iterationsSoFar() + k); };
        // The first round (the L2 solve) always runs to its tolerance; later ones stop at the
        // deadline, mid-round if need be.
        FrameBlocks* mg = nullptr;
        if (multigrid) {
            vcycle.build(op, threads);
            mg = &vcycle;
        }
        const std::array<ChannelSolve, 3> solved =
            pcg(op, b, x, tolerance, options.maxIterations, threads, vectors, every16,
                round > 0 ? options.deadline : std::nullopt, mg, options.coupleFrames);
        s.residual = 0.0;
        s.converged = true;
        for (int c = 0; c < 3; ++c) {
            iterations[c] += solved[c].iterations;
            const double rel = solved[c].rhsNorm > 0.0 ? solved[c].residualNorm / solved[c].rhsNorm : 0.0;
            s.residual = std::max(s.residual, rel);
            s.converged = s.converged && solved[c].converged;
        }
        roundsDone = round + 1;
        if (solved[0].stoppedAtDeadline) {
            s.stoppedAtDeadline = true;
            break;
        }
        if (options.progress) options.progress(roundsDone, rounds, iterationsSoFar());
    }
    s.iterations = iterationsSoFar();
    s.irlsIterations = roundsDone;
    s.multigrid = multigrid;
    s.coupledFrames = multigrid && options.coupleFrames && problem.frames > 1;
    s.ms = timer.ms();
    if (stats) *stats = s;
    return x;
}

Field solveSpaceTimeExactL2(const SpaceTimeProblem& problem, int channel) {
    check(problem);
    Operator op;
    makeStructure(problem, op);
    Weights unit;
    unitWeights(problem, unit);
    setWeights(problem, std::move(unit), op, 1);
    std::array<Field, 3> rhsAll;
    MixedRowValues scratch;
    rhs(problem, op, rhsAll, scratch, 1);
    const Field& b = rhsAll[std::size_t(channel)];
    const Field& d = op.diag;
    const std::size_t n = op.size(), w = std::size_t(op.width);
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(n * 7);
    for (std::size_t i = 0; i < n; ++i) {
        const int ii = static_cast<int>(i);
        triplets.emplace_back(ii, ii, d[i]);
        const auto edge = [&](std::size_t j, double c) {
            if (c == 0.0) return;
            triplets.emplace_back(ii, static_cast<int>(j), -c);
            triplets.emplace_back(static_cast<int>(j), ii, -c);
        };
        edge(i + 1, op.cx[i]);
        edge(i + w, op.cy[i]);
        if (op.ct[i] != 0.0) edge(op.next[i], op.ct[i]);
        // Mixed rows: c σ_u σ_v for every pair of the row's four pixels (the diagonal too).
        for (const auto& [cm, s] : {std::pair<const Field*, std::size_t>{&op.cmx, 1}, {&op.cmy, w}}) {
            if (i >= cm->size() || (*cm)[i] == 0.0) continue;
            const std::size_t at[4] = {i, i + s, op.next[i], op.next[i] + s};
            const double sign[4] = {1.0, -1.0, -1.0, 1.0};
            for (int u = 0; u < 4; ++u)
                for (int v = 0; v < 4; ++v)
                    triplets.emplace_back(static_cast<int>(at[u]), static_cast<int>(at[v]),
                                          (*cm)[i] * sign[u] * sign[v]);
        }
    }
    Eigen::SparseMatrix<double> a(static_cast<int>(n), static_cast<int>(n));
    a.setFromTriplets(triplets.begin(), triplets.end());
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(a);
    if (ldlt.info() != Eigen::Success) throw Error("space-time Poisson: LDLT factorisation failed");
    Eigen::VectorXd bv(static_cast<int>(n));
    for (std::size_t i = 0; i < n; ++i) bv[static_cast<int>(i)] = b[i];
    const Eigen::VectorXd xv = ldlt.solve(bv);
    return Field(xv.data(), xv.data() + n);
}

}  // namespace gdpt
