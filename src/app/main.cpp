// SPDX-License-Identifier: GPL-3.0-or-later
// fiberfluid: command-line tool. It only parses, loads and dispatches.
#include <unistd.h>
#include <CLI/CLI.hpp>
#include <csignal>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>

#include "fiberfluid/experiment/build_info.hpp"
#include "fiberfluid/experiment/compare.hpp"
#include "fiberfluid/experiment/experiment.hpp"
#include "fiberfluid/experiment/fitting.hpp"
#include "fiberfluid/experiment/mesh_study.hpp"
#include "fiberfluid/experiment/output_folder.hpp"
#include "fiberfluid/experiment/outputs.hpp"
#include "fiberfluid/experiment/runner.hpp"
#include "fiberfluid/experiment/schema.hpp"
#include "fiberfluid/geom/mesh_check.hpp"
#include "fiberfluid/geom/mesh_io.hpp"
#include "fiberfluid/parallel/ranks.hpp"
#include "fiberfluid/util/error.hpp"
#include "fiberfluid/util/omp_wait_policy.hpp"
#include "fiberfluid/util/progress.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace {

namespace experiment = fiberfluid::experiment;

enum ExitCode {
  kOk = 0,
  kBadInput = 1,
  kSolverFailed = 2,
  kChecksFailed = 3,
  kUsage = 64,
  kInterrupted = 130,  // 128 + SIGINT, as a shell reports a process ended by Ctrl-C
};

// The first Ctrl-C asks the run to stop at its next check (a load step, a
// pruning row, a solver iteration) and clean up; a second one ends the
// process at once (the handler is reset after the first).
void stop_on_interrupt() {
  struct sigaction action {};
  action.sa_handler = [](int) { fiberfluid::request_cancel(); };
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  // Past a file-size limit (ulimit -f) a write fails with EFBIG, reported
  // with the file's name, instead of the signal ending the process.
  signal(SIGXFSZ, SIG_IGN);
}

// Throws Interrupted after a phase that returned early because of Ctrl-C,
// before its partial results are written anywhere.
void stop_if_interrupted(const std::string& phase) { fiberfluid::throw_if_cancelled(phase); }

// Draws the library's progress reports on stderr, for phases that run longer
// than a moment: one line redrawn in place on a terminal; plain lines (every
// tenth, or every 10 s, and the end) when stderr is a file or a pipe. Each
// line has the elapsed time of the phase and, when its total is known, an
// estimate of what remains. A phase that reports rarely (a factorisation is
// one call) is redrawn by a heartbeat, so a long run always shows life.
class ProgressPrinter {
 public:
  ProgressPrinter() : tty_(isatty(STDERR_FILENO) != 0), heartbeat_([this] { beat(); }) {}
  ~ProgressPrinter() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_all();
    heartbeat_.join();
  }

  void operator()(const std::string& label, const char* phase, double done, double total) {
    const std::lock_guard<std::mutex> lock(mutex_);
    const Clock::time_point now = Clock::now();
    Phase& p = phases_[label + "|" + phase];
    if (p.start == Clock::time_point{} || done < p.done)  // a new phase
      p = Phase{label, phase, now, Clock::time_point{}};
    const bool repeat = done == p.done && p.printed;
    p.done = done;
    p.total = total;
    latest_ = &p;
    const double elapsed = seconds(now - p.start);
    const bool finished = total > 0.0 && done >= total;
    const int tenth = total > 0.0 ? static_cast<int>(10.0 * done / total) : -1;
    if (repeat || (elapsed < kQuietSeconds && !(finished && p.printed))) return;
    const double since_last = seconds(now - p.drawn);
    if (!finished && (tty_ ? since_last < 0.1 : tenth == p.tenth && since_last < 10.0)) return;
    p.tenth = tenth;
    print(p, now);
  }

  // Clears a redrawn line, so that what follows starts on its own.
  void close() {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (line_open_) std::fprintf(stderr, "\r\033[K");
    line_open_ = false;
    latest_ = nullptr;
  }

 private:
  using Clock = std::chrono::steady_clock;
  static constexpr double kQuietSeconds = 2.0;  // shorter phases print nothing
  struct Phase {
    std::string label;
    const char* name = "";
    Clock::time_point start, drawn;
    double done = 0.0, total = 0.0;
    int tenth = -1;
    bool printed = false;
  };
  static double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

  void print(Phase& p, Clock::time_point now) {
    p.drawn = now;
    p.printed = true;
    const double elapsed = seconds(now - p.start);
    std::string line = (p.label.empty() ? "" : "[" + p.label + "] ") + p.name;
    char buffer[160];
    if (p.total > 0.0) {
      std::snprintf(buffer, sizeof buffer, " %g/%g (%.0f%%), %.1f s", p.done, p.total,
                    100.0 * p.done / p.total, elapsed);
      line += buffer;
      if (p.done > 0.0 && p.done < p.total) {
        std::snprintf(buffer, sizeof buffer, ", about %.0f s left",
                      elapsed * (p.total - p.done) / p.done);
        line += buffer;
      }
    } else {  // a count with no known end, or only a start
      if (p.done > 0.0) line += " " + std::to_string(static_cast<long long>(p.done));
      std::snprintf(buffer, sizeof buffer, ", %.1f s", elapsed);
      line += buffer;
    }
    if (tty_)
      std::fprintf(stderr, "\r\033[K%s", line.c_str());
    else
      std::fprintf(stderr, "%s\n", line.c_str());
    std::fflush(stderr);
    line_open_ = tty_;
  }

  // Redraws the latest unfinished phase when nothing was printed for a while.
  void beat() {
    std::unique_lock<std::mutex> lock(mutex_);
    const auto interval = tty_ ? std::chrono::seconds(1) : std::chrono::seconds(10);
    while (!wake_.wait_for(lock, interval, [this] { return stopping_; })) {
      if (latest_ == nullptr || (latest_->total > 0.0 && latest_->done >= latest_->total)) continue;
      const Clock::time_point now = Clock::now();
      if (seconds(now - latest_->start) >= kQuietSeconds && now - latest_->drawn >= interval)
        print(*latest_, now);
    }
  }

  std::mutex mutex_;
  std::condition_variable wake_;
  bool tty_;
  bool stopping_ = false;
  bool line_open_ = false;
  std::map<std::string, Phase> phases_;  // std::map: latest_ stays valid as it grows
  Phase* latest_ = nullptr;
  std::thread heartbeat_;  // last: it starts once the rest is ready
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

// Loads an experiment (throwing before anything is written), drawing the
// progress of long phases such as pruning unless quiet; the sink stays set.
// Estimates of long runs are printed before they start (as notes).
experiment::Experiment load_showing_progress(const std::string& path, bool quiet,
                                             ProgressPrinter& printer) {
  if (!quiet) {
    fiberfluid::set_progress_sink([&printer](const std::string& label, const char* phase,
                                             double done,
                                             double total) { printer(label, phase, done, total); });
    fiberfluid::set_note_sink([&printer](const std::string& label, const std::string& text) {
      printer.close();
      std::cerr << "note: " << (label.empty() ? "" : "[" + label + "] ") << text << "\n";
    });
  }
  experiment::Experiment ex = experiment::load_experiment(path);
  printer.close();
  fiberfluid::set_note_sink({});
  for (const auto& w : ex.warnings) std::cerr << "warning: " << w << "\n";
  return ex;
}

// Single quotes for a shell, with any quote inside closed and escaped.
std::string shell_quoted(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// The plot script: installed beside the program (share/fiberfluid/plot.py),
// or the source tree's when run from the build.
std::filesystem::path plot_script() {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  if (!error) {
    const std::filesystem::path installed =
        self.parent_path().parent_path() / "share" / "fiberfluid" / "plot.py";
    if (std::filesystem::exists(installed)) return installed;
  }
  return FIBERFLUID_PLOT_SCRIPT;
}

// --plot: DIR/plot.png from DIR/summary.json, drawn by the plot script with
// the first python3 that has matplotlib (the one on PATH, else Debian's). A
// plot that cannot be drawn is a warning: the results are written already.
void draw_plot(const std::filesystem::path& folder, const std::string& input = "summary.json") {
  const std::filesystem::path script = plot_script();
  if (!std::filesystem::exists(script)) {
    std::cerr << "warning: no plot: the plot script " << script.string() << " is missing\n";
    return;
  }
  for (const char* python : {"python3", "/usr/bin/python3"}) {
    if (std::system((std::string(python) + " -c 'import matplotlib' >/dev/null 2>&1").c_str()) != 0)
      continue;
    const std::filesystem::path png = folder / "plot.png";
    const std::string command = std::string(python) + " " + shell_quoted(script.string()) + " " +
                                shell_quoted((folder / input).string()) + " " +
                                shell_quoted(png.string());
    if (std::system(command.c_str()) == 0 && std::filesystem::exists(png))
      std::cout << "  plot: " << png.string() << "\n";
    else
      std::cerr << "warning: no plot: " << command << " failed\n";
    return;
  }
  std::cerr << "warning: no plot: no python3 with matplotlib (Debian: apt-get install "
               "python3-matplotlib)\n";
}

// Thrown on a rank whose own part of a step succeeded when another rank's failed.
struct AnotherRankFailed : fiberfluid::InputError {
  AnotherRankFailed()
      : InputError(
            "another MPI rank could not read the experiment or prepare its run (run "
            "it without mpirun to see why)") {}
};

// True once every rank is failing the same way (on_every_rank, a
// disagreement): the ranks end on their own. A failure on one rank alone
// ends the whole job instead (main).
bool every_rank_fails = false;

// Runs `step` on every rank and ends in agreement: when it throws on one
// rank, it throws on all (the others an AnotherRankFailed), so no rank goes on
// to wait for work that will never be dealt.
void on_every_rank(const fiberfluid::parallel::Ranks& ranks, const std::function<void()>& step) {
  try {
    step();
  } catch (...) {
    ranks.all_ok(false);
    every_rank_fails = true;
    throw;
  }
  if (!ranks.all_ok(true)) {
    every_rank_fails = true;
    throw AnotherRankFailed();
  }
}

// Fault injection for the tests of a failure on one rank alone
// (tests/mpi/mpi_test.sh): FIBERFLUID_FAIL_RANK=r makes rank r throw once its
// run is set up, outside any work item, while the others wait for it.
void fail_if_injected(const fiberfluid::parallel::Ranks& ranks) {
  const char* rank = std::getenv("FIBERFLUID_FAIL_RANK");
  if (rank != nullptr && std::atoi(rank) == ranks.rank() && ranks.size() > 1)
    throw std::runtime_error("a failure injected by FIBERFLUID_FAIL_RANK");
}

// A digest of what a rank will run: the resolved experiment and every
// case's surface, bit for bit (FNV-1a, 64 bits).
std::string experiment_digest(const experiment::Experiment& ex) {
  std::uint64_t hash = 14695981039346656037ull;
  const auto add = [&hash](const void* data, size_t size) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (size_t k = 0; k < size; ++k) hash = (hash ^ bytes[k]) * 1099511628211ull;
  };
  const auto add_experiment = [&](const experiment::Experiment& e) {
    const std::string resolved = e.resolved.dump();
    add(resolved.data(), resolved.size());
    for (const experiment::Case& c : e.cases) {
      add(c.model.surface.V.data(), sizeof(double) * static_cast<size_t>(c.model.surface.V.size()));
      add(c.model.surface.F.data(), sizeof(int) * static_cast<size_t>(c.model.surface.F.size()));
    }
  };
  add_experiment(ex);
  for (const experiment::Experiment& specimen : ex.specimens) add_experiment(specimen);
  return std::to_string(hash);
}

// Every rank must run what rank 0 runs: started with other files (mpirun's
// "A : B" form), a rank computed B's variants under A's record, or waited
// for ever when B had fewer (issue 43). Refused on every rank, naming them.
void require_one_experiment(const fiberfluid::parallel::Ranks& ranks,
                            const experiment::Experiment& ex, const std::string& path) {
  const std::vector<int> differing = ranks.differing_from_root(experiment_digest(ex));
  if (differing.empty()) return;
  std::string which;
  for (int r : differing) which += (which.empty() ? "" : ", ") + std::to_string(r);
  every_rank_fails = true;
  throw fiberfluid::InputError(
      "MPI rank(s) " + which + " read another experiment or surface than rank 0 (" + path +
      "): every rank must run the same experiment file, with the same mesh");
}

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
  if (ex.fit)
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
  if (ex.kind == experiment::Experiment::Kind::Simulate) {
    const experiment::FiberReport& f = ex.cases.front().fibers;
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
  if (flags.plot && ex.kind == experiment::Experiment::Kind::Simulate) draw_plot(writer.folder());
  if (flags.check_expected && !result.checks_passed()) {
    std::cerr << "error: some expected figures were not met (see above)\n";
    return kChecksFailed;
  }
  return kOk;
}

// Prints one line per iteration of a fit: its cost and point, and for a
// rejected step why (its cost, or its forward run's failure).
void print_iteration(const fiberfluid::fit::IterationRecord& r,
                     const std::vector<std::string>& names) {
  std::cerr << "fit: iteration " << r.iteration << ": cost " << r.cost << " m^2";
  if (!r.accepted && !r.trial_failure.empty())
    std::cerr << " (step rejected: its forward run failed: " << r.trial_failure << ")";
  else if (!r.accepted)
    std::cerr << " (step rejected: it cost " << r.trial_cost << ")";
  else if (!r.trial_failure.empty())
    std::cerr << " (after a trial point whose forward run failed: " << r.trial_failure << ")";
  std::cerr << ";";
  for (size_t k = 0; k < names.size(); ++k)
    std::cerr << (k ? ", " : " ") << names[k] << " = " << r.values[static_cast<Eigen::Index>(k)];
  std::cerr << "; " << r.forward_runs << " runs, " << r.seconds << " s\n";
}

// One line per finished start of a multi-start search.
void print_start(size_t s, const fiberfluid::fit::StartOutcome& o,
                 const std::vector<std::string>& names) {
  std::cerr << "fit: start " << s << " (rank " << o.rank
            << "): " << fiberfluid::fit::to_string(o.fit.status) << ", cost " << o.fit.final_cost
            << " m^2;";
  for (size_t k = 0; k < names.size(); ++k)
    std::cerr << (k ? ", " : " ") << names[k] << " " << o.start[static_cast<Eigen::Index>(k)]
              << " -> " << o.fit.values[static_cast<Eigen::Index>(k)];
  std::cerr << "; " << o.fit.iterations.size() << " iterations, " << o.fit.seconds << " s\n";
}

// The distinct optima of a multi-start search, and a warning when the best
// was reached from one start only.
void print_optima(const fiberfluid::fit::MultistartResult& search,
                  const std::vector<std::string>& names) {
  std::cout << "  " << search.optima.size() << " distinct optima from " << search.starts.size()
            << " starts (" << search.seconds << " s):\n";
  for (size_t o = 0; o < search.optima.size(); ++o) {
    const fiberfluid::fit::Optimum& optimum = search.optima[o];
    std::cout << "    " << (o == 0 ? "best" : "    ") << " cost " << optimum.cost << " m^2, "
              << optimum.starts.size() << " start(s):";
    for (size_t k = 0; k < names.size(); ++k)
      std::cout << (k ? ", " : " ") << names[k] << " = "
                << optimum.values[static_cast<Eigen::Index>(k)];
    std::cout << "\n";
  }
  if (search.best_found_once)
    std::cerr << "warning: the best optimum was reached from one start only: a cheaper one may "
                 "lie where no start came near (more \"starts\" or narrower bounds tell)\n";
}

void print_fit(const fiberfluid::fit::FitResult& fitted) {
  namespace fit = fiberfluid::fit;
  if (!fitted.start_note.empty()) std::cout << "  start: " << fitted.start_note << "\n";
  for (size_t k = 0; k < fitted.names.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    std::cout << "  " << fitted.names[k] << " = " << fitted.values[i];
    if (std::find(fitted.at_bounds.begin(), fitted.at_bounds.end(), fitted.names[k]) !=
        fitted.at_bounds.end())
      std::cout << " (on its bound: no standard error";
    else if (std::isfinite(fitted.standard_errors[i]))
      std::cout << " +- " << fitted.standard_errors[i] << " (95%: " << fitted.lower_95[i] << " .. "
                << fitted.upper_95[i];
    else
      std::cout << " (no standard error";
    std::cout << "; start " << fitted.initial[i] << ")\n";
    if (k < fitted.interval_notes.size() && !fitted.interval_notes[k].empty())
      std::cout << "    interval: " << fitted.interval_notes[k] << "\n";
  }
  if (!fitted.statistics.empty()) {
    const auto& d = fitted.overall;
    std::cout << "  distance (" << d.count << " model vertices to their targets): mean " << d.mean
              << ", rms " << d.rms << ", sd " << d.standard_deviation << " ("
              << 100.0 * d.share(d.standard_deviation) << "% of the body's length " << d.length
              << "), largest " << d.largest << " m\n";
  }
  for (const fit::ForceMisfit& m : fitted.force_misfits)
    std::cout << "  force misfit (" << m.simulated.size() << " rows): rms " << m.rms << " N ("
              << 100.0 * m.share(m.rms) << "% of the largest measured force " << m.scale
              << " N), largest " << m.largest << " N\n";
  std::cout << "  " << fitted.forward_runs << " forward runs";
  if (fitted.failed_runs > 0) std::cout << " (" << fitted.failed_runs << " failed)";
  if (fitted.warm_started_runs > 0)
    std::cout << " (" << fitted.warm_started_runs << " solved from a nearby point's state)";
  std::cout << ", " << fitted.sensitivity_solves << " sensitivity solves, " << fitted.seconds
            << " s\n";
  if (!fitted.warm_start_note.empty())
    std::cerr << "warning: " << fitted.warm_start_note << "\n";
  for (const auto& [cause, count] : fitted.failures_by_cause)
    std::cout << "  failed forward runs: " << count << " x " << cause << "\n";
  if (!fitted.failed_examples.empty()) {
    const fit::FailedRun& f = fitted.failed_examples.front();
    std::cout << "  first failure at";
    for (size_t k = 0; k < fitted.names.size(); ++k)
      std::cout << (k ? ", " : " ") << fitted.names[k] << " = "
                << f.values[static_cast<Eigen::Index>(k)];
    std::cout << ": " << f.message << "\n";
  }
}

// A calibration over several specimens ("kind": "calibration"): rank 0 runs
// Levenberg-Marquardt, every rank evaluates the specimens dealt to it at each
// point. The folder holds calibration.json and each specimen's fit files.
int calibrate_specimens(const experiment::Experiment& ex, const experiment::JointSetup& setup,
                        const std::filesystem::path& folder, const RunFlags& flags,
                        const fiberfluid::parallel::Ranks& ranks) {
  namespace fit = fiberfluid::fit;
  const fit::JointCalibration& joint = *setup.joint;
  const fit::Broadcast broadcast = [&ranks](std::string& bytes) { ranks.broadcast(bytes); };
  if (!ranks.root()) {
    joint.serve(ranks.dealer(), broadcast);
    stop_if_interrupted("the calibration");
    return kOk;
  }
  std::cout << "calibrating " << joint.names().size() << " parameters ("
            << ex.calibration->shared.size() << " shared) to " << joint.num_residuals()
            << " residuals of " << joint.specimen_names().size() << " specimens over "
            << ranks.size() << " rank(s)\n";
  for (size_t s = 0; s < setup.specimens.size(); ++s)
    std::cout << "  specimen " << joint.specimen_names()[s] << ": "
              << ex.specimens[s].source.string() << ", " << setup.specimens[s].targets.size()
              << " target(s), " << setup.specimens[s].calibration->num_residuals()
              << " residuals\n";
  const fit::JointFitResult fitted = joint.run(ranks.dealer(), broadcast);
  experiment::OutputWriter writer(ex, folder);
  writer.begin();
  experiment::ExperimentResult result;
  result.figures = experiment::joint_figures(ex, fitted);
  result.checks = experiment::check_expected(ex, result);
  const auto files = [&](const std::filesystem::path& dir) {
    experiment::write_joint_files(dir, ex, setup, fitted, result);
  };
  if (fitted.status == fit::FitStatus::Interrupted) {
    writer.keep_interrupted("the calibration was interrupted after " +
                                std::to_string(fitted.iterations.size()) + " iterations",
                            files);
    std::cerr << "\nerror: the calibration was interrupted (SIGINT or SIGTERM); its best point "
                 "so far is in "
              << (writer.folder() / "calibration.json").string() << "\n";
    return experiment::fit_exit_status(fitted.status);
  }
  if (!experiment::fit_result_kept(fitted.status))
    result.failure = std::string("the calibration ended ") + fit::to_string(fitted.status) + ": " +
                     fitted.message +
                     (fitted.status_detail.empty() ? "" : "; " + fitted.status_detail);
  writer.finish(result, files);
  for (const std::string& w : writer.warnings()) std::cerr << "warning: " << w << "\n";
  std::cout << ex.name << ": " << fit::to_string(fitted.status) << ": " << fitted.message
            << "; results in " << writer.folder().string() << "\n";
  if (!fitted.status_detail.empty()) std::cout << "  " << fitted.status_detail << "\n";
  for (size_t k = 0; k < fitted.names.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    std::cout << "  " << fitted.names[k] << (static_cast<int>(k) < fitted.shared ? " (shared)" : "")
              << " = " << fitted.values[i];
    if (std::isfinite(fitted.standard_errors[i]))
      std::cout << " +- " << fitted.standard_errors[i] << " (95%: " << fitted.lower_95[i] << " .. "
                << fitted.upper_95[i] << ")";
    std::cout << "; start " << fitted.initial[i] << "\n";
  }
  for (size_t s = 0; s < fitted.specimens.size(); ++s) {
    const fit::DistanceStatistics& d = fitted.specimens[s].overall;
    std::cout << "  specimen " << joint.specimen_names()[s] << ": distance sd "
              << d.standard_deviation << " m (" << 100.0 * d.share(d.standard_deviation)
              << "% of its length " << d.length << " m), rms " << d.rms << ", largest " << d.largest
              << " m\n";
  }
  std::cout << "  " << fitted.evaluations << " evaluations, " << fitted.seconds << " s\n";
  for (const experiment::FigureCheck& c : result.checks) std::cout << "  " << c.Describe() << "\n";
  if (!experiment::fit_result_kept(fitted.status)) std::cerr << "error: " << result.failure << "\n";
  if (const int status = experiment::fit_exit_status(fitted.status); status != kOk) return status;
  if (flags.check_expected && !result.checks_passed()) {
    std::cerr << "error: some expected figures were not met (see above)\n";
    return kChecksFailed;
  }
  return kOk;
}

// Calibrates the material of an experiment to its "fit" targets, then runs
// it at the fitted values and writes the usual outputs with the fit's files.
// Every fit file is in the folder before it moves into place: DIR for a fit
// that converged, DIR.failed for one that did not, DIR.interrupted (the best
// point so far, for fit.start_from) for one stopped by SIGINT or SIGTERM.
// Each parameter on the other mesh beside its statistical interval; a
// warning where the mesh moves it further than the data pin it.
void print_mesh_check(const fiberfluid::fit::FitResult& fitted,
                      const experiment::MeshCheck& check) {
  std::cout << "  mesh check (" << check.resolution << ", "
            << fiberfluid::fit::to_string(check.fitted.status) << "):\n";
  for (size_t k = 0; k < fitted.names.size() && k < check.fitted.names.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    const double shift = check.fitted.values[i] - fitted.values[i];
    const double half_width =
        fitted.upper_95.size() > i ? 0.5 * (fitted.upper_95[i] - fitted.lower_95[i]) : 0.0;
    std::printf("    %s = %.6g there: mesh shift %+.4g (%.2g%%), the 95%% interval's half-width %.4g\n",
                fitted.names[k].c_str(), check.fitted.values[i], shift,
                100.0 * shift / fitted.values[i], half_width);
    if (std::isfinite(half_width) && std::abs(shift) > half_width)
      std::cerr << "warning: the mesh moves " << fitted.names[k]
                << " further than its statistical interval: the fitted value is this mesh's "
                   "model's more than the material's (refine the mesh, or report the shift)\n";
  }
}

int fit_command(const std::string& path, const RunFlags& flags,
                const fiberfluid::parallel::Ranks& ranks) {
  namespace fit = fiberfluid::fit;
  fiberfluid::set_memory_budget(flags.max_memory);
  fiberfluid::set_time_budget(flags.max_time);
  ProgressPrinter printer;
  // Every rank reads the experiment and its targets; rank 0 alone checks the
  // output folder (refused now, not after the fit).
  std::optional<experiment::Experiment> loaded;
  std::filesystem::path folder;
  experiment::FitSetup setup;
  experiment::JointSetup joint;
  std::vector<std::string> names;
  bool multistart = false;
  on_every_rank(ranks, [&] {
    loaded.emplace(load_showing_progress(path, flags.quiet || !ranks.root(), printer));
  });
  require_one_experiment(ranks, *loaded, path);
  on_every_rank(ranks, [&] {
    fiberfluid::set_progress_sink({});  // the fit's many runs: one line per iteration instead
    if (ranks.root()) folder = experiment::output_folder(flags.output, loaded->name);
    if (loaded->kind == experiment::Experiment::Kind::Calibration) {
      joint = experiment::setup_joint(*loaded, [&](const fit::IterationRecord& r) {
        if (!flags.quiet) print_iteration(r, joint.joint->names());
      });
      return;
    }
    if (loaded->fit)
      for (const auto& p : loaded->fit->parameters) names.push_back(p.request.name);
    multistart = loaded->fit && loaded->fit->multistart;
    // A multi-start search prints a line per start instead of per iteration.
    setup = experiment::setup_fit(*loaded, [&](const fit::IterationRecord& r) {
      if (!flags.quiet && !multistart) print_iteration(r, names);
    });
  });
  const experiment::Experiment& ex = *loaded;
  if (ex.kind == experiment::Experiment::Kind::Calibration)
    return calibrate_specimens(ex, joint, folder, flags, ranks);
  const fiberfluid::WorkDealer dealer = ranks.dealer();
  if (!ranks.root()) {  // the ranks' share of the starts; a single fit is rank 0's alone
    if (multistart) fit::serve_multistart(*setup.calibration, *ex.fit->multistart, dealer);
    stop_if_interrupted("the fit");
    return kOk;
  }
  if (ranks.size() > 1 && !multistart)
    std::cerr << "note: a single fit runs on rank 0 alone; \"method\": \"multistart\" deals "
                 "its starts out over the ranks\n";
  for (const auto& t : setup.targets)
    std::cout << "target " << t.target.label << " (step " << t.step << "): " << t.target.description
              << "\n";
  const fit::Calibration& calibration = *setup.calibration;
  int force_rows = 0;
  for (size_t k = 0; k < setup.force_curves.size(); ++k) {
    const fit::ForceCurve& f = setup.force_curves[k];
    force_rows += static_cast<int>(f.force.size());
    std::cout << "force curve " << f.label << ": " << f.force.size() << " rows at "
              << (f.by_step ? "load steps" : "travels") << ", weight "
              << calibration.force_weight(k) << " m per N\n";
  }
  const int counted = calibration.num_counted_vertices();
  const int forward = counted * static_cast<int>(setup.targets.size());
  const int distances = calibration.num_residuals() - force_rows;
  std::cout << "fitting " << calibration.parameters().size() << " parameters to ";
  if (!setup.targets.empty()) {
    std::cout << distances << " distances (" << counted << " model vertices to each of "
              << setup.targets.size() << " target(s)";
    if (distances > forward)
      std::cout << ", and " << distances - forward << " target points to the simulated surface";
    std::cout << ")" << (force_rows > 0 ? " and " : "");
  }
  if (force_rows > 0) std::cout << force_rows << " force misfits";
  std::cout << " (" << fit::to_string(ex.fit->options.method) << ", "
            << (setup.calibration->analytic_jacobian() ? "analytic Jacobian"
                                                       : "finite differences");
  if (multistart)
    std::cout << ", from each of " << ex.fit->multistart->starts << " starts over " << ranks.size()
              << " rank(s)";
  std::cout << ")\n";
  std::optional<fit::MultistartResult> search;
  fit::FitResult fitted;
  if (multistart) {
    search = fit::run_multistart(calibration, *ex.fit->multistart, dealer,
                                 [&](size_t s, const fit::StartOutcome& o) {
                                   if (!flags.quiet) print_start(s, o, names);
                                 });
    fitted = search->best();
    // Stopped early: the best start so far, kept as an interrupted fit's.
    if (fiberfluid::cancel_requested()) fitted.status = fit::FitStatus::Interrupted;
  } else {
    fitted = calibration.run();
  }
  const fit::MultistartResult* searched = search ? &*search : nullptr;

  const experiment::Experiment at_fit =
      experiment::with_fitted_material(ex, *setup.calibration, fitted);
  experiment::OutputWriter writer(at_fit, folder);
  writer.begin();
  if (fitted.status == fit::FitStatus::Interrupted) {
    const experiment::ExperimentResult none;
    writer.keep_interrupted(
        "the fit was interrupted after " + std::to_string(fitted.iterations.size()) +
            " iterations; fit.json holds the best point so far (continue "
            "with \"start_from\" in the fit section)",
        [&](const std::filesystem::path& dir) {
          experiment::write_fit_files(dir, at_fit, setup, fitted, none, searched);
        });
    std::cerr
        << "\nerror: the fit was interrupted (SIGINT or SIGTERM); its best point so far is in "
        << (writer.folder() / "fit.json").string() << " (continue with \"start_from\": \""
        << (writer.folder() / "fit.json").string() << "\" in the fit section)\n";
    return experiment::fit_exit_status(fitted.status);
  }
  experiment::ExperimentResult result;
  std::optional<experiment::MeshCheck> mesh_check;
  if (fitted.status != fit::FitStatus::StartFailed) {
    result = experiment::run_experiment(
        at_fit, [&](size_t run, const fiberfluid::solve::StepRecord& r, const Eigen::VectorXd& x) {
          writer.on_step(run, r, x);
        });
    stop_if_interrupted("the run at the fitted values");
    for (const auto& [name, value] : experiment::fit_figures(fitted)) result.figures[name] = value;
    if (ex.fit->mesh_check != "none" && experiment::fit_result_kept(fitted.status)) {
      if (!flags.quiet) std::cerr << "mesh check: the fit again on a " << ex.fit->mesh_check << " mesh\n";
      mesh_check = experiment::run_mesh_check(at_fit);
      stop_if_interrupted("the mesh check");
      for (const auto& [name, value] : experiment::mesh_check_figures(fitted, *mesh_check))
        result.figures[name] = value;
    }
    if (search)
      for (const auto& [name, value] : experiment::multistart_figures(*search))
        result.figures[name] = value;
    result.checks = experiment::check_expected(at_fit, result);
  }
  if (!experiment::fit_result_kept(fitted.status))
    result.failure = std::string("the fit ended ") + fit::to_string(fitted.status) + ": " +
                     fitted.message +
                     (fitted.status_detail.empty() ? "" : "; " + fitted.status_detail);
  writer.finish(result, [&](const std::filesystem::path& dir) {
    experiment::write_fit_files(dir, at_fit, setup, fitted, result, searched);
  });
  for (const std::string& w : writer.warnings()) std::cerr << "warning: " << w << "\n";

  std::cout << ex.name << ": " << fit::to_string(fitted.status) << ": " << fitted.message
            << "; results in " << writer.folder().string() << "\n";
  if (!fitted.status_detail.empty()) std::cout << "  " << fitted.status_detail << "\n";
  if (search) print_optima(*search, names);
  print_fit(fitted);
  if (mesh_check) print_mesh_check(fitted, *mesh_check);
  for (const experiment::FigureCheck& c : result.checks) std::cout << "  " << c.Describe() << "\n";
  if (!result.runs_succeeded()) {
    for (const experiment::RunResult& run : result.runs)
      if (!run.summary.success) std::cerr << "error: " << run.summary.message << "\n";
    return kSolverFailed;
  }
  if (fitted.status == fit::FitStatus::ConvergedAtBounds)
    std::cerr << "warning: the fit converged on bounds: " << fitted.status_detail
              << ". A bound is no estimate: widen it, fix the parameter, or check the model\n";
  else if (!experiment::fit_result_kept(fitted.status))
    std::cerr << "error: " << result.failure << "\n";
  if (const int status = experiment::fit_exit_status(fitted.status); status != kOk) return status;
  if (flags.check_expected && !result.checks_passed()) {
    std::cerr << "error: some expected figures were not met (see above)\n";
    return kChecksFailed;
  }
  return kOk;
}

struct StudyFlags {
  std::string experiment, output;
  bool fem = false;
  int levels = 3;
  double ratio = 1.5;
  std::vector<std::string> figures;
  bool plot = false;
};

// fiberfluid study mesh: the levels' values, observed orders and
// extrapolations as a table, and study.csv / study.json in the output folder.
int study_command(const StudyFlags& flags) {
  experiment::MeshStudySpec spec;
  spec.mesh = flags.fem ? experiment::StudiedMesh::FemReference : experiment::StudiedMesh::Surface;
  spec.levels = flags.levels;
  spec.ratio = flags.ratio;
  spec.figures = flags.figures;
  // A result folder like run's and fit's: checked before the study runs,
  // staged, and put in place whole.
  const std::string name =
      experiment::folder_name_from(std::filesystem::path(flags.experiment).stem().string()) +
      "_mesh_study";
  const std::filesystem::path output = experiment::output_folder(flags.output, name);
  const experiment::MeshStudy study = experiment::run_mesh_study(
      flags.experiment, spec, [](const std::string& line) { std::cerr << line << "\n"; });
  std::printf("%-40s", "figure");
  for (size_t k = 0; k < study.resolutions.size(); ++k) std::printf(" %14s", ("level " + std::to_string(k + 1)).c_str());
  std::printf(" %8s %14s %11s\n", "order", "extrapolated", "error est.");
  for (const experiment::StudiedFigure& f : study.figures) {
    std::printf("%-40s", f.name.c_str());
    for (double v : f.values) std::printf(" %14.7g", v);
    if (f.estimate.monotone && std::isfinite(f.estimate.order))
      std::printf(" %8.2f %14.7g %11.3g\n", f.estimate.order, f.estimate.extrapolated,
                  f.estimate.error);
    else
      std::printf(" %8s %14s %11.3g\n", "-", "(not monotone)", f.estimate.error);
  }
  for (size_t k = 0; k < study.resolutions.size(); ++k)
    std::printf("level %zu: %s, relative size %.4g, %.1f s\n", k + 1, study.resolutions[k].c_str(),
                study.sizes[k], study.seconds[k]);
  const std::filesystem::path staging = experiment::create_staging_folder(output, name);
  fiberfluid::geom::write_text_file(staging / "study.csv", experiment::mesh_study_csv(study));
  fiberfluid::geom::write_text_file(staging / "study.json",
                                    experiment::mesh_study_json(study).dump(2) + "\n");
  std::vector<std::string> warnings;
  experiment::move_into_place(staging, output, &warnings);
  for (const std::string& w : warnings) std::cerr << "warning: " << w << "\n";
  std::printf("wrote %s and %s\n", (output / "study.csv").c_str(), (output / "study.json").c_str());
  if (flags.plot) draw_plot(output, "study.json");
  return kOk;
}

int compare_command(const std::string& reference, const std::string& approximation,
                    const std::string& undeformed, bool as_json) {
  const experiment::Comparison c = experiment::compare_files(
      reference, approximation,
      undeformed.empty() ? std::nullopt : std::optional<std::filesystem::path>(undeformed));
  for (const std::string& w : c.warnings) std::cerr << "warning: " << w << "\n";
  if (as_json)
    std::cout << experiment::comparison_json(c).dump(2) << "\n";
  else
    std::cout << experiment::comparison_text(c);
  return kOk;
}

int check_command(const std::string& path, bool flip) {
  fiberfluid::geom::ReadResult read = fiberfluid::geom::read_surface(path);
  if (flip) fiberfluid::geom::flip_orientation(read.surface);
  // Vertices and faces counted as the file counts them (OBJ from 1).
  const fiberfluid::geom::MeshReport report =
      fiberfluid::geom::inspect(read.surface, read.index_base);
  for (const auto& w : read.warnings) std::cerr << "warning: " << w << "\n";
  std::cout << fiberfluid::geom::format_report(report, path);
  if (!report.ok()) {
    std::cerr << "error: " << path << ": " << report.problems.front() << "\n";
    return kBadInput;
  }
  return kOk;
}

// --max-memory SIZE: the memory budget that every case's estimate and every
// dense factor is checked against before it is allocated; --max-time: the
// longest estimate that may start.
void add_resource_limits(CLI::App* command, RunFlags& flags) {
  command
      ->add_option("--max-time", flags.max_time,
                   "Refuse a case whose estimated time exceeds this many seconds")
      ->check(CLI::PositiveNumber);
  command
      ->add_option_function<std::string>(
          "--max-memory",
          [&flags](const std::string& text) { fiberfluid::parse_bytes(text, &flags.max_memory); },
          "Memory a run may plan for, e.g. 8G or 512M (default: 80% of this machine's); a case "
          "estimated beyond it is refused before it starts")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            double bytes = 0.0;
            return fiberfluid::parse_bytes(text, &bytes)
                       ? ""
                       : "expected a size such as 8G, 512M or 2e9 (bytes), got '" + text + "'";
          },
          "SIZE"));
}

}  // namespace

// `--version`: the version, then what the build is made of.
std::string version_text() {
  std::ostringstream out;
  out << "fiberfluid " << fiberfluid::experiment::program_version() << "\n";
  for (const auto& [name, value] : fiberfluid::experiment::build_info())
    if (name != "version") out << "  " << name << ": " << value << "\n";
  out << "  mpi: " << fiberfluid::parallel::mpi_description() << "\n";
  std::string text = out.str();
  text.pop_back();  // CLI11 ends the line
  return text;
}

// A first word that is no subcommand ("runn"): named, with the valid ones
// (CLI11 alone would say only that a subcommand is required).
bool unknown_subcommand(const CLI::App& cli, int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') return false;
  const std::string word = argv[1];
  std::string known;
  for (const CLI::App* sub : cli.get_subcommands([](const CLI::App*) { return true; })) {
    if (sub->get_name() == word) return false;
    known += (known.empty() ? "" : ", ") + sub->get_name();
  }
  std::cerr << "error: unknown command '" << word << "' (expected one of: " << known
            << "; fiberfluid --help lists them)\n";
  return true;
}

// An argument the command does not take ("--plott"): named, with the
// command's options (CLI11 alone says only that it was not expected).
void report_unexpected_arguments(const CLI::App& cli, const CLI::ExtrasError& e, int argc,
                                 char** argv) {
  const CLI::App* command = nullptr;
  for (const CLI::App* sub : cli.get_subcommands([](const CLI::App*) { return true; }))
    if (argc > 1 && sub->get_name() == argv[1]) command = sub;
  if (command == nullptr) {
    std::cerr << "error: " << e.what() << "\n";
    return;
  }
  std::string options;
  for (const CLI::Option* option : command->get_options())
    if (option->nonpositional())
      options += (options.empty() ? "" : ", ") + option->get_name(false, true);
  std::cerr << "error: " << e.what() << " ('" << command->get_name()
            << "' takes the options: " << options << "; fiberfluid " << command->get_name()
            << " --help describes them)\n";
}

// Discards what this process writes to std::cout and std::cerr while it
// lives: the output of ranks other than rank 0, which would repeat rank 0's.
// (FIBERFLUID_ALL_RANKS_SPEAK=1 keeps it, to see a rank's own failure.)
class SilencedOutput {
 public:
  explicit SilencedOutput(bool silent) {
    if (!silent || std::getenv("FIBERFLUID_ALL_RANKS_SPEAK") != nullptr) return;
    cout_ = std::cout.rdbuf(&discard_);
    cerr_ = std::cerr.rdbuf(&discard_);
  }
  // The streams get their own buffers back before this one goes: they are
  // flushed once more at exit.
  ~SilencedOutput() {
    if (cout_ != nullptr) std::cout.rdbuf(cout_);
    if (cerr_ != nullptr) std::cerr.rdbuf(cerr_);
  }
  SilencedOutput(const SilencedOutput&) = delete;
  SilencedOutput& operator=(const SilencedOutput&) = delete;

 private:
  struct Discard : std::streambuf {
    int overflow(int c) override { return c; }
  } discard_;
  std::streambuf* cout_ = nullptr;
  std::streambuf* cerr_ = nullptr;
};

int main(int argc, char** argv) {
  // Threads that sleep rather than spin while they wait, unless the user chose.
  fiberfluid::util::wait_passively_unless_chosen(argv);
  // Under mpirun or srun (and built with MPI): this process is one of the
  // ranks; else the only one.
  const fiberfluid::parallel::Ranks ranks(&argc, &argv);
  if (!ranks.problem().empty()) {
    std::cerr << "error: " << ranks.problem() << "\n";
    return kUsage;
  }
  const SilencedOutput silenced(!ranks.root());
  CLI::App cli{"fiberfluid: the fibers-and-fluid soft-tissue model (Sardinha et al. 2016)"};
  cli.require_subcommand(1);
  cli.set_version_flag("--version", version_text());

  std::string experiment, mesh;
  RunFlags flags;
  bool flip = false;
  CLI::App* run = cli.add_subcommand("run", "Run an experiment file");
  run->add_option("experiment", experiment, "Experiment file (JSON)")->required();
  run->add_option("-o,--output", flags.output, "Output folder (default: out/<experiment name>)");
  run->add_flag("--check", flags.check_expected,
                "Exit with status 3 when an expected figure of the file is not met");
  run->add_flag("-q,--quiet", flags.quiet, "No progress lines");
  run->add_flag("--plot", flags.plot,
                "Also draw DIR/plot.png (python3 with matplotlib; the deformed surface, and "
                "per load step the displacement, pressure and reactions)");
  add_resource_limits(run, flags);
  run->add_option("-j,--jobs", flags.jobs,
                  "Variants of a sweep run at once (default: one per core); each gets "
                  "cores / jobs threads")
      ->check(CLI::Range(0, 256));

  RunFlags fit_flags;
  CLI::App* fit = cli.add_subcommand(
      "fit",
      "Calibrate the material of an experiment to its \"fit\" targets, then run it at the "
      "fitted values");
  fit->add_option("experiment", experiment, "Experiment file (JSON) with a \"fit\" section")
      ->required();
  fit->add_option("-o,--output", fit_flags.output,
                  "Output folder (default: out/<experiment name>)");
  fit->add_flag("--check", fit_flags.check_expected,
                "Exit with status 3 when an expected figure of the file is not met");
  fit->add_flag("-q,--quiet", fit_flags.quiet, "No progress lines");
  add_resource_limits(fit, fit_flags);

  CLI::App* check = cli.add_subcommand("check", "Check a mesh file and print its report");
  check->add_option("mesh", mesh, "Mesh file (.obj, .off, .stl, .ply)")->required();
  check->add_flag("--flip", flip, "Reverse the face orientation before checking");

  std::string compared_reference, compared, undeformed;
  bool as_json = false;
  CLI::App* compare = cli.add_subcommand(
      "compare",
      "The benchmarks paper's metrics (E_s; E_n and E_i with --reference) and the "
      "surface distances between a reference deformed surface M and another M'");
  compare->add_option("M", compared_reference, "The reference deformed surface")->required();
  compare->add_option("M_prime", compared, "The deformed surface to compare with it")->required();
  compare->add_option("--reference", undeformed,
                      "The undeformed surface M0 (same vertices as both): adds E_n and E_i");
  compare->add_flag("--json", as_json, "Print JSON instead of text");

  StudyFlags study_flags;
  CLI::App* study = cli.add_subcommand(
      "study", "Studies of an experiment: `study mesh` runs it at several resolutions");
  CLI::App* mesh_study = study->add_subcommand(
      "mesh",
      "Run an experiment at several resolutions (its surface's, or with --fem its FEM "
      "reference's element size) and print each figure's values, observed order and "
      "Richardson-extrapolated value with an error estimate");
  study->require_subcommand(1);
  mesh_study->add_option("experiment", study_flags.experiment, "Experiment file (JSON)")
      ->required();
  mesh_study->add_option("-o,--output", study_flags.output,
                         "Output folder for study.csv and study.json (default: "
                         "out/<experiment>_mesh_study)");
  mesh_study->add_flag("--fem", study_flags.fem,
                       "Refine the FEM reference's element size (fem_reference.size) instead "
                       "of the surface");
  mesh_study->add_option("--levels", study_flags.levels, "Resolutions, coarse to fine (at least 3)")
      ->check(CLI::Range(3, 8));
  mesh_study->add_option("--ratio", study_flags.ratio,
                         "Refinement between levels (element size, coarse over fine)")
      ->check(CLI::Range(1.1, 4.0));
  mesh_study->add_option("--figure", study_flags.figures,
                         "A figure to study (repeatable; default: every figure)");
  mesh_study->add_flag("--plot", study_flags.plot,
                       "Also draw DIR/plot.png: each figure against the element size, with its "
                       "extrapolation (python3 with matplotlib)");

  CLI::App* schema = cli.add_subcommand(
      "schema",
      "Print the JSON Schema of experiment files (for an editor: \"$schema\" or its settings)");

  if (unknown_subcommand(cli, argc, argv)) return kUsage;
  try {
    cli.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return cli.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return cli.exit(e);
  } catch (const CLI::ExtrasError& e) {
    report_unexpected_arguments(cli, e, argc, argv);
    return kUsage;
  } catch (const CLI::ParseError& e) {
    // One status for every usage mistake (sysexits' EX_USAGE), distinct from bad input files.
    cli.exit(e);
    return kUsage;
  }
  stop_on_interrupt();
  // A failure: said, and the status. Under mpirun, a failure on one rank that
  // the others cannot learn of (they wait for its work, or it for theirs)
  // ends the whole job, naming the rank, rather than leaving it to hang.
  const auto failure = [&ranks](int status, const std::string& message) {
    std::cerr << message << "\n";
    if (ranks.size() > 1 && !every_rank_fails) {
      std::fprintf(stderr, "error: MPI rank %d of %d failed alone (%s): ending the job\n",
                   ranks.rank(), ranks.size(), message.c_str());
      std::fflush(stderr);
      ranks.end_job(status);
    }
    return status;
  };
  try {
    if (run->parsed()) return run_command(experiment, flags, ranks);
    if (fit->parsed()) return fit_command(experiment, fit_flags, ranks);
    if (!ranks.root()) return kOk;  // the other commands run on rank 0 alone
    if (schema->parsed()) {
      std::cout << fiberfluid::experiment::experiment_schema().dump(2) << "\n";
      return 0;
    }
    if (compare->parsed())
      return compare_command(compared_reference, compared, undeformed, as_json);
    if (study->parsed()) return study_command(study_flags);
    return check_command(mesh, flip);
  } catch (const fiberfluid::Interrupted& e) {
    std::cerr << "\nerror: " << e.what() << " (Ctrl-C): nothing was written; an earlier "
              << "result in the output folder is kept as it was\n";
    return kInterrupted;
  } catch (const fiberfluid::InputError& e) {
    return failure(kBadInput, std::string("error: ") + e.what());
  } catch (const std::filesystem::filesystem_error& e) {
    return failure(kBadInput, std::string("error: ") + e.what());
  } catch (const std::bad_alloc&) {
    return failure(kSolverFailed, "error: out of memory; use a coarser mesh");
  } catch (const nlohmann::json::exception& e) {
    return failure(kBadInput, std::string("error: bad JSON: ") + e.what());
  } catch (const std::exception& e) {  // the standard library's, CGAL's: a failure, never a crash
    return failure(kSolverFailed, std::string("error: ") + e.what());
  } catch (...) {
    return failure(kSolverFailed, "error: an unknown failure");
  }
}
