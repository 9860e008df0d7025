// SPDX-License-Identifier: GPL-3.0-or-later
// The tiled, symmetric pair kernels against the plain definition, pair by
// pair (PairFactors::row and bulk_weight), on a set large enough for whole,
// partial and off-diagonal tiles: unpruned, pruned with both connection
// counts, with a strain-dependent law, and over a subset of the vertices.
#include "fiberfluid/model/pair_kernels.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <cstring>
#include <random>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/geom/fiber_pruning.hpp"
#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/model/pair_stencil.hpp"

namespace fiberfluid::model {
namespace {

struct PairSet {
  Eigen::MatrixXd X;  // 642 vertices: three tiles, the last partial
  Eigen::VectorXd area;
  std::shared_ptr<geom::FiberMask> mask;
};

PairSet sphere(bool pruned) {
  PairSet s;
  const geom::Surface surface = geom::icosphere(3, 2.0);
  s.X = surface.V;
  s.area = geom::vertex_area_vectors(surface.V, surface.F).magnitude;
  if (pruned) {  // an arbitrary, symmetric mask: about one pair in five dropped
    s.mask = std::make_shared<geom::FiberMask>(static_cast<int>(s.X.rows()));
    std::mt19937 random(7);
    for (int i = 0; i < s.X.rows(); ++i)
      for (int j = i + 1; j < s.X.rows(); ++j)
        if (random() % 5 == 0) s.mask->prune(i, j);
  }
  return s;
}

// The plain definition: w_ij = h_ij (a_i + a_j) / r_ij times Y(e_ij), as a dense matrix
// over `vertices` (zero diagonal).
Eigen::MatrixXd plain_weights(const PairSet& s, const PairFactors& factors,
                              const std::vector<int>& vertices, const FiberLaw* law = nullptr,
                              const Eigen::MatrixXd* strained = nullptr) {
  const auto n = static_cast<Eigen::Index>(vertices.size());
  Eigen::MatrixXd W = Eigen::MatrixXd::Zero(n, n);
  std::vector<double> h(static_cast<size_t>(s.X.rows()));
  for (Eigen::Index r = 0; r < n; ++r) {
    const int i = vertices[static_cast<size_t>(r)];
    factors.row(i, h.data());
    for (Eigen::Index c = 0; c < n; ++c) {
      const int j = vertices[static_cast<size_t>(c)];
      if (i == j || h[static_cast<size_t>(j)] == 0.0) continue;
      const double length = (s.X.row(i) - s.X.row(j)).norm();
      double w = bulk_weight(h[static_cast<size_t>(j)], s.area[i], s.area[j], length);
      if (law != nullptr)
        w *= law->modulus((strained->row(i) - strained->row(j)).norm() / length - 1.0);
      W(r, c) = w;
    }
  }
  return W;
}

std::vector<int> all_vertices(const PairSet& s) {
  std::vector<int> v(static_cast<size_t>(s.X.rows()));
  for (size_t k = 0; k < v.size(); ++k) v[k] = static_cast<int>(k);
  return v;
}

// Every kernel of `pairs` against the dense weights W.
void expect_kernels_match(const BulkPairs& pairs, const Eigen::MatrixXd& W) {
  const Eigen::Index n = W.rows();
  ASSERT_EQ(pairs.size(), n);
  const double scale = W.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 0.0);

  const Eigen::VectorXd sums = W.rowwise().sum();
  EXPECT_LT((pairs.row_sums() - sums).cwiseAbs().maxCoeff(), 1e-13 * sums.cwiseAbs().maxCoeff());

  // L V with four columns: one group of three and one of one.
  const Eigen::MatrixXd V = Eigen::MatrixXd::Random(n, 4);
  const Eigen::MatrixXd L = Eigen::MatrixXd(sums.asDiagonal()) - W;
  const Eigen::MatrixXd expected = L * V;
  EXPECT_LT((pairs.laplacian_product(V) - expected).cwiseAbs().maxCoeff(),
            1e-13 * expected.cwiseAbs().maxCoeff());

  // Off-diagonal entries -scale w_ij; the diagonal untouched.
  Eigen::MatrixXd K = Eigen::MatrixXd::Constant(n, n, 42.0);
  pairs.fill_off_diagonal(3.0, &K);
  EXPECT_TRUE((K.diagonal().array() == 42.0).all());
  K.diagonal().setZero();
  EXPECT_LT((K + 3.0 * W).cwiseAbs().maxCoeff(), 1e-15 * 3.0 * scale);
  EXPECT_EQ(K, K.transpose());  // both triangles from the same weight, to the bit
}

TEST(BulkPairs, MatchTheDefinitionOnEveryPairUnpruned) {
  const PairSet s = sphere(false);
  const PairFactors factors(nullptr, ConnectionCount::Symmetric, static_cast<int>(s.X.rows()));
  expect_kernels_match(BulkPairs(s.X, s.area, factors), plain_weights(s, factors, all_vertices(s)));
}

TEST(BulkPairs, MatchTheDefinitionWithPrunedFibersAndBothCounts) {
  const PairSet s = sphere(true);
  for (ConnectionCount count : {ConnectionCount::Symmetric, ConnectionCount::Global}) {
    const PairFactors factors(s.mask.get(), count, static_cast<int>(s.X.rows()));
    expect_kernels_match(BulkPairs(s.X, s.area, factors),
                         plain_weights(s, factors, all_vertices(s)));
  }
}

TEST(BulkPairs, MatchTheDefinitionWithASecantLawOverASubset) {
  const PairSet s = sphere(true);
  const PairFactors factors(s.mask.get(), ConnectionCount::Symmetric, static_cast<int>(s.X.rows()));
  const FiberLaw law = FiberLaw::exponential(1000.0, 8.0);
  Eigen::MatrixXd strained = s.X;
  strained.col(2) *= 1.1;  // stretched along z: strains from 0 to 10%
  // Every other vertex from the fifth: 319, not a multiple of the tile.
  std::vector<int> subset;
  for (int i = 5; i < s.X.rows(); i += 2) subset.push_back(i);
  BulkPairs pairs(s.X, s.area, factors, subset);
  pairs.set_secant_law(&law, &s.X, &strained);
  expect_kernels_match(pairs, plain_weights(s, factors, subset, &law, &strained));
}

TEST(BulkPairs, SameThreadsSameBitsOneOrTwoThreadsClose) {
  const PairSet s = sphere(false);
  const PairFactors factors(nullptr, ConnectionCount::Symmetric, static_cast<int>(s.X.rows()));
  const BulkPairs pairs(s.X, s.area, factors);
  const Eigen::MatrixXd V = Eigen::MatrixXd::Random(s.X.rows(), 3);
  const int before = omp_get_max_threads();
  omp_set_num_threads(2);
  const Eigen::MatrixXd first = pairs.laplacian_product(V), again = pairs.laplacian_product(V);
  omp_set_num_threads(1);
  const Eigen::MatrixXd serial = pairs.laplacian_product(V);
  omp_set_num_threads(before);
  EXPECT_EQ(0, std::memcmp(first.data(), again.data(),
                           sizeof(double) * static_cast<size_t>(first.size())));
  EXPECT_LT((serial - first).cwiseAbs().maxCoeff(), 1e-13 * first.cwiseAbs().maxCoeff());
}

// DeformedPairs against the vector spring written out pair by pair here
// (model.md section 7: c1 = a Y(e), c2 = a Y'(e) / (r L)):
// forces, the tangent product and the stored coefficients (in double, and
// in single for the stored product), on a pruned
// sphere with a strain-dependent law and a non-affine displacement.
TEST(DeformedPairs, MatchTheStencilPairByPair) {
  const PairSet s = sphere(true);
  const int n = static_cast<int>(s.X.rows());
  const PairFactors factors(s.mask.get(), ConnectionCount::Symmetric, n);
  const FiberLaw law = FiberLaw::exponential(1000.0, 8.0);
  Eigen::MatrixXd U = 0.05 * Eigen::MatrixXd::Random(n, 3);
  U.col(2) += 0.1 * s.X.col(2);
  const Eigen::MatrixXd X = s.X + U, W = Eigen::MatrixXd::Random(n, 3);

  Eigen::MatrixXd C1 = Eigen::MatrixXd::Zero(n, n), C2 = C1, forces = Eigen::MatrixXd::Zero(n, 3);
  Eigen::MatrixXd product = forces;
  std::vector<double> h(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    factors.row(i, h.data());
    for (int j = 0; j < n; ++j) {
      if (i == j) continue;
      const double L = (s.X.row(i) - s.X.row(j)).norm(), r = (X.row(i) - X.row(j)).norm();
      const double a = bulk_weight(h[static_cast<size_t>(j)], s.area[i], s.area[j], L);
      C1(i, j) = a * law.modulus(r / L - 1.0);
      C2(i, j) = a * law.slope(r / L - 1.0) / (r * L);
      const Eigen::RowVector3d d = U.row(i) - U.row(j), v = W.row(i) - W.row(j);
      forces.row(i) += C1(i, j) * d;
      product.row(i) += C1(i, j) * v + C2(i, j) * (X.row(i) - X.row(j)).dot(v) * d;
    }
  }
  const DeformedPairs pairs(s.X, X, U, s.area, factors, law, FiberKinematics::VectorSpring);
  EXPECT_LT((pairs.forces() - forces).cwiseAbs().maxCoeff(), 1e-12 * forces.cwiseAbs().maxCoeff());
  EXPECT_LT((pairs.tangent_product(W) - product).cwiseAbs().maxCoeff(),
            1e-12 * product.cwiseAbs().maxCoeff());
  Eigen::MatrixXd c1, c2;
  pairs.coefficients(&c1, &c2);
  // Kept once, in the lower triangle (column i: the pairs (i, j > i)).
  const auto lower = [](const Eigen::MatrixXd& M) {
    return Eigen::MatrixXd(M.triangularView<Eigen::StrictlyLower>());
  };
  EXPECT_LT((lower(c1) - lower(C1)).cwiseAbs().maxCoeff(), 1e-14 * C1.cwiseAbs().maxCoeff());
  EXPECT_LT((lower(c2) - lower(C2)).cwiseAbs().maxCoeff(), 1e-14 * C2.cwiseAbs().maxCoeff());
  // The single-precision table holds the same coefficients rounded.
  Eigen::MatrixXf f1, f2;
  pairs.coefficients(&f1, &f2);
  const auto lower_single = [](const Eigen::MatrixXf& M) {
    return Eigen::MatrixXf(M.triangularView<Eigen::StrictlyLower>());
  };
  EXPECT_TRUE((lower_single(f1).array() == lower(c1).cast<float>().array()).all());
  EXPECT_TRUE((lower_single(f2).array() == lower(c2).cast<float>().array()).all());
  // Both tables have a zero diagonal (a pair of a vertex with itself).
  EXPECT_TRUE((c1.diagonal().array() == 0.0).all() && (c2.diagonal().array() == 0.0).all());
  EXPECT_TRUE((f1.diagonal().array() == 0.0f).all() && (f2.diagonal().array() == 0.0f).all());
  // The product from it, each pair read once, is the product pair by pair
  // of the rounded coefficients, and the exact one to single precision.
  Eigen::MatrixXd rounded = Eigen::MatrixXd::Zero(n, 3);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      if (i == j) continue;
      const int low = std::min(i, j), high = std::max(i, j);
      const Eigen::RowVector3d v = W.row(i) - W.row(j), d = U.row(i) - U.row(j);
      rounded.row(i) +=
          double(f1(high, low)) * v + double(f2(high, low)) * (X.row(i) - X.row(j)).dot(v) * d;
    }
  const Eigen::MatrixXd stored =
      stored_tangent_product(FiberKinematics::VectorSpring, X, U, f1, f2, W);
  EXPECT_LT((stored - rounded).cwiseAbs().maxCoeff(), 1e-12 * product.cwiseAbs().maxCoeff());
  EXPECT_LT((stored - product).cwiseAbs().maxCoeff(), 1e-6 * product.cwiseAbs().maxCoeff());
}

}  // namespace
}  // namespace fiberfluid::model
