// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <array>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "fiberfluid/experiment/run/results.hpp"
#include "fiberfluid/experiment/spec/experiment.hpp"

namespace fiberfluid::model {
class Equilibrium;
}

#include "fiberfluid/experiment/write/file_names.hpp"

namespace fiberfluid::experiment {

// Writes an experiment's files as the run goes, so that a folder never mixes
// two runs: everything goes to a staging folder beside the target
// ("DIR.running-HOST-PID-XXXXXXXX", marked by a file INCOMPLETE), which
// replaces DIR in one atomic exchange when every run succeeded (the rules of
// experiment/output_folder.hpp: only a folder fiberfluid wrote is ever replaced).
// When a run fails, DIR keeps the last complete result and the staging
// folder becomes "DIR.failed" with a FAILED file saying why; an interrupted
// fit keeps its best point in "DIR.interrupted" (INTERRUPTED). A run that is
// killed leaves its staging folder apart (a later run on the same host
// removes it once its process has gone).
//
// Files, per run (in a subfolder named after the variant when the experiment
// sweeps): final.obj, steps.csv, vertices.csv, series.pvd and
// vtk/step_NNNN.vtu (point data displacement, displacement_magnitude,
// area_vector); at the top: summary.json, comparison.csv for a sweep,
// fibers.vtu when asked, and the marker .fiberfluid-output.json. A benchmark
// writes metrics.csv, benchmark.json and the final deformed boundaries
// (reference_final.obj, fiber_model_final.obj). A "fem_reference" adds
// fem_reference.obj (the FEM's deformed boundary, a target for
// `fiberfluid fit`) and fem_reference.vtu.
class OutputWriter {
 public:
  // Writes more files into the folder before it is moved into place.
  using FolderFiller = std::function<void(const std::filesystem::path& folder)>;

  // Throws InputError when DIR exists and may not be replaced (see
  // check_replaceable): before anything runs.
  OutputWriter(const Experiment& experiment, std::filesystem::path folder);
  // A writer dropped before finish() (an interruption, an exception) removes
  // its staging folder: DIR keeps its last complete result.
  ~OutputWriter();
  OutputWriter(const OutputWriter&) = delete;
  OutputWriter& operator=(const OutputWriter&) = delete;

  // Creates the staging folder and writes step 0 (the reference) of each run.
  void begin();
  // Runs of a sweep may report steps from several threads: each run's files are its own.
  void on_step(size_t run, const solve::StepRecord& record, const Eigen::VectorXd& unknowns);
  // Writes the summaries (and `more`) and moves the staging folder into
  // place: DIR when every run succeeded and result.failure is empty, else
  // DIR.failed.
  void finish(const ExperimentResult& result, const FolderFiller& more = {});
  // Moves what was written so far (and `more`) to DIR.interrupted, marked
  // INTERRUPTED with `why`.
  void keep_interrupted(const std::string& why, const FolderFiller& more);
  // Removes the staging folder and everything written so far.
  void abandon() noexcept;

  // Where the results are: DIR after a success, DIR.failed after a failure.
  const std::filesystem::path& folder() const { return result_folder_; }
  // What went wrong after the results were safely in place (an earlier
  // result that could not be removed).
  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  std::filesystem::path run_folder(size_t run) const;
  void write_state(size_t run, int step, const Eigen::VectorXd& unknowns,
                   const std::vector<double>& load_factors,
                   const std::vector<solve::StepRecord::HeldForce>& held_forces = {});
  // fem_reference_series.pvd: a nonlinear FEM's boundary after each load step.
  void write_fem_path(const FemReferenceResult& f);
  void write_fibers() const;  // fibers.vtu: the kept or pruned fibers, if asked
  void write_final_fibers(size_t run, const Eigen::VectorXd& unknowns) const;
  // The equations of a run's fiber readings (surface tension per face,
  // fibers_final.vtu), made on the run's first use.
  const model::Equilibrium& equilibrium(size_t run) const;
  void write_experiment_files() const;  // experiment.json and experiment.resolved.json
  void set_aside(const char* mark, const char* suffix, const std::string& what,
                 const std::string& why);
  void place(const std::filesystem::path& where);

  const Experiment& experiment_;
  std::filesystem::path target_, staging_, result_folder_;
  std::vector<std::vector<std::pair<double, std::string>>> series_;            // per run
  mutable std::vector<std::unique_ptr<const model::Equilibrium>> equilibria_;  // per run
  std::vector<std::string> warnings_;
};

}  // namespace fiberfluid::experiment
