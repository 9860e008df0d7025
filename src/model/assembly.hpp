// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <vector>

#include "fiberfluid/model/model.hpp"

namespace fiberfluid::model {

// Positions X = s + u (#V by dim) from the unknown vector of the paper's layout.
Eigen::MatrixXd positions(const Model& model, const Eigen::VectorXd& unknowns);

// Displacements as #V by dim from the unknown vector.
Eigen::MatrixXd displacements(const Model& model, const Eigen::VectorXd& unknowns);

// B(X, factors) before boundary conditions: external loads from the geometry
// at X (area vectors, depths), each load scaled by its factor.
Eigen::VectorXd right_hand_side(const Model& model, const Eigen::MatrixXd& X,
                                const std::vector<double>& factors);

}  // namespace fiberfluid::model
