// SPDX-License-Identifier: GPL-3.0-or-later
// The Newton scheme: the linear limit, quadratic convergence, path
// independence, step cutting, contact with paddles, and its failures.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/geom/horizon.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/equilibrium.hpp"
#include "fiberfluid/solve/stepping.hpp"
#include "fiberfluid/solve/tangent/tangent_solve.hpp"
#include "model/model_fixtures.hpp"

namespace fiberfluid::solve {
namespace {

// The paper's sphere (162 vertices, cap held) under gravity alone.
model::Model hanging_sphere(const model::FiberLaw& law, double density = 300.0) {
  model::Model m = testing::paper_sphere_model();
  m.material.law = law;
  m.loads.resize(1);  // gravity only
  m.loads[0].density = density;
  return m;
}

SteppingOptions newton(int steps, TangentSolver tangent = TangentSolver::Dense) {
  SteppingOptions o;
  o.scheme = Scheme::Newton;
  o.steps = steps;
  o.newton.tangent = tangent;
  return o;
}

double displacement_norm(const model::Model& m, const Eigen::VectorXd& x) {
  return x.head(m.num_unknowns() - 1).norm();
}

TEST(Newton, TendsToTheLinearSolutionAsTheLoadShrinks) {
  // The difference is second order in the load: halving the load quarters it.
  std::vector<double> differences;
  for (double density : {40.0, 20.0, 10.0}) {
    const model::Model m = hanging_sphere(model::FiberLaw::constant(3000.0), density);
    SteppingOptions linear;
    linear.steps = 1;
    const SteppingSummary a = solve_load_steps(m, linear);
    const SteppingSummary b = solve_load_steps(m, newton(1));
    ASSERT_TRUE(a.success && b.success) << a.message << b.message;
    differences.push_back(displacement_norm(m, a.unknowns - b.unknowns));
    EXPECT_LT(differences.back(), 0.05 * displacement_norm(m, a.unknowns));
  }
  for (size_t k = 1; k < differences.size(); ++k)
    EXPECT_NEAR(differences[k - 1] / differences[k], 4.0, 0.3) << k;
}

TEST(Newton, ConvergesQuadratically) {
  for (const model::FiberLaw& law :
       {model::FiberLaw::constant(3000.0), model::FiberLaw::exponential(3000.0, 5.0)}) {
    const model::Model m = hanging_sphere(law);
    SteppingOptions o = newton(1);
    o.newton.residual_tolerance = 1e-14;
    const SteppingSummary s = solve_load_steps(m, o);
    ASSERT_TRUE(s.success) << s.message;
    const std::vector<double>& r = s.steps[0].residual_norms;
    ASSERT_GE(r.size(), 4u);
    // Once in the basin, each residual is about the square of the one before.
    int quadratic = 0;
    for (size_t k = 1; k < r.size(); ++k)
      if (r[k - 1] < 1e-2 && r[k] > 1e-12) {  // above the rounding floor
        EXPECT_LT(r[k], 50.0 * r[k - 1] * r[k - 1]) << law.name() << " iteration " << k;
        ++quadratic;
      }
    EXPECT_GE(quadratic, 1) << law.name();
    EXPECT_LT(r.back(), 1e-11);
    EXPECT_EQ(s.steps[0].line_search_halvings, 0);
  }
}

TEST(Newton, RoundTripReturnsToTheStartForAnyStepCount) {
  for (int n : {2, 10, 100}) {
    model::Model m = hanging_sphere(model::FiberLaw::exponential(3000.0, 5.0));
    m.loads[0].schedule.kind = model::Schedule::Kind::UpDown;
    const SteppingSummary s = solve_load_steps(m, newton(n));
    ASSERT_TRUE(s.success) << s.message;
    const double peak = s.steps[static_cast<size_t>(n / 2 - 1)].max_displacement;
    EXPECT_GT(peak, 0.05);
    EXPECT_LT(s.steps.back().max_displacement, 1e-9 * peak) << n;
  }
}

TEST(Newton, KrylovAgreesWithTheDenseTangent) {
  const model::Model m = hanging_sphere(model::FiberLaw::exponential(3000.0, 5.0));
  const SteppingSummary dense = solve_load_steps(m, newton(2, TangentSolver::Dense));
  for (SolverKind preconditioner : {SolverKind::BlockCholesky, SolverKind::Cholmod}) {
    SteppingOptions o = newton(2, TangentSolver::Krylov);
    o.solver = preconditioner;
    const SteppingSummary krylov = solve_load_steps(m, o);
    ASSERT_TRUE(dense.success && krylov.success) << dense.message << krylov.message;
    EXPECT_EQ(krylov.solver, preconditioner);
    EXPECT_GT(krylov.krylov_iterations, 0);
    EXPECT_LT(displacement_norm(m, krylov.unknowns - dense.unknowns),
              1e-8 * displacement_norm(m, dense.unknowns));
  }
}

// Issue 25: the paddle contacts the tangent holds beyond the supports are
// held in the preconditioner's solve by a capacitance correction. It must be
// the solve of the preconditioner factored with them held: GMRES takes the
// same iterations to the same answer, for block Cholesky and CHOLMOD alike.
TEST(Newton, ContactsHeldByCapacitanceGiveTheirOwnFactorisationsPreconditioner) {
  const model::Model m = hanging_sphere(model::FiberLaw::exponential(3000.0, 5.0));
  const auto equilibrium = std::make_shared<const model::Equilibrium>(m);
  const model::DofMap supports = model::DofMap::from_constraints(m);
  std::vector<int> contacts;  // the lowest ten vertices, held along z as on a paddle
  std::vector<int> order(static_cast<size_t>(m.num_vertices()));
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return m.surface.V(a, 2) < m.surface.V(b, 2); });
  for (int k = 0; k < 10; ++k)
    contacts.push_back(2 * m.num_vertices() + order[static_cast<size_t>(k)]);
  const model::DofMap held = supports.with_held(contacts);
  const Eigen::VectorXd x = 1e-3 * Eigen::VectorXd::Random(m.num_unknowns());
  const std::vector<double> factors(m.loads.size(), 1.0);
  const Eigen::VectorXd b = Eigen::VectorXd::Random(held.num_reduced());
  for (SolverKind preconditioner : {SolverKind::BlockCholesky, SolverKind::Cholmod}) {
    SteppingOptions o = newton(1, TangentSolver::Krylov);
    o.solver = preconditioner;
    const auto corrected = make_tangent_solve(equilibrium, o, TangentSolver::Krylov);
    const auto factored = make_tangent_solve(equilibrium, o, TangentSolver::Krylov);
    ASSERT_TRUE(corrected->prepare(x, factors, held, &supports).ok);
    ASSERT_TRUE(factored->prepare(x, factors, held, nullptr).ok);
    Eigen::VectorXd y_corrected, y_factored;
    int corrected_iterations = 0, factored_iterations = 0;
    ASSERT_TRUE(corrected->solve(b, 1e-10, &y_corrected, &corrected_iterations).ok);
    ASSERT_TRUE(factored->solve(b, 1e-10, &y_factored, &factored_iterations).ok);
    EXPECT_EQ(corrected_iterations, factored_iterations) << to_string(preconditioner);
    EXPECT_LT((y_corrected - y_factored).norm(), 1e-8 * y_factored.norm());
    EXPECT_EQ(corrected->factorizations(), 1);
  }
  // Held sets that wander (100 unknowns at a time, 700 in all: the cache of
  // solves drops those no longer held) keep the correction exact.
  SteppingOptions o = newton(1, TangentSolver::Krylov);
  o.solver = SolverKind::BlockCholesky;
  const auto wandering = make_tangent_solve(equilibrium, o, TangentSolver::Krylov);
  std::vector<int> free_dofs;
  for (int d = 0; d < 3 * m.num_vertices(); ++d)
    if (!supports.held(d)) free_dofs.push_back(d);
  ASSERT_GE(free_dofs.size(), 400u);
  for (size_t start = 0; start < 700; start += 100) {
    std::vector<int> set;
    for (size_t k = 0; k < 100; ++k) set.push_back(free_dofs[(start + k) % free_dofs.size()]);
    const model::DofMap moved = supports.with_held(set);
    const Eigen::VectorXd c = Eigen::VectorXd::Random(moved.num_reduced());
    ASSERT_TRUE(wandering->prepare(x, factors, moved, &supports).ok);
    const auto factored = make_tangent_solve(equilibrium, o, TangentSolver::Krylov);
    ASSERT_TRUE(factored->prepare(x, factors, moved, nullptr).ok);
    Eigen::VectorXd y_wandering, y_factored;
    int wandering_iterations = 0, factored_iterations = 0;
    ASSERT_TRUE(wandering->solve(c, 1e-10, &y_wandering, &wandering_iterations).ok);
    ASSERT_TRUE(factored->solve(c, 1e-10, &y_factored, &factored_iterations).ok);
    EXPECT_EQ(wandering_iterations, factored_iterations) << start;
    EXPECT_LT((y_wandering - y_factored).norm(), 1e-8 * y_factored.norm()) << start;
  }
  EXPECT_EQ(wandering->factorizations(), 1);
}

// Issue 25: the line search's residual stores the tangent at its trial, which
// becomes the next iterate: one pass over the pairs per Newton iteration
// (and one per Newton solve's start), not two, and the same bits as
// linearising again.
TEST(Newton, EachIterationGoesOverThePairsOnce) {
  const model::Model m = hanging_sphere(model::FiberLaw::exponential(3000.0, 5.0));
  SteppingOptions o = newton(3, TangentSolver::Krylov);
  o.solver = SolverKind::BlockCholesky;
  const SteppingSummary run = solve_load_steps(m, o);
  ASSERT_TRUE(run.success) << run.message;
  for (const StepRecord& step : run.steps) {
    SCOPED_TRACE(step.step);
    EXPECT_EQ(step.line_search_halvings, 0);
    EXPECT_EQ(step.pair_passes.computed, step.newton_iterations + 1);
    EXPECT_GE(step.pair_passes.stored, step.krylov_iterations);
  }
  // The operator stored by the residual is the one linearize builds.
  const model::Equilibrium eq(m);
  const Eigen::VectorXd x = run.unknowns, v = Eigen::VectorXd::Random(x.size());
  const std::vector<double> factors = {0.8};
  model::TangentOperator stored;
  const Eigen::VectorXd R = eq.residual(x, factors, stored);
  EXPECT_EQ(R, eq.residual(x, factors));
  EXPECT_EQ(stored.apply(v), eq.linearize(x, factors).apply(v));
  const model::PairPasses before = model::pair_passes();
  eq.linearize(x, factors, stored);  // held already: no pass
  EXPECT_EQ((model::pair_passes() - before).computed, 0);
}

// The summary's final tangent gives the sensitivity of the solution to a
// material parameter, du/dtheta = -K_T^{-1} dR/dtheta: against central
// differences of whole Newton runs, with the dense and the krylov tangent.
TEST(Newton, FinalTangentGivesParameterSensitivities) {
  const model::Model m = hanging_sphere(model::FiberLaw::exponential(3000.0, 5.0));
  for (TangentSolver kind : {TangentSolver::Dense, TangentSolver::Krylov}) {
    SteppingOptions o = newton(2, kind);
    o.newton.residual_tolerance = 1e-13;
    o.keep_final_tangent = true;
    const SteppingSummary s = solve_load_steps(m, o);
    ASSERT_TRUE(s.success) << s.message;
    ASSERT_TRUE(s.final_tangent);
    for (const std::string name : {"beta", "gamma"}) {
      const Eigen::VectorXd dR = model::Equilibrium(m).parameter_derivatives(s.unknowns, {name});
      Eigen::VectorXd du;
      ASSERT_TRUE(s.final_tangent->solve_full(-dR, &du).ok);
      auto solve_with = [&](double delta) {
        model::Model changed = m;
        if (name == "gamma")
          changed.material.surface_tension += delta;
        else
          changed.material.law.set_parameter(name, 5.0 + delta);
        SteppingOptions plain = newton(2);
        plain.newton.residual_tolerance = 1e-13;
        return solve_load_steps(changed, plain).unknowns;
      };
      const double h = name == "gamma" ? 1.0 : 1e-3;
      const Eigen::VectorXd fd = (solve_with(h) - solve_with(-h)) / (2.0 * h);
      EXPECT_LT((du - fd).norm(), 1e-5 * fd.norm()) << name << " " << to_string(kind);
    }
  }
}

// The stepper's own sensitivities at an intermediate step and the last, for
// every kind of parameter, against central differences of whole runs.
TEST(Newton, SensitivitiesAtChosenStepsMatchFiniteDifferences) {
  const model::Model m = hanging_sphere(model::FiberLaw::exponential(3000.0, 5.0));
  const std::vector<std::string> names = {"Y0", "beta", "gamma", "factor_z"};
  // Central differences of whole runs, at steps 2 and 3, per parameter.
  std::vector<std::vector<Eigen::VectorXd>> fd(names.size());
  for (size_t p = 0; p < names.size(); ++p) {
    auto states_with = [&](double delta) {
      model::Model changed = m;
      if (names[p] == "gamma")
        changed.material.surface_tension += delta;
      else if (names[p] == "factor_z")
        changed.material.axis_factors.z() += delta;
      else
        changed.material.law.set_parameter(names[p],
                                           changed.material.law.parameter(names[p]) + delta);
      SteppingOptions plain = newton(3);
      plain.newton.residual_tolerance = 1e-13;
      std::vector<Eigen::VectorXd> states;
      const SteppingSummary run = solve_load_steps(
          changed, plain,
          [&](const StepRecord&, const Eigen::VectorXd& x) { states.push_back(x); });
      EXPECT_TRUE(run.success) << run.message;
      return states;
    };
    const double h = names[p] == "Y0" || names[p] == "gamma" ? 1.0 : 1e-3;
    const auto plus = states_with(h), minus = states_with(-h);
    for (int step : {2, 3}) fd[p].push_back((plus[step - 1] - minus[step - 1]) / (2.0 * h));
  }
  for (TangentSolver kind : {TangentSolver::Dense, TangentSolver::Krylov}) {
    SteppingOptions o = newton(3, kind);
    o.newton.residual_tolerance = 1e-13;
    o.sensitivities = {names, {2, 3}};
    const SteppingSummary s = solve_load_steps(m, o);
    ASSERT_TRUE(s.success) << s.message;
    EXPECT_EQ(s.steps[0].sensitivities.state.size(), 0);
    for (size_t p = 0; p < names.size(); ++p)
      for (int step : {2, 3}) {
        const Eigen::VectorXd& expected = fd[p][static_cast<size_t>(step - 2)];
        const Eigen::VectorXd du = s.steps[static_cast<size_t>(step - 1)].sensitivities.state.col(
            static_cast<Eigen::Index>(p));
        EXPECT_LT((du - expected).norm(), 1e-6 * expected.norm())
            << names[p] << " step " << step << " " << to_string(kind);
      }
  }
  // Asked of the incremental scheme, for an unknown name or a step beyond the run: a message.
  SteppingOptions bad = newton(2);
  bad.sensitivities = {{"stiffness"}, {2}};
  EXPECT_NE(solve_load_steps(m, bad).message.find("\"stiffness\" is not a parameter"),
            std::string::npos);
  bad.sensitivities = {{"beta"}, {3}};
  EXPECT_NE(solve_load_steps(m, bad).message.find("expected 1..2"), std::string::npos);
  bad.scheme = Scheme::Incremental;
  bad.sensitivities.steps = {2};
  EXPECT_NE(solve_load_steps(m, bad).message.find("need the Newton scheme"), std::string::npos);
}

TEST(Newton, CutsAStepThatFailsAndStillSucceeds) {
  // A heavy load in one step: from the start, Newton needs seven iterations;
  // allowed four, the step is cut, and its pieces converge; an easy piece
  // lets the next one grow.
  const model::Model m = hanging_sphere(model::FiberLaw::exponential(3000.0, 5.0), 1000.0);
  SteppingOptions o = newton(1);
  o.newton.max_iterations = 4;
  const SteppingSummary s = solve_load_steps(m, o);
  ASSERT_TRUE(s.success) << s.message;
  ASSERT_GE(s.steps[0].step_cuts, 2);
  // After the hard start the pieces grow again: fewer than the 2^cuts pieces
  // of the deepest halving (here a quarter, then a half, then the rest).
  EXPECT_LT(s.steps[0].pieces, 1 << s.steps[0].step_cuts);
  // The same answer as an uncut run with enough iterations.
  const SteppingSummary reference = solve_load_steps(m, newton(1));
  ASSERT_TRUE(reference.success) << reference.message;
  EXPECT_LT(displacement_norm(m, s.unknowns - reference.unknowns),
            1e-7 * displacement_norm(m, reference.unknowns));
  // And with no cuts allowed it fails, naming the step and the option.
  o.newton.max_step_cuts = 0;
  const SteppingSummary failed = solve_load_steps(m, o);
  EXPECT_FALSE(failed.success);
  EXPECT_NE(failed.message.find("step 1: newton: no convergence"), std::string::npos)
      << failed.message;
  EXPECT_NE(failed.message.find("newton.max_step_cuts"), std::string::npos);
}

// Adaptive stepping: the pieces a step ended with are where the next step
// starts, so a hard stretch of the path is not entered with a whole step
// (and its failure) at every step; easy pieces grow back.
TEST(Newton, ThePiecesCarryFromStepToStep) {
  const model::Model m = hanging_sphere(model::FiberLaw::exponential(3000.0, 5.0), 1200.0);
  SteppingOptions o = newton(2);
  o.newton.max_iterations = 5;
  const SteppingSummary s = solve_load_steps(m, o);
  ASSERT_TRUE(s.success) << s.message;
  ASSERT_GE(s.steps[0].step_cuts, 1);
  // Step 1 is cut once, and its second half is not easy; step 2 starts in
  // halves: two pieces, no cut of its own (without the carry: a failed whole
  // step first, then the same halves).
  EXPECT_LT(s.steps[1].step_cuts, s.steps[0].step_cuts);
  EXPECT_GT(s.steps[1].pieces, 1);
  const SteppingSummary reference = solve_load_steps(m, newton(2));
  ASSERT_TRUE(reference.success) << reference.message;
  EXPECT_LT(displacement_norm(m, s.unknowns - reference.unknowns),
            1e-7 * displacement_norm(m, reference.unknowns));
}

TEST(Newton, ADivergingStepIsAStatusNamingTheStepWithFiniteUnknowns) {
  // Gravity a million times too strong for a stiffening law: the Newton
  // iterates leave every basin, with or without the line search, and every
  // cut piece fails too. The run stops at step 1 with the cause; the state it
  // returns is the last one reached (the start), never NaN.
  const model::Model m = hanging_sphere(model::FiberLaw::exponential(3000.0, 5.0), 1e9);
  for (bool line_search : {true, false}) {
    SteppingOptions o = newton(2);
    o.newton.line_search = line_search;
    o.newton.max_step_cuts = 2;
    const SteppingSummary s = solve_load_steps(m, o);
    ASSERT_FALSE(s.success) << line_search;
    EXPECT_EQ(s.message.rfind("step 1: ", 0), 0u) << s.message;
    // With the line search, every cut stalls at one residual (0.7068): the
    // walk stops at the third, saying why shorter pieces will not help.
    // Without it, the iterates overflow at each cut, to the last one.
    EXPECT_NE(s.message.find(line_search ? "3 cuts in a row (down to 0.25 of a step): shorter "
                                           "pieces will not help"
                                         : "the step was halved 2 times"),
              std::string::npos)
        << s.message;
    EXPECT_TRUE(s.unknowns.allFinite());
    EXPECT_TRUE(s.steps.empty());
    // Why Newton gave up is named: the line search found no decrease, or
    // (without it) the iterates overflowed. Never a false "converged": a
    // wild iterate's reactions do not raise the residual's force scale.
    const std::string why =
        line_search ? "newton: the line search found no decrease" : "the residual is not finite";
    EXPECT_NE(s.message.find(why), std::string::npos) << s.message;
  }
}

// Issue 29 (from issue 23): a tabulated law 17.5 kPa below zero strain and
// 20 kPa above stalls Newton on the paper's hanging sphere (water) near load
// factor 0.6 when sharp; the default blend over |e| < 0.005 runs to full load.
TEST(Newton, ATablesSlopeJumpAtZeroNoLongerStallsNewton) {
  const std::vector<double> strain = {-0.5, 0.0, 0.5}, stress = {-8750.0, 0.0, 10000.0};
  const SteppingSummary sharp = solve_load_steps(
      hanging_sphere(model::FiberLaw::tabulated(strain, stress, 0.0), 1000.0), newton(5));
  EXPECT_FALSE(sharp.success);
  EXPECT_NE(sharp.message.find("step 3: newton: the line search found no decrease"),
            std::string::npos)
      << sharp.message;
  const SteppingSummary smooth = solve_load_steps(
      hanging_sphere(model::FiberLaw::tabulated(strain, stress), 1000.0), newton(5));
  ASSERT_TRUE(smooth.success) << smooth.message;
  EXPECT_EQ(smooth.steps.size(), 5u);
  EXPECT_TRUE(smooth.unknowns.allFinite());
}

using testing::pressed_sphere;

TEST(Newton, PaddleContactPushesHoldsAndBalances) {
  for (bool sticking : {false, true}) {
    const model::Model m = pressed_sphere(sticking);
    const int n = m.num_vertices();
    const SteppingSummary s = solve_load_steps(m, newton(5));
    ASSERT_TRUE(s.success) << s.message;
    const StepRecord& last = s.steps.back();
    ASSERT_EQ(last.paddles.size(), 1u);
    const StepRecord::PaddleState& top = last.paddles[0];
    EXPECT_NEAR(top.plane, m.paddles[0].position - 0.3, 1e-15);
    EXPECT_GT(top.contacts, 3);
    EXPECT_LT(top.force.z(), 0.0);  // the paddle pushes down on the body
    const Eigen::MatrixXd X = model::positions(m, s.unknowns);
    EXPECT_LE(X.col(2).maxCoeff(), top.plane + 1e-12);  // nothing beyond the paddle
    // Every contact force pushes: on the top paddle, no vertex is pulled up.
    for (int v = 0; v < n; ++v) {
      if (std::abs(X(v, 2) - top.plane) < 1e-12) {
        EXPECT_LE(s.reaction_forces(v, 2), 1e-9);
      }
    }
    // Global equilibrium: supports + paddle + loads (none) = 0.
    const Eigen::Vector3d total = last.reactions[0] + top.force + last.applied_force;
    EXPECT_LT(total.norm(), 1e-8 * top.force.norm()) << "sticking " << sticking;
    // The force grows with the compression.
    for (size_t k = 1; k < s.steps.size(); ++k)
      EXPECT_LT(s.steps[k].paddles[0].force.z(), s.steps[k - 1].paddles[0].force.z());
    // Volume held by the fluid.
    EXPECT_LT(std::abs(last.volume_drift), 1e-8);
  }
}

// A warm start (a fit's previous trial point's final state) solves the end
// of the path in one piece and lands on the equilibrium the path reaches:
// on the hanging sphere, and pressed by a frictionless paddle (the contact
// set taken from the vertices on the plane). A sticking paddle, whose end
// depends on the way there, refuses one; a start that does not converge
// falls back on the path.
TEST(Newton, AWarmStartSolvesThePathsEndFromANearbyState) {
  for (const bool pressed : {false, true}) {
    model::Model m = pressed ? testing::pressed_sphere(false)
                             : hanging_sphere(model::FiberLaw::exponential(3000.0, 5.0));
    const SteppingOptions path = newton(5);
    const SteppingSummary near = solve_load_steps(m, path);
    ASSERT_TRUE(near.success) << near.message;
    for (const std::string& name : m.material.law.parameter_names())  // the next trial point
      if (name[0] == 'Y') m.material.law.set_parameter(name, 1.25 * m.material.law.parameter(name));
    m.material.surface_tension *= 0.8;
    const SteppingSummary walked = solve_load_steps(m, path);
    ASSERT_TRUE(walked.success) << walked.message;
    SteppingOptions warm = path;
    warm.warm_start = near.unknowns;
    std::vector<int> observed;
    const SteppingSummary s = solve_load_steps(
        m, warm, [&](const StepRecord& r, const Eigen::VectorXd&) { observed.push_back(r.step); });
    ASSERT_TRUE(s.success) << s.message;
    EXPECT_TRUE(s.warm_started) << "pressed " << pressed;
    EXPECT_EQ(observed, std::vector<int>{5});
    ASSERT_EQ(s.steps.size(), 1u);
    EXPECT_EQ(s.steps[0].step, 5);
    EXPECT_LT((s.unknowns - walked.unknowns).norm(), 1e-8 * walked.unknowns.norm())
        << "pressed " << pressed;
    EXPECT_LT(s.newton_iterations, walked.newton_iterations) << "pressed " << pressed;
    if (pressed) {
      EXPECT_EQ(s.steps[0].paddles[0].contacts, walked.steps.back().paddles[0].contacts);
      EXPECT_NEAR(s.steps[0].paddles[0].force.z(), walked.steps.back().paddles[0].force.z(),
                  1e-8 * std::abs(walked.steps.back().paddles[0].force.z()));
    }
    // A start from nowhere near (a thousand times the displacement) fails
    // its piece: the path is walked and gives the same answer.
    warm.warm_start = 1000.0 * near.unknowns;
    const SteppingSummary fallen_back = solve_load_steps(m, warm);
    ASSERT_TRUE(fallen_back.success) << fallen_back.message;
    EXPECT_FALSE(fallen_back.warm_started);
    EXPECT_EQ(fallen_back.steps.size(), 5u);
    EXPECT_LT((fallen_back.unknowns - walked.unknowns).norm(), 1e-8 * walked.unknowns.norm());
  }
  const model::Model sticking = testing::pressed_sphere(true);
  SteppingOptions warm = newton(5);
  warm.warm_start = Eigen::VectorXd::Zero(sticking.num_unknowns());
  const SteppingSummary refused = solve_load_steps(sticking, warm);
  EXPECT_FALSE(refused.success);
  EXPECT_NE(refused.message.find("warm_start: paddle"), std::string::npos) << refused.message;
  warm.warm_start = Eigen::VectorXd::Zero(7);
  const SteppingSummary wrong_size = solve_load_steps(testing::pressed_sphere(false), warm);
  EXPECT_FALSE(wrong_size.success);
  EXPECT_NE(wrong_size.message.find("warm_start: expected"), std::string::npos)
      << wrong_size.message;
}

// The forces' sensitivities (the paddle's and the supports' reaction, read
// off the held rows of K_T du/dtheta + dR/dtheta) against central
// differences of whole runs.
TEST(Newton, ForceSensitivitiesMatchFiniteDifferences) {
  {  // A sticking paddle holds vertices where they touched: a place that moves with the parameters.
    SteppingOptions o = newton(2);
    o.sensitivities = {{"gamma"}, {2}};
    EXPECT_NE(solve_load_steps(pressed_sphere(true), o).message.find("paddle top sticks"),
              std::string::npos);
  }
  for (bool sticking : {false}) {
    model::Model m = pressed_sphere(sticking);
    m.material.law = model::FiberLaw::exponential(3000.0, 5.0);
    for (model::Constraint& c : m.constraints)
      if (c.axis == 2) c.value = -0.05;  // the resting supports sink as the paddle comes down
    const std::vector<std::string> names = {"Y0", "beta", "gamma"};
    auto final_forces = [&](const std::string& name, double delta) {
      model::Model changed = m;
      if (name == "gamma")
        changed.material.surface_tension += delta;
      else
        changed.material.law.set_parameter(name, changed.material.law.parameter(name) + delta);
      SteppingOptions plain = newton(4);
      plain.newton.residual_tolerance = 1e-13;
      const SteppingSummary run = solve_load_steps(changed, plain);
      EXPECT_TRUE(run.success) << run.message;
      return std::make_pair(run.steps.back().paddles[0].force, run.steps.back().reactions[0]);
    };
    SteppingOptions o = newton(4);
    o.newton.residual_tolerance = 1e-13;
    o.sensitivities = {names, {4}};
    const SteppingSummary s = solve_load_steps(m, o);
    ASSERT_TRUE(s.success) << s.message;
    const StepRecord& last = s.steps.back();
    ASSERT_EQ(last.sensitivities.reactions.size(), 1u);
    for (size_t p = 0; p < names.size(); ++p) {
      const double h = names[p] == "beta" ? 1e-4 : 0.1;
      const auto plus = final_forces(names[p], h), minus = final_forces(names[p], -h);
      const Eigen::Vector3d paddle = (plus.first - minus.first) / (2.0 * h);
      const Eigen::Vector3d support = (plus.second - minus.second) / (2.0 * h);
      const auto column = static_cast<Eigen::Index>(p);
      EXPECT_GT(paddle.norm(), 0.0) << names[p];
      EXPECT_LT((last.sensitivities.paddle_forces[0].col(column) - paddle).norm(),
                1e-5 * paddle.norm())
          << names[p] << " sticking " << sticking;
      EXPECT_LT((last.sensitivities.reactions[0].col(column) - support).norm(),
                1e-5 * support.norm())
          << names[p] << " sticking " << sticking;
    }
  }
}

// The predictor (the path extrapolated to each step's guess) and the active
// set updated within Newton's iterations change the work, not the answer.
TEST(Newton, ThePredictorSavesIterationsAndKeepsTheAnswer) {
  const std::vector<std::pair<const char*, model::Model>> cases = {
      {"hanging", hanging_sphere(model::FiberLaw::exponential(3000.0, 5.0))},
      {"pressed", pressed_sphere(false)}};
  for (const auto& [name, m] : cases) {
    SteppingOptions with = newton(8), without = newton(8);
    without.newton.predictor = false;
    const SteppingSummary a = solve_load_steps(m, with), b = solve_load_steps(m, without);
    ASSERT_TRUE(a.success && b.success) << a.message << b.message;
    EXPECT_LT(displacement_norm(m, a.unknowns - b.unknowns),
              1e-9 * displacement_norm(m, b.unknowns))
        << name;
    EXPECT_LT(a.newton_iterations, b.newton_iterations) << name;
    if (!m.paddles.empty()) {
      EXPECT_EQ(a.steps.back().paddles[0].contacts, b.steps.back().paddles[0].contacts);
    }
  }
}

TEST(Newton, BadPaddlesAreRejected) {
  model::Model inside = pressed_sphere(false);
  inside.paddles[0].position = 0.5;
  SteppingSummary s = solve_load_steps(inside, newton(2));
  EXPECT_FALSE(s.success);
  EXPECT_NE(s.message.find("paddle top: it starts inside the body"), std::string::npos)
      << s.message;

  model::Model crossing = pressed_sphere(false);
  model::Paddle bottom = crossing.paddles[0];
  bottom.label = "bottom";
  bottom.above = false;
  bottom.position = -1.0;
  bottom.travel = 1.8;  // at step 2: 0.8, above the top paddle's 0.7
  crossing.paddles.push_back(bottom);
  s = solve_load_steps(crossing, newton(2));
  EXPECT_FALSE(s.success);
  EXPECT_NE(s.message.find("paddles top and bottom meet or pass each other at step 2"),
            std::string::npos)
      << s.message;

  SteppingOptions incremental;
  s = solve_load_steps(pressed_sphere(false), incremental);
  EXPECT_FALSE(s.success);
  EXPECT_NE(s.message.find("paddles need the Newton scheme"), std::string::npos) << s.message;
}

SteppingOptions arc_length(int steps) {
  SteppingOptions o = newton(steps);
  o.newton.control = NewtonOptions::Control::ArcLength;
  return o;
}

// Along a path without a limit point, arc length lands on the final load at
// the same equilibrium as load control; its steps are its own (the load
// factor is an unknown), their factors rise to exactly 1.
TEST(ArcLength, ReachesTheFinalLoadAtTheLoadControlledAnswer) {
  const model::Model m = hanging_sphere(model::FiberLaw::exponential(3000.0, 5.0), 300.0);
  const SteppingSummary by_load = solve_load_steps(m, newton(5));
  const SteppingSummary by_arc = solve_load_steps(m, arc_length(5));
  ASSERT_TRUE(by_load.success && by_arc.success) << by_load.message << by_arc.message;
  EXPECT_LT(displacement_norm(m, by_arc.unknowns - by_load.unknowns),
            1e-8 * displacement_norm(m, by_load.unknowns));
  EXPECT_NEAR(by_arc.unknowns[m.pressure_dof()], by_load.unknowns[m.pressure_dof()],
              1e-8 * std::abs(by_load.unknowns[m.pressure_dof()]));
  ASSERT_GE(by_arc.steps.size(), 2u);
  EXPECT_DOUBLE_EQ(by_arc.steps.back().load_factors[0], 1.0);
  for (size_t k = 1; k < by_arc.steps.size(); ++k)
    EXPECT_GT(by_arc.steps[k].load_factors[0], by_arc.steps[k - 1].load_factors[0]);
  EXPECT_TRUE(std::isnan(by_arc.limit_load_factor));
}

// The paper's sphere under gravity updated from the current geometry (its
// own experiment, Newton's exact equilibria): load control fails at step 9 of
// 10. Arc length shows why: the load peaks at 0.876 of full gravity (a limit
// point at 1.76 m of sag) and falls after it while the sphere stretches on.
TEST(ArcLength, ThePapersSphereHasALimitPointBelowFullGravity) {
  const model::Model m = testing::paper_sphere_model();
  const SteppingSummary s = solve_load_steps(m, arc_length(10));
  EXPECT_FALSE(s.success);
  EXPECT_NEAR(s.limit_load_factor, 0.8756, 0.001);
  EXPECT_NE(s.message.find("a limit point: the load peaked at 0.87"), std::string::npos)
      << s.message;
  // The path: up to the peak, then down with the sag still growing.
  double peak = 0.0;
  size_t at_peak = 0;
  for (size_t k = 0; k < s.steps.size(); ++k)
    if (s.steps[k].load_factors[0] > peak) peak = s.steps[k].load_factors[0], at_peak = k;
  ASSERT_LT(at_peak + 3, s.steps.size());
  EXPECT_LT(s.steps.back().load_factors[0], 0.8 * peak);
  EXPECT_GT(s.steps.back().max_displacement, 2.0 * s.steps[at_peak].max_displacement);
  // Load control converges up to the limit and not past it: in 8 steps,
  // step 7 (0.875, just below the limit) is the last reached.
  const SteppingSummary by_load = solve_load_steps(m, newton(8));
  EXPECT_FALSE(by_load.success);
  ASSERT_EQ(by_load.steps.size(), 7u);
  EXPECT_NEAR(by_load.steps.back().load_factors[0], 0.875, 1e-12);
}

TEST(ArcLength, DisplacementDrivenRunsAreLeftToLoadControl) {
  const SteppingSummary pressed = solve_load_steps(pressed_sphere(false), arc_length(4));
  EXPECT_FALSE(pressed.success);
  EXPECT_NE(pressed.message.find("arc_length: paddles"), std::string::npos) << pressed.message;
}

// Runs `m` with the dense tangent and with `kind` (steps, final tangents
// kept), checks that they give the same path and the same sensitivities
// du/dbeta from their final tangents, and returns the run with `kind`.
SteppingSummary expect_the_dense_path(const model::Model& m, int steps, TangentSolver kind) {
  SteppingOptions o = newton(steps, TangentSolver::Dense);
  o.keep_final_tangent = true;
  const SteppingSummary dense = solve_load_steps(m, o);
  o.newton.tangent = kind;
  SteppingSummary other = solve_load_steps(m, o);
  EXPECT_TRUE(dense.success && other.success) << dense.message << other.message;
  if (!dense.success || !other.success) return other;
  EXPECT_EQ(other.tangent, kind);
  EXPECT_GT(other.factorizations, 0);
  // Both stop once the residual is within Newton's tolerance, at iterates
  // that differ by about the inverse tangent times it: 1.9e-9 of the
  // displacement for the reused factor rounded to single precision (whose
  // GMRES stops at other iterates), below 1e-9 for the others.
  EXPECT_LT(displacement_norm(m, other.unknowns - dense.unknowns),
            5e-9 * displacement_norm(m, dense.unknowns));
  const Eigen::VectorXd dR = model::Equilibrium(m).parameter_derivatives(other.unknowns, {"beta"});
  Eigen::VectorXd du_other, du_dense;
  EXPECT_TRUE(other.final_tangent->solve_full(-dR, &du_other).ok);
  EXPECT_TRUE(dense.final_tangent->solve_full(-dR, &du_dense).ok);
  EXPECT_LT((du_other - du_dense).norm(), 1e-8 * du_dense.norm());
  return other;
}

// Fibers within a horizon stored as neighbour lists: the sparse LU of the
// tangent (UMFPACK) gives the dense LU's path, and its final tangent the
// same sensitivities; Auto takes it above the dense sizes, and its reuse
// above 4,000 unknowns.
TEST(Newton, TheSparseTangentAgreesWithTheDenseOne) {
  model::Model m = hanging_sphere(model::FiberLaw::exponential(20000.0, 5.0), 100.0);
  m.material.kinematics = model::FiberKinematics::Central;
  const double radius = 0.5 * (m.surface.V.col(0).maxCoeff() - m.surface.V.col(0).minCoeff());
  m.fibers = std::make_shared<const geom::FiberMask>(
      geom::horizon_fibers(m.surface, 0.6 * radius, geom::MaskStorage::Sparse));
  expect_the_dense_path(m, 2, TangentSolver::Sparse);
  const auto central = model::FiberKinematics::Central;
  EXPECT_EQ(choose_tangent(TangentSolver::Auto, 5000, central, true), TangentSolver::Reused);
  EXPECT_EQ(choose_tangent(TangentSolver::Auto, 3000, central, true), TangentSolver::Sparse);
  EXPECT_EQ(choose_tangent(TangentSolver::Auto, 600, central, true), TangentSolver::Dense);
  EXPECT_EQ(choose_tangent(TangentSolver::Auto, 5000, central, false), TangentSolver::Reused);
  EXPECT_EQ(choose_tangent(TangentSolver::Auto, 1000, central, false), TangentSolver::Reused);
  EXPECT_EQ(choose_tangent(TangentSolver::Auto, 600, central, false), TangentSolver::Dense);
  EXPECT_EQ(choose_tangent(TangentSolver::Auto, 60000, central, false), TangentSolver::Krylov);
  EXPECT_EQ(choose_tangent(TangentSolver::Auto, 60000, central, true), TangentSolver::Krylov);
  EXPECT_EQ(choose_tangent(TangentSolver::Auto, 5000, model::FiberKinematics::VectorSpring, true),
            TangentSolver::Krylov);
}

// Central fibers over every pair: GMRES on the exact tangent preconditioned
// by the LU of an earlier one gives the dense LU's path and sensitivities
// to rounding, with fewer factorisations than Newton iterations.
TEST(Newton, TheReusedTangentAgreesWithTheDenseOne) {
  model::Model m = hanging_sphere(model::FiberLaw::exponential(20000.0, 5.0), 100.0);
  m.material.kinematics = model::FiberKinematics::Central;
  const SteppingSummary reused = expect_the_dense_path(m, 3, TangentSolver::Reused);
  EXPECT_LT(reused.factorizations, reused.newton_iterations);
  EXPECT_GT(reused.krylov_iterations, 0);
  // Its factors were rounded to single precision for GMRES's solves.
  EXPECT_EQ(reused.single_precision_factorizations, reused.factorizations);
}

// GMRES allowed one iteration: a fresh rounded factor meets the forcing
// term's 0.1 of the first iterations but not its 1e-12 near convergence,
// where a fresh double one does. The run goes on in double from there
// (refactoring at every aged factor's failure), to the dense tangent's answer.
TEST(Newton, AFreshRoundedFactorThatFailsIsFactoredInDouble) {
  model::Model m = hanging_sphere(model::FiberLaw::exponential(20000.0, 5.0), 100.0);
  m.material.kinematics = model::FiberKinematics::Central;
  SteppingOptions o = newton(3, TangentSolver::Reused);
  o.newton.krylov_max_iterations = 1;
  o.newton.krylov_tolerance = 1e-12;
  const SteppingSummary one = solve_load_steps(m, o);
  ASSERT_TRUE(one.success) << one.message;
  EXPECT_GT(one.single_precision_factorizations, 0);
  EXPECT_LT(one.single_precision_factorizations, one.factorizations);
  const SteppingSummary dense = solve_load_steps(m, newton(3, TangentSolver::Dense));
  ASSERT_TRUE(dense.success) << dense.message;
  EXPECT_LT(displacement_norm(m, one.unknowns - dense.unknowns),
            5e-9 * displacement_norm(m, dense.unknowns));
}

}  // namespace
}  // namespace fiberfluid::solve
