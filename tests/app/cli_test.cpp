// SPDX-License-Identifier: GPL-3.0-or-later
// The command-line tool, run as a user would.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "app/cli_support.hpp"
#include "fiberfluid/experiment/read/schema.hpp"
#include "fiberfluid/experiment/write/build_info.hpp"
#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/geom/mesh_io.hpp"
#include "test_support.hpp"

namespace fiberfluid {
namespace {

using testing::count_files;
using testing::Outcome;
using testing::read_file;
using testing::run_cli;
using testing::ScratchDir;
using testing::staging_of;
using testing::start_cli;
using testing::wait_for;

TEST(Cli, CheckReportsAGoodMesh) {
  const Outcome o = run_cli("check " + testing::data_mesh("torus.obj").string());
  EXPECT_EQ(o.status, 0) << o.output;
  for (const char* part :
       {"vertices:      800", "closed:        yes", "genus:         1", "consistent, outward"})
    EXPECT_NE(o.output.find(part), std::string::npos) << part << "\n" << o.output;
}

TEST(Cli, CheckRejectsABadMesh) {
  ScratchDir dir;
  const auto open_mesh = dir.write("open.obj",
                                   "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                   "f 1 3 2\nf 1 2 4\nf 1 4 3\n");
  const Outcome o = run_cli("check " + open_mesh.string());
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.output.find("open.obj: not closed"), std::string::npos) << o.output;
  // OBJ counts its vertices from 1, and so does the report (the edge v2-v3 of the file).
  EXPECT_NE(o.output.find("not closed: edge (2, 3) borders only one face"), std::string::npos)
      << o.output;
  EXPECT_NE(o.output.find("counted from 1, as the file counts them"), std::string::npos)
      << o.output;
}

TEST(Cli, RunWritesItsOutputsAndChecksTheExpectedFigures) {
  ScratchDir dir;
  const Outcome o = run_cli("run " + testing::experiment_file("rectangle.json").string() + " -o " +
                            (dir.path() / "rect").string() + " --check");
  EXPECT_EQ(o.status, 0) << o.output;
  EXPECT_NE(o.output.find("pass  final_pressure = 32"), std::string::npos) << o.output;
  for (const char* file : {"summary.json", "final.obj", "series.pvd", "vtk/step_0001.vtu"})
    EXPECT_TRUE(std::filesystem::exists(dir.path() / "rect" / file)) << file;
}

// --plot draws DIR/plot.png with the plot script (Debian's python3 has matplotlib).
TEST(Cli, RunDrawsItsPlotOnRequest) {
  ScratchDir dir;
  const Outcome o = run_cli("run " + testing::experiment_file("rectangle.json").string() + " -o " +
                            (dir.path() / "rect").string() + " -q --plot");
  EXPECT_EQ(o.status, 0) << o.output;
  EXPECT_NE(o.output.find("plot: " + (dir.path() / "rect" / "plot.png").string()),
            std::string::npos)
      << o.output;
  EXPECT_GT(std::filesystem::file_size(dir.path() / "rect" / "plot.png"), 10000u);
}

TEST(Cli, FitCalibratesThenWritesTheRunAndTheFitFiles) {
  ScratchDir dir;
  const Outcome o = run_cli("fit " + testing::experiment_file("fit_sphere.json").string() + " -o " +
                            (dir.path() / "fit").string() + " --check");
  EXPECT_EQ(o.status, 0) << o.output;
  for (const char* part :
       {"sphere_final.obj (step 10): a triangle soup of 320 triangles", "finite differences",
        "fit: iteration 1:", "pass  fit.Y = ", "% of the body's length"})
    EXPECT_NE(o.output.find(part), std::string::npos) << part << "\n" << o.output;
  for (const char* file : {"summary.json", "fit.json", "fit_iterations.csv", "fit_target_0.vtu"})
    EXPECT_TRUE(std::filesystem::exists(dir.path() / "fit" / file)) << file;
  // An experiment without a fit section is refused, naming the file.
  const Outcome none = run_cli("fit " + testing::experiment_file("rectangle.json").string() +
                               " -o " + (dir.path() / "none").string());
  EXPECT_EQ(none.status, 1);
  EXPECT_NE(none.output.find("rectangle.json: no \"fit\" section"), std::string::npos)
      << none.output;
}

// Issue 24's must-show: under paddles alone a scan cannot tell Y0 from
// gamma; the fit says so with its documented status (exit 2, DIR.failed)
// and names both, with no solver log on the way.
TEST(Cli, APaddlesOnlyFitIsNotIdentifiableAndNamesY0AndGamma) {
  ScratchDir dir;
  const std::filesystem::path out = dir.path() / "shape";
  const Outcome o =
      run_cli("fit " + testing::experiment_file("fit_paddles_liver_shape.json").string() +
              " -q -o " + out.string());
  EXPECT_EQ(o.status, 2) << o.output;
  for (const char* part :
       {"fit_paddles_liver_shape: not_identifiable", "shape.failed",
        "the distances cannot tell \"Y0\", \"gamma\" apart (the Jacobian is rank deficient)"})
    EXPECT_NE(o.output.find(part), std::string::npos) << part << "\n" << o.output;
  for (const char* absent : {"+- nan", "covariance_impl", "InitGoogleLogging"})
    EXPECT_EQ(o.output.find(absent), std::string::npos) << absent << "\n" << o.output;
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "shape.failed" / "fit.json"));
}

// `fiberfluid schema` prints the schema the reader makes of itself
// (tests/python/test_schema.py validates the shipped experiments with it).
TEST(Cli, SchemaPrintsTheExperimentFilesJsonSchema) {
  const Outcome o = run_cli("schema");
  EXPECT_EQ(o.status, 0) << o.output;
  const nlohmann::json printed = nlohmann::json::parse(o.output);
  EXPECT_EQ(printed, experiment::experiment_schema());
  EXPECT_EQ(printed["$schema"], "https://json-schema.org/draft/2020-12/schema");
  EXPECT_FALSE(printed["additionalProperties"].get<bool>());
  for (const char* section :
       {"surface", "material", "supports", "prescribed", "loads", "paddles", "stepping", "fibers",
        "fit", "fem_reference", "output", "expected", "variants", "surfaces", "scene"})
    EXPECT_TRUE(printed["properties"].contains(section)) << section;
  EXPECT_EQ(printed["properties"]["stepping"]["properties"]["scheme"]["enum"],
            nlohmann::json({"incremental", "newton"}));
}

TEST(Cli, BadExperimentWritesNothing) {
  ScratchDir dir;
  const auto config = dir.write("bad.json", R"({"name": "bad",
    "surface": {"generator": "icosphere"}, "material": {"Y": 1, "colour": "red"}})");
  const Outcome o = run_cli("run " + config.string() + " -o " + (dir.path() / "out").string());
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.output.find("material.colour: unknown field"), std::string::npos) << o.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out"));
}

TEST(Cli, SingularSetupIsAFailureStatusNotACrash) {
  ScratchDir dir;
  const auto config = dir.write("free.json", R"({"name": "free",
    "surface": {"generator": "icosphere", "subdivisions": 1},
    "material": {"Y": 1000},
    "loads": [{"type": "gravity", "acceleration": [0, 0, -9.81]}]})");
  const Outcome o = run_cli("run " + config.string() + " -o " + (dir.path() / "out").string());
  EXPECT_EQ(o.status, 2);
  EXPECT_NE(o.output.find("no supports"), std::string::npos) << o.output;
}

// Issue 59, class 2: a FEM reference that fails after the fiber run keeps
// the run in DIR.failed with the reason, exit 2 (it was "bad input", exit 1,
// and the run was lost).
TEST(Cli, AFemReferenceThatFailsKeepsTheFinishedRun) {
  ScratchDir dir;
  const auto config = dir.write("column.json", R"({"name": "column",
    "surface": {"generator": "box", "min": [0, 0, 0], "max": [0.1, 0.1, 0.2], "segments": [2, 2, 4]},
    "material": {"Y": 1000, "gamma": 0}, "supports": [{"where": "z <= 0"}],
    "loads": [{"type": "gravity", "acceleration": [0, 0, -9.81], "density": 1}],
    "stepping": {"steps": 1}, "fem_reference": {"E": 1000, "nu": 0.4999999999999999, "size": 0.04}})");
  const Outcome o = run_cli("run " + config.string() + " -o " + (dir.path() / "out").string());
  EXPECT_EQ(o.status, 2) << o.output;
  EXPECT_NE(o.output.find("error: fem_reference: "), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("likely cause: nu = 0.49999999999999989"), std::string::npos) << o.output;
  const std::filesystem::path kept = dir.path() / "out.failed";
  EXPECT_TRUE(std::filesystem::exists(kept / "steps.csv"));
  EXPECT_TRUE(std::filesystem::exists(kept / "final.obj"));
  std::ifstream failed(kept / "FAILED");
  const std::string why((std::istreambuf_iterator<char>(failed)), std::istreambuf_iterator<char>());
  EXPECT_NE(why.find("fem_reference: "), std::string::npos) << why;
}

// Issue 59, class 1: a gauge holds a rotation nothing else holds, checked on
// the loads at their full factors. Two loads on one vertex that cancel only
// at the last step turn the body before it: the gauge carried 0.09 N at step
// 1 and the run succeeded. Its reaction is now checked after every step.
TEST(Cli, AGaugeThatCarriesAForceIsNoEquilibrium) {
  ScratchDir dir;
  const std::string base = R"({"name": "gauge",
    "surface": {"generator": "cylinder", "radius": 0.025, "length": 0.03, "segments": [3, 12]},
    "material": {"Y": 30000, "gamma": 0.001}, "fibers": {"kinematics": "central"},
    "supports": [{"label": "centre", "box": {"min": [-1e-7, -1e-7, -1e-7], "max": [1e-7, 1e-7, 1e-7]}}],
    "paddles": [{"label": "lower", "axis": "x", "side": "below", "travel": 0},
                {"label": "upper", "axis": "x", "side": "above", "travel": -0.003}],
    "stepping": {"scheme": "newton", "steps": 4},
    "loads": [{"type": "point", "vertex": 5, "force": [0, 0, 0.5], "schedule": "ramp"},
              {"type": "point", "vertex": 5, "force": [0, 0, -0.5], "schedule": "SCHEDULE"}]})";
  const auto with = [&](const std::string& schedule) {
    std::string text = base;
    text.replace(text.find("SCHEDULE"), 8, schedule);
    return dir.write(schedule + ".json", text);
  };
  Outcome o = run_cli("run " + with("final").string() + " -o " + (dir.path() / "a").string());
  EXPECT_EQ(o.status, 2) << o.output;
  EXPECT_NE(o.output.find("step 1: the gauge (group \"gauge\") carries "), std::string::npos)
      << o.output;
  // The same loads cancelling at every step: the gauge carries nothing.
  o = run_cli("run " + with("ramp").string() + " -o " + (dir.path() / "b").string());
  EXPECT_EQ(o.status, 0) << o.output;
}

TEST(Cli, ARunawayStopsWithStatus2NamingTheStep) {
  ScratchDir dir;
  // The sphere experiment with a fluid 1e9 times too heavy.
  std::ifstream in(testing::experiment_file("sphere.json"));
  nlohmann::json config = nlohmann::json::parse(in);
  config["loads"][0]["density"] = 1e12;
  config["expected"] = nlohmann::json::array();
  const auto file = dir.write("runaway.json", config.dump());
  const Outcome o = run_cli("run " + file.string() + " -o " + (dir.path() / "out").string());
  EXPECT_EQ(o.status, 2) << o.output;
  EXPECT_NE(o.output.find("error: step 1: runaway: face"), std::string::npos) << o.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out"));
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "out.failed" / "FAILED"));
}

TEST(Cli, SupportsOnEveryVertexAreNamed) {
  ScratchDir dir;
  const auto config = dir.write("fixed.json", R"({"name": "fixed",
    "surface": {"generator": "icosphere", "subdivisions": 1},
    "material": {"Y": 1000},
    "supports": [{"where": "z >= -2"}],
    "loads": [{"type": "gravity", "acceleration": [0, 0, -9.81]}]})");
  const Outcome o = run_cli("run " + config.string() + " -o " + (dir.path() / "out").string());
  EXPECT_EQ(o.status, 2) << o.output;
  EXPECT_NE(o.output.find("the supports fix every vertex on every axis"), std::string::npos)
      << o.output;
}

// Starts the tool in the background; its standard output and error go to a file.

// A run long enough to be stopped part way: 642 vertices, A rebuilt every
// step (about 10 ms each), a .vtu per step.
nlohmann::json many_steps(int steps) {
  nlohmann::json config = nlohmann::json::parse(R"({"name": "long",
    "surface": {"generator": "icosphere", "subdivisions": 3, "radius": 0.05},
    "material": {"Y": 20000, "gamma": 1},
    "supports": [{"where": "z >= 0.04"}],
    "loads": [{"type": "gravity", "acceleration": [0, 0, -9.81]}],
    "stepping": {"rebuild_matrix": true, "solver": "block-cholesky"}})");
  config["stepping"]["steps"] = steps;
  return config;
}

TEST(Cli, AKilledRunAndARerunNeverMixTheirFiles) {
  ScratchDir dir;
  const std::filesystem::path out = dir.path() / "out";
  nlohmann::json config = many_steps(400);
  const auto long_run = dir.write("long.json", config.dump());
  config["stepping"]["steps"] = 3;
  const auto short_run = dir.write("short.json", config.dump());

  auto kill_part_way = [&](const std::string& name) {
    const pid_t pid =
        start_cli({"run", long_run.string(), "-o", out.string()}, dir.path() / (name + ".log"));
    std::filesystem::path staging;
    for (int wait = 0; wait < 600 && count_files(staging / "vtk") < 5; ++wait) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      staging = staging_of(out, pid);
    }
    kill(pid, SIGKILL);
    int status = 0;
    waitpid(pid, &status, 0);
    EXPECT_TRUE(WIFSIGNALED(status)) << "the run ended before it was killed";
    EXPECT_GE(count_files(staging / "vtk"), 5);
    EXPECT_TRUE(std::filesystem::exists(staging / "INCOMPLETE"));
    return staging;
  };

  // Killed with no earlier result: nothing appears at out.
  const std::filesystem::path first_staging = kill_part_way("first");
  EXPECT_FALSE(std::filesystem::exists(out));

  // A short rerun: out holds exactly its 4 states; the killed run's folder is gone.
  Outcome o = run_cli("run " + short_run.string() + " -q -o " + out.string());
  ASSERT_EQ(o.status, 0) << o.output;
  EXPECT_FALSE(std::filesystem::exists(first_staging));
  EXPECT_EQ(count_files(out / "vtk"), 4);
  EXPECT_FALSE(std::filesystem::exists(out / "INCOMPLETE"));
  std::ifstream summary_in(out / "summary.json");
  const std::string summary((std::istreambuf_iterator<char>(summary_in)),
                            std::istreambuf_iterator<char>());

  // Killed again: the complete short result stays untouched.
  kill_part_way("second");
  EXPECT_EQ(count_files(out / "vtk"), 4);
  std::ifstream again_in(out / "summary.json");
  EXPECT_EQ(
      std::string((std::istreambuf_iterator<char>(again_in)), std::istreambuf_iterator<char>()),
      summary);
}

TEST(Cli, CtrlCDuringTheLoadStepsWritesNothingAndKeepsTheEarlierResult) {
  ScratchDir dir;
  const std::filesystem::path out = dir.path() / "out";
  nlohmann::json config = many_steps(3);
  ASSERT_EQ(
      run_cli("run " + dir.write("short.json", config.dump()).string() + " -q -o " + out.string())
          .status,
      0);
  const std::string earlier = read_file(out / "summary.json");

  config["stepping"]["steps"] = 4000;
  const pid_t pid =
      start_cli({"run", dir.write("long.json", config.dump()).string(), "-o", out.string()},
                dir.path() / "run.log");
  std::filesystem::path staging;
  for (int wait = 0; wait < 600 && count_files(staging / "vtk") < 5; ++wait) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    staging = staging_of(out, pid);
  }
  ASSERT_GE(count_files(staging / "vtk"), 5) << "the run did not get going";
  kill(pid, SIGINT);
  double seconds = 0.0;
  EXPECT_EQ(wait_for(pid, &seconds), 130) << read_file(dir.path() / "run.log");
  EXPECT_LT(seconds, 10.0);  // at the next load step
  EXPECT_NE(read_file(dir.path() / "run.log")
                .find("interrupted during the run (Ctrl-C): nothing was written"),
            std::string::npos)
      << read_file(dir.path() / "run.log");
  EXPECT_FALSE(std::filesystem::exists(staging));
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out.failed"));
  EXPECT_EQ(read_file(out / "summary.json"), earlier);
}

TEST(Cli, CtrlCDuringPruningStopsAtOnce) {
  ScratchDir dir;
  // A 5,000-vertex torus: 12.5 million fiber pairs, about 20 s of pruning
  // (minutes under ASan).
  const auto config = dir.write("torus.json", R"({"name": "torus",
    "surface": {"generator": "torus", "major_radius": 0.05, "minor_radius": 0.02,
                "segments": [100, 50]},
    "material": {"Y": 20000, "gamma": 1},
    "supports": [{"where": "z >= 0.015"}],
    "loads": [{"type": "gravity", "acceleration": [0, 0, -9.81]}],
    "stepping": {"steps": 1}})");
  const pid_t pid = start_cli({"run", config.string(), "-o", (dir.path() / "out").string()},
                              dir.path() / "run.log");
  // Progress lines start after 2 s: "pruning 1234/930,000 (...)".
  auto pruning = [&] {
    return ("\n" + read_file(dir.path() / "run.log")).find("\npruning ") != std::string::npos;
  };
  for (int wait = 0; wait < 1200 && !pruning(); ++wait)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  kill(pid, SIGINT);
  double seconds = 0.0;
  EXPECT_EQ(wait_for(pid, &seconds), 130) << read_file(dir.path() / "run.log");
  EXPECT_LT(seconds, 10.0);
  EXPECT_NE(read_file(dir.path() / "run.log").find("interrupted during the fiber pruning"),
            std::string::npos)
      << read_file(dir.path() / "run.log");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()),
                          std::filesystem::directory_iterator()),
            2);  // the config and the log
}

TEST(Cli, MaxMemoryRefusesARunBeforeItStarts) {
  ScratchDir dir;
  nlohmann::json dense = many_steps(1);
  dense["stepping"] = {{"solver", "dense-lu"}};
  const auto config = dir.write("dense.json", dense.dump());
  const std::filesystem::path out = dir.path() / "out";
  Outcome o = run_cli("run " + config.string() + " --max-memory 20M -o " + out.string());
  EXPECT_EQ(o.status, 1) << o.output;
  EXPECT_NE(o.output.find("dense.json: this case needs about "), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("; dense-lu), more than"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("more than the memory budget of 20 MiB set by --max-memory; raise "
                          "--max-memory"),
            std::string::npos)
      << o.output;
  EXPECT_FALSE(std::filesystem::exists(out));
  o = run_cli("run " + config.string() + " --max-memory 100M -q -o " + out.string());
  EXPECT_EQ(o.status, 0) << o.output;
  o = run_cli("run " + config.string() + " --max-memory lots");
  EXPECT_EQ(o.status, 64) << o.output;
  EXPECT_NE(o.output.find("expected a size such as 8G"), std::string::npos) << o.output;
}

TEST(Cli, LongPhasesShowProgressUnlessQuiet) {
  ScratchDir dir;
  // About 4 s of load steps.
  nlohmann::json steps = many_steps(400);
  steps["output"] = {{"vtk", false}};
  const auto config = dir.write("steps.json", steps.dump());
  Outcome o = run_cli("run " + config.string() + " -o " + (dir.path() / "a").string());
  ASSERT_EQ(o.status, 0) << o.output;
  // Not a terminal: plain lines with the elapsed time and an estimate of what is left.
  EXPECT_NE(o.output.find("step 400/400 (100%), "), std::string::npos) << o.output;
  EXPECT_NE(o.output.find(" s left"), std::string::npos) << o.output;
  o = run_cli("run " + config.string() + " -q -o " + (dir.path() / "b").string());
  ASSERT_EQ(o.status, 0) << o.output;
  EXPECT_EQ(o.output.find("step "), std::string::npos) << o.output;
}

// --version names the version and what the build's solvers are made of.
TEST(Cli, VersionSaysWhatTheBuildIs) {
  const Outcome o = run_cli("--version");
  EXPECT_EQ(o.status, 0) << o.output;
  EXPECT_EQ(o.output.rfind("fiberfluid " + experiment::program_version() + "\n", 0), 0u)
      << o.output;
  for (const char* part :
       {"compiler: ", "lapack: ", "suitesparse: ", "cgal: ", "ceres: ", "nlopt: "})
    EXPECT_NE(o.output.find(part), std::string::npos) << part << "\n" << o.output;
}

// OpenMP threads sleep rather than spin while they wait (a spinning thread
// takes the core that the thread it waits for needs, on a shared machine),
// unless the user chose a policy: libgomp itself says how long its threads
// spin (its default 300,000 times; passive 0).
TEST(Cli, ThreadsWaitPassivelyUnlessTheUserChose) {
  const std::string cli = std::string(" OMP_DISPLAY_ENV=VERBOSE ") + FIBERFLUID_CLI + " --version";
  Outcome o = testing::run_cli_command("env -u OMP_WAIT_POLICY -u GOMP_SPINCOUNT" + cli);
  EXPECT_EQ(o.status, 0) << o.output;
  EXPECT_NE(o.output.find("GOMP_SPINCOUNT = '0'"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("openmp_wait_policy: passive (fiberfluid's default)"), std::string::npos)
      << o.output;
  o = testing::run_cli_command("env -u GOMP_SPINCOUNT OMP_WAIT_POLICY=active" + cli);
  EXPECT_NE(o.output.find("OMP_WAIT_POLICY = 'ACTIVE'"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("openmp_wait_policy: OMP_WAIT_POLICY=active (the user's)"),
            std::string::npos)
      << o.output;
  o = testing::run_cli_command("env -u OMP_WAIT_POLICY GOMP_SPINCOUNT=1000" + cli);
  EXPECT_NE(o.output.find("GOMP_SPINCOUNT = '1000'"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("openmp_wait_policy: GOMP_SPINCOUNT=1000 (the user's)"),
            std::string::npos)
      << o.output;
}

TEST(Cli, UsageErrors) {
  // Status 64 and CLI11's message, not just any failure (a missing binary exits 127).
  const struct {
    const char* arguments;
    const char* message;
  } cases[] = {
      {"", "A subcommand is required"},
      {"run", "experiment is required"},
      {"frobnicate",
       "unknown command 'frobnicate' (expected one of: run, fit, predict, check, compare"},
      {"runn x.json", "unknown command 'runn'"},
      {"run x.json --plott", "--plott ('run' takes the options: -h,--help, -o,--output, --check"},
      {"check a.obj b.obj", "b.obj ('check' takes the options: -h,--help, --flip;"},
      {"run x.json -j -3", "--jobs"},
      // Not a number is no number: NaN fails every comparison a range makes.
      {"run x.json --max-time nan", "--max-time: expected a finite number, got 'nan'"},
      {"fit x.json --max-time inf", "--max-time: expected a finite number, got 'inf'"},
      {"predict f x.json --max-time -nan", "--max-time: expected a finite number"},
      {"study mesh x.json --ratio nan", "--ratio: expected a finite number, got 'nan'"},
      {"study mesh x.json --ratio 9", "--ratio"}};
  for (const auto& c : cases) {
    const Outcome o = run_cli(c.arguments);
    EXPECT_EQ(o.status, 64) << c.arguments << "\n" << o.output;
    EXPECT_NE(o.output.find(c.message), std::string::npos) << c.arguments << "\n" << o.output;
  }
  EXPECT_EQ(run_cli("--help").status, 0);
}

// The benchmarks paper's metrics between two files: a unit cube and the same
// cube moved 0.1 along x (E_s = 0.2 exactly), with the undeformed cube as M0.
TEST(Cli, CompareGivesTheMetricsAsTextAndJson) {
  ScratchDir dir;
  geom::Surface cube = geom::box({0, 0, 0}, {1, 1, 1}, {2, 2, 2});
  const std::filesystem::path m = dir.path() / "m.obj", moved = dir.path() / "moved.obj",
                              m0 = dir.path() / "m0.obj";
  geom::write_obj(m0, cube);
  cube.V.col(2) *= 0.8;  // the reference: squashed to 80% height
  geom::write_obj(m, cube);
  cube.V.col(0).array() += 0.1;
  geom::write_obj(moved, cube);
  const Outcome text = run_cli("compare " + m.string() + " " + moved.string());
  EXPECT_EQ(text.status, 0) << text.output;
  for (const char* part : {"E_s = 0.2 ", "need the undeformed mesh", "distance from M' to M"})
    EXPECT_NE(text.output.find(part), std::string::npos) << part << "\n" << text.output;
  const Outcome json = run_cli("compare " + m.string() + " " + moved.string() + " --reference " +
                               m0.string() + " --json");
  ASSERT_EQ(json.status, 0) << json.output;
  const nlohmann::json j = nlohmann::json::parse(json.output.substr(json.output.find('{')));
  EXPECT_NEAR(j["E_s"].get<double>(), 0.2, 1e-14);
  // u = (0, 0, -0.2 z), u' = u + (0.1, 0, 0) at every node.
  double u2 = 0.0;
  for (Eigen::Index v = 0; v < cube.V.rows(); ++v) u2 += std::pow(0.2 * cube.V(v, 2) / 0.8, 2);
  EXPECT_NEAR(j["E_n"].get<double>(), 0.1 * std::sqrt(static_cast<double>(cube.V.rows()) / u2),
              1e-12);
  EXPECT_GT(j["E_i"].get<double>(), 0.0);
  EXPECT_NEAR(j["distance"]["largest"].get<double>(), 0.1, 1e-12);
  // An open scan bounds no solid: E_s says so, naming the file, and the
  // distances are still given (a scan is rarely closed).
  std::ofstream(dir.path() / "open.obj")
      << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\n";
  const Outcome open = run_cli("compare " + m.string() + " " + (dir.path() / "open.obj").string());
  EXPECT_EQ(open.status, 0) << open.output;
  for (const char* part : {"E_s: not computed: it needs two closed solids",
                           "open.obj: the mesh is not closed", "distance from M' to M"})
    EXPECT_NE(open.output.find(part), std::string::npos) << part << "\n" << open.output;
  // A point cloud (vertices only) against the reference: the distances.
  std::ofstream(dir.path() / "cloud.obj") << "v 0.5 0.5 1.0\nv 0.5 0.5 0.0\nv 0.25 0.5 0.8\n";
  const Outcome cloud =
      run_cli("compare " + m.string() + " " + (dir.path() / "cloud.obj").string() + " --json");
  ASSERT_EQ(cloud.status, 0) << cloud.output;
  const nlohmann::json c = nlohmann::json::parse(cloud.output.substr(cloud.output.find('{')));
  EXPECT_TRUE(c["E_s"].is_null());
  EXPECT_EQ(c["distance"]["count"].get<int>(), 3);
  EXPECT_NEAR(c["distance"]["largest"].get<double>(), 0.2,
              1e-12);  // (0.5, 0.5, 1) to the top at 0.8
  // 2D polygons have nothing but E_s: an open one is still an error, naming the file.
  std::ofstream(dir.path() / "a.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\nl 3 1\n";
  std::ofstream(dir.path() / "b.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n";
  const Outcome flat =
      run_cli("compare " + (dir.path() / "a.obj").string() + " " + (dir.path() / "b.obj").string());
  EXPECT_EQ(flat.status, 1) << flat.output;
  EXPECT_NE(flat.output.find("b.obj"), std::string::npos) << flat.output;
}

// A scan in other units than the model (25 times larger: cm against mm, or
// an M0 of another scale) gives metrics that mean nothing: compare says so.
TEST(Cli, CompareWarnsOfSurfacesOfDifferentSizes) {
  ScratchDir dir;
  geom::Surface cube = geom::box({0, 0, 0}, {1, 1, 1}, {2, 2, 2});
  const std::filesystem::path m = dir.path() / "m.obj", big = dir.path() / "big.obj";
  geom::write_obj(m, cube);
  cube.V *= 25.0;
  geom::write_obj(big, cube);
  const Outcome text = run_cli("compare " + m.string() + " " + big.string());
  EXPECT_EQ(text.status, 0) << text.output;
  EXPECT_NE(text.output.find("warning: " + big.string() + " is 25 times larger than " + m.string()),
            std::string::npos)
      << text.output;
  const Outcome with_m0 = run_cli("compare " + m.string() + " " + m.string() + " --reference " +
                                  big.string() + " --json");
  ASSERT_EQ(with_m0.status, 0) << with_m0.output;
  const nlohmann::json j = nlohmann::json::parse(with_m0.output.substr(with_m0.output.find('{')));
  ASSERT_EQ(j["warnings"].size(), 1u);
  EXPECT_NE(j["warnings"][0].get<std::string>().find("same units"), std::string::npos);
  // Surfaces of one size: no warning.
  const Outcome same = run_cli("compare " + m.string() + " " + m.string() + " --json");
  EXPECT_TRUE(nlohmann::json::parse(same.output.substr(same.output.find('{')))["warnings"].empty());
}

}  // namespace
}  // namespace fiberfluid
