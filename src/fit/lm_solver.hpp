// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// Ceres' options for this project's Levenberg-Marquardt fits (one
// calibration, or several specimens at once). Included only by the .cpp
// files that include Ceres already (its headers compile slowly).

#include <ceres/ceres.h>

namespace fiberfluid::fit {

inline ceres::Solver::Options lm_solver(int max_iterations, double function_tolerance,
                                        double parameter_tolerance,
                                        double initial_trust_region_radius) {
  ceres::Solver::Options solver;
  solver.minimizer_type = ceres::TRUST_REGION;
  solver.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.initial_trust_region_radius = initial_trust_region_radius;
  solver.max_num_iterations = max_iterations;
  solver.function_tolerance = function_tolerance;
  solver.parameter_tolerance = parameter_tolerance;
  solver.gradient_tolerance = 1e-16;
  solver.num_threads = 1;  // the forward runs are threaded themselves
  solver.logging_type = ceres::SILENT;
  solver.update_state_every_iteration = true;  // the iteration callbacks read the point
  return solver;
}

}  // namespace fiberfluid::fit
