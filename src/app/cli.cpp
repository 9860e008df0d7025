// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/app/cli.hpp"

#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>
#include <system_error>

#include "fiberfluid/experiment/write/file_names.hpp"
#include "fiberfluid/util/progress.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::app {

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

void stop_if_interrupted(const std::string& phase) { fiberfluid::throw_if_cancelled(phase); }

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

// Runs a plot script on the python3 on PATH first, else Debian's, with
// `arguments` (quoted) after it; a plot that cannot be drawn is a warning.
static void run_plot_script(const std::filesystem::path& script, const std::string& arguments,
                            const std::filesystem::path& png) {
  if (!std::filesystem::exists(script)) {
    std::cerr << "warning: no plot: the plot script " << script.string() << " is missing\n";
    return;
  }
  for (const char* python : {"python3", "/usr/bin/python3"}) {
    if (std::system((std::string(python) + " -c 'import matplotlib' >/dev/null 2>&1").c_str()) != 0)
      continue;
    const std::string command =
        std::string(python) + " " + shell_quoted(script.string()) + " " + arguments;
    if (std::system((command + " >/dev/null").c_str()) == 0 && std::filesystem::exists(png))
      std::cout << "  plot: " << png.string() << "\n";
    else
      std::cerr << "warning: no plot: " << command << " failed\n";
    return;
  }
  std::cerr << "warning: no plot: no python3 with matplotlib (Debian: apt-get install "
               "python3-matplotlib)\n";
}

void draw_plot(const std::filesystem::path& folder, const std::string& input) {
  const std::filesystem::path png = folder / experiment::output_files::kPlot;
  run_plot_script(plot_script(),
                  shell_quoted((folder / input).string()) + " " + shell_quoted(png.string()), png);
}

void draw_prediction_plot(const std::filesystem::path& folder,
                          const std::filesystem::path& measured) {
  const std::filesystem::path png = folder / experiment::output_files::kPredictionPlot;
  std::string arguments = shell_quoted(folder.string()) + " -o " + shell_quoted(png.string());
  if (!measured.empty()) arguments += " --measured " + shell_quoted(measured.string());
  run_plot_script(plot_script().parent_path() / "plot_prediction.py", arguments, png);
}

bool every_rank_fails = false;

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

void fail_if_injected(const fiberfluid::parallel::Ranks& ranks) {
  const char* rank = std::getenv("FIBERFLUID_FAIL_RANK");
  if (rank != nullptr && std::atoi(rank) == ranks.rank() && ranks.size() > 1)
    throw std::runtime_error("a failure injected by FIBERFLUID_FAIL_RANK");
}

// Every rank must run what rank 0 runs: started with other files (mpirun's
// "A : B" form), a rank computed B's variants under A's record, or waited
// for ever when B had fewer (issue 43). Refused on every rank, naming them.
void require_one_experiment(const fiberfluid::parallel::Ranks& ranks,
                            const experiment::Experiment& ex, const std::string& path) {
  const std::vector<int> differing = ranks.differing_from_root(experiment::experiment_digest(ex));
  if (differing.empty()) return;
  std::string which;
  for (int r : differing) which += (which.empty() ? "" : ", ") + std::to_string(r);
  every_rank_fails = true;
  throw fiberfluid::InputError(
      "MPI rank(s) " + which + " read another experiment or surface than rank 0 (" + path +
      "): every rank must run the same experiment file, with the same mesh");
}

}  // namespace fiberfluid::app
