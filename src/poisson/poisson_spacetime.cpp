// poisson_spacetime.cpp — the space-time screened Poisson reconstruction (poisson_spacetime.h).
#include "poisson/poisson_spacetime.h"

#include <Eigen/Sparse>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <numeric>
#include <tuple>
#include <vector>

#include "poisson/host_vcycle.h"
#include "util/error.h"
#include "util/huge_pages.h"
#include "util/parallel.h"
#include "util/timer.h"

namespace gdpt {
namespace {

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

std::size_t rangesOf(std::size_t n) {
    return (n + kGrain - 1) / kGrain;
}

// f.resize(n), a new buffer advised for huge pages (util/huge_pages.h): the window's fields
// are tens of MiB, and a page fault per 4 KiB cost a fifth of a solve on a virtual machine.
void sized(Field& f, std::size_t n) {
    if (f.capacity() < n) {
        Field fresh;
        reserveHuge(fresh, n);
        f.swap(fresh);
    }
    f.resize(n);
}

// `to` = `from`, in a buffer advised for huge pages.
void copied(Field& to, const Field& from) {
    sized(to, from.size());
    std::copy(from.begin(), from.end(), to.begin());
}

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
std::size_t rowValuesSize(const Operator& op) {
    return op.linkedOnce() ? op.size() + 1 : op.cmx.size();
}

void mixedRowValues(const Operator& op, const std::array<Field, 3>& v, const std::array<bool, 3>& which,
                    MixedRowValues& out, std::uint32_t threads) {
    const std::size_t nt = op.cmx.size(), w = std::size_t(op.width);
    const std::size_t size = rowValuesSize(op);
    for (int c = 0; c < 3; ++c) {
        if (!which[c]) continue;
        sized(out.x[c], size);
        sized(out.y[c], size);
    }
    parallelRanges(threads, nt, kGrain, [&](std::size_t begin, std::size_t end) {
        for (int c = 0; c < 3; ++c) {
            if (!which[c]) continue;
            if (op.linkedOnce()) {
                const double* __restrict x = v[c].data();
                const double* __restrict cmx = op.cmx.data();
                const double* __restrict cmy = op.cmy.data();
                const std::uint32_t* __restrict tx = op.mxTo.data();
                const std::uint32_t* __restrict ty = op.myTo.data();
                double* __restrict rx = out.x[c].data();
                double* __restrict ry = out.y[c].data();
                for (std::size_t m = begin; m < end; ++m) {
                    const double xm = x[m];
                    rx[m] = cmx[m] * ((x[tx[m] + 1] - x[tx[m]]) - (x[m + 1] - xm));
                    ry[m] = cmy[m] * ((x[ty[m] + w] - x[ty[m]]) - (x[m + w] - xm));
                }
                continue;
            }
            for (std::size_t m = begin; m < end; ++m) {
                out.x[c][m] = op.cmx[m] != 0.0 ? op.cmx[m] * mixedResidual(op, v[c], m, 1) : 0.0;
                out.y[c][m] = op.cmy[m] != 0.0 ? op.cmy[m] * mixedResidual(op, v[c], m, w) : 0.0;
            }
        }
    });
}

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

// The temporal neighbour of every pixel in the window (frame f's i → frame f+1's π(i)), a
// window index, or kNoTemporalPartner where π names none (and in the last frame), into `next`.
void nextPixels(const SpaceTimeProblem& p, std::vector<std::uint32_t>& next) {
    const std::size_t np = p.pixels(), nt = np * std::size_t(p.frames - 1);
    next.assign(p.size(), kNoTemporalPartner);
    for (std::size_t i = 0; i < nt; ++i) {
        const std::size_t frameStart = (i / np + 1) * np;
        if (p.temporalPartner.empty())
            next[i] = std::uint32_t(i + np);
        else
            next[i] = p.temporalPartner[i] == kNoTemporalPartner
                          ? kNoTemporalPartner
                          : std::uint32_t(frameStart + p.temporalPartner[i]);
    }
}

// The pixel of frame 0 that each pixel of the previous frame joins (the same pixel without
// previousPartner); empty without a previous frame.
std::vector<std::uint32_t> previousNext(const SpaceTimeProblem& p) {
    if (p.previous[0].empty()) return {};
    if (!p.previousPartner.empty()) return p.previousPartner;
    std::vector<std::uint32_t> next(p.pixels());
    std::iota(next.begin(), next.end(), 0u);
    return next;
}

// The mixed rows' weights (1, or weightX, weightY where given) of rows i in [0, count) whose pixel
// pair k, k+s (k = i mod W·H) both have partners, carried rigidly: π(i+s) = π(i) + s, with
// π(i) + s in π(i)'s row (x: s = 1) or frame (y: s = W). wx, wy keep their values elsewhere.
template <class PartnerOf>
void rigidMixedRows(std::size_t count, std::size_t np, std::size_t w, std::size_t h,
                    const PartnerOf& partnerOf, const Field& weightX, const Field& weightY, Field& wx,
                    Field& wy) {
    for (std::size_t i = 0; i < count; ++i) {
        const std::uint32_t to = partnerOf(i);
        if (to == kNoTemporalPartner) continue;
        const std::size_t k = i % np;
        if (k % w + 1 < w && std::size_t(to) % w + 1 < w && partnerOf(i + 1) == to + 1)
            wx[i] = weightX.empty() ? 1.0 : weightX[i];
        if (k / w + 1 < h && std::size_t(to) / w + 1 < h && partnerOf(i + w) == to + w)
            wy[i] = weightY.empty() ? 1.0 : weightY[i];
    }
}

// f = n copies of v, in f's buffer where it is large enough (else one advised for huge pages).
void filled(Field& f, std::size_t n, double v) {
    sized(f, n);
    std::fill(f.begin(), f.end(), v);
}

// The rows' own weights (1, or the problem's; 0 for the rows that do not exist), into wt (its
// buffers reused).
void unitWeights(const SpaceTimeProblem& p, Weights& wt) {
    const std::size_t n = p.size(), np = p.pixels(), w = std::size_t(p.width);
    filled(wt.primal, n, 1.0);
    filled(wt.dx, n, 1.0);
    filled(wt.dy, n, 1.0);
    filled(wt.dt, np * std::size_t(p.frames - 1), 1.0);
    filled(wt.boundary, p.previous[0].empty() ? 0 : np, 1.0);
    for (std::size_t i = 0; i < n; ++i) {
        if (!p.weightPrimal.empty()) wt.primal[i] = p.weightPrimal[i];
        if (!p.weightDx.empty()) wt.dx[i] = p.weightDx[i];
        if (!p.weightDy.empty()) wt.dy[i] = p.weightDy[i];
        if (!spaceTimeHasDx(p, i)) wt.dx[i] = 0.0;
        if (!spaceTimeHasDy(p, i)) wt.dy[i] = 0.0;
    }
    if (!p.weightDt.empty()) std::copy(p.weightDt.begin(), p.weightDt.end(), wt.dt.begin());
    if (!p.weightDtPrevious.empty() && !wt.boundary.empty())
        std::copy(p.weightDtPrevious.begin(), p.weightDtPrevious.end(), wt.boundary.begin());
    for (std::size_t i = 0; i < p.temporalPartner.size(); ++i)
        if (p.temporalPartner[i] == kNoTemporalPartner) wt.dt[i] = 0.0;
    for (std::size_t j = 0; j < p.previousPartner.size() && !wt.boundary.empty(); ++j)
        if (p.previousPartner[j] == kNoTemporalPartner) wt.boundary[j] = 0.0;
    const std::size_t h = std::size_t(p.height);
    wt.bmx.clear(), wt.bmy.clear();
    if (!p.dxtPrevious[0].empty()) {
        // The same rule for the rows from the previous frame's pixel j into frame 0.
        const std::vector<std::uint32_t> to = previousNext(p);
        filled(wt.bmx, np, 0.0);
        filled(wt.bmy, np, 0.0);
        rigidMixedRows(
            np, np, w, h, [&](std::size_t j) { return to[j]; }, p.weightDxtPrevious, p.weightDytPrevious,
            wt.bmx, wt.bmy);
    }
    if (p.gamma > 0.0) {
        const std::size_t nt = np * std::size_t(p.frames - 1);
        const auto partner = [&](std::size_t i) {
            return p.temporalPartner.empty() ? std::uint32_t(i % np) : p.temporalPartner[i];
        };
        filled(wt.mx, nt, 0.0);
        filled(wt.my, nt, 0.0);
        rigidMixedRows(nt, np, w, h, partner, p.weightDxt, p.weightDyt, wt.mx, wt.my);
    } else {
        wt.mx.clear(), wt.my.clear();
    }
}

// The structure of the operator (neighbours), which the weights do not change, into op (its
// buffers reused).
void makeStructure(const SpaceTimeProblem& p, Operator& op) {
    op.width = p.width;
    op.height = p.height;
    op.frames = p.frames;
    const std::size_t n = p.size();
    nextPixels(p, op.next);
    op.bnext = previousNext(p);
    op.fwd.clear(), op.src.clear(), op.srcRow.clear(), op.mxTo.clear(), op.myTo.clear();
    op.backStart.assign(n + 1, 0);
    for (std::size_t i = 0; i < n; ++i)
        if (op.next[i] != kNoTemporalPartner) ++op.backStart[op.next[i] + 1];
    for (std::size_t i = 0; i < n; ++i) op.backStart[i + 1] += op.backStart[i];
    op.back.resize(op.backStart[n]);
    std::vector<std::uint32_t> fill(op.backStart.begin(), op.backStart.end() - 1);
    for (std::size_t i = 0; i < n; ++i)
        if (op.next[i] != kNoTemporalPartner) op.back[fill[op.next[i]]++] = std::uint32_t(i);
    for (std::size_t i = 0; i < n; ++i)
        if (op.backStart[i + 1] - op.backStart[i] > 1) return;  // no linkedOnce() form
    op.fwd.resize(n);
    op.src.resize(n);
    op.srcRow.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        op.fwd[i] = op.next[i] == kNoTemporalPartner ? std::uint32_t(i) : op.next[i];
        const bool has = op.backStart[i + 1] > op.backStart[i];
        op.src[i] = has ? op.back[op.backStart[i]] : std::uint32_t(i);
        op.srcRow[i] = has ? op.back[op.backStart[i]] : std::uint32_t(n);
    }
    if (p.gamma > 0.0) {
        const std::size_t nt = n - p.pixels(), w = std::size_t(p.width);
        op.mxTo.resize(nt);
        op.myTo.resize(nt);
        for (std::size_t m = 0; m < nt; ++m) {
            const std::size_t b = op.next[m];
            op.mxTo[m] = std::uint32_t(b != kNoTemporalPartner && b + 1 < n ? b : m);
            op.myTo[m] = std::uint32_t(b != kNoTemporalPartner && b + w < n ? b : m);
        }
    }
}

// The coefficients of the row weights `wt` into `op` (made by makeStructure), on `threads`: op
// takes wt's arrays over and scales them in place (takeWeightStorage hands them back for the
// next round's weights), so that a window holds its weights once.
void setWeights(const SpaceTimeProblem& p, Weights&& wt, Operator& op, std::uint32_t threads) {
    const std::size_t n = p.size(), np = p.pixels(), w = std::size_t(p.width);
    const double a2 = p.alpha * p.alpha, b2 = p.beta * p.beta, g2 = p.gamma * p.gamma;
    const auto scaled = [&](Field& f, double by) {
        parallelRanges(threads, f.size(), kGrain, [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i) f[i] *= by;
        });
    };
    op.cx = std::move(wt.dx);
    op.cy = std::move(wt.dy);
    op.bmx = std::move(wt.bmx);
    op.bmy = std::move(wt.bmy);
    if (op.bmx.empty()) {
        op.bmy.clear(), op.cx0.clear(), op.cy0.clear();
    } else {
        // Each mixed row to the previous frame is an edge of frame 0 (above).
        op.cx0.assign(op.cx.begin(), op.cx.begin() + std::ptrdiff_t(np));
        op.cy0.assign(op.cy.begin(), op.cy.begin() + std::ptrdiff_t(np));
        for (std::size_t j = 0; j < np; ++j) {
            op.bmx[j] *= g2;
            op.bmy[j] *= g2;
            if (op.bmx[j] != 0.0) op.cx[op.bnext[j]] += op.bmx[j];
            if (op.bmy[j] != 0.0) op.cy[op.bnext[j]] += op.bmy[j];
        }
    }
    // The temporal rows' weights are (F − 1)·W·H (or already n from takeWeightStorage); the
    // last frame's coefficients are 0.
    op.ct = std::move(wt.dt);
    op.ct.resize(n, 0.0);
    op.cp = std::move(wt.primal);
    sized(op.diag, n);
    parallelRanges(threads, n, kGrain, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) {
            op.ct[i] = i + np < n && op.next[i] != kNoTemporalPartner ? b2 * op.ct[i] : 0.0;
            op.cp[i] *= a2;
        }
    });
    parallelRanges(threads, n, kGrain, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) {
            double d = op.cp[i] + op.cx[i] + op.cy[i] + op.ct[i];
            if (i >= 1) d += op.cx[i - 1];
            if (i >= w) d += op.cy[i - w];
            for (std::uint32_t k = op.backStart[i]; k < op.backStart[i + 1]; ++k) d += op.ct[op.back[k]];
            op.diag[i] = d;
        }
    });
    if (op.linkedOnce()) {
        sized(op.srcCt, n);
        parallelRanges(threads, n, kGrain, [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i) op.srcCt[i] = op.src[i] != i ? op.ct[op.src[i]] : 0.0;
        });
    }
    op.cb = std::move(wt.boundary);
    for (std::size_t j = 0; j < op.cb.size(); ++j) {
        op.cb[j] *= b2;
        if (op.cb[j] != 0.0) op.diag[op.bnext[j]] += op.cb[j];
    }
    op.cmx = std::move(wt.mx);
    op.cmy = std::move(wt.my);
    if (op.cmx.empty()) return;
    scaled(op.cmx, g2);
    scaled(op.cmy, g2);
    // Each row adds its coefficient to the diagonal at its four pixels (σ² = 1).
    copied(op.mixedDiag, op.diag);
    parallelRanges(threads, n, kGrain, [&](std::size_t begin, std::size_t end) {
        for (std::size_t k = begin; k < end; ++k)
            op.mixedDiag[k] += gatherMixed(op, op.cmx, k, 1, true) + gatherMixed(op, op.cmy, k, w, true);
    });
}

// The arrays of op's row weights (setWeights's), for the next round's weights to be written
// into; op's coefficients are gone until setWeights.
Weights takeWeightStorage(Operator& op) {
    Weights wt;
    wt.primal = std::move(op.cp);
    wt.dx = std::move(op.cx);
    wt.dy = std::move(op.cy);
    wt.dt = std::move(op.ct);
    wt.boundary = std::move(op.cb);
    wt.mx = std::move(op.cmx);
    wt.my = std::move(op.cmy);
    wt.bmx = std::move(op.bmx);
    wt.bmy = std::move(op.bmy);
    return wt;
}

// to = from, each array in to's buffer where it is large enough.
void copyWeights(const Weights& from, Weights& to) {
    copied(to.primal, from.primal);
    copied(to.dx, from.dx);
    copied(to.dy, from.dy);
    copied(to.dt, from.dt);
    copied(to.boundary, from.boundary);
    copied(to.mx, from.mx);
    copied(to.my, from.my);
    copied(to.bmx, from.bmx);
    copied(to.bmy, from.bmy);
}

// b = Pᵀ W target for the three channels: α² wp t minus the weighted divergence of the
// (dx, dy, dt) field, plus the rows from the previous frame.
// `targets`: scratch for the mixed rows' C t per row, gathered as the operator gathers C M x.
void rhs(const SpaceTimeProblem& p, const Operator& op, std::array<Field, 3>& b, MixedRowValues& targets,
         std::uint32_t threads) {
    const std::size_t n = op.size(), w = std::size_t(op.width);
    for (Field& f : b) sized(f, n);
    const bool mixed = !op.cmx.empty();
    if (mixed) {
        // (The operator's size, so that the scratch is allocated once: gatherMixed takes either.)
        for (int c = 0; c < 3; ++c) {
            sized(targets.x[c], rowValuesSize(op));
            sized(targets.y[c], rowValuesSize(op));
        }
        parallelRanges(threads, op.cmx.size(), kGrain, [&](std::size_t begin, std::size_t end) {
            for (int c = 0; c < 3; ++c)
                for (std::size_t m = begin; m < end; ++m) {
                    targets.x[c][m] = op.cmx[m] * p.dxt[c][m];
                    targets.y[c][m] = op.cmy[m] * p.dyt[c][m];
                }
        });
    }
    parallelRanges(threads, n, kGrain, [&](std::size_t begin, std::size_t end) {
        for (int c = 0; c < 3; ++c) {
            const Field &dx = p.dx[c], &dy = p.dy[c], &dt = p.dt[c];
            // The dx, dy rows' own coefficients (frame 0's cx, cy also hold the mixed rows to
            // the previous frame, whose targets are added below).
            const auto cxRow = [&](std::size_t i) { return i < op.cx0.size() ? op.cx0[i] : op.cx[i]; };
            const auto cyRow = [&](std::size_t i) { return i < op.cy0.size() ? op.cy0[i] : op.cy[i]; };
            const auto at = [&](std::size_t i) {
                double v = op.cp[i] * p.primal[c][i] - cxRow(i) * dx[i] - cyRow(i) * dy[i];
                if (op.ct[i] != 0.0) v -= op.ct[i] * dt[i];
                if (i >= 1) v += cxRow(i - 1) * dx[i - 1];
                if (i >= w) v += cyRow(i - w) * dy[i - w];
                for (std::uint32_t k = op.backStart[i]; k < op.backStart[i + 1]; ++k)
                    v += op.ct[op.back[k]] * dt[op.back[k]];
                if (mixed) v += gatherMixed(op, targets.x[c], i, 1) + gatherMixed(op, targets.y[c], i, w);
                b[c][i] = v;
            };
            // The linkedOnce() form: away from the window's first and last rows and from frame
            // 0's rows to the frame before (cx0, cy0), at's terms without the lists and the tests
            // (a missing source has coefficient 0; a missing mixed row the value 0).
            std::size_t lo = end, hi = end;
            if (op.linkedOnce() && n > 2 * w) {
                lo = std::clamp(std::max(w, op.cx0.size()), begin, end);
                hi = std::clamp(n - w, lo, end);
            }
            for (std::size_t i = begin; i < lo; ++i) at(i);
            const double* __restrict cp = op.cp.data();
            const double* __restrict cx = op.cx.data();
            const double* __restrict cy = op.cy.data();
            const double* __restrict ct = op.ct.data();
            const double* __restrict sct = op.srcCt.data();
            const std::uint32_t* __restrict src = op.src.data();
            const std::uint32_t* __restrict sr = op.srcRow.data();
            const double* __restrict t = p.primal[c].data();
            const double* __restrict tx = dx.data();
            const double* __restrict ty = dy.data();
            const double* __restrict tt = dt.data();
            const double* __restrict rx = mixed ? targets.x[c].data() : nullptr;
            const double* __restrict ry = mixed ? targets.y[c].data() : nullptr;
            for (std::size_t i = lo; i < hi; ++i) {
                double v = cp[i] * t[i] - cx[i] * tx[i] - cy[i] * ty[i];
                if (ct[i] != 0.0) v -= ct[i] * tt[i];
                v += cx[i - 1] * tx[i - 1];
                v += cy[i - w] * ty[i - w];
                if (sct[i] != 0.0) v += sct[i] * tt[src[i]];
                if (mixed) {
                    v += gatherMixedLinked(rx, sr, i, 1);
                    v += gatherMixedLinked(ry, sr, i, w);
                }
                b[c][i] = v;
            }
            for (std::size_t i = hi; i < end; ++i) at(i);
        }
    });
    for (int c = 0; c < 3; ++c) {
        for (std::size_t j = 0; j < op.cb.size(); ++j)
            if (op.cb[j] != 0.0) b[c][op.bnext[j]] += op.cb[j] * (p.previous[c][j] + p.dtPrevious[c][j]);
        // Mixed rows to the previous frame: (x_q+s − x_q) with target previous_j+s − previous_j + dst_j.
        for (std::size_t j = 0; j < op.bmx.size(); ++j) {
            const std::size_t q = op.bnext[j];
            if (op.bmx[j] != 0.0) {
                const double t = op.bmx[j] * (p.previous[c][j + 1] - p.previous[c][j] + p.dxtPrevious[c][j]);
                b[c][q + 1] += t;
                b[c][q] -= t;
            }
            if (op.bmy[j] != 0.0) {
                const double t = op.bmy[j] * (p.previous[c][j + w] - p.previous[c][j] + p.dytPrevious[c][j]);
                b[c][q + w] += t;
                b[c][q] -= t;
            }
        }
    }
}

// (A x)_i for i in [begin, end); `rowsX`, `rowsY`: x's mixed row values C M x
// (mixedRowValues), or null without mixed rows. (One pass over the three channels, reading each
// pixel's lists once, measured 10-15 % slower on windows with mixed rows.)
void applyRangeGeneral(const Operator& op, const Field& x, Field& y, std::size_t begin, std::size_t end,
                       const Field* rowsX, const Field* rowsY) {
    const std::size_t n = op.size(), w = std::size_t(op.width);
    for (std::size_t i = begin; i < end; ++i) {
        double v = op.diag[i] * x[i];
        if (i + 1 < n) v -= op.cx[i] * x[i + 1];
        if (i >= 1) v -= op.cx[i - 1] * x[i - 1];
        if (i + w < n) v -= op.cy[i] * x[i + w];
        if (i >= w) v -= op.cy[i - w] * x[i - w];
        if (op.next[i] != kNoTemporalPartner) v -= op.ct[i] * x[op.next[i]];
        for (std::uint32_t k = op.backStart[i]; k < op.backStart[i + 1]; ++k) {
            const std::uint32_t j = op.back[k];
            v -= op.ct[j] * x[j];
        }
        if (rowsX) v += gatherMixed(op, *rowsX, i, 1) + gatherMixed(op, *rowsY, i, w);
        y[i] = v;
    }
}

// applyRange of a window of several frames in its linkedOnce() form: the pixels [lo, hi) away
// from the window's first and last rows without a test (the neighbours across a row's end have
// coefficient 0, a missing temporal neighbour is the pixel itself with coefficient 0, a missing
// mixed row has the value 0), the others by applyRangeGeneral. The same terms as
// applyRangeGeneral, in another order.
void applyRangeLinked(const Operator& op, const Field& x, Field& y, std::size_t begin, std::size_t lo,
                      std::size_t hi, std::size_t end, const Field* rowsX, const Field* rowsY) {
    const std::size_t w = std::size_t(op.width);
    applyRangeGeneral(op, x, y, begin, lo, rowsX, rowsY);
    const double* __restrict xs = x.data();
    const double* __restrict d = op.diag.data();
    const double* __restrict cx = op.cx.data();
    const double* __restrict cy = op.cy.data();
    const double* __restrict ct = op.ct.data();
    const double* __restrict sct = op.srcCt.data();
    const std::uint32_t* __restrict fwd = op.fwd.data();
    const std::uint32_t* __restrict src = op.src.data();
    double* __restrict ys = y.data();
    // The graph Laplacian's terms: the frame's neighbours, the temporal neighbour and source.
    const auto laplacian = [&](std::size_t i) {
        double v = d[i] * xs[i];
        v -= cx[i] * xs[i + 1];
        v -= cx[i - 1] * xs[i - 1];
        v -= cy[i] * xs[i + w];
        v -= cy[i - w] * xs[i - w];
        v -= ct[i] * xs[fwd[i]];
        v -= sct[i] * xs[src[i]];
        return v;
    };
    if (rowsX) {
        const double* __restrict rx = rowsX->data();
        const double* __restrict ry = rowsY->data();
        const std::uint32_t* __restrict sr = op.srcRow.data();
        for (std::size_t i = lo; i < hi; ++i) {
            double v = laplacian(i);
            v += gatherMixedLinked(rx, sr, i, 1);
            v += gatherMixedLinked(ry, sr, i, w);
            ys[i] = v;
        }
    } else {
        for (std::size_t i = lo; i < hi; ++i) ys[i] = laplacian(i);
    }
    applyRangeGeneral(op, x, y, hi, end, rowsX, rowsY);
}

// (A x)_i for i in [begin, end): one frame (no temporal or mixed rows) takes the 5-point stencil
// without a test per neighbour at the pixels that have all four in the field (rows 1 .. H−2,
// and the neighbours across a row's end, whose coefficient is 0); the same operations in the
// same order as applyRangeGeneral, so the same bits. The one-frame solve is G-PT's
// reconstruction on a CPU device, where this loop is most of the time.
void applyRange(const Operator& op, const Field& x, Field& y, std::size_t begin, std::size_t end,
                const Field* rowsX, const Field* rowsY) {
    const std::size_t n = op.size(), w = std::size_t(op.width);
    if (n <= 2 * w || (op.frames != 1 && !op.linkedOnce())) {
        applyRangeGeneral(op, x, y, begin, end, rowsX, rowsY);
        return;
    }
    const std::size_t lo = std::clamp(w, begin, end), hi = std::clamp(n - w, lo, end);
    if (op.frames != 1) {
        applyRangeLinked(op, x, y, begin, lo, hi, end, rowsX, rowsY);
        return;
    }
    applyRangeGeneral(op, x, y, begin, lo, nullptr, nullptr);
    const double* __restrict xs = x.data();
    const double* __restrict d = op.diag.data();
    const double* __restrict cx = op.cx.data();
    const double* __restrict cy = op.cy.data();
    double* __restrict ys = y.data();
    for (std::size_t i = lo; i < hi; ++i) {
        double v = d[i] * xs[i];
        v -= cx[i] * xs[i + 1];
        v -= cx[i - 1] * xs[i - 1];
        v -= cy[i] * xs[i + w];
        v -= cy[i - w] * xs[i - w];
        ys[i] = v;
    }
    applyRangeGeneral(op, x, y, hi, end, nullptr, nullptr);
}

// fn(c, begin, end) for the channels in `which` over ranges of one frame's `np` pixels.
template <class Fn>
void overFrame(std::uint32_t threads, std::size_t np, const std::array<bool, 3>& which, const Fn& fn) {
    parallelRanges(threads, np, kGrain, [&](std::size_t begin, std::size_t end) {
        for (int c = 0; c < 3; ++c)
            if (which[c]) fn(c, begin, end);
    });
}

// CG's multigrid preconditioner: one V-cycle per frame (host_vcycle.h), as block Jacobi or block
// Gauss-Seidel over the frames. Each frame's diagonal block of A is a 5-point graph Laplacian
// (its dx, dy rows, and the halves of the mixed rows inside one frame: a mixed row joins m with
// m+s and π(m) with π(m)+s by edges of its weight) plus the diagonal; the rows between frames
// (dt, the mixed rows' cross terms) are left to CG (block Jacobi) or applied between the
// frames' cycles (block Gauss-Seidel). One frame is HostVcycle on the operator itself.
class FrameBlocks {
public:
    void build(const Operator& op, std::uint32_t threads) {
        const std::size_t np = op.pixels(), frames = std::size_t(op.frames);
        cycles_.resize(frames);
        if (frames == 1) {
            cycles_[0].build(op.width, op.height, op.cx, op.cy, op.diag, threads);
            return;
        }
        cx_.resize(frames);
        cy_.resize(frames);
        diag_.resize(frames);
        const std::size_t nt = op.cmx.size();
        // The frames' blocks and hierarchies side by side (each on one thread: a frame's coarse
        // levels are too small to share).
        parallelFor(threads, frames, [&](std::size_t f) {
            const std::size_t at = f * np;
            cx_[f].assign(op.cx.begin() + std::ptrdiff_t(at), op.cx.begin() + std::ptrdiff_t(at + np));
            cy_[f].assign(op.cy.begin() + std::ptrdiff_t(at), op.cy.begin() + std::ptrdiff_t(at + np));
            diag_[f].assign(op.jacobiDiag().begin() + std::ptrdiff_t(at),
                            op.jacobiDiag().begin() + std::ptrdiff_t(at + np));
            if (nt > 0)
                for (std::size_t i = 0; i < np; ++i) {
                    const std::size_t k = at + i;
                    if (k < nt) cx_[f][i] += op.cmx[k], cy_[f][i] += op.cmy[k];
                    for (std::uint32_t j = op.backStart[k]; j < op.backStart[k + 1]; ++j)
                        cx_[f][i] += op.cmx[op.back[j]], cy_[f][i] += op.cmy[op.back[j]];
                }
            cycles_[f].build(op.width, op.height, cx_[f], cy_[f], diag_[f], 1);
        });
    }

    // z = M⁻¹ r for the channels in `which`: block Jacobi (a V-cycle per frame), or with
    // `coupled` and several frames symmetric block Gauss-Seidel (applyCoupled).
    void apply(const Operator& op, const std::array<Field, 3>& r, std::array<Field, 3>& z,
               const std::array<bool, 3>& which, std::uint32_t threads, bool coupled) {
        if (coupled && cycles_.size() > 1) {
            applyCoupled(op, r, z, which, threads);
            return;
        }
        const std::size_t np = r[0].size() / cycles_.size();
        for (std::size_t f = 0; f < cycles_.size(); ++f) {
            std::array<const double*, 3> rf{};
            std::array<double*, 3> zf{};
            for (int c = 0; c < 3; ++c)
                if (which[c]) rf[c] = r[c].data() + f * np, zf[c] = z[c].data() + f * np;
            cycles_[f].applyTo(rf, zf, which, threads);
        }
    }

private:
    // Symmetric block Gauss-Seidel over the frames, each block's inverse approximated by its
    // V-cycle V_f: forward t_f = V_f (r_f − A_f,f−1 t_f−1), backward z_f = t_f − V_f A_f,f+1 z_f+1.
    // With A_f+1,f = A_f,f+1ᵀ, M⁻¹ = (V⁻¹ + U)⁻¹ V⁻¹ (V⁻¹ + L)⁻¹ (L, U the blocks below and above
    // the diagonal), symmetric positive definite for SPD V_f: a valid CG preconditioner that,
    // unlike block Jacobi, sees the coupling between neighbouring frames (the temporal rows and
    // the mixed rows' terms across frames), which IRLS makes stiff where the frames agree.
    void applyCoupled(const Operator& op, const std::array<Field, 3>& r, std::array<Field, 3>& z,
                      const std::array<bool, 3>& which, std::uint32_t threads) {
        const std::size_t frames = cycles_.size(), np = op.pixels(), w = std::size_t(op.width);
        const bool mixed = !op.cmx.empty();
        for (int c = 0; c < 3; ++c) {
            if (!which[c]) continue;
            sized(s_[c], np);
            sized(e_[c], np);
            // One more, always 0: the value of a missing row (linkedOnce()).
            if (mixed) sized(rx_[c], np + 1), sized(ry_[c], np + 1);
        }
        const auto cycle = [&](std::size_t f, std::array<double*, 3> out) {
            std::array<const double*, 3> in{};
            for (int c = 0; c < 3; ++c)
                if (which[c]) in[c] = s_[c].data();
            cycles_[f].applyTo(in, out, which, threads);
        };
        // Forward: s = r_f + (the temporal rows' −A_f,f−1 t) − (the mixed rows' A_f,f−1 t), where
        // t is z, filled for the frames before f. A mixed row at m of frame f−1 (b = next(m))
        // has t's part c (t_m − t_m+s) (frame f's part is still 0) and enters A t at b with
        // sign −1 and at b + s with +1.
        for (std::size_t f = 0; f < frames; ++f) {
            const std::size_t base = f * np, prev = base - np;
            if (mixed && f > 0)
                overFrame(threads, np, which, [&](int c, std::size_t begin, std::size_t end) {
                    // (m + W is in the window: m is in a frame before the last; a missing row's
                    // coefficient is 0.)
                    const double* __restrict t = z[c].data() + prev;
                    const double* __restrict cmx = op.cmx.data() + prev;
                    const double* __restrict cmy = op.cmy.data() + prev;
                    double* __restrict rx = rx_[c].data();
                    double* __restrict ry = ry_[c].data();
                    for (std::size_t i = begin; i < end; ++i) {
                        rx[i] = cmx[i] * (t[i] - t[i + 1]);
                        ry[i] = cmy[i] * (t[i] - t[i + w]);
                    }
                });
            overFrame(threads, np, which, [&](int c, std::size_t begin, std::size_t end) {
                const Field& t = z[c];
                if (f > 0 && op.linkedOnce()) {
                    const std::size_t lo = std::clamp(w, begin, end);
                    forwardLinked(op, r[c], t, base, lo, end, mixed, c);
                    end = lo;
                }
                for (std::size_t i = begin; i < end; ++i) {
                    const std::size_t k = base + i;
                    double v = r[c][k];
                    if (f > 0) {
                        for (std::uint32_t j = op.backStart[k]; j < op.backStart[k + 1]; ++j) {
                            const std::uint32_t m = op.back[j];
                            v += op.ct[m] * t[m];
                            if (mixed) v += rx_[c][m - prev] + ry_[c][m - prev];
                        }
                        if (mixed && i >= 1)
                            for (std::uint32_t j = op.backStart[k - 1]; j < op.backStart[k]; ++j)
                                v -= rx_[c][op.back[j] - prev];
                        if (mixed && i >= w)
                            for (std::uint32_t j = op.backStart[k - w]; j < op.backStart[k - w + 1]; ++j)
                                v -= ry_[c][op.back[j] - prev];
                    }
                    s_[c][i] = v;
                }
            });
            std::array<double*, 3> out{};
            for (int c = 0; c < 3; ++c)
                if (which[c]) out[c] = z[c].data() + base;
            cycle(f, out);
        }
        // Backward: s = A_f,f+1 z_f+1: the temporal row at k (−ct z_next) and the mixed rows of
        // frame f with their frame f+1 part c (z_b+s − z_b), entering at m with +1, m + s with −1.
        for (std::size_t f = frames - 1; f-- > 0;) {
            const std::size_t base = f * np;
            if (mixed)
                overFrame(threads, np, which, [&](int c, std::size_t begin, std::size_t end) {
                    const Field& zc = z[c];
                    if (op.linkedOnce()) {
                        const double* __restrict cmx = op.cmx.data() + base;
                        const double* __restrict cmy = op.cmy.data() + base;
                        const std::uint32_t* __restrict tx = op.mxTo.data() + base;
                        const std::uint32_t* __restrict ty = op.myTo.data() + base;
                        const double* __restrict zs = zc.data();
                        double* __restrict rx = rx_[c].data();
                        double* __restrict ry = ry_[c].data();
                        for (std::size_t i = begin; i < end; ++i) {
                            rx[i] = cmx[i] * (zs[tx[i] + 1] - zs[tx[i]]);
                            ry[i] = cmy[i] * (zs[ty[i] + w] - zs[ty[i]]);
                        }
                        return;
                    }
                    for (std::size_t i = begin; i < end; ++i) {
                        const std::size_t k = base + i, b = op.next[k];
                        rx_[c][i] = op.cmx[k] != 0.0 ? op.cmx[k] * (zc[b + 1] - zc[b]) : 0.0;
                        ry_[c][i] = op.cmy[k] != 0.0 ? op.cmy[k] * (zc[b + w] - zc[b]) : 0.0;
                    }
                });
            overFrame(threads, np, which, [&](int c, std::size_t begin, std::size_t end) {
                const Field& zc = z[c];
                if (op.linkedOnce()) {
                    const std::size_t lo = std::clamp(w, begin, end);
                    backwardLinked(op, zc, base, lo, end, mixed, c);
                    end = lo;
                }
                for (std::size_t i = begin; i < end; ++i) {
                    const std::size_t k = base + i, b = op.next[k];
                    double v = b != kNoTemporalPartner ? -op.ct[k] * zc[b] : 0.0;
                    if (mixed) {
                        v += rx_[c][i] + ry_[c][i];
                        if (i >= 1) v -= rx_[c][i - 1];
                        if (i >= w) v -= ry_[c][i - w];
                    }
                    s_[c][i] = v;
                }
            });
            std::array<double*, 3> out{};
            for (int c = 0; c < 3; ++c)
                if (which[c]) out[c] = e_[c].data();
            cycle(f, out);
            overFrame(threads, np, which, [&](int c, std::size_t begin, std::size_t end) {
                double* zf = z[c].data() + base;
                for (std::size_t i = begin; i < end; ++i) zf[i] -= e_[c][i];
            });
        }
    }

    // The forward sweep's right-hand side s_ at frame pixels [lo, end) (lo ≥ W) of the frame at
    // `base` (not the first), in the operator's linkedOnce() form: r plus the temporal row from
    // the pixel's source in the frame before (a missing one has coefficient 0) and, with
    // `mixed`, the mixed rows' terms (rx_, ry_ at the frame before's pixels; np: a 0).
    void forwardLinked(const Operator& op, const Field& r, const Field& t, std::size_t base, std::size_t lo,
                       std::size_t end, bool mixed, int c) {
        const std::size_t np = op.pixels(), w = std::size_t(op.width), n = op.size(), prev = base - np;
        const double* __restrict rs = r.data() + base;
        const double* __restrict ts = t.data();
        const double* __restrict sct = op.srcCt.data() + base;
        const std::uint32_t* __restrict src = op.src.data() + base;
        double* __restrict out = s_[c].data();
        if (!mixed) {
            for (std::size_t i = lo; i < end; ++i) out[i] = rs[i] + sct[i] * ts[src[i]];
            return;
        }
        const std::uint32_t* __restrict sr = op.srcRow.data() + base;
        const double* __restrict rx = rx_[c].data();
        const double* __restrict ry = ry_[c].data();
        const auto local = [&](std::uint32_t m) { return m == n ? np : std::size_t(m) - prev; };
        for (std::size_t i = lo; i < end; ++i) {
            const std::size_t a = local(sr[i]);
            double v = rs[i] + sct[i] * ts[src[i]];
            v += rx[a] + ry[a];
            v -= rx[local(sr[i - 1])];
            v -= ry[local(sr[i - w])];
            out[i] = v;
        }
    }

    // The backward sweep's s_ = A_f,f+1 z_f+1 at frame pixels [lo, end) (lo ≥ W) of the frame at
    // `base`, in the linkedOnce() form (a missing temporal neighbour is the pixel itself with
    // coefficient 0); with `mixed`, rx_, ry_ hold the frame's mixed rows' parts in frame f+1.
    void backwardLinked(const Operator& op, const Field& z, std::size_t base, std::size_t lo, std::size_t end,
                        bool mixed, int c) {
        const std::size_t w = std::size_t(op.width);
        const double* __restrict zs = z.data();
        const double* __restrict ct = op.ct.data() + base;
        const std::uint32_t* __restrict fwd = op.fwd.data() + base;
        double* __restrict out = s_[c].data();
        if (!mixed) {
            for (std::size_t i = lo; i < end; ++i) out[i] = -ct[i] * zs[fwd[i]];
            return;
        }
        const double* __restrict rx = rx_[c].data();
        const double* __restrict ry = ry_[c].data();
        for (std::size_t i = lo; i < end; ++i)
            out[i] = -ct[i] * zs[fwd[i]] + (rx[i] + ry[i]) - rx[i - 1] - ry[i - w];
    }

    std::vector<HostVcycle> cycles_;
    std::vector<Field> cx_, cy_, diag_;     // the frames' blocks (several frames only)
    std::array<Field, 3> s_, e_, rx_, ry_;  // applyCoupled's, one frame each
};

struct ChannelSolve {
    int iterations = 0;
    double rhsNorm = 0.0, residualNorm = 0.0;
    bool converged = false;
    bool stoppedAtDeadline = false;
};

// Preconditioned CG from x until ‖b − A x‖ ≤ tolerance ‖b‖, the three channels in
// lockstep (each stops where it converges), pixel ranges over `threads`. A is SPD (α > 0).
// Jacobi: z = r / d is not stored (p ← r/d + β p). Multigrid (`mg`, one-frame windows): z =
// M⁻¹ r by one V-cycle (host_vcycle.h), p ← z + β p.
// CG's vectors, kept across the IRLS rounds (allocating them anew each round cost more than
// the iterations on a machine where page faults are slow).
struct CgVectors {
    std::array<Field, 3> r, p, q, z;  // z: multigrid only
    MixedRowValues rows;              // with mixed rows only
};

// `every16`: called after every 16th iteration with the iterations so far (may throw).
std::array<ChannelSolve, 3> pcg(const Operator& op, const std::array<Field, 3>& b, std::array<Field, 3>& x,
                                double tolerance, int maxIterations, std::uint32_t threads, CgVectors& v,
                                const std::function<void(int)>& every16,
                                std::optional<std::chrono::steady_clock::time_point> deadline,
                                FrameBlocks* mg, bool coupleFrames) {
    const std::size_t n = op.size(), ranges = rangesOf(n);
    const Field& jd = op.jacobiDiag();
    std::array<Field, 3>&r = v.r, &p = v.p, &q = v.q;
    // Per range: the partial sums of one pass (three per channel at most), added in range order.
    std::vector<std::array<double, 9>> partial(ranges);
    const auto sumOf = [&](int slot) {
        double s = 0.0;
        for (const auto& part : partial) s += part[std::size_t(slot)];
        return s;
    };
    for (int c = 0; c < 3; ++c) {
        sized(r[c], n);
        sized(p[c], n);
        sized(q[c], n);
        if (mg) sized(v.z[c], n);
    }
    // z = M⁻¹ r and r·z for the channels in `which` (multigrid).
    const auto precondition = [&](const std::array<bool, 3>& which) {
        mg->apply(op, r, v.z, which, threads, coupleFrames);
        parallelRanges(threads, n, kGrain, [&](std::size_t begin, std::size_t end) {
            std::array<double, 9> s{};
            for (int c = 0; c < 3; ++c) {
                if (!which[c]) continue;
                double rz = 0.0;
                for (std::size_t i = begin; i < end; ++i) rz += r[c][i] * v.z[c][i];
                s[std::size_t(c)] = rz;
            }
            partial[begin / kGrain] = s;
        });
    };
    const bool mixed = !op.cmx.empty();
    const auto rowsOf = [&](int c, bool y) -> const Field* {
        return mixed ? &(y ? v.rows.y : v.rows.x)[std::size_t(c)] : nullptr;
    };
    // r = b − A x, ‖b‖² and ‖r‖²; Jacobi: p = z = r / d and r·z (multigrid: below).
    if (mixed) mixedRowValues(op, x, {true, true, true}, v.rows, threads);
    parallelRanges(threads, n, kGrain, [&](std::size_t begin, std::size_t end) {
        std::array<double, 9> s{};
        for (int c = 0; c < 3; ++c) {
            applyRange(op, x[c], q[c], begin, end, rowsOf(c, false), rowsOf(c, true));
            double bb = 0.0, rz = 0.0, rr = 0.0;
            for (std::size_t i = begin; i < end; ++i) {
                const double ri = b[c][i] - q[c][i];
                r[c][i] = ri;
                if (!mg) {
                    p[c][i] = ri / jd[i];
                    rz += ri * p[c][i];
                }
                bb += b[c][i] * b[c][i];
                rr += ri * ri;
            }
            s[std::size_t(c)] = bb;
            s[std::size_t(c) + 3] = rz;
            s[std::size_t(c) + 6] = rr;
        }
        partial[begin / kGrain] = s;
    });
    std::array<ChannelSolve, 3> out;
    std::array<double, 3> rz{}, rr{}, target{}, alpha{}, beta{};
    std::array<bool, 3> active{};
    for (int c = 0; c < 3; ++c) {
        out[c].rhsNorm = std::sqrt(sumOf(c));
        rz[c] = sumOf(c + 3);
        rr[c] = sumOf(c + 6);
        target[c] = tolerance * out[c].rhsNorm;
        active[c] = std::sqrt(rr[c]) > target[c] && maxIterations > 0;
    }
    if (mg && (active[0] || active[1] || active[2])) {
        precondition(active);
        for (int c = 0; c < 3; ++c)
            if (active[c]) {
                rz[c] = sumOf(c);
                std::copy(v.z[c].begin(), v.z[c].end(), p[c].begin());
            }
    }
    const auto anyActive = [&] { return active[0] || active[1] || active[2]; };
    int k = 0;
    bool cut = false;
    while (anyActive()) {
        if (every16 && k > 0 && k % 16 == 0) every16(k);
        if (deadline && std::chrono::steady_clock::now() >= *deadline) {
            cut = true;  // the iterate so far: every CG iterate is an image of lower energy
            break;
        }
        ++k;
        // q = A p and p·q.
        if (mixed) mixedRowValues(op, p, active, v.rows, threads);
        parallelRanges(threads, n, kGrain, [&](std::size_t begin, std::size_t end) {
            std::array<double, 9> s{};
            for (int c = 0; c < 3; ++c) {
                if (!active[c]) continue;
                applyRange(op, p[c], q[c], begin, end, rowsOf(c, false), rowsOf(c, true));
                double pq = 0.0;
                for (std::size_t i = begin; i < end; ++i) pq += p[c][i] * q[c][i];
                s[std::size_t(c)] = pq;
            }
            partial[begin / kGrain] = s;
        });
        for (int c = 0; c < 3; ++c) {
            if (!active[c]) continue;
            const double pq = sumOf(c);
            if (!(pq > 0.0)) {
                active[c] = false;  // breakdown: keep x
                continue;
            }
            alpha[c] = rz[c] / pq;
        }
        // x += α p, r −= α q, and r·z, r·r.
        parallelRanges(threads, n, kGrain, [&](std::size_t begin, std::size_t end) {
            std::array<double, 9> s{};
            for (int c = 0; c < 3; ++c) {
                if (!active[c]) continue;
                double rzNew = 0.0, rrNew = 0.0;
                const double a = alpha[c];
                for (std::size_t i = begin; i < end; ++i) {
                    x[c][i] += a * p[c][i];
                    const double ri = r[c][i] - a * q[c][i];
                    r[c][i] = ri;
                    if (!mg) rzNew += ri * ri / jd[i];  // multigrid: r·z after the cycle
                    rrNew += ri * ri;
                }
                s[std::size_t(c)] = rzNew;
                s[std::size_t(c) + 3] = rrNew;
            }
            partial[begin / kGrain] = s;
        });
        std::array<double, 3> rzNew{};
        for (int c = 0; c < 3; ++c) {
            if (!active[c]) continue;
            rzNew[c] = sumOf(c);
            rr[c] = sumOf(c + 3);
            ++out[c].iterations;
            active[c] = std::sqrt(rr[c]) > target[c] && out[c].iterations < maxIterations;
        }
        if (!anyActive()) break;
        if (mg) {
            precondition(active);
            for (int c = 0; c < 3; ++c)
                if (active[c]) rzNew[c] = sumOf(c);
        }
        for (int c = 0; c < 3; ++c) {
            if (!active[c]) continue;
            beta[c] = rzNew[c] / rz[c];
            rz[c] = rzNew[c];
        }
        // p = r / d + β p.
        parallelRanges(threads, n, kGrain, [&](std::size_t begin, std::size_t end) {
            for (int c = 0; c < 3; ++c) {
                if (!active[c]) continue;
                const double bt = beta[c];
                if (mg)
                    for (std::size_t i = begin; i < end; ++i) p[c][i] = v.z[c][i] + bt * p[c][i];
                else
                    for (std::size_t i = begin; i < end; ++i) p[c][i] = r[c][i] / jd[i] + bt * p[c][i];
            }
        });
    }
    for (int c = 0; c < 3; ++c) {
        out[c].residualNorm = std::sqrt(rr[c]);
        out[c].converged = out[c].residualNorm <= target[c];
        out[c].stoppedAtDeadline = cut;
    }
    return out;
}

// IRLS's factor of a row with RGB residual e: 1 / (‖e‖ + reg).
inline double irlsFactor(const double e[3], double reg) {
    return 1.0 / (std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]) + reg);
}

// IRLS weights of the estimate x: the row's weight times 1 / (‖e‖_RGB + reg) for every kept
// row, the IRLS factors renormalised to mean 1 over the kept rows (as poisson_irls_weights.comp).
// `kept`: the unit weights (0 for dropped rows); `wt` gets the same sizes.
void irlsWeights(const SpaceTimeProblem& p, const Operator& op, const std::array<Field, 3>& x, double reg,
                 const Weights& kept, Weights& wt, std::uint32_t threads) {
    sized(wt.primal, kept.primal.size());
    sized(wt.dx, kept.dx.size());
    sized(wt.dy, kept.dy.size());
    sized(wt.dt, p.size());  // as op.ct (setWeights), the last frame's 0
    sized(wt.boundary, kept.boundary.size());
    sized(wt.mx, kept.mx.size());
    sized(wt.my, kept.my.size());
    sized(wt.bmx, kept.bmx.size());
    sized(wt.bmy, kept.bmy.size());
    const std::size_t n = p.size(), np = p.pixels(), w = std::size_t(p.width);
    std::vector<std::array<double, 2>> partial(rangesOf(n));  // per range: Σ weights, rows
    parallelRanges(threads, n, kGrain, [&](std::size_t begin, std::size_t end) {
        double sum = 0.0, rows = 0.0;
        const auto weightOf = [&](const double e[3]) {
            const double v = irlsFactor(e, reg);
            sum += v;
            rows += 1.0;
            return v;
        };
        double e[3];
        for (std::size_t i = begin; i < end; ++i) {
            wt.primal[i] = 0.0;
            if (kept.primal[i] != 0.0) {
                for (int c = 0; c < 3; ++c) e[c] = p.alpha * (x[c][i] - p.primal[c][i]);
                wt.primal[i] = kept.primal[i] * weightOf(e);
            }
            wt.dx[i] = 0.0;
            if (kept.dx[i] != 0.0) {
                for (int c = 0; c < 3; ++c) e[c] = x[c][i + 1] - x[c][i] - p.dx[c][i];
                wt.dx[i] = kept.dx[i] * weightOf(e);
            }
            wt.dy[i] = 0.0;
            if (kept.dy[i] != 0.0) {
                for (int c = 0; c < 3; ++c) e[c] = x[c][i + w] - x[c][i] - p.dy[c][i];
                wt.dy[i] = kept.dy[i] * weightOf(e);
            }
            wt.dt[i] = 0.0;
            if (i + np < n) {
                if (kept.dt[i] != 0.0) {
                    const std::size_t j = op.next[i];
                    for (int c = 0; c < 3; ++c) e[c] = p.beta * (x[c][j] - x[c][i] - p.dt[c][i]);
                    wt.dt[i] = kept.dt[i] * weightOf(e);
                }
                if (!kept.mx.empty()) {
                    wt.mx[i] = wt.my[i] = 0.0;
                    if (kept.mx[i] != 0.0) {
                        for (int c = 0; c < 3; ++c)
                            e[c] = p.gamma * (mixedResidual(op, x[c], i, 1) - p.dxt[c][i]);
                        wt.mx[i] = kept.mx[i] * weightOf(e);
                    }
                    if (kept.my[i] != 0.0) {
                        for (int c = 0; c < 3; ++c)
                            e[c] = p.gamma * (mixedResidual(op, x[c], i, w) - p.dyt[c][i]);
                        wt.my[i] = kept.my[i] * weightOf(e);
                    }
                }
            }
        }
        partial[begin / kGrain] = {sum, rows};
    });
    double sum = 0.0, rows = 0.0;
    for (const auto& v : partial) sum += v[0], rows += v[1];
    for (std::size_t i = 0; i < wt.boundary.size(); ++i) {
        wt.boundary[i] = 0.0;
        if (kept.boundary[i] == 0.0) continue;
        const std::size_t j = op.bnext[i];
        double e[3];
        for (int c = 0; c < 3; ++c) e[c] = p.beta * (x[c][j] - p.previous[c][i] - p.dtPrevious[c][i]);
        const double v = irlsFactor(e, reg);
        wt.boundary[i] = kept.boundary[i] * v;
        sum += v;
        rows += 1.0;
    }
    for (std::size_t j = 0; j < wt.bmx.size(); ++j) {
        const std::size_t q = op.bnext[j];
        for (const auto& [kw, out, s, target] :
             {std::tuple<const Field*, Field*, std::size_t, const std::array<Field, 3>*>{&kept.bmx, &wt.bmx,
                                                                                         1, &p.dxtPrevious},
              {&kept.bmy, &wt.bmy, w, &p.dytPrevious}}) {
            (*out)[j] = 0.0;
            if ((*kw)[j] == 0.0) continue;
            double e[3];
            for (int c = 0; c < 3; ++c)
                e[c] = p.gamma * ((x[c][q + s] - x[c][q]) - (p.previous[c][j + s] - p.previous[c][j]) -
                                  (*target)[c][j]);
            const double v = irlsFactor(e, reg);
            (*out)[j] = (*kw)[j] * v;
            sum += v;
            rows += 1.0;
        }
    }
    const double scale = sum > 0.0 ? rows / sum : 1.0;
    for (Field* f : {&wt.primal, &wt.dx, &wt.dy, &wt.dt, &wt.boundary, &wt.mx, &wt.my, &wt.bmx, &wt.bmy}) {
        Field& v = *f;
        parallelRanges(threads, v.size(), kGrain, [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i) v[i] *= scale;
        });
    }
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
