// SPDX-License-Identifier: GPL-3.0-or-later
// Fibers within a horizon: the grid search against every pair.
#include "fiberfluid/geom/horizon.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "fiberfluid/geom/generators.hpp"

namespace fiberfluid::geom {
namespace {

void expect_every_pair_decided_by_distance(const Surface& s, double horizon) {
  const FiberMask mask = horizon_fibers(s, horizon);
  long long kept = 0;
  for (int i = 0; i < s.num_vertices(); ++i)
    for (int j = 0; j < s.num_vertices(); ++j) {
      const bool near = i != j && (s.V.row(i) - s.V.row(j)).norm() <= horizon;
      ASSERT_EQ(mask.kept(i, j), near) << i << " " << j;
      kept += near && i < j;
    }
  EXPECT_EQ(mask.num_kept(), kept);
  EXPECT_GT(kept, 0);
  EXPECT_LT(kept, mask.num_pairs());
}

TEST(Horizon, TheGridFindsExactlyThePairsWithinIt) {
  expect_every_pair_decided_by_distance(icosphere(3, 1.0), 0.3);
  expect_every_pair_decided_by_distance(icosphere(3, 1.0), 1.3);
  // A slender box: cells along one axis only, pairs on cell boundaries.
  expect_every_pair_decided_by_distance(
      box({0.0, 0.0, 0.0}, {0.2, 0.01, 0.01}, Eigen::Vector3i(40, 2, 2)), 0.011);
  // 2D: a polygon (cells in the plane).
  Eigen::MatrixXd P(64, 2);
  for (int k = 0; k < 64; ++k)
    P.row(k) << std::cos(2.0 * M_PI * k / 64), 0.4 * std::sin(2.0 * M_PI * k / 64);
  expect_every_pair_decided_by_distance(polygon(P), 0.25);
}

TEST(Horizon, TheLongestEdgeAndBadHorizons) {
  const Surface b = box({0.0, 0.0, 0.0}, {2.0, 1.0, 1.0}, Eigen::Vector3i(2, 1, 1));
  EXPECT_NEAR(longest_edge(b), std::sqrt(2.0), 1e-15);  // a unit square's diagonal
  EXPECT_THROW(horizon_fibers(b, 0.0), std::invalid_argument);
  EXPECT_THROW(horizon_fibers(b, -1.0), std::invalid_argument);
  EXPECT_THROW(horizon_fibers(b, NAN), std::invalid_argument);
  // A horizon beyond the body keeps every pair.
  EXPECT_EQ(horizon_fibers(b, 10.0).num_kept(), horizon_fibers(b, 10.0).num_pairs());
}

}  // namespace
}  // namespace fiberfluid::geom
