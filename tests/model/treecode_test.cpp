// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/model/treecode.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <random>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/geom/fiber_pruning.hpp"
#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/geom/mesh_io.hpp"
#include "fiberfluid/geom/surface.hpp"
#include "fiberfluid/model/bulk_treecode.hpp"
#include "fiberfluid/model/pair_kernels.hpp"
#include "test_support.hpp"

namespace fiberfluid::model {
namespace {

// sum_{j != i} Q_jc / |x_i - x_j|, the plain definition.
Eigen::MatrixXd direct_potentials(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Q) {
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(X.rows(), Q.cols());
  for (Eigen::Index i = 0; i < X.rows(); ++i)
    for (Eigen::Index j = 0; j < X.rows(); ++j)
      if (j != i) out.row(i) += Q.row(j) / (X.row(i) - X.row(j)).norm();
  return out;
}

// Points on a surface patch and in two dense clumps: leaves of every shape.
Eigen::MatrixXd scattered_points(int n) {
  std::mt19937 random(11);
  std::normal_distribution<double> clump(0.0, 0.02);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::MatrixXd X(n, 3);
  for (int i = 0; i < n; ++i) {
    if (i % 3 == 0) {
      X.row(i) << 0.5 + clump(random), -0.3 + clump(random), 0.2 + clump(random);
    } else {
      const double u = uniform(random), v = uniform(random);
      X.row(i) << u, v, 0.3 * std::sin(3 * u) * v;  // a curved sheet
    }
  }
  return X;
}

TEST(Treecode, PotentialsMatchTheDirectSumsToTheirDegree) {
  const Eigen::MatrixXd X = scattered_points(3000);
  Eigen::MatrixXd Q(X.rows(), 3);
  for (Eigen::Index i = 0; i < X.rows(); ++i) Q.row(i) << 1.0, std::cos(5 * X(i, 0)), X(i, 1) - 0.4;
  const Eigen::MatrixXd exact = direct_potentials(X, Q);
  double previous = 1.0;
  for (int degree : {2, 4, 6, 8}) {
    TreecodeOptions options;
    options.degree = degree;
    options.theta = 0.6;
    options.leaf_size = 32;
    const Treecode tree(X, options);
    const Eigen::MatrixXd approximate = tree.potentials(Q);
    const double error = (approximate - exact).norm() / exact.norm();
    EXPECT_GT(tree.proxy_terms(), 0) << degree;  // far boxes were approximated
    EXPECT_LT(error, 0.5 * previous) << degree;  // and the error falls with the degree
    previous = error;
  }
  EXPECT_LT(previous, 1e-7);
}

TEST(Treecode, SmallSetsAreSummedDirectly) {
  const Eigen::MatrixXd X = scattered_points(40);
  const Eigen::MatrixXd Q = Eigen::MatrixXd::Ones(40, 1);
  const Treecode tree(X, TreecodeOptions{});
  const Eigen::MatrixXd approximate = tree.potentials(Q);
  EXPECT_EQ(tree.proxy_terms(), 0);
  EXPECT_EQ(tree.direct_terms(), 40 * 40);
  EXPECT_LT((approximate - direct_potentials(X, Q)).norm(), 1e-13 * approximate.norm());
}

TEST(Treecode, SameBitsForOneOrTwoThreads) {
  const Eigen::MatrixXd X = scattered_points(5000);
  const Eigen::MatrixXd Q = X.col(0).array().exp().matrix();
  const Treecode tree(X, TreecodeOptions::for_tolerance(1e-4));
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const Eigen::MatrixXd one = tree.potentials(Q);
  omp_set_num_threads(2);
  const Eigen::MatrixXd two = tree.potentials(Q);
  omp_set_num_threads(threads);
  EXPECT_EQ((one - two).cwiseAbs().maxCoeff(), 0.0);
}

TEST(Treecode, RefusesWhatItCannotDo) {
  const Eigen::MatrixXd X = scattered_points(10);
  EXPECT_THROW(Treecode(X.leftCols(2), TreecodeOptions{}), std::invalid_argument);
  TreecodeOptions bad;
  bad.theta = 1.5;
  EXPECT_THROW(Treecode(X, bad), std::invalid_argument);
  EXPECT_THROW(TreecodeOptions::for_tolerance(0.5), std::invalid_argument);
  EXPECT_THROW(Treecode(X, TreecodeOptions{}).potentials(Eigen::MatrixXd::Ones(10, 9)),
               std::invalid_argument);
}

// The bulk product and diagonal against the exact tiled kernel, at the
// tolerance asked for (relative 2-norm).
void expect_bulk_within(const Eigen::MatrixXd& X, const Eigen::MatrixXi& F,
                        const PairFactors& factors, double tolerance) {
  const Eigen::VectorXd area = geom::vertex_area_vectors(X, F).magnitude;
  Eigen::MatrixXd V(X.rows(), 3);
  for (Eigen::Index i = 0; i < X.rows(); ++i)
    V.row(i) << std::sin(2 * X(i, 0)) + X(i, 1), X(i, 2) * X(i, 0), 1.0 - X(i, 1) * X(i, 1);
  const BulkPairs exact(X, area, factors);
  const BulkTreecode approximate(X, area, factors, tolerance);
  const Eigen::MatrixXd product = exact.laplacian_product(V);
  EXPECT_LT((approximate.laplacian_product(V) - product).norm(), tolerance * product.norm())
      << tolerance;
  const Eigen::VectorXd diagonal = exact.row_sums();
  EXPECT_LT((approximate.row_sums() - diagonal).norm(), tolerance * diagonal.norm()) << tolerance;
  // A rigid translation is in the kernel of any Laplacian built this way.
  const Eigen::MatrixXd shift = Eigen::MatrixXd::Ones(X.rows(), 1);
  EXPECT_LT(approximate.laplacian_product(shift).norm(), 1e-12 * diagonal.norm());
}

TEST(BulkTreecode, MatchesTheExactProductOnASphereAtEachTolerance) {
  const geom::Surface sphere = geom::icosphere(4);
  const PairFactors factors(nullptr, ConnectionCount::Symmetric, sphere.num_vertices());
  for (double tolerance : {1e-3, 1e-4, 1e-6, 1e-8})
    expect_bulk_within(sphere.V, sphere.F, factors, tolerance);
}

TEST(BulkTreecode, PrunedFibersWithTheGlobalCountAreExactCorrections) {
  const geom::Surface bunny =
      geom::remove_unused_vertices(geom::read_surface(testing::data_mesh("Bunny.stl")).surface)
          .surface;
  const geom::PruningResult pruned = geom::prune_fibers(bunny);
  ASSERT_GT(pruned.mask.num_pairs() - pruned.mask.num_kept(), 0);
  const PairFactors global(&pruned.mask, ConnectionCount::Global, bunny.num_vertices());
  EXPECT_TRUE(BulkTreecode::applicable(global));
  expect_bulk_within(bunny.V, bunny.F, global, 1e-6);
  const PairFactors symmetric(&pruned.mask, ConnectionCount::Symmetric, bunny.num_vertices());
  EXPECT_FALSE(BulkTreecode::applicable(symmetric));
  const Eigen::VectorXd area = Eigen::VectorXd::Ones(bunny.num_vertices());
  EXPECT_THROW(BulkTreecode(bunny.V, area, symmetric, 1e-6), std::invalid_argument);
}

}  // namespace
}  // namespace fiberfluid::model
