// SPDX-License-Identifier: GPL-3.0-or-later
// The linear bulk product and diagonal below O(N^2), from the 1/r sums of a
// treecode (treecode.hpp). With one pair factor h for every kept fiber (an
// unpruned body, or the global connection count):
//   sum_j w_ij V_j = h (|S_i| phi[V]_i + phi[|S| V]_i),
//   sum_j w_ij     = h (|S_i| phi[1]_i + phi[|S|]_i),
// phi[q]_i = sum_{j != i} q_j / |x_i - x_j|. Pruned fibers are subtracted
// pair by pair, exactly.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "fiberfluid/model/fiber_network.hpp"
#include "fiberfluid/model/treecode.hpp"

namespace fiberfluid::model {

class BulkTreecode {
 public:
  // Whether the factors have one h for all kept fibers.
  static bool applicable(const PairFactors& factors);

  // X: #V by 2 or 3 positions, area: |S_i|. tolerance: the product's
  // relative error to aim at (TreecodeOptions::for_tolerance).
  BulkTreecode(const Eigen::MatrixXd& X, const Eigen::VectorXd& area, const PairFactors& factors,
               double tolerance)
      : BulkTreecode(X, area, factors, TreecodeOptions::for_tolerance(tolerance)) {}
  BulkTreecode(const Eigen::MatrixXd& X, const Eigen::VectorXd& area, const PairFactors& factors,
               const TreecodeOptions& options);

  // sum_j w_ij per vertex (the bulk diagonal).
  const Eigen::VectorXd& row_sums() const { return row_sums_; }
  // (L V)_i = sum_j w_ij (V_i - V_j); V: #V by k.
  Eigen::MatrixXd laplacian_product(const Eigen::MatrixXd& V) const;
  const Treecode& treecode() const { return treecode_; }

 private:
  // sum_j w_ij V_j over every pair (pruned ones included), k <= 4 columns.
  Eigen::MatrixXd weighted_sums(const Eigen::MatrixXd& V) const;

  Treecode treecode_;
  Eigen::VectorXd area_;
  double h_ = 0.0;
  struct PrunedPair {
    int i, j;
    double weight;
  };
  std::vector<PrunedPair> pruned_;
  Eigen::VectorXd row_sums_;
};

}  // namespace fiberfluid::model
