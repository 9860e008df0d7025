// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <vector>

#include "model/model.hpp"

namespace fiberfluid::model {

// Positions X = s + u (#V by dim) from the unknown vector of the paper's layout.
Eigen::MatrixXd positions(const Model& model, const Eigen::VectorXd& unknowns);

// Displacements as #V by dim from the unknown vector.
Eigen::MatrixXd displacements(const Model& model, const Eigen::VectorXd& unknowns);

// The paper's matrix A at positions X, before boundary conditions:
//   [ K(X)    S(X) ]     K = blockdiag(Y_x L_bulk + gamma L_surf, ...)
//   [ S(X)^T  0    ]     S = vertex area vectors at X (one column)
// (dim N + 1) square, the sign convention of the paper's worked example.
// A(s) is the tangent of the linear model; A at a deformed configuration is
// the matrix the paper rebuilds for geometry updates.
Eigen::MatrixXd system_matrix(const Model& model, const Eigen::MatrixXd& X);

// B(X, factors) before boundary conditions: external loads from the geometry
// at X (area vectors, depths), each load scaled by its factor.
Eigen::VectorXd right_hand_side(const Model& model, const Eigen::MatrixXd& X,
                                const std::vector<double>& factors);

// Residual of the linear model about the reference configuration,
// A(s) x - B(s, factors), for any unknown vector x (boundary conditions not
// applied). Zero at the linear solution on the free degrees of freedom.
Eigen::VectorXd linear_residual(const Model& model, const Eigen::VectorXd& unknowns,
                                const std::vector<double>& factors);

}  // namespace fiberfluid::model
