// SPDX-License-Identifier: GPL-3.0-or-later
// The reproducers of issues 27 and 30, run as a user ran them: results are
// never lost, nothing is written outside its place, a fit always ends with a
// status that says what happened, and nothing ends in a crash.
#include <gtest/gtest.h>

#include <thread>

#include <nlohmann/json.hpp>

#include "app/cli_support.hpp"
#include "fiberfluid/experiment/write/file_names.hpp"
#include "fiberfluid/experiment/write/output_folder.hpp"
#include "test_support.hpp"

namespace fiberfluid {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::Outcome;
using testing::read_file;
using testing::run_cli;
using testing::run_cli_command;
using testing::ScratchDir;

const char kSmall[] = R"({"name": "small",
  "surface": {"generator": "icosphere", "subdivisions": 1},
  "material": {"Y": 3000, "gamma": 3000},
  "supports": [{"where": "z >= 0.8"}],
  "loads": [{"type": "gravity", "acceleration": [0, 0, -10], "density": 1000}],
  "stepping": {"steps": 2}})";

// `fiberfluid ARGUMENTS` run from `folder` (for the default output folder out/NAME).
Outcome run_in(const fs::path& folder, const std::string& arguments,
               const std::string& shell_prefix = "") {
  return run_cli_command("cd '" + folder.string() + "' && " + shell_prefix +
                         std::string(FIBERFLUID_CLI) + " " + arguments);
}

json fit_sphere() {
  std::ifstream in(testing::experiment_file("fit_sphere.json"));
  json d = json::parse(in);
  d["fit"]["targets"][0]["file"] = testing::data_target("sphere_final.obj").string();
  d["expected"] = json::array();
  return d;
}

// Issue 43, "names are refused when the file is read": a variant or a
// specimen named like a file of the result (its folder would sit beside it)
// ran the whole sweep and then failed to write, discarding every result.
TEST(NamesAreRefusedWhenTheFileIsRead, AVariantOrSpecimenNamedLikeAResultFileIsRefusedAtOnce) {
  ScratchDir dir;
  for (const char* name : {"summary.json", "comparison.csv", "experiment.json", "FAILED", "vtk",
                           "fit_force_0.csv", "fit_target_2.vtu"}) {
    json config = json::parse(kSmall);
    config["variants"] = {{{"name", "fine"}}, {{"name", name}}};
    const auto file = dir.write("sweep.json", config.dump());
    const Outcome o = run_in(dir.path(), "run sweep.json -q");
    EXPECT_EQ(o.status, 1) << o.output;
    EXPECT_NE(o.output.find("sweep.json: variants[1].name: expected a name that is not one of "
                            "the result's own files"),
              std::string::npos)
        << o.output;
    EXPECT_EQ(o.output.find("step 1"), std::string::npos) << "it ran: " << o.output;
    EXPECT_FALSE(fs::exists(dir.path() / "out")) << name;
  }
  // A specimen of a calibration: refused by the reader too.
  dir.write("a.json", fit_sphere().dump());
  const json calibration = {{"name", "joint"},
                            {"kind", "calibration"},
                            {"shared", {"Y"}},
                            {"specimens",
                             {{{"name", "a"}, {"experiment", "a.json"}},
                              {{"name", "calibration.json"}, {"experiment", "a.json"}}}}};
  dir.write("joint.json", calibration.dump());
  const Outcome joint = run_in(dir.path(), "fit joint.json -q");
  EXPECT_EQ(joint.status, 1) << joint.output;
  EXPECT_NE(joint.output.find("specimens[1].name: expected a name that is not one of"),
            std::string::npos)
      << joint.output;
}

// The reserved names are every name a result writes at its top: a sweep's
// and a fit's folders hold nothing else (beside the variants' folders).
TEST(NamesAreRefusedWhenTheFileIsRead, EveryNameAResultWritesAtItsTopIsReserved) {
  ScratchDir dir;
  json config = json::parse(kSmall);
  config["variants"] = {{{"name", "soft"}, {"material", {{"Y", 2000}}}}, {{"name", "stiff"}}};
  dir.write("sweep.json", config.dump());
  ASSERT_EQ(run_in(dir.path(), "run sweep.json -q -o sweep --plot").status, 0);
  dir.write("fit.json", fit_sphere().dump());
  const Outcome fitted = run_in(dir.path(), "fit fit.json -q -o fit");
  ASSERT_EQ(fitted.status, 0) << fitted.output;
  int seen = 0;
  for (const char* result : {"sweep", "fit"})
    for (const fs::directory_entry& entry : fs::directory_iterator(dir.path() / result)) {
      const std::string name = entry.path().filename().string();
      if (std::string(result) == "sweep" && (name == "soft" || name == "stiff")) continue;
      EXPECT_FALSE(experiment::check_not_reserved(name).ok)
          << result << "/" << name << " is written but not reserved";
      ++seen;
    }
  EXPECT_GT(seen, 10);
}

// Issue 43, "one result folder never sits inside another": run A -o X, fit
// B -o X/inner, run A -o X again deleted X/inner with X.
TEST(OneResultFolderNeverSitsInsideAnother, AFolderInsideAResultIsRefusedAndSoIsOneHoldingAResult) {
  ScratchDir dir;
  dir.write("small.json", kSmall);
  dir.write("fit.json", fit_sphere().dump());
  ASSERT_EQ(run_in(dir.path(), "run small.json -q -o X").status, 0);
  const Outcome inner = run_in(dir.path(), "fit fit.json -q -o X/inner");
  EXPECT_EQ(inner.status, 1) << inner.output;
  EXPECT_NE(inner.output.find("X/inner: inside " + (dir.path() / "X").string() +
                              ", a fiberfluid result folder"),
            std::string::npos)
      << inner.output;
  EXPECT_FALSE(fs::exists(dir.path() / "X" / "inner"));
  EXPECT_FALSE(fs::exists(dir.path() / "X" / "inner.failed"));
  // Deeper too, and the outer result stays as it was.
  EXPECT_EQ(run_in(dir.path(), "run small.json -q -o X/a/b/c").status, 1);
  EXPECT_TRUE(fs::exists(dir.path() / "X" / "summary.json"));
  // The reverse: a result moved by hand into another one is not deleted by
  // running the outer one again.
  ASSERT_EQ(run_in(dir.path(), "run small.json -q -o Y").status, 0);
  fs::rename(dir.path() / "Y", dir.path() / "X" / "kept");
  const Outcome outer = run_in(dir.path(), "run small.json -q -o X");
  EXPECT_EQ(outer.status, 1) << outer.output;
  EXPECT_NE(outer.output.find("holds another fiberfluid result folder"), std::string::npos)
      << outer.output;
  EXPECT_TRUE(fs::exists(dir.path() / "X" / "kept" / "summary.json"));
}

// Issue 43, "budgets cover every phase": a generated surface of a million
// vertices grew to a gigabyte and ran past --max-time before the case's own
// estimate could refuse it; remesh_vertices 1000000 ran 30 s first; a
// SIGTERM did not stop the generation.
TEST(BudgetsCoverEveryPhase, ASurfaceBeyondTheBudgetsIsRefusedBeforeItIsBuiltAndStopsWhenAsked) {
  ScratchDir dir;
  json big = json::parse(kSmall);
  big["surface"] = {
      {"generator", "cylinder"}, {"radius", 0.02}, {"length", 0.1}, {"segments", {1000, 1000}}};
  big["supports"] = {{{"where", "x <= 0"}}};
  dir.write("big.json", big.dump());
  for (const char* flags : {"--max-memory 100M", "--max-time 1"}) {
    const auto began = std::chrono::steady_clock::now();
    const Outcome o = run_in(dir.path(), std::string("run big.json -q ") + flags);
    EXPECT_EQ(o.status, 1) << o.output;
    EXPECT_NE(o.output.find("big.json: surface.generator: about 1334335 vertices: making and "
                            "checking them alone needs about"),
              std::string::npos)
        << o.output;
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count(), 2.0)
        << flags;
  }
  json remeshed = json::parse(kSmall);
  remeshed["surface"]["remesh_vertices"] = 1000000;
  dir.write("remeshed.json", remeshed.dump());
  const Outcome r = run_in(dir.path(), "run remeshed.json -q --max-memory 100M");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("surface.remesh_vertices: about 1000000 vertices"), std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(dir.path() / "out"));
  // Within the budgets, a SIGTERM stops the surface's making and checks
  // between their parts. The longest part is the exact self-intersection
  // test: 4 to 8 s on a 400,000-vertex cylinder here, 10.9 s once beside
  // other work; this one has half as many vertices.
  big["surface"]["segments"] = {1000, 200};
  dir.write("large.json", big.dump());
  const fs::path log = dir.path() / "large.log";
  const pid_t pid = testing::start_cli(
      {"run", (dir.path() / "large.json").string(), "-q", "-o", (dir.path() / "large").string()},
      log);
  std::this_thread::sleep_for(std::chrono::milliseconds(700));
  const auto signalled = std::chrono::steady_clock::now();
  kill(pid, SIGTERM);
  EXPECT_EQ(testing::wait_for(pid), 130) << read_file(log);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - signalled).count(),
            10.0);
  EXPECT_FALSE(fs::exists(dir.path() / "large"));
}

TEST(CliSafety, ANameFromAFileNeverWritesOutsideTheOutputRoot) {
  ScratchDir dir;
  fs::create_directories(dir.path() / "victim");
  std::ofstream(dir.path() / "victim" / "thesis.tex") << "years of work";
  json config = json::parse(kSmall);
  config["name"] = "../victim";
  const auto file = dir.write("shared.json", config.dump());
  const Outcome o = run_in(dir.path(), "run shared.json -q");
  EXPECT_EQ(o.status, 1) << o.output;
  EXPECT_NE(o.output.find("shared.json: name: expected a name of letters, digits"),
            std::string::npos)
      << o.output;
  EXPECT_EQ(read_file(dir.path() / "victim" / "thesis.tex"), "years of work");
  EXPECT_FALSE(fs::exists(dir.path() / "out"));
  // A good name goes to out/NAME; a file with no name takes its stem, made safe.
  config.erase("name");
  dir.write("my scan (2).json", config.dump());
  const Outcome unnamed = run_in(dir.path(), "run 'my scan (2).json' -q");
  EXPECT_EQ(unnamed.status, 0) << unnamed.output;
  EXPECT_TRUE(fs::exists(dir.path() / "out" / "my_scan__2_" / "summary.json"));
}

TEST(CliSafety, AFolderFiberfluidDidNotWriteIsNeverReplacedAndTheRunNeverStarts) {
  ScratchDir dir;
  const fs::path data = dir.path() / "data";
  fs::create_directories(data);
  std::ofstream(data / "summary.json") << R"({"written by": "another tool"})";
  std::ofstream(data / "scan_0001.ply") << "ply";
  const auto file = dir.write("small.json", kSmall);
  const Outcome o = run_cli("run " + file.string() + " -q -o " + data.string());
  EXPECT_EQ(o.status, 1) << o.output;
  EXPECT_NE(o.output.find(data.string() + ": exists and was not written by fiberfluid"),
            std::string::npos)
      << o.output;
  EXPECT_EQ(o.output.find("results in"), std::string::npos) << o.output;  // refused before the run
  EXPECT_TRUE(fs::exists(data / "scan_0001.ply"));
  // The same for a fit, before its forward runs.
  const Outcome fit = run_cli("fit " + dir.write("fit.json", fit_sphere().dump()).string() +
                              " -o " + data.string());
  EXPECT_EQ(fit.status, 1) << fit.output;
  EXPECT_EQ(fit.output.find("fit: iteration"), std::string::npos) << fit.output;
}

TEST(CliSafety, AnOutputPathWithATrailingSlashIsTheFolder) {
  ScratchDir dir;
  const auto file = dir.write("small.json", kSmall);
  const Outcome o =
      run_cli("run " + file.string() + " -q -o " + (dir.path() / "out" / "small").string() + "/");
  EXPECT_EQ(o.status, 0) << o.output;
  EXPECT_TRUE(fs::exists(dir.path() / "out" / "small" / "summary.json"));
  // And again: the folder it wrote is replaced, nothing is left beside it.
  EXPECT_EQ(
      run_cli("run " + file.string() + " -q -o " + (dir.path() / "out" / "small").string() + "/")
          .status,
      0);
  for (const auto& entry : fs::directory_iterator(dir.path() / "out"))
    EXPECT_EQ(entry.path().filename(), "small") << entry.path();
}

// A write past the file-size limit (a full disk behaves alike): a named
// error, exit 1, the earlier result kept; never SIGXFSZ or an abort.
TEST(CliSafety, AFailedWriteIsANamedErrorAndTheEarlierResultStays) {
  ScratchDir dir;
  json config = json::parse(kSmall);
  config["variants"] = {{{"name", "a"}}, {{"name", "b"}}, {{"name", "c"}}};
  const auto file = dir.write("sweep.json", config.dump());
  const fs::path out = dir.path() / "out";
  ASSERT_EQ(run_cli("run " + file.string() + " -q -o " + out.string()).status, 0);
  const std::string earlier = read_file(out / "summary.json");
  // 8 KiB a file: the marker fits, the .vtu files of the variants do not.
  const Outcome o = run_in(dir.path(), "run sweep.json -q -j 2 -o out", "ulimit -f 8; ");
  EXPECT_EQ(o.status, 1) << o.output;
  EXPECT_NE(o.output.find("writing failed: File too large"), std::string::npos) << o.output;
  EXPECT_EQ(o.output.find("terminate called"), std::string::npos) << o.output;
  EXPECT_EQ(read_file(out / "summary.json"), earlier);
  for (const auto& entry : fs::directory_iterator(dir.path()))
    EXPECT_EQ(entry.path().filename().string().find(".running-"), std::string::npos)
        << entry.path();
}

TEST(CliSafety, FitOptionsThatCrashedAreNamedErrorsAndNothingIsWritten) {
  ScratchDir dir;
  const struct {
    const char* what;
    std::function<void(json&)> change;
    const char* message;
  } cases[] = {
      {"difference_step 5",
       [](json& d) {
         d["fit"]["jacobian"] = "finite-differences";
         d["fit"]["difference_step"] = 5;
       },
       "fit.difference_step: expected a step in the fitted variable above 0 and at most 0.5"},
      {"lower == upper",
       [](json& d) {
         d["fit"]["parameters"][0]["lower"] = 1000;
         d["fit"]["parameters"][0]["upper"] = 1000;
       },
       "fit.parameters[0]: parameter \"Y\": expected a lower bound below the upper one"},
      {"variant name of 300",
       [](json& d) {
         d.erase("fit");
         d["variants"] = {{{"name", std::string(300, 'v')}}};
       },
       "variants[0].name: expected a name of at most 100 characters"},
  };
  for (const auto& c : cases) {
    json d = fit_sphere();
    c.change(d);
    const auto file = dir.write("case.json", d.dump());
    const Outcome o = run_cli(std::string(d.contains("fit") ? "fit " : "run ") + file.string() +
                              " -o " + (dir.path() / "out").string());
    EXPECT_EQ(o.status, 1) << c.what << "\n" << o.output;
    EXPECT_NE(o.output.find(c.message), std::string::npos) << c.what << "\n" << o.output;
    EXPECT_FALSE(fs::exists(dir.path() / "out")) << c.what;
    EXPECT_FALSE(fs::exists(dir.path() / "out.failed")) << c.what;
  }
  // An experiment nested 100,000 deep (valid JSON, 200 KB): refused with a short message.
  const auto deep =
      dir.write("deep.json", "{\"stepping\": {\"steps\": " + std::string(100000, '[') +
                                 std::string(100000, ']') + "}}");
  for (const char* command : {"run ", "fit "}) {
    const Outcome o = run_cli(command + deep.string());
    EXPECT_EQ(o.status, 1) << o.output.substr(0, 300);
    EXPECT_NE(o.output.find("nested more than 64 levels deep"), std::string::npos)
        << o.output.substr(0, 300);
    EXPECT_LT(o.output.size(), 400u);
  }
}

// A fit whose parameters end on their bounds: converged, status 4, the
// bounds named with the correlation that explains them; the folder has
// every fit file.
TEST(CliSafety, AFitOnItsBoundsSaysSoAndExitsWith4) {
  ScratchDir dir;
  json d = fit_sphere();
  d["fit"]["parameters"][1]["lower"] = 3500;
  const auto file = dir.write("bounds.json", d.dump());
  const Outcome o = run_cli("fit " + file.string() + " -q -o " + (dir.path() / "out").string());
  EXPECT_EQ(o.status, 4) << o.output;
  for (const char* part :
       {"converged_at_bounds", "Y = 10 is on its lower bound (its correlation with gamma is",
        "Y = 10 (on its bound: no standard error", "warning: the fit converged on bounds"})
    EXPECT_NE(o.output.find(part), std::string::npos) << part << "\n" << o.output;
  const json report = json::parse(read_file(dir.path() / "out" / "fit.json"));
  EXPECT_EQ(report["status"], "converged_at_bounds");
  EXPECT_TRUE(report["parameters"][0]["at_bound"].get<bool>());
  EXPECT_TRUE(report["parameters"][0]["standard_error"].is_null());
  EXPECT_EQ(report["counts"]["model_vertices_counted"].get<int>(),
            report["distance"]["count"].get<int>());
}

// A fit that cannot see its parameters (no load) is "not identifiable", its
// folder DIR.failed with every fit file, never "converged +- nan".
TEST(CliSafety, AFitThatCannotSeeItsParametersFailsWithItsReasonAndKeepsItsFiles) {
  ScratchDir dir;
  json d = fit_sphere();
  d["loads"][0]["acceleration"] = {0, 0, 0};
  d["loads"][1]["force"] = {0, 0, 0};
  const auto file = dir.write("still.json", d.dump());
  const fs::path out = dir.path() / "out";
  const Outcome o = run_cli("fit " + file.string() + " -q -o " + out.string());
  EXPECT_EQ(o.status, 2) << o.output;
  EXPECT_NE(o.output.find("not_identifiable"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("no distance changes with \"Y\""), std::string::npos) << o.output;
  EXPECT_EQ(o.output.find("+- nan"), std::string::npos) << o.output;
  EXPECT_FALSE(fs::exists(out));
  fs::path failed = out;
  failed += ".failed";
  EXPECT_NE(read_file(failed / "FAILED").find("not_identifiable"), std::string::npos);
  EXPECT_EQ(json::parse(read_file(failed / "fit.json"))["status"], "not_identifiable");
}

// The crash of difference_step 5, at its root: a central-difference run
// that fails (here at the start, a step of 0.5 in log Y) stops Ceres; the
// fit says so with the run's own message and writes every file (fit.json
// read the missing standard errors, SIGSEGV).
TEST(CliSafety, AFailedDifferenceRunEndsTheFitWithItsCause) {
  ScratchDir dir;
  json d = fit_sphere();
  d["fit"]["difference_step"] = 0.5;
  const fs::path out = dir.path() / "out";
  const Outcome o =
      run_cli("fit " + dir.write("steep.json", d.dump()).string() + " -q -o " + out.string());
  EXPECT_EQ(o.status, 2) << o.output;
  for (const char* part :
       {"forward_runs_failed", "a finite-difference run failed: step 2: runaway",
        "failed forward runs: 1 x a finite-difference run failed: step #: runaway",
        "first failure at Y = 1000, gamma = 9000"})
    EXPECT_NE(o.output.find(part), std::string::npos) << part << "\n" << o.output;
  fs::path failed = out;
  failed += ".failed";
  const json report = json::parse(read_file(failed / "fit.json"));
  EXPECT_EQ(report["status"], "forward_runs_failed");
  EXPECT_NEAR(report["failed_run_examples"][0]["values"]["Y"].get<double>(), 1000.0, 1e-9);
  EXPECT_TRUE(report["parameters"][0]["standard_error"].is_null());
}

// SIGINT during a fit: the best point so far is kept in DIR.interrupted, and
// "start_from" continues from it.
// Issue 43, "an interrupted or stopped fit keeps its best point": SIGINT
// after iteration 2 left fit.json at the start (Ceres puts its start back
// into the parameters when a callback aborts), and start_from began again.
TEST(AnInterruptedFitKeepsItsBestPoint, AtAnyIterationAndStartFromGoesOnFromThere) {
  ScratchDir dir;
  json slow = fit_sphere();
  slow["surface"]["subdivisions"] = 3;
  const auto file = dir.write("slow.json", slow.dump());
  const fs::path out = dir.path() / "out", log = dir.path() / "fit.log";
  const pid_t pid = testing::start_cli({"fit", file.string(), "-o", out.string()}, log);
  for (int wait = 0; wait < 2400 && read_file(log).find("fit: iteration 2:") == std::string::npos;
       ++wait)
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
  ASSERT_NE(read_file(log).find("fit: iteration 2:"), std::string::npos) << read_file(log);
  const auto signalled = std::chrono::steady_clock::now();
  kill(pid, SIGINT);
  EXPECT_EQ(testing::wait_for(pid), 130) << read_file(log);
  // It stops at once, wherever it was (the bending phantom, 1,418 vertices:
  // at most 1.3 s, experiments measured by hand in the issue's note).
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - signalled).count(),
            2.0);
  fs::path interrupted = out;
  interrupted += ".interrupted";
  const json report = json::parse(read_file(interrupted / "fit.json"));
  ASSERT_EQ(report["status"], "interrupted");
  // The best accepted point: the last accepted iteration's, not the start.
  json last;
  for (const json& it : report["iterations"])
    if (it["accepted"].get<bool>()) last = it;
  ASSERT_GE(last["iteration"].get<int>(), 2) << report["iterations"].dump();
  const double Y = report["parameters"][0]["value"], gamma = report["parameters"][1]["value"];
  EXPECT_EQ(Y, last["values"]["Y"].get<double>());
  EXPECT_EQ(gamma, last["values"]["gamma"].get<double>());
  EXPECT_NE(Y, 1000.0);
  EXPECT_EQ(report["cost"]["final"].get<double>(), last["cost"].get<double>());
  // An interrupted run is no failed run.
  EXPECT_EQ(report["failed_runs"], 0) << report["failed_runs_by_cause"].dump();
  // start_from goes on from there: its first cost is the last one reported.
  json next = slow;
  next["fit"]["start_from"] = (interrupted / "fit.json").string();
  next["fit"]["parameters"][0].erase("start");
  next["fit"]["max_iterations"] = 1;
  const Outcome o = run_cli("fit " + dir.write("next.json", next.dump()).string() + " -o " +
                            (dir.path() / "next").string());
  fs::path next_out = dir.path() / "next";
  next_out += ".failed";  // one iteration: iteration_limit
  const json continued = json::parse(read_file(next_out / "fit.json"));
  EXPECT_EQ(continued["iterations"][0]["cost"].get<double>(), last["cost"].get<double>())
      << o.output;
  EXPECT_NEAR(continued["parameters"][0]["initial"].get<double>() / Y, 1.0, 1e-12);
}

TEST(CliSafety, AnInterruptedFitKeepsItsBestPointAndCanBeContinued) {
  ScratchDir dir;
  json slow = fit_sphere();
  slow["surface"]["subdivisions"] = 3;  // about 5 s per iteration: time to interrupt it
  const auto file = dir.write("slow.json", slow.dump());
  const fs::path out = dir.path() / "out", log = dir.path() / "fit.log";
  const pid_t pid = testing::start_cli({"fit", file.string(), "-o", out.string()}, log);
  for (int wait = 0; wait < 1200 && read_file(log).find("fit: iteration 0:") == std::string::npos;
       ++wait)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ASSERT_NE(read_file(log).find("fit: iteration 0:"), std::string::npos) << read_file(log);
  kill(pid, SIGINT);
  EXPECT_EQ(testing::wait_for(pid), 130) << read_file(log);
  fs::path interrupted = out;
  interrupted += ".interrupted";
  ASSERT_TRUE(fs::exists(interrupted / "fit.json")) << read_file(log);
  EXPECT_TRUE(fs::exists(interrupted / "INTERRUPTED"));
  EXPECT_FALSE(fs::exists(out));
  const json report = json::parse(read_file(interrupted / "fit.json"));
  EXPECT_EQ(report["status"], "interrupted");
  EXPECT_NEAR(report["parameters"][0]["value"].get<double>(), 1000.0,
              1e-9);  // the start: iteration 0's point
  EXPECT_NE(read_file(log).find("start_from"), std::string::npos) << read_file(log);

  // Continued (on the quicker mesh) from that point: it starts there and converges.
  json next = fit_sphere();
  next["fit"]["start_from"] = (interrupted / "fit.json").string();
  next["fit"]["parameters"][0].erase("start");
  const Outcome o =
      run_cli("fit " + dir.write("next.json", next.dump()).string() + " -o " + out.string());
  EXPECT_EQ(o.status, 0) << o.output;
  EXPECT_NE(o.output.find("Y = 1000, gamma = 9000"), std::string::npos) << o.output;
  EXPECT_EQ(json::parse(read_file(out / "fit.json"))["status"], "converged");
}

}  // namespace
}  // namespace fiberfluid
