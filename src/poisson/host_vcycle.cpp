#include "poisson/host_vcycle.h"

#include <algorithm>

#include "util/error.h"
#include "util/parallel.h"

namespace gdpt {

namespace {

// Levels of fewer pixels run on the calling thread (starting threads costs more than their
// work); the others in ranges of whole rows of at least this many pixels.
constexpr std::size_t kParallelPixels = std::size_t{1} << 15;
constexpr std::size_t kRangePixels = std::size_t{1} << 13;

// fn(begin, end) over rows [0, rows) of a level of `pixels` pixels, `width` wide.
template <class Fn>
void overRows(std::size_t pixels, std::size_t width, std::size_t rows, std::uint32_t threads, const Fn& fn) {
    if (pixels < kParallelPixels || threads <= 1) {
        fn(std::size_t{0}, rows);
        return;
    }
    parallelRanges(threads, rows, std::max<std::size_t>(1, kRangePixels / width), fn);
}

// (A x)_i of the 5-point operator with diagonal d at pixel (px, y), index i.
inline double applyAt(const double* d, const double* cx, const double* cy, const double* x, std::size_t i,
                      std::size_t px, std::size_t y, std::size_t w, std::size_t h) {
    double v = d[i] * x[i];
    if (px + 1 < w) v -= cx[i] * x[i + 1];
    if (px > 0) v -= cx[i - 1] * x[i - 1];
    if (y + 1 < h) v -= cy[i] * x[i + w];
    if (y > 0) v -= cy[i - w] * x[i - w];
    return v;
}

}  // namespace

void HostVcycle::build(int width, int height, const Field& cx, const Field& cy, const Field& diag,
                       std::uint32_t threads) {
    GDPT_CHECK(width > 0 && height > 0);
    const std::size_t n = std::size_t(width) * std::size_t(height);
    GDPT_CHECK(cx.size() == n && cy.size() == n && diag.size() == n);
    // Levels down to 2×2 or less (poisson_multigrid.cpp's hierarchy).
    std::size_t count = 1;
    for (std::size_t w = std::size_t(width), h = std::size_t(height); w > 2 || h > 2; ++count)
        w = (w + 1) / 2, h = (h + 1) / 2;
    levels_.resize(count);
    for (std::size_t l = 0; l < count; ++l) {
        Level& L = levels_[l];
        if (l == 0) {
            L.width = std::size_t(width);
            L.height = std::size_t(height);
            L.cx = cx.data();
            L.cy = cy.data();
            L.diag = diag.data();
        } else {
            // Galerkin: ¼ Pᵀ A P with piecewise-constant P (poisson_multigrid.cpp's
            // coarsenOperator): an edge between two aggregates adds ¼ of its weight to theirs;
            // the diagonal of aggregate I is ¼ (Σ_{i∈I} d_i − 2 Σ_{edges inside I} c).
            const Level& F = levels_[l - 1];
            const std::size_t fw = F.width, fh = F.height, w = (fw + 1) / 2, h = (fh + 1) / 2;
            L.width = w;
            L.height = h;
            L.ownCx.resize(w * h);
            L.ownCy.resize(w * h);
            L.ownDiag.resize(w * h);
            for (int c = 0; c < 3; ++c) {
                L.b[c].resize(w * h);
                L.x[c].resize(w * h);
            }
            double *ccx = L.ownCx.data(), *ccy = L.ownCy.data(), *cd = L.ownDiag.data();
            overRows(fw * fh, fw, h, threads, [&](std::size_t y0, std::size_t y1) {
                for (std::size_t Y = y0; Y < y1; ++Y)
                    for (std::size_t X = 0; X < w; ++X) {
                        double ex = 0.0, ey = 0.0, d = 0.0;
                        for (std::size_t y = 2 * Y; y < std::min(2 * Y + 2, fh); ++y)
                            for (std::size_t x = 2 * X; x < std::min(2 * X + 2, fw); ++x) {
                                const std::size_t i = y * fw + x;
                                d += F.diag[i];
                                if (x == 2 * X + 1 && x + 1 < fw) ex += F.cx[i];   // crosses to X + 1
                                if (x == 2 * X && x + 1 < fw) d -= 2.0 * F.cx[i];  // inside
                                if (y == 2 * Y + 1 && y + 1 < fh) ey += F.cy[i];
                                if (y == 2 * Y && y + 1 < fh) d -= 2.0 * F.cy[i];
                            }
                        const std::size_t I = Y * w + X;
                        ccx[I] = 0.25 * ex;
                        ccy[I] = 0.25 * ey;
                        cd[I] = 0.25 * d;
                    }
            });
            L.cx = ccx;
            L.cy = ccy;
            L.diag = cd;
        }
        const std::size_t size = L.width * L.height;
        L.invDiag.resize(size);
        for (std::size_t i = 0; i < size; ++i) L.invDiag[i] = 1.0 / L.diag[i];
    }
    // The coarsest level's pseudo-inverse (minimum-norm: a singular operator, no screening, gets
    // the zero-mean solution): buildHierarchy's, of that level as a PoissonOperator (≤ 2×2, so
    // it is its own coarsest level), whose screening is the diagonal less the edges.
    const Level& last = levels_.back();
    PoissonOperator coarsest;
    coarsest.width = static_cast<int>(last.width);
    coarsest.height = static_cast<int>(last.height);
    const std::size_t m = last.width * last.height;
    coarsest.cx.assign(last.cx, last.cx + m);
    coarsest.cy.assign(last.cy, last.cy + m);
    coarsest.cp.resize(m);
    for (std::size_t i = 0; i < m; ++i) {
        double e = last.cx[i] + last.cy[i];
        if (i % last.width > 0) e += last.cx[i - 1];
        if (i >= last.width) e += last.cy[i - last.width];
        coarsest.cp[i] = last.diag[i] - e;
    }
    coarsestPseudoInverse_ = buildHierarchy(coarsest).coarsestPseudoInverse;
}

void HostVcycle::apply(const std::array<const Field*, 3>& r, const std::array<Field*, 3>& z,
                       const std::array<bool, 3>& active, std::uint32_t threads) {
    GDPT_CHECK(!levels_.empty());
    std::array<const double*, 3> b{};
    std::array<double*, 3> x{};
    for (int c = 0; c < 3; ++c)
        if (active[c]) {
            const std::size_t n = levels_[0].width * levels_[0].height;
            GDPT_CHECK(r[c]->size() == n && z[c]->size() == n);
            b[c] = r[c]->data();
            x[c] = z[c]->data();
        }
    applyTo(b, x, active, threads);
}

void HostVcycle::applyTo(const std::array<const double*, 3>& r, const std::array<double*, 3>& z,
                         const std::array<bool, 3>& active, std::uint32_t threads) {
    GDPT_CHECK(!levels_.empty());
    cycle(0, r, z, active, threads);
}

void HostVcycle::cycle(std::size_t level, const std::array<const double*, 3>& b,
                       const std::array<double*, 3>& x, const std::array<bool, 3>& active,
                       std::uint32_t threads) {
    Level& L = levels_[level];
    const std::size_t w = L.width, h = L.height, n = w * h;
    if (level + 1 == levels_.size()) {
        for (int c = 0; c < 3; ++c) {
            if (!active[c]) continue;
            for (std::size_t i = 0; i < n; ++i) {
                double v = 0.0;
                for (std::size_t j = 0; j < n; ++j) v += coarsestPseudoInverse_[i * n + j] * b[c][j];
                x[c][i] = v;
            }
        }
        return;
    }
    const double* cx = L.cx;
    const double* cy = L.cy;
    const double* inv = L.invDiag.data();
    // One colour's Gauss-Seidel update, rows [y0, y1): x_i = (b_i + Σ_j c_ij x_j) / d_i at the
    // pixels with (px + y) % 2 == colour. fromZero: x was 0 (the first sweep of a cycle), so the
    // red pixels are b_i / d_i and the black ones are set to 0.
    const bool all = active[0] && active[1] && active[2];
    const auto sweep = [&](int colour, bool fromZero) {
        overRows(n, w, h, threads, [&](std::size_t y0, std::size_t y1) {
            for (std::size_t y = y0; y < y1; ++y) {
                const std::size_t row = y * w, first = (y + std::size_t(colour)) & 1u;
                if (fromZero) {
                    for (int c = 0; c < 3; ++c) {
                        if (!active[c]) continue;
                        for (std::size_t px = first; px < w; px += 2)
                            x[c][row + px] = b[c][row + px] * inv[row + px];
                        for (std::size_t px = first ^ 1u; px < w; px += 2) x[c][row + px] = 0.0;
                    }
                    continue;
                }
                const bool top = y == 0, bottom = y + 1 == h;
                const auto update = [&](int c, std::size_t px) {
                    const double* bc = b[c];
                    double* xc = x[c];
                    const std::size_t i = row + px;
                    double s = bc[i];
                    if (px + 1 < w) s += cx[i] * xc[i + 1];
                    if (px > 0) s += cx[i - 1] * xc[i - 1];
                    if (!bottom) s += cy[i] * xc[i + w];
                    if (!top) s += cy[i - w] * xc[i - w];
                    xc[i] = s * inv[i];
                };
                if (top || bottom || w < 3) {
                    for (int c = 0; c < 3; ++c)
                        if (active[c])
                            for (std::size_t px = first; px < w; px += 2) update(c, px);
                    continue;
                }
                // Inside the level every neighbour is there: update's terms in its order,
                // without its tests, and with every channel active each pixel's coefficients
                // read once for the three.
                const std::size_t lo = first == 0 ? 2 : 1;
                const std::size_t last = (w - 1 - first) % 2 == 0 ? w - 1 : w;  // one past the inside
                for (int c = 0; c < 3; ++c) {
                    if (!active[c]) continue;
                    if (first == 0) update(c, 0);
                    if (last < w) update(c, last);
                }
                const auto relax = [&](const double* __restrict bc, double* __restrict xc, std::size_t i,
                                       double e, double west, double s, double north, double d) {
                    xc[i] =
                        (bc[i] + e * xc[i + 1] + west * xc[i - 1] + s * xc[i + w] + north * xc[i - w]) * d;
                };
                if (all) {
                    for (std::size_t px = lo; px + 1 < w; px += 2) {
                        const std::size_t i = row + px;
                        const double e = cx[i], west = cx[i - 1], s = cy[i], north = cy[i - w], d = inv[i];
                        for (int c = 0; c < 3; ++c) relax(b[c], x[c], i, e, west, s, north, d);
                    }
                    continue;
                }
                for (int c = 0; c < 3; ++c) {
                    if (!active[c]) continue;
                    for (std::size_t px = lo; px + 1 < w; px += 2) {
                        const std::size_t i = row + px;
                        relax(b[c], x[c], i, cx[i], cx[i - 1], cy[i], cy[i - w], inv[i]);
                    }
                }
            }
        });
    };
    sweep(0, true);
    sweep(1, false);

    // The residual b − A x, restricted (¼ of the sum over each 2×2 aggregate) into the next
    // level's right-hand side, by coarse rows.
    Level& C = levels_[level + 1];
    const std::size_t cw = C.width, ch = C.height;
    const double* diag = L.diag;
    overRows(n, w, ch, threads, [&](std::size_t Y0, std::size_t Y1) {
        for (std::size_t Y = Y0; Y < Y1; ++Y) {
            for (int c = 0; c < 3; ++c)
                if (active[c]) std::fill(C.b[c].data() + Y * cw, C.b[c].data() + (Y + 1) * cw, 0.0);
            for (std::size_t y = 2 * Y; y < std::min(2 * Y + 2, h); ++y) {
                const std::size_t row = y * w;
                const auto add = [&](int c, std::size_t px) {
                    const std::size_t i = row + px;
                    C.b[c][Y * cw + px / 2] += 0.25 * (b[c][i] - applyAt(diag, cx, cy, x[c], i, px, y, w, h));
                };
                const bool inside = y > 0 && y + 1 < h && w >= 3;
                for (int c = 0; c < 3; ++c) {
                    if (!active[c]) continue;
                    if (!inside) {
                        for (std::size_t px = 0; px < w; ++px) add(c, px);
                        continue;
                    }
                    add(c, 0);
                }
                if (!inside) continue;
                // Inside the level: applyAt's terms in its order, without its tests, and with
                // every channel active each pixel's coefficients read once for the three.
                const auto residual = [&](const double* __restrict bc, const double* __restrict xc,
                                          std::size_t i, double d, double e, double west, double s,
                                          double north) {
                    double v = d * xc[i];
                    v -= e * xc[i + 1];
                    v -= west * xc[i - 1];
                    v -= s * xc[i + w];
                    v -= north * xc[i - w];
                    return 0.25 * (bc[i] - v);
                };
                if (all) {
                    for (std::size_t px = 1; px + 1 < w; ++px) {
                        const std::size_t i = row + px;
                        const double d = diag[i], e = cx[i], west = cx[i - 1], s = cy[i], north = cy[i - w];
                        for (int c = 0; c < 3; ++c)
                            C.b[c][Y * cw + px / 2] += residual(b[c], x[c], i, d, e, west, s, north);
                    }
                } else {
                    for (int c = 0; c < 3; ++c) {
                        if (!active[c]) continue;
                        double* __restrict cb = C.b[c].data() + Y * cw;
                        for (std::size_t px = 1; px + 1 < w; ++px) {
                            const std::size_t i = row + px;
                            cb[px / 2] +=
                                residual(b[c], x[c], i, diag[i], cx[i], cx[i - 1], cy[i], cy[i - w]);
                        }
                    }
                }
                for (int c = 0; c < 3; ++c)
                    if (active[c]) add(c, w - 1);
            }
        }
    });
    std::array<const double*, 3> cbp{};
    std::array<double*, 3> cxp{};
    for (int c = 0; c < 3; ++c)
        if (active[c]) {
            cbp[c] = C.b[c].data();
            cxp[c] = C.x[c].data();
        }
    cycle(level + 1, cbp, cxp, active, threads);

    // x += P e (piecewise constant), then the sweep in the other order.
    overRows(n, w, h, threads, [&](std::size_t y0, std::size_t y1) {
        for (int c = 0; c < 3; ++c) {
            if (!active[c]) continue;
            const double* e = C.x[c].data();
            for (std::size_t y = y0; y < y1; ++y)
                for (std::size_t px = 0; px < w; ++px) x[c][y * w + px] += e[(y / 2) * cw + px / 2];
        }
    });
    sweep(1, false);
    sweep(0, false);
}

}  // namespace gdpt
