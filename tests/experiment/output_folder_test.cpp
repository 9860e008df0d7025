// SPDX-License-Identifier: GPL-3.0-or-later
// Where a run may write and what it may replace (issue 30): names from a
// file never leave the output root, only fiberfluid's own folders are
// replaced, concurrent writers never mix or lose a result, and an exception
// in a worker reaches the caller.
#include "fiberfluid/experiment/write/output_folder.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <fstream>
#include <thread>

#include "fiberfluid/experiment/experiment.hpp"
#include "fiberfluid/experiment/run/runner.hpp"
#include "fiberfluid/experiment/write/outputs.hpp"
#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/util/error.hpp"
#include "fiberfluid/util/run_control.hpp"
#include "test_support.hpp"

namespace fiberfluid::experiment {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::ScratchDir;

json small_config() {
  return json::parse(R"({"name": "small",
    "surface": {"generator": "icosphere", "subdivisions": 1},
    "material": {"Y": 3000, "gamma": 3000},
    "supports": [{"where": "z >= 0.8"}],
    "loads": [{"type": "gravity", "acceleration": [0, 0, -10], "density": 1000}],
    "stepping": {"steps": 2}})");
}

std::string error_of(const std::function<void()>& action) {
  try {
    action();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

std::string read_text(const fs::path& file) {
  std::ifstream in(file);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(OutputFolder, NamesFromAFileStayOneFolderName) {
  EXPECT_TRUE(check_folder_name("liver-2026_a.b").ok);
  for (const char* bad : {"../victim", "..", ".", "", "a/b", "/etc", "a b", "x\\y"})
    EXPECT_FALSE(check_folder_name(bad).ok) << bad;
  EXPECT_NE(check_folder_name(std::string(300, 'a')).message.find("at most 100 characters"),
            std::string::npos);
  EXPECT_EQ(folder_name_from("my scan (2)"), "my_scan__2_");
  EXPECT_EQ(folder_name_from(".."), "experiment");

  // The experiment's name and a variant's, as a file gives them.
  json c = small_config();
  c["name"] = "../victim";
  EXPECT_NE(error_of([&] {
              read_experiment(c, ".", "shared.json");
            }).find("shared.json: name: expected a name of letters, digits"),
            std::string::npos);
  c = small_config();
  c["variants"] = {{{"name", std::string(300, 'v')}}};
  EXPECT_NE(error_of([&] {
              read_experiment(c, ".", "shared.json");
            }).find("variants[0].name: expected a name of at most 100 characters"),
            std::string::npos);
  // Without -o the output is out/NAME, and a bad name never makes a path.
  EXPECT_EQ(output_folder("", "small"), fs::path("out/small"));
  EXPECT_NE(error_of([] { output_folder("", "../victim"); }).find("the experiment's name"),
            std::string::npos);
}

TEST(OutputFolder, PathsAsUsersTypeThemAreNormalisedBeforeTheRun) {
  ScratchDir dir;
  EXPECT_EQ(output_folder((dir.path() / "out/small/").string(), "x"), dir.path() / "out/small");
  EXPECT_EQ(output_folder((dir.path() / "out/./a/../small").string(), "x"),
            dir.path() / "out/small");
  for (const std::string& bad :
       std::vector<std::string>{".", "./", "/", "..", "a/..", std::string(200, 'o')})
    EXPECT_NE(error_of([&] { output_folder(bad, "x"); }).find("-o " + bad), std::string::npos)
        << bad;
}

TEST(OutputFolder, OnlyFoldersFiberfluidWroteAreReplaced) {
  ScratchDir dir;
  // Another tool's data set that happens to hold a summary.json.
  const fs::path data = dir.path() / "data";
  fs::create_directories(data);
  std::ofstream(data / "summary.json") << "{}";
  std::ofstream(data / "scan.obj") << "v 0 0 0\n";
  EXPECT_NE(error_of([&] {
              check_replaceable(data);
            }).find("data: exists and was not written by fiberfluid"),
            std::string::npos);
  // An older fiberfluid's folder (before the marker) is named as such, and kept.
  const fs::path old = dir.path() / "old";
  fs::create_directories(old);
  std::ofstream(old / "summary.json") << R"({"fiberfluid_version": "0.1.0"})";
  EXPECT_NE(error_of([&] { check_replaceable(old); }).find("holds results of an older fiberfluid"),
            std::string::npos);
  // A marker of another format does not count either.
  std::ofstream(data / kOutputMarker) << R"({"format": "something-else", "version": 1})";
  EXPECT_THROW(check_replaceable(data), InputError);
  // A file, a symbolic link.
  std::ofstream(dir.path() / "file") << "x";
  EXPECT_NE(error_of([&] { check_replaceable(dir.path() / "file"); }).find("is not a folder"),
            std::string::npos);
  fs::create_directory_symlink(data, dir.path() / "link");
  EXPECT_NE(error_of([&] { check_replaceable(dir.path() / "link"); }).find("symbolic link"),
            std::string::npos);
  // Absent, empty, and written by fiberfluid: replaceable.
  EXPECT_NO_THROW(check_replaceable(dir.path() / "absent"));
  fs::create_directories(dir.path() / "empty");
  EXPECT_NO_THROW(check_replaceable(dir.path() / "empty"));

  const Experiment ex = parse_experiment(small_config(), ".", "small.json");
  {
    OutputWriter writer(ex, dir.path() / "out");
    writer.begin();
    writer.finish(run_experiment(ex));
  }
  EXPECT_TRUE(fs::exists(dir.path() / "out" / kOutputMarker));
  EXPECT_NE(read_text(dir.path() / "out" / kOutputMarker).find("\"format\": \"fiberfluid-output\""),
            std::string::npos);
  EXPECT_NO_THROW(check_replaceable(dir.path() / "out"));
  EXPECT_TRUE(fs::exists(data / "scan.obj"));
}

TEST(OutputFolder, AForeignFolderThatAppearsDuringTheRunIsSwappedBack) {
  ScratchDir dir;
  const fs::path target = dir.path() / "out";
  const fs::path staging = create_staging_folder(target, "x");
  std::ofstream(staging / "result.csv") << "1\n";
  // Between the check and the swap, someone puts their own folder there.
  fs::create_directories(target);
  std::ofstream(target / "theirs.txt") << "keep me";
  const std::string error = error_of([&] { move_into_place(staging, target, nullptr); });
  EXPECT_NE(error.find("was not written by fiberfluid"), std::string::npos) << error;
  EXPECT_NE(error.find("the results are in " + staging.string()), std::string::npos) << error;
  EXPECT_EQ(read_text(target / "theirs.txt"), "keep me");
  EXPECT_EQ(read_text(staging / "result.csv"), "1\n");
}

TEST(OutputFolder, StagingNamesAreUniqueAndOnlyDeadRunsOfThisHostAreCleaned) {
  ScratchDir dir;
  const fs::path target = dir.path() / "out";
  const fs::path a = create_staging_folder(target, "x"), b = create_staging_folder(target, "x");
  EXPECT_NE(a, b);  // the same process twice (two threads, two writers)
  EXPECT_TRUE(fs::exists(a / kOutputMarker));
  // Another host's folder with our PID, and this host's folder of a process that is gone.
  const fs::path other_host =
      dir.path() / ("out.running-elsewhere-" + std::to_string(getpid()) + "-00000000");
  fs::create_directories(other_host);
  std::string mine = a.filename().string();
  mine = mine.substr(0, mine.rfind('-', mine.rfind('-') - 1));  // out.running-HOST
  const fs::path dead = dir.path() / (mine + "-999999999-0000abcd");
  fs::create_directories(dead);
  create_staging_folder(target, "x");
  EXPECT_TRUE(fs::exists(other_host));
  EXPECT_FALSE(fs::exists(dead));
  EXPECT_TRUE(fs::exists(a));  // its process (this one) is alive
}

TEST(OutputFolder, WritersRacingForOneFolderNeverMixOrLoseAResult) {
  ScratchDir dir;
  const fs::path out = dir.path() / "out";
  json soft = small_config(), stiff = small_config();
  stiff["material"]["Y"] = 30000;
  const Experiment a = parse_experiment(soft, ".", "a.json"),
                   b = parse_experiment(stiff, ".", "b.json");
  const ExperimentResult ra = run_experiment(a), rb = run_experiment(b);
  std::atomic<int> failures{0};
  auto write = [&](const Experiment& ex, const ExperimentResult& r) {
    for (int k = 0; k < 10; ++k) {
      try {
        OutputWriter writer(ex, out);
        writer.begin();
        writer.finish(r);
      } catch (const std::exception&) {
        ++failures;
      }
    }
  };
  std::thread first(write, std::cref(a), std::cref(ra)), second(write, std::cref(b), std::cref(rb));
  first.join();
  second.join();
  EXPECT_EQ(failures, 0);
  // One complete result, from one writer: its summary and its final state agree.
  const json summary = json::parse(read_text(out / "summary.json"));
  const double Y = summary["runs"][0]["material"]["Y"].get<double>();
  EXPECT_TRUE(Y == 3000 || Y == 30000) << Y;
  const ExperimentResult& r = Y == 3000 ? ra : rb;
  EXPECT_NEAR(summary["figures"]["max_displacement"].get<double>(),
              r.figures.at("max_displacement"), 0.0);
  for (const auto& entry : fs::directory_iterator(dir.path()))
    EXPECT_EQ(entry.path().filename(), "out")
        << entry.path();  // no staging or previous result left
}

// Issue 30: an exception in a worker of a sweep (a write that failed) ended
// the process with std::terminate; it is the caller's, as with one job.
TEST(Runner, AnExceptionInAWorkerReachesTheCaller) {
  json c = small_config();
  c["variants"] = {{{"name", "a"}}, {{"name", "b"}}, {{"name", "c"}}};
  const Experiment ex = parse_experiment(c, ".", "sweep.json");
  RunOptions options;
  options.jobs = 2;
  const std::string error = error_of([&] {
    run_experiment(
        ex,
        [](size_t run, const solve::StepRecord&, const Eigen::VectorXd&) {
          if (run == 1) throw InputError("b/vtk/step_0001.vtu: writing failed: File too large");
        },
        options);
  });
  EXPECT_EQ(error, "b/vtk/step_0001.vtu: writing failed: File too large");
  // A standard library exception too, not only the project's.
  EXPECT_THROW(run_experiment(
                   ex,
                   [](size_t, const solve::StepRecord&, const Eigen::VectorXd&) {
                     throw std::runtime_error("disk gone");
                   },
                   options),
               std::runtime_error);
}

TEST(Threads, AnExceptionInAnOpenMPLoopIsRethrownAfterIt) {
  ThreadFailure failure;
  std::atomic<int> ran{0};
#pragma omp parallel for schedule(dynamic, 1)
  for (int i = 0; i < 1000; ++i) {
    if (failure.happened()) continue;
    try {
      ++ran;
      if (i == 7) throw InputError("item 7 failed");
    } catch (...) {
      failure.capture();
    }
  }
  EXPECT_TRUE(failure.happened());
  EXPECT_GE(ran.load(), 8);  // (how many the other thread ran meanwhile is a race: not asserted)
  EXPECT_EQ(error_of([&] { failure.rethrow_if_any(); }), "item 7 failed");
  ThreadFailure none;
  EXPECT_NO_THROW(none.rethrow_if_any());
}

}  // namespace
}  // namespace fiberfluid::experiment

namespace fiberfluid::experiment {
namespace {

// Runs an experiment into DIR and returns DIR.
fs::path run_into(const Experiment& ex, const fs::path& folder) {
  OutputWriter writer(ex, folder);
  writer.begin();
  writer.finish(run_experiment(ex));
  return folder;
}

// The output folder keeps the experiment as read and as resolved; running
// the resolved one repeats the run bit for bit (every file but those that
// hold wall times, whose figures are compared): a plain run, a Newton sweep
// of variants, and a surface a program gave.
TEST(OutputFolder, TheResolvedExperimentRepeatsTheRunBitForBit) {
  ScratchDir dir;
  for (const char* name : {"sphere.json", "round_trip.json"}) {
    SCOPED_TRACE(name);
    Experiment first = load_experiment(testing::experiment_file(name));
    if (first.document.contains("variants")) {  // the sweep's short variants are enough
      nlohmann::json shorter = first.document;
      nlohmann::json& variants = shorter["variants"];
      variants.erase(std::remove_if(variants.begin(), variants.end(),
                                    [](const nlohmann::json& v) {
                                      return v["stepping"]["steps"].get<int>() > 20;
                                    }),
                     variants.end());
      shorter.erase("expected");
      EXPECT_THROW(run_into(read_experiment(shorter, ".", name), dir.path() / "unbuilt"),
                   std::logic_error);  // read, not built: said, not a crash
      first = parse_experiment(shorter, testing::experiment_file("").parent_path(), name);
    }
    const fs::path a = run_into(first, dir.path() / (std::string("a_") + name));
    EXPECT_EQ(nlohmann::json::parse(read_text(a / "experiment.json")), first.document);
    const Experiment again = load_experiment(a / "experiment.resolved.json");
    EXPECT_EQ(again.resolved, first.resolved);  // resolving is idempotent
    const fs::path b = run_into(again, dir.path() / (std::string("b_") + name));
    for (const auto& entry : fs::recursive_directory_iterator(a)) {
      const std::string file = entry.path().filename().string();
      if (!entry.is_regular_file() || file == "summary.json" || file == kOutputMarker ||
          file == "steps.csv" || file == "comparison.csv" ||  // these hold the wall time
          file == "experiment.json")                          // b's is a's resolved one
        continue;
      const fs::path other = b / fs::relative(entry.path(), a);
      EXPECT_EQ(read_text(entry.path()), read_text(other)) << other;
    }
    const auto figures = [](const fs::path& folder) {
      return nlohmann::json::parse(read_text(folder / "summary.json"))["figures"];
    };
    EXPECT_EQ(figures(a), figures(b));
  }
  // summary.json says what made the run: the whole material and the build.
  const nlohmann::json summary =
      nlohmann::json::parse(read_text(dir.path() / "a_sphere.json" / "summary.json"));
  EXPECT_EQ(summary["runs"][0]["material"]["gamma"], 3000.0);
  EXPECT_EQ(summary["runs"][0]["material"]["kinematics"], "vector");
  EXPECT_EQ(summary["build"]["version"], summary["fiberfluid_version"]);
  EXPECT_NE(summary["build"]["lapack"], "");
  // The BLAS the run loaded has the threading the build checked for (one
  // thread pool: OpenBLAS's OpenMP build, selected by scripts/install-deps.sh).
  const std::string threading = summary["build"]["blas_threading_at_build"];
  if (threading != "unknown") {
    EXPECT_NE(summary["build"]["blas"].get<std::string>().find("(threading: " + threading + ")"),
              std::string::npos)
        << summary["build"];
  }
  // A program's surface is written beside the resolved file, which reads it.
  nlohmann::json given = small_config();
  const geom::Surface ball = geom::icosphere(1, 1.0);
  given.erase("surface");
  Experiment program = read_experiment(given, ".", "program");
  build_experiment(program, &ball);
  const fs::path c = run_into(program, dir.path() / "c");
  EXPECT_TRUE(fs::exists(c / "input_surface.obj"));
  const Experiment reread = load_experiment(c / "experiment.resolved.json");
  const fs::path d = run_into(reread, dir.path() / "d");
  EXPECT_EQ(read_text(c / "vertices.csv"), read_text(d / "vertices.csv"));
}

// Every shipped experiment resolves: reading its resolved form gives the
// same resolved form (the defaults written out are read back as such).
TEST(OutputFolder, EveryShippedExperimentResolvesToItself) {
  int resolved = 0;
  for (const auto& entry : fs::directory_iterator(testing::experiment_file("").parent_path())) {
    if (entry.path().extension() != ".json") continue;
    SCOPED_TRACE(entry.path().filename().string());
    std::ifstream in(entry.path());
    nlohmann::json document = parse_json(in, entry.path().string());
    if (!document.contains("name")) document["name"] = entry.path().stem().string();
    const Experiment ex = read_experiment(document, entry.path().parent_path(), "shipped");
    const Experiment again = read_experiment(ex.resolved, ".", "resolved");
    EXPECT_EQ(again.resolved, ex.resolved);
    ++resolved;
  }
  EXPECT_GT(resolved, 20);
}

}  // namespace
}  // namespace fiberfluid::experiment
