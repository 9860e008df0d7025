// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>

#include "model/model.hpp"

namespace fiberfluid::model {

// The two weighted graph Laplacians (positive diagonal, negative off-diagonal)
// from which each axis block of the stiffness is made:
//   bulk:    every pair i != j, weight (S_i + S_j) / (2 (N-1) |x_i - x_j|)   (paper Eq. 6)
//   surface: every mesh edge,   weight (S_i + S_k) / (2 |x_i - x_k|^2)       (paper Eq. 7)
// so that block(axis) = Y_axis * bulk + gamma * surface.
struct FiberLaplacians {
  Eigen::MatrixXd bulk;     // N x N, dense (all pairs)
  Eigen::MatrixXd surface;  // N x N, nonzero on mesh edges only
};

// X: #V by dim positions giving the fiber lengths; area: #V vertex area
// magnitudes |S_i|; edges: #E by 2 mesh edges. Throws InputError when two
// vertices coincide (a fiber of zero length).
FiberLaplacians fiber_laplacians(const Eigen::MatrixXd& X, const Eigen::VectorXd& area,
                                 const Eigen::MatrixXi& edges);

// Y_axis * bulk + gamma * surface.
Eigen::MatrixXd axis_block(const FiberLaplacians& laplacians, const Material& material, int axis);

}  // namespace fiberfluid::model
