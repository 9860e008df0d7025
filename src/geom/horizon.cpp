// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/geom/horizon.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <utility>
#include <vector>

namespace fiberfluid::geom {
namespace {

// Each vertex's cell on a grid of cubes of edge `cell` from the lowest
// corner of the vertices, as one sortable key.
class CellGrid {
 public:
  CellGrid(const Eigen::MatrixXd& V, double cell) : V_(V), cell_(cell) {
    origin_ = V.colwise().minCoeff();
    const Eigen::RowVectorXd extent = V.colwise().maxCoeff() - origin_;
    for (Eigen::Index a = 0; a < V.cols(); ++a)
      size_[static_cast<size_t>(a)] = static_cast<int64_t>(std::floor(extent[a] / cell)) + 1;
    sorted_.reserve(static_cast<size_t>(V.rows()));
    for (int v = 0; v < V.rows(); ++v) sorted_.push_back({key(coordinates(v)), v});
    std::sort(sorted_.begin(), sorted_.end());
  }

  std::array<int64_t, 3> coordinates(int v) const {
    std::array<int64_t, 3> c = {0, 0, 0};
    for (Eigen::Index a = 0; a < V_.cols(); ++a)
      c[static_cast<size_t>(a)] = static_cast<int64_t>(std::floor((V_(v, a) - origin_[a]) / cell_));
    return c;
  }

  // body(j) for every vertex j in the cells next to (and at) vertex v's.
  template <class Body>
  void for_each_near(int v, Body&& body) const {
    const std::array<int64_t, 3> c = coordinates(v);
    const int reach_z = V_.cols() == 3 ? 1 : 0;
    for (int64_t dx = -1; dx <= 1; ++dx)
      for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dz = -reach_z; dz <= reach_z; ++dz) {
          const std::array<int64_t, 3> n = {c[0] + dx, c[1] + dy, c[2] + dz};
          if (!inside(n)) continue;
          const int64_t k = key(n);
          auto it = std::lower_bound(sorted_.begin(), sorted_.end(), std::make_pair(k, -1));
          for (; it != sorted_.end() && it->first == k; ++it) body(it->second);
        }
  }

 private:
  bool inside(const std::array<int64_t, 3>& c) const {
    for (size_t a = 0; a < 3; ++a)
      if (c[a] < 0 || c[a] >= size_[a]) return false;
    return true;
  }
  int64_t key(const std::array<int64_t, 3>& c) const {
    return (c[0] * size_[1] + c[1]) * size_[2] + c[2];
  }

  const Eigen::MatrixXd& V_;
  double cell_;
  Eigen::RowVectorXd origin_;
  std::array<int64_t, 3> size_ = {1, 1, 1};
  std::vector<std::pair<int64_t, int>> sorted_;  // (cell key, vertex), by key
};

}  // namespace

FiberMask horizon_fibers(const Surface& surface, double horizon, MaskStorage storage) {
  if (!(horizon > 0.0) || !std::isfinite(horizon))
    throw std::invalid_argument("the horizon must be a positive length");
  const Eigen::MatrixXd& V = surface.V;
  const int n = static_cast<int>(V.rows());
  std::vector<std::vector<int>> partners(static_cast<size_t>(n));
  const CellGrid grid(V, horizon);
  const double reach = horizon * horizon;
  long long kept = 0;
  for (int i = 0; i < n; ++i) {
    grid.for_each_near(i, [&](int j) {
      if (j > i && (V.row(i) - V.row(j)).squaredNorm() <= reach)
        partners[static_cast<size_t>(i)].push_back(j);
    });
    kept += static_cast<long long>(partners[static_cast<size_t>(i)].size());
  }
  const double pairs = 0.5 * static_cast<double>(n) * (n - 1);
  const bool sparse =
      storage == MaskStorage::Sparse ||
      (storage == MaskStorage::Auto && static_cast<double>(kept) <= kSparseShare * pairs);
  FiberMask mask = FiberMask::from_neighbours(std::move(partners));
  return sparse ? mask : mask.as_dense();
}

double longest_edge(const Surface& surface) {
  double longest = 0.0;
  const Eigen::MatrixXi& F = surface.F;
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (Eigen::Index k = 0; k < F.cols(); ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % F.cols());
      longest = std::max(longest, (surface.V.row(a) - surface.V.row(b)).norm());
    }
  return longest;
}

}  // namespace fiberfluid::geom
