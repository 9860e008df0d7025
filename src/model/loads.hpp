// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <vector>

#include "model/model.hpp"

namespace fiberfluid::model {

// Depth of each vertex below the highest point of X along the acceleration
// direction: h_i = (x_i - x_top) . a / |a| >= 0. X: #V by dim.
Eigen::VectorXd hydrostatic_depths(const Eigen::MatrixXd& X, const Eigen::Vector3d& acceleration);

// The load part of the right-hand side B (paper Eq. 4) at positions X with
// vertex area vectors S (#V by dim), each load scaled by factors[l]. Length
// dim * N + 1; the last (volume) entry is 0.
Eigen::VectorXd load_vector(const Model& model, const Eigen::MatrixXd& X,
                            const Eigen::MatrixXd& S, const std::vector<double>& factors);

// Factors of every load after step k of n.
std::vector<double> load_factors(const Model& model, int step, int steps);

}  // namespace fiberfluid::model
