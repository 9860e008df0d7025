// SPDX-License-Identifier: GPL-3.0-or-later
// Internal: the split of the unknowns into free and held ones, shared by the
// static solve and the integrators.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

namespace fiberfluid::fem {

struct FreeUnknowns {
  std::vector<int> index;  // per unknown: its place among the free ones, or -1 when held
  int free = 0;

  // `held` must lie in 0..n-1.
  FreeUnknowns(int n, const std::vector<int>& held) : index(static_cast<size_t>(n), 0) {
    for (int d : held) index[static_cast<size_t>(d)] = -1;
    for (int d = 0; d < n; ++d)
      if (index[static_cast<size_t>(d)] >= 0) index[static_cast<size_t>(d)] = free++;
  }
  Eigen::SparseMatrix<double> free_block(const Eigen::SparseMatrix<double>& A) const {
    std::vector<Eigen::Triplet<double>> entries;
    for (int c = 0; c < A.outerSize(); ++c)
      for (Eigen::SparseMatrix<double>::InnerIterator it(A, c); it; ++it) {
        const int r = index[static_cast<size_t>(it.row())],
                  k = index[static_cast<size_t>(it.col())];
        if (r >= 0 && k >= 0) entries.emplace_back(r, k, it.value());
      }
    Eigen::SparseMatrix<double> B(free, free);
    B.setFromTriplets(entries.begin(), entries.end());
    return B;
  }
  Eigen::VectorXd restrict(const Eigen::VectorXd& x) const {
    Eigen::VectorXd out(free);
    for (size_t d = 0; d < index.size(); ++d)
      if (index[d] >= 0) out[index[d]] = x[static_cast<Eigen::Index>(d)];
    return out;
  }
  void scatter(const Eigen::VectorXd& free_values, Eigen::VectorXd& x) const {
    for (size_t d = 0; d < index.size(); ++d)
      if (index[d] >= 0) x[static_cast<Eigen::Index>(d)] = free_values[index[d]];
  }
};

}  // namespace fiberfluid::fem
