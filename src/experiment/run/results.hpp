// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// What running an experiment gives: each case's run, the figures, the checks
// of the expected figures, and a benchmark's or FEM reference's result. The
// runner makes it (runner.hpp), the run archive carries a run between ranks
// (run_archive.hpp), and write/ writes it.

#include <Eigen/Core>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fiberfluid/experiment/run/benchmark.hpp"
#include "fiberfluid/experiment/run/fem_reference.hpp"
#include "fiberfluid/experiment/run/run_result.hpp"
#include "fiberfluid/experiment/spec/experiment.hpp"
#include "fiberfluid/solve/stepping.hpp"

namespace fiberfluid::experiment {

struct FigureCheck {
  ExpectedFigure expected;
  double actual = 0.0;  // for a matrix: the largest entry-wise difference
  bool found = false;
  bool passed = false;
  std::string Describe() const;
};

struct ExperimentResult {
  std::vector<RunResult> runs;
  std::map<std::string, double> figures;  // headline figures, "variant.figure" for sweeps,
                                          // and fibers.in_all / kept / pruned
  std::vector<FigureCheck> checks;
  std::shared_ptr<const BenchmarkResult> benchmark;         // a benchmark's series
  std::shared_ptr<const FemReferenceResult> fem_reference;  // when the experiment asks for one
  std::string failure;  // what failed besides the runs (a benchmark's reference)
  // Sections a command adds to summary.json, by name (a prediction's).
  nlohmann::json summary_sections = nlohmann::json::object();
  bool runs_succeeded() const;
  bool checks_passed() const;
};

}  // namespace fiberfluid::experiment
