// SPDX-License-Identifier: GPL-3.0-or-later
// Resource guards: the estimate before a run, the memory and time budgets,
// and interruption (Ctrl-C) of pruning and of every solver loop.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "fiberfluid/experiment/experiment.hpp"
#include "fiberfluid/experiment/run/case_builder.hpp"
#include "fiberfluid/experiment/run/resources.hpp"
#include "fiberfluid/experiment/run/runner.hpp"
#include "fiberfluid/experiment/write/outputs.hpp"
#include "fiberfluid/solve/gmres.hpp"
#include "fiberfluid/util/error.hpp"
#include "fiberfluid/util/progress.hpp"
#include "fiberfluid/util/run_control.hpp"
#include "test_support.hpp"

namespace fiberfluid::experiment {
namespace {

using nlohmann::json;

// Restores the process-wide budgets, the cancel flag and the sinks.
class ResourceGuards : public ::testing::Test {
 protected:
  void TearDown() override {
    set_memory_budget(0.0);
    set_time_budget(0.0);
    clear_cancel();
    set_progress_sink({});
    set_note_sink({});
  }
};

json sphere(int subdivisions, const std::string& solver = "auto") {
  return {
      {"name", "sphere"},
      {"surface", {{"generator", "icosphere"}, {"subdivisions", subdivisions}, {"radius", 0.05}}},
      {"material", {{"Y", 20000}, {"gamma", 1}}},
      {"supports", {{{"where", "z >= 0.04"}}}},
      {"loads", {{{"type", "gravity"}, {"acceleration", {0, 0, -9.81}}}}},
      {"stepping", {{"steps", 3}, {"solver", solver}}}};
}

json liver() {
  return {{"name", "liver"},
          {"surface", {{"file", "../data/meshes/liver.obj"}, {"scale", 0.04}}},
          {"material", {{"Y", 20000}, {"gamma", 50}}},
          {"supports", {{{"where", "y <= 0.015"}}}},
          {"loads", {{{"type", "gravity"}, {"acceleration", {0, -9.81, 0}}}}},
          {"stepping", {{"steps", 2}}}};
}

Experiment read(const json& doc) {
  return read_experiment(doc, FIBERFLUID_EXPERIMENTS, "test.json");
}

const ResourcePart* part(const ResourceEstimate& e, const std::string& name) {
  for (const ResourcePart& p : e.parts)
    if (p.name.find(name) != std::string::npos) return &p;
  return nullptr;
}

Case built(const json& doc) { return build_case(read(doc).simulation().specs[0]); }

TEST_F(ResourceGuards, TheEstimateCountsTheBackendsDenseBlocks) {
  const Case c = built(sphere(3, "block-cholesky"));  // 642 vertices, 61 held (z >= 0.04)
  const double n = 642 - 61;
  ASSERT_EQ(c.model.constraints.size(), 3u * 61u);
  const ResourceEstimate e = estimate_resources(c.model, c.stepping, PruningWork::ConvexityCheck);
  EXPECT_EQ(e.solver, "block-cholesky") << e.describe();
  // Every axis held alike: one factor of the free vertices, 8 n^2 bytes.
  ASSERT_NE(part(e, "factorisation"), nullptr);
  EXPECT_DOUBLE_EQ(part(e, "factorisation")->bytes, 8 * n * n);
  EXPECT_DOUBLE_EQ(e.peak_bytes, part(e, "model")->bytes + 8 * n * n);
  ASSERT_NE(part(e, "3 load steps"), nullptr);
  ASSERT_NE(part(e, "convexity check"), nullptr);
  EXPECT_EQ(part(e, "pruning"), nullptr);
  // Held on x alone: three distinct blocks, three factors.
  Case one_axis = c;
  one_axis.model.constraints.erase(
      std::remove_if(one_axis.model.constraints.begin(), one_axis.model.constraints.end(),
                     [](const model::Constraint& k) { return k.axis != 0; }),
      one_axis.model.constraints.end());
  const ResourceEstimate three =
      estimate_resources(one_axis.model, c.stepping, PruningWork::ConvexityCheck);
  EXPECT_DOUBLE_EQ(part(three, "factorisation")->bytes, 3 * 8 * 642.0 * 642.0);
  // dense-lu: the whole (3n+1)-square system; 2/3 (3n)^3 flops against n^3 / 3 (54 times).
  solve::SteppingOptions lu_options = c.stepping;
  lu_options.solver = solve::SolverKind::DenseLU;
  const ResourceEstimate lu = estimate_resources(c.model, lu_options, PruningWork::ConvexityCheck);
  EXPECT_DOUBLE_EQ(part(lu, "factorisation")->bytes, 1.2 * 8 * (3 * n + 1) * (3 * n + 1));
  EXPECT_GT(part(lu, "factorisation")->seconds, 30 * part(e, "factorisation")->seconds)
      << lu.describe() << "\n"
      << e.describe();
  // A concave body adds its N x N table of kept fibers and the pair tests.
  const ResourceEstimate pruned = estimate_resources(c.model, c.stepping, PruningWork::Prune);
  ASSERT_NE(part(pruned, "pruning"), nullptr);
  EXPECT_GE(part(pruned, "pruning")->bytes, 642.0 * 642.0);
  EXPECT_NEAR(pruned.peak_bytes - e.peak_bytes, part(pruned, "pruning")->bytes, 1.0);
  EXPECT_GT(pruned.seconds, e.seconds);
}

TEST_F(ResourceGuards, AutoTakesPcgWhenTheDenseBlocksWouldNotFitTheBudget) {
  const Case c = built(sphere(4));  // 2562 vertices: a 48 MB block and its copy
  EXPECT_EQ(estimate_resources(c.model, c.stepping, PruningWork::None).solver, "block-cholesky");
  set_memory_budget(200e6);  // 3/8 of it is 75 MB < 96 MB
  EXPECT_EQ(estimate_resources(c.model, c.stepping, PruningWork::None).solver, "pcg");
  // The solver that runs is the one estimated.
  Experiment ex = read(sphere(4));
  build_experiment(ex);
  const ExperimentResult r = run_experiment(ex);
  ASSERT_TRUE(r.runs_succeeded()) << r.runs[0].summary.message;
  EXPECT_EQ(r.runs[0].summary.solver, solve::SolverKind::PCG);
  EXPECT_EQ(ex.simulation().cases[0].estimate.solver, "pcg");
}

// A horizon's fibers are found before the estimate, which then counts its
// pairs and its sparse blocks, not N^2: 40,962 vertices within a tenth of
// the radius (about 100 fibers each) plan for CHOLMOD's sparse blocks in
// well under a gigabyte, where every pair's dense blocks (13 GB) leave only PCG.
TEST_F(ResourceGuards, AHorizonsEstimateCountsItsPairsNotAllOfThem) {
  json doc = sphere(6);
  doc["fibers"] = {{"horizon", 0.005}};
  doc["stepping"] = {{"scheme", "newton"}, {"steps", 1}};
  const Case c = built(doc);
  ASSERT_TRUE(c.model.fibers && c.model.fibers->sparse());
  const ResourceEstimate e = estimate_resources(c.model, c.stepping, PruningWork::ConvexityCheck);
  EXPECT_EQ(e.solver, "cholmod") << e.describe();
  EXPECT_LT(e.peak_bytes, 1e9) << e.describe();
  EXPECT_LT(e.seconds, 120.0) << e.describe();
  // The same sphere with every pair: its dense blocks would not fit, so PCG.
  model::Model every = c.model;
  every.fibers = nullptr;
  EXPECT_EQ(estimate_resources(every, c.stepping, PruningWork::ConvexityCheck).solver, "pcg");
}

TEST_F(ResourceGuards, ACaseBeyondTheMemoryBudgetIsRefusedBeforeItStarts) {
  set_memory_budget(40.0 * 1024 * 1024);
  Experiment ex = read(sphere(3, "dense-lu"));  // 28 MiB of dense LU beside the process's 21
  try {
    build_experiment(ex);
    FAIL() << "expected a refusal";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("test.json: this case needs about"), std::string::npos) << what;
    EXPECT_NE(what.find("more than the memory budget of 40 MiB set by --max-memory"),
              std::string::npos)
        << what;
    EXPECT_NE(what.find("raise --max-memory"), std::string::npos) << what;
    EXPECT_NE(what.find("\"solver\": \"pcg\""), std::string::npos) << what;
  }
  // The same run with pcg fits in the same budget.
  Experiment pcg = read(sphere(3, "pcg"));
  EXPECT_NO_THROW(build_experiment(pcg));
}

TEST_F(ResourceGuards, TheBudgetIsCheckedBeforePruning) {
  set_memory_budget(1e4);  // below even the liver's 139 x 139 fiber table
  bool pruned = false;
  set_progress_sink([&](const std::string&, const char* phase, double, double) {
    if (std::string(phase) == "pruning") pruned = true;
  });
  Experiment ex = read(liver());
  EXPECT_THROW(build_experiment(ex), InputError);
  EXPECT_FALSE(pruned);
}

TEST_F(ResourceGuards, ATimeBudgetRefusesALongEstimate) {
  set_time_budget(1.0);
  json doc = sphere(3);
  doc["stepping"] = {{"steps", 100000}, {"rebuild_matrix", true}};
  Experiment ex = read(doc);
  try {
    build_experiment(ex);
    FAIL() << "expected a refusal";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("more than --max-time 1 s"), std::string::npos)
        << e.what();
  }
}

TEST_F(ResourceGuards, ALongRunsEstimateIsANoteBeforeItStarts) {
  std::vector<std::string> notes;
  set_note_sink([&](const std::string&, const std::string& text) { notes.push_back(text); });
  json doc = sphere(3);
  doc["stepping"] = {{"steps", 100000}, {"rebuild_matrix", true}};
  Experiment ex = read(doc);
  build_experiment(ex);  // built, not run
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_EQ(notes[0].rfind("estimate for a long run: about ", 0), 0u) << notes[0];
  EXPECT_NE(notes[0].find("100000 factorisations"), std::string::npos) << notes[0];
  notes.clear();
  Experiment quick = read(sphere(2));
  build_experiment(quick);
  EXPECT_TRUE(notes.empty());
}

TEST_F(ResourceGuards, PruningStopsWhenInterrupted) {
  set_progress_sink([](const std::string&, const char* phase, double done, double) {
    if (std::string(phase) == "pruning" && done > 0) request_cancel();
  });
  json doc = liver();
  Experiment ex = read(doc);
  EXPECT_THROW(build_experiment(ex), Interrupted);
}

TEST_F(ResourceGuards, EverySolverLoopStopsWhenInterrupted) {
  for (const char* scheme : {"incremental", "newton"}) {
    for (const char* solver : {"dense-lu", "pcg"}) {
      json doc = sphere(2, solver);
      doc["stepping"]["scheme"] = scheme;
      Experiment ex = read(doc);
      build_experiment(ex);
      request_cancel();
      const ExperimentResult r = run_experiment(ex);
      clear_cancel();
      ASSERT_FALSE(r.runs_succeeded()) << scheme << " " << solver;
      EXPECT_NE(r.runs[0].summary.message.find("step 1: interrupted"), std::string::npos)
          << r.runs[0].summary.message;
    }
  }
  // GMRES between restarts (the Newton tangent's Krylov solve).
  const Eigen::MatrixXd A = Eigen::MatrixXd::Identity(4, 4) + Eigen::MatrixXd::Constant(4, 4, 0.1);
  solve::GmresOptions options;
  options.restart = 1;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(4);
  request_cancel();
  const solve::GmresResult g =
      solve::gmres([&](const Eigen::VectorXd& v) -> Eigen::VectorXd { return A * v; },
                   [](const Eigen::VectorXd& v) -> Eigen::VectorXd { return v; },
                   Eigen::VectorXd::Ones(4), x, options);
  EXPECT_FALSE(g.status.ok);
  EXPECT_NE(g.status.message.find("gmres: interrupted"), std::string::npos) << g.status.message;
}

TEST_F(ResourceGuards, ADroppedWriterLeavesNoStagingFolder) {
  testing::ScratchDir dir;
  Experiment ex = read(sphere(1));
  build_experiment(ex);
  const std::filesystem::path out = dir.path() / "out";
  {
    OutputWriter first(ex, out);
    first.begin();
    first.finish(run_experiment(ex));
  }
  const std::filesystem::file_time_type written =
      std::filesystem::last_write_time(out / "summary.json");
  {
    OutputWriter interrupted(ex, out);
    interrupted.begin();  // then an exception, or Ctrl-C: finish() is never called
  }
  for (const auto& entry : std::filesystem::directory_iterator(dir.path()))
    EXPECT_EQ(entry.path().filename(), "out") << entry.path();
  EXPECT_EQ(std::filesystem::last_write_time(out / "summary.json"), written);
}

TEST(Budgets, SizesAreParsedAndPrinted) {
  double bytes = 0.0;
  EXPECT_TRUE(parse_bytes("8G", &bytes));
  EXPECT_DOUBLE_EQ(bytes, 8.0 * 1024 * 1024 * 1024);
  EXPECT_TRUE(parse_bytes("512MiB", &bytes));
  EXPECT_DOUBLE_EQ(bytes, 512.0 * 1024 * 1024);
  EXPECT_TRUE(parse_bytes("2e9", &bytes));
  EXPECT_DOUBLE_EQ(bytes, 2e9);
  for (const char* bad : {"", "-1G", "0", "8X", "nan", "1e999", "G"})
    EXPECT_FALSE(parse_bytes(bad, &bytes)) << bad;
  EXPECT_EQ(format_bytes(1536.0 * 1024 * 1024), "1.5 GiB");
  EXPECT_EQ(format_bytes(100), "100 bytes");
}

}  // namespace
}  // namespace fiberfluid::experiment
