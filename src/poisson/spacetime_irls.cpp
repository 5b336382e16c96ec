// spacetime_irls.cpp — the rows' weights of the space-time solve (spacetime_irls.h).
#include "poisson/spacetime_irls.h"

#include <cmath>
#include <tuple>

#include "util/parallel.h"

namespace gdpt::spacetime {
namespace {

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

// IRLS's factor of a row with RGB residual e: 1 / (‖e‖ + reg).
inline double irlsFactor(const double e[3], double reg) {
    return 1.0 / (std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]) + reg);
}

}  // namespace

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

}  // namespace gdpt::spacetime
