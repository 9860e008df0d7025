// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/model/bulk_treecode.hpp"

#include <stdexcept>

#include "fiberfluid/model/pair_stencil.hpp"

namespace fiberfluid::model {

namespace {

// Positions as 3D points (a 2D outline lies in z = 0).
Eigen::MatrixXd as_3d(const Eigen::MatrixXd& X) {
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(X.rows(), 3);
  P.leftCols(X.cols()) = X;
  return P;
}

}  // namespace

bool BulkTreecode::applicable(const PairFactors& factors) {
  if (factors.mean_count()) return false;        // its weights are not h (|S_i| + |S_j|) / L
  if (factors.lines() != nullptr) return false;  // a measure per pair, not per vertex
  const std::vector<double> counts = factors.vertex_counts();
  for (double c : counts)
    if (c != counts.front()) return false;
  return true;
}

BulkTreecode::BulkTreecode(const Eigen::MatrixXd& X, const Eigen::VectorXd& area,
                           const PairFactors& factors, const TreecodeOptions& options)
    : treecode_(as_3d(X), options), area_(area) {
  if (!applicable(factors))
    throw std::invalid_argument(
        "the treecode product needs one connection count for all fibers (no pruning, or the "
        "global count) and the weights h (|S_i| + |S_j|) / L (not the mean count)");
  const std::vector<double> counts = factors.vertex_counts();
  h_ = counts.empty() ? 0.0 : connection_factor(1.0, counts.front(), counts.front());
  if (const geom::FiberMask* mask = factors.mask())
    for (int i = 0; i < mask->num_vertices(); ++i)
      for (int j = i + 1; j < mask->num_vertices(); ++j)
        if (!mask->kept(i, j))
          pruned_.push_back(
              {i, j, bulk_weight(h_, area[i], area[j], (X.row(i) - X.row(j)).norm())});
  Eigen::MatrixXd ones = Eigen::MatrixXd::Ones(X.rows(), 1);
  row_sums_ = weighted_sums(ones).col(0);
  for (const PrunedPair& p : pruned_) {
    row_sums_[p.i] -= p.weight;
    row_sums_[p.j] -= p.weight;
  }
}

Eigen::MatrixXd BulkTreecode::weighted_sums(const Eigen::MatrixXd& V) const {
  const Eigen::Index k = V.cols();
  Eigen::MatrixXd charges(V.rows(), 2 * k);
  charges.leftCols(k) = V;
  charges.rightCols(k) = V.array().colwise() * area_.array();
  const Eigen::MatrixXd phi = treecode_.potentials(charges);
  return h_ *
         ((phi.leftCols(k).array().colwise() * area_.array()) + phi.rightCols(k).array()).matrix();
}

Eigen::MatrixXd BulkTreecode::laplacian_product(const Eigen::MatrixXd& V) const {
  Eigen::MatrixXd out(V.rows(), V.cols());
  for (Eigen::Index c0 = 0; c0 < V.cols(); c0 += 4) {  // the treecode takes 8 columns
    const Eigen::Index k = std::min<Eigen::Index>(4, V.cols() - c0);
    out.middleCols(c0, k) = (V.middleCols(c0, k).array().colwise() * row_sums_.array()).matrix() -
                            weighted_sums(V.middleCols(c0, k));
  }
  // The weighted sums took in the pruned fibers too (the diagonal did not):
  // take their terms back out.
  for (const PrunedPair& p : pruned_) {
    out.row(p.i) += p.weight * V.row(p.j);
    out.row(p.j) += p.weight * V.row(p.i);
  }
  return out;
}

}  // namespace fiberfluid::model
