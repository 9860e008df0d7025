// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// What the pair kernels of BulkPairs (bulk_pairs.cpp) and DeformedPairs
// (deformed_pairs.cpp) share: the tiles of the pairs i <= j dealt to the
// OpenMP threads in fixed shares, and one accumulator per thread summed in
// thread order, which together give the same bits run after run. Internal
// to those two files.

#include <omp.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <type_traits>
#include <vector>

#include "fiberfluid/model/pair_kernels.hpp"

namespace fiberfluid::model {
namespace detail {

// One n x cols accumulator per thread, summed in thread order: with
// for_each_tile_pair's fixed shares, the same bits run after run.
class ThreadAccumulators {
 public:
  ThreadAccumulators(int n, int cols)
      : partial_(static_cast<size_t>(omp_get_max_threads()), Eigen::MatrixXd::Zero(n, cols)) {}
  double* column(int thread, int c) { return partial_[static_cast<size_t>(thread)].col(c).data(); }
  std::array<double*, 3> columns(int thread) {
    return {column(thread, 0), column(thread, 1), column(thread, 2)};
  }
  Eigen::MatrixXd sum() const {
    Eigen::MatrixXd total = Eigen::MatrixXd::Zero(partial_[0].rows(), partial_[0].cols());
    for (const Eigen::MatrixXd& p : partial_) total += p;
    return total;
  }

 private:
  std::vector<Eigen::MatrixXd> partial_;
};

using Tile = BulkPairs::Tile;

// Runs visit(tile, thread) over the tiles covering the pairs i <= j of n
// vertices, on the OpenMP threads, each thread a fixed share (thread <
// omp_get_max_threads()): one accumulator per thread, summed in thread order,
// gives the same bits run after run.
template <class Visit>
void for_each_tile_pair(int n, Visit&& visit) {
  constexpr int T = BulkPairs::kTile;
  std::vector<Tile> tiles;
  for (int i0 = 0; i0 < n; i0 += T)
    for (int j0 = i0; j0 < n; j0 += T)
      tiles.push_back({i0, std::min(T, n - i0), j0, std::min(T, n - j0), i0 == j0});
#pragma omp parallel
  {
    const int thread = omp_get_thread_num();
#pragma omp for schedule(static, 1)
    for (size_t k = 0; k < tiles.size(); ++k) visit(tiles[k], thread);
  }
}

// f(std::bool_constant<mean>): which weight the count takes (the mean
// count's or the others'), fixed at compile time so that the default's
// loops carry no select.
template <class F>
void with_count(bool mean, F&& f) {
  if (mean)
    f(std::true_type{});
  else
    f(std::false_type{});
}

}  // namespace detail
}  // namespace fiberfluid::model
