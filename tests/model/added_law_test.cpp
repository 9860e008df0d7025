// SPDX-License-Identifier: GPL-3.0-or-later
// The proof that the fiber physics has one door (issue 22): a law written in
// this file alone, registered from outside the library, goes through the
// stencil, the kernels, Newton's residual and tangent, dR/dtheta, the
// sensitivities and the JSON reader without a change to any of them.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>

#include "fiberfluid/experiment/experiment.hpp"
#include "fiberfluid/model/equilibrium.hpp"
#include "fiberfluid/solve/stepping.hpp"
#include "fiberfluid/solve/tangent/tangent_solve.hpp"
#include "model/model_fixtures.hpp"

namespace fiberfluid {
namespace {

// sigma(e) = Y0 (e + c e^3): a fiber that stiffens symmetrically in tension
// and compression, so Y(e) = Y0 (1 + c e^2).
class CubicLaw final : public model::LawModel {
 public:
  std::string name() const override { return "cubic_test_law"; }
  std::vector<std::string> parameter_names() const override { return {"Y0", "c"}; }
  double modulus(const double* p, double e) const override { return p[0] * (1.0 + p[1] * e * e); }
  double slope(const double* p, double e) const override { return 2.0 * p[0] * p[1] * e; }
  double modulus_derivative(const double* p, int k, double e) const override {
    return k == 0 ? 1.0 + p[1] * e * e : p[0] * e * e;
  }
};

std::shared_ptr<const model::LawModel> cubic_law() {
  static const std::shared_ptr<const model::LawModel> law = [] {
    auto made = std::make_shared<const CubicLaw>();
    model::register_law(made);
    return made;
  }();
  return law;
}

model::Model hanging_sphere(double Y0, double c) {
  model::Model m = testing::paper_sphere_model();
  m.material.law = model::FiberLaw(cubic_law(), {Y0, c});
  m.loads.resize(1);  // gravity only
  m.loads[0].density = 300.0;
  return m;
}

Eigen::VectorXd random_state(const model::Model& m, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::VectorXd x(m.num_unknowns());
  for (Eigen::Index k = 0; k < x.size(); ++k) x[k] = 0.05 * uniform(rng);
  x[m.pressure_dof()] = 500.0 * uniform(rng);
  return x;
}

TEST(AddedLaw, TangentAndParameterDerivativesMatchCentralDifferences) {
  const model::Model m = hanging_sphere(3000.0, 40.0);
  const model::Equilibrium eq(m);
  const Eigen::VectorXd x = random_state(m, 7);
  const std::vector<double> factors = {0.6};
  const Eigen::MatrixXd J = eq.tangent(x, factors);
  const Eigen::VectorXd v = random_state(m, 8);
  Eigen::VectorXd fd_product = Eigen::VectorXd::Zero(x.size());
  const double h = 1e-6;
  fd_product = (eq.residual(x + h * v, factors) - eq.residual(x - h * v, factors)) / (2.0 * h);
  EXPECT_LT((J * v - fd_product).norm(), 1e-6 * fd_product.norm());
  EXPECT_LT((eq.linearize(x, factors).apply(v) - J * v).norm(), 1e-10 * (J * v).norm());

  const Eigen::MatrixXd D = eq.parameter_derivatives(x, {"Y0", "c"});
  for (int k = 0; k < 2; ++k) {
    const std::string name = k == 0 ? "Y0" : "c";
    const double step = k == 0 ? 1.0 : 1e-3;
    model::Model plus = m, minus = m;
    plus.material.law.set_parameter(name, m.material.law.parameter(name) + step);
    minus.material.law.set_parameter(name, m.material.law.parameter(name) - step);
    const Eigen::VectorXd fd = (model::Equilibrium(plus).residual(x, factors) -
                                model::Equilibrium(minus).residual(x, factors)) /
                               (2.0 * step);
    EXPECT_LT((D.col(k) - fd).norm(), 1e-7 * fd.norm()) << name;
    EXPECT_GT(fd.norm(), 0.0) << name;
  }
}

TEST(AddedLaw, NewtonConvergesAndItsSensitivitiesMatchWholeRuns) {
  const model::Model m = hanging_sphere(3000.0, 40.0);
  solve::SteppingOptions o;
  o.scheme = solve::Scheme::Newton;
  o.steps = 2;
  o.newton.residual_tolerance = 1e-13;
  o.keep_final_tangent = true;
  const solve::SteppingSummary s = solve::solve_load_steps(m, o);
  ASSERT_TRUE(s.success) << s.message;
  // The law is not the constant one: it must move the answer away from it.
  model::Model linear = m;
  linear.material.law = model::FiberLaw::constant(3000.0);
  solve::SteppingOptions plain = o;
  plain.newton.residual_tolerance = solve::SteppingOptions().newton.residual_tolerance;
  const solve::SteppingSummary l = solve::solve_load_steps(linear, plain);
  ASSERT_TRUE(l.success) << l.message;
  EXPECT_GT((s.unknowns - l.unknowns).head(m.num_unknowns() - 1).norm(),
            1e-4 * l.unknowns.head(m.num_unknowns() - 1).norm());

  const Eigen::VectorXd dR = model::Equilibrium(m).parameter_derivatives(s.unknowns, {"c"});
  Eigen::VectorXd du;
  ASSERT_TRUE(s.final_tangent->solve_full(-dR, &du).ok);
  auto solve_with = [&](double c) {
    model::Model changed = m;
    changed.material.law.set_parameter("c", c);
    solve::SteppingOptions plain = o;
    plain.keep_final_tangent = false;
    return solve::solve_load_steps(changed, plain).unknowns;
  };
  const double h = 0.05;
  const Eigen::VectorXd fd = (solve_with(40.0 + h) - solve_with(40.0 - h)) / (2.0 * h);
  EXPECT_GT(fd.norm(), 0.0);
  EXPECT_LT((du - fd).norm(), 1e-5 * fd.norm());
}

TEST(AddedLaw, ExperimentFilesNameItByItsTypeAndCheckItsParameters) {
  cubic_law();
  const nlohmann::json document = nlohmann::json::parse(R"({
    "name": "cubic",
    "surface": {"generator": "icosphere", "subdivisions": 1, "radius": 1.0},
    "material": {"law": {"type": "cubic_test_law", "Y0": 2500, "c": 12}},
    "supports": [{"where": "z >= 0.5"}],
    "loads": [{"type": "gravity", "acceleration": [0, 0, -9.81]}],
    "stepping": {"steps": 2, "scheme": "newton"}
  })");
  const experiment::Experiment ex = experiment::parse_experiment(document, ".", "cubic.json");
  const model::FiberLaw& law = ex.simulation().cases[0].model.material.law;
  EXPECT_EQ(law.name(), "cubic_test_law");
  EXPECT_EQ(law.parameter("c"), 12.0);
  EXPECT_DOUBLE_EQ(law.modulus(0.1), 2500.0 * 1.12);
  // Its parameters are the material's, so a fit can name them.
  EXPECT_TRUE(ex.simulation().cases[0].model.material.has_parameter("c"));

  nlohmann::json missing = document;
  missing["material"]["law"].erase("c");
  try {
    experiment::parse_experiment(missing, ".", "cubic.json");
    ADD_FAILURE() << "a missing parameter was accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("c"), std::string::npos) << e.what();
  }
  // A name cannot be registered twice, nor take a built-in's.
  EXPECT_THROW(model::register_law(std::make_shared<const CubicLaw>()), std::invalid_argument);
}

}  // namespace
}  // namespace fiberfluid
