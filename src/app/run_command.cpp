// SPDX-License-Identifier: GPL-3.0-or-later
// fiberfluid run: an experiment's runs, written as they go.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>

#include "fiberfluid/app/cli.hpp"
#include "fiberfluid/experiment/fit_workflow.hpp"
#include "fiberfluid/experiment/run/fit_setup.hpp"
#include "fiberfluid/experiment/run/runner.hpp"
#include "fiberfluid/experiment/write/benchmark_files.hpp"
#include "fiberfluid/experiment/write/output_folder.hpp"
#include "fiberfluid/experiment/write/outputs.hpp"
#include "fiberfluid/util/progress.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::app {

int run_command(const std::string& path, const RunFlags& flags,
                const fiberfluid::parallel::Ranks& ranks) {
  fiberfluid::set_memory_budget(flags.max_memory);
  fiberfluid::set_time_budget(flags.max_time);
  ProgressPrinter printer;
  // Every rank reads and builds the experiment (the surface and its fibers);
  // rank 0 alone checks and prepares the output folder.
  std::optional<experiment::Experiment> loaded;
  std::optional<experiment::OutputWriter> output;
  on_every_rank(ranks, [&] {
    loaded.emplace(load_showing_progress(path, flags.quiet || !ranks.root(), printer));
  });
  require_one_experiment(ranks, *loaded, path);
  on_every_rank(ranks, [&] {
    if (ranks.root())
      output.emplace(*loaded, experiment::output_folder(flags.output, loaded->name));
  });
  fail_if_injected(ranks);
  const experiment::Experiment& ex = *loaded;
  experiment::RunOptions options;
  options.jobs = flags.jobs;
  if (ranks.size() > 1) options.dealer = ranks.dealer();
  if (!ranks.root()) {
    experiment::serve_cases(ex, options.dealer);
    stop_if_interrupted("the run");
    return kOk;
  }
  if (ex.fit())
    std::cerr << "note: " << path << " has a \"fit\" section: `run` simulates at the starting "
              << "values; `fiberfluid fit` calibrates\n";
  if (ranks.size() > 1 && flags.jobs > 1)
    std::cerr << "note: -j is not used under mpirun: each of the " << ranks.size()
              << " ranks runs one variant at a time with " << ranks.threads()
              << " threads (OMP_NUM_THREADS)\n";
  experiment::OutputWriter& writer = *output;
  writer.begin();
  const experiment::ExperimentResult result = experiment::run_experiment(
      ex,
      [&](size_t run, const fiberfluid::solve::StepRecord& r, const Eigen::VectorXd& x) {
        writer.on_step(run, r, x);
      },
      options);
  printer.close();
  fiberfluid::set_progress_sink({});
  stop_if_interrupted("the run");  // the writer's staging folder goes with it
  writer.finish(result);
  for (const std::string& w : writer.warnings()) std::cerr << "warning: " << w << "\n";

  std::cout << ex.name << ": results in " << writer.folder().string() << "\n";
  if (ex.kind() == experiment::Experiment::Kind::Simulate) {
    const experiment::FiberReport& f = ex.simulation().cases.front().fibers;
    std::cout << "  fibers: " << f.kept << " kept of " << f.pairs << " ("
              << (!f.pruning ? "pruning off"
                  : f.convex ? "convex"
                             : "pruned exactly")
              << "; per vertex " << f.min_per_vertex << " / " << f.mean_per_vertex << " / "
              << f.max_per_vertex << "; " << f.seconds << " s)\n";
  }
  for (const experiment::RunResult& run : result.runs)
    std::cout << "  " << (run.variant.empty() ? "run" : run.variant) << ": "
              << run.summary.BriefReport() << "\n";
  if (result.benchmark) {  // its many figures are in summary.json
    std::cout << experiment::benchmark_report(*result.benchmark);
  } else {
    for (const auto& [name, value] : result.figures)
      std::cout << "  " << name << " = " << value << "\n";
  }
  for (const experiment::FigureCheck& c : result.checks) std::cout << "  " << c.Describe() << "\n";

  if (!result.failure.empty()) {
    std::cerr << "error: " << result.failure << "\n";
    return kSolverFailed;
  }
  if (!result.runs_succeeded()) {
    for (const experiment::RunResult& run : result.runs)
      if (!run.summary.success) std::cerr << "error: " << run.summary.message << "\n";
    return kSolverFailed;
  }
  if (flags.plot && ex.kind() == experiment::Experiment::Kind::Simulate) draw_plot(writer.folder());
  if (flags.check_expected && !result.checks_passed()) {
    std::cerr << "error: some expected figures were not met (see above)\n";
    return kChecksFailed;
  }
  return kOk;
}

}  // namespace fiberfluid::app
