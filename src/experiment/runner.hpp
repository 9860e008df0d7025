// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fiberfluid/experiment/experiment.hpp"
#include "fiberfluid/solve/stepping.hpp"
#include "fiberfluid/util/work_dealer.hpp"

namespace fiberfluid::experiment {

// The outcome of one case (Experiment::cases, same index).
struct RunResult {
  std::string variant;
  solve::SteppingSummary summary;
  int rank = 0;  // the MPI rank that ran it
  // The bordered matrix the backend factored last, dense, when an expected
  // figure checks it ("system_matrix"); else empty.
  Eigen::MatrixXd system_matrix;
};

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
  bool runs_succeeded() const;
  bool checks_passed() const;
};

// Observes each load step of a run: (case index, record, unknowns). With
// several jobs it is called from several threads at once.
using RunObserver =
    std::function<void(size_t run, const solve::StepRecord&, const Eigen::VectorXd&)>;

// Checks the experiment's expected figures against a result's figures and runs.
std::vector<FigureCheck> check_expected(const Experiment& experiment,
                                        const ExperimentResult& result);

struct RunOptions {
  // Cases run at once. Each job's OpenMP loops get cores / jobs threads, so a
  // sweep of small models runs its variants side by side and a single large
  // model keeps every core for its pair loops. 0: as many as there are cores
  // (at most one per case).
  int jobs = 0;
  // When set, the cases are dealt out through it instead (over MPI ranks:
  // parallel::Ranks::dealer; jobs is not used):
  // each outcome comes back as bytes and is replayed into the observer, step
  // by step, where it is delivered. The other ranks call serve_cases.
  WorkDealer dealer;
};

// Runs every case of a simulation (or measures the surfaces of an areas
// experiment), then computes the figures and checks the expected ones.
ExperimentResult run_experiment(const Experiment& experiment, const RunObserver& observer = {},
                                const RunOptions& options = {});

// A rank other than rank 0 of a dealt run: runs the cases dealt to it and
// sends their outcomes back, through the same dealer rank 0 passed to
// run_experiment (RunOptions::dealer). Only a simulation has cases to deal.
void serve_cases(const Experiment& experiment, const WorkDealer& dealer);

// Positions of every input vertex (input order and count; vertices that are
// in no face stay where they are) for a model unknown vector.
Eigen::MatrixXd input_positions(const Case& c, const Eigen::VectorXd& unknowns);

// A named figure of one run, or nothing when the name is unknown:
//   max_displacement, final_pressure, final_volume, initial_volume,
//   volume_change_relative, mean_displacement_over_diagonal (the paper's
//   Eq. 9), surface_area, steps, factorizations, newton_iterations,
//   max_newton_iterations_per_step, step_cuts, max_equilibrium_residual,
//   paddle_force.LABEL (along its axis, on the body), paddle_contacts.LABEL,
//   position.I.x / displacement.I.y (I an input vertex index).
std::optional<double> run_figure(const Case& c, const RunResult& run, const std::string& name);

}  // namespace fiberfluid::experiment
