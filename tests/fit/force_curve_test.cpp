// SPDX-License-Identifier: GPL-3.0-or-later
// Force curves as fit targets: the CSV reader, the rows' placement by travel
// or step, their residuals' Jacobian against central differences, and what
// a force curve adds: under paddles alone a modulus and the surface tension
// act through their ratio (a surface cannot tell them apart); the force
// fixes the scale.
#include "fiberfluid/fit/force_curve.hpp"
#include "fiberfluid/fit/force_misfit.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "fit/fit_fixtures.hpp"

#include <functional>

#include "fiberfluid/fit/calibration.hpp"
#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/util/error.hpp"
#include "model/model_fixtures.hpp"
#include "test_support.hpp"

namespace fiberfluid::fit {
namespace {

using testing::newton;
using testing::parameter;

void expect_input_error(const std::function<void()>& action, const std::string& part) {
  try {
    action();
    ADD_FAILURE() << "no error; expected one with: " << part;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

ForceCurveColumns scaled(double travel_scale, double force_scale) {
  ForceCurveColumns c;
  c.travel_scale = travel_scale;
  c.force_scale = force_scale;
  return c;
}
ForceCurveColumns rows_by_step() {
  ForceCurveColumns c;
  c.rows_at = "step";
  return c;
}
ForceCurveColumns with_sd(const std::string& column) {
  ForceCurveColumns c;
  c.sd = column;
  return c;
}

TEST(ForceCurve, TheReaderTakesTravelOrStepAndNamesWhatIsWrong) {
  testing::ScratchDir dir;
  const ForceCurve curve = read_force_curve(
      dir.write("a.csv", "# a compression test\ntime, travel ,force\n0,0,0\n1, 2.5, -1.5\n\n"),
      scaled(1e-3, 2.0));
  EXPECT_FALSE(curve.by_step);
  ASSERT_EQ(curve.at.size(), 2u);
  EXPECT_DOUBLE_EQ(curve.at[1], 2.5e-3);
  EXPECT_DOUBLE_EQ(curve.force[1], -3.0);
  const ForceCurve by_step = read_force_curve(dir.write("b.csv", "step,force\n3,1.25\n"));
  EXPECT_TRUE(by_step.by_step);
  EXPECT_EQ(by_step.at[0], 3.0);
  // With both columns the travel places the rows, unless the step is asked for.
  const auto both = dir.write("c.csv", "step,travel,force\n3,0.01,1\n");
  EXPECT_FALSE(read_force_curve(both).by_step);
  EXPECT_TRUE(read_force_curve(both, rows_by_step()).by_step);
  EXPECT_EQ(read_force_curve(both, rows_by_step()).at[0], 3.0);
  expect_input_error(
      [&] { read_force_curve(dir.write("d.csv", "travel,force\n1,1\n"), rows_by_step()); },
      "expected a header with the columns force and step");
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"", "empty"},
      {"travel,load\n1,2\n", "line 1: expected a header with the columns force and travel or step"},

      {"travel,force\n", "a header but no rows"},
      {"travel,force\n1,abc\n", "line 2: expected a finite number in column 2, got \"abc\""},
      {"travel,force\n1,nan\n", "line 2: expected a finite number"},
      {"travel,force\n1,2,3\n", "line 2: expected 2 values as in the header, got 3"},
      {"step,force\n2.5,1\n", "line 2: expected a load step"},
      {"step,force\n0,1\n", "expected a load step"}};
  for (const auto& [text, part] : bad) {
    const auto file = dir.write("bad.csv", text);
    expect_input_error([&] { read_force_curve(file); }, part);
    expect_input_error([&] { read_force_curve(file); }, file.string());
  }
  expect_input_error([&] { read_force_curve(dir.path() / "missing.csv"); }, "cannot open");
}

// A measured file as a test machine's software exports it: its own column
// names, the scatter over repeat tests, a curve longer than the part fitted.
TEST(ForceCurve, AMeasuredFileIsReadByItsColumnsScatterAndRange) {
  testing::ScratchDir dir;
  const auto file = dir.write("measured.csv",
                              "compression_mm,A1_N,mean_N,sd_N\n0,0,0,0\n0.5,1.1,1.0,0.1\n"
                              "5,9,10,0.5\n10,41,40,1.5\n15,99,100,4\n");
  ForceCurveColumns columns;
  columns.travel = "compression_mm";
  columns.force = "mean_N";
  columns.sd = "sd_N";
  columns.travel_scale = 1e-3;
  columns.from = 0.5;
  columns.to = 10;
  const ForceCurve curve = read_force_curve(file, columns);
  ASSERT_EQ(curve.at.size(), 3u);  // 0 and 15 mm are outside the range
  EXPECT_DOUBLE_EQ(curve.at[0], 0.5e-3);
  EXPECT_DOUBLE_EQ(curve.at[2], 10e-3);
  EXPECT_EQ(curve.force, (std::vector<double>{1.0, 10.0, 40.0}));
  EXPECT_EQ(curve.sd, (std::vector<double>{0.1, 0.5, 1.5}));
  EXPECT_FALSE(curve.by_step);

  columns.sd = "scatter";
  expect_input_error(
      [&] { read_force_curve(file, columns); },
      "expected a header with the columns mean_N, compression_mm or step, and scatter");
  columns.sd = "";
  columns.from = 20;
  columns.to = 30;
  expect_input_error([&] { read_force_curve(file, columns); },
                     "no row has its compression_mm between 20 and 30");
  const auto negative = dir.write("negative.csv", "travel,force,sd\n1,1,-0.5\n");
  expect_input_error([&] { read_force_curve(negative, with_sd("sd")); },
                     "line 2: expected a finite scatter of 0 or more in column 3");
}

// A small sphere (42 vertices) on supports that sink along z as a paddle
// comes down on it from above, with gravity when asked.
model::Model pressed_sphere(bool gravity, const model::FiberLaw& law) {
  model::Model m;
  m.surface = geom::icosphere(1, 0.05);
  m.material.law = law;
  m.material.surface_tension = 5.0;
  m.constraint_groups = {"resting"};
  for (int v : model::select_half_space(m.surface.V, model::parse_half_space("z <= -0.04", 3)))
    for (int a = 0; a < 3; ++a) m.constraints.push_back({v, a, a == 2 ? -0.002 : 0.0, {}, 0});
  m.paddles = {testing::paddle_on_top(m, "upper", -0.02)};
  if (gravity) m.loads = {testing::hydrostatic_load({0.0, 0.0, -9.81}, 1000.0)};
  return m;
}

// The run's paddle push (into the body) and the supports' z reaction per step,
// and its surfaces at `steps` as targets.
struct Measured {
  std::vector<double> paddle, support;
  std::vector<MeasuredStep> surfaces;
};
Measured measure(const model::Model& m, int steps, const std::vector<int>& surface_steps) {
  Measured out;
  const solve::SteppingSummary s = solve::solve_load_steps(
      m, newton(steps), [&](const solve::StepRecord& r, const Eigen::VectorXd& x) {
        out.paddle.push_back(-r.paddles[0].force.z());
        out.support.push_back(r.reactions[0].z());
        if (std::find(surface_steps.begin(), surface_steps.end(), r.step) != surface_steps.end())
          out.surfaces.push_back(
              {make_target("step " + std::to_string(r.step), model::positions(m, x), m.surface.F),
               r.step});
      });
  EXPECT_TRUE(s.success) << s.message;
  return out;
}

ForceCurve paddle_curve(const std::vector<double>& travel, const std::vector<double>& force) {
  ForceCurve c;
  c.label = "paddle curve";
  c.at = travel;
  c.force = force;
  return c;
}

// Rows between steps read the force interpolated by travel; the Jacobian of
// the force rows (Newton sensitivities of the held rows) matches central
// differences of whole runs, and the finite-difference mode agrees.
// Issue 43, "a file means one thing": a header that names a column twice
// was read from its last such column without a word (step,travel,force,force
// fitted the second force column).
TEST(AFileMeansOneThing, AForceCurveHeaderNamingAColumnTwiceIsRefused) {
  testing::ScratchDir dir;
  for (const char* header : {"step,travel,force,force", "travel,travel,force", "force,step,step",
                             "time,force,time,travel"}) {
    const auto file = dir.write("twice.csv", std::string(header) + "\n1,2,3,4\n");
    expect_input_error([&] { read_force_curve(file); }, "line 1: the header names");
    expect_input_error([&] { read_force_curve(file); }, "twice (columns");
  }
  // Empty cells are not names: "travel,,force" is one travel, one force.
  EXPECT_EQ(read_force_curve(dir.write("gap.csv", "travel,,force\n1,,2\n")).force[0], 2.0);
}

TEST(ForceCurve, ItsResidualsAndJacobianMatchTheRunAndFiniteDifferences) {
  const model::Model m = pressed_sphere(true, model::FiberLaw::exponential(3000.0, 5.0));
  const Measured truth = measure(m, 4, {4});
  // The paddle travels 5 mm a step: 7.5 mm lies halfway between steps 1 and 2.
  ForceCurve paddle = paddle_curve({0.0, 0.0075, 0.02}, {0.0, 1.0, 2.0});
  ForceCurve support;
  support.label = "support curve";
  support.source = ForceCurve::Source::Support;
  support.axis = 2;
  support.by_step = true;
  support.at = {2, 4};
  support.force = {0.5, 1.5};
  support.weight = 0.01;
  // Travel by the schedules: the paddle's distance from its start, the
  // supports' mean held displacement (they sink 2 mm along z, not along x).
  EXPECT_NEAR(curve_travel(paddle, m, 1, 4), 0.005, 1e-15);
  EXPECT_NEAR(curve_travel(support, m, 2, 4), -0.001, 1e-15);
  EXPECT_NEAR(curve_travel(support, m, 4, 4), -0.002, 1e-15);
  ForceCurve sideways = support;
  sideways.axis = 0;
  EXPECT_EQ(curve_travel(sideways, m, 4, 4), 0.0);
  const std::vector<Parameter> parameters = {parameter("Y0", 2500.0), parameter("beta", 4.0, false),
                                             parameter("gamma", 7.0)};
  const Calibration c(m, newton(4), truth.surfaces, parameters, {}, {paddle, support});
  EXPECT_TRUE(c.analytic_jacobian());
  EXPECT_DOUBLE_EQ(c.force_weight(0), c.body_length() / 2.0);  // the default: length / largest
  EXPECT_DOUBLE_EQ(c.force_weight(1), 0.01);
  EXPECT_EQ(c.num_residuals(), 42 + 3 + 2);
  const Eigen::VectorXd phi = c.parameters().initial_phi();
  const Evaluation e = c.evaluate(phi, true);
  ASSERT_TRUE(e.ok) << e.message;
  // At the truth's parameters the rows read the truth's forces.
  const Calibration at_truth(
      m, newton(4), truth.surfaces,
      {parameter("Y0", 3000.0), parameter("beta", 5.0, false), parameter("gamma", 5.0)}, {},
      {paddle, support});
  const Evaluation t = at_truth.evaluate(at_truth.parameters().initial_phi(), false);
  ASSERT_TRUE(t.ok) << t.message;
  EXPECT_EQ(t.forces[0][0], 0.0);
  EXPECT_NEAR(t.forces[0][1], 0.5 * (truth.paddle[0] + truth.paddle[1]), 1e-12);
  EXPECT_NEAR(t.forces[0][2], truth.paddle[3], 1e-12);
  EXPECT_NEAR(t.forces[1][1], truth.support[3], 1e-12);
  EXPECT_NEAR(t.residuals[42 + 1], at_truth.force_weight(0) * (t.forces[0][1] - 1.0), 1e-15);
  for (int k = 0; k < phi.size(); ++k) {
    const double h = 1e-6;
    Eigen::VectorXd plus = phi, minus = phi;
    plus[k] += h;
    minus[k] -= h;
    const Eigen::VectorXd fd =
        (c.evaluate(plus, false).residuals - c.evaluate(minus, false).residuals) / (2.0 * h);
    const Eigen::VectorXd forces = fd.tail(5), analytic = e.jacobian.col(k).tail(5);
    EXPECT_GT(forces.norm(), 0.0);
    EXPECT_LT((analytic - forces).norm(), 1e-5 * forces.norm())
        << c.parameters().parameters()[static_cast<size_t>(k)].name;
  }
  FitOptions differences;
  differences.finite_differences = true;
  const Calibration by_differences(m, newton(4), truth.surfaces, parameters, differences,
                                   {paddle, support});
  const Evaluation d = by_differences.evaluate(phi, true);
  ASSERT_TRUE(d.ok) << d.message;
  EXPECT_LT((d.jacobian.bottomRows(5) - e.jacobian.bottomRows(5)).norm(),
            1e-6 * e.jacobian.bottomRows(5).norm());
}

TEST(ForceCurve, ACurveTheRunCannotPlaceIsNamed) {
  const model::Model m = pressed_sphere(false, model::FiberLaw::constant(3000.0));
  const std::vector<Parameter> y = {parameter("Y", 2000.0)};
  auto build = [&](const model::Model& model, const ForceCurve& curve) {
    return [=] { Calibration(model, newton(4), {}, y, {}, {curve}); };
  };
  expect_input_error(build(m, paddle_curve({0.0, 0.03}, {0.0, 1.0})),
                     "paddle curve: row 2: travel 0.03 m is outside the run's, from 0 to 0.02 m");
  expect_input_error(build(m, paddle_curve({-0.001}, {1.0})), "row 1: travel -0.001 m is outside");
  ForceCurve step = paddle_curve({5}, {1.0});
  step.by_step = true;
  expect_input_error(build(m, step), "row 1: step 5 is not one of the run's steps 1..4");
  expect_input_error(build(m, paddle_curve({0.01}, {0.0})),
                     "every measured force is 0: give the curve a weight");
  model::Model up_down = m;
  up_down.paddles[0].schedule.kind = model::Schedule::Kind::UpDown;
  expect_input_error(build(up_down, paddle_curve({0.01}, {1.0})),
                     "the travel does not move on with every step (step 3");
  ForceCurve missing = paddle_curve({0.01}, {1.0});
  missing.index = 1;
  expect_input_error(build(m, missing), "paddle 1 does not exist (the model has 1)");
  ForceCurve sideways = missing;
  sideways.source = ForceCurve::Source::Support;
  sideways.index = 0;
  sideways.axis = 2;
  sideways.by_step = true;
  sideways.at = {1};
  model::Model held_in_x = m;
  for (model::Constraint& constraint : held_in_x.constraints) constraint.axis = 0;
  expect_input_error(build(held_in_x, sideways), "support resting holds no vertex along axis z");
  expect_input_error([&] { Calibration(m, newton(4), {}, y, {}, {}); },
                     "nothing to fit to: no target surface and no force curve");
}

// Under paddles alone (no weight) the shape depends on Y and gamma only
// through their ratio: a surface fit is not identifiable and says which
// parameters it cannot tell apart. The force curve fixes the scale: the
// same fit with it recovers both.
TEST(ForceCurve, APaddlesOnlySurfaceFitCannotTellYFromGammaAndTheForceCurveCan) {
  const model::Model m = pressed_sphere(false, model::FiberLaw::constant(3000.0));
  const Measured truth = measure(m, 4, {4});
  const std::vector<Parameter> start = {parameter("Y", 6000.0), parameter("gamma", 2.0)};
  const FitResult shapes = Calibration(m, newton(4), truth.surfaces, start).run();
  EXPECT_EQ(shapes.status, FitStatus::NotIdentifiable) << to_string(shapes.status);
  EXPECT_NE(shapes.status_detail.find("cannot tell \"Y\", \"gamma\" apart"), std::string::npos)
      << shapes.status_detail;
  const ForceCurve curve =
      paddle_curve({0.005, 0.01, 0.015, 0.02},
                   {truth.paddle[0], truth.paddle[1], truth.paddle[2], truth.paddle[3]});
  const FitResult both = Calibration(m, newton(4), truth.surfaces, start, {}, {curve}).run();
  ASSERT_EQ(both.status, FitStatus::Converged) << both.message << both.status_detail;
  EXPECT_NEAR(both.values[0] / 3000.0, 1.0, 1e-6);
  EXPECT_NEAR(both.values[1] / 5.0, 1.0, 1e-6);
  ASSERT_EQ(both.force_misfits.size(), 1u);
  EXPECT_LT(both.force_misfits[0].rms, 1e-8 * both.force_misfits[0].scale);
  EXPECT_DOUBLE_EQ(both.force_misfits[0].scale, truth.paddle[3]);
  // The force curve alone fixes the scale too, and the ratio with it.
  const FitResult force_only = Calibration(m, newton(4), {}, start, {}, {curve}).run();
  ASSERT_EQ(force_only.status, FitStatus::Converged) << force_only.status_detail;
  EXPECT_NEAR(force_only.values[0] / 3000.0, 1.0, 1e-5);
  EXPECT_EQ(force_only.overall.count, 0);
}

// Friction is fitted like a material parameter (issue 58): a Coulomb
// paddle's coefficient from the force it pushes with, by finite differences
// of whole runs (where a vertex sticks depends on the way there). Fitting it
// where no paddle has Coulomb contact is refused.
TEST(ForceCurve, TheFrictionAtAPaddleIsFittedFromItsForce) {
  model::Model m = pressed_sphere(false, model::FiberLaw::constant(3000.0));
  m.paddles[0].contact = model::Paddle::Contact::Coulomb;
  m.material.friction = 0.08;
  solve::SteppingOptions stepping = newton(4);
  stepping.newton.friction_tolerance = 1e-9;  // finite differences read it
  const solve::SteppingSummary run = solve::solve_load_steps(m, stepping);
  ASSERT_TRUE(run.success) << run.message;
  std::vector<double> force;
  for (const solve::StepRecord& r : run.steps) force.push_back(-r.paddles[0].force.z());
  ASSERT_GT(run.steps.back().paddles[0].sliding, 0);  // friction is felt, not a stick
  const ForceCurve curve = paddle_curve({0.005, 0.01, 0.015, 0.02}, force);
  Parameter friction = parameter("friction", 0.02, false);
  friction.upper = 0.3;
  const FitResult fitted =
      Calibration(m, stepping, {}, {parameter("Y", 3000.0), friction}, {}, {curve}).run();
  ASSERT_TRUE(fitted.success) << fitted.message << fitted.status_detail;
  EXPECT_NEAR(fitted.values[1], 0.08, 2e-3);
  EXPECT_NEAR(fitted.values[0] / 3000.0, 1.0, 1e-4);

  model::Model frictionless = m;
  frictionless.paddles[0].contact = model::Paddle::Contact::Frictionless;
  expect_input_error(
      [&] { Calibration(frictionless, stepping, {}, {friction}, {}, {curve}).run(); },
      "no paddle has \"contact\": \"coulomb\"");
}

// Fits that go straight (issue 58). With every modulus and gamma times s a
// body moved by paddles alone has every force times s: the start's own run
// gives s, and from a start ten times too soft in both the fit starts at the
// truth. An exponent between bounds moves by at most 5% of its range a step.
TEST(ForceCurve, TheStartIsScaledToItsSmallLoadForcesAndEveryStepIsBounded) {
  const model::Model m = pressed_sphere(false, model::FiberLaw::exponential(3000.0, 5.0));
  const Measured truth = measure(m, 4, {});
  const ForceCurve curve =
      paddle_curve({0.005, 0.01, 0.015, 0.02},
                   {truth.paddle[0], truth.paddle[1], truth.paddle[2], truth.paddle[3]});
  const std::vector<Parameter> soft = {parameter("Y0", 300.0), parameter("beta", 5.0, false),
                                       parameter("gamma", 0.5)};
  const FitResult scaled = Calibration(m, newton(4), {}, soft, {}, {curve}).run();
  ASSERT_TRUE(scaled.success) << scaled.message;
  EXPECT_NE(scaled.start_note.find("scaled by 10"), std::string::npos) << scaled.start_note;
  ASSERT_FALSE(scaled.iterations.empty());
  EXPECT_NEAR(scaled.iterations.front().values[0] / 3000.0, 1.0, 1e-9);  // iteration 0
  EXPECT_NEAR(scaled.iterations.front().values[2] / 5.0, 1.0, 1e-9);
  EXPECT_LT(scaled.iterations.front().cost, 1e-16);
  FitOptions unscaled;
  unscaled.scale_start = false;
  const FitResult plain = Calibration(m, newton(4), {}, soft, unscaled, {curve}).run();
  EXPECT_TRUE(plain.start_note.empty());
  EXPECT_NEAR(plain.iterations.front().values[0], 300.0, 1e-9);
  EXPECT_GT(plain.forward_runs, scaled.forward_runs);

  // beta in [-10, 10] from 0: no step moves it by more than 1 (5% of 20).
  Parameter beta = parameter("beta", 0.0, false);
  beta.lower = -10.0;
  beta.upper = 10.0;
  const FitResult boxed =
      Calibration(m, newton(4), {}, {parameter("Y0", 3000.0), beta}, {}, {curve}).run();
  ASSERT_TRUE(boxed.success) << boxed.message;
  EXPECT_NEAR(boxed.values[1], 5.0, 1e-4);
  double from = 0.0;
  for (const IterationRecord& it : boxed.iterations) {
    EXPECT_LE(std::abs(it.values[1] - from), 1.0 + 1e-12) << "iteration " << it.iteration;
    from = it.values[1];
  }
  EXPECT_GE(boxed.iterations.size(), 6u);  // five steps of at most 1 to reach 5
  FitOptions bad;
  bad.max_step_share = 0.0;
  EXPECT_THROW(check_options(bad), InputError);
}

// misfit: relative: each row's miss as a share of its own force, a share of
// 1 weighing what the largest force's whole miss weighs in newtons.
TEST(ForceCurve, ARelativeMisfitWeighsEachRowByItsOwnForce) {
  const model::Model m = pressed_sphere(true, model::FiberLaw::exponential(3000.0, 5.0));
  const Measured truth = measure(m, 4, {4});
  const std::vector<Parameter> parameters = {parameter("Y0", 2500.0),
                                             parameter("beta", 4.0, false)};
  ForceCurve newtons = paddle_curve({0.0075, 0.02}, {1.0, 4.0});
  ForceCurve relative = newtons;
  relative.relative = true;
  const Calibration a(m, newton(4), truth.surfaces, parameters, {}, {newtons});
  const Calibration r(m, newton(4), truth.surfaces, parameters, {}, {relative});
  const Eigen::VectorXd phi = a.parameters().initial_phi();
  const Evaluation ea = a.evaluate(phi, true), er = r.evaluate(phi, true);
  ASSERT_TRUE(ea.ok && er.ok);
  const Eigen::Index first = a.num_residuals() - 2;
  for (Eigen::Index row = 0; row < 2; ++row) {
    const double factor = 4.0 / newtons.force[static_cast<size_t>(row)];  // largest / own
    EXPECT_NEAR(er.residuals[first + row], factor * ea.residuals[first + row], 1e-14);
    for (Eigen::Index k = 0; k < phi.size(); ++k)
      EXPECT_NEAR(er.jacobian(first + row, k), factor * ea.jacobian(first + row, k),
                  1e-12 * std::abs(er.jacobian(first + row, k)) + 1e-15);
  }
  relative.force[0] = 0.0;
  expect_input_error([&] { Calibration(m, newton(4), truth.surfaces, parameters, {}, {relative}); },
                     "row 1: a measured force of 0 has no relative misfit");
}

// The misfit's verdict: noise or the model's form. A runs test on the signs
// (Wald and Wolfowitz: R runs of n1 and n2 signs, mean 1 + 2 n1 n2 / n,
// variance (mean - 1)(mean - 2) / (n - 1)) and the measurement's scatter.
TEST(ForceCurve, AMisfitThatRunsInLongStretchesOrExceedsTheScatterIsSystematic) {
  ForceCurve curve;
  for (int r = 0; r < 12; ++r) {
    curve.at.push_back(1e-3 * (r + 1));
    curve.force.push_back(10.0 * (r + 1));
    curve.sd.push_back(0.5);
  }
  const auto simulated = [&](const std::function<double(int)>& miss) {
    std::vector<double> s;
    for (int r = 0; r < 12; ++r) s.push_back(curve.force[static_cast<size_t>(r)] + miss(r));
    return s;
  };
  // Alternating signs of 0.2 N: 12 runs where chance gives 7, within the scatter.
  const ForceMisfit noise =
      force_misfit(curve, simulated([](int r) { return r % 2 ? 0.2 : -0.2; }), 1);
  EXPECT_EQ(noise.runs, 12);
  EXPECT_DOUBLE_EQ(noise.runs_expected, 7.0);
  EXPECT_NEAR(noise.runs_z, 5.0 / std::sqrt(6.0 * 5.0 / 11.0), 1e-12);
  EXPECT_DOUBLE_EQ(noise.scatter, 0.5);
  EXPECT_NEAR(noise.rms, 0.2, 1e-12);
  EXPECT_FALSE(noise.systematic) << noise.verdict;
  EXPECT_NE(noise.verdict.find("as noise"), std::string::npos) << noise.verdict;

  // Six over, then six under: 2 runs, z = -5 / sqrt(30 / 11).
  const ForceMisfit bowed =
      force_misfit(curve, simulated([](int r) { return r < 6 ? 0.2 : -0.2; }), 1);
  EXPECT_EQ(bowed.runs, 2);
  EXPECT_NEAR(bowed.runs_z, -5.0 / std::sqrt(30.0 / 11.0), 1e-12);
  EXPECT_TRUE(bowed.systematic);
  EXPECT_NE(bowed.verdict.find("2 runs where random signs would give 7"), std::string::npos)
      << bowed.verdict;
  EXPECT_NE(bowed.verdict.find("the model's form, not the data's noise"), std::string::npos);

  // Alternating, but four times the scatter.
  const ForceMisfit large =
      force_misfit(curve, simulated([](int r) { return r % 2 ? 2.0 : -2.0; }), 1);
  EXPECT_TRUE(large.systematic);
  EXPECT_NE(large.verdict.find("4 times the measurement's scatter"), std::string::npos)
      << large.verdict;
  // Relative: each miss over its force, 2 / (10 (r + 1)).
  double squares = 0.0;
  for (int r = 0; r < 12; ++r) squares += std::pow(2.0 / (10.0 * (r + 1)), 2);
  EXPECT_NEAR(large.rms_relative, std::sqrt(squares / 12.0), 1e-15);

  // One side only: systematic whatever the runs' statistics.
  const ForceMisfit above = force_misfit(curve, simulated([](int) { return 0.1; }), 1);
  EXPECT_TRUE(above.systematic);
  EXPECT_NE(above.verdict.find("every row misses on one side"), std::string::npos);
  // Without a scatter and with few rows there is no verdict to give.
  ForceCurve short_curve = curve;
  short_curve.sd.clear();
  short_curve.at.resize(5);
  short_curve.force.resize(5);
  const ForceMisfit few = force_misfit(short_curve, {1, 2, 3, 4, 5}, 1);
  EXPECT_FALSE(few.systematic);
  EXPECT_TRUE(std::isnan(few.scatter));
  EXPECT_NE(few.verdict.find("too few rows"), std::string::npos) << few.verdict;
}

}  // namespace
}  // namespace fiberfluid::fit
