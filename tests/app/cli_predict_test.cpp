// SPDX-License-Identifier: GPL-3.0-or-later
// `fiberfluid predict`: a fit folder and an experiment in, the run with its
// bands out; bad input named, with nothing written.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "app/cli_support.hpp"
#include "test_support.hpp"

namespace fiberfluid {
namespace {

using testing::Outcome;
using testing::run_cli;
using testing::ScratchDir;

constexpr const char* kPressed = R"({
  "name": "pressed",
  "surface": {"generator": "cylinder", "radius": 0.025, "length": 0.03, "segments": [3, 13]},
  "material": {"law": {"type": "exponential", "Y0": 30000, "beta": 0}, "gamma": 0.001},
  "fibers": {"kinematics": "central", "horizon": 0.03},
  "supports": [{"label": "centre", "box": {"min": [-1e-7, -1e-7, -1e-7], "max": [1e-7, 1e-7, 1e-7]}}],
  "paddles": [{"label": "lower", "axis": "x", "side": "below", "travel": 0},
              {"label": "upper", "axis": "x", "side": "above", "travel": -0.003}],
  "stepping": {"scheme": "newton", "steps": 3}
})";

constexpr const char* kFit = R"({
  "experiment": "fitted", "status": "converged", "success": true,
  "parameters": [{"name": "Y0", "value": 50000, "standard_error": 2500, "log_scale": true},
                 {"name": "beta", "value": 2, "standard_error": 0.4, "log_scale": false}],
  "correlation": [[1, -0.6], [-0.6, 1]]
})";

TEST(CliPredict, WritesTheRunWithBandsBesideEachForce) {
  const ScratchDir dir;
  const std::filesystem::path fit = dir.path() / "fit";
  std::filesystem::create_directories(fit);
  std::ofstream(fit / "fit.json") << kFit;
  const std::filesystem::path experiment = dir.write("pressed.json", kPressed);
  const std::filesystem::path measured =
      dir.write("measured.csv", "# made up\ntravel,force\n1,0.8\n2,1.5\n3,2.3\n");
  const std::filesystem::path out = dir.path() / "out";
  const Outcome o = run_cli("predict " + fit.string() + " " + experiment.string() + " -q -o " +
                            out.string() + " --measured " + measured.string());
  ASSERT_EQ(o.status, 0) << o.output;
  EXPECT_NE(o.output.find("paddle_force.upper = "), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("(95%: "), std::string::npos) << o.output;
  std::ifstream steps(out / "steps.csv");
  std::string header;
  std::getline(steps, header);
  for (const char* column : {"paddle_upper_force_x_N,paddle_upper_force_x_N_lower95,"
                             "paddle_upper_force_x_N_upper95",
                             "reaction_centre_x_N,reaction_centre_x_N_lower95"})
    EXPECT_NE(header.find(column), std::string::npos) << header;
  std::ifstream summary_file(out / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  const nlohmann::json& band = summary["prediction"]["runs"][0]["figures"]["paddle_force.upper"];
  EXPECT_LT(band["lower95"].get<double>(), band["value"].get<double>());
  EXPECT_GT(band["upper95"].get<double>(), band["value"].get<double>());
  // The run is at the fit's values, and so is the folder's record of it.
  std::ifstream resolved_file(out / "experiment.resolved.json");
  const nlohmann::json resolved = nlohmann::json::parse(resolved_file);
  EXPECT_DOUBLE_EQ(resolved["material"]["law"]["Y0"].get<double>(), 50000.0);
  EXPECT_DOUBLE_EQ(resolved["material"]["law"]["beta"].get<double>(), 2.0);
}

TEST(CliPredict, BadInputIsNamedAndNothingIsWritten) {
  const ScratchDir dir;
  const std::filesystem::path experiment = dir.write("pressed.json", kPressed);
  const std::filesystem::path out = dir.path() / "out";
  const Outcome missing = run_cli("predict " + (dir.path() / "nofit").string() + " " +
                                  experiment.string() + " -q -o " + out.string());
  EXPECT_EQ(missing.status, 1) << missing.output;
  EXPECT_NE(missing.output.find("fit.json: no such file"), std::string::npos) << missing.output;
  const std::filesystem::path fit = dir.path() / "fit";
  std::filesystem::create_directories(fit);
  std::ofstream(fit / "fit.json") << kFit;
  const Outcome no_csv = run_cli("predict " + fit.string() + " " + experiment.string() + " -q -o " +
                                 out.string() + " --measured nothing.csv");
  EXPECT_EQ(no_csv.status, 1) << no_csv.output;
  EXPECT_NE(no_csv.output.find("nothing.csv: no such file"), std::string::npos) << no_csv.output;
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace fiberfluid
