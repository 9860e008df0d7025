// SPDX-License-Identifier: GPL-3.0-or-later
// Coulomb friction at a paddle: its two limits (no friction, frictionless;
// great friction, sticking), Coulomb's law at every contact vertex of a
// solution, the balance of forces and the refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/dof_map.hpp"
#include "fiberfluid/solve/newton/contact_set.hpp"
#include "fiberfluid/solve/newton/newton.hpp"
#include "fiberfluid/solve/stepping.hpp"
#include "model/model_fixtures.hpp"

namespace fiberfluid::solve {
namespace {

using Contact = model::Paddle::Contact;

// The paper's sphere on supports at its bottom, pressed 0.3 from above by a
// paddle with this contact.
model::Model pressed(Contact contact, double friction = 0.0) {
  model::Model m = testing::pressed_sphere();
  m.paddles[0].contact = contact;
  m.material.friction = friction;
  return m;
}

SteppingOptions newton(int steps) {
  SteppingOptions o;
  o.scheme = Scheme::Newton;
  o.steps = steps;
  o.newton.tangent = TangentSolver::Dense;
  o.newton.friction_tolerance = 1e-7;  // Coulomb's law checked to 1e-5 below
  return o;
}

double relative_difference(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return (a - b).norm() / b.norm();
}

TEST(PaddleFriction, NoFrictionIsFrictionlessAndGreatFrictionSticks) {
  const SteppingSummary frictionless = solve_load_steps(pressed(Contact::Frictionless), newton(5));
  const SteppingSummary none = solve_load_steps(pressed(Contact::Coulomb, 0.0), newton(5));
  ASSERT_TRUE(frictionless.success && none.success) << frictionless.message << none.message;
  EXPECT_LT(relative_difference(none.unknowns, frictionless.unknowns), 1e-9);
  EXPECT_EQ(none.steps.back().paddles[0].contacts, frictionless.steps.back().paddles[0].contacts);
  EXPECT_EQ(none.steps.back().paddles[0].sliding, none.steps.back().paddles[0].contacts);

  const SteppingSummary sticking = solve_load_steps(pressed(Contact::Sticking), newton(5));
  const SteppingSummary great = solve_load_steps(pressed(Contact::Coulomb, 1e6), newton(5));
  ASSERT_TRUE(sticking.success && great.success) << sticking.message << great.message;
  EXPECT_LT(relative_difference(great.unknowns, sticking.unknowns), 1e-9);
  EXPECT_EQ(great.steps.back().paddles[0].sliding, 0);
  // The two limits differ: friction is seen at all.
  EXPECT_GT(relative_difference(sticking.unknowns, frictionless.unknowns), 1e-3);
}

// Per step, the state and each contact vertex's force on the body.
struct Path {
  SteppingSummary summary;
  std::vector<Eigen::VectorXd> states;  // from the unloaded body
  std::vector<std::map<int, Eigen::Vector3d>> contact_forces;
};

Path walk(const model::Model& m, int steps) {
  Path path;
  path.states.push_back(Eigen::VectorXd::Zero(m.num_unknowns()));
  path.contact_forces.emplace_back();
  path.summary =
      solve_load_steps(m, newton(steps), [&](const StepRecord& r, const Eigen::VectorXd& x) {
        path.states.push_back(x);
        std::map<int, Eigen::Vector3d> forces;
        for (const StepRecord::HeldForce& held : r.held_forces)
          if (held.paddle == 0) forces[held.vertex] = held.force;
        path.contact_forces.push_back(forces);
      });
  return path;
}

TEST(PaddleFriction, EveryContactObeysCoulombsLaw) {
  const double mu = 0.15;
  const model::Model m = pressed(Contact::Coulomb, mu);
  const int n = m.num_vertices(), steps = 5;
  const Path path = walk(m, steps);
  ASSERT_TRUE(path.summary.success) << path.summary.message;
  int stuck = 0, slid = 0;
  for (int k = 1; k <= steps; ++k) {
    for (const auto& [v, force] : path.contact_forces[static_cast<size_t>(k)]) {
      const double normal = -force.z();  // the paddle pushes down
      ASSERT_GT(normal, 0.0) << "vertex " << v << " step " << k;
      const Eigen::Vector2d tangential = force.head<2>();
      // Within the cone, to the fixed point's tolerance.
      EXPECT_LE(tangential.norm(), mu * normal * (1.0 + 1e-5)) << "vertex " << v << " step " << k;
      const bool in_contact_before = path.contact_forces[static_cast<size_t>(k - 1)].count(v) > 0;
      if (!in_contact_before) continue;
      Eigen::Vector2d increment;
      for (int a = 0; a < 2; ++a)
        increment[a] = path.states[static_cast<size_t>(k)][a * n + v] -
                       path.states[static_cast<size_t>(k - 1)][a * n + v];
      if (tangential.norm() < mu * normal * (1.0 - 1e-4)) {
        // Inside the cone: it stuck over the step.
        EXPECT_LT(increment.norm(), 1e-12) << "vertex " << v << " step " << k;
        ++stuck;
      } else if (increment.norm() > 1e-9) {
        // On the cone's rim: it slid, its friction against its slide.
        EXPECT_LT(tangential.dot(increment), -0.999 * tangential.norm() * increment.norm())
            << "vertex " << v << " step " << k;
        ++slid;
      }
    }
  }
  EXPECT_GT(stuck, 0);  // both kinds are tested
  EXPECT_GT(slid, 0);
  const StepRecord& last = path.summary.steps.back();
  EXPECT_GT(last.paddles[0].sliding, 0);
  EXPECT_LT(last.paddles[0].sliding, last.paddles[0].contacts);
  // The paddle's force (friction in) balances the supports'.
  const Eigen::Vector3d total = last.reactions[0] + last.paddles[0].force + last.applied_force;
  EXPECT_LT(total.norm(), 1e-8 * last.paddles[0].force.norm());
  EXPECT_LT(std::abs(last.volume_drift), 1e-8);
}

// The friction's tangent (what every tangent strategy adds to the bulk's) is
// the derivative of the friction in the residual, by the slide and by the
// normal force: central differences at slides inside the cone, near its rim
// and far past it, vertex by vertex.
TEST(PaddleFriction, TheFrictionsTangentIsTheDerivativeOfItsForce) {
  const model::Model m = pressed(Contact::Coulomb, 0.2);
  const int n = m.num_vertices(), steps = 4;
  const model::DofMap supports = model::DofMap::from_constraints(m);
  ContactSet contacts(m, supports);
  // Press the paddle's plane 0.05 into the sphere: the vertices past it join.
  LoadPoint at = scheduled_point(m, 0.0, steps);
  at.planes[0] -= 0.05;
  const Eigen::VectorXd rest = Eigen::VectorXd::Zero(m.num_unknowns());
  ASSERT_GT(contacts.add_penetrating(at, rest), 2);
  // A residual whose tangential forces exceed 0.2 times the normal ones,
  // each vertex pushed its own way: every contact starts to slide.
  Eigen::VectorXd R = Eigen::VectorXd::Zero(m.num_unknowns()), normal = R;
  std::vector<int> touching;
  for (int v = 0; v < n; ++v) {
    if (contacts.paddle_of()[static_cast<size_t>(v)] < 0) continue;
    touching.push_back(v);
    R[2 * n + v] = normal[2 * n + v] = 1.0 + 0.1 * v / n;  // the body pushes the paddle up
    R[v] = 0.5 * std::cos(v), R[n + v] = 0.5 * std::sin(v);
  }
  ASSERT_EQ(contacts.update_friction(R, rest, 1e-9), static_cast<int>(touching.size()));
  // The friction in a residual whose normal rows are `bulk`'s.
  const auto friction = [&](const Eigen::VectorXd& x, const Eigen::VectorXd& bulk) {
    Eigen::VectorXd out = bulk;
    contacts.add_friction(x, out);
    return Eigen::VectorXd(out - bulk);
  };
  // Slides about 1e-9 (inside the cone: the elastic part is 1e-8 of the
  // sphere's diagonal, 3.5), 1e-8 (near the rim) and 1e-3 (far past it).
  for (double size : {1e-9, 1e-8, 1e-3}) {
    Eigen::VectorXd x = rest;
    for (int v : touching) x[v] = size * std::sin(3.0 * v), x[n + v] = size * std::cos(5.0 * v);
    const AddedTangent tangent = contacts.friction_tangent(x, normal);
    const double h = 1e-4 * size;
    double largest = 0.0, worst = 0.0, largest_mix = 0.0, worst_mix = 0.0;
    for (int v : touching) {
      for (int a = 0; a < 2; ++a) {
        const int d = a * n + v;
        Eigen::VectorXd plus = x, minus = x;
        plus[d] += h;
        minus[d] -= h;
        const Eigen::VectorXd column =
            (friction(plus, normal) - friction(minus, normal)) / (2.0 * h);
        const Eigen::VectorXd exact = tangent.stiffness * Eigen::VectorXd::Unit(x.size(), d);
        largest = std::max(largest, exact.cwiseAbs().maxCoeff());
        worst = std::max(worst, (column - exact).cwiseAbs().maxCoeff());
      }
      // By the normal force, through the mix of the normal row into the
      // tangential ones.
      const int d = 2 * n + v;
      const double dN = 1e-6 * normal[d];
      Eigen::VectorXd more = normal, less = normal;
      more[d] += dN;
      less[d] -= dN;
      const Eigen::VectorXd column = (friction(x, more) - friction(x, less)) / (2.0 * dN);
      const Eigen::VectorXd exact = tangent.row_mix * Eigen::VectorXd::Unit(x.size(), d);
      largest_mix = std::max(largest_mix, exact.cwiseAbs().maxCoeff());
      worst_mix = std::max(worst_mix, (column - exact).cwiseAbs().maxCoeff());
    }
    EXPECT_GT(largest, 0.0) << "slide " << size;
    EXPECT_LT(worst, 1e-6 * largest) << "slide " << size;
    EXPECT_LT(worst_mix, 1e-6 * std::max(largest_mix, 0.2)) << "slide " << size;
    if (size == 1e-3) {
      EXPECT_GT(largest_mix, 0.1);  // every slide past its rim feels N
    }
  }
}

// Each tangent strategy takes the friction's tangent in (the LU ones in
// their factors, the GMRES ones in their operator): all find the same slides.
TEST(PaddleFriction, EveryTangentStrategyFindsTheSameSlides) {
  const model::Model m = pressed(Contact::Coulomb, 0.15);
  const SteppingSummary dense = solve_load_steps(m, newton(5));
  ASSERT_TRUE(dense.success) << dense.message;
  ASSERT_GT(dense.steps.back().paddles[0].sliding, 0);
  for (TangentSolver kind : {TangentSolver::Sparse, TangentSolver::Krylov, TangentSolver::Reused}) {
    SteppingOptions o = newton(5);
    o.newton.tangent = kind;
    const SteppingSummary other = solve_load_steps(m, o);
    ASSERT_TRUE(other.success) << other.message;
    EXPECT_LT(relative_difference(other.unknowns, dense.unknowns), 1e-7);
    EXPECT_EQ(other.steps.back().paddles[0].sliding, dense.steps.back().paddles[0].sliding);
  }
}

// Friction resists the contact's outward slide: the paddle pushes harder the
// more there is, up to the friction at which nothing slides (here below 0.3),
// past which the body sticks.
TEST(PaddleFriction, MoreFrictionPushesHarderBetweenTheLimits) {
  std::vector<double> forces;
  for (const double mu : {0.0, 0.05, 0.1, 0.15}) {
    const SteppingSummary s = solve_load_steps(pressed(Contact::Coulomb, mu), newton(5));
    ASSERT_TRUE(s.success) << "friction " << mu << ": " << s.message;
    forces.push_back(-s.steps.back().paddles[0].force.z());
  }
  const SteppingSummary sticking = solve_load_steps(pressed(Contact::Sticking), newton(5));
  ASSERT_TRUE(sticking.success) << sticking.message;
  forces.push_back(-sticking.steps.back().paddles[0].force.z());
  for (size_t k = 1; k < forces.size(); ++k)
    EXPECT_GT(forces[k], forces[k - 1] * (1.0 + 1e-6)) << "friction step " << k;
  const SteppingSummary enough = solve_load_steps(pressed(Contact::Coulomb, 0.3), newton(5));
  ASSERT_TRUE(enough.success) << enough.message;
  EXPECT_EQ(enough.steps.back().paddles[0].sliding, 0);
  EXPECT_LT(relative_difference(enough.unknowns, sticking.unknowns), 1e-9);
}

TEST(PaddleFriction, ABadCoefficientAndPathBlindUsesAreRefused) {
  const SteppingSummary negative = solve_load_steps(pressed(Contact::Coulomb, -0.1), newton(2));
  EXPECT_FALSE(negative.success);
  EXPECT_NE(negative.message.find("friction coefficient of at least 0"), std::string::npos)
      << negative.message;
  const SteppingSummary nan_friction =
      solve_load_steps(pressed(Contact::Coulomb, std::nan("")), newton(2));
  EXPECT_FALSE(nan_friction.success);

  const model::Model m = pressed(Contact::Coulomb, 0.2);
  EXPECT_FALSE(check_sensitivities(m).ok);
  EXPECT_NE(check_sensitivities(m).message.find("Coulomb friction"), std::string::npos);
  SteppingOptions warm = newton(2);
  warm.warm_start = Eigen::VectorXd::Zero(m.num_unknowns());
  const SteppingSummary refused = solve_load_steps(m, warm);
  EXPECT_FALSE(refused.success);
  EXPECT_NE(refused.message.find("depends on the way there"), std::string::npos) << refused.message;
}

}  // namespace
}  // namespace fiberfluid::solve
