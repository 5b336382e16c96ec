// spacetime_weights.h — the row weights of temporal G-PT's variance-weighted space-time
// reconstructions (`--recon wl2`, `wl1`), the 2D ones' (poisson_gpu.h) extended to the temporal
// and mixed rows: each row gets w = 1 / (v + ε), v the RGB mean of its estimate's variance per
// pixel (var_primal, var_dx, var_dy of each frame; the paired differences' variances of dt, dxt,
// dyt from the halves' sample groups, sample_groups.h), for wl1 first averaged over a
// (2r+1)² box (boxFilteredVariance) so that a row's weight is not an estimate from its own
// samples, and bounded to `contrast` around the median of all the window's rows
// (boundWeightContrast: a still scene's dt has variance 0, whose rows would otherwise weigh 10⁸
// times a firefly's); 0 where the variance is not finite or negative. The weights are then
// renormalised to mean 1 over the rows that have one (a common scale, which moves no minimiser).
#pragma once

#include <vector>

#include "image/image.h"
#include "poisson/poisson_spacetime.h"
#include "poisson/weight_contrast.h"

namespace gdpt {

struct RowVariances {
    std::vector<Image> primal, dx, dy;  // per frame of the window
    // Per pair of consecutive frames (F − 1), at the earlier frame's pixels, as the solve's dt;
    // dxt, dyt only with mixed rows.
    std::vector<Image> dt, dxt, dyt;
    Image dtPrevious;                // the rows to the previous window's last frame (at its pixels), or empty
    Image dxtPrevious, dytPrevious;  // its mixed rows (with problem.dxtPrevious), or empty
};

// Sets problem.weight{Primal,Dx,Dy,Dt,Dxt,Dyt,DtPrevious,DxtPrevious,DytPrevious} from `v` (dxt,
// dyt with γ > 0, dtPrevious with problem.previous, dxtPrevious and dytPrevious with
// problem.dxtPrevious). Throws gdpt::Error if the counts or sizes disagree.
void setVarianceWeights(SpaceTimeProblem& problem, const RowVariances& v, bool filtered, double epsilon,
                        int radius, double contrast = kDefaultVarianceWeightContrast);

}  // namespace gdpt
