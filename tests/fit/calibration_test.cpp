// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fit/calibration.hpp"

#include <gtest/gtest.h>

#include <random>

#include "fit/fit_fixtures.hpp"
#include "model/model_fixtures.hpp"

#include "fiberfluid/fit/evaluation_cache.hpp"
#include "fiberfluid/fit/optimizers.hpp"
#include "fiberfluid/fit/problem.hpp"

#include <ceres/rotation.h>

#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::fit {
namespace {

using testing::hanging_sphere;
using testing::newton;
using testing::parameter;

// The deformed surfaces of a run at every step, as targets on the same mesh.
std::vector<MeasuredStep> synthetic_targets(const model::Model& m, const solve::SteppingOptions& o,
                                            const std::vector<int>& steps) {
  std::vector<MeasuredStep> targets;
  const solve::SteppingSummary s =
      solve::solve_load_steps(m, o, [&](const solve::StepRecord& r, const Eigen::VectorXd& x) {
        if (std::find(steps.begin(), steps.end(), r.step) != steps.end())
          targets.push_back(
              {make_target("step " + std::to_string(r.step), model::positions(m, x), m.surface.F),
               r.step});
      });
  EXPECT_TRUE(s.success) << s.message;
  return targets;
}

// The residuals' Jacobian (Newton sensitivities chained through the closest
// points, and the alignment) against central differences of whole runs.
TEST(Calibration, JacobianMatchesFiniteDifferencesForEveryParameterKind) {
  const model::Model m = hanging_sphere();
  std::vector<MeasuredStep> targets = synthetic_targets(m, newton(2), {2});
  // Move the target: the alignment then has something to do.
  for (Eigen::Index i = 0; i < targets[0].target.points.rows(); ++i)
    targets[0].target.points.row(i) += Eigen::RowVector3d(0.01, -0.02, 0.015);
  FitOptions options;
  options.symmetric = true;
  const Calibration c(
      m, newton(2), targets,
      {parameter("Y0", 2500.0), parameter("beta", 4.0, false), parameter("gamma", 350.0),
       parameter("factor_x", 1.2), parameter("rotation_y", 0.02, false),
       parameter("translation_z", -0.01, false), parameter("scale", 1.03)},
      options);
  EXPECT_TRUE(c.analytic_jacobian());
  const Eigen::VectorXd phi = c.parameters().initial_phi();
  const Evaluation e = c.evaluate(phi, true);
  ASSERT_TRUE(e.ok) << e.message;
  EXPECT_EQ(e.residuals.size(), 2 * 42);
  EXPECT_EQ(e.sensitivity_solves, 4);  // one per material parameter
  for (int k = 0; k < phi.size(); ++k) {
    const double h = 1e-6;
    Eigen::VectorXd plus = phi, minus = phi;
    plus[k] += h;
    minus[k] -= h;
    const Eigen::VectorXd fd =
        (c.evaluate(plus, false).residuals - c.evaluate(minus, false).residuals) / (2.0 * h);
    EXPECT_LT((e.jacobian.col(k) - fd).norm(), 1e-5 * fd.norm())
        << c.parameters().parameters()[static_cast<size_t>(k)].name;
  }
  // The finite-difference mode differentiates the forward runs, not the
  // distances (which have a kink at zero), and chains the same way.
  options.finite_differences = true;
  const Calibration by_differences(m, newton(2), targets, c.parameters().parameters(), options);
  EXPECT_FALSE(by_differences.analytic_jacobian());
  const Evaluation d = by_differences.evaluate(phi, true);
  ASSERT_TRUE(d.ok) << d.message;
  EXPECT_EQ(d.forward_runs, 1 + 2 * 4);
  EXPECT_LT((d.jacobian - e.jacobian).norm(), 1e-6 * e.jacobian.norm());
}

// A start so soft that its forward run fails (issue 42: a phantom fitted
// from a fifth of its modulus failed its first run, so the fit could not
// start): the fit goes on from the softest stiffer start that runs (the
// moduli and gamma times 2, 4, ...), says so, and finds the truth.
TEST(Calibration, AStartWhoseRunFailsIsStiffenedUntilItRuns) {
  const model::Model m = hanging_sphere();
  const std::vector<MeasuredStep> targets = synthetic_targets(m, newton(2), {2});
  const std::vector<Parameter> parameters = {parameter("Y0", 150.0), parameter("gamma", 15.0)};
  const Calibration c(m, newton(2), targets, parameters);
  ASSERT_FALSE(c.evaluate(c.parameters().initial_phi(), false).ok)
      << "the start must fail for this test to mean something";
  const FitResult r = c.run();
  ASSERT_TRUE(r.success) << r.message;
  EXPECT_NE(r.start_note.find("the forward run at the starting parameters failed"),
            std::string::npos)
      << r.start_note;
  EXPECT_NE(r.start_note.find("the moduli and gamma times"), std::string::npos) << r.start_note;
  EXPECT_NEAR(r.values[0] / 3000.0, 1.0, 1e-6);
  EXPECT_NEAR(r.values[1] / 300.0, 1.0, 1e-6);
  EXPECT_NEAR(r.initial[0], 150.0, 1e-9);  // the start reported is the one given
}

// A start that fails late on its path (issue 42: the layered phantom from
// Y/5 folds at its last step). Every modulus and gamma times s carries the
// full load as the start carries 1/s of it (the pressure times s), so the
// start stiffened twice is solved from the failed probe's state at half the
// load, warm, and the fit goes on to the truth as from a cold start.
TEST(Calibration, AStiffenedStartIsSolvedFromTheFailedStartsPath) {
  const model::Model m = hanging_sphere();
  const int n = 4;
  // Stiffness times 2 at the full load is the body at half of it.
  model::Model stiff = m;
  for (const char* name : {"Y0", "gamma"})
    stiff.material.set_parameter(name, 2.0 * m.material.parameter(name));
  Eigen::VectorXd half;
  ASSERT_TRUE(solve::solve_load_steps(m, newton(n),
                                      [&](const solve::StepRecord& r, const Eigen::VectorXd& x) {
                                        if (r.step == n / 2) half = x;
                                      })
                  .success);
  const solve::SteppingSummary doubled = solve::solve_load_steps(stiff, newton(n));
  ASSERT_TRUE(doubled.success) << doubled.message;
  half[half.size() - 1] *= 2.0;
  EXPECT_LT((doubled.unknowns - half).cwiseAbs().maxCoeff(),
            1e-8 * std::max(1.0, half.cwiseAbs().maxCoeff()));

  // The softest start (Y0 and gamma in proportion) that runs, by bisection;
  // just below it a run fails part of the way: the first, going down, that
  // fails past half the load (0.99 of it, at step 3 of 4).
  const std::vector<MeasuredStep> targets = synthetic_targets(m, newton(n), {n});
  auto start = [](double f) {
    return std::vector<Parameter>{parameter("Y0", 3000.0 * f), parameter("gamma", 300.0 * f)};
  };
  double ok = 1.0, fails = 1e-4;
  for (int k = 0; k < 30; ++k) {
    const double mid = std::sqrt(ok * fails);
    const Calibration c(m, newton(n), targets, start(mid));
    (c.evaluate(c.parameters().initial_phi(), false).ok ? ok : fails) = mid;
  }
  double f = 0.99;
  for (; f > 0.5; f -= 0.01) {
    const Calibration c(m, newton(n), targets, start(f * ok));
    const Evaluation e = c.evaluate(c.parameters().initial_phi(), false);
    if (!e.ok && e.summary.steps.size() >= static_cast<size_t>(n / 2)) break;
  }
  ASSERT_GT(f, 0.5) << "no start that fails past half the load";
  const Calibration c(m, newton(n), targets, start(f * ok));
  const int s = 2;  // its end is the failed path's state at step n/2
  const FitResult r = c.run();
  ASSERT_TRUE(r.success) << r.message;
  EXPECT_NE(r.start_note.find("times " + std::to_string(s) + ","), std::string::npos)
      << r.start_note;
  EXPECT_NEAR(r.values[0] / 3000.0, 1.0, 1e-6);
  EXPECT_NEAR(r.values[1] / 300.0, 1.0, 1e-6);
  // The warm start reached the stiffened start's own equilibrium: the cost
  // there is the one a walk of its path gives.
  Eigen::VectorXd stiffened = c.parameters().initial_phi();
  stiffened.array() += std::log(static_cast<double>(s));
  EXPECT_NEAR(r.initial_cost / c.cost(c.evaluate(stiffened, false).residuals), 1.0, 1e-8);
  // The failed probe, and the path's run at the optimum: the rest were warm.
  EXPECT_EQ(r.failed_runs, 1);
  EXPECT_EQ(r.warm_started_runs, r.forward_runs - 2);
}

// Levenberg-Marquardt moves a log-scaled parameter by at most
// max_step_factor per step (a box around the current point), and still
// reaches the truth from 30 times it.
TEST(Calibration, LevenbergMarquardtStepsStayWithinTheStepFactor) {
  const model::Model m = hanging_sphere();
  const std::vector<MeasuredStep> targets = synthetic_targets(m, newton(2), {2});
  const std::vector<Parameter> parameters = {parameter("Y0", 90000.0), parameter("gamma", 300.0)};
  for (const double factor : {4.0, 1.5}) {
    FitOptions options;
    options.max_step_factor = factor;
    const FitResult r = Calibration(m, newton(2), targets, parameters, options).run();
    ASSERT_TRUE(r.success) << r.message;
    EXPECT_NEAR(r.values[0] / 3000.0, 1.0, 1e-6) << factor;
    EXPECT_NEAR(r.values[1] / 300.0, 1.0, 1e-6) << factor;
    Eigen::VectorXd from = r.initial;
    int accepted = 0;
    for (const IterationRecord& it : r.iterations) {
      for (Eigen::Index k = 0; k < from.size(); ++k)
        EXPECT_LE(std::abs(std::log(it.values[k] / from[k])), std::log(factor) * (1 + 1e-12))
            << "iteration " << it.iteration << ", " << r.names[static_cast<size_t>(k)];
      if (it.accepted && it.iteration > 0) ++accepted;
      from = it.values;
    }
    // 30 times the truth is more than two steps of 4 (ten of 1.5) away.
    EXPECT_GE(accepted, static_cast<int>(std::ceil(std::log(30.0) / std::log(factor)))) << factor;
  }
  FitOptions bad;
  bad.max_step_factor = 1.0;
  EXPECT_THROW(check_options(bad), InputError);
}

TEST(Calibration, RecoversTheParametersOfANoiseFreeTargetWithCeresAndBobyqa) {
  const model::Model m = hanging_sphere();
  const std::vector<MeasuredStep> targets = synthetic_targets(m, newton(2), {1, 2});
  // From a start a factor 3 away.
  const std::vector<Parameter> parameters = {
      parameter("Y0", 9000.0), parameter("beta", 5.0 / 3.0, false), parameter("gamma", 100.0)};
  const Eigen::Vector3d truth(3000.0, 5.0, 300.0);
  const FitResult lm = Calibration(m, newton(2), targets, parameters).run();
  ASSERT_TRUE(lm.success) << lm.message;
  EXPECT_TRUE(lm.analytic_jacobian);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(lm.values[k] / truth[k], 1.0, 1e-6) << lm.names[k];
  EXPECT_LT(lm.overall.largest, 1e-8);
  EXPECT_GT(lm.sensitivity_solves, 0);
  EXPECT_FALSE(lm.iterations.empty());
  EXPECT_LT(lm.final_cost, 1e-6 * lm.initial_cost);
  // The cost reported per iteration is the current point's: it never rises;
  // a rejected trial point costs more.
  for (size_t k = 1; k < lm.iterations.size(); ++k) {
    EXPECT_LE(lm.iterations[k].cost, lm.iterations[k - 1].cost) << k;
    if (!lm.iterations[k].accepted) {
      EXPECT_GT(lm.iterations[k].trial_cost, lm.iterations[k].cost);
    }
  }
  // One forward run per trial point: the start, the optimum and the
  // covariance reuse the optimiser's runs (at most one last trial point is
  // evaluated without an iteration of its own).
  EXPECT_LE(lm.forward_runs, static_cast<int>(lm.iterations.size()) + 1);

  FitOptions bobyqa;
  bobyqa.method = Method::Bobyqa;
  bobyqa.max_evaluations = 600;
  const FitResult b = Calibration(m, newton(2), targets, parameters, bobyqa).run();
  ASSERT_TRUE(b.success) << b.message;
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(b.values[k] / lm.values[k], 1.0, 1e-4) << b.names[k];
  // No sensitivities for the search; the covariance's Jacobian at the
  // optimum takes one solve per material parameter and target step.
  EXPECT_EQ(b.sensitivity_solves, 3 * 2);
}

// Targets on the final step only: each trial point's run is solved from the
// nearest point already run (a warm start) instead of walking the load path,
// and the fit finds what it finds without them. The optimum is run along the
// path once more: its report has every step, and agrees with the warm run.
TEST(Calibration, TrialPointsAreSolvedFromTheNearestPointsState) {
  const model::Model m = hanging_sphere();
  const std::vector<MeasuredStep> targets = synthetic_targets(m, newton(4), {4});
  const std::vector<Parameter> parameters = {parameter("Y0", 9000.0), parameter("gamma", 100.0)};
  FitOptions walking;
  walking.warm_start = false;
  const Calibration cold(m, newton(4), targets, parameters, walking);
  const Calibration warm(m, newton(4), targets, parameters);
  EXPECT_FALSE(cold.warm_starts());
  EXPECT_TRUE(warm.warm_starts());
  const FitResult a = cold.run(), b = warm.run();
  ASSERT_TRUE(a.success) << a.message;
  ASSERT_TRUE(b.success) << b.message;
  for (int k = 0; k < 2; ++k) {
    EXPECT_NEAR(b.values[k] / a.values[k], 1.0, 1e-7) << b.names[static_cast<size_t>(k)];
    EXPECT_NEAR(b.standard_errors[k] / a.standard_errors[k], 1.0, 1e-3);
  }
  EXPECT_NEAR(b.values[0] / 3000.0, 1.0, 1e-6);
  EXPECT_EQ(a.warm_started_runs, 0);
  EXPECT_GT(b.warm_started_runs, b.forward_runs / 2);  // all but the start's and the check's
  EXPECT_EQ(b.warm_start_note, "");
  EXPECT_EQ(b.summary.steps.size(), 4u);  // the path's run at the optimum, reported
  EXPECT_EQ(b.statistics.size(), 1u);     // once
  EXPECT_EQ(b.vertex_distances.size(), 1u);
  EXPECT_FALSE(b.summary.warm_started);

  // Targets that read an earlier step too: the path every time.
  EXPECT_FALSE(
      Calibration(m, newton(4), synthetic_targets(m, newton(4), {2, 4}), parameters).warm_starts());
}

// A parameter the data barely see: a sphere pressed by a paddle, its force
// read at 5 steps with 1% noise, and gamma 0.3 N/m against Y = 3000, which
// moves the force by a ten-thousandth. Re-fitting Y, the cost flattens as
// gamma goes to zero, so the linearised interval (in log scale) closes
// below where the data do not. The checked interval runs to gamma's lower
// bound, says why, and holds the truth.
TEST(Calibration, AnIntervalTheDataLeaveOpenRunsToItsBound) {
  model::Model m = testing::pressed_sphere(false);
  m.material.surface_tension = 0.3;
  const solve::SteppingSummary truth = solve::solve_load_steps(m, newton(5));
  ASSERT_TRUE(truth.success) << truth.message;
  ForceCurve curve;
  curve.label = "pressed sphere";
  curve.by_step = true;
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.01);
  for (const solve::StepRecord& r : truth.steps) {
    curve.at.push_back(r.step);
    curve.force.push_back(curve_force(curve, m, r.paddles[0].force) * (1.0 + noise(rng)));
  }
  Parameter y = parameter("Y", 6000.0), gamma = parameter("gamma", 30.0);
  y.lower = 100.0, y.upper = 1e6;
  gamma.lower = 1e-6, gamma.upper = 1e4;
  FitOptions checked;
  checked.check_intervals = true;
  const FitResult linear = Calibration(m, newton(5), {}, {y, gamma}, {}, {curve}).run();
  const FitResult r = Calibration(m, newton(5), {}, {y, gamma}, checked, {curve}).run();
  ASSERT_TRUE(converged(r.status)) << r.message << " " << r.status_detail;
  ASSERT_EQ(r.interval_notes.size(), 2u);
  EXPECT_GT(linear.lower_95[1], 0.01) << "the linearised interval closes below: 0.11 here";
  EXPECT_NEAR(r.lower_95[1], 1e-6, 1e-12) << r.interval_notes[1];
  EXPECT_NE(r.interval_notes[1].find("the data do not bound gamma from below"), std::string::npos)
      << r.interval_notes[1];
  EXPECT_EQ(r.upper_95[1], linear.upper_95[1]);  // an end is only ever moved out
  EXPECT_GT(r.upper_95[1], 0.3);
  EXPECT_EQ(r.values, linear.values);
  EXPECT_GT(r.interval_runs, 2);
  EXPECT_EQ(r.forward_runs, linear.forward_runs + r.interval_runs);
}

// A point asked for twice costs one forward run; with the Jacobian after
// without it, a second.
TEST(Calibration, EvaluationsAreKeptAndCounted) {
  const model::Model m = hanging_sphere();
  const Calibration c(m, newton(2), synthetic_targets(m, newton(2), {2}),
                      {parameter("Y0", 2000.0), parameter("gamma", 200.0)});
  EvaluationCache cache(c.problem());
  const Eigen::VectorXd phi = c.parameters().initial_phi();
  const double cost = c.cost(cache.at(phi, false).residuals);
  EXPECT_EQ(cache.forward_runs, 1);
  EXPECT_EQ(c.cost(cache.at(phi, false).residuals), cost);
  EXPECT_EQ(cache.forward_runs, 1);
  EXPECT_EQ(cache.at(phi, true).jacobian.cols(), 2);
  EXPECT_EQ(cache.forward_runs, 2);
  EXPECT_EQ(cache.sensitivity_solves, 2);              // one tangent solve per material parameter
  EXPECT_EQ(cache.at(phi, false).jacobian.cols(), 2);  // the kept one, Jacobian and all
  EXPECT_EQ(cache.forward_runs, 2);
  Eigen::VectorXd moved = phi;
  moved[0] += 0.1;
  EXPECT_GT(c.cost(cache.at(moved, false).residuals), 0.0);
  EXPECT_EQ(cache.forward_runs, 3);
  cache.at(phi, false);  // still kept
  EXPECT_EQ(cache.forward_runs, 3);
}

// A scan of unsure units: a similarity T(q) = s q + t takes it back.
TEST(Calibration, AlignmentRecoversAKnownScale) {
  const model::Model m = hanging_sphere();
  std::vector<MeasuredStep> targets = synthetic_targets(m, newton(1), {1});
  const Eigen::RowVector3d shift(0.01, -0.02, 0.005);
  for (Eigen::Index i = 0; i < targets[0].target.points.rows(); ++i)
    targets[0].target.points.row(i) = targets[0].target.points.row(i) / 1.04 - shift;
  const FitResult r =
      Calibration(m, newton(1), targets,
                  {parameter("scale", 1.0), parameter("translation_x", 0.0, false),
                   parameter("translation_y", 0.0, false), parameter("translation_z", 0.0, false)})
          .run();
  ASSERT_EQ(r.status, FitStatus::Converged) << r.message << " " << r.status_detail;
  EXPECT_NEAR(r.values[0], 1.04, 1e-8);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(r.values[1 + a], 1.04 * shift[a], 1e-8);
  EXPECT_LT(r.overall.largest, 1e-9);
}

TEST(Calibration, AlignmentRecoversAKnownRigidMotion) {
  const model::Model m = hanging_sphere();
  std::vector<MeasuredStep> targets = synthetic_targets(m, newton(1), {1});
  const double omega[3] = {0.05, -0.03, 0.02};
  const Eigen::Vector3d shift(0.01, 0.02, -0.01);
  Eigen::MatrixXd& P = targets[0].target.points;
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    const double p[3] = {P(i, 0), P(i, 1), P(i, 2)};
    double q[3];
    ceres::AngleAxisRotatePoint(omega, p, q);
    P.row(i) = Eigen::RowVector3d(q[0], q[1], q[2]) + shift.transpose();
  }
  std::vector<Parameter> motion;
  for (const char* name : {"rotation_x", "rotation_y", "rotation_z", "translation_x",
                           "translation_y", "translation_z"})
    motion.push_back(parameter(name, 0.0, false));
  const FitResult r = Calibration(m, newton(1), targets, motion).run();
  ASSERT_TRUE(r.success) << r.message;
  // The fitted motion takes the target back onto the body: T(M(p)) = p.
  const double back[3] = {r.values[0], r.values[1], r.values[2]};
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 0, 1)}) {
    double moved[3], returned[3];
    const double pp[3] = {p.x(), p.y(), p.z()};
    ceres::AngleAxisRotatePoint(omega, pp, moved);
    for (int a = 0; a < 3; ++a) moved[a] += shift[a];
    ceres::AngleAxisRotatePoint(back, moved, returned);
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(returned[a] + r.values[3 + a], p[a], 1e-7);
  }
}

TEST(Calibration, TheIncrementalSchemeIsFittedWithFiniteDifferences) {
  model::Model m = hanging_sphere();
  m.material.law = model::FiberLaw::constant(3000.0);
  solve::SteppingOptions incremental;
  incremental.steps = 2;
  const std::vector<MeasuredStep> targets = synthetic_targets(m, incremental, {2});
  const Calibration c(m, incremental, targets, {parameter("Y", 1000.0), parameter("gamma", 900.0)});
  EXPECT_FALSE(c.analytic_jacobian());
  const FitResult r = c.run();
  ASSERT_TRUE(r.success) << r.message;
  EXPECT_FALSE(r.analytic_jacobian);
  EXPECT_NEAR(r.values[0] / 3000.0, 1.0, 1e-5);
  EXPECT_NEAR(r.values[1] / 300.0, 1.0, 1e-5);
}

// A point cloud (the target's vertices alone) is fitted point to point.
TEST(Calibration, FitsAPointCloudTarget) {
  const model::Model m = hanging_sphere();
  std::vector<MeasuredStep> targets = synthetic_targets(m, newton(2), {2});
  targets[0].target = make_target("cloud", targets[0].target.points);
  ASSERT_TRUE(targets[0].target.is_point_cloud());
  const FitResult r =
      Calibration(m, newton(2), targets, {parameter("Y0", 1000.0), parameter("gamma", 900.0)})
          .run();
  ASSERT_TRUE(r.success) << r.message;
  EXPECT_NEAR(r.values[0] / 3000.0, 1.0, 1e-6);
  EXPECT_NEAR(r.values[1] / 300.0, 1.0, 1e-6);
}

// Outliers in a scan (stray points far off the surface) pull a least-squares
// fit; a robust loss discounts them.
TEST(Calibration, ARobustLossResistsOutliers) {
  const model::Model m = hanging_sphere();
  std::vector<MeasuredStep> targets = synthetic_targets(m, newton(2), {2});
  Target& t = targets[0].target;
  for (Eigen::Index i = 0; i < t.points.rows(); i += 7) t.points(i, 0) += 0.15;  // spikes
  const std::vector<Parameter> parameters = {parameter("Y0", 1000.0), parameter("gamma", 900.0)};
  auto fit_with = [&](Loss loss) {
    FitOptions options;
    options.loss = loss;
    options.loss_scale = 0.005;
    options.symmetric = true;  // the stray points' own distances count too
    const FitResult r = Calibration(m, newton(2), targets, parameters, options).run();
    EXPECT_TRUE(r.success) << r.message;
    return std::max(std::abs(r.values[0] / 3000.0 - 1.0), std::abs(r.values[1] / 300.0 - 1.0));
  };
  const double squared = fit_with(Loss::Squared), huber = fit_with(Loss::Huber),
               cauchy = fit_with(Loss::Cauchy);
  // Measured: squared 7.5% off, Huber 0.47%, Cauchy 0.018%.
  EXPECT_GT(squared, 0.03);
  EXPECT_LT(huber, 0.1 * squared);
  EXPECT_LT(cauchy, 0.01 * squared);
}

// A trial point whose forward run fails (a material so soft that the body
// runs away) is a rejected step: the fit goes on and still recovers the truth.
TEST(Calibration, AForwardRunThatFailsInsideTheFitIsARejectedStep) {
  const model::Model m = hanging_sphere();
  std::vector<MeasuredStep> probe = synthetic_targets(m, newton(2), {2});
  // The softest Y0 that still runs, by bisection in log scale.
  double ok = 3000.0, fails = 1e-3;
  for (int k = 0; k < 40; ++k) {
    const double mid = std::sqrt(ok * fails);
    const Calibration c(m, newton(2), probe, {parameter("Y0", mid)});
    (c.evaluate(c.parameters().initial_phi(), false).ok ? ok : fails) = mid;
  }
  ASSERT_LT(ok, 2000.0) << "no failing region below the truth";
  // The truth just above it; BOBYQA starts where its first steps (a factor
  // e^0.3 down) fail.
  model::Model soft = m;
  soft.material.law.set_parameter("Y0", 1.3 * ok);
  const std::vector<MeasuredStep> targets = synthetic_targets(soft, newton(2), {2});
  FitOptions bobyqa;
  bobyqa.method = Method::Bobyqa;
  bobyqa.warm_start = false;  // every trial walks the path, as a failing one must show
  const FitResult b =
      Calibration(soft, newton(2), targets, {parameter("Y0", 1.2 * ok)}, bobyqa).run();
  EXPECT_GT(b.failed_runs, 0);
  ASSERT_TRUE(b.success) << b.message;
  EXPECT_NEAR(b.values[0] / (1.3 * ok), 1.0, 1e-5);
  // Warm-started, a trial point past where the path fails may still reach an
  // equilibrium from its neighbour's state; the optimum is the path's.
  bobyqa.warm_start = true;
  const FitResult w =
      Calibration(soft, newton(2), targets, {parameter("Y0", 1.2 * ok)}, bobyqa).run();
  ASSERT_TRUE(w.success) << w.message;
  EXPECT_NEAR(w.values[0] / (1.3 * ok), 1.0, 1e-5);
  EXPECT_EQ(w.warm_start_note, "");
  // Levenberg-Marquardt from a factor 3 above: whatever its trial points, it recovers.
  const FitResult lm = Calibration(soft, newton(2), targets, {parameter("Y0", 3.9 * ok)}).run();
  ASSERT_TRUE(lm.success) << lm.message;
  EXPECT_NEAR(lm.values[0] / (1.3 * ok), 1.0, 1e-6);
}

void expect_input_error(const std::function<void()>& f, const std::string& part) {
  try {
    f();
    ADD_FAILURE() << "no error, expected one mentioning '" << part << "'";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

TEST(Calibration, BadFitsAreNamed) {
  const model::Model m = hanging_sphere();
  const std::vector<MeasuredStep> targets = synthetic_targets(m, newton(1), {1});
  expect_input_error([&] { Calibration(m, newton(1), targets, {parameter("stiffness", 1.0)}); },
                     "parameter \"stiffness\" is not a parameter");
  Parameter bounded = parameter("Y0", 3000.0);
  bounded.lower = 4000.0;
  bounded.upper = 8000.0;
  expect_input_error([&] { Calibration(m, newton(1), targets, {bounded}); },
                     "the start 3000 lies outside the bounds [4000, 8000]");
  expect_input_error([&] { Calibration(m, newton(1), targets, {parameter("beta", -1.0)}); },
                     "log scale");
  std::vector<MeasuredStep> far = targets;
  far[0].target.points.col(0).array() += 10.0;
  expect_input_error([&] { Calibration(m, newton(1), far, {parameter("Y0", 3000.0)}); },
                     "does not overlap the body");
  std::vector<MeasuredStep> late = targets;
  late[0].step = 5;
  expect_input_error([&] { Calibration(m, newton(1), late, {parameter("Y0", 3000.0)}); },
                     "tied to load step 5");
  FitOptions global;
  global.method = Method::DirectL;
  expect_input_error(
      [&] { Calibration(m, newton(1), targets, {parameter("Y0", 3000.0)}, global).run(); },
      "needs finite lower and upper bounds");

  // A global search stays within max_evaluations, however small: NLopt reads
  // a phase's limit of 0 as none (DIRECT-L's global half of 1 made 156,168 runs).
  Parameter boxed = parameter("Y0", 3000.0);
  boxed.lower = 1000.0;
  boxed.upper = 10000.0;
  for (Method method : {Method::DirectL, Method::Crs2}) {
    for (int most : {1, 2, 5}) {
      FitOptions few;
      few.method = method;
      few.max_evaluations = most;
      few.warm_start = false;  // a warm-started optimum's check from rest is a run more
      const FitResult r = Calibration(m, newton(1), targets, {boxed}, few).run();
      EXPECT_LE(r.forward_runs, most) << to_string(method) << " " << most;
      EXPECT_EQ(r.status, FitStatus::IterationLimit) << to_string(method) << " " << most;
    }
  }

  // A forward run that fails is a result with a message, not a crash.
  const Calibration soft(m, newton(1), targets, {parameter("Y0", 1e-3)});
  const Evaluation e = soft.evaluate(soft.parameters().initial_phi(), true);
  EXPECT_FALSE(e.ok);
  EXPECT_FALSE(e.message.empty());
  const FitResult r = soft.run();
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.message.find("the forward run at the starting parameters failed"), std::string::npos)
      << r.message;
}

}  // namespace
}  // namespace fiberfluid::fit

