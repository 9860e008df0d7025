// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

#include "fiberfluid/model/bordered_system.hpp"
#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/model/bulk_treecode.hpp"
#include "fiberfluid/model/dof_map.hpp"
#include "fiberfluid/model/fiber_network.hpp"
#include "fiberfluid/model/model.hpp"
#include "fiberfluid/model/pair_kernels.hpp"

namespace fiberfluid::model {

// The paper's A at a configuration X with the boundary conditions applied,
// kept in the structure that the solvers exploit (model.md section 5):
//
//   [ K    s ] [u]   [f]     K = blockdiag(K_x, K_y, K_z)
//   [ s^T  0 ] [P] = [c]     K_a = Y_a L_bulk + gamma L_surf on axis a's active vertices
//
// The reduced unknowns are, axis by axis, the active vertices of the axis
// (its free vertices with elimination; all vertices with the penalty, whose
// constrained diagonal entries become the penalty), then P.
//
// The dense N x N bulk Laplacian is never stored here: dense_block() forms
// one block on request and bulk_product() applies it on the fly.
class FiberSystem final : public BorderedSystem {
 public:
  // The supports and prescribed values of the model held.
  FiberSystem(const Model& model, const Eigen::MatrixXd& X, BoundaryMethod method, double penalty);
  // The unknowns that `dofs` holds (e.g. with a contact active set). With a
  // strain-dependent law, each bulk weight is multiplied by the secant modulus
  // Y(e_ij) at the strains of `strained` (positions #V by dim, against the
  // reference lengths); null means the small-strain modulus Y(0).
  FiberSystem(const Model& model, const Eigen::MatrixXd& X, const DofMap& dofs,
              BoundaryMethod method, double penalty, const Eigen::MatrixXd* strained = nullptr);

  int dim() const { return dim_; }
  int num_vertices() const { return n_; }
  int offset(int axis) const { return offsets_[static_cast<size_t>(axis)]; }
  // BorderedSystem: one block per axis, the reduced unknowns of each axis.
  int num_blocks() const override { return dim_; }
  // Start of each axis block in the reduced unknowns, then the end of the last.
  const std::vector<int>& block_offsets() const override { return offsets_; }
  bool dense_blocks() const override;
  std::string block_name(int axis) const override {
    return std::string("the ") + "xyz"[axis] + " block";
  }
  const std::vector<int>& active(int axis) const { return active_[static_cast<size_t>(axis)]; }
  // Positions within active(axis) whose diagonal is the penalty (penalty method only).
  const std::vector<int>& penalised(int axis) const {
    return penalised_[static_cast<size_t>(axis)];
  }
  // Every axis has the same active and penalised vertices and the same Y, so
  // one factor of K_x serves all blocks.
  bool blocks_equal() const override;

  double young(int axis) const { return young_[axis]; }
  double surface_tension() const { return gamma_; }
  double penalty() const { return penalty_; }

  // Bulk Laplacian weights w_ij = h_ij (|S_i| + |S_j|) / |x_i - x_j|, with
  // h_ij = 1 / (2 (N-1)), or kept_ij / (2 c_ij) for pruned fibers (PairFactors).
  const Eigen::MatrixXd& positions() const { return X_; }
  const Eigen::VectorXd& area() const { return area_; }
  const Eigen::SparseMatrix<double>& surface_laplacian() const { return surface_; }

  // The bulk fibers are stored as neighbour lists (a horizon): the blocks
  // are sparse, N times the neighbours entries.
  bool sparse_fibers() const;
  // K_a over the active vertices, dense.
  Eigen::MatrixXd dense_block(int axis) const override;
  Eigen::MatrixXf dense_block_single(int axis) const override;
  // K_a as a sparse matrix (with the bulk fibers: N^2 entries).
  Eigen::SparseMatrix<double> sparse_block(int axis) const override {
    return sparse_block(axis, true);
  }
  // The sparse part of K_a over the active vertices: gamma L_surf plus the
  // bulk fibers when include_bulk (all pairs: N^2 entries), with the penalty.
  Eigen::SparseMatrix<double> sparse_block(int axis, bool include_bulk) const;
  // The surface-tension Laplacian plus the bulk diagonal (and the penalty):
  // sparse, and close to K_a because the complete bulk graph is so well
  // connected (model.md section 5).
  Eigen::SparseMatrix<double> preconditioner_block(int axis) const override;
  // Diagonal of axis a's L_bulk (#V), computed on first use (one pass over
  // the pairs); the same for every axis unless the weights are projected.
  const Eigen::VectorXd& bulk_diagonal(int axis = 0) const;
  // From now on, axis a's bulk weights are each times the share of a in the
  // fiber's direction at `positions` (BulkPairs::set_axis_projection): the
  // blocks then approximate a central fiber's tangent, axis by axis, for
  // Newton's Krylov preconditioner. Call before any block or product.
  void project_on_axes(const Eigen::MatrixXd& positions);
  bool projected() const { return projected_; }
  // L_bulk V for #V by k vectors, computed pair by pair without storing L_bulk
  // (projected weights: column a with axis a's; k = dim).
  // With Model::treecode_tolerance (and a constant law) both come from the
  // treecode; dense and sparse blocks stay exact, so that option goes with PCG.
  Eigen::MatrixXd bulk_product(const Eigen::MatrixXd& V) const;
  bool approximate_bulk() const { return treecode_ != nullptr; }
  // K u over the reduced unknowns except P, matrix-free.
  Eigen::VectorXd apply_K(const Eigen::VectorXd& u) const override;

  // Rows of the unreduced A(X) [U; P] at the listed vertices: per vertex i and
  // axis a, Y_a (L_bulk U)_ia + gamma (L_surf U)_ia + S_ia P, the force that the
  // fibers and the fluid need at i (boundary conditions not applied). The
  // reactions of the supports are these rows minus the loads. U: #V by dim.
  Eigen::MatrixXd unreduced_rows(const std::vector<int>& vertices, const Eigen::MatrixXd& U,
                                 double P) const;

  // The border s over the reduced unknowns except P.
  Eigen::VectorXd border() const override;

  // The reduced right-hand side [f; c] for loads F (dim N, the paper's
  // layout) and constrained displacements U_c (dim N, zero where free).
  Eigen::VectorXd reduce_rhs(const Eigen::VectorXd& F, const Eigen::VectorXd& U_c) const;
  // The full unknown vector (dim N + 1) from a reduced solution.
  Eigen::VectorXd expand(const Eigen::VectorXd& reduced, const Eigen::VectorXd& U_c) const;

 private:
  // dense_block in double or single precision.
  template <class Matrix>
  Matrix dense_block_in(int axis) const;
  // The bulk pairs of `vertices` (empty: all), with the secant law if any.
  // Axis a's weights when projected (axis -1: unprojected).
  BulkPairs bulk_pairs(const std::vector<int>& vertices = {}, int axis = -1) const;
  // Fills row (length N) with h_ij, times Y(e_ij) / ... for a strain-dependent law.
  void pair_row(int i, double* row) const;

  int dim_ = 3, n_ = 0;
  Eigen::MatrixXd X_;
  std::shared_ptr<const geom::FiberMask> fibers_;  // keeps factors_'s mask alive
  PairFactors factors_;
  Eigen::VectorXd area_;
  Eigen::MatrixXd S_;
  Eigen::SparseMatrix<double> surface_;
  mutable Eigen::VectorXd
      bulk_diagonal_[3];  // per axis when projected, else [0]; empty until asked
  bool projected_ = false;
  Eigen::MatrixXd projection_positions_;
  // The approximate bulk product and diagonal (Model::treecode_tolerance).
  std::shared_ptr<const BulkTreecode> treecode_;
  Eigen::Vector3d young_;  // per axis: Y m_a, or m_a when the moduli are per pair
  // Strain-dependent law: the law, the reference and strained positions.
  const FiberLaw* law_ = nullptr;
  Eigen::MatrixXd reference_, strained_;
  double gamma_ = 0.0;
  BoundaryMethod method_;
  double penalty_ = 0.0;
  std::vector<std::vector<int>> active_, penalised_, constrained_;
  std::vector<int> offsets_;  // per axis, then the total
};

// Constrained displacements of the model after step k of n as a dim N
// vector in the paper's layout (zero on free unknowns).
Eigen::VectorXd constrained_displacements(const Model& model, int step, int steps);

}  // namespace fiberfluid::model
