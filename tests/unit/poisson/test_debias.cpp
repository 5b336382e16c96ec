// The debiasing of a reconstruction's coarse scales (poisson/debias.h): the projection against
// a dense least-squares fit on explicitly built hat functions; a field of the coarse space is
// reproduced; the projection is idempotent and keeps every hat's weighted sum (so the image
// sum); a reconstruction off by a bilinear ramp comes back as the primal; a reconstruction's
// fine detail survives; non-finite pixels and bad arguments.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "poisson/debias.h"
#include "util/error.h"

namespace gdpt {
namespace {

// Hat k of an axis with nodes every `scale` pixels, written from the definition.
double hat(int x, int k, int scale) {
    return std::max(0.0, 1.0 - std::abs(double(x - k * scale)) / scale);
}

int nodeCount(int n, int scale) {
    return n == 1 ? 1 : 1 + std::max(1, (n - 1 + scale - 1) / scale);
}

// Π d by dense normal equations over explicit basis functions (Gaussian elimination).
std::vector<double> denseProjection(int w, int h, const std::vector<double>& d, int scale) {
    const int kx = nodeCount(w, scale), ky = nodeCount(h, scale), m = kx * ky;
    auto phi = [&](int b, int x, int y) {
        const double fx = kx == 1 ? 1.0 : hat(x, b % kx, scale), fy = ky == 1 ? 1.0 : hat(y, b / kx, scale);
        return fx * fy;
    };
    std::vector<double> a(std::size_t(m) * (m + 1), 0.0);
    for (int i = 0; i < m; ++i)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const double pi = phi(i, x, y);
                if (pi == 0.0) continue;
                for (int j = 0; j < m; ++j) a[std::size_t(i) * (m + 1) + j] += pi * phi(j, x, y);
                a[std::size_t(i) * (m + 1) + m] += pi * d[std::size_t(y) * w + x];
            }
    for (int c = 0; c < m; ++c) {  // partial pivoting
        int p = c;
        for (int r = c + 1; r < m; ++r)
            if (std::abs(a[std::size_t(r) * (m + 1) + c]) > std::abs(a[std::size_t(p) * (m + 1) + c])) p = r;
        for (int j = 0; j <= m; ++j)
            std::swap(a[std::size_t(c) * (m + 1) + j], a[std::size_t(p) * (m + 1) + j]);
        for (int r = 0; r < m; ++r) {
            if (r == c) continue;
            const double f = a[std::size_t(r) * (m + 1) + c] / a[std::size_t(c) * (m + 1) + c];
            for (int j = c; j <= m; ++j)
                a[std::size_t(r) * (m + 1) + j] -= f * a[std::size_t(c) * (m + 1) + j];
        }
    }
    std::vector<double> out(std::size_t(w) * h, 0.0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int b = 0; b < m; ++b)
                out[std::size_t(y) * w + x] +=
                    phi(b, x, y) * a[std::size_t(b) * (m + 1) + m] / a[std::size_t(b) * (m + 1) + b];
    return out;
}

std::vector<double> noise(int w, int h, unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> n(0.3, 1.0);
    std::vector<double> d(std::size_t(w) * h);
    for (double& v : d) v = n(rng);
    return d;
}

TEST(Debias, ProjectionMatchesDenseLeastSquares) {
    // Sizes whose last node falls on the last pixel, past it, one node interval, one pixel wide.
    const struct {
        int w, h, scale;
    } cases[] = {{17, 9, 4}, {23, 14, 5}, {7, 7, 16}, {1, 12, 4}, {12, 1, 3}, {1, 1, 2}, {30, 20, 1}};
    for (const auto& c : cases) {
        const std::vector<double> d = noise(c.w, c.h, 7u + unsigned(c.w));
        const std::vector<double> fast = coarseProjection(c.w, c.h, d, c.scale);
        const std::vector<double> dense = denseProjection(c.w, c.h, d, c.scale);
        for (std::size_t i = 0; i < d.size(); ++i)
            ASSERT_NEAR(fast[i], dense[i], 1e-9)
                << c.w << "x" << c.h << " scale " << c.scale << " pixel " << i;
    }
}

TEST(Debias, ProjectionReproducesTheCoarseSpaceAndIsIdempotent) {
    const int w = 40, h = 27, scale = 8;
    // A bilinear function on the node grid: random node values interpolated by the hats.
    const int kx = nodeCount(w, scale), ky = nodeCount(h, scale);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-2.0, 2.0);
    std::vector<double> nodes(std::size_t(kx) * ky);
    for (double& v : nodes) v = u(rng);
    std::vector<double> f(std::size_t(w) * h, 0.0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int l = 0; l < ky; ++l)
                for (int k = 0; k < kx; ++k)
                    f[std::size_t(y) * w + x] +=
                        nodes[std::size_t(l) * kx + k] * hat(x, k, scale) * hat(y, l, scale);
    const std::vector<double> pf = coarseProjection(w, h, f, scale);
    for (std::size_t i = 0; i < f.size(); ++i) ASSERT_NEAR(pf[i], f[i], 1e-10);

    const std::vector<double> d = noise(w, h, 11);
    const std::vector<double> pd = coarseProjection(w, h, d, scale);
    const std::vector<double> ppd = coarseProjection(w, h, pd, scale);
    double sumD = 0.0, sumPd = 0.0, change = 0.0;
    for (std::size_t i = 0; i < d.size(); ++i) {
        ASSERT_NEAR(ppd[i], pd[i], 1e-10);
        sumD += d[i];
        sumPd += pd[i];
        change += std::abs(pd[i] - d[i]);
    }
    EXPECT_NEAR(sumPd, sumD, 1e-9);             // the hats sum to 1: the projection keeps the image sum
    EXPECT_GT(change / double(d.size()), 0.5);  // and it is not the identity on noise
    // Galerkin orthogonality: every hat's weighted sum of the residual is zero.
    for (int l = 0; l < ky; ++l)
        for (int k = 0; k < kx; ++k) {
            double s = 0.0;
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x)
                    s += hat(x, k, scale) * hat(y, l, scale) *
                         (d[std::size_t(y) * w + x] - pd[std::size_t(y) * w + x]);
            ASSERT_NEAR(s, 0.0, 1e-9) << "node " << k << "," << l;
        }
}

TEST(Debias, AReconstructionOffByACoarseFieldComesBackAsThePrimalKeepingItsDetail) {
    const int w = 48, h = 32, scale = 16;
    std::vector<float> primal(std::size_t(w) * h), recon(primal.size());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = std::size_t(y) * w + x;
            // Fine detail (a checkerboard) the reconstruction has and the primal has too.
            const float detail = ((x + y) % 2) ? 0.2f : -0.2f;
            primal[i] = 1.0f + detail;
            // The reconstruction is darker by a bilinear ramp (a coarse bias).
            recon[i] = primal[i] - (0.1f + 0.002f * float(x) + 0.001f * float(y));
        }
    const DebiasReport r = debiasChannel(w, h, recon, primal, scale);
    for (std::size_t i = 0; i < primal.size(); ++i) ASSERT_NEAR(recon[i], primal[i], 1e-5);
    EXPECT_NEAR(r.meanCorrection, 0.1 + 0.002 * 23.5 + 0.001 * 15.5, 1e-6);
    EXPECT_GT(r.meanBefore, 0.8);

    // The primal's fine noise does not come through: a reconstruction that is the truth (1)
    // against a primal of truth + zero-mean pixel noise moves by the noise's coarse part only.
    std::vector<float> noisy(primal.size()), truth(primal.size(), 1.0f);
    std::mt19937 rng(5);
    std::normal_distribution<float> n(0.0f, 0.5f);
    for (float& v : noisy) v = 1.0f + n(rng);
    debiasChannel(w, h, truth, noisy, scale);
    double mse = 0.0, primalMse = 0.0;
    for (std::size_t i = 0; i < truth.size(); ++i) {
        mse += (truth[i] - 1.0) * (truth[i] - 1.0);
        primalMse += (noisy[i] - 1.0) * (noisy[i] - 1.0);
    }
    // A hat's footprint averages about scale² pixels: the error variance falls by far more
    // than 10x (measured about 50x here; a per-pixel copy of the primal would give 1x).
    EXPECT_LT(mse, primalMse / 10.0);
}

TEST(Debias, NonFinitePixelsAddNothingAndStayOutOfTheResult) {
    const int w = 20, h = 20;
    std::vector<float> primal(std::size_t(w) * h, 2.0f), recon(primal.size(), 1.0f);
    primal[5] = std::numeric_limits<float>::quiet_NaN();
    primal[17] = std::numeric_limits<float>::infinity();
    debiasChannel(w, h, recon, primal, 8);
    for (std::size_t i = 0; i < recon.size(); ++i) {
        ASSERT_TRUE(std::isfinite(recon[i])) << i;
        // Two zero differences among 400 pull the coarse field below +1 near them (and a
        // least-squares fit overshoots a little elsewhere).
        ASSERT_GT(recon[i], 1.5f) << i;
        ASSERT_LT(recon[i], 2.05f) << i;
    }
}

TEST(Debias, BadArgumentsAreRefused) {
    std::vector<float> a(12, 1.0f), b(12, 1.0f), c(11, 1.0f);
    EXPECT_THROW(debiasChannel(4, 3, a, b, 0), Error);
    EXPECT_THROW(debiasChannel(4, 3, a, c, 4), Error);
    EXPECT_THROW(debiasChannel(5, 3, a, b, 4), Error);
    Image x(4, 3), y(3, 4);
    EXPECT_THROW(debiasImage(x, y, 4), Error);
}

}  // namespace
}  // namespace gdpt
