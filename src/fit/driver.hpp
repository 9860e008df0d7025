// SPDX-License-Identifier: GPL-3.0-or-later
// The fit's driver (internal to fit/): from a start to an ending, through
// the start's probe (a stiffer start where the given one fails), the
// optimiser (Ceres or NLopt), the run at the optimum and its estimate.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <utility>

#include "fiberfluid/fit/fit_types.hpp"
#include "fiberfluid/fit/problem.hpp"

namespace fiberfluid::fit {

class EvaluationCache;

class FitDriver {
 public:
  // The problem must outlive the driver.
  explicit FitDriver(const FitProblem& problem);

  // Calibration::run_from and Calibration::result_at.
  FitResult run_from(const Eigen::VectorXd& start_phi) const;
  FitResult result_at(const Eigen::VectorXd& phi) const;

 private:
  // A result at phi with nothing known yet: the values there, NaN errors,
  // intervals and costs, sized for the parameters.
  FitResult result_from(const Eigen::VectorXd& phi) const;
  // The optimum's warm-started evaluation run again along the load path: its
  // run described (every step's record) and, where the two equilibria
  // differ, FitResult::warm_start_note says so.
  void check_along_path(const Eigen::VectorXd& phi, const Evaluation& warm,
                        FitResult& result) const;
  // A start's run that gives up early (at most kProbeCuts halvings of a step
  // and kProbeIterations Newton iterations per piece; a success is the full
  // run's, to the bit), keeping a failed path's states near n/2, n/4, ...
  Evaluation probe_start(const Eigen::VectorXd& phi, bool with_jacobian,
                         const Eigen::VectorXd& warm_start = {}) const;
  // Where the start's probe failed: the softest start with every modulus
  // and gamma 2, 4, ... 1024 times the start's (within the bounds) whose
  // probe succeeds, and that factor; nullopt when none does, or none can
  // help. One whose end the failed probe passed (its state at step n/s) is
  // solved from there, warm.
  std::optional<Eigen::VectorXd> stiffer_start(const Eigen::VectorXd& start_phi,
                                               const Evaluation& failed_probe,
                                               EvaluationCache& evaluations,
                                               bool with_sensitivities, double* factor) const;

  // Where the fit starts (evaluated and kept): start_phi when its run
  // succeeds, else the softest stiffer start whose probe runs
  // (FitResult::start_note says so); nullopt, with how the fit ends, when it
  // cannot start (interrupted, or no start runs).
  std::optional<Eigen::VectorXd> starting_point(const Eigen::VectorXd& start_phi,
                                                bool with_sensitivities,
                                                EvaluationCache& evaluations, FitResult& result,
                                                std::pair<FitStatus, std::string>* ending) const;

  // A start whose moduli and gamma are scaled to its small-load forces
  // (FitOptions::scale_start): the scaled point, evaluated and kept, when its
  // cost is below the start's; else `phi` itself. FitResult::start_note says
  // what was done.
  Eigen::VectorXd scaled_start(const Eigen::VectorXd& phi, bool with_sensitivities,
                               EvaluationCache& evaluations, FitResult& result) const;

  const FitProblem& problem_;
};

}  // namespace fiberfluid::fit
