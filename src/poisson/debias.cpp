#include "poisson/debias.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <string>

#include "util/error.h"

namespace gdpt {
namespace {

// The hat functions of one axis: n pixels, nodes 0..nodes-1 every `scale` pixels (node k at
// pixel k * scale). Pixel x lies between node first[x] (weight 1 - frac[x]) and first[x] + 1
// (weight frac[x]); one pixel: one constant function.
struct Hats {
    int nodes = 1;
    std::vector<int> first;
    std::vector<double> frac;
    // The symmetric tridiagonal mass matrix Σ_x φ_k(x) φ_j(x): diagonal and the one above it.
    std::vector<double> diag, upper;

    Hats(int n, int scale) : first(static_cast<std::size_t>(n), 0), frac(static_cast<std::size_t>(n), 0.0) {
        if (n > 1) {
            nodes = 1 + std::max(1, (n - 1 + scale - 1) / scale);  // the last node at or past pixel n-1
            for (int x = 0; x < n; ++x) {
                const int k = std::min(x / scale, nodes - 2);
                first[static_cast<std::size_t>(x)] = k;
                frac[static_cast<std::size_t>(x)] = double(x - k * scale) / double(scale);
            }
        }
        diag.assign(static_cast<std::size_t>(nodes), 0.0);
        upper.assign(static_cast<std::size_t>(nodes), 0.0);
        for (int x = 0; x < n; ++x) {
            const double w1 = frac[static_cast<std::size_t>(x)], w0 = 1.0 - w1;
            const auto k = static_cast<std::size_t>(first[static_cast<std::size_t>(x)]);
            diag[k] += w0 * w0;
            if (nodes > 1) {
                diag[k + 1] += w1 * w1;
                upper[k] += w0 * w1;
            }
        }
    }

    // Solves M c = r in place over `count` right-hand sides stored with stride `stride` between
    // a right-hand side's consecutive entries and `step` between right-hand sides (Thomas).
    void solve(double* r, std::size_t count, std::size_t stride, std::size_t step) const {
        const auto m = static_cast<std::size_t>(nodes);
        std::vector<double> c(m), d(m);
        for (std::size_t i = 0; i < count; ++i) {
            double* v = r + i * step;
            c[0] = m > 1 ? upper[0] / diag[0] : 0.0;
            d[0] = v[0] / diag[0];
            for (std::size_t k = 1; k < m; ++k) {
                const double denom = diag[k] - upper[k - 1] * c[k - 1];
                c[k] = k + 1 < m ? upper[k] / denom : 0.0;
                d[k] = (v[k * stride] - upper[k - 1] * d[k - 1]) / denom;
            }
            v[(m - 1) * stride] = d[m - 1];
            for (std::size_t k = m - 1; k-- > 0;) v[k * stride] = d[k] - c[k] * v[(k + 1) * stride];
        }
    }
};

}  // namespace

std::vector<double> coarseProjection(int width, int height, const std::vector<double>& d, int scale) {
    if (scale < 1)
        throw Error("debias: the coarse scale must be at least 1 pixel (got " + std::to_string(scale) + ")");
    if (width < 1 || height < 1 ||
        d.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height))
        throw Error("debias: a " + std::to_string(width) + "x" + std::to_string(height) + " field needs " +
                    std::to_string(static_cast<std::size_t>(std::max(width, 0)) * std::max(height, 0)) +
                    " values (got " + std::to_string(d.size()) + ")");
    const Hats hx(width, scale), hy(height, scale);
    const auto W = static_cast<std::size_t>(width), H = static_cast<std::size_t>(height);
    const auto kx = static_cast<std::size_t>(hx.nodes), ky = static_cast<std::size_t>(hy.nodes);
    // Load vector r = Σ_p φ_l(y) φ_k(x) d(p), rows first (a: H x kx), then columns (r: ky x kx).
    std::vector<double> a(H * kx, 0.0), r(ky * kx, 0.0);
    for (std::size_t y = 0; y < H; ++y)
        for (std::size_t x = 0; x < W; ++x) {
            const double v = d[y * W + x], w1 = hx.frac[x];
            const auto k = static_cast<std::size_t>(hx.first[x]);
            a[y * kx + k] += (1.0 - w1) * v;
            if (kx > 1) a[y * kx + k + 1] += w1 * v;
        }
    for (std::size_t y = 0; y < H; ++y) {
        const double w1 = hy.frac[y];
        const auto l = static_cast<std::size_t>(hy.first[y]);
        for (std::size_t k = 0; k < kx; ++k) {
            r[l * kx + k] += (1.0 - w1) * a[y * kx + k];
            if (ky > 1) r[(l + 1) * kx + k] += w1 * a[y * kx + k];
        }
    }
    // (My ⊗ Mx) c = r: along x for each row of nodes, then along y for each column.
    hx.solve(r.data(), ky, 1, kx);
    hy.solve(r.data(), kx, kx, 1);
    // Evaluate Σ c_lk φ_l(y) φ_k(x): columns first (b: H x kx), then rows.
    std::vector<double> b(H * kx, 0.0), out(W * H, 0.0);
    for (std::size_t y = 0; y < H; ++y) {
        const double w1 = hy.frac[y];
        const auto l = static_cast<std::size_t>(hy.first[y]);
        for (std::size_t k = 0; k < kx; ++k)
            b[y * kx + k] = (1.0 - w1) * r[l * kx + k] + (ky > 1 ? w1 * r[(l + 1) * kx + k] : 0.0);
    }
    for (std::size_t y = 0; y < H; ++y)
        for (std::size_t x = 0; x < W; ++x) {
            const double w1 = hx.frac[x];
            const auto k = static_cast<std::size_t>(hx.first[x]);
            out[y * W + x] = (1.0 - w1) * b[y * kx + k] + (kx > 1 ? w1 * b[y * kx + k + 1] : 0.0);
        }
    return out;
}

DebiasReport debiasChannel(int width, int height, std::vector<float>& recon, const std::vector<float>& primal,
                           int scale) {
    const std::size_t n = recon.size();
    if (primal.size() != n)
        throw Error("debias: the primal has " + std::to_string(primal.size()) +
                    " values, the reconstruction " + std::to_string(n));
    std::vector<double> d(n, 0.0);
    double sumBefore = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        if (std::isfinite(recon[i])) sumBefore += recon[i];
        if (std::isfinite(primal[i]) && std::isfinite(recon[i])) d[i] = double(primal[i]) - double(recon[i]);
    }
    const std::vector<double> correction = coarseProjection(width, height, d, scale);
    double sumCorrection = 0.0, maxCorrection = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        recon[i] = static_cast<float>(double(recon[i]) + correction[i]);
        sumCorrection += correction[i];
        maxCorrection = std::max(maxCorrection, std::abs(correction[i]));
    }
    DebiasReport report;
    report.meanBefore = sumBefore / double(n);
    report.meanCorrection = sumCorrection / double(n);
    report.maxCorrection = maxCorrection;
    return report;
}

int debiasScale(int width, int height, int cells) {
    if (cells < 1)
        throw Error("debias: the coarse grid needs at least 1 cell (got " + std::to_string(cells) + ")");
    const int side = std::max(1, std::min(width, height));
    return std::max(1, (side + cells - 1) / cells);
}

DebiasReport debiasImage(Image& recon, const Image& primal, int cells) {
    if (!recon.sameSize(primal))
        throw Error("debias: the reconstruction is " + std::to_string(recon.width()) + "x" +
                    std::to_string(recon.height()) + ", the primal " + std::to_string(primal.width()) + "x" +
                    std::to_string(primal.height()));
    const int scale = debiasScale(recon.width(), recon.height(), cells);
    DebiasReport total;
    total.scale = scale;
    for (int c = 0; c < Image::kChannels; ++c) {
        const DebiasReport r =
            debiasChannel(recon.width(), recon.height(), recon.plane(c), primal.plane(c), scale);
        total.meanBefore += r.meanBefore / Image::kChannels;
        total.meanCorrection += r.meanCorrection / Image::kChannels;
        total.maxCorrection = std::max(total.maxCorrection, r.maxCorrection);
    }
    return total;
}

std::string describeDebias(const DebiasReport& report) {
    const int scale = report.scale;
    char buf[160];
    if (report.meanBefore > 0.0)
        std::snprintf(buf, sizeof buf, "debiased at %d px: mean %+.2f %% (largest change %.3g)", scale,
                      100.0 * report.relativeMeanChange(), report.maxCorrection);
    else
        std::snprintf(buf, sizeof buf, "debiased at %d px: mean %+.3g (largest change %.3g)", scale,
                      report.meanCorrection, report.maxCorrection);
    return buf;
}

}  // namespace gdpt
