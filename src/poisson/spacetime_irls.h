// spacetime_irls.h — the rows' weights of the space-time solve: each row's own weight (1, the
// problem's, or 0 where the row does not exist) and IRLS's reweighting for L1 (poisson_spacetime.h).
// Internal to the solver (gdpt_poisson_cpu).
#pragma once

#include <cstdint>

#include "poisson/spacetime_operator.h"

namespace gdpt::spacetime {

// The rows' own weights (1, or the problem's; 0 for the rows that do not exist), into wt (its
// buffers reused).
void unitWeights(const SpaceTimeProblem& p, Weights& wt);

// to = from, each array in to's buffer where it is large enough.
void copyWeights(const Weights& from, Weights& to);

// IRLS weights of the estimate x: the row's weight times 1 / (‖e‖_RGB + reg) for every kept
// row, the IRLS factors renormalised to mean 1 over the kept rows (as poisson_irls_weights.comp).
// `kept`: the unit weights (0 for dropped rows); `wt` gets the same sizes.
void irlsWeights(const SpaceTimeProblem& p, const Operator& op, const std::array<Field, 3>& x, double reg,
                 const Weights& kept, Weights& wt, std::uint32_t threads);

}  // namespace gdpt::spacetime
