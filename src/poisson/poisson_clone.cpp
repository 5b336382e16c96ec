// poisson_clone.cpp — seamless cloning as a weighted screened Poisson problem (see
// poisson_clone.h).
#include "poisson/poisson_clone.h"

#include <cmath>
#include <string>

#include "image/finite_check.h"
#include "util/error.h"

namespace gdpt {

Image seamlessClone(const vk::Context& ctx, const Image& source, const Image& target, const Image& mask,
                    const CloneOptions& o, SolveReport* report) {
    if (!source.sameSize(mask))
        throw Error("clone: mask is " + std::to_string(mask.width()) + "x" + std::to_string(mask.height()) +
                    " but the source is " + std::to_string(source.width()) + "x" +
                    std::to_string(source.height()));
    if (target.empty() || source.empty()) throw Error("clone: empty source or target image");
    // The target is copied outside the mask and is the boundary inside: it must be finite.
    if (scanNonFinite(target).any()) throw Error("clone: the target has NaN or infinite values");
    const int w = target.width(), h = target.height();
    const std::size_t n = target.pixelCount();
    // Ω in target coordinates.
    std::vector<std::uint8_t> inside(n, 0);
    auto sourceAt = [&](int x, int y, int& sx, int& sy) {
        sx = x - o.offsetX;
        sy = y - o.offsetY;
        return sx >= 0 && sy >= 0 && sx < source.width() && sy < source.height();
    };
    // Red > 0.5 selects; a NaN or infinite value in any channel does not.
    auto selected = [&](int sx, int sy) {
        for (int c = 0; c < 3; ++c)
            if (!std::isfinite(mask.at(sx, sy, c))) return false;
        return mask.at(sx, sy, 0) > 0.5f;
    };
    std::size_t count = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            int sx = 0, sy = 0;
            if (sourceAt(x, y, sx, sy) && selected(sx, sy)) {
                inside[target.index(x, y)] = 1;
                ++count;
            }
        }
    if (count == 0) throw Error("clone: the mask selects no pixel inside the target at this offset");

    // Guidance field per edge: source gradient where both source pixels exist, else target's.
    Image dx(w, h), dy(w, h);
    auto guidance = [&](int x0, int y0, int x1, int y1, float out[3]) {
        float gt[3], gs[3];
        bool haveSource = false;
        int sx0 = 0, sy0 = 0, sx1 = 0, sy1 = 0;
        if (sourceAt(x0, y0, sx0, sy0) && sourceAt(x1, y1, sx1, sy1)) haveSource = true;
        double nt = 0.0, ns = 0.0;
        for (int c = 0; c < 3; ++c) {
            gt[c] = target.at(x1, y1, c) - target.at(x0, y0, c);
            gs[c] = haveSource ? source.at(sx1, sy1, c) - source.at(sx0, sy0, c) : gt[c];
            nt += double(gt[c]) * gt[c];
            ns += double(gs[c]) * gs[c];
        }
        // A source gradient through a NaN or infinite pixel is no guidance: the target's.
        haveSource = haveSource && std::isfinite(ns);
        const bool useSource = haveSource && (!o.mixed || ns > nt);
        for (int c = 0; c < 3; ++c) out[c] = useSource ? gs[c] : gt[c];
    };
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = target.index(x, y);
            float g[3];
            if (x + 1 < w) {
                if (inside[i] || inside[i + 1])
                    guidance(x, y, x + 1, y, g);
                else
                    for (int c = 0; c < 3; ++c) g[c] = target.at(x + 1, y, c) - target.at(x, y, c);
                for (int c = 0; c < 3; ++c) dx.at(x, y, c) = g[c];
            }
            if (y + 1 < h) {
                if (inside[i] || inside[i + static_cast<std::size_t>(w)])
                    guidance(x, y, x, y + 1, g);
                else
                    for (int c = 0; c < 3; ++c) g[c] = target.at(x, y + 1, c) - target.at(x, y, c);
                for (int c = 0; c < 3; ++c) dy.at(x, y, c) = g[c];
            }
        }
    std::vector<float> weightPrimal(n);
    for (std::size_t i = 0; i < n; ++i)
        weightPrimal[i] = inside[i] ? 0.0f : static_cast<float>(kClonePinWeight);

    // Solve for the correction y = f − target: its primal is 0 and its guidance v − ∇target
    // vanishes away from Ω, so ‖b‖ measures the cloning problem itself and the relative
    // residual tolerance is not swamped by the pinned rows (weight 1e6 × target).
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                if (x + 1 < w) dx.at(x, y, c) -= target.at(x + 1, y, c) - target.at(x, y, c);
                if (y + 1 < h) dy.at(x, y, c) -= target.at(x, y + 1, c) - target.at(x, y, c);
            }
    const Image zero(w, h);
    PoissonSolverGpu solver(ctx, w, h);
    PoissonInput in;
    in.primal = &zero;
    in.dx = &dx;
    in.dy = &dy;
    in.weightPrimal = &weightPrimal;
    SolveOptions so;
    so.alpha = 1.0;
    so.tolerance = o.tolerance;
    so.solver = o.solver;
    so.maxIterations = 20000;
    Image result;
    const SolveReport r = solver.solve(in, so, result);
    if (report) *report = r;
    // f = target + y inside Ω; the Dirichlet boundary: exactly the target outside.
    for (int c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < n; ++i)
            result.plane(c)[i] = target.plane(c)[i] + (inside[i] ? result.plane(c)[i] : 0.0f);
    return result;
}

}  // namespace gdpt
