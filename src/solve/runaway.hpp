// SPDX-License-Identifier: GPL-3.0-or-later
// What both steppers check before and after every step (internal header).
#pragma once

#include <Eigen/Core>
#include <string>

#include "model/model.hpp"
#include "solve/load_stepper.hpp"

namespace fiberfluid::solve {

// Why the run cannot start, or "": invalid options, or a singular setup.
std::string setup_problem(const model::Model& model, const SteppingOptions& options);

// Why the state reached after a step is a runaway rather than a result, or
// "": non-finite unknowns, a face turned over, a volume change beyond
// options.max_volume_change.
std::string runaway_reason(const model::Model& model, const SteppingOptions& options,
                           const Eigen::VectorXd& unknowns, const Eigen::MatrixXd& X,
                           double volume, double reference_volume,
                           const Eigen::MatrixXd& reference_face_areas);

}  // namespace fiberfluid::solve
