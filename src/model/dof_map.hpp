// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <vector>

namespace fiberfluid::model {

struct Model;

// Which displacement unknowns are held (supports, prescribed values, the
// contact active set) and the map between the paper's full layout
// [u_x.. u_y.. (u_z..) P] and the reduced one: per axis the free vertices in
// ascending order, then P. Built once per constraint set; with_held() makes
// the map for a larger set (contact) without touching the model.
class DofMap {
 public:
  DofMap() = default;
  // held: one flag per displacement unknown (dim * N, the paper's layout).
  DofMap(int dim, int num_vertices, std::vector<char> held);
  // The supports and prescribed displacements of the model.
  static DofMap from_constraints(const Model& model);

  int dim() const { return dim_; }
  int num_vertices() const { return n_; }
  int num_full() const { return dim_ * n_ + 1; }
  int num_reduced() const { return offsets_.back() + 1; }
  bool held(int dof) const { return held_[static_cast<size_t>(dof)] != 0; }
  const std::vector<char>& held_flags() const { return held_; }
  // Free vertices of one axis, ascending.
  const std::vector<int>& free(int axis) const { return free_[static_cast<size_t>(axis)]; }
  // Start of each axis block in the reduced unknowns, then the end of the last.
  const std::vector<int>& offsets() const { return offsets_; }
  // Held unknowns, ascending.
  std::vector<int> held_dofs() const;

  // The same held set plus `more` (full-layout indices).
  DofMap with_held(const std::vector<int>& more) const;

  // The free entries of a full vector (or rows and columns of a full matrix), P last.
  Eigen::VectorXd reduce(const Eigen::VectorXd& full) const;
  Eigen::MatrixXd reduce(const Eigen::MatrixXd& full) const;
  // Writes a reduced vector into the free entries of `full`, keeping the held ones.
  void scatter(const Eigen::VectorXd& reduced, Eigen::VectorXd& full) const;
  // Full index of each reduced index.
  const std::vector<int>& full_index() const { return full_index_; }

 private:
  int dim_ = 0, n_ = 0;
  std::vector<char> held_;
  std::vector<std::vector<int>> free_;
  std::vector<int> offsets_{0};
  std::vector<int> full_index_;
};

}  // namespace fiberfluid::model
