// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/solve/linear_solver.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>

#include "fiberfluid/geom/fiber_pruning.hpp"
#include "fiberfluid/geom/mesh_io.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/model/fiber_system.hpp"
#include "fiberfluid/model/loads.hpp"
#include "fiberfluid/model/reference/dense_assembly.hpp"
#include "fiberfluid/solve/backends.hpp"
#include "fiberfluid/solve/stepping.hpp"
#include "model/model_fixtures.hpp"
#include "test_support.hpp"

namespace fiberfluid::solve {
namespace {

using namespace fiberfluid::model::reference;  // the oracle

using model::BoundaryMethod;

model::Model mesh_model(const char* file, const char* support) {
  model::Model m;
  m.surface =
      geom::remove_unused_vertices(geom::read_surface(testing::data_mesh(file)).surface).surface;
  m.material.law = model::FiberLaw::constant(5000.0);
  m.material.surface_tension = 20.0;
  for (int v : model::select_half_space(m.surface.V, model::parse_half_space(support, 3)))
    for (int a = 0; a < 3; ++a) m.constraints.push_back({v, a, 0.0, {}});
  model::Load gravity;
  gravity.kind = model::Load::Kind::Hydrostatic;
  gravity.acceleration = {0.0, -9.81, -3.0};
  gravity.density = 10.0;  // strains of a few percent: no face turns over
  model::Load pull;
  pull.vertex = m.num_vertices() / 2;
  pull.force = {50.0, 20.0, -10.0};
  m.loads = {gravity, pull};
  return m;
}

model::Model cube_with_prescribed_corner() {
  model::Model m = mesh_model("cube.obj", "z <= -0.9");
  // A top corner pulled sideways, and an axis-only support: unequal blocks.
  int top = 0;
  for (int i = 0; i < m.num_vertices(); ++i)
    if (m.surface.V(i, 2) > 0.9) top = i;
  m.constraints.push_back({top, 0, 0.05, {}});
  m.material.axis_factors = {1.0, 0.8, 0.6};
  return m;
}

struct Case {
  const char* name;
  model::Model (*make)();
};

model::Model pruned_liver() {
  model::Model m = mesh_model("liver.obj", "y >= 4.75");
  m.fibers = std::make_shared<const geom::FiberMask>(geom::prune_fibers(m.surface).mask);
  return m;
}

const Case kCases[] = {
    {"rectangle", [] { return testing::paper_rectangle_model(); }},
    {"sphere", [] { return testing::paper_sphere_model(); }},
    {"liver", [] { return mesh_model("liver.obj", "y >= 4.75"); }},
    {"cube", [] { return cube_with_prescribed_corner(); }},
    {"liver_pruned", [] { return pruned_liver(); }},
};

using Param = std::tuple<size_t, SolverKind, BoundaryMethod>;

class EveryBackend : public ::testing::TestWithParam<Param> {};

// An independent reference: the incremental scheme written out on the
// separately assembled dense matrix of model/assembly.cpp (not FiberSystem),
// with the boundary conditions of model/boundary_conditions.cpp and Eigen's LU.
Eigen::VectorXd reference_steps(const model::Model& m, const SteppingOptions& options) {
  const model::DofPartition partition = model::partition_dofs(m);
  const Eigen::MatrixXd A = model::reference::system_matrix(m, m.surface.V);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(m.num_unknowns());
  for (int k = 1; k <= options.steps; ++k) {
    std::vector<double> increment = model::load_factors(m, k, options.steps);
    const std::vector<double> before = model::load_factors(m, k - 1, options.steps);
    for (size_t l = 0; l < increment.size(); ++l) increment[l] -= before[l];
    const Eigen::VectorXd dB = model::right_hand_side(m, model::positions(m, x), increment);
    const Eigen::VectorXd du_c = model::constrained_displacements(m, k, options.steps) -
                                 model::constrained_displacements(m, k - 1, options.steps);
    Eigen::VectorXd values(static_cast<Eigen::Index>(partition.constrained.size()));
    Eigen::VectorXd dx = Eigen::VectorXd::Zero(m.num_unknowns());
    for (size_t c = 0; c < partition.constrained.size(); ++c) {
      values[static_cast<Eigen::Index>(c)] = du_c[partition.constrained[c]];
      dx[partition.constrained[c]] = du_c[partition.constrained[c]];
    }
    if (options.boundary_method == BoundaryMethod::Penalty) {
      Eigen::MatrixXd A_pen = A;
      Eigen::VectorXd B = dB;
      model::reference::apply_penalty(partition, values, options.penalty, A_pen, B);
      dx = A_pen.partialPivLu().solve(B);
    } else {
      Eigen::MatrixXd A_free;
      Eigen::VectorXd B_free;
      model::reference::reduce_system(partition, values, A, dB, A_free, B_free);
      const Eigen::VectorXd free = A_free.partialPivLu().solve(B_free);
      for (size_t i = 0; i < partition.free.size(); ++i)
        dx[partition.free[i]] = free[static_cast<Eigen::Index>(i)];
    }
    x += dx;
  }
  return x;
}

TEST_P(EveryBackend, AgreesWithAnIndependentDenseSolve) {
  const auto [case_index, kind, method] = GetParam();
  const model::Model m = kCases[case_index].make();
  SteppingOptions options;
  options.steps = 3;
  options.boundary_method = method;
  const Eigen::VectorXd reference = reference_steps(m, options);
  options.solver = kind;
  options.pcg.tolerance = 1e-12;
  const SteppingSummary s = solve_load_steps(m, options);
  ASSERT_TRUE(s.success) << s.message;
  EXPECT_EQ(s.solver, kind);
  const Eigen::Index u = reference.size() - 1;
  const double difference = (s.unknowns - reference).head(u).norm() / reference.head(u).norm();
  // Direct solvers to rounding (times the penalty's conditioning); pcg to its
  // tolerance times the conditioning it meets.
  const double direct = method == BoundaryMethod::Penalty ? 1e-8 : 1e-11;
  EXPECT_LT(difference, kind == SolverKind::PCG ? 1e-8 : direct) << kCases[case_index].name;
  const double P = reference[u];
  EXPECT_NEAR(s.unknowns[u], P, 1e-8 * std::abs(P) + 1e-12);
  // The summary hands back the factored system: it solves again, the same answer.
  ASSERT_TRUE(s.system && s.factorization);
  const Eigen::VectorXd rhs = Eigen::VectorXd::Random(s.system->num_unknowns());
  Eigen::VectorXd again;
  ASSERT_TRUE(s.factorization->solve(rhs, &again).ok);
  const Eigen::VectorXd lu = s.system->dense_matrix().partialPivLu().solve(rhs);
  EXPECT_LT((again - lu).norm(), (kind == SolverKind::PCG ? 1e-7 : 1e-9) * lu.norm());
}

std::string param_name(const ::testing::TestParamInfo<Param>& info) {
  std::string name = std::string(kCases[std::get<0>(info.param)].name) + "_" +
                     to_string(std::get<1>(info.param)) + "_" +
                     model::to_string(std::get<2>(info.param));
  for (char& c : name)
    if (c == '-') c = '_';
  return name;
}

INSTANTIATE_TEST_SUITE_P(
    Backends, EveryBackend,
    ::testing::Combine(::testing::Values(0u, 1u, 2u, 3u, 4u),
                       ::testing::Values(SolverKind::DenseLU, SolverKind::BlockCholesky,
                                         SolverKind::Cholmod, SolverKind::PCG),
                       ::testing::Values(BoundaryMethod::Elimination, BoundaryMethod::Penalty)),
    param_name);

// The Newton-Krylov preconditioner's block Cholesky in single precision: its
// solves agree with the double one's to single precision's digits, for equal
// axis blocks (one shared factor) and for different ones.
TEST(BlockCholesky, SinglePrecisionSolvesToSevenDigits) {
  for (size_t c : {0u, 1u, 2u, 3u, 4u}) {
    const model::Model m = kCases[c].make();
    const model::FiberSystem system(m, m.surface.V, model::DofMap::from_constraints(m),
                                    BoundaryMethod::Elimination, 1e9);
    const auto single = make_block_cholesky_solver(true), twice = make_block_cholesky_solver(false);
    ASSERT_TRUE(single->analyze_pattern(system).ok && single->factorize(system).ok)
        << kCases[c].name;
    ASSERT_TRUE(twice->analyze_pattern(system).ok && twice->factorize(system).ok);
    const Eigen::VectorXd rhs = Eigen::VectorXd::Random(system.num_unknowns());
    Eigen::VectorXd a, b;
    ASSERT_TRUE(single->solve(rhs, &a).ok && twice->solve(rhs, &b).ok);
    EXPECT_LT((a - b).norm(), 1e-4 * b.norm()) << kCases[c].name;
    EXPECT_GT((a - b).norm(), 0.0) << kCases[c].name << ": not single precision";
  }
}

// Failures come back as a status with a message, for setups built to cause them.
SteppingSummary run(model::Model m, SolverKind kind, PcgOptions pcg = {}) {
  SteppingOptions options;
  options.solver = kind;
  options.pcg = pcg;
  return solve_load_steps(m, options);
}

void expect_failure(const SteppingSummary& s, const std::string& part) {
  EXPECT_FALSE(s.success);
  EXPECT_NE(s.message.find(part), std::string::npos) << s.message;
}

TEST(BackendFailures, NotPositiveDefinite) {
  model::Model m = testing::paper_sphere_model();
  m.material.law = model::FiberLaw::constant(-3000.0);  // the input reader forbids this
  m.material.surface_tension = 0.0;
  expect_failure(run(m, SolverKind::BlockCholesky), "not positive definite");
  expect_failure(run(m, SolverKind::Cholmod), "not positive definite");
  expect_failure(run(m, SolverKind::PCG), "not positive definite");
}

TEST(BackendFailures, PcgWithoutConvergence) {
  PcgOptions tight;
  tight.tolerance = 1e-15;
  tight.max_iterations = 1;
  expect_failure(run(testing::paper_sphere_model(), SolverKind::PCG, tight), "no convergence in 1");
}

TEST(BackendFailures, PcgNamesNonFiniteValues) {
  const Eigen::MatrixXd K =
      4.0 * Eigen::MatrixXd::Identity(20, 20) + Eigen::MatrixXd::Constant(20, 20, 0.1);
  PcgOptions pcg;
  auto solve_with = [&](const Eigen::MatrixXd& block, const Eigen::VectorXd& rhs) {
    const model::DenseBorderedSystem system({block}, Eigen::VectorXd::Ones(20));
    const auto solver = make_linear_solver(SolverKind::PCG, pcg);
    EXPECT_TRUE(solver->analyze_pattern(system).ok);
    Status status = solver->factorize(system);
    Eigen::VectorXd x;
    if (status.ok) status = solver->solve(rhs, &x);
    EXPECT_FALSE(status.ok);
    return status.message;
  };
  Eigen::VectorXd rhs = Eigen::VectorXd::Ones(21);
  rhs[3] = std::nan("");
  EXPECT_NE(solve_with(K, rhs).find("pcg: the right-hand side is not finite"), std::string::npos);
  // A right-hand side near the largest double: its inner products overflow.
  const std::string message = solve_with(K, 1e300 * Eigen::VectorXd::Ones(21));
  EXPECT_NE(message.find("pcg: a product with the matrix is not finite at iteration 1"),
            std::string::npos)
      << message;
}

TEST(BackendFailures, SingularSetupForEveryBackend) {
  model::Model m = testing::paper_sphere_model();
  m.constraints.clear();
  for (SolverKind kind :
       {SolverKind::DenseLU, SolverKind::BlockCholesky, SolverKind::Cholmod, SolverKind::PCG})
    expect_failure(run(m, kind), "no supports");
}

// The backends solve any bordered system, not only the model's: random SPD
// blocks (distinct, then equal) and a random border, against Eigen's LU.
TEST(EveryBackend, SolvesAnyBorderedSystem) {
  std::srand(7);
  auto spd = [](int n) {
    const Eigen::MatrixXd B = Eigen::MatrixXd::Random(n, n);
    return Eigen::MatrixXd(B * B.transpose() + n * Eigen::MatrixXd::Identity(n, n));
  };
  const Eigen::MatrixXd K = spd(30);
  for (bool equal : {false, true}) {
    std::vector<Eigen::MatrixXd> blocks = {K, equal ? K : spd(30), equal ? K : spd(30)};
    const model::DenseBorderedSystem system(blocks, Eigen::VectorXd::Random(90));
    EXPECT_EQ(system.blocks_equal(), equal);
    const Eigen::VectorXd rhs = Eigen::VectorXd::Random(91);
    const Eigen::VectorXd expected = system.dense_matrix().partialPivLu().solve(rhs);
    for (SolverKind kind :
         {SolverKind::DenseLU, SolverKind::BlockCholesky, SolverKind::Cholmod, SolverKind::PCG}) {
      PcgOptions pcg;
      pcg.tolerance = 1e-13;
      const auto solver = make_linear_solver(kind, pcg);
      ASSERT_TRUE(solver->analyze_pattern(system).ok);
      ASSERT_TRUE(solver->factorize(system).ok) << to_string(kind);
      Eigen::VectorXd x;
      ASSERT_TRUE(solver->solve(rhs, &x).ok) << to_string(kind);
      EXPECT_LT((x - expected).norm(), 1e-10 * expected.norm()) << to_string(kind) << equal;
    }
  }
}

TEST(BackendChoice, BySize) {
  const model::Model small = testing::paper_sphere_model();
  const model::FiberSystem system(small, small.surface.V, BoundaryMethod::Elimination, 1e9);
  const double GiB = 1024.0 * 1024.0 * 1024.0;
  EXPECT_EQ(choose_solver(system, 24 * GiB), SolverKind::DenseLU);
  EXPECT_EQ(choose_solver(system, 0.1 * GiB), SolverKind::DenseLU);  // tiny: always dense
  model::Model large;
  large.surface = geom::icosphere(5);  // 10242 vertices: two 0.84 GB blocks (factor and copy)
  large.constraints = {{0, 0, 0.0, {}}, {0, 1, 0.0, {}}, {0, 2, 0.0, {}}};
  const model::FiberSystem big(large, large.surface.V, BoundaryMethod::Elimination, 1e9);
  EXPECT_EQ(choose_solver(big, 24 * GiB), SolverKind::BlockCholesky);
  EXPECT_EQ(choose_solver(big, 4 * GiB), SolverKind::PCG);
  EXPECT_EQ(kSolverKindNames.find("pcg"), SolverKind::PCG);
  EXPECT_FALSE(kSolverKindNames.find("gauss-seidel"));
}

}  // namespace
}  // namespace fiberfluid::solve
