// spacetime_operator.h — the normal equations of the space-time Poisson solve (poisson_spacetime.h)
// on the host: the operator A = Pᵀ W P in graph form, its coefficients from the rows' weights, the
// right-hand side and the product A x over pixel ranges. Internal to the solver (gdpt_poisson_cpu).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "poisson/poisson_spacetime.h"
#include "util/parallel.h"

namespace gdpt::spacetime {

// The normal equations A = Pᵀ W P (shared by the channels) in graph form: (A x)_i =
// Σ_j c_ij (x_i − x_j) + cp_i x_i over the x, y and frame neighbours (poisson_problem.h's form,
// one more axis), applied by gathering over each pixel's neighbours (so disjoint pixel ranges
// can run on different threads): d_i x_i − Σ_j c_ij x_j with the diagonal d.
struct Operator {
    int width = 0, height = 0, frames = 0;
    Field cx, cy, ct, cp;  // edge i–(i+1), i–(i+W), i–next(i); screening
    Field cb;              // rows from the fixed previous frame's pixel j to bnext(j) (W·H; empty: none)
    Field diag;            // d_i: cp_i, the boundary rows at i and every edge at i
    // Mixed rows (γ > 0): γ² w of the row at frame f's pixel i, (F − 1)·W·H each (x: s = 1, y:
    // s = W), 0 where there is none; empty without mixed rows. mixedDiag: diag plus every mixed
    // row's coefficient at each of its four pixels (with mixed rows only; jacobiDiag()).
    Field cmx, cmy;
    Field mixedDiag;
    // Mixed rows to the previous frame: γ² w of the row at its pixel j (W·H each; empty: none),
    // an edge bnext(j)–bnext(j)+s of frame 0 added into cx, cy; cx0, cy0: frame 0's dx, dy rows'
    // own coefficients (the right-hand side takes them apart).
    Field bmx, bmy, cx0, cy0;
    std::vector<std::uint32_t>
        next;  // next(i): the temporal neighbour of i in the window, or kNoTemporalPartner
    std::vector<std::uint32_t> bnext;  // bnext(j): the pixel of frame 0 of the previous frame's pixel j
    // The pixels whose next() is i: back[backStart[i] .. backStart[i+1]).
    std::vector<std::uint32_t> backStart, back;
    // The links again in a form without tests (linkedOnce(), where every pixel is next() of at
    // most one pixel, as the motion map and the replay make it; empty otherwise), for the
    // loops that run every CG iteration: fwd[i] = next(i), or i where none (its ct is 0); src[i]
    // = the pixel whose next() is i, or i where none (srcCt 0); srcRow[i] = the same, or n
    // where none (the mixed row values are n + 1 long, 0 past the rows); mxTo[m] (myTo[m]) =
    // next(m) where next(m) + 1 (+ W) is in the window, else m (a row that cannot exist there,
    // whose residual with the target m is 0, as its coefficient is).
    std::vector<std::uint32_t> fwd, src, srcRow, mxTo, myTo;
    Field srcCt;  // ct(src(i)), 0 where none (setWeights)
    [[nodiscard]] bool linkedOnce() const { return !fwd.empty(); }
    [[nodiscard]] std::size_t pixels() const { return std::size_t(width) * std::size_t(height); }
    [[nodiscard]] std::size_t size() const { return pixels() * std::size_t(frames); }
    // The diagonal of A (Jacobi's, and the V-cycles'): the operator's own applies diag and
    // gathers the mixed rows separately.
    [[nodiscard]] const Field& jacobiDiag() const { return cmx.empty() ? diag : mixedDiag; }
};

// Row weights shared by the channels (IRLS; all 1 for L2). Dropped rows are 0.
struct Weights {
    Field primal, dx, dy, dt, boundary;  // boundary: W·H rows to the previous frame, or empty
    Field mx, my;                        // mixed rows ((F − 1)·W·H), or empty without them
    Field bmx, bmy;                      // mixed rows to the previous frame (W·H), or empty
};

// Pixels per range of the parallel loops. Sums are taken per range and added in range order,
// so the result does not depend on the number of threads.
constexpr std::size_t kGrain = 8192;

inline std::size_t rangesOf(std::size_t n) {
    return (n + kGrain - 1) / kGrain;
}

// f.resize(n), a new buffer advised for huge pages (util/huge_pages.h): the window's fields
// are tens of MiB, and a page fault per 4 KiB cost a fifth of a solve on a virtual machine.
void sized(Field& f, std::size_t n);
// `to` = `from`, in a buffer advised for huge pages.
void copied(Field& to, const Field& from);
// f = n copies of v, in f's buffer where it is large enough (else one advised for huge pages).
void filled(Field& f, std::size_t n, double v);

// The residual of the mixed row at m (step s = 1 or W) for the iterate x:
// (x_π(m)+s − x_π(m)) − (x_m+s − x_m).
inline double mixedResidual(const Operator& op, const Field& x, std::size_t m, std::size_t s) {
    const std::size_t b = op.next[m];
    return (x[b + s] - x[b]) - (x[m + s] - x[m]);
}

// The mixed rows' part of A x is Mᵀ C M x (M: four ±1 per row). A pass before the operator
// stores C M x per row (0 where there is none), so that the operator only gathers each pixel's
// rows, instead of evaluating every row at each of its four pixels.
struct MixedRowValues {
    std::array<Field, 3> x, y;  // per channel, (F − 1)·W·H
};

// The size of the row values: in the linkedOnce() form n + 1, the ones past the rows 0
// (resize's), for the operator's gather without tests.
inline std::size_t rowValuesSize(const Operator& op) {
    return op.linkedOnce() ? op.size() + 1 : op.cmx.size();
}

// C M v per row for the channels in `which` (MixedRowValues), on `threads`.
void mixedRowValues(const Operator& op, const std::array<Field, 3>& v, const std::array<bool, 3>& which,
                    MixedRowValues& out, std::uint32_t threads);

// (Mᵀ r)_k for the row values r of one direction (step s): + at m and π(m)+s, − at m+s and π(m);
// `unsign`: every sign +, the sum of the values of the rows at k.
inline double gatherMixed(const Operator& op, const Field& r, std::size_t k, std::size_t s,
                          bool unsign = false) {
    const std::size_t nt = r.size();
    const double minus = unsign ? 1.0 : -1.0;
    double v = 0.0;
    if (k < nt) v += r[k];
    if (k >= s && k - s < nt) v += minus * r[k - s];
    for (std::uint32_t j = op.backStart[k]; j < op.backStart[k + 1]; ++j) v += minus * r[op.back[j]];
    if (k >= s)
        for (std::uint32_t j = op.backStart[k - s]; j < op.backStart[k - s + 1]; ++j) v += r[op.back[j]];
    return v;
}

// gatherMixed in the linkedOnce() form, at k ≥ s: r holds n + 1 values (0 past the rows) and
// sr[k] is k's source (n where none), so every term is there without a test.
inline double gatherMixedLinked(const double* __restrict r, const std::uint32_t* __restrict sr, std::size_t k,
                                std::size_t s) {
    return (r[k] - r[k - s]) - (r[sr[k]] - r[sr[k - s]]);
}

// The pixel of frame 0 that each pixel of the previous frame joins (the same pixel without
// previousPartner); empty without a previous frame.
std::vector<std::uint32_t> previousNext(const SpaceTimeProblem& p);

// The structure of the operator (neighbours), which the weights do not change, into op (its
// buffers reused).
void makeStructure(const SpaceTimeProblem& p, Operator& op);

// The coefficients of the row weights `wt` into `op` (made by makeStructure), on `threads`: op
// takes wt's arrays over and scales them in place (takeWeightStorage hands them back for the
// next round's weights), so that a window holds its weights once.
void setWeights(const SpaceTimeProblem& p, Weights&& wt, Operator& op, std::uint32_t threads);

// The arrays of op's row weights (setWeights's), for the next round's weights to be written
// into; op's coefficients are gone until setWeights.
Weights takeWeightStorage(Operator& op);

// b = Pᵀ W target for the three channels: α² wp t minus the weighted divergence of the
// (dx, dy, dt) field, plus the rows from the previous frame.
// `targets`: scratch for the mixed rows' C t per row, gathered as the operator gathers C M x.
void rhs(const SpaceTimeProblem& p, const Operator& op, std::array<Field, 3>& b, MixedRowValues& targets,
         std::uint32_t threads);

// (A x)_i for i in [begin, end); `rowsX`, `rowsY`: x's mixed row values C M x
// (mixedRowValues), or null without mixed rows.
void applyRange(const Operator& op, const Field& x, Field& y, std::size_t begin, std::size_t end,
                const Field* rowsX, const Field* rowsY);

// fn(c, begin, end) for the channels in `which` over ranges of one frame's `np` pixels.
template <class Fn>
void overFrame(std::uint32_t threads, std::size_t np, const std::array<bool, 3>& which, const Fn& fn) {
    parallelRanges(threads, np, kGrain, [&](std::size_t begin, std::size_t end) {
        for (int c = 0; c < 3; ++c)
            if (which[c]) fn(c, begin, end);
    });
}

}  // namespace gdpt::spacetime
