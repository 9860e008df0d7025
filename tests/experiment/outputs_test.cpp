// SPDX-License-Identifier: GPL-3.0-or-later
// Sweeps, reactions, CSV tables and output folders, through the library.
#include "fiberfluid/experiment/write/outputs.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "fiberfluid/experiment/experiment.hpp"
#include "fiberfluid/experiment/run/runner.hpp"
#include "fiberfluid/util/error.hpp"
#include "test_support.hpp"

namespace fiberfluid::experiment {
namespace {

using nlohmann::json;
using testing::ScratchDir;

json small_config() {
  return json::parse(R"({
    "name": "small",
    "surface": {"generator": "icosphere", "subdivisions": 1, "radius": 0.05},
    "material": {"Y": 20000, "gamma": 1},
    "supports": [{"where": "z >= 0.04", "label": "top"}],
    "loads": [{"type": "gravity", "label": "g", "acceleration": [0, 0, -9.81]}],
    "stepping": {"steps": 3}
  })");
}

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::vector<std::vector<std::string>> read_csv(const std::filesystem::path& path) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(read_text(path));
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells;
    std::istringstream cells_in(line);
    for (std::string cell; std::getline(cells_in, cell, ',');) cells.push_back(cell);
    rows.push_back(cells);
  }
  return rows;
}

Experiment parse(const json& config) { return parse_experiment(config, ".", "test.json"); }

void expect_error(const json& config, const std::string& part) {
  try {
    parse(config);
    ADD_FAILURE() << "no error, expected one mentioning '" << part << "'";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

TEST(Sweep, EachVariantIsTheBaseWithItsMergePatch) {
  json c = small_config();
  c["variants"] = json::parse(R"([
    {"name": "soft", "material": {"Y": 10000}},
    {"name": "pushed", "loads": [{"type": "point", "vertex": 0, "force": [0, 1, 0]}],
     "supports": [{"where": "z <= -0.04", "label": "bottom"}], "stepping": {"steps": 5}},
    {"name": "no_tension", "material": {"gamma": null}}
  ])");
  const Experiment ex = parse(c);
  ASSERT_EQ(ex.simulation().cases.size(), 3u);
  EXPECT_TRUE(ex.sweeps());
  EXPECT_EQ(ex.simulation().cases[0].model.material.young_modulus().x(), 10000.0);
  EXPECT_EQ(ex.simulation().cases[0].model.material.surface_tension, 1.0);  // kept from the base
  EXPECT_EQ(ex.simulation().cases[0].stepping.steps, 3);
  EXPECT_EQ(ex.simulation().cases[1].model.loads.size(), 1u);  // a list is replaced whole
  EXPECT_EQ(ex.simulation().cases[1].model.loads[0].kind, model::Load::Kind::Point);
  EXPECT_EQ(ex.simulation().cases[1].model.constraint_groups, std::vector<std::string>{"bottom"});
  EXPECT_EQ(ex.simulation().cases[1].stepping.steps, 5);
  EXPECT_EQ(ex.simulation().cases[1].model.material.young_modulus().x(), 20000.0);
  EXPECT_EQ(ex.simulation().cases[2].model.material.surface_tension,
            0.0);  // null removes the field
  EXPECT_EQ(ex.simulation().cases[1].patch["stepping"]["steps"], 5);
}

TEST(Sweep, BadVariantsAreNamed) {
  json c = small_config();
  c["variants"] = {{{"name", "soft"}, {"material", {{"Y", "soft"}}}}};
  expect_error(c, "test.json [variant soft]: material.Y: expected a number");
  c["variants"] = {{{"name", "a"}}, {{"name", "a"}}};
  expect_error(c, "variants[1].name: \"a\" names another variant already");
  c["variants"] = {{{"name", "../up"}}};
  expect_error(c, "variants[0].name: expected a name of letters, digits");
  c["variants"] = {{{"name", "x"}, {"expected", json::array()}}};
  expect_error(c, "variants[0].expected: belongs to the whole experiment");
  c["variants"] = json::array();
  expect_error(c, "variants: expected a non-empty list");
  c["variants"] = {{{"name", "x"}, {"colour", "red"}}};
  expect_error(c, "[variant x]: colour: unknown field");
}

TEST(Sweep, ParallelVariantsGiveTheSerialNumbers) {
  const Experiment ex = load_experiment(testing::experiment_file("liver_sweep.json"));
  RunOptions serial, parallel;
  serial.jobs = 1;
  parallel.jobs = 2;
  const ExperimentResult a = run_experiment(ex, {}, serial);
  const ExperimentResult b = run_experiment(ex, {}, parallel);
  ASSERT_TRUE(a.runs_succeeded() && b.runs_succeeded());
  for (const auto& [name, value] : a.figures)
    EXPECT_NEAR(b.figures.at(name), value, 1e-12 * std::abs(value)) << name;
}

TEST(Reactions, TheLiverIsInEquilibrium) {
  const Experiment ex = load_experiment(testing::experiment_file("liver_gravity.json"));
  const ExperimentResult result = run_experiment(ex);
  ASSERT_TRUE(result.runs_succeeded());
  for (const solve::StepRecord& r : result.runs[0].summary.steps) {
    ASSERT_EQ(r.reactions.size(), 1u);
    EXPECT_LT((r.reactions[0] + r.applied_force).norm(), 1e-10 * r.applied_force.norm());
  }
  // The support holds up the fluid's load: about its weight, upward.
  EXPECT_GT(result.runs[0].summary.steps.back().reactions[0].y(), 20.0);
}

TEST(Outputs, CsvTablesOpenAsTables) {
  ScratchDir dir;
  json c = small_config();
  c["variants"] = {{{"name", "stiff"}, {"material", {{"Y", 40000}}}}, {{"name", "base"}}};
  const Experiment ex = parse(c);
  OutputWriter writer(ex, dir.path() / "out");
  writer.begin();
  const ExperimentResult result = run_experiment(ex);
  writer.finish(result);
  ASSERT_TRUE(result.runs_succeeded());

  const auto steps = read_csv(dir.path() / "out" / "stiff" / "steps.csv");
  ASSERT_EQ(steps.size(), 4u);  // header and 3 steps
  const std::vector<std::string> header = {"step",
                                           "load_factor_g",
                                           "pressure_Pa",
                                           "volume_m3",
                                           "max_displacement_m",
                                           "applied_force_x_N",
                                           "applied_force_y_N",
                                           "applied_force_z_N",
                                           "reaction_top_x_N",
                                           "reaction_top_y_N",
                                           "reaction_top_z_N",
                                           "equilibrium_residual",
                                           "seconds"};
  EXPECT_EQ(steps[0], header);
  for (size_t r = 1; r < steps.size(); ++r) {
    ASSERT_EQ(steps[r].size(), header.size());
    EXPECT_EQ(std::stoi(steps[r][0]), static_cast<int>(r));
    EXPECT_NEAR(std::stod(steps[r][7]) + std::stod(steps[r][10]), 0.0,
                1e-10 * std::abs(std::stod(steps[r][7])));  // z: load and reaction balance
  }

  const auto vertices = read_csv(dir.path() / "out" / "stiff" / "vertices.csv");
  ASSERT_EQ(vertices.size(), 43u);  // header and 42 vertices
  EXPECT_EQ(vertices[0][0], "vertex");
  EXPECT_EQ(vertices[0][7], "u_magnitude_m");
  for (size_t r = 1; r < vertices.size(); ++r) {
    const double ux = std::stod(vertices[r][4]), uy = std::stod(vertices[r][5]),
                 uz = std::stod(vertices[r][6]);
    EXPECT_NEAR(std::stod(vertices[r][7]), std::sqrt(ux * ux + uy * uy + uz * uz), 1e-15);
  }

  const auto comparison = read_csv(dir.path() / "out" / "comparison.csv");
  ASSERT_EQ(comparison.size(), 3u);
  EXPECT_EQ(comparison[0][0], "variant");
  EXPECT_EQ(comparison[1][0], "stiff");
  EXPECT_EQ(comparison[2][0], "base");
  // Twice the modulus, about half the displacement (gamma adds a little).
  const double ratio = std::stod(comparison[1][3]) / std::stod(comparison[2][3]);
  EXPECT_GT(ratio, 0.45);
  EXPECT_LT(ratio, 0.55);

  const json summary = json::parse(read_text(dir.path() / "out" / "summary.json"));
  EXPECT_EQ(summary["units"]["pressure"], "Pa");
  EXPECT_EQ(summary["runs"][0]["patch"]["material"]["Y"], 40000);
  EXPECT_EQ(summary["runs"][0]["steps"][2]["reactions"]["top"].size(), 3u);
}

// A paddle's final force and contacts are figures of every run, and columns
// of a sweep's comparison.csv.
TEST(Outputs, APaddleSweepListsEachPaddlesForceAndContacts) {
  ScratchDir dir;
  json c = small_config();
  c["supports"] = {{{"where", "z <= -0.04"}, {"label", "base"}}};
  c["loads"] = json::array();
  c["paddles"] = {{{"label", "press"}, {"axis", "z"}, {"side", "above"}, {"compression", 0.05}}};
  c["stepping"] = {{"scheme", "newton"}, {"steps", 2}};
  c["variants"] = {{{"name", "soft"}}, {{"name", "stiff"}, {"material", {{"Y", 40000}}}}};
  const Experiment ex = parse(c);
  const ExperimentResult result = run_experiment(ex);
  ASSERT_TRUE(result.runs_succeeded());
  for (const char* v : {"soft", "stiff"}) {
    const double force = result.figures.at(std::string(v) + ".paddle_force.press");
    EXPECT_LT(force, 0.0) << v;  // the paddle pushes the body down
    EXPECT_GT(result.figures.at(std::string(v) + ".paddle_contacts.press"), 0.0) << v;
    // The base holds what the paddle pushes.
    const solve::StepRecord& last = result.runs[v[1] == 'o' ? 0 : 1].summary.steps.back();
    EXPECT_NEAR(last.reactions[0][2] + force, 0.0, 1e-8 * std::abs(force)) << v;
  }
  EXPECT_NEAR(
      result.figures.at("stiff.paddle_force.press") / result.figures.at("soft.paddle_force.press"),
      2.0, 0.2);  // twice the modulus, about twice the force
  {
    OutputWriter writer(ex, dir.path() / "out");
    writer.begin();
    writer.finish(result);
  }
  const auto comparison = read_csv(dir.path() / "out" / "comparison.csv");
  const auto& header = comparison[0];
  const auto column = std::find(header.begin(), header.end(), "paddle_press_force_N");
  ASSERT_NE(column, header.end());
  EXPECT_EQ(*(column + 1), "paddle_press_contacts");
  const size_t k = static_cast<size_t>(column - header.begin());
  EXPECT_EQ(std::stod(comparison[1][k]), result.figures.at("soft.paddle_force.press"));
}

TEST(Outputs, AFailedRunIsKeptApartAndTheLastResultStays) {
  ScratchDir dir;
  const std::filesystem::path out = dir.path() / "out";
  json c = small_config();
  {
    const Experiment good = parse(c);
    OutputWriter writer(good, out);
    writer.begin();
    writer.finish(run_experiment(good));
  }
  ASSERT_TRUE(std::filesystem::exists(out / "summary.json"));
  const std::string before = read_text(out / "summary.json");

  c["loads"][0]["density"] = 1e12;  // a runaway
  const Experiment bad = parse(c);
  OutputWriter writer(bad, out);
  writer.begin();
  const ExperimentResult result = run_experiment(bad);
  writer.finish(result);
  EXPECT_FALSE(result.runs_succeeded());
  EXPECT_EQ(read_text(out / "summary.json"), before);  // the last complete result
  std::filesystem::path failed = out;
  failed += ".failed";
  EXPECT_EQ(writer.folder(), failed);
  EXPECT_NE(read_text(failed / "FAILED").find("step 1: runaway"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(failed / "INCOMPLETE"));
  for (const auto& entry : std::filesystem::directory_iterator(dir.path()))
    EXPECT_EQ(entry.path().filename().string().find(".running-"), std::string::npos)
        << entry.path();
}

TEST(Outputs, AFolderThatIsNotAnOutputFolderIsNeverReplaced) {
  ScratchDir dir;
  dir.write("notes.txt", "mine");
  const Experiment ex = parse(small_config());
  EXPECT_THROW(OutputWriter(ex, dir.path()), InputError);
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "notes.txt"));
}

}  // namespace
}  // namespace fiberfluid::experiment
