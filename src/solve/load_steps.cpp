// SPDX-License-Identifier: GPL-3.0-or-later
// The entry point of load stepping: a run handed to its scheme. Its own
// file, above both schemes, so that neither includes the other.
#include "fiberfluid/solve/newton/newton.hpp"
#include "fiberfluid/solve/stepping.hpp"

namespace fiberfluid::solve {

SteppingSummary solve_load_steps(const model::Model& model, const SteppingOptions& options,
                                 const StepObserver& observer) {
  return options.scheme == Scheme::Newton ? solve_newton_steps(model, options, observer)
                                          : solve_incremental_steps(model, options, observer);
}

}  // namespace fiberfluid::solve
