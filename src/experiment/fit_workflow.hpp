// SPDX-License-Identifier: GPL-3.0-or-later
// The fit workflow every front end runs once its fit is set up
// (fitting.hpp's setup_fit, setup_joint): the fit (one start or a
// multi-start search; or a calibration over specimens), the run at the
// fitted values, the mesh check, the figures and checks, and the output
// folder's ending (DIR for a fit that converged, DIR.failed for one that did
// not, DIR.interrupted for one stopped by SIGINT or SIGTERM). What it did is
// returned for the front end to show; it prints nothing.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "fiberfluid/experiment/experiment.hpp"
#include "fiberfluid/experiment/run/fit_setup.hpp"
#include "fiberfluid/experiment/run/runner.hpp"
#include "fiberfluid/fit/joint_calibration.hpp"
#include "fiberfluid/fit/multistart.hpp"
#include "fiberfluid/util/work_dealer.hpp"

namespace fiberfluid::experiment {

struct FitHooks {
  // A multi-start search's start, as each ends (its index and outcome).
  std::function<void(size_t, const fit::StartOutcome&)> on_start;
  // Before a long phase after the fit: "mesh check: the fit again on a coarser mesh".
  std::function<void(const std::string&)> on_phase;
};

struct FitOutcome {
  fit::FitResult fitted;
  std::optional<fit::MultistartResult> search;  // a multi-start search's starts and optima
  std::optional<MeshCheck> mesh_check;
  // The run at the fitted values with the fit's figures and the checks
  // (empty where the fit ended before any start ran), and, where the fit
  // did not converge, why (ExperimentResult::failure).
  ExperimentResult result;
  std::filesystem::path folder;       // where the files went
  std::vector<std::string> warnings;  // the output folder's
  // Stopped by SIGINT or SIGTERM: the best point so far is in folder/fit.json.
  bool interrupted() const { return fitted.status == fit::FitStatus::Interrupted; }
};

// The fit of `experiment` (set up as `setup`), written into `folder`. A
// multi-start search deals its starts out through `dealer` (empty: here, in
// order); the other ranks serve it (fit::serve_multistart). Throws
// InputError for a bad set-up, and Interrupted (util/run_control.hpp) when
// stopped after the fit
// (during the run at the fitted values or the mesh check).
FitOutcome run_fit(const Experiment& experiment, const FitSetup& setup,
                   const std::filesystem::path& folder, const WorkDealer& dealer = {},
                   const FitHooks& hooks = {});

struct CalibrationOutcome {
  fit::JointFitResult fitted;
  ExperimentResult result;  // the figures and checks, and why it failed
  std::filesystem::path folder;
  std::vector<std::string> warnings;
  bool interrupted() const { return fitted.status == fit::FitStatus::Interrupted; }
};

// The calibration over specimens ("kind": "calibration") set up as `setup`,
// written into `folder`; its evaluations dealt out through `dealer` and
// `broadcast` (the other ranks serve it: fit::JointCalibration::serve).
CalibrationOutcome run_calibration(const Experiment& experiment, const JointSetup& setup,
                                   const std::filesystem::path& folder, const WorkDealer& dealer,
                                   const fit::Broadcast& broadcast);

}  // namespace fiberfluid::experiment
