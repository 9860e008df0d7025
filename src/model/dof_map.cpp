// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/model/dof_map.hpp"

#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/model/model.hpp"

namespace fiberfluid::model {

DofMap::DofMap(int dim, int num_vertices, std::vector<char> held)
    : dim_(dim), n_(num_vertices), held_(std::move(held)) {
  held_.resize(static_cast<size_t>(dim_ * n_), 0);
  free_.assign(static_cast<size_t>(dim_), {});
  offsets_.assign(1, 0);
  full_index_.clear();
  for (int a = 0; a < dim_; ++a) {
    for (int i = 0; i < n_; ++i)
      if (!held_[static_cast<size_t>(a * n_ + i)]) {
        free_[static_cast<size_t>(a)].push_back(i);
        full_index_.push_back(a * n_ + i);
      }
    offsets_.push_back(static_cast<int>(full_index_.size()));
  }
  full_index_.push_back(dim_ * n_);  // P
}

DofMap DofMap::from_constraints(const Model& model) {
  std::vector<char> held(static_cast<size_t>(model.dim() * model.num_vertices()), 0);
  for (int d : partition_dofs(model).constrained) held[static_cast<size_t>(d)] = 1;
  return DofMap(model.dim(), model.num_vertices(), std::move(held));
}

std::vector<int> DofMap::held_dofs() const {
  std::vector<int> out;
  for (size_t d = 0; d < held_.size(); ++d)
    if (held_[d]) out.push_back(static_cast<int>(d));
  return out;
}

DofMap DofMap::with_held(const std::vector<int>& more) const {
  std::vector<char> held = held_;
  for (int d : more) held[static_cast<size_t>(d)] = 1;
  return DofMap(dim_, n_, std::move(held));
}

Eigen::VectorXd DofMap::reduce(const Eigen::VectorXd& full) const {
  Eigen::VectorXd out(static_cast<Eigen::Index>(full_index_.size()));
  for (size_t r = 0; r < full_index_.size(); ++r)
    out[static_cast<Eigen::Index>(r)] = full[full_index_[r]];
  return out;
}

Eigen::MatrixXd DofMap::reduce(const Eigen::MatrixXd& full) const {
  const auto m = static_cast<Eigen::Index>(full_index_.size());
  Eigen::MatrixXd out(m, m);
  for (Eigen::Index c = 0; c < m; ++c)
    for (Eigen::Index r = 0; r < m; ++r)
      out(r, c) = full(full_index_[static_cast<size_t>(r)], full_index_[static_cast<size_t>(c)]);
  return out;
}

void DofMap::scatter(const Eigen::VectorXd& reduced, Eigen::VectorXd& full) const {
  for (size_t r = 0; r < full_index_.size(); ++r)
    full[full_index_[r]] = reduced[static_cast<Eigen::Index>(r)];
}

}  // namespace fiberfluid::model
