// spacetime_operator.cpp — the space-time normal equations on the host (spacetime_operator.h).
#include "poisson/spacetime_operator.h"

#include <algorithm>
#include <numeric>

#include "util/huge_pages.h"
#include "util/parallel.h"

namespace gdpt::spacetime {

void sized(Field& f, std::size_t n) {
    if (f.capacity() < n) {
        Field fresh;
        reserveHuge(fresh, n);
        f.swap(fresh);
    }
    f.resize(n);
}

void copied(Field& to, const Field& from) {
    sized(to, from.size());
    std::copy(from.begin(), from.end(), to.begin());
}

void filled(Field& f, std::size_t n, double v) {
    sized(f, n);
    std::fill(f.begin(), f.end(), v);
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

namespace {

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
}  // namespace

std::vector<std::uint32_t> previousNext(const SpaceTimeProblem& p) {
    if (p.previous[0].empty()) return {};
    if (!p.previousPartner.empty()) return p.previousPartner;
    std::vector<std::uint32_t> next(p.pixels());
    std::iota(next.begin(), next.end(), 0u);
    return next;
}

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

namespace {

// applyRange over any window, each neighbour tested. (One pass over the three channels, reading
// each pixel's lists once, measured 10-15 % slower on windows with mixed rows.)
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

}  // namespace

// One frame (no temporal or mixed rows) takes the 5-point stencil
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

}  // namespace gdpt::spacetime
