// SPDX-License-Identifier: GPL-3.0-or-later
#include "model/fiber_network.hpp"

#include <algorithm>
#include <string>

#include "model/pair_stencil.hpp"
#include "util/error.hpp"

namespace fiberfluid::model {

double checked_fiber_length(const Eigen::MatrixXd& X, int i, int j) {
  const double length = (X.row(i) - X.row(j)).norm();
  if (!(length > 0.0))
    throw InputError("vertices " + std::to_string(i) + " and " + std::to_string(j) +
                     " coincide: the fiber between them has zero length");
  return length;
}

const char* to_string(ConnectionCount count) {
  return count == ConnectionCount::Global ? "global" : "symmetric";
}

PairFactors::PairFactors(const geom::FiberMask* fibers, ConnectionCount count, int num_vertices)
    : fibers_(fibers), count_(count), n_(num_vertices) {
  // The paper divides by N-1, the fibers per vertex, so that Y does not
  // depend on the discretisation; with pruning, by the fibers that exist.
  global_ = n_ - 1;
  if (fibers_ == nullptr) return;
  const std::vector<int> kept = fibers_->kept_per_vertex();
  kept_.assign(kept.begin(), kept.end());
  double sum = 0.0;
  for (double k : kept_) sum += k;
  global_ = n_ > 0 ? sum / n_ : 0.0;
}

std::vector<double> PairFactors::vertex_counts() const {
  if (fibers_ != nullptr && count_ == ConnectionCount::Symmetric) return kept_;
  return std::vector<double>(static_cast<size_t>(n_), global_);
}

void PairFactors::row(int i, double* row) const {
  if (fibers_ == nullptr) {
    std::fill(row, row + n_, connection_factor(1.0, global_, global_));
  } else {
    const uint8_t* kept = fibers_->row(i);
    const bool global = count_ == ConnectionCount::Global;
    const auto count = [&](int k) { return global ? global_ : kept_[static_cast<size_t>(k)]; };
    for (int j = 0; j < n_; ++j) row[j] = connection_factor(kept[j], count(i), count(j));
  }
  row[i] = 0.0;
}

Eigen::SparseMatrix<double> surface_tension_laplacian(const Eigen::MatrixXd& X,
                                                      const Eigen::VectorXd& area,
                                                      const Eigen::MatrixXi& edges) {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<size_t>(4 * edges.rows()));
  for (Eigen::Index e = 0; e < edges.rows(); ++e) {
    const int i = edges(e, 0), k = edges(e, 1);
    checked_fiber_length(X, i, k);  // throws for coincident ends
    const double w = surface_weight(area[i], area[k], (X.row(i) - X.row(k)).squaredNorm());
    entries.insert(entries.end(), {{i, i, w}, {k, k, w}, {i, k, -w}, {k, i, -w}});
  }
  Eigen::SparseMatrix<double> L(X.rows(), X.rows());
  L.setFromTriplets(entries.begin(), entries.end());
  return L;
}

}  // namespace fiberfluid::model
