// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

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

// The factor h_ij = kept_ij / (2 c_ij) of every bulk fiber at one vertex, so
// that w_ij = h_ij (|S_i| + |S_j|) / |x_i - x_j|; c_ij is N-1 when every pair
// is kept, else the model's connection count. h_ii = 0.
class PairFactors {
 public:
  PairFactors(const geom::FiberMask* fibers, ConnectionCount count, int num_vertices);
  // Fills row (length N) with h_ij for j = 0..N-1.
  void row(int i, double* row) const;
  // The same factors in the form the tiled pair kernels use:
  // h_ij = kept_ij / (c_i + c_j), c_i per vertex (N-1 with every pair kept,
  // the mean count with the global count, n_i with the symmetric one).
  std::vector<double> vertex_counts() const;
  const geom::FiberMask* mask() const { return fibers_; }  // null: every pair kept

 private:
  const geom::FiberMask* fibers_;
  ConnectionCount count_;
  int n_;
  std::vector<double> kept_;  // n_i
  double global_ = 0.0;       // the count for ConnectionCount::Global or a full body
};

// The surface-tension Laplacian gamma-free (paper Eq. 7), sparse: weight
// (|S_i| + |S_k|) / (2 |x_i - x_k|^2) on every mesh edge (i, k). The one
// builder of it (the linear system, Newton's equilibrium, the oracle).
// Throws InputError when an edge has zero length.
Eigen::SparseMatrix<double> surface_tension_laplacian(const Eigen::MatrixXd& X,
                                                      const Eigen::VectorXd& area,
                                                      const Eigen::MatrixXi& edges);

// X: #V by dim positions giving the fiber lengths; area: #V vertex area
// magnitudes |S_i|; edges: #E by 2 mesh edges; fibers and count as in the
// Model. Throws InputError when two vertices coincide (a fiber of zero length).
FiberLaplacians fiber_laplacians(const Eigen::MatrixXd& X, const Eigen::VectorXd& area,
                                 const Eigen::MatrixXi& edges,
                                 const geom::FiberMask* fibers = nullptr,
                                 ConnectionCount count = ConnectionCount::Symmetric);

// Y_axis * bulk + gamma * surface.
Eigen::MatrixXd axis_block(const FiberLaplacians& laplacians, const Material& material, int axis);

}  // namespace fiberfluid::model
