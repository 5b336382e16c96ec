// poisson_gpu_support.h — what the GPU Poisson solver's tests share: the fixture (PoissonGpu),
// random and structured test images, their exact gradients, the per-channel CPU problems, and the
// float tolerances they are held to.
//
// Float tolerances: a kernel output is a sum of ≤ 10 products of float inputs, so its
// rounding error is ≤ ~10·2⁻²⁴·Σ|terms| ≈ 6e-7 Σ|terms|; we allow 1e-5 of the magnitude
// of the terms (values are O(1) here). Solves are compared with the CPU solution in the
// relative 2-norm at 1e-4 after converging to a relative residual of 1e-6: float32 floors
// the residual near 1e-7, and the error is bounded by cond(A)·residual with cond(A) ≲ 100
// for these small grids.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "gpu_fixture.h"
#include "poisson/poisson_cpu.h"
#include "poisson/poisson_gpu.h"
#include "poisson_shared.h"
#include "vk/commands.h"

namespace gdpt::poisson_test {

using namespace gpu;

inline PoissonKernels& sharedKernels() {
    static PoissonKernels k(test::gpuContext());
    return k;
}

inline Field randomField(int w, int h, unsigned seed, double lo = 0.0, double hi = 1.0) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(lo, hi);
    Field v(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
    for (double& x : v) x = u(rng);
    return v;
}

// Smooth ramp + sharp box + line, different per channel.
inline Image structuredImage(int w, int h, double scale = 1.0) {
    Image im(w, h);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                double v = 0.5 + 0.3 * std::sin(0.7 * x + c) * std::cos(0.4 * y);
                if (x >= w / 4 && x < w / 2 && y >= h / 3 && y < (2 * h) / 3) v += 2.0 + c;
                if (x == w / 2) v += 0.7;
                im.at(x, y, c) = static_cast<float>(scale * v);
            }
    return im;
}

inline Image randomImage(int w, int h, unsigned seed, double lo, double hi) {
    Image im(w, h);
    for (int c = 0; c < 3; ++c) {
        const Field f = randomField(w, h, seed + static_cast<unsigned>(c), lo, hi);
        for (std::size_t i = 0; i < f.size(); ++i) im.plane(c)[i] = static_cast<float>(f[i]);
    }
    return im;
}

// Forward differences of an image (dropped rows 0).
inline void gradients(const Image& im, Image& dx, Image& dy) {
    const int w = im.width(), h = im.height();
    dx = Image(w, h);
    dy = Image(w, h);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                if (x + 1 < w) dx.at(x, y, c) = im.at(x + 1, y, c) - im.at(x, y, c);
                if (y + 1 < h) dy.at(x, y, c) = im.at(x, y + 1, c) - im.at(x, y, c);
            }
}

inline Field channel(const Image& im, int c) {
    return Field(im.plane(c).begin(), im.plane(c).end());
}

inline PoissonProblem channelProblem(const Image& primal, const Image& dx, const Image& dy, double alpha,
                                     int c) {
    PoissonProblem p;
    p.width = primal.width();
    p.height = primal.height();
    p.alpha = alpha;
    p.primal = channel(primal, c);
    p.dx = channel(dx, c);
    p.dy = channel(dy, c);
    return p;
}

inline double relError(const Field& a, const Field& b) {
    double num = 0.0, den = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        num += (a[i] - b[i]) * (a[i] - b[i]);
        den += b[i] * b[i];
    }
    return den > 0.0 ? std::sqrt(num / den) : std::sqrt(num);
}

inline double maxAbs(const Field& a) {
    double m = 0.0;
    for (double v : a) m = std::max(m, std::abs(v));
    return m;
}

// Uploads one double field per channel into a float buffer at a float offset.
inline void uploadRgb(vk::Buffer& buf, std::uint32_t offset, const std::array<Field, 3>& f) {
    std::vector<float> v;
    for (const Field& c : f)
        for (double x : c) v.push_back(static_cast<float>(x));
    buf.upload(v.data(), v.size() * sizeof(float), std::uint64_t{offset} * sizeof(float));
}

inline std::vector<float> downloadFloats(const vk::Buffer& buf, std::uint32_t offset, std::size_t count) {
    std::vector<float> v(count);
    buf.download(v.data(), count * sizeof(float), std::uint64_t{offset} * sizeof(float));
    return v;
}

inline void expectNear(const std::vector<float>& gpu, std::size_t gpuOffset, const Field& cpu, double tol,
                       const char* what) {
    const double scale = std::max(1.0, maxAbs(cpu));
    for (std::size_t i = 0; i < cpu.size(); ++i)
        ASSERT_NEAR(gpu[gpuOffset + i], cpu[i], tol * scale) << what << " at " << i;
}

class PoissonGpu : public test::GpuTest {
protected:
    template <typename F>
    void run(PoissonGpuEngine& e, F record) {
        vk::CommandStream s(ctx(), "poisson test");
        VkCommandBuffer cmd = s.begin();
        e.bind();
        record(cmd);
        s.submitAndWait();
    }

    SolveReport solve(const Image& primal, const Image& dx, const Image& dy, const SolveOptions& o,
                      Image& out, const PoissonInput* extra = nullptr) {
        PoissonSolverGpu solver(ctx(), primal.width(), primal.height(), &sharedKernels());
        PoissonInput in = extra ? *extra : PoissonInput{};
        in.primal = &primal;
        in.dx = &dx;
        in.dy = &dy;
        return solver.solve(in, o, out);
    }
};

// A 37x21 problem with random weights: 4 levels (37x21, 19x11, 10x6, 5x3).
struct OperatorCase {
    int w = 37, h = 21;
    double alpha = 0.3;
    std::array<PoissonProblem, 3> problems;
    OperatorCase() {
        for (int c = 0; c < 3; ++c) {
            PoissonProblem& p = problems[static_cast<std::size_t>(c)];
            p.width = w;
            p.height = h;
            p.alpha = alpha;
            const unsigned s = 100u * static_cast<unsigned>(c);
            p.primal = randomField(w, h, s + 1, -1.0, 2.0);
            p.dx = randomField(w, h, s + 2, -1.0, 1.0);
            p.dy = randomField(w, h, s + 3, -1.0, 1.0);
            // Shared weights (the GPU operator is one for all channels).
            p.weightPrimal = randomField(w, h, 7, 0.1, 2.0);
            p.weightDx = randomField(w, h, 8, 0.1, 2.0);
            p.weightDy = randomField(w, h, 9, 0.1, 2.0);
        }
    }
    void upload(PoissonGpuEngine& e) const {
        uploadRgb(e.primal, 0, {problems[0].primal, problems[1].primal, problems[2].primal});
        uploadRgb(e.dx, 0, {problems[0].dx, problems[1].dx, problems[2].dx});
        uploadRgb(e.dy, 0, {problems[0].dy, problems[1].dy, problems[2].dy});
        uploadRgb(e.weights, 0, {problems[0].weightPrimal, problems[0].weightDx, problems[0].weightDy});
    }
};

// The structured image, its exact gradients, and a primal with Gaussian noise (σ 0.05).
struct NoisyProblem {
    Image truth, primal, dx, dy;
};

inline NoisyProblem noisyProblem(int w, int h, unsigned seed) {
    NoisyProblem p;
    p.truth = structuredImage(w, h);
    gradients(p.truth, p.dx, p.dy);
    p.primal = p.truth;
    std::mt19937 rng(seed);
    std::normal_distribution<float> noise(0.0f, 0.05f);
    for (int c = 0; c < 3; ++c)
        for (float& v : p.primal.plane(c)) v += noise(rng);
    return p;
}

// Random primal, gradients and variances (primal variance in [0.01, 1], the gradients'
// in the given ranges) from images seeded seed .. seed + 5.
struct VarianceProblem {
    Image primal, dx, dy, vp, vx, vy;
    [[nodiscard]] PoissonInput variances() const {
        PoissonInput in;
        in.varPrimal = &vp;
        in.varDx = &vx;
        in.varDy = &vy;
        return in;
    }
};

inline VarianceProblem varianceProblem(int w, int h, unsigned seed, std::array<double, 2> vxRange,
                                       std::array<double, 2> vyRange) {
    return {randomImage(w, h, seed, 0.0, 1.0),
            randomImage(w, h, seed + 1, -0.3, 0.3),
            randomImage(w, h, seed + 2, -0.3, 0.3),
            randomImage(w, h, seed + 3, 0.01, 1.0),
            randomImage(w, h, seed + 4, vxRange[0], vxRange[1]),
            randomImage(w, h, seed + 5, vyRange[0], vyRange[1])};
}

}  // namespace gdpt::poisson_test
