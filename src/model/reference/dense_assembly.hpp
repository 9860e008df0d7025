// SPDX-License-Identifier: GPL-3.0-or-later
// The reference assembly: the oracle. The paper's matrices written the plain
// way (dense, every entry from its definition, no tiles, no threads, no
// structure), which the tests hold the production paths to (FiberSystem, the
// pair kernels, Equilibrium, the solver backends). Not used by a run.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/model/model.hpp"

namespace fiberfluid::model::reference {

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
// magnitudes |S_i|; edges: #E by 2 mesh edges; fibers and count as in the
// Model. Throws InputError when two vertices coincide (a fiber of zero length).
FiberLaplacians fiber_laplacians(const Eigen::MatrixXd& X, const Eigen::VectorXd& area,
                                 const Eigen::MatrixXi& edges,
                                 const geom::FiberMask* fibers = nullptr,
                                 ConnectionCount count = ConnectionCount::Symmetric);

// Y_axis * bulk + gamma * surface.
Eigen::MatrixXd axis_block(const FiberLaplacians& laplacians, const Material& material, int axis);

// The paper's matrix A at positions X, before boundary conditions:
//   [ K(X)    S(X) ]     K = blockdiag(Y_x L_bulk + gamma L_surf, ...)
//   [ S(X)^T  0    ]     S = vertex area vectors at X (one column)
// (dim N + 1) square, the sign convention of the paper's worked example.
// A(s) is the tangent of the linear model; A at a deformed configuration is
// the matrix the paper rebuilds for geometry updates.
Eigen::MatrixXd system_matrix(const Model& model, const Eigen::MatrixXd& X);

// Residual of the linear model about the reference configuration,
// A(s) x - B(s, factors), for any unknown vector x (boundary conditions not
// applied). Zero at the linear solution on the free degrees of freedom.
Eigen::VectorXd linear_residual(const Model& model, const Eigen::VectorXd& unknowns,
                                const std::vector<double>& factors);

// The paper's penalty: A(d, d) = penalty and B(d) = penalty * value for each
// constrained unknown d; the rest of the row is kept.
void apply_penalty(const DofPartition& partition, const Eigen::VectorXd& values, double penalty,
                   Eigen::MatrixXd& A, Eigen::VectorXd& B);

// Elimination: A_ff x_f = B_f - A_fc values.
void reduce_system(const DofPartition& partition, const Eigen::VectorXd& values,
                   const Eigen::MatrixXd& A, const Eigen::VectorXd& B, Eigen::MatrixXd& A_free,
                   Eigen::VectorXd& B_free);
Eigen::VectorXd reduce_rhs(const DofPartition& partition, const Eigen::VectorXd& values,
                           const Eigen::MatrixXd& A, const Eigen::VectorXd& B);

}  // namespace fiberfluid::model::reference
