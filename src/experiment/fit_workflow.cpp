// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/fit_workflow.hpp"

#include "fiberfluid/experiment/write/fit_files.hpp"
#include "fiberfluid/experiment/write/outputs.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::experiment {
namespace {

// Why a fit that did not converge is not a result ("" for one that did).
std::string ending(const char* what, fit::FitStatus status, const std::string& message,
                   const std::string& detail) {
  if (fit_result_kept(status)) return {};
  return std::string(what) + " ended " + fit::to_string(status) + ": " + message +
         (detail.empty() ? "" : "; " + detail);
}

}  // namespace

FitOutcome run_fit(const Experiment& ex, const FitSetup& setup, const std::filesystem::path& folder,
                   const WorkDealer& dealer, const FitHooks& hooks) {
  const fit::Calibration& calibration = *setup.calibration;
  FitOutcome out;
  // A mesh check that cannot be posed (its mesh lacks a point the experiment
  // names, its fibers refuse it) is bad input before the fit, not after it.
  if (ex.fit()->mesh_check != "none") {
    std::string resolution;
    mesh_check_experiment(ex, &resolution);
  }
  if (ex.fit()->multistart) {
    out.search = fit::run_multistart(calibration, *ex.fit()->multistart, dealer, hooks.on_start);
    out.fitted = out.search->best();
    // Stopped early: the best start so far, kept as an interrupted fit's.
    if (cancel_requested()) out.fitted.status = fit::FitStatus::Interrupted;
  } else {
    out.fitted = calibration.run();
  }
  const fit::FitResult& fitted = out.fitted;
  const fit::MultistartResult* searched = out.search ? &*out.search : nullptr;

  const Experiment at_fit = with_fitted_material(ex, calibration, fitted);
  OutputWriter writer(at_fit, folder);
  writer.begin();
  if (out.interrupted()) {
    const ExperimentResult none;
    writer.keep_interrupted("the fit was interrupted after " +
                                std::to_string(fitted.iterations.size()) +
                                " iterations; fit.json holds the best point so far (continue "
                                "with \"start_from\" in the fit section)",
                            [&](const std::filesystem::path& dir) {
                              write_fit_files(dir, at_fit, setup, fitted, none, searched);
                            });
    out.folder = writer.folder();
    return out;
  }
  ExperimentResult& result = out.result;
  if (fitted.status != fit::FitStatus::StartFailed) {
    result = run_experiment(at_fit, [&](size_t run, const solve::StepRecord& r,
                                        const Eigen::VectorXd& x) { writer.on_step(run, r, x); });
    throw_if_cancelled("the run at the fitted values");
    for (const auto& [name, value] : fit_figures(fitted)) result.figures[name] = value;
    if (ex.fit()->mesh_check != "none" && fit_result_kept(fitted.status)) {
      if (hooks.on_phase)
        hooks.on_phase("mesh check: the fit again on a " + ex.fit()->mesh_check + " mesh");
      out.mesh_check = run_mesh_check(at_fit);
      throw_if_cancelled("the mesh check");
      if (out.mesh_check->failure.empty())
        for (const auto& [name, value] : mesh_check_figures(fitted, *out.mesh_check))
          result.figures[name] = value;
    }
    if (out.search)
      for (const auto& [name, value] : multistart_figures(*out.search))
        result.figures[name] = value;
    result.checks = check_expected(at_fit, result);
  }
  result.failure = ending("the fit", fitted.status, fitted.message, fitted.status_detail);
  // A check that failed keeps the fit: DIR.failed with the check's reason.
  if (result.failure.empty() && out.mesh_check && !out.mesh_check->failure.empty())
    result.failure = "the mesh check failed: " + out.mesh_check->failure;
  const MeshCheck* check = out.mesh_check ? &*out.mesh_check : nullptr;
  writer.finish(result, [&](const std::filesystem::path& dir) {
    write_fit_files(dir, at_fit, setup, fitted, result, searched, check);
  });
  out.folder = writer.folder();
  out.warnings = writer.warnings();
  return out;
}

CalibrationOutcome run_calibration(const Experiment& ex, const JointSetup& setup,
                                   const std::filesystem::path& folder, const WorkDealer& dealer,
                                   const fit::Broadcast& broadcast) {
  CalibrationOutcome out;
  out.fitted = setup.joint->run(dealer, broadcast);
  const fit::JointFitResult& fitted = out.fitted;
  OutputWriter writer(ex, folder);
  writer.begin();
  ExperimentResult& result = out.result;
  result.figures = joint_figures(ex, fitted);
  result.checks = check_expected(ex, result);
  const auto files = [&](const std::filesystem::path& dir) {
    write_joint_files(dir, ex, setup, fitted, result);
  };
  if (out.interrupted()) {
    writer.keep_interrupted("the calibration was interrupted after " +
                                std::to_string(fitted.iterations.size()) + " iterations",
                            files);
    out.folder = writer.folder();
    return out;
  }
  result.failure = ending("the calibration", fitted.status, fitted.message, fitted.status_detail);
  writer.finish(result, files);
  out.folder = writer.folder();
  out.warnings = writer.warnings();
  return out;
}

}  // namespace fiberfluid::experiment
