// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// A calibration over several specimens: each its own surface, loads and
// targets (a Calibration), some parameters shared by all (a law's Y0 and
// beta: one tissue) and the others each specimen's own (gamma, an alignment
// of its scans). The cost is the sum of the specimens' costs; the fitted
// variables are the shared ones, then each specimen's own in its order.
//
// The fit is a single fit's (Levenberg-Marquardt, the bounded step, the
// covariance and estimate) on the specimens' residuals stacked as one
// objective, on the gathering process (MPI rank 0). At each point it asks for, the specimens' residuals and Jacobian blocks
// (Newton sensitivities) are dealt out as work items (util/work_dealer.hpp:
// over the ranks, one specimen at a time to whichever rank asks); the other
// ranks serve them (serve) until the fit ends. The point reaches them by a
// Broadcast. One process: the same, in order, here.

#include <functional>
#include <string>
#include <vector>

#include "fiberfluid/fit/calibration.hpp"
#include "fiberfluid/util/work_dealer.hpp"

namespace fiberfluid::fit {

// Rank 0's bytes to every rank, in place (parallel::Ranks::broadcast); one
// process: nothing to do.
using Broadcast = std::function<void(std::string& bytes)>;

struct JointOptions {
  int max_iterations = 50;
  double function_tolerance = 1e-12;
  double parameter_tolerance = 1e-8;
  double max_step_factor = 4.0;  // as FitOptions::max_step_factor
  // Called on the gathering process after every iteration.
  std::function<void(const IterationRecord&)> progress;
};

struct JointFitResult {
  FitStatus status = FitStatus::StartFailed;
  bool success = false;
  std::string message, status_detail;
  // The fitted parameters: the shared ones by name, then each specimen's
  // own as "SPECIMEN.NAME".
  std::vector<std::string> names;
  int shared = 0;  // how many of names are shared (the first ones)
  Eigen::VectorXd initial, values;
  // 95% intervals from the covariance (J^T J)^-1 at the optimum, scaled by the
  // residual variance 2 cost / (residuals - parameters); in log scale for
  // log-scaled parameters. NaN for a parameter on a bound.
  bool covariance_ok = false;
  Eigen::VectorXd standard_errors, lower_95, upper_95;
  Eigen::MatrixXd correlation;
  std::vector<IterationRecord> iterations;
  double initial_cost = 0.0, final_cost = 0.0;  // 1/2 sum r^2 over every specimen, m^2
  int residuals = 0;
  int evaluations = 0;  // points evaluated (each one run per specimen)
  double seconds = 0.0;
  // Per specimen, at the fitted values: its run, distances and statistics
  // (Calibration::result_at; its own parameters' values in fit.values).
  std::vector<FitResult> specimens;
};

class JointCalibration {
 public:
  // The specimens' calibrations (each with its own parameters, which must
  // include every shared one with the same bounds and scale; a shared
  // parameter starts from the first specimen's start). They must outlive
  // this. Throws InputError naming the specimen and the parameter, or for a
  // specimen whose objective is not squared distances.
  JointCalibration(std::vector<std::string> specimen_names,
                   std::vector<const Calibration*> specimens, std::vector<std::string> shared,
                   JointOptions options = {});

  const std::vector<std::string>& names() const { return names_; }
  // The joint variables (shared, then each specimen's own), with their
  // bounds and scales.
  const Variables& variables() const { return variables_; }
  // Every specimen's Jacobian is analytic (Newton sensitivities).
  bool analytic_jacobian() const;
  const std::vector<std::string>& specimen_names() const { return specimen_names_; }
  int num_residuals() const { return residuals_; }
  // Specimen s's fitted variables within the joint ones, and the joint
  // index of its k-th.
  Eigen::VectorXd specimen_phi(size_t s, const Eigen::VectorXd& phi) const;
  int joint_index(size_t s, int k) const { return joint_of_[s][static_cast<size_t>(k)]; }
  // Specimen s's share at the joint point phi, as bytes (wherever it is
  // dealt): its residuals and Jacobian block, or its run and distances.
  std::string specimen_evaluation(size_t s, const Eigen::VectorXd& phi, bool with_jacobian) const;
  std::string specimen_result(size_t s, const Eigen::VectorXd& phi) const;

  // The fit, on the gathering process.
  JointFitResult run(const WorkDealer& deal, const Broadcast& broadcast) const;
  // The other ranks: their share of every evaluation until run() ends.
  void serve(const WorkDealer& deal, const Broadcast& broadcast) const;

 private:
  std::vector<std::string> specimen_names_, names_;
  std::vector<const Calibration*> specimens_;
  Variables variables_{{}};                 // joint, with their bounds and scales
  std::vector<std::vector<int>> joint_of_;  // per specimen: its k-th variable's joint index
  int shared_ = 0, residuals_ = 0;
  JointOptions options_;
};

}  // namespace fiberfluid::fit
