// SPDX-License-Identifier: GPL-3.0-or-later
// Fibers within a horizon stored as neighbour lists (a sparse FiberMask):
// every kernel gives what the same fibers stored as an N x N table give,
// and the sparse Newton tangent is the dense one.
#include <gtest/gtest.h>

#include <random>

#include "fiberfluid/geom/fiber_mask.hpp"
#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/geom/horizon.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/equilibrium.hpp"
#include "fiberfluid/model/fiber_system.hpp"
#include "model/model_fixtures.hpp"

namespace fiberfluid::model {
namespace {

TEST(FiberMask, NeighbourListsAnswerAsTheTableDoes) {
  const geom::Surface s = geom::icosphere(2, 1.0);
  const geom::FiberMask sparse = geom::horizon_fibers(s, 0.7, geom::MaskStorage::Sparse);
  const geom::FiberMask dense = geom::horizon_fibers(s, 0.7, geom::MaskStorage::Dense);
  ASSERT_TRUE(sparse.sparse());
  ASSERT_FALSE(dense.sparse());
  EXPECT_EQ(sparse.num_kept(), dense.num_kept());
  EXPECT_EQ(sparse.kept_per_vertex(), dense.kept_per_vertex());
  long long listed = 0;
  for (int i = 0; i < s.num_vertices(); ++i)
    for (int j = 0; j < s.num_vertices(); ++j) {
      ASSERT_EQ(sparse.kept(i, j), dense.kept(i, j)) << i << " " << j;
      // Kept exactly when at most the horizon apart.
      ASSERT_EQ(dense.kept(i, j), i != j && (s.V.row(i) - s.V.row(j)).norm() <= 0.7);
    }
  for (int i = 0; i < s.num_vertices(); ++i)
    sparse.for_each_kept(i, [&](int j) { listed += dense.kept(i, j) ? 1 : 0; });
  EXPECT_EQ(listed, 2 * dense.num_kept());
  // Conversions both ways, and edits on the lists.
  EXPECT_EQ(dense.as_sparse().neighbours(5), sparse.neighbours(5));
  geom::FiberMask edited = sparse;
  const int j = sparse.neighbours(3).front();
  edited.prune(3, j);
  EXPECT_FALSE(edited.kept(3, j));
  EXPECT_FALSE(edited.kept(j, 3));
  EXPECT_EQ(edited.num_kept(), sparse.num_kept() - 1);
  edited.keep(3, j);
  EXPECT_EQ(edited.as_dense().num_kept(), dense.num_kept());
  // Intersections in either storage.
  geom::FiberMask both = geom::horizon_fibers(s, 0.9, geom::MaskStorage::Sparse);
  both.keep_only_where(dense);
  EXPECT_EQ(both.num_kept(), dense.num_kept());
  geom::FiberMask wide = geom::horizon_fibers(s, 0.9, geom::MaskStorage::Dense);
  wide.keep_only_where(sparse);
  EXPECT_EQ(wide.num_kept(), dense.num_kept());
  EXPECT_THROW(dense.neighbours(0), std::logic_error);
  EXPECT_THROW(sparse.row(0), std::logic_error);
}

TEST(FiberMask, AHorizonThatKeepsFewPairsIsStoredAsNeighbourLists) {
  const geom::Surface s = geom::icosphere(3, 1.0);  // 642 vertices
  const geom::FiberMask near = geom::horizon_fibers(s, 0.3);
  EXPECT_TRUE(near.sparse());
  EXPECT_LT(near.bytes(), 0.2 * near.as_dense().bytes());  // N times the neighbours, not N^2
  EXPECT_FALSE(geom::horizon_fibers(s, 1.5).sparse());
}

// The 42-vertex sphere of the equilibrium tests (cap held, gravity, a point
// load, surface tension, axis factors) with a horizon of 0.8 in each storage.
Model sphere_with_horizon(const FiberLaw& law, FiberKinematics kinematics, bool conical,
                          geom::MaskStorage storage) {
  Model m = testing::small_sphere(law, kinematics);
  m.fibers = std::make_shared<const geom::FiberMask>(geom::horizon_fibers(m.surface, 0.8, storage));
  if (conical) m.influence = {Influence::Kind::Conical, 0.8};
  return m;
}

using testing::random_state;

double relative(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).norm() / b.norm();
}

TEST(SparseFibers, EveryEquilibriumKernelAgreesWithTheTable) {
  for (FiberKinematics kinematics : kAllKinematics)
    for (const FiberLaw& law : {FiberLaw::constant(3000.0), FiberLaw::exponential(3000.0, 4.0)})
      for (bool conical : {false, true}) {
        SCOPED_TRACE(std::string(kinematics_name(kinematics)) + " " + law.name() +
                     (conical ? " conical" : " constant influence"));
        const Model table = sphere_with_horizon(law, kinematics, conical, geom::MaskStorage::Dense);
        const Model lists =
            sphere_with_horizon(law, kinematics, conical, geom::MaskStorage::Sparse);
        const Equilibrium dense(table), sparse(lists);
        ASSERT_TRUE(sparse.sparse_fibers());
        ASSERT_FALSE(dense.sparse_fibers());
        const Eigen::VectorXd x = random_state(table, 3, 0.05);
        const std::vector<double> factors = {0.7, 0.4};
        EXPECT_LT(relative(sparse.residual(x, factors), dense.residual(x, factors)), 1e-13);
        const Eigen::MatrixXd J = dense.tangent(x, factors);
        EXPECT_LT(relative(sparse.tangent(x, factors), J), 1e-13);
        EXPECT_LT(relative(Eigen::MatrixXd(sparse.sparse_tangent(x, factors)), J), 1e-13);
        EXPECT_LT(relative(Eigen::MatrixXd(dense.sparse_tangent(x, factors)), J), 1e-13);
        const Eigen::VectorXd v = random_state(table, 4, 1.0);
        EXPECT_LT(relative(sparse.tangent_product(x, factors, v), J * v), 1e-12);
        EXPECT_LT(relative(sparse.linearize(x, factors).apply(v), J * v), 1e-12);
        const std::vector<std::string> names = {law.parameter_names().front(), "gamma", "factor_y"};
        EXPECT_LT(
            relative(sparse.parameter_derivatives(x, names), dense.parameter_derivatives(x, names)),
            1e-13);
        // The sparse tangent holds only the pairs within the horizon.
        EXPECT_LT(sparse.sparse_tangent(x, factors).nonZeros(), 0.8 * J.size());
      }
}

// The paper's linear system with a horizon: the blocks the sparse direct
// backends factor, the bulk products and the rows of the reactions.
TEST(SparseFibers, TheLinearSystemAgreesWithTheTable) {
  const FiberLaw law = FiberLaw::exponential(3000.0, 4.0);
  const Model table =
      sphere_with_horizon(law, FiberKinematics::VectorSpring, true, geom::MaskStorage::Dense);
  const Model lists =
      sphere_with_horizon(law, FiberKinematics::VectorSpring, true, geom::MaskStorage::Sparse);
  const Eigen::VectorXd x = random_state(table, 6, 0.05);
  const Eigen::MatrixXd strained = positions(table, x);
  const DofMap dofs = DofMap::from_constraints(table);
  const FiberSystem dense(table, table.surface.V, dofs, BoundaryMethod::Elimination, 1e9,
                          &strained);
  const FiberSystem sparse(lists, lists.surface.V, dofs, BoundaryMethod::Elimination, 1e9,
                           &strained);
  EXPECT_TRUE(sparse.sparse_fibers());
  EXPECT_FALSE(sparse.dense_blocks());
  EXPECT_LT(relative(sparse.bulk_diagonal(), dense.bulk_diagonal()), 1e-14);
  const Eigen::MatrixXd U = displacements(table, x);
  EXPECT_LT(relative(sparse.bulk_product(U), dense.bulk_product(U)), 1e-13);
  for (int a = 0; a < 3; ++a) {
    EXPECT_LT(relative(sparse.dense_block(a), dense.dense_block(a)), 1e-14);
    EXPECT_LT(relative(Eigen::MatrixXd(sparse.sparse_block(a)), dense.dense_block(a)), 1e-14);
  }
  const std::vector<int> rows = {0, 7, 30};
  EXPECT_LT(relative(sparse.unreduced_rows(rows, U, 250.0), dense.unreduced_rows(rows, U, 250.0)),
            1e-13);
}

}  // namespace
}  // namespace fiberfluid::model
