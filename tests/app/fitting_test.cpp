// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/fitting.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "app/outputs.hpp"
#include "geom/error.hpp"
#include "test_support.hpp"

namespace fiberfluid::app {
namespace {

// The fit experiments as `fiberfluid fit` runs them: calibrate, run at the
// fitted values, check the expected figures.
class FitExperiment : public ::testing::TestWithParam<const char*> {};

TEST_P(FitExperiment, RecoversItsParametersAndMeetsItsExpectedFigures) {
  const Experiment ex = load_experiment(testing::experiment_file(GetParam()));
  const FitSetup setup = setup_fit(ex);
  const fit::FitResult fitted = setup.calibration->run();
  ASSERT_TRUE(fitted.success) << fitted.message;
  const Experiment at_fit = with_fitted_material(ex, *setup.calibration, fitted);
  ExperimentResult result = run_experiment(at_fit);
  ASSERT_TRUE(result.runs_succeeded());
  for (const auto& [name, value] : fit_figures(fitted)) result.figures[name] = value;
  result.checks = check_expected(at_fit, result);
  EXPECT_FALSE(result.checks.empty());
  for (const FigureCheck& c : result.checks) EXPECT_TRUE(c.passed) << c.Describe();

  testing::ScratchDir dir;
  write_fit_files(dir.path(), at_fit, setup, fitted, result);
  std::ifstream in(dir.path() / "fit.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_EQ(report["parameters"].size(), fitted.names.size());
  EXPECT_TRUE(report["success"].get<bool>());
  EXPECT_EQ(report["targets"].size(), setup.targets.size());
  for (const char* file : {"fit_iterations.csv", "fit_distances.csv", "fit_target_0.vtu"})
    EXPECT_TRUE(std::filesystem::exists(dir.path() / file)) << file;
}

INSTANTIATE_TEST_SUITE_P(Experiments, FitExperiment,
                         ::testing::Values("fit_sphere.json", "fit_synthetic_liver_exact.json",
                                           "fit_liver_fem.json"));

nlohmann::json sphere_fit_document() {
  std::ifstream in(testing::experiment_file("fit_sphere.json"));
  return nlohmann::json::parse(in);
}

void expect_fit_error(const nlohmann::json& document, const std::string& part) {
  try {
    const Experiment ex = parse_experiment(document, testing::experiment_file("").parent_path(), "doc");
    setup_fit(ex);
    ADD_FAILURE() << "no error, expected one mentioning '" << part << "'";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

TEST(FitConfig, BadFitSectionsAreNamed) {
  nlohmann::json d = sphere_fit_document();
  d["fit"]["parameters"][0]["name"] = "stiffness";
  expect_fit_error(d, "doc: fit.parameters[0].name: \"stiffness\" is not a parameter");
  d = sphere_fit_document();
  d["fit"]["parameters"][0]["lower"] = 5000;
  expect_fit_error(d, "the start 1000 lies outside the bounds [5000, 1e+06]");
  d = sphere_fit_document();
  d["fit"]["targets"][0]["file"] = "no_such_scan.obj";
  expect_fit_error(d, "doc: fit.targets[0].file");
  d = sphere_fit_document();
  d["fit"]["targets"][0]["step"] = 11;
  expect_fit_error(d, "fit.targets[0].step: load step 11 is beyond the run's 10 steps");
  d = sphere_fit_document();
  d["fit"]["method"] = "newton";
  expect_fit_error(d, "fit.method: expected one of");
  d = sphere_fit_document();
  d["fit"]["objective"] = {{"exclude", {{"where", "z >= -2"}}}};
  expect_fit_error(d, "excludes every vertex");
  d = sphere_fit_document();
  d["fit"]["colour"] = "green";
  expect_fit_error(d, "fit.colour: unknown field");
  d = sphere_fit_document();
  d["fit"]["initial_trust_region_radius"] = 0;
  expect_fit_error(d, "fit.initial_trust_region_radius");
  d = sphere_fit_document();
  d["variants"] = {{{"name", "a"}}};
  expect_fit_error(d, "a fit calibrates one simulation");
}

}  // namespace
}  // namespace fiberfluid::app
