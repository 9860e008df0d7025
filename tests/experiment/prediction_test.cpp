// SPDX-License-Identifier: GPL-3.0-or-later
// fiberfluid predict (run/prediction.hpp): an experiment at a fit's values,
// its bands from the fit's covariance through the Newton sensitivities,
// against finite differences of whole runs at the intervals' ends.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>

#include "fiberfluid/experiment/experiment.hpp"
#include "fiberfluid/experiment/run/prediction.hpp"
#include "fiberfluid/experiment/run/runner.hpp"
#include "fiberfluid/experiment/write/csv_tables.hpp"
#include "fiberfluid/solve/stepping.hpp"
#include "fiberfluid/util/error.hpp"
#include "test_support.hpp"

namespace fiberfluid::experiment {
namespace {

using json = nlohmann::json;

// A small cylinder (80 vertices) of an exponential law pressed by 10%
// between frictionless platens in 3 Newton steps.
json pressed_cylinder() {
  return json::parse(R"({
    "name": "pressed",
    "surface": {"generator": "cylinder", "radius": 0.025, "length": 0.03, "segments": [3, 13]},
    "material": {"law": {"type": "exponential", "Y0": 30000, "beta": 0}, "gamma": 0.001},
    "fibers": {"kinematics": "central", "horizon": 0.03},
    "supports": [{"label": "centre", "box": {"min": [-1e-7, -1e-7, -1e-7],
                                            "max": [1e-7, 1e-7, 1e-7]}}],
    "paddles": [{"label": "lower", "axis": "x", "side": "below", "travel": 0},
                {"label": "upper", "axis": "x", "side": "above", "travel": -0.003}],
    "stepping": {"scheme": "newton", "steps": 3}
  })");
}

// A fit.json as `fiberfluid fit` writes it: Y0 (log-scaled) and beta,
// correlated.
json fit_document(double se_Y0 = 2500.0) {
  return {{"experiment", "fitted"},
          {"status", "converged"},
          {"success", true},
          {"parameters",
           {{{"name", "Y0"}, {"value", 50000.0}, {"standard_error", se_Y0}, {"log_scale", true}},
            {{"name", "beta"}, {"value", 2.0}, {"standard_error", 0.4}, {"log_scale", false}}}},
          {"correlation", {{1.0, -0.6}, {-0.6, 1.0}}}};
}

struct Predicted {
  Experiment experiment;
  ExperimentResult result;
  std::vector<RunBands> bands;
};

Predicted predict(const json& experiment, const FittedEstimate& estimate) {
  Predicted p{parse_experiment(experiment, ".", "pressed.json"), {}, {}};
  apply_estimate(estimate, p.experiment);
  std::vector<std::vector<Eigen::VectorXd>> unknowns(1);
  p.result = run_experiment(p.experiment,
                            [&](size_t, const solve::StepRecord& r, const Eigen::VectorXd& x) {
                              if (r.step >= 1) unknowns[0].push_back(x);
                            });
  p.bands = prediction_bands(p.experiment, p.result, estimate, unknowns);
  return p;
}

// The upper paddle's push along x after the last step, at parameters `values`.
double final_force(const json& experiment, const std::vector<std::pair<std::string, double>>& at) {
  Experiment ex = parse_experiment(experiment, ".", "pressed.json");
  Case& c = ex.simulation().cases.front();
  for (const auto& [name, value] : at) c.model.material.set_parameter(name, value);
  const solve::SteppingSummary run = solve::solve_load_steps(c.model, c.stepping);
  EXPECT_TRUE(run.success) << run.message;
  return run.steps.back().paddles[1].force[0];
}

TEST(Prediction, TheBandIsTheCovarianceCarriedByFiniteDifferencesOfWholeRuns) {
  const testing::ScratchDir dir;
  dir.write("fit.json", fit_document().dump());
  const FittedEstimate estimate = read_fitted_estimate(dir.path());
  ASSERT_EQ(estimate.banded.size(), 2u);
  // The covariance of (log Y0, beta): sd 0.05 and 0.4, correlation -0.6.
  EXPECT_NEAR(estimate.covariance(0, 0), 0.05 * 0.05, 1e-15);
  EXPECT_NEAR(estimate.covariance(0, 1), -0.6 * 0.05 * 0.4, 1e-15);

  const Predicted p = predict(pressed_cylinder(), estimate);
  ASSERT_TRUE(p.result.runs_succeeded()) << p.result.runs[0].summary.message;
  const Band force = p.bands[0].figures.at("paddle_force.upper");
  EXPECT_DOUBLE_EQ(force.value, p.result.runs[0].summary.steps.back().paddles[1].force[0]);
  ASSERT_TRUE(std::isfinite(force.sd));

  // Whole runs at each fitted variable's 95% interval ends (log Y0 +- 1.96
  // 0.05, beta +- 1.96 0.4): their central differences carried through the
  // same covariance.
  const double Y0 = 5e4, beta = 2.0, hY = 1.96 * 0.05, hb = 1.96 * 0.4;
  const json ex = pressed_cylinder();
  const double dY = (final_force(ex, {{"Y0", Y0 * std::exp(hY)}, {"beta", beta}}) -
                     final_force(ex, {{"Y0", Y0 * std::exp(-hY)}, {"beta", beta}})) /
                    (2 * hY);
  const double db = (final_force(ex, {{"Y0", Y0}, {"beta", beta + hb}}) -
                     final_force(ex, {{"Y0", Y0}, {"beta", beta - hb}})) /
                    (2 * hb);
  const Eigen::Vector2d g(dY, db);
  const double sd = std::sqrt(g.dot(estimate.covariance * g));
  std::printf("upper paddle force %.4f N: band sd %.5f N (Newton), %.5f N (whole runs)\n",
              force.value, force.sd, sd);
  EXPECT_NEAR(force.sd, sd, 0.02 * sd);
  EXPECT_NEAR(force.upper95() - force.lower95(), 2 * 1.96 * sd, 0.04 * sd);
  // A force proportional to Y0 has d F / d log Y0 = F.
  EXPECT_NEAR(dY, force.value, 0.01 * std::abs(force.value));

  // Every step's row: the banded columns of steps.csv.
  ASSERT_EQ(p.bands[0].steps.size(), 3u);
  for (const char* column : {"pressure_Pa", "max_displacement_m", "paddle_upper_force_x_N",
                             "paddle_lower_force_x_N", "reaction_centre_x_N"})
    EXPECT_TRUE(p.bands[0].steps.back().count(column)) << column;
  EXPECT_TRUE(std::isfinite(p.bands[0].figures.at("max_displacement").sd));
}

TEST(Prediction, AParameterWithoutAStandardErrorIsHeldAndNamed) {
  const testing::ScratchDir dir;
  json doc = fit_document();
  doc["parameters"][1]["standard_error"] = nullptr;  // beta on its bound
  dir.write("fit.json", doc.dump());
  const FittedEstimate estimate = read_fitted_estimate(dir.path());
  ASSERT_EQ(estimate.banded, std::vector<std::string>{"Y0"});
  ASSERT_EQ(estimate.held.size(), 1u);
  EXPECT_NE(estimate.held[0].find("beta"), std::string::npos);
  const Predicted p = predict(pressed_cylinder(), estimate);
  ASSERT_TRUE(p.result.runs_succeeded());
  // With log Y0 alone banded, a force proportional to Y0 has sd F * 0.05.
  const Band force = p.bands[0].figures.at("paddle_force.upper");
  EXPECT_NEAR(force.sd, 0.05 * std::abs(force.value), 0.01 * 0.05 * std::abs(force.value));
}

// The cells of each line of a CSV without quoted cells.
std::vector<std::vector<std::string>> csv_rows(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    rows.emplace_back();
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) rows.back().push_back(cell);
  }
  return rows;
}

TEST(Prediction, BandColumnsStandBesideTheirColumns) {
  const testing::ScratchDir dir;
  dir.write("fit.json", fit_document().dump());
  Predicted p = predict(pressed_cylinder(), read_fitted_estimate(dir.path()));
  ASSERT_TRUE(p.result.runs_succeeded());
  const Case& c = p.experiment.simulation().cases.front();
  RunResult run = p.result.runs[0];
  const auto plain = csv_rows(steps_csv(c, run));
  run.bands = p.bands[0];
  const auto banded = csv_rows(steps_csv(c, run));
  ASSERT_EQ(banded.size(), 4u);  // the header and three steps

  // Each banded column is followed by its two ends; the others are as before.
  const std::vector<std::string>& header = banded[0];
  size_t plain_column = 0;
  for (size_t k = 0; k < header.size(); ++k, ++plain_column) {
    ASSERT_LT(plain_column, plain[0].size());
    ASSERT_EQ(header[k], plain[0][plain_column]);
    const bool has_band = p.bands[0].steps.back().count(header[k]) > 0;
    if (!has_band) {
      for (size_t r = 1; r < banded.size(); ++r) EXPECT_EQ(banded[r][k], plain[r][plain_column]);
      continue;
    }
    ASSERT_LT(k + 2, header.size());
    EXPECT_EQ(header[k + 1], header[k] + "_lower95");
    EXPECT_EQ(header[k + 2], header[k] + "_upper95");
    for (size_t r = 1; r < banded.size(); ++r) {
      const Band& b = p.bands[0].steps[r - 1].at(header[k]);
      EXPECT_DOUBLE_EQ(std::stod(banded[r][k + 1]), b.lower95()) << header[k] << " row " << r;
      EXPECT_DOUBLE_EQ(std::stod(banded[r][k + 2]), b.upper95()) << header[k] << " row " << r;
      EXPECT_LE(b.lower95(), b.upper95());  // equal where symmetry zeroes a component
    }
    k += 2;
  }
  EXPECT_EQ(plain_column, plain[0].size());
  const auto force = std::find(header.begin(), header.end(), "paddle_upper_force_x_N");
  ASSERT_NE(force, header.end());
  EXPECT_EQ(*(force + 1), "paddle_upper_force_x_N_lower95");
  EXPECT_GT(p.bands[0].steps.back().at("paddle_upper_force_x_N").sd, 0.0);
}

TEST(Prediction, WhatCannotBePredictedIsRefusedByName) {
  const testing::ScratchDir dir;
  const auto refusal = [&](const json& fit, const json& experiment) {
    dir.write("fit.json", fit.dump());
    try {
      const FittedEstimate estimate = read_fitted_estimate(dir.path());
      Experiment ex = parse_experiment(experiment, ".", "pressed.json");
      apply_estimate(estimate, ex);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(refusal(fit_document(), pressed_cylinder()), "accepted");
  const json ok = fit_document();
  {
    const std::filesystem::path empty = dir.path() / "empty";
    std::filesystem::create_directories(empty);
    try {
      read_fitted_estimate(empty);
      ADD_FAILURE() << "a folder without fit.json was read";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("fit.json"), std::string::npos) << e.what();
    }
  }
  json failed = ok;
  failed["success"] = false;
  failed["status"] = "no_convergence";
  EXPECT_NE(refusal(failed, pressed_cylinder()).find("without converging"), std::string::npos);
  json bad = ok;
  bad["correlation"] = {{1.0}};
  EXPECT_NE(refusal(bad, pressed_cylinder()).find("correlation"), std::string::npos);
  bad = ok;
  bad["parameters"][0].erase("log_scale");
  EXPECT_NE(refusal(bad, pressed_cylinder()).find("parameters[0].log_scale"), std::string::npos);
  json other = ok;
  other["parameters"][1]["name"] = "mu";
  EXPECT_NE(refusal(other, pressed_cylinder()).find("\"mu\""), std::string::npos);
  json sticking = pressed_cylinder();
  sticking["paddles"][1]["contact"] = "sticking";
  EXPECT_NE(refusal(ok, sticking).find("predict cannot band this run"), std::string::npos);
  json incremental = pressed_cylinder();
  for (const char* field : {"paddles", "fibers"}) incremental.erase(field);
  incremental["loads"] = {
      {{"type", "gravity"}, {"acceleration", {0, 0, -9.81}}, {"density", 1000}}};
  incremental["stepping"] = {{"steps", 3}};  // the paper's incremental scheme
  EXPECT_NE(refusal(ok, incremental).find("stepping.scheme"), std::string::npos);
}

}  // namespace
}  // namespace fiberfluid::experiment
