// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "app/experiment.hpp"
#include "app/runner.hpp"

namespace fiberfluid::app {

// The summary.json document: the experiment, per run its stepping options
// and per step load factors, pressure, volume, largest displacement and wall
// time, then the final figures and the checks of the expected ones.
nlohmann::json summary_json(const Experiment& experiment, const ExperimentResult& result);

// Writes an experiment's files into a folder as the run goes:
//   summary.json, fibers.vtu when asked, and per run (in a subfolder named after the variant when
//   the experiment sweeps): final.obj, series.pvd and vtk/step_NNNN.vtu with
//   point data displacement, displacement_magnitude and area_vector.
// Every file is written whole or not at all (temporary file and rename).
class OutputWriter {
 public:
  OutputWriter(const Experiment& experiment, std::filesystem::path folder);

  // Creates the folders and writes step 0 (the reference) of each run.
  void begin();
  void on_step(size_t run, const solve::StepRecord& record, const Eigen::VectorXd& unknowns);
  void finish(const ExperimentResult& result);

  const std::filesystem::path& folder() const { return folder_; }

 private:
  std::filesystem::path run_folder(size_t run) const;
  void write_state(size_t run, int step, const Eigen::VectorXd& unknowns);
  void write_fibers() const;  // fibers.vtu: the kept or pruned fibers, if asked

  const Experiment& experiment_;
  std::filesystem::path folder_;
  std::vector<std::vector<std::pair<double, std::string>>> series_;  // per run
};

}  // namespace fiberfluid::app
