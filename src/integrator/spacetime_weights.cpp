// spacetime_weights.cpp — the variance-weighted space-time reconstructions' row weights.
#include "integrator/spacetime_weights.h"

#include <string>

#include "poisson/poisson_gpu.h"
#include "util/error.h"

namespace gdpt {
namespace {

// The weights of `images` (frame-major, W·H each) appended to `to`.
void appendWeights(Field& to, const std::vector<Image>& images, std::size_t pixels, bool filtered,
                   double epsilon, int radius, const char* what) {
    for (const Image& var : images) {
        if (var.pixelCount() != pixels)
            throw Error(std::string("space-time weights: a ") + what + " variance has " +
                        std::to_string(var.pixelCount()) + " pixels, expected " + std::to_string(pixels));
        // (Non-finite or negative variances give weight 0; their counts are not reported.)
        NonFiniteCounts unused;
        if (filtered) {
            for (float v : boxFilteredVariance(var, radius, unused.variance, unused.negativeVariance))
                to.push_back(inverseFilteredVariance(v, epsilon));
            continue;
        }
        for (std::size_t i = 0; i < pixels; ++i) to.push_back(inverseVariance(var, i, epsilon, unused));
    }
}

// Weight 0 for the rows the solve does not have (unitWeights in poisson/spacetime_irls.h): dx of
// each frame's last column, dy of its last row, dt and the rows to the previous frame where a
// pixel has no temporal partner. They then count neither in the bound's median nor in the
// renormalisation, as in the 2D weights (poisson_gpu.cpp). The mixed rows' own conditions
// (rigidMixedRows) are left to the solve.
void zeroAbsentRows(SpaceTimeProblem& p) {
    for (std::size_t i = 0; i < p.weightDx.size(); ++i)
        if (!spaceTimeHasDx(p, i)) p.weightDx[i] = 0.0;
    for (std::size_t i = 0; i < p.weightDy.size(); ++i)
        if (!spaceTimeHasDy(p, i)) p.weightDy[i] = 0.0;
    for (std::size_t i = 0; i < p.temporalPartner.size() && i < p.weightDt.size(); ++i)
        if (p.temporalPartner[i] == kNoTemporalPartner) p.weightDt[i] = 0.0;
    for (std::size_t j = 0; j < p.previousPartner.size() && j < p.weightDtPrevious.size(); ++j)
        if (p.previousPartner[j] == kNoTemporalPartner) p.weightDtPrevious[j] = 0.0;
}

}  // namespace

void setVarianceWeights(SpaceTimeProblem& problem, const RowVariances& v, bool filtered, double epsilon,
                        int radius, double contrast) {
    const std::size_t frames = std::size_t(problem.frames), pixels = problem.pixels();
    const bool mixed = problem.gamma > 0.0, previous = !problem.previous[0].empty();
    const auto count = [&](const std::vector<Image>& images, std::size_t want, const char* what) {
        if (images.size() != want)
            throw Error(std::string("space-time weights: ") + std::to_string(images.size()) + " " + what +
                        " variances for a window of " + std::to_string(frames) + " frames");
    };
    count(v.primal, frames, "primal");
    count(v.dx, frames, "dx");
    count(v.dy, frames, "dy");
    count(v.dt, frames - 1, "dt");
    if (mixed) {
        count(v.dxt, frames - 1, "dxt");
        count(v.dyt, frames - 1, "dyt");
    }
    if (previous && v.dtPrevious.pixelCount() != pixels)
        throw Error("space-time weights: the window joins a previous frame but has no variance for its dt");
    const bool mixedPrevious = !problem.dxtPrevious[0].empty();
    if (mixedPrevious && (v.dxtPrevious.pixelCount() != pixels || v.dytPrevious.pixelCount() != pixels))
        throw Error("space-time weights: the mixed rows to the previous frame have no variances");
    std::vector<Field*> fields = {
        &problem.weightPrimal,     &problem.weightDx,          &problem.weightDy,
        &problem.weightDt,         &problem.weightDxt,         &problem.weightDyt,
        &problem.weightDtPrevious, &problem.weightDxtPrevious, &problem.weightDytPrevious};
    for (Field* f : fields) f->clear();
    appendWeights(problem.weightPrimal, v.primal, pixels, filtered, epsilon, radius, "primal");
    appendWeights(problem.weightDx, v.dx, pixels, filtered, epsilon, radius, "dx");
    appendWeights(problem.weightDy, v.dy, pixels, filtered, epsilon, radius, "dy");
    appendWeights(problem.weightDt, v.dt, pixels, filtered, epsilon, radius, "dt");
    if (mixed) {
        appendWeights(problem.weightDxt, v.dxt, pixels, filtered, epsilon, radius, "dxt");
        appendWeights(problem.weightDyt, v.dyt, pixels, filtered, epsilon, radius, "dyt");
    }
    if (previous)
        appendWeights(problem.weightDtPrevious, {v.dtPrevious}, pixels, filtered, epsilon, radius, "dt");
    if (mixedPrevious) {
        appendWeights(problem.weightDxtPrevious, {v.dxtPrevious}, pixels, filtered, epsilon, radius, "dxt");
        appendWeights(problem.weightDytPrevious, {v.dytPrevious}, pixels, filtered, epsilon, radius, "dyt");
    }
    zeroAbsentRows(problem);
    if (filtered)
        boundWeightContrast({&problem.weightPrimal, &problem.weightDx, &problem.weightDy, &problem.weightDt,
                             &problem.weightDxt, &problem.weightDyt, &problem.weightDtPrevious,
                             &problem.weightDxtPrevious, &problem.weightDytPrevious},
                            contrast);
    double sum = 0.0, rows = 0.0;
    for (const Field* f : fields)
        for (double w : *f)
            if (w > 0.0) sum += w, rows += 1.0;
    if (!(sum > 0.0)) return;
    const double scale = rows / sum;
    for (Field* f : fields)
        for (double& w : *f) w *= scale;
}

}  // namespace gdpt
