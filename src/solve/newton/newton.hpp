// SPDX-License-Identifier: GPL-3.0-or-later
// The Newton scheme (model.md section 7): equilibrium R(x; lambda_k) = 0 at
// every load step, with a line search, step cutting, rigid paddles as an
// active set, and arc-length control. Its parts (internal): the solver
// (newton_solver.hpp), the paddles' contact set (contact_set.hpp), the walk
// along the path (path_walk.hpp), what each converged step leaves
// (step_finisher.hpp); one step at a time: interactive_stepper.hpp.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fiberfluid/model/model.hpp"
#include "fiberfluid/solve/stepping.hpp"
#include "fiberfluid/util/status.hpp"

namespace fiberfluid::solve {

// Where the loads, the supports and the paddles stand at one point of a load
// path: what a Newton step solves equilibrium at.
struct LoadPoint {
  std::vector<double> factors;  // per Model::loads: 0 unloaded, 1 the full load
  Eigen::VectorXd held_values;  // dim N: the supports' prescribed displacements, zero where free
  std::vector<double> planes;   // per Model::paddles: the plane's coordinate (m)
};

// The model's own load path at t (t = k after step k of `steps`, linear in
// between): its loads' and supports' schedules, its paddles' travel.
LoadPoint scheduled_point(const model::Model& model, double t, int steps);

// The Newton scheme (what solve_load_steps runs for Scheme::Newton).
SteppingSummary solve_newton_steps(const model::Model& model, const SteppingOptions& options,
                                   const StepObserver& observer = {});

// Whether the Newton stepper's analytic sensitivities (du/dtheta and the
// forces' derivatives) are exact for this model, else why not: a sticking
// paddle holds each vertex where it first touched, and that place moves with
// the parameters, which the sensitivities take as fixed.
Status check_sensitivities(const model::Model& model);

// Whether SteppingOptions::warm_start can be used for this model, else why
// not: the Newton scheme by load control, a start of the model's size with
// finite values, and no sticking paddle (where a vertex sticks depends on
// the way there).
Status check_warm_start(const model::Model& model, const SteppingOptions& options);

}  // namespace fiberfluid::solve
