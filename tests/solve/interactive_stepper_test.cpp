// SPDX-License-Identifier: GPL-3.0-or-later
// The interactive stepper: one Newton step at a time to points the caller
// chooses. It must give the batch run's answer on the batch run's path, hold
// no memory of the path (an elastic body), keep its state when a step fails,
// and reject points that do not fit the model.
#include <gtest/gtest.h>

#include <cmath>

#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/solve/newton/interactive_stepper.hpp"
#include "fiberfluid/util/error.hpp"
#include "model/model_fixtures.hpp"

namespace fiberfluid::solve {
namespace {

// The paper's sphere resting on its bottom cap, a paddle pressing from
// above, the exponential law.
model::Model pressed_sphere() {
  model::Model m = testing::pressed_sphere();
  m.material.law = model::FiberLaw::exponential(3000.0, 3.0);
  return m;
}

// Newton from the last solution (the interactive stepper does not extrapolate).
SteppingOptions newton_options(int steps) {
  SteppingOptions o;
  o.scheme = Scheme::Newton;
  o.steps = steps;
  o.newton.predictor = false;
  return o;
}

TEST(InteractiveStepper, StepsAlongTheScheduleGiveTheBatchRunBitForBit) {
  const model::Model m = pressed_sphere();
  const int n = 5;
  for (TangentSolver tangent : {TangentSolver::Dense, TangentSolver::Krylov}) {
    SteppingOptions o = newton_options(n);
    o.newton.tangent = tangent;
    const SteppingSummary batch = solve_load_steps(m, o);
    ASSERT_TRUE(batch.success) << batch.message;
    InteractiveStepper stepper(m, o);
    for (int k = 1; k <= n; ++k) {
      const InteractiveStepper::Result r = stepper.step(scheduled_point(m, k, n));
      ASSERT_TRUE(r.success) << r.message;
      const StepRecord& b = batch.steps[static_cast<size_t>(k - 1)];
      EXPECT_EQ(r.record.newton_iterations, b.newton_iterations) << k;
      EXPECT_EQ(r.record.krylov_iterations, b.krylov_iterations) << k;
      EXPECT_EQ(r.record.paddles[0].contacts, b.paddles[0].contacts) << k;
      EXPECT_EQ(r.record.paddles[0].force, b.paddles[0].force) << k;
    }
    EXPECT_EQ(stepper.steps_taken(), n);
    EXPECT_TRUE(stepper.unknowns() == batch.unknowns) << to_string(tangent);
  }
}

TEST(InteractiveStepper, APressThatGoesOnIsExtrapolatedAndReachesTheSameState) {
  // Equal moves down, then one back up: the predictor extrapolates the moves
  // that go on in the last one's direction, and not the one that turns.
  const model::Model m = pressed_sphere();
  SteppingOptions plain = newton_options(1), predicted = newton_options(1);
  predicted.newton.predictor = true;
  InteractiveStepper a(m, plain), b(m, predicted);
  LoadPoint point = a.point();
  int plain_iterations = 0, predicted_iterations = 0;
  for (int k = 1; k <= 9; ++k) {
    point.planes[0] -= k < 9 ? 0.03 : -0.05;
    const InteractiveStepper::Result ra = a.step(point), rb = b.step(point);
    ASSERT_TRUE(ra.success && rb.success) << ra.message << rb.message;
    plain_iterations += ra.record.newton_iterations;
    predicted_iterations += rb.record.newton_iterations;
  }
  EXPECT_LT(predicted_iterations, plain_iterations);
  const Eigen::VectorXd &xa = a.unknowns(), &xb = b.unknowns();
  EXPECT_LT((xa - xb).head(xa.size() - 1).norm(), 1e-8 * xa.head(xa.size() - 1).norm());
}

TEST(InteractiveStepper, APaddleMovedDownAndBackLeavesTheBodyAtRest) {
  // Frictionless contact on an elastic body: no memory of the path.
  const model::Model m = pressed_sphere();
  InteractiveStepper stepper(m, newton_options(1));
  LoadPoint point = stepper.point();
  const double start = point.planes[0];
  double deepest = 0.0;
  for (double depth : {0.05, 0.12, 0.2, 0.25, 0.15, 0.08, 0.0}) {
    point.planes[0] = start - depth;
    const InteractiveStepper::Result r = stepper.step(point);
    ASSERT_TRUE(r.success) << r.message;
    EXPECT_LE(stepper.positions().col(2).maxCoeff(), point.planes[0] + 1e-12) << depth;
    if (depth == 0.25) deepest = -r.record.paddles[0].force.z();
    if (depth == 0.0) {  // the top vertex may still touch the plane, with no force
      EXPECT_LE(r.record.paddles[0].contacts, 1);
      EXPECT_LT(r.record.paddles[0].force.norm(), 1e-9 * deepest);
    }
  }
  EXPECT_GT(deepest, 0.0);
  const Eigen::VectorXd& x = stepper.unknowns();
  EXPECT_LT(x.head(x.size() - 1).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(InteractiveStepper, AStepAtTheSamePointCostsOneResidualPass) {
  const model::Model m = pressed_sphere();
  InteractiveStepper stepper(m, newton_options(1));
  LoadPoint point = stepper.point();
  point.planes[0] -= 0.1;
  ASSERT_TRUE(stepper.step(point).success);
  const Eigen::VectorXd before = stepper.unknowns();
  const InteractiveStepper::Result again = stepper.step(point);
  ASSERT_TRUE(again.success) << again.message;
  EXPECT_EQ(again.record.newton_iterations, 0);
  EXPECT_EQ(again.record.pair_passes.computed, 1);
  EXPECT_TRUE(stepper.unknowns() == before);
}

TEST(InteractiveStepper, AFailedStepKeepsTheLastEquilibrium) {
  model::Model m = pressed_sphere();
  model::Load pull;  // a point load pulling the body's side out
  pull.label = "pull";
  m.surface.V.col(0).maxCoeff(&pull.vertex);
  pull.force = Eigen::Vector3d(1.0, 0.0, 0.0);
  m.loads = {pull};
  SteppingOptions o = newton_options(1);
  o.newton.max_iterations = 4;
  o.newton.max_step_cuts = 0;
  InteractiveStepper stepper(m, o);
  LoadPoint point = stepper.point();
  point.planes[0] -= 0.01;
  ASSERT_TRUE(stepper.step(point).success);
  const Eigen::VectorXd before = stepper.unknowns();
  LoadPoint wild = point;
  wild.factors[0] = 1e6;  // far more than four iterations can follow
  const InteractiveStepper::Result failed = stepper.step(wild);
  ASSERT_FALSE(failed.success);
  EXPECT_NE(failed.message.find("interactive step 2: "), std::string::npos) << failed.message;
  EXPECT_TRUE(stepper.unknowns() == before);
  EXPECT_EQ(stepper.steps_taken(), 1);
  EXPECT_EQ(stepper.point().factors[0], 0.0);
  // It goes on from there.
  point.planes[0] -= 0.01;
  const InteractiveStepper::Result next = stepper.step(point);
  EXPECT_TRUE(next.success) << next.message;
  EXPECT_EQ(stepper.steps_taken(), 2);
}

TEST(InteractiveStepper, PointsThatDoNotFitTheModelAreRejectedByName) {
  const model::Model m = pressed_sphere();
  InteractiveStepper stepper(m, newton_options(1));
  const auto message = [&](const LoadPoint& p) {
    try {
      stepper.step(p);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  LoadPoint p = stepper.point();
  p.planes.push_back(0.0);
  EXPECT_NE(message(p).find("paddle planes: 2 given, the model has 1"), std::string::npos);
  p = stepper.point();
  p.factors.push_back(1.0);
  EXPECT_NE(message(p).find("load factors: 1 given, the model has 0"), std::string::npos);
  p = stepper.point();
  p.held_values = Eigen::VectorXd::Zero(5);
  EXPECT_NE(message(p).find("held values"), std::string::npos);
  p = stepper.point();
  p.planes[0] = std::nan("");
  EXPECT_NE(message(p).find("not finite"), std::string::npos);
  EXPECT_EQ(stepper.steps_taken(), 0);

  model::Model two = pressed_sphere();
  model::Paddle bottom = two.paddles[0];
  bottom.label = "bottom";
  bottom.above = false;
  bottom.position = -1.2;
  two.paddles.push_back(bottom);
  InteractiveStepper crossing(two, newton_options(1));
  p = crossing.point();
  p.planes[1] = p.planes[0] + 0.1;
  try {
    crossing.step(p);
    ADD_FAILURE() << "crossing paddles were accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("paddles top and bottom meet or pass each other"),
              std::string::npos)
        << e.what();
  }

  model::Model inside = pressed_sphere();
  inside.paddles[0].position = 0.5;
  EXPECT_THROW(InteractiveStepper(inside, newton_options(1)), InputError);
}

}  // namespace
}  // namespace fiberfluid::solve
