// SPDX-License-Identifier: GPL-3.0-or-later
// fiberfluid: command-line tool. It only parses, loads and dispatches.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>
#include <unistd.h>

#include "app/experiment.hpp"
#include "app/outputs.hpp"
#include "app/runner.hpp"
#include "geom/error.hpp"
#include "geom/mesh_check.hpp"
#include "geom/mesh_io.hpp"

namespace {

namespace app = fiberfluid::app;

enum ExitCode { kOk = 0, kBadInput = 1, kSolverFailed = 2, kChecksFailed = 3 };

// Prints a progress line per step on a terminal, or about ten lines otherwise.
class Progress {
 public:
  explicit Progress(const app::Experiment& ex) : ex_(ex), tty_(isatty(STDERR_FILENO) != 0) {}
  void operator()(size_t run, const fiberfluid::solve::StepRecord& r) const {
    const int steps = ex_.variants[run].stepping.steps;
    if (steps < 10) return;
    const bool last = r.step == steps;
    if (!tty_ && r.step % std::max(1, steps / 10) != 0 && !last) return;
    const std::string& variant = ex_.variants[run].name;
    std::fprintf(stderr, "%s[%s%s%s] step %d/%d  P = %.6g  max|u| = %.6g%s", tty_ ? "\r" : "",
                 ex_.name.c_str(), variant.empty() ? "" : " ", variant.c_str(), r.step, steps,
                 r.pressure, r.max_displacement, tty_ && !last ? "" : "\n");
  }

 private:
  const app::Experiment& ex_;
  bool tty_;
};

int run_command(const std::string& path, std::string output, bool check_expected) {
  const app::Experiment ex = app::load_experiment(path);  // throws before anything is written
  for (const auto& w : ex.warnings) std::cerr << "warning: " << w << "\n";
  if (output.empty()) output = "out/" + ex.name;

  app::OutputWriter writer(ex, output);
  writer.begin();
  const Progress progress(ex);
  const app::ExperimentResult result = app::run_experiment(
      ex, [&](size_t run, const fiberfluid::solve::StepRecord& r, const Eigen::VectorXd& x) {
        progress(run, r);
        writer.on_step(run, r, x);
      });
  writer.finish(result);

  std::cout << ex.name << ": results in " << writer.folder().string() << "\n";
  if (ex.kind == app::Experiment::Kind::Simulate) {
    const app::FiberReport& f = ex.fibers;
    std::cout << "  fibers: " << f.kept << " kept of " << f.pairs << " ("
              << (!f.pruning ? "pruning off" : f.convex ? "convex" : "pruned exactly")
              << "; per vertex " << f.min_per_vertex << " / " << f.mean_per_vertex << " / "
              << f.max_per_vertex << "; " << f.seconds << " s)\n";
  }
  for (const app::RunResult& run : result.runs)
    std::cout << "  " << (run.variant.empty() ? "run" : run.variant) << ": "
              << run.summary.BriefReport() << "\n";
  for (const auto& [name, value] : result.figures)
    std::cout << "  " << name << " = " << value << "\n";
  for (const app::FigureCheck& c : result.checks) std::cout << "  " << c.Describe() << "\n";

  if (!result.runs_succeeded()) {
    for (const app::RunResult& run : result.runs)
      if (!run.summary.success) std::cerr << "error: " << run.summary.message << "\n";
    return kSolverFailed;
  }
  if (check_expected && !result.checks_passed()) {
    std::cerr << "error: some expected figures were not met (see above)\n";
    return kChecksFailed;
  }
  return kOk;
}

int check_command(const std::string& path, bool flip) {
  fiberfluid::geom::ReadResult read = fiberfluid::geom::read_surface(path);
  if (flip) fiberfluid::geom::flip_orientation(read.surface);
  const fiberfluid::geom::MeshReport report = fiberfluid::geom::inspect(read.surface);
  for (const auto& w : read.warnings) std::cerr << "warning: " << w << "\n";
  std::cout << fiberfluid::geom::format_report(report, path);
  if (!report.ok()) {
    std::cerr << "error: " << path << ": " << report.problems.front() << "\n";
    return kBadInput;
  }
  return kOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"fiberfluid: the fibers-and-fluid soft-tissue model (Sardinha et al. 2016)"};
  cli.require_subcommand(1);

  std::string experiment, output, mesh;
  bool check_expected = false, flip = false;
  CLI::App* run = cli.add_subcommand("run", "Run an experiment file");
  run->add_option("experiment", experiment, "Experiment file (JSON)")->required();
  run->add_option("-o,--output", output, "Output folder (default: out/<experiment name>)");
  run->add_flag("--check", check_expected,
                "Exit with status 3 when an expected figure of the file is not met");

  CLI::App* check = cli.add_subcommand("check", "Check a mesh file and print its report");
  check->add_option("mesh", mesh, "Mesh file (.obj, .off, .stl, .ply)")->required();
  check->add_flag("--flip", flip, "Reverse the face orientation before checking");

  CLI11_PARSE(cli, argc, argv);
  try {
    if (run->parsed()) return run_command(experiment, output, check_expected);
    return check_command(mesh, flip);
  } catch (const fiberfluid::InputError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kBadInput;
  } catch (const std::filesystem::filesystem_error& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kBadInput;
  } catch (const std::bad_alloc&) {
    std::cerr << "error: out of memory; use a coarser mesh\n";
    return kSolverFailed;
  }
}
