// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/solve/stepping.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/equilibrium.hpp"
#include "fiberfluid/model/loads.hpp"
#include "fiberfluid/model/reference/dense_assembly.hpp"
#include "fiberfluid/solve/dense_lu.hpp"
#include "model/model_fixtures.hpp"

namespace fiberfluid::solve {
namespace {

using namespace fiberfluid::model::reference;  // the oracle

using model::BoundaryMethod;

SteppingOptions options(int steps, BoundaryMethod method = BoundaryMethod::Elimination) {
  SteppingOptions o;
  o.steps = steps;
  o.boundary_method = method;
  return o;
}

double relative_difference(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return (a - b).norm() / b.norm();
}

// The treecode's rules are the library's: a C++ caller who sets a tolerance
// with Newton, a strain-dependent law or a factorising solver gets the same
// refusal as an experiment file, not a silently exact run.
TEST(LoadStepper, TheTreecodeRulesAreCheckedForEveryCaller) {
  model::Model m = testing::paper_sphere_model();
  m.treecode_tolerance = 1e-6;
  SteppingOptions o;
  o.steps = 1;
  const SteppingSummary fine = solve_load_steps(m, o);
  ASSERT_TRUE(fine.success) << fine.message;
  EXPECT_EQ(fine.solver, SolverKind::PCG);  // Auto chose the matrix-free backend
  const auto refused = [&](const model::Model& model, const SteppingOptions& options,
                           const std::string& why) {
    const SteppingSummary s = solve_load_steps(model, options);
    EXPECT_FALSE(s.success);
    EXPECT_NE(s.message.find(why), std::string::npos) << s.message;
  };
  SteppingOptions dense = o;
  dense.solver = SolverKind::DenseLU;
  refused(m, dense, "is matrix-free");
  SteppingOptions newton = o;
  newton.scheme = Scheme::Newton;
  refused(m, newton, "Newton's tangent is exact");
  model::Model nonlinear = m;
  nonlinear.material.law = model::FiberLaw::exponential(3000.0, 5.0);
  refused(nonlinear, o, "needs a linear material");
}

TEST(LoadStepper, PaperRectangleExactWithElimination) {
  const SteppingSummary s = solve_load_steps(testing::paper_rectangle_model(), options(1));
  ASSERT_TRUE(s.success) << s.message;
  Eigen::VectorXd expected(9);  // u1x = u2x = -4, u1y = u4y = 16/3, P = 32
  expected << -4, -4, 0, 0, 16.0 / 3.0, 0, 0, 16.0 / 3.0, 32;
  EXPECT_NEAR((s.unknowns - expected).cwiseAbs().maxCoeff(), 0.0, 1e-11);
}

TEST(LoadStepper, PaperRectangleWithPenaltyAsInThePaper) {
  const SteppingSummary s =
      solve_load_steps(testing::paper_rectangle_model(), options(1, BoundaryMethod::Penalty));
  ASSERT_TRUE(s.success) << s.message;
  EXPECT_NEAR(15 + s.unknowns[0], 11.0, 1e-5);            // right corners at x = 11
  EXPECT_NEAR(20 + s.unknowns[4], 25.0 + 1.0 / 3, 1e-5);  // top corners at y = 25.33
  EXPECT_NEAR(s.unknowns[8], 32.0, 1e-5);
  EXPECT_LT(std::abs(s.unknowns[2]), 1e-5);  // "fixed" only up to the penalty
}

// An independent solve: the bordered system with its constrained rows and
// columns removed, by Eigen's full-pivot LU instead of LAPACK.
Eigen::VectorXd eigen_reference_solution(const model::Model& m, const std::vector<double>& f) {
  const Eigen::MatrixXd A = model::reference::system_matrix(m, m.surface.V);
  const Eigen::VectorXd B = model::right_hand_side(m, m.surface.V, f);
  std::vector<char> fixed(static_cast<size_t>(m.num_unknowns()), 0);
  for (const model::Constraint& c : m.constraints)
    fixed[static_cast<size_t>(m.dof(c.vertex, c.axis))] = 1;
  std::vector<int> free;
  for (int d = 0; d < m.num_unknowns(); ++d)
    if (!fixed[static_cast<size_t>(d)]) free.push_back(d);
  const Eigen::MatrixXd A_free = A(free, free);
  const Eigen::VectorXd x_free = A_free.fullPivLu().solve(B(free));
  Eigen::VectorXd x = Eigen::VectorXd::Zero(m.num_unknowns());
  x(free) = x_free;
  return x;
}

TEST(LoadStepper, OneStepAgreesWithAnIndependentSolveAndBothBoundaryMethods) {
  const model::Model m = testing::paper_sphere_model();
  const Eigen::VectorXd reference = eigen_reference_solution(m, {1.0, 1.0});
  const SteppingSummary eliminated = solve_load_steps(m, options(1));
  const SteppingSummary penalised = solve_load_steps(m, options(1, BoundaryMethod::Penalty));
  ASSERT_TRUE(eliminated.success && penalised.success);
  EXPECT_LT(relative_difference(eliminated.unknowns, reference), 1e-10);
  // Penalty 1e9 against stiffness ~1e3: agreement to about 1e-6.
  EXPECT_LT(relative_difference(penalised.unknowns, reference), 1e-5);
}

TEST(LoadStepper, WithoutGeometryUpdatesNStepsGiveTheSameAnswerAsOne) {
  model::Model m = testing::paper_sphere_model();
  m.loads[1].schedule.kind = model::Schedule::Kind::Ramp;
  SteppingOptions fixed_geometry = options(10);
  fixed_geometry.update_load_geometry = false;
  const SteppingSummary ten = solve_load_steps(m, fixed_geometry);
  fixed_geometry.steps = 1;
  const SteppingSummary one = solve_load_steps(m, fixed_geometry);
  ASSERT_TRUE(ten.success && one.success);
  EXPECT_LT(relative_difference(ten.unknowns, one.unknowns), 1e-12);
  EXPECT_EQ(ten.factorizations, 1);
  EXPECT_EQ(ten.steps.size(), 10u);
}

TEST(LoadStepper, UniformPressureLoadIsCarriedByTheFluidAlone) {
  // Forces c S_i on every vertex are balanced by P = c with u = 0.
  model::Model m = testing::paper_sphere_model();
  const Eigen::MatrixXd S = geom::vertex_area_vectors(m.surface.V, m.surface.F).S;
  m.loads.clear();
  for (int i = 0; i < m.num_vertices(); ++i) {
    model::Load load;
    load.vertex = i;
    load.force = 250.0 * S.row(i).transpose();
    m.loads.push_back(load);
  }
  const SteppingSummary s = solve_load_steps(m, options(1));
  ASSERT_TRUE(s.success);
  EXPECT_NEAR(s.unknowns[m.pressure_dof()], 250.0, 1e-9);
  EXPECT_LT(s.unknowns.head(m.pressure_dof()).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(LoadStepper, OneStepKeepsTheLinearisedVolume) {
  const model::Model m = testing::paper_sphere_model();
  const SteppingSummary s = solve_load_steps(m, options(1));
  ASSERT_TRUE(s.success);
  const Eigen::MatrixXd S = geom::vertex_area_vectors(m.surface.V, m.surface.F).S;
  const Eigen::MatrixXd U = model::displacements(m, s.unknowns);
  EXPECT_NEAR((S.array() * U.array()).sum(), 0.0, 1e-12 * S.norm() * U.norm());
}

TEST(LoadStepper, ResponseIsLinearInTheLoad) {
  model::Model m = testing::paper_sphere_model();
  const SteppingSummary once = solve_load_steps(m, options(1));
  for (model::Load& load : m.loads) {
    load.force *= 2.5;
    load.density *= 2.5;
  }
  const SteppingSummary scaled = solve_load_steps(m, options(1));
  EXPECT_LT(relative_difference(scaled.unknowns, 2.5 * once.unknowns), 1e-12);
}

TEST(LoadStepper, PrescribedDisplacementIsReachedExactly) {
  model::Model m = testing::paper_rectangle_model();
  m.loads.clear();
  m.constraints.push_back({0, 1, 3.0, {}});  // v1 pulled up by 3, ramped over 4 steps
  const SteppingSummary s = solve_load_steps(m, options(4));
  ASSERT_TRUE(s.success);
  EXPECT_NEAR(s.unknowns[m.dof(0, 1)], 3.0, 1e-12);
  EXPECT_NEAR(s.unknowns[m.dof(2, 0)], 0.0, 1e-15);
}

TEST(LoadStepper, RoundTripReturnsOnlyWithoutGeometryUpdatesAndErrorFallsAsOneOverN) {
  model::Model m = testing::paper_sphere_model();
  m.loads.pop_back();
  m.loads[0].schedule.kind = model::Schedule::Kind::UpDown;
  auto round_trip_error = [&](int n, bool update) {
    SteppingOptions o = options(2 * n);
    o.update_load_geometry = update;
    const SteppingSummary s = solve_load_steps(m, o);
    EXPECT_TRUE(s.success);
    return model::displacements(m, s.unknowns).rowwise().norm().mean();
  };
  EXPECT_LT(round_trip_error(1, false), 1e-12);
  const double e1 = round_trip_error(1, true), e10 = round_trip_error(10, true),
               e100 = round_trip_error(100, true);
  EXPECT_GT(e1, 1e-4);
  EXPECT_GT(e1 / e10, 9.0);
  EXPECT_NEAR(e10 / e100, 10.0, 0.5);  // forward Euler: error ~ 1/n asymptotically
}

// The incremental scheme is built on the problem object, which also measures
// its answer: the residual left is what the linearisation misses.
TEST(LoadStepper, EquilibriumResidualMeasuresWhatTheLinearisationMisses) {
  model::Model m = testing::paper_sphere_model();
  m.loads.pop_back();  // gravity alone, ramped
  auto final_residual = [&](double load_scale, int steps, bool rebuild) {
    model::Model scaled = m;
    scaled.loads[0].acceleration *= load_scale;
    SteppingOptions o = options(steps);
    o.rebuild_matrix = rebuild;
    const SteppingSummary s = solve_load_steps(scaled, o);
    EXPECT_TRUE(s.success) << s.message;
    return s.steps.empty() ? 0.0 : s.steps.back().residual;
  };
  // An independent evaluation of the reported figure at the end of a run.
  SteppingOptions o = options(4);
  const SteppingSummary s = solve_load_steps(m, o);
  ASSERT_TRUE(s.success);
  const model::Equilibrium problem(m);
  const std::vector<double> factors = model::load_factors(m, 4, 4);
  const Eigen::VectorXd R = problem.residual(s.unknowns, factors);
  const Eigen::VectorXd F = problem.external_forces(s.unknowns, factors);
  const model::DofMap dofs = model::DofMap::from_constraints(m);
  double held = 0.0, free = 0.0;
  for (int d = 0; d + 1 < R.size(); ++d) (dofs.held(d) ? held : free) += R[d] * R[d];
  const double scale = std::max(F.head(F.size() - 1).norm(), std::sqrt(held));
  const double expected =
      std::hypot(std::sqrt(free) / scale, R[R.size() - 1] / problem.volume_scale());
  EXPECT_NEAR(s.steps.back().residual, expected, 1e-12 * expected);
  EXPECT_GT(expected, 1e-8);  // the paper's scheme is not at equilibrium
  // A small load: displacements ~ s and the missed terms ~ s^2, so the
  // residual relative to the load falls as s.
  const double r1 = final_residual(1e-2, 1, false), r2 = final_residual(1e-3, 1, false);
  EXPECT_NEAR(r1 / r2, 10.0, 0.5);
  // At a third of the paper's gravity the incremental answer is still far
  // from equilibrium (the pressure and the hydrostatic load follow the
  // geometry, which the fixed A does not), however many steps; Newton is not.
  EXPECT_GT(final_residual(0.3, 40, false), 0.01);
  model::Model lighter = m;
  lighter.loads[0].acceleration *= 0.3;
  SteppingOptions newton = options(4);
  newton.scheme = Scheme::Newton;
  const SteppingSummary sn = solve_load_steps(lighter, newton);
  ASSERT_TRUE(sn.success) << sn.message;
  EXPECT_LT(sn.steps.back().residual, newton.newton.residual_tolerance);
  EXPECT_EQ(sn.steps.back().residual, sn.steps.back().residual_norms.back());
  // Measuring can be turned off.
  o.measure_residual = false;
  EXPECT_EQ(solve_load_steps(m, o).steps.back().residual, 0.0);
}

TEST(LoadStepper, RebuiltMatrixIsFactoredEveryStep) {
  SteppingOptions o = options(3);
  o.rebuild_matrix = true;
  int observed = 0;
  const SteppingSummary s = solve_load_steps(
      testing::paper_sphere_model(), o,
      [&](const StepRecord& r, const Eigen::VectorXd&) { EXPECT_EQ(r.step, ++observed); });
  ASSERT_TRUE(s.success);
  EXPECT_EQ(s.factorizations, 3);
  EXPECT_EQ(observed, 3);
}

TEST(LoadStepper, SingularSetupsFailWithAMessage) {
  model::Model m = testing::paper_sphere_model();
  m.constraints.clear();
  SteppingSummary s = solve_load_steps(m, options(1));
  EXPECT_FALSE(s.success);
  EXPECT_NE(s.message.find("no supports"), std::string::npos) << s.message;

  m = testing::paper_sphere_model();
  for (auto& c : m.constraints) c.axis = c.axis == 2 ? 0 : c.axis;  // nothing holds z
  s = solve_load_steps(m, options(1));
  EXPECT_FALSE(s.success);
  EXPECT_NE(s.message.find("along z"), std::string::npos) << s.message;

  SteppingOptions bad = options(0);
  s = solve_load_steps(testing::paper_sphere_model(), bad);
  EXPECT_FALSE(s.success);
}

TEST(DenseLU, ReportsASingularMatrix) {
  DenseLU lu;
  Eigen::Matrix3d A;
  A << 1, 2, 3, 2, 4, 6, 1, 0, 1;
  EXPECT_FALSE(lu.factorize(A).ok);
  A(1, 1) = 5;
  ASSERT_TRUE(lu.factorize(A).ok);
  const Eigen::Vector3d b(1, 2, 3);
  EXPECT_NEAR((A * lu.solve(b) - b).norm(), 0.0, 1e-14);
}

// A preconditioner's LU rounded to single precision: its solves within
// float's rounding of the double LU's on a well-conditioned matrix; not
// rounded where the rounded solves would be off by over 1%.
TEST(DenseLU, RoundsToSinglePrecisionOnlyWhereItsSolvesServe) {
  const int n = 300;
  Eigen::MatrixXd A = Eigen::MatrixXd::Random(n, n);
  A.diagonal().array() += 20.0;
  DenseLU exact, rounded;
  EXPECT_THROW(rounded.round_to_single(), std::logic_error);  // nothing factored yet
  ASSERT_TRUE(exact.factorize(A).ok);
  ASSERT_TRUE(rounded.factorize(A).ok);
  EXPECT_FALSE(rounded.single());
  ASSERT_TRUE(rounded.round_to_single());
  EXPECT_TRUE(rounded.single());
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
  const Eigen::VectorXd x = exact.solve(b), y = rounded.solve(b);
  EXPECT_LT((y - x).norm(), 1e-5 * x.norm());
  EXPECT_GT((y - x).norm(), 1e-12 * x.norm());  // it did round
  EXPECT_LT((A * y - b).norm(), 1e-5 * b.norm());
  EXPECT_GT(rounded.rounding_stretch(), 1e-9);
  EXPECT_LT(rounded.rounding_stretch(), 1e-5);
  // A new factorisation is in double again.
  ASSERT_TRUE(rounded.factorize(A).ok);
  EXPECT_FALSE(rounded.single());
  EXPECT_LT((rounded.solve(b) - x).norm(), 1e-13 * x.norm());

  // Hilbert's matrix of order 7 (condition 4.8e8): double serves, single
  // does not (rounding stretches by up to 4.8e8 times float's 6e-8).
  Eigen::MatrixXd hilbert(7, 7);
  for (int i = 0; i < 7; ++i)
    for (int j = 0; j < 7; ++j) hilbert(i, j) = 1.0 / (i + j + 1);
  ASSERT_TRUE(rounded.factorize(hilbert).ok);
  EXPECT_FALSE(rounded.round_to_single());
  EXPECT_FALSE(rounded.single());
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(7);
  EXPECT_LT((hilbert * rounded.solve(ones) - ones).norm(), 1e-7);
}

}  // namespace
}  // namespace fiberfluid::solve

namespace fiberfluid::solve {
namespace {

TEST(LoadStepper, RefusesADenseSystemLargerThanMemory) {
  model::Model m;
  m.surface = geom::icosphere(7, 1.0);  // 163842 vertices: ~1.4 TB as a dense system
  m.material.law = model::FiberLaw::constant(1.0);
  for (int a = 0; a < 3; ++a) m.constraints.push_back({0, a, 0.0, {}});
  for (SolverKind kind : {SolverKind::DenseLU, SolverKind::BlockCholesky, SolverKind::Cholmod}) {
    SteppingOptions o;
    o.solver = kind;
    const SteppingSummary s = solve_load_steps(m, o);
    EXPECT_FALSE(s.success);
    EXPECT_NE(s.message.find("GiB"), std::string::npos) << s.message;
  }
}

}  // namespace
}  // namespace fiberfluid::solve

// ------------------------------------------------------------ reactions
namespace fiberfluid::solve {
namespace {

// Sum of the group reactions and the applied loads of the last step, and the
// size of the applied load, for the equilibrium check.
std::pair<double, double> equilibrium_error(const SteppingSummary& s) {
  const StepRecord& last = s.steps.back();
  Eigen::Vector3d total = last.applied_force;
  for (const Eigen::Vector3d& r : last.reactions) total += r;
  return {total.norm(), last.applied_force.norm()};
}

TEST(Reactions, PaperRectangleSupportsCarryTheAppliedForce) {
  // model.md section 8 by hand: the rows of v3 and v2 in y give
  // -84 (16/3) - 105 (16/3) - 21 (32) = -1680 each; v3's x row gives 0.
  for (BoundaryMethod method : {BoundaryMethod::Elimination, BoundaryMethod::Penalty}) {
    const SteppingSummary s =
        solve_load_steps(testing::paper_rectangle_model(), options(1, method));
    ASSERT_TRUE(s.success) << s.message;
    EXPECT_NEAR(s.reaction_forces(2, 1), -1680.0, 1e-9);
    EXPECT_NEAR(s.reaction_forces(1, 1), -1680.0, 1e-9);
    EXPECT_NEAR(s.reaction_forces(2, 0), 0.0, 1e-9);
    EXPECT_EQ(s.reaction_forces(0, 1), 0.0);  // free vertices carry none
    ASSERT_EQ(s.steps.back().reactions.size(), 1u);
    EXPECT_NEAR(s.steps.back().reactions[0].y(), -3360.0, 1e-9);
    EXPECT_NEAR(s.steps.back().applied_force.y(), 3360.0, 1e-9);
  }
}

TEST(Reactions, AgreeWithTheDenseAssemblyRows) {
  // An independent path: (A(s) x - B) at the constrained unknowns of the
  // plain dense assembly, for the sphere in one step (A and the loads at s).
  const model::Model m = testing::paper_sphere_model();
  SteppingOptions o = options(1);
  o.update_load_geometry = false;
  const SteppingSummary s = solve_load_steps(m, o);
  ASSERT_TRUE(s.success) << s.message;
  const Eigen::VectorXd residual = model::reference::linear_residual(m, s.unknowns, {1.0, 1.0});
  double largest = 0.0;
  for (const model::Constraint& c : m.constraints)
    largest = std::max(
        largest, std::abs(s.reaction_forces(c.vertex, c.axis) - residual[m.dof(c.vertex, c.axis)]));
  EXPECT_LT(largest, 1e-9 * s.reaction_forces.cwiseAbs().maxCoeff());
}

TEST(Reactions, BalanceTheLoadsAtEveryStep) {
  // Global equilibrium: the Laplacian rows and the closed surface's area
  // vectors each sum to zero, so the reactions balance the loads, with A
  // constant or rebuilt, by elimination or penalty.
  for (bool rebuild : {false, true})
    for (BoundaryMethod method : {BoundaryMethod::Elimination, BoundaryMethod::Penalty}) {
      SteppingOptions o = options(10, method);
      o.rebuild_matrix = rebuild;
      const SteppingSummary s = solve_load_steps(testing::paper_sphere_model(), o);
      ASSERT_TRUE(s.success) << s.message;
      for (const StepRecord& r : s.steps) {
        Eigen::Vector3d total = r.applied_force;
        for (const Eigen::Vector3d& reaction : r.reactions) total += reaction;
        EXPECT_LT(total.norm(), 1e-10 * r.applied_force.norm()) << "step " << r.step;
      }
      const auto [error, size] = equilibrium_error(s);
      EXPECT_GT(size, 1e4);  // the fluid's weight, about rho g V = 4e4 N
      EXPECT_LT(error, 1e-10 * size);
    }
}

// ------------------------------------------------------------ guards
TEST(Guards, ALoadFarTooLargeIsARunawayNamingTheStep) {
  model::Model m = testing::paper_sphere_model();
  m.loads[0].density *= 1e9;
  const SteppingSummary s = solve_load_steps(m, options(10));
  EXPECT_FALSE(s.success);
  EXPECT_NE(s.message.find("step 1: runaway"), std::string::npos) << s.message;
  EXPECT_TRUE(s.steps.empty());
}

TEST(Guards, VolumeDriftBeyondTheBoundStops) {
  // The sphere drifts +2.9% over its 10 steps with A constant: a bound of 1%
  // stops it part way, naming the option.
  SteppingOptions o = options(10);
  o.max_volume_change = 0.01;
  const SteppingSummary s = solve_load_steps(testing::paper_sphere_model(), o);
  EXPECT_FALSE(s.success);
  EXPECT_NE(s.message.find("runaway: the enclosed volume changed by"), std::string::npos)
      << s.message;
  EXPECT_NE(s.message.find("stepping.max_volume_change"), std::string::npos) << s.message;
  EXPECT_GT(s.steps.size(), 0u);
  EXPECT_LT(s.steps.size(), 10u);
}

TEST(Guards, ASupportOnEveryVertexIsNamed) {
  model::Model m = testing::paper_sphere_model();
  m.constraints.clear();
  for (int v = 0; v < m.num_vertices(); ++v)
    for (int a = 0; a < 3; ++a) m.constraints.push_back({v, a, 0.0, {}});
  const SteppingSummary s = solve_load_steps(m, options(1));
  EXPECT_FALSE(s.success);
  EXPECT_NE(s.message.find("fix every vertex on every axis"), std::string::npos) << s.message;
}

}  // namespace
}  // namespace fiberfluid::solve
