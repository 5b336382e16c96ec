// poisson_irls.h — L1 screened Poisson reconstruction by iteratively reweighted least squares
// (IRLS), as the published G-PT solver does it (Kettunen et al. 2015, §4 "L1 reconstruction";
// the authors' public screened Poisson solver by T. Karras, poisson_solver/ in
// gradientdomain-mitsuba):
//   iteration k = 0: all weights 1 (an L2 solve);
//   iteration k ≥ 1: every row j (primal, dx, dy) gets w_j = 1 / (‖e_j‖_RGB + reg_k) with
//     e_j the row residual of the current RGB estimate (primal rows: α (x − t)),
//     ‖·‖_RGB the Euclidean length over the three channels (weights shared by R, G, B),
//     reg_k = regInit · regIter^(k−1), and the weights renormalised to mean 1;
//   each iteration's inner solve is warm-started from the previous estimate (the first
//   from the primal). Minimising Σ w_j e_j² with w_j ≈ 1/‖e_j‖ approximates Σ ‖e_j‖.
#pragma once

#include <array>
#include <vector>

#include "poisson/poisson_cpu.h"

namespace gdpt {

// One RGB reconstruction problem; planar fields of width*height values per channel.
struct RgbPoissonProblem {
    int width = 0;
    int height = 0;
    double alpha = 0.2;
    std::array<Field, 3> primal, dx, dy;
};

enum class InnerSolver { Cg, PcgMultigrid };

struct IrlsOptions {
    int iterations = 20;    // IRLS iterations (1 = plain L2)
    double regInit = 0.05;  // reg_1
    double regIter = 0.5;   // reg_k = regInit · regIter^(k−1)
    // reg is in the units of the input (radiance for G-PT). For data in other units, scale
    // it here (e.g. the image's typical value) instead of rescaling the data.
    double regScale = 1.0;
    int innerIterations = 50;     // CG iterations per IRLS iteration
    double innerTolerance = 0.0;  // relative residual; 0 = always run innerIterations
    InnerSolver inner = InnerSolver::Cg;
};

// Presets of the published solver (its Solver.cpp, setConfigPreset: L1D and L2D).
IrlsOptions irlsPresetL1D();  // default: 20 x 50 CG, regInit 0.05, regIter 0.5
IrlsOptions irlsPresetL2D();  // 1 x 50 (L2)

// Row weights shared by the three channels.
struct IrlsWeights {
    Field primal, dx, dy;  // dropped rows (last column of dx, last row of dy) are 0
};

// w_j = 1 / (‖e_j‖_RGB + reg) for every kept row, then scaled to mean 1 over kept rows.
IrlsWeights computeIrlsWeights(const RgbPoissonProblem& problem, const std::array<Field, 3>& x, double reg);

struct IrlsStats {
    int irlsIterations = 0;
    int innerIterations = 0;  // total over all IRLS iterations and channels
};

// L1 reconstruction; returns the three channels. Throws gdpt::Error on invalid input.
std::array<Field, 3> solveL1Irls(const RgbPoissonProblem& problem,
                                 const IrlsOptions& options = irlsPresetL1D(), IrlsStats* stats = nullptr);

}  // namespace gdpt
