// SPDX-License-Identifier: GPL-3.0-or-later
// The fit target kind "material_test" (experiment/targets/material_test_target.cpp):
// a measured material test fitted by the body's law at material level.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "fiberfluid/experiment/read/schema.hpp"
#include "fiberfluid/experiment/run/fit_setup.hpp"
#include "fiberfluid/experiment/write/fit_files.hpp"
#include "fiberfluid/fit/material_fit.hpp"
#include "fiberfluid/material/material_test.hpp"
#include "fiberfluid/model/material_response.hpp"
#include "fiberfluid/util/error.hpp"
#include "test_support.hpp"

namespace fiberfluid::experiment {
namespace {

nlohmann::json treloar_document() {
  std::ifstream in(testing::experiment_file("fit_treloar_rubber.json"));
  return nlohmann::json::parse(in);
}

std::vector<material::TestPoint> treloar_points() {
  return material::read_material_test(std::string(FIBERFLUID_MEASUREMENTS) +
                                      "/treloar_rubber/treloar1944_uniaxial_equibiaxial.csv");
}

// The shipped experiment: the spline law fitted to Treloar's rubber. The fit
// runs no body, lands where the library's material fit lands, and the fitted
// rubber cylinder then follows its network's curve.
TEST(MaterialTestTarget, FitsTheLawAtMaterialLevelWithoutRunningTheBody) {
  const Experiment ex = load_experiment(testing::experiment_file("fit_treloar_rubber.json"));
  const FitSetup setup = setup_fit(ex);
  const fit::FitResult fitted = setup.calibration->run();
  ASSERT_TRUE(fitted.success) << fitted.message;
  EXPECT_EQ(fitted.forward_runs, 0);
  const model::FiberLaw start = ex.simulation().cases[0].model.material.law;
  fit::FitOptions options;
  options.max_iterations = 300;
  const fit::MaterialFitResult library =
      fit::fit_material_test(fit::material_model(start), treloar_points(), options);
  ASSERT_EQ(fitted.other_targets.size(), 1u);
  const auto& figures = fitted.other_targets[0].figures;
  EXPECT_NEAR(figures.at("rms_relative_misfit"), library.rms, 1e-6);
  EXPECT_EQ(figures.at("points"), 40.0);
  EXPECT_LT(figures.at("rms_relative_misfit_uniaxial"), figures.at("rms_relative_misfit"));
  for (Eigen::Index k = 0; k < library.parameters.size(); ++k)
    EXPECT_NEAR(fitted.values[k], library.parameters[k], 1e-4 * library.parameters.maxCoeff())
        << fitted.names[static_cast<size_t>(k)];

  const Experiment at_fit = with_fitted_material(ex, *setup.calibration, fitted);
  ExperimentResult result = run_experiment(at_fit);
  ASSERT_TRUE(result.runs_succeeded());
  // The points with the fitted stress beside them, as fit_other_0.csv.
  testing::ScratchDir dir;
  write_fit_files(dir.path(), at_fit, setup, fitted, result);
  std::ifstream rows(dir.path() / "fit_other_0.csv");
  std::string header, first;
  std::getline(rows, header);
  std::getline(rows, first);
  EXPECT_EQ(header, "test,stretch,measured_Pa,fitted_Pa,relative_misfit");
  EXPECT_EQ(first.rfind("uniaxial,1.02,25497,", 0), 0u) << first;
  int count = 1;
  for (std::string line; std::getline(rows, line);) ++count;
  EXPECT_EQ(count, 40);
  for (const auto& [name, value] : fit_figures(fitted)) result.figures[name] = value;
  result.checks = check_expected(at_fit, result);
  EXPECT_FALSE(result.checks.empty());
  for (const FigureCheck& c : result.checks) EXPECT_TRUE(c.passed) << c.Describe();
  const model::FiberLaw law = at_fit.simulation().cases[0].model.material.law;
  const double l = 0.7, area = M_PI * 0.025 * 0.025;
  const double curve =
      -model::fiber_network_nominal_stress(law, material::HomogeneousTest::Uniaxial, l) * area;
  const double force = -result.figures.at("paddle_force.upper");
  std::printf(
      "fitted rubber cylinder pressed by 30%%: %.2f N against its network's curve %.2f N "
      "(%+.1f%%)\n",
      force, curve, 100 * (force / curve - 1));
  EXPECT_NEAR(force / curve, 1.0, 0.08);  // the coarse mesh's excess (docs/model.md)
}

// Beside a body's parameter (gamma, which no material test sees) and in log
// scale, the block's Jacobian is the central difference of its residuals.
// A parameter the data cannot see (a material test does not read gamma) is
// held and named; the law's mu keeps its estimate and interval, and the fit
// converges instead of ending "not identifiable".
TEST(MaterialTestTarget, AParameterTheDataCannotSeeIsHeldAndTheOthersKeepTheirIntervals) {
  nlohmann::json doc = treloar_document();
  doc["material"] = {{"law", {{"type", "neo_hookean"}, {"mu", 3e5}}}, {"gamma", 0.5}};
  doc["fit"]["parameters"] = {{{"name", "mu"}},
                              {{"name", "gamma"}, {"lower", 1e-3}, {"upper", 10}}};
  doc.erase("expected");
  const Experiment ex = parse_experiment(doc, testing::experiment_file("").parent_path(), "doc");
  const FitSetup setup = setup_fit(ex);
  const fit::FitResult fitted = setup.calibration->run();
  ASSERT_TRUE(fitted.success) << fitted.message << " " << fitted.status_detail;
  EXPECT_EQ(fitted.status, fit::FitStatus::Converged);
  EXPECT_EQ(fitted.unseen, std::vector<std::string>{"gamma"});
  EXPECT_NE(fitted.status_detail.find("the data cannot see \"gamma\""), std::string::npos)
      << fitted.status_detail;
  EXPECT_DOUBLE_EQ(fitted.values[1], 0.5);  // held where it started
  EXPECT_TRUE(std::isnan(fitted.standard_errors[1]));
  // mu's estimate is the one-parameter fit's, with its interval.
  fit::FitOptions options;
  const fit::MaterialFitResult alone = fit::fit_material_test(
      fit::material_model(model::FiberLaw::neo_hookean(3e5)), treloar_points(), options);
  EXPECT_NEAR(fitted.values[0], alone.parameters[0], 1e-4 * alone.parameters[0]);
  ASSERT_TRUE(std::isfinite(fitted.standard_errors[0]));
  EXPECT_GT(fitted.standard_errors[0], 0.0);
  EXPECT_LT(fitted.lower_95[0], fitted.values[0]);
  EXPECT_GT(fitted.upper_95[0], fitted.values[0]);

  // The same parameter on its bound: named there, the fit "converged at
  // bounds" (exit 4), mu's interval the same.
  doc["material"]["gamma"] = 1e-3;
  const Experiment at_bound =
      parse_experiment(doc, testing::experiment_file("").parent_path(), "doc");
  const fit::FitResult bounded = setup_fit(at_bound).calibration->run();
  ASSERT_TRUE(bounded.success) << bounded.message << " " << bounded.status_detail;
  EXPECT_EQ(bounded.status, fit::FitStatus::ConvergedAtBounds);
  EXPECT_EQ(bounded.at_bounds, std::vector<std::string>{"gamma"});
  EXPECT_NE(bounded.status_detail.find("cannot see \"gamma\" on its bound"), std::string::npos)
      << bounded.status_detail;
  EXPECT_NEAR(bounded.upper_95[0], fitted.upper_95[0], 1e-6 * fitted.upper_95[0]);
}

TEST(MaterialTestTarget, JacobianIsTheCentralDifferenceOfItsMisfits) {
  nlohmann::json d = treloar_document();
  d.erase("expected");
  d["material"] = {{"law", {{"type", "neo_hookean"}, {"mu", 2e5}}}, {"gamma", 5.0}};
  d["fit"]["parameters"] = {{{"name", "mu"}}, {{"name", "gamma"}}};
  const Experiment ex = parse_experiment(d, testing::experiment_file("").parent_path(), "doc");
  const FitSetup setup = setup_fit(ex);
  const Eigen::VectorXd phi = setup.calibration->parameters().initial_phi();
  const fit::Evaluation e = setup.calibration->evaluate(phi, true);
  ASSERT_TRUE(e.ok) << e.message;
  ASSERT_EQ(e.jacobian.rows(), 40);
  for (Eigen::Index k = 0; k < phi.size(); ++k) {
    const double h = 1e-5;
    Eigen::VectorXd up = phi, down = phi;
    up[k] += h, down[k] -= h;
    const Eigen::VectorXd difference = (setup.calibration->evaluate(up, false).residuals -
                                        setup.calibration->evaluate(down, false).residuals) /
                                       (2 * h);
    EXPECT_LT((e.jacobian.col(k) - difference).norm(), 1e-6 * (1.0 + difference.norm())) << k;
  }
  EXPECT_EQ(e.jacobian.col(1).norm(), 0.0);  // gamma
  EXPECT_GT(e.jacobian.col(0).norm(), 0.1);
}

TEST(MaterialTestTarget, BadFilesAndFieldsAreRefusedNamingThem) {
  const auto expect_error = [](const nlohmann::json& d, const std::string& part) {
    try {
      setup_fit(parse_experiment(d, testing::experiment_file("").parent_path(), "doc"));
      ADD_FAILURE() << "no error, expected one mentioning '" << part << "'";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  };
  nlohmann::json d = treloar_document();
  d["fit"]["targets"][0]["file"] = "no_such_test.csv";
  expect_error(d, "fit.targets[0].file");
  d = treloar_document();
  d["fit"]["targets"][0]["colour"] = "red";
  expect_error(d, "colour");
  d = treloar_document();
  d["fit"]["targets"][0]["weight"] = -1;
  expect_error(d, "fit.targets[0].weight");
  testing::ScratchDir dir;
  {
    std::ofstream out(dir.path() / "unloaded.csv");
    out << "test,stretch,nominal_stress_Pa\nuniaxial,1,0\n";
  }
  d = treloar_document();
  d["fit"]["targets"][0]["file"] = (dir.path() / "unloaded.csv").string();
  expect_error(d, "holds no loaded point");
  const nlohmann::json fields =
      experiment_schema()["properties"]["fit"]["properties"]["targets"]["items"]["properties"];
  EXPECT_NE(fields["type"].dump().find("material_test"), std::string::npos) << fields["type"];
  EXPECT_TRUE(fields.contains("file"));
}

}  // namespace
}  // namespace fiberfluid::experiment
