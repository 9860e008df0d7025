// SPDX-License-Identifier: GPL-3.0-or-later
// fiberfluid: command-line tool. It only parses, loads and dispatches.
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <sstream>

#include "fiberfluid/app/cli.hpp"
#include "fiberfluid/experiment/read/schema.hpp"
#include "fiberfluid/experiment/run/compare.hpp"
#include "fiberfluid/experiment/run/mesh_study.hpp"
#include "fiberfluid/experiment/write/build_info.hpp"
#include "fiberfluid/experiment/write/output_folder.hpp"
#include "fiberfluid/geom/mesh_check.hpp"
#include "fiberfluid/geom/mesh_io.hpp"
#include "fiberfluid/util/omp_wait_policy.hpp"
#include "fiberfluid/util/run_control.hpp"

using namespace fiberfluid::app;  // NOLINT: the command's own helpers

namespace {

struct StudyFlags {
  std::string experiment, output;
  bool fem = false;
  int levels = 3;
  double ratio = 1.5;
  std::vector<std::string> figures;
  bool plot = false;
  RunFlags budgets;  // --max-memory and --max-time, over every level's runs and FEM
};

// One figure's row: its values, then its order and extrapolation or why it has none.
void print_studied_figure(const experiment::StudiedFigure& f, size_t levels) {
  std::printf("%-40s", f.name.c_str());
  for (double v : f.values) std::printf(" %14.7g", v);
  for (size_t k = f.values.size(); k < levels; ++k) std::printf(" %14s", "-");
  const fiberfluid::metrics::RichardsonEstimate& e = f.estimate;
  if (!f.estimated)
    std::printf(" %8s %14s\n", "-", "(< 3 levels)");
  else if (std::isfinite(e.order))
    std::printf(" %8.2f %14.7g %11.3g\n", e.order, e.extrapolated, e.error);
  else if (e.trend == fiberfluid::metrics::Trend::Oscillating)
    std::printf(" %8s %14s %11.3g\n", "-", "(oscillating)", e.error);
  else
    std::printf(" %8s %14s\n", "-",
                ("(" + std::string(fiberfluid::metrics::trend_name(e.trend)) + ")").c_str());
}

// fiberfluid study mesh: the levels' values, observed orders and
// extrapolations as a table, and study.csv / study.json in the output folder.
// A level that fails after others ran keeps theirs in DIR.failed (exit 2).
int study_command(const StudyFlags& flags) {
  fiberfluid::set_memory_budget(flags.budgets.max_memory);
  fiberfluid::set_time_budget(flags.budgets.max_time);
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
  for (int k = 0; k < spec.levels; ++k)
    std::printf(" %14s", ("level " + std::to_string(k + 1)).c_str());
  std::printf(" %8s %14s %11s\n", "order", "extrapolated", "error est.");
  for (const experiment::StudiedFigure& f : study.figures)
    print_studied_figure(f, static_cast<size_t>(spec.levels));
  for (size_t k = 0; k < study.resolutions.size(); ++k)
    std::printf("level %zu: %s, relative size %.4g, %.1f s\n", k + 1, study.resolutions[k].c_str(),
                study.sizes[k], study.seconds[k]);
  for (const std::string& w : study.warnings) std::cerr << "warning: " << w << "\n";
  const std::filesystem::path staging = experiment::create_staging_folder(output, name);
  fiberfluid::geom::write_text_file(staging / "study.csv", experiment::mesh_study_csv(study));
  fiberfluid::geom::write_text_file(staging / "study.json",
                                    experiment::mesh_study_json(study).dump(2) + "\n");
  std::filesystem::path placed = output;
  if (!study.failure.empty()) {
    fiberfluid::geom::write_text_file(
        staging / experiment::kFailedMark,
        "this study failed at level " + std::to_string(study.resolutions.size() + 1) +
            "; the levels before it are in study.csv and study.json\n" + study.failure + "\n");
    placed += ".failed";
  }
  std::vector<std::string> warnings;
  experiment::move_into_place(staging, placed, &warnings);
  for (const std::string& w : warnings) std::cerr << "warning: " << w << "\n";
  std::printf("wrote %s and %s\n", (placed / "study.csv").c_str(), (placed / "study.json").c_str());
  if (!study.failure.empty()) {
    std::cerr << "error: " << study.failure << "\n";
    return kSolverFailed;
  }
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

// A number option's check: CLI11's ranges compare, and NaN fails no
// comparison, so `--max-time nan` would pass as a budget and disable it.
// Every floating-point option is checked through here: a finite number, then
// `range`.
CLI::Validator finite_and(const CLI::Validator& range) {
  return CLI::Validator(
      [range](std::string& text) -> std::string {
        double value = 0.0;
        if (!CLI::detail::lexical_cast(text, value) || !std::isfinite(value))
          return "expected a finite number, got '" + text + "'";
        return range(text);
      },
      range.get_description());
}

// --max-memory SIZE: the memory budget that every case's estimate and every
// dense factor is checked against before it is allocated; --max-time: the
// longest estimate that may start.
void add_resource_limits(CLI::App* command, RunFlags& flags) {
  command
      ->add_option("--max-time", flags.max_time,
                   "Refuse a case whose estimated time exceeds this many seconds")
      ->check(finite_and(CLI::PositiveNumber));
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

// The command line's subcommands and what they read into.
struct Commands {
  std::string experiment, mesh;
  RunFlags flags, fit_flags, predict_flags;
  PredictFlags predict_paths;
  bool flip = false;
  std::string compared_reference, compared, undeformed;
  bool as_json = false;
  StudyFlags study_flags;
  CLI::App *run = nullptr, *fit = nullptr, *predict = nullptr, *check = nullptr, *compare = nullptr,
           *study = nullptr, *mesh_study = nullptr, *schema = nullptr;
};

void define_predict(CLI::App& cli, Commands& c) {
  c.predict = cli.add_subcommand(
      "predict",
      "Run an experiment at the values a fit found, with 95% bands on its figures, pressure, "
      "reactions and paddle forces from the fit's covariance (steps.csv: COLUMN_lower95, "
      "COLUMN_upper95; summary.json: \"prediction\")");
  c.predict
      ->add_option("fit_folder", c.predict_paths.fit_folder, "The folder `fiberfluid fit` wrote")
      ->required();
  c.predict->add_option("experiment", c.predict_paths.experiment, "Experiment file (JSON) to run")
      ->required();
  c.predict->add_option("-o,--output", c.predict_flags.output,
                        "Output folder (default: out/<experiment name>)");
  c.predict->add_flag("-q,--quiet", c.predict_flags.quiet, "No progress lines");
  c.predict->add_flag("--plot", c.predict_flags.plot,
                      "Also draw DIR/plot.png, as `run --plot` does, and DIR/prediction.png (the "
                      "force against travel with its band)");
  c.predict->add_option("--measured", c.predict_paths.measured,
                        "A measured force curve (CSV: a travel* or compression* column in mm, a "
                        "mean_N or force column in N) drawn against the prediction in "
                        "DIR/prediction.png");
  add_resource_limits(c.predict, c.predict_flags);
}

void define_commands(CLI::App& cli, Commands& c) {
  c.run = cli.add_subcommand("run", "Run an experiment file");
  c.run->add_option("experiment", c.experiment, "Experiment file (JSON)")->required();
  c.run->add_option("-o,--output", c.flags.output,
                    "Output folder (default: out/<experiment name>)");
  c.run->add_flag("--check", c.flags.check_expected,
                  "Exit with status 3 when an expected figure of the file is not met");
  c.run->add_flag("-q,--quiet", c.flags.quiet, "No progress lines");
  c.run->add_flag("--plot", c.flags.plot,
                  "Also draw DIR/plot.png (python3 with matplotlib; the deformed surface, and "
                  "per load step the displacement, pressure and reactions)");
  add_resource_limits(c.run, c.flags);
  c.run
      ->add_option("-j,--jobs", c.flags.jobs,
                   "Variants of a sweep run at once (default: one per core); each gets "
                   "cores / jobs threads")
      ->check(CLI::Range(0, 256));

  c.fit = cli.add_subcommand(
      "fit",
      "Calibrate the material of an experiment to its \"fit\" targets, then run it at the "
      "fitted values");
  c.fit->add_option("experiment", c.experiment, "Experiment file (JSON) with a \"fit\" section")
      ->required();
  c.fit->add_option("-o,--output", c.fit_flags.output,
                    "Output folder (default: out/<experiment name>)");
  c.fit->add_flag("--check", c.fit_flags.check_expected,
                  "Exit with status 3 when an expected figure of the file is not met");
  c.fit->add_flag("-q,--quiet", c.fit_flags.quiet, "No progress lines");
  add_resource_limits(c.fit, c.fit_flags);

  define_predict(cli, c);

  c.check = cli.add_subcommand("check", "Check a mesh file and print its report");
  c.check->add_option("mesh", c.mesh, "Mesh file (.obj, .off, .stl, .ply)")->required();
  c.check->add_flag("--flip", c.flip, "Reverse the face orientation before checking");

  c.compare = cli.add_subcommand(
      "compare",
      "The benchmarks paper's metrics (E_s; E_n and E_i with --reference) and the "
      "surface distances between a reference deformed surface M and another M'");
  c.compare->add_option("M", c.compared_reference, "The reference deformed surface")->required();
  c.compare->add_option("M_prime", c.compared, "The deformed surface to compare with it")
      ->required();
  c.compare->add_option("--reference", c.undeformed,
                        "The undeformed surface M0 (same vertices as both): adds E_n and E_i");
  c.compare->add_flag("--json", c.as_json, "Print JSON instead of text");

  c.study = cli.add_subcommand(
      "study", "Studies of an experiment: `study mesh` runs it at several resolutions");
  c.mesh_study = c.study->add_subcommand(
      "mesh",
      "Run an experiment at several resolutions (its surface's, or with --fem its FEM "
      "reference's element size) and print each figure's values, observed order and "
      "Richardson-extrapolated value with an error estimate");
  c.study->require_subcommand(1);
  c.mesh_study->add_option("experiment", c.study_flags.experiment, "Experiment file (JSON)")
      ->required();
  c.mesh_study->add_option("-o,--output", c.study_flags.output,
                           "Output folder for study.csv and study.json (default: "
                           "out/<experiment>_mesh_study)");
  c.mesh_study->add_flag("--fem", c.study_flags.fem,
                         "Refine the FEM reference's element size (fem_reference.size) instead "
                         "of the surface");
  c.mesh_study
      ->add_option("--levels", c.study_flags.levels, "Resolutions, coarse to fine (at least 3)")
      ->check(CLI::Range(3, 8));
  c.mesh_study
      ->add_option("--ratio", c.study_flags.ratio,
                   "Refinement between levels (element size, coarse over fine)")
      ->check(finite_and(CLI::Range(1.1, 4.0)));
  c.mesh_study->add_option("--figure", c.study_flags.figures,
                           "A figure to study (repeatable; default: every figure)");
  c.mesh_study->add_flag("--plot", c.study_flags.plot,
                         "Also draw DIR/plot.png: each figure against the element size, with its "
                         "extrapolation (python3 with matplotlib)");
  add_resource_limits(c.mesh_study, c.study_flags.budgets);

  c.schema = cli.add_subcommand(
      "schema",
      "Print the JSON Schema of experiment files (for an editor: \"$schema\" or its settings)");
}

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

  Commands c;
  define_commands(cli, c);

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
    if (c.run->parsed()) return run_command(c.experiment, c.flags, ranks);
    if (c.fit->parsed()) return fit_command(c.experiment, c.fit_flags, ranks);
    if (c.predict->parsed()) {
      if (!ranks.root()) return kOk;  // one process runs the prediction
      return predict_command(c.predict_paths, c.predict_flags);
    }
    if (!ranks.root()) return kOk;  // the other commands run on rank 0 alone
    if (c.schema->parsed()) {
      std::cout << fiberfluid::experiment::experiment_schema().dump(2) << "\n";
      return 0;
    }
    if (c.compare->parsed())
      return compare_command(c.compared_reference, c.compared, c.undeformed, c.as_json);
    if (c.study->parsed()) return study_command(c.study_flags);
    return check_command(c.mesh, c.flip);
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
