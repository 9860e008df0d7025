// SPDX-License-Identifier: GPL-3.0-or-later
// What the fiberfluid command's subcommands share: exit codes, the run and
// fit flags, Ctrl-C, loading an experiment with its progress shown, plots,
// and keeping MPI ranks in step.
#pragma once

#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>

#include "fiberfluid/app/progress_printer.hpp"
#include "fiberfluid/experiment/experiment.hpp"
#include "fiberfluid/parallel/ranks.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::app {

namespace experiment = fiberfluid::experiment;

enum ExitCode {
  kOk = 0,
  kBadInput = 1,
  kSolverFailed = 2,
  kChecksFailed = 3,
  kUsage = 64,
  kInterrupted = 130,  // 128 + SIGINT, as a shell reports a process ended by Ctrl-C
};

struct RunFlags {
  std::string output;
  bool check_expected = false;
  bool quiet = false;
  bool plot = false;  // draw DIR/plot.png after a successful run
  int jobs = 0;
  double max_memory = 0.0;  // bytes; 0: 80% of the machine's memory
  double max_time = 0.0;    // seconds of estimated time; 0: no limit
};

// The first Ctrl-C asks the run to stop at its next check (a load step, a
// pruning row, a solver iteration) and clean up; a second one ends the
// process at once (the handler is reset after the first).
void stop_on_interrupt();
// Throws Interrupted after a phase that returned early because of Ctrl-C,
// before its partial results are written anywhere.
void stop_if_interrupted(const std::string& phase);

// Loads an experiment (throwing before anything is written), drawing the
// progress of long phases such as pruning unless quiet; the sink stays set.
// Estimates of long runs are printed before they start (as notes).
experiment::Experiment load_showing_progress(const std::string& path, bool quiet,
                                             ProgressPrinter& printer);

// --plot: DIR/plot.png from DIR/`input`, drawn by the plot script with the
// first python3 that has matplotlib. A plot that cannot be drawn is a
// warning: the results are written already.
void draw_plot(const std::filesystem::path& folder, const std::string& input = "summary.json");
// A prediction's DIR/prediction.png (experiments/plot_prediction.py): its
// force against travel with the 95% band, and the measured curve if given.
void draw_prediction_plot(const std::filesystem::path& folder,
                          const std::filesystem::path& measured);

// Thrown on a rank whose own part of a step succeeded when another rank's failed.
struct AnotherRankFailed : InputError {
  AnotherRankFailed()
      : InputError(
            "another MPI rank could not read the experiment or prepare its run (run "
            "it without mpirun to see why)") {}
};

// True once every rank is failing the same way (on_every_rank, a
// disagreement): the ranks end on their own. A failure on one rank alone
// ends the whole job instead (main).
extern bool every_rank_fails;

// Runs `step` on every rank and ends in agreement: when it throws on one
// rank, it throws on all (the others an AnotherRankFailed), so no rank goes on
// to wait for work that will never be dealt.
void on_every_rank(const parallel::Ranks& ranks, const std::function<void()>& step);

// Fault injection for the tests of a failure on one rank alone
// (tests/mpi/mpi_test.sh): FIBERFLUID_FAIL_RANK=r makes rank r throw once its
// run is set up, outside any work item, while the others wait for it.
void fail_if_injected(const parallel::Ranks& ranks);

// Every rank must run what rank 0 runs: refused on every rank, naming them.
void require_one_experiment(const parallel::Ranks& ranks, const experiment::Experiment& ex,
                            const std::string& path);

// fiberfluid run (run_command.cpp) and fiberfluid fit (fit_command.cpp).
int run_command(const std::string& path, const RunFlags& flags, const parallel::Ranks& ranks);
int fit_command(const std::string& path, const RunFlags& flags, const parallel::Ranks& ranks);
// fiberfluid predict (predict_command.cpp): EXPERIMENT run at the values of
// the fit in FIT_FOLDER, with bands.
struct PredictFlags {
  std::string fit_folder, experiment;
  std::string measured;  // a measured force curve to plot beside the prediction
};
int predict_command(const PredictFlags& predict, const RunFlags& flags);

}  // namespace fiberfluid::app
