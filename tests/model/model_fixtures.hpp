// SPDX-License-Identifier: GPL-3.0-or-later
// Models used by several tests: the paper's rectangle and sphere, the small
// sphere of the Newton equations' tests and random states of it.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/model/equilibrium.hpp"
#include "fiberfluid/model/model.hpp"
#include "fiberfluid/solve/stepping.hpp"

namespace fiberfluid::testing {

// The spline law (FiberLaw::spline) whose tension is the straight line
// A l + B on `knots`: a quadratic spline reproduces a line with coefficients
// A g_j + B at its Greville abscissae g_j = (t_j+1 + t_j+2) / 2 (de Boor, A
// Practical Guide to Splines, ch. IX), so its rises are A (g_j - g_j-1).
inline model::FiberLaw spline_of_line(const std::vector<double>& knots, double A, double B) {
  std::vector<double> g = {knots.front()};
  for (size_t k = 0; k + 1 < knots.size(); ++k) g.push_back(0.5 * (knots[k] + knots[k + 1]));
  g.push_back(knots.back());
  std::vector<double> rises;
  for (size_t j = 1; j < g.size(); ++j) rises.push_back(A * (g[j] - g[j - 1]));
  return model::FiberLaw::spline(knots, A + B, rises);
}

// The fluid's weight under an acceleration (a hydrostatic load).
inline model::Load hydrostatic_load(const Eigen::Vector3d& acceleration, double density) {
  model::Load load;
  load.kind = model::Load::Kind::Hydrostatic;
  load.acceleration = acceleration;
  load.density = density;
  return load;
}

// A paddle above the body along z, touching its top, that moves by `travel`.
inline model::Paddle paddle_on_top(const model::Model& m, const std::string& label, double travel) {
  model::Paddle paddle;
  paddle.label = label;
  paddle.axis = 2;
  paddle.above = true;
  paddle.position = m.surface.V.col(2).maxCoeff();
  paddle.travel = travel;
  return paddle;
}

// model.md section 8: v3 fixed, v2 held in y, 1680 upward on v1 and v4.
inline model::Model paper_rectangle_model() {
  model::Model m;
  Eigen::MatrixXd P(4, 2);
  P << 15, 20, 15, -20, -15, -20, -15, 20;
  m.surface = geom::polygon(P);
  m.material.law = model::FiberLaw::constant(360.0);
  m.constraints = {{2, 0, 0.0, {}}, {2, 1, 0.0, {}}, {1, 1, 0.0, {}}};
  for (int v : {0, 3}) {
    model::Load load;
    load.vertex = v;
    load.force = {0.0, 1680.0, 0.0};
    m.loads.push_back(load);
  }
  return m;
}

// model.md section 9: the paper's sphere (SI units).
inline model::Model paper_sphere_model() {
  model::Model m;
  m.surface = geom::icosphere(2, 1.0);
  m.material.law = model::FiberLaw::constant(3000.0);
  m.material.surface_tension = 3000.0;
  for (int v : model::select_half_space(m.surface.V, model::parse_half_space("z >= 0.8", 3)))
    for (int a = 0; a < 3; ++a) m.constraints.push_back({v, a, 0.0, {}});
  model::Load gravity;
  gravity.kind = model::Load::Kind::Hydrostatic;
  gravity.acceleration = {0.0, 0.0, -10.0};
  gravity.density = 1000.0;
  model::Load pull;
  pull.vertex = 0;
  pull.force = {-300.0, -300.0, -300.0};
  pull.schedule.kind = model::Schedule::Kind::Final;
  m.loads = {gravity, pull};
  return m;
}

// A 42-vertex sphere with a cap held, gravity, a point load and surface
// tension, with axis factors that enter every term.
// The paper's sphere resting on supports at its bottom (z <= -0.9, every
// axis), no load, pressed by a paddle from above that travels 0.3 down.
inline model::Model pressed_sphere(bool sticking = false) {
  model::Model m = paper_sphere_model();
  m.loads.clear();
  m.constraints.clear();
  for (int v : model::select_half_space(m.surface.V, model::parse_half_space("z <= -0.9", 3)))
    for (int a = 0; a < 3; ++a) m.constraints.push_back({v, a, 0.0, {}});
  m.paddles = {paddle_on_top(m, "top", -0.3)};
  m.paddles[0].contact =
      sticking ? model::Paddle::Contact::Sticking : model::Paddle::Contact::Frictionless;
  return m;
}

inline model::Model small_sphere(
    const model::FiberLaw& law,
    model::FiberKinematics kinematics = model::FiberKinematics::VectorSpring,
    model::Load::Integration integration = model::Load::Integration::Vertex) {
  model::Model m = paper_sphere_model();
  m.surface = geom::icosphere(1, 1.0);
  m.constraints.clear();
  for (int v : model::select_half_space(m.surface.V, model::parse_half_space("z >= 0.8", 3)))
    for (int a = 0; a < 3; ++a) m.constraints.push_back({v, a, 0.0, {}});
  m.material.law = law;
  m.material.kinematics = kinematics;
  m.material.axis_factors = {1.0, 0.8, 1.3};
  m.material.surface_tension = 500.0;
  m.loads[1].vertex = 7;
  m.loads[0].integration = integration;  // the hydrostatic load
  return m;
}

// A random state: displacements of up to `size` in each coordinate, a pressure.
inline Eigen::VectorXd random_state(const model::Model& m, unsigned seed, double size = 0.04) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::VectorXd x(m.num_unknowns());
  for (Eigen::Index k = 0; k < x.size(); ++k) x[k] = size * uniform(rng);
  x[m.pressure_dof()] = 800.0 * uniform(rng);
  return x;
}

// dR/dx by central differences of the residual, column by column: a step
// for the displacements and one for the pressure (the last unknown).
inline Eigen::MatrixXd finite_difference_tangent(const model::Equilibrium& eq,
                                                 const Eigen::VectorXd& x,
                                                 const std::vector<double>& factors,
                                                 double displacement_step = 1e-6,
                                                 double pressure_step = 1e-3) {
  Eigen::MatrixXd J(x.size(), x.size());
  for (Eigen::Index k = 0; k < x.size(); ++k) {
    const double h = k == x.size() - 1 ? pressure_step : displacement_step;
    Eigen::VectorXd plus = x, minus = x;
    plus[k] += h;
    minus[k] -= h;
    J.col(k) = (eq.residual(plus, factors) - eq.residual(minus, factors)) / (2.0 * h);
  }
  return J;
}

// The stored tangent (Equilibrium::linearize) times v against the exact J v:
// its pair coefficients are kept in single precision, so each pair's term is
// within 2^-24 of its own size, and the sum within that of |J| |v| (entry by
// entry), with a margin of 16 for the other roundings. Cancellation between
// the terms of a row can make it far larger relative to |J v| itself.
inline ::testing::AssertionResult stored_product_matches(const Eigen::VectorXd& stored,
                                                         const Eigen::MatrixXd& J,
                                                         const Eigen::VectorXd& v) {
  const double bound = 1e-6 * (J.cwiseAbs() * v.cwiseAbs()).norm();
  const double error = (stored - J * v).norm();
  if (error < bound) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "stored product off by " << error << ", bound " << bound;
}

// The mean z displacement of the vertices at x (a bar's deflection at a station).
inline double mean_deflection_at(const model::Model& m, const Eigen::MatrixXd& U, double x) {
  double sum = 0.0;
  int count = 0;
  for (int v = 0; v < m.num_vertices(); ++v)
    if (std::abs(m.surface.V(v, 0) - x) < 1e-9) sum += U(v, 2), ++count;
  return sum / count;
}

// Displacements uniform in [-size, size] (Eigen's Random after srand(seed))
// and a pressure of 300 Pa.
inline Eigen::VectorXd random_displacements(const model::Model& m, unsigned seed, double size) {
  std::srand(seed);
  Eigen::VectorXd x = size * Eigen::VectorXd::Random(m.num_unknowns());
  x[m.pressure_dof()] = 300.0;
  return x;
}

// The tangent at x against central differences of the residual, and its
// product, stored-coefficient product and sparse form against it (v: a
// direction).
inline void expect_tangent_matches_differences(const model::Equilibrium& eq,
                                               const Eigen::VectorXd& x,
                                               const std::vector<double>& factors,
                                               const Eigen::VectorXd& v) {
  const Eigen::MatrixXd J = eq.tangent(x, factors);
  const Eigen::MatrixXd fd = finite_difference_tangent(eq, x, factors, /*displacement_step=*/1e-7,
                                                       /*pressure_step=*/1e-2);
  EXPECT_LT((J - fd).norm() / fd.norm(), 1e-6);
  EXPECT_LT((eq.tangent_product(x, factors, v) - J * v).norm(), 1e-10 * (J * v).norm());
  EXPECT_TRUE(stored_product_matches(eq.linearize(x, factors).apply(v), J, v));
  EXPECT_LT((Eigen::MatrixXd(eq.sparse_tangent(x, factors)) - J).norm(), 1e-12 * J.norm());
}

// dR/dtheta at x for every parameter of the model's law and the z axis
// factor against central differences of the residual.
inline void expect_parameter_derivatives_match_differences(const model::Model& m,
                                                           const Eigen::VectorXd& x,
                                                           const std::vector<double>& factors) {
  const model::FiberLaw& law = m.material.law;
  std::vector<std::string> names = law.parameter_names();
  names.push_back("factor_z");
  const Eigen::MatrixXd D = model::Equilibrium(m).parameter_derivatives(x, names);
  for (size_t k = 0; k < names.size(); ++k) {
    const bool factor = names[k] == "factor_z";
    auto with = [&](double delta) {
      model::Model changed = m;
      if (factor)
        changed.material.axis_factors.z() += delta;
      else
        changed.material.law.set_parameter(names[k], law.parameter(names[k]) + delta);
      return model::Equilibrium(changed).residual(x, factors);
    };
    const double h = 1e-5 * std::max(1.0, factor ? m.material.axis_factors.z()
                                                 : std::abs(law.parameter(names[k])));
    const Eigen::VectorXd difference = (with(h) - with(-h)) / (2.0 * h);
    EXPECT_LT((D.col(static_cast<Eigen::Index>(k)) - difference).norm(), 1e-6 * difference.norm())
        << names[k];
  }
}

// The model solved by Newton in `steps` steps; the first support group's
// reaction balances the applied load (to 1e-8 of it, which is over 0.01 N).
inline solve::SteppingSummary expect_reaction_balances_load(const model::Model& m, int steps) {
  solve::SteppingOptions newton;
  newton.scheme = solve::Scheme::Newton;
  newton.steps = steps;
  const solve::SteppingSummary run = solve::solve_load_steps(m, newton);
  EXPECT_TRUE(run.success) << run.message;
  if (!run.success) return run;
  const solve::StepRecord& last = run.steps.back();
  const Eigen::Vector3d weight = last.applied_force;
  EXPECT_GT(weight.norm(), 0.01);
  EXPECT_LT((last.reactions[0] + weight).norm(), 1e-8 * weight.norm());
  return run;
}

}  // namespace fiberfluid::testing
