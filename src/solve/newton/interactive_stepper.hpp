// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "fiberfluid/model/model.hpp"
#include "fiberfluid/solve/newton/newton.hpp"
#include "fiberfluid/solve/stepping.hpp"

namespace fiberfluid::solve {

// One Newton step at a time, each to a load point the caller chooses as it
// goes: a paddle moved by a hand or a haptic device, a load turned up. Each
// step starts from the last equilibrium (a warm start; no extrapolation along
// the steps taken, which would guess wrong where a hand stops or turns),
// keeps the tangent's preconditioner and its factorisation, and cuts itself
// in halves when Newton fails, as the batch stepper does. A failed step leaves
// the last equilibrium in place.
//
// It refers to the model, which must outlive it; one thread at a time.
class InteractiveStepper {
 public:
  // Starts at the unloaded body (zero displacement). The options' scheme,
  // steps, predictor, arc-length control and sensitivities are not used here.
  // Throws InputError when the model cannot be run (a singular setup, a
  // paddle inside the body at its start, bad options).
  InteractiveStepper(const model::Model& model, const SteppingOptions& options);
  ~InteractiveStepper();
  InteractiveStepper(const InteractiveStepper&) = delete;
  InteractiveStepper& operator=(const InteractiveStepper&) = delete;

  struct Result {
    bool success = false;
    std::string message;  // why the step failed, or ""
    StepRecord record;    // forces, paddles, iterations, pair passes of the step
  };
  // Solves equilibrium at `to` from the last state. Throws InputError when
  // `to` does not fit the model (its sizes, non-finite values, paddles that
  // meet each other).
  Result step(const LoadPoint& to);

  const model::Model& model() const;
  // The last equilibrium: [u_x.. u_y.. (u_z..) P], and the positions (#V by dim).
  const Eigen::VectorXd& unknowns() const;
  Eigen::MatrixXd positions() const;
  // The point the last equilibrium stands at (the unloaded start before any step).
  const LoadPoint& point() const;
  int steps_taken() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fiberfluid::solve
