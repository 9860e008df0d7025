// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Small pieces the calibration tests share.

#include <string>

#include "fiberfluid/fit/parameters.hpp"
#include "fiberfluid/solve/load_stepper.hpp"

namespace fiberfluid::testing {

// The Newton scheme in `steps` steps, converged far below the fits' tolerances.
inline solve::SteppingOptions newton(int steps) {
  solve::SteppingOptions o;
  o.scheme = solve::Scheme::Newton;
  o.steps = steps;
  o.newton.residual_tolerance = 1e-13;
  return o;
}

// A fitted parameter by name, from `start`, in log scale unless asked otherwise.
inline fit::Parameter parameter(const std::string& name, double start, bool log = true) {
  fit::Parameter p;
  p.name = name;
  p.initial = start;
  p.log_scale = log;
  return p;
}

}  // namespace fiberfluid::testing
