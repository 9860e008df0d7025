// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/model/fiber_system.hpp"

#include <gtest/gtest.h>

#include "fiberfluid/geom/fiber_pruning.hpp"
#include "fiberfluid/geom/mesh_io.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/reference/dense_assembly.hpp"
#include "model/model_fixtures.hpp"
#include "test_support.hpp"

namespace fiberfluid::model {
namespace {

using namespace fiberfluid::model::reference;  // the oracle

// The structured system against the straightforward full assembly of
// assembly.cpp with the boundary conditions applied there: two
// implementations of the same matrix.
void expect_same_as_full_assembly(const Model& m, BoundaryMethod method) {
  const FiberSystem system(m, m.surface.V, method, 1e9);
  Eigen::MatrixXd A = system_matrix(m, m.surface.V);
  const DofPartition partition = partition_dofs(m);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(partition.constrained.size());
  Eigen::MatrixXd expected;
  if (method == BoundaryMethod::Penalty) {
    Eigen::VectorXd B = Eigen::VectorXd::Zero(A.rows());
    apply_penalty(partition, zero, 1e9, A, B);
    expected = A;
  } else {
    Eigen::VectorXd B_free;
    reduce_system(partition, zero, A, Eigen::VectorXd::Zero(A.rows()), expected, B_free);
  }
  const Eigen::MatrixXd structured = system.dense_matrix();
  ASSERT_EQ(structured.rows(), expected.rows());
  const double scale = expected.topLeftCorner(expected.rows() - 1, expected.rows() - 1)
                           .diagonal()
                           .cwiseAbs()
                           .minCoeff();
  EXPECT_LT((structured - expected).cwiseAbs().maxCoeff(), 1e-11 * std::max(scale, 1.0));

  // Matrix-free products agree with the dense blocks.
  const int m_unknowns = system.num_unknowns() - 1;
  const Eigen::VectorXd u = Eigen::VectorXd::LinSpaced(m_unknowns, -1.0, 2.0);
  const Eigen::VectorXd dense = structured.topLeftCorner(m_unknowns, m_unknowns) * u;
  EXPECT_LT((system.apply_K(u) - dense).norm(), 1e-12 * dense.norm());

  // The blocks filled in single precision (a single-precision preconditioner)
  // are the double ones rounded: within a few units of float's last place
  // (the surface tension is added in single precision).
  for (int block = 0; block < system.num_blocks(); ++block) {
    const Eigen::MatrixXd K = system.dense_block(block);
    const Eigen::MatrixXd single = system.dense_block_single(block).cast<double>();
    EXPECT_LT((single - K).cwiseAbs().maxCoeff(), 3.0 * 0x1p-24 * K.cwiseAbs().maxCoeff());
  }
}

TEST(FiberSystem, MatchesTheFullAssemblyWithBothBoundaryMethods) {
  Model sphere = testing::paper_sphere_model();
  sphere.material = Material::linear(Eigen::Vector3d(3000, 2000, 1000));  // distinct blocks
  for (BoundaryMethod method : {BoundaryMethod::Elimination, BoundaryMethod::Penalty}) {
    expect_same_as_full_assembly(testing::paper_rectangle_model(), method);
    expect_same_as_full_assembly(testing::paper_sphere_model(), method);
    expect_same_as_full_assembly(sphere, method);
  }
}

Model pruned_liver(ConnectionCount count) {
  Model m;
  m.surface =
      geom::remove_unused_vertices(geom::read_surface(testing::data_mesh("liver.obj")).surface)
          .surface;
  m.material.law = FiberLaw::constant(2000.0);
  m.material.surface_tension = 3.0;
  for (int v : select_half_space(m.surface.V, parse_half_space("y >= 4.75", 3)))
    for (int a = 0; a < 3; ++a) m.constraints.push_back({v, a, 0.0, {}});
  m.fibers = std::make_shared<const geom::FiberMask>(geom::prune_fibers(m.surface).mask);
  m.connection_count = count;
  return m;
}

TEST(FiberSystem, PrunedFibersMatchTheFullAssemblyForBothConnectionCounts) {
  for (ConnectionCount count : {ConnectionCount::Symmetric, ConnectionCount::Global})
    for (BoundaryMethod method : {BoundaryMethod::Elimination, BoundaryMethod::Penalty})
      expect_same_as_full_assembly(pruned_liver(count), method);
}

TEST(FiberSystem, PrunedBlocksIgnoreTranslationAndDropThePrunedPairs) {
  const Model m = pruned_liver(ConnectionCount::Symmetric);
  const Eigen::MatrixXd A = system_matrix(m, m.surface.V);
  const int n = m.num_vertices();
  const Eigen::MatrixXd K = A.topLeftCorner(n, n);
  EXPECT_LT((K * Eigen::VectorXd::Ones(n)).cwiseAbs().maxCoeff(), 1e-12 * K.diagonal().maxCoeff());
  EXPECT_LT((K - K.transpose()).cwiseAbs().maxCoeff(), 1e-14 * K.diagonal().maxCoeff());
  // A pruned pair is joined only where a mesh edge adds surface tension.
  Model bulk_only = m;
  bulk_only.material.surface_tension = 0.0;
  const Eigen::MatrixXd B = system_matrix(bulk_only, m.surface.V);
  int pruned = 0;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      if (!m.fibers->kept(i, j)) {
        ++pruned;
        EXPECT_EQ(B(i, j), 0.0);
      } else {
        EXPECT_LT(B(i, j), 0.0);
      }
  EXPECT_EQ(pruned, 9591 - 5536);
}

TEST(FiberSystem, AFullMaskWithEitherCountIsTheUnprunedModel) {
  Model m = testing::paper_sphere_model();
  const Eigen::MatrixXd unpruned = system_matrix(m, m.surface.V);
  m.fibers = std::make_shared<const geom::FiberMask>(m.num_vertices());  // every pair kept
  for (ConnectionCount count : {ConnectionCount::Symmetric, ConnectionCount::Global}) {
    m.connection_count = count;
    // (n_i + n_j) / 2 = N - 1 for a convex body: the paper's normalisation.
    EXPECT_LT((system_matrix(m, m.surface.V) - unpruned).cwiseAbs().maxCoeff(), 1e-12);
    const FiberSystem system(m, m.surface.V, BoundaryMethod::Elimination, 1e9);
    const FiberSystem plain(testing::paper_sphere_model(), m.surface.V, BoundaryMethod::Elimination,
                            1e9);
    EXPECT_LT((system.dense_block(0) - plain.dense_block(0)).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST(FiberSystem, EqualBlocksAreRecognised) {
  Model m = testing::paper_sphere_model();
  EXPECT_TRUE(FiberSystem(m, m.surface.V, BoundaryMethod::Elimination, 1e9).blocks_equal());
  m.material.axis_factors.z() = 0.5;
  EXPECT_FALSE(FiberSystem(m, m.surface.V, BoundaryMethod::Elimination, 1e9).blocks_equal());
  Model partial = testing::paper_sphere_model();
  partial.constraints.push_back({100, 0, 0.0, {}});  // x only: the x block loses a vertex
  EXPECT_FALSE(
      FiberSystem(partial, partial.surface.V, BoundaryMethod::Elimination, 1e9).blocks_equal());
}

TEST(FiberSystem, PrescribedDisplacementsMoveToTheRightHandSide) {
  Model m = testing::paper_sphere_model();
  const FiberSystem system(m, m.surface.V, BoundaryMethod::Elimination, 1e9);
  Eigen::VectorXd U_c = Eigen::VectorXd::Zero(3 * m.num_vertices());
  const Constraint& c = m.constraints.front();
  U_c[m.dof(c.vertex, c.axis)] = 0.01;
  const Eigen::VectorXd rhs = system.reduce_rhs(Eigen::VectorXd::Zero(U_c.size()), U_c);
  // Against the full matrix: -A_fc u_c on the free rows, -s_c . u_c in the volume row.
  const Eigen::MatrixXd A = system_matrix(m, m.surface.V);
  const DofPartition p = partition_dofs(m);
  Eigen::VectorXd full = Eigen::VectorXd::Zero(m.num_unknowns());
  full.head(U_c.size()) = U_c;
  const Eigen::VectorXd moved = -(A * full);
  Eigen::VectorXd expected(p.free.size());
  for (size_t k = 0; k < p.free.size(); ++k)
    expected[static_cast<Eigen::Index>(k)] = moved[p.free[k]];
  EXPECT_LT((rhs - expected).norm(), 1e-12 * expected.norm());
}

}  // namespace
}  // namespace fiberfluid::model

#include "fiberfluid/solve/cost_model.hpp"

namespace fiberfluid::model {
namespace {

// The cost model's block shape, from the model alone, is the structured
// system's own: the same largest block and the same equal-blocks rule, for
// supports on every axis, on one axis, per-axis factors and the penalty.
TEST(FiberSystem, TheCostModelsBlockShapeIsTheSystems) {
  Model all = testing::paper_sphere_model();
  Model factors = all;
  factors.material.axis_factors = {1.0, 2.0, 1.0};
  Model partial = all;
  partial.constraints.erase(std::remove_if(partial.constraints.begin(), partial.constraints.end(),
                                           [](const Constraint& c) { return c.axis == 2; }),
                            partial.constraints.end());
  partial.constraints.push_back({0, 2, 0.0, {}});
  for (const Model* m : {&all, &factors, &partial})
    for (BoundaryMethod method : {BoundaryMethod::Elimination, BoundaryMethod::Penalty}) {
      const FiberSystem system(*m, m->surface.V, method, 1e9);
      const solve::BlockShape shape = solve::block_shape(*m, method);
      EXPECT_EQ(shape.largest, system.largest_block()) << to_string(method);
      EXPECT_EQ(shape.factors == 1, system.blocks_equal()) << to_string(method);
    }
}

}  // namespace
}  // namespace fiberfluid::model
