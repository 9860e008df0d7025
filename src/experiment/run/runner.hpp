// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Running an experiment: its cases, side by side or dealt over MPI ranks,
// then its figures and the checks of the expected ones.

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fiberfluid/experiment/run/results.hpp"
#include "fiberfluid/experiment/spec/experiment.hpp"
#include "fiberfluid/solve/stepping.hpp"
#include "fiberfluid/util/work_dealer.hpp"

namespace fiberfluid::experiment {

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
