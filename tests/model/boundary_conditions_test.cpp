// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/model/boundary_conditions.hpp"

#include <gtest/gtest.h>

#include "fiberfluid/model/reference/dense_assembly.hpp"
#include "fiberfluid/util/error.hpp"
#include "model/model_fixtures.hpp"

namespace fiberfluid::model {
namespace {

using namespace fiberfluid::model::reference;  // the oracle

TEST(BoundaryConditions, ParsesHalfSpaces) {
  const HalfSpace h = parse_half_space("z >= 0.8", 3);
  EXPECT_EQ(h.axis, 2);
  EXPECT_TRUE(h.greater && h.inclusive);
  EXPECT_DOUBLE_EQ(h.threshold, 0.8);
  const HalfSpace g = parse_half_space("x<-1e-3", 2);
  EXPECT_EQ(g.axis, 0);
  EXPECT_FALSE(g.greater || g.inclusive);
  EXPECT_DOUBLE_EQ(g.threshold, -1e-3);
  EXPECT_THROW(parse_half_space("z => 1", 3), InputError);
  EXPECT_THROW(parse_half_space("w >= 1", 3), InputError);
  EXPECT_THROW(parse_half_space("z >= 1", 2), InputError);
  EXPECT_THROW(parse_half_space("z >= one", 3), InputError);
}

TEST(BoundaryConditions, SelectsByHalfSpaceAndBox) {
  Eigen::MatrixXd X(4, 2);
  X << 0, 0, 1, 0, 1, 1, 0, 1;
  EXPECT_EQ(select_half_space(X, parse_half_space("x >= 1", 2)), (std::vector<int>{1, 2}));
  EXPECT_EQ(select_half_space(X, parse_half_space("y < 1", 2)), (std::vector<int>{0, 1}));
  EXPECT_EQ(select_box(X, Eigen::Vector2d(-0.5, 0.5), Eigen::Vector2d(0.5, 1.5)),
            (std::vector<int>{3}));
}

TEST(BoundaryConditions, SingularSetupsAreNamed) {
  Model m = testing::paper_rectangle_model();
  EXPECT_TRUE(check_not_singular(m).ok);
  m.constraints.pop_back();
  m.constraints.erase(m.constraints.begin() + 1);  // only x of v3 left
  EXPECT_NE(check_not_singular(m).message.find("no support along y"), std::string::npos);
  // A paddle on y touching the body at its start holds y; one clear of it does not.
  Paddle floor;
  floor.axis = 1;
  floor.above = false;
  floor.position = m.surface.V.col(1).minCoeff();
  m.paddles = {floor};
  EXPECT_TRUE(check_not_singular(m).ok);
  EXPECT_EQ(touching_at_start(m, floor).size(), 2u);  // the rectangle's lower side
  m.paddles[0].position -= 1e-3;
  EXPECT_TRUE(touching_at_start(m, m.paddles[0]).empty());
  EXPECT_NE(check_not_singular(m).message.find("a paddle on y touching the body at its start"),
            std::string::npos)
      << check_not_singular(m).message;
  m.paddles.clear();
  m.constraints.clear();
  EXPECT_NE(check_not_singular(m).message.find("no supports"), std::string::npos);
  Model soft = testing::paper_rectangle_model();
  soft.material.law = FiberLaw::constant(0.0);
  EXPECT_NE(check_not_singular(soft).message.find("no stiffness"), std::string::npos);
}

TEST(BoundaryConditions, PartitionMergesRepeatsAndRejectsConflicts) {
  Model m = testing::paper_rectangle_model();
  m.constraints.push_back({2, 0, 0.0, {}});  // the same support twice
  const DofPartition p = partition_dofs(m);
  EXPECT_EQ(p.constrained, (std::vector<int>{2, 5, 6}));
  EXPECT_EQ(p.free.size(), 6u);
  m.constraints.push_back({2, 0, 1.0, {}});
  EXPECT_THROW(partition_dofs(m), InputError);
}

TEST(BoundaryConditions, ReductionMovesConstrainedValuesToTheRightHandSide) {
  Eigen::MatrixXd A(3, 3);
  A << 4, 1, 0, 1, 3, 1, 0, 1, 2;
  DofPartition p;
  p.free = {0, 2};
  p.constrained = {1};
  Eigen::MatrixXd A_free;
  Eigen::VectorXd B_free;
  const Eigen::VectorXd values = Eigen::VectorXd::Constant(1, 2.0);
  reduce_system(p, values, A, Eigen::Vector3d(1, 0, 1), A_free, B_free);
  EXPECT_EQ(A_free, (Eigen::Matrix2d() << 4, 0, 0, 2).finished());
  EXPECT_EQ(B_free, Eigen::Vector2d(-1, -1));
}

}  // namespace
}  // namespace fiberfluid::model
