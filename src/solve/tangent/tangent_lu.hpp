// SPDX-License-Identifier: GPL-3.0-or-later
// The equilibrated LU of the exact Newton tangent over the unknowns a DofMap
// leaves free (internal to solve/tangent/): dense (LAPACK, its factors
// rounded to single precision when asked and DenseLU's check allows) or
// sparse (UMFPACK, its symbolic analysis kept while the pattern stays).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "fiberfluid/model/dof_map.hpp"
#include "fiberfluid/model/equilibrium.hpp"
#include "fiberfluid/solve/dense_lu.hpp"
#include "fiberfluid/solve/sparse_lu.hpp"
#include "fiberfluid/solve/status.hpp"
#include "fiberfluid/solve/tangent/added_tangent.hpp"

namespace fiberfluid::solve {

class TangentLU {
 public:
  enum class Storage { Dense, Sparse };
  explicit TangentLU(Storage storage) : storage_(storage) {}

  // Factors J(x) with `added` in, reduced to `dofs`.
  // `single` (dense only) rounds the factors to single precision where that
  // serves; rounded_to_single() says whether it did.
  Status factor(const model::Equilibrium& equilibrium, const Eigen::VectorXd& x,
                const std::vector<double>& factors, const model::DofMap& dofs,
                const AddedTangent& added, bool single = false);
  // J_ff^-1 b through the scaling.
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  bool rounded_to_single() const { return dense_ && dense_->single(); }

 private:
  Storage storage_;
  std::unique_ptr<DenseLU> dense_;
  std::unique_ptr<SparseLU> sparse_;
  // The tangent is equilibrated before its LU (rows, then columns, by their
  // largest entries): force rows of a stiff material and the volume row
  // differ by many orders, which would make a sound system look singular.
  Eigen::VectorXd row_scale_, column_scale_;
};

}  // namespace fiberfluid::solve
