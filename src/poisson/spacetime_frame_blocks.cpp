// spacetime_frame_blocks.cpp — CG's multigrid preconditioner over a window's frames
// (spacetime_frame_blocks.h).
#include "poisson/spacetime_frame_blocks.h"

#include <algorithm>

#include "util/parallel.h"

namespace gdpt::spacetime {

void FrameBlocks::build(const Operator& op, std::uint32_t threads) {
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

void FrameBlocks::apply(const Operator& op, const std::array<Field, 3>& r, std::array<Field, 3>& z,
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

// Symmetric block Gauss-Seidel over the frames, each block's inverse approximated by its
// V-cycle V_f: forward t_f = V_f (r_f − A_f,f−1 t_f−1), backward z_f = t_f − V_f A_f,f+1 z_f+1.
// With A_f+1,f = A_f,f+1ᵀ, M⁻¹ = (V⁻¹ + U)⁻¹ V⁻¹ (V⁻¹ + L)⁻¹ (L, U the blocks below and above
// the diagonal), symmetric positive definite for SPD V_f: a valid CG preconditioner that,
// unlike block Jacobi, sees the coupling between neighbouring frames (the temporal rows and
// the mixed rows' terms across frames), which IRLS makes stiff where the frames agree.
void FrameBlocks::applyCoupled(const Operator& op, const std::array<Field, 3>& r, std::array<Field, 3>& z,
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
void FrameBlocks::forwardLinked(const Operator& op, const Field& r, const Field& t, std::size_t base,
                                std::size_t lo, std::size_t end, bool mixed, int c) {
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
void FrameBlocks::backwardLinked(const Operator& op, const Field& z, std::size_t base, std::size_t lo,
                                 std::size_t end, bool mixed, int c) {
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

}  // namespace gdpt::spacetime
