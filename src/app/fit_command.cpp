// SPDX-License-Identifier: GPL-3.0-or-later
// fiberfluid fit: a fit or a calibration over specimens, shown as it goes.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>

#include "fiberfluid/app/cli.hpp"
#include "fiberfluid/experiment/fit_workflow.hpp"
#include "fiberfluid/experiment/run/fit_setup.hpp"
#include "fiberfluid/experiment/run/runner.hpp"
#include "fiberfluid/experiment/write/fit_files.hpp"
#include "fiberfluid/experiment/write/output_folder.hpp"
#include "fiberfluid/experiment/write/outputs.hpp"
#include "fiberfluid/util/progress.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::app {
namespace {

// Prints one line per iteration of a fit: its cost and point, and for a
// rejected step why (its cost, or its forward run's failure).
void print_iteration(const fiberfluid::fit::IterationRecord& r,
                     const std::vector<std::string>& names) {
  std::cerr << "fit: iteration " << r.iteration << ": cost " << r.cost << " m^2";
  if (!r.accepted && !r.trial_failure.empty())
    std::cerr << " (step rejected: its forward run failed: " << r.trial_failure << ")";
  else if (!r.accepted)
    std::cerr << " (step rejected: it cost " << r.trial_cost << ")";
  else if (!r.trial_failure.empty())
    std::cerr << " (after a trial point whose forward run failed: " << r.trial_failure << ")";
  std::cerr << ";";
  for (size_t k = 0; k < names.size(); ++k)
    std::cerr << (k ? ", " : " ") << names[k] << " = " << r.values[static_cast<Eigen::Index>(k)];
  std::cerr << "; " << r.forward_runs << " runs, " << r.seconds << " s\n";
}

// One line per finished start of a multi-start search.
void print_start(size_t s, const fiberfluid::fit::StartOutcome& o,
                 const std::vector<std::string>& names) {
  std::cerr << "fit: start " << s << " (rank " << o.rank
            << "): " << fiberfluid::fit::to_string(o.fit.status) << ", cost " << o.fit.final_cost
            << " m^2;";
  for (size_t k = 0; k < names.size(); ++k)
    std::cerr << (k ? ", " : " ") << names[k] << " " << o.start[static_cast<Eigen::Index>(k)]
              << " -> " << o.fit.values[static_cast<Eigen::Index>(k)];
  std::cerr << "; " << o.fit.iterations.size() << " iterations, " << o.fit.seconds << " s\n";
}

// The distinct optima of a multi-start search, and a warning when the best
// was reached from one start only.
void print_optima(const fiberfluid::fit::MultistartResult& search,
                  const std::vector<std::string>& names) {
  std::cout << "  " << search.optima.size() << " distinct optima from " << search.starts.size()
            << " starts (" << search.seconds << " s):\n";
  for (size_t o = 0; o < search.optima.size(); ++o) {
    const fiberfluid::fit::Optimum& optimum = search.optima[o];
    std::cout << "    " << (o == 0 ? "best" : "    ") << " cost " << optimum.cost << " m^2, "
              << optimum.starts.size() << " start(s):";
    for (size_t k = 0; k < names.size(); ++k)
      std::cout << (k ? ", " : " ") << names[k] << " = "
                << optimum.values[static_cast<Eigen::Index>(k)];
    std::cout << "\n";
  }
  if (search.best_found_once)
    std::cerr << "warning: the best optimum was reached from one start only: a cheaper one may "
                 "lie where no start came near (more \"starts\" or narrower bounds tell)\n";
}

void print_fit(const fiberfluid::fit::FitResult& fitted) {
  namespace fit = fiberfluid::fit;
  if (!fitted.start_note.empty()) std::cout << "  start: " << fitted.start_note << "\n";
  for (size_t k = 0; k < fitted.names.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    std::cout << "  " << fitted.names[k] << " = " << fitted.values[i];
    const auto listed = [&](const std::vector<std::string>& names) {
      return std::find(names.begin(), names.end(), fitted.names[k]) != names.end();
    };
    if (listed(fitted.at_bounds))
      std::cout << " (on its bound: no standard error";
    else if (listed(fitted.unseen))
      std::cout << " (not seen by the data: held, no standard error";
    else if (std::isfinite(fitted.standard_errors[i]))
      std::cout << " +- " << fitted.standard_errors[i] << " (95%: " << fitted.lower_95[i] << " .. "
                << fitted.upper_95[i];
    else
      std::cout << " (no standard error";
    std::cout << "; start " << fitted.initial[i] << ")\n";
    if (k < fitted.interval_notes.size() && !fitted.interval_notes[k].empty())
      std::cout << "    interval: " << fitted.interval_notes[k] << "\n";
  }
  if (!fitted.statistics.empty()) {
    const auto& d = fitted.overall;
    std::cout << "  distance (" << d.count << " model vertices to their targets): mean " << d.mean
              << ", rms " << d.rms << ", sd " << d.standard_deviation << " ("
              << 100.0 * d.share(d.standard_deviation) << "% of the body's length " << d.length
              << "), largest " << d.largest << " m\n";
  }
  for (const fit::ForceMisfit& m : fitted.force_misfits) {
    std::cout << "  force misfit (" << m.simulated.size() << " rows): rms " << m.rms << " N ("
              << 100.0 * m.share(m.rms) << "% of the largest measured force " << m.scale << " N; "
              << 100.0 * m.rms_relative << "% rms relative), largest " << m.largest << " N\n";
    if (!m.verdict.empty()) std::cout << "    residuals: " << m.verdict << "\n";
  }
  std::cout << "  " << fitted.forward_runs << " forward runs";
  if (fitted.failed_runs > 0) std::cout << " (" << fitted.failed_runs << " failed)";
  if (fitted.warm_started_runs > 0)
    std::cout << " (" << fitted.warm_started_runs << " solved from a nearby point's state)";
  std::cout << ", " << fitted.sensitivity_solves << " sensitivity solves, " << fitted.seconds
            << " s\n";
  if (!fitted.warm_start_note.empty()) std::cerr << "warning: " << fitted.warm_start_note << "\n";
  for (const auto& [cause, count] : fitted.failures_by_cause)
    std::cout << "  failed forward runs: " << count << " x " << cause << "\n";
  if (!fitted.failed_examples.empty()) {
    const fit::FailedRun& f = fitted.failed_examples.front();
    std::cout << "  first failure at";
    for (size_t k = 0; k < fitted.names.size(); ++k)
      std::cout << (k ? ", " : " ") << fitted.names[k] << " = "
                << f.values[static_cast<Eigen::Index>(k)];
    std::cout << ": " << f.message << "\n";
  }
}

// A calibration over several specimens ("kind": "calibration"): rank 0 runs
// Levenberg-Marquardt, every rank evaluates the specimens dealt to it at each
// point. The folder holds calibration.json and each specimen's fit files.
int calibrate_specimens(const experiment::Experiment& ex, const experiment::JointSetup& setup,
                        const std::filesystem::path& folder, const RunFlags& flags,
                        const fiberfluid::parallel::Ranks& ranks) {
  namespace fit = fiberfluid::fit;
  const fit::JointCalibration& joint = *setup.joint;
  const fit::Broadcast broadcast = [&ranks](std::string& bytes) { ranks.broadcast(bytes); };
  if (!ranks.root()) {
    joint.serve(ranks.dealer(), broadcast);
    stop_if_interrupted("the calibration");
    return kOk;
  }
  std::cout << "calibrating " << joint.names().size() << " parameters ("
            << ex.calibration().spec.shared.size() << " shared) to " << joint.num_residuals()
            << " residuals of " << joint.specimen_names().size() << " specimens over "
            << ranks.size() << " rank(s)\n";
  for (size_t s = 0; s < setup.specimens.size(); ++s)
    std::cout << "  specimen " << joint.specimen_names()[s] << ": "
              << ex.calibration().specimens[s].source.string() << ", "
              << setup.specimens[s].targets.size() << " target(s), "
              << setup.specimens[s].calibration->num_residuals() << " residuals\n";
  const experiment::CalibrationOutcome outcome =
      experiment::run_calibration(ex, setup, folder, ranks.dealer(), broadcast);
  const fit::JointFitResult& fitted = outcome.fitted;
  const experiment::ExperimentResult& result = outcome.result;
  if (outcome.interrupted()) {
    std::cerr << "\nerror: the calibration was interrupted (SIGINT or SIGTERM); its best point "
                 "so far is in "
              << (outcome.folder / "calibration.json").string() << "\n";
    return experiment::fit_exit_status(fitted.status);
  }
  for (const std::string& w : outcome.warnings) std::cerr << "warning: " << w << "\n";
  std::cout << ex.name << ": " << fit::to_string(fitted.status) << ": " << fitted.message
            << "; results in " << outcome.folder.string() << "\n";
  if (!fitted.status_detail.empty()) std::cout << "  " << fitted.status_detail << "\n";
  for (size_t k = 0; k < fitted.names.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    std::cout << "  " << fitted.names[k] << (static_cast<int>(k) < fitted.shared ? " (shared)" : "")
              << " = " << fitted.values[i];
    if (std::isfinite(fitted.standard_errors[i]))
      std::cout << " +- " << fitted.standard_errors[i] << " (95%: " << fitted.lower_95[i] << " .. "
                << fitted.upper_95[i] << ")";
    std::cout << "; start " << fitted.initial[i] << "\n";
  }
  for (size_t s = 0; s < fitted.specimens.size(); ++s) {
    const fit::DistanceStatistics& d = fitted.specimens[s].overall;
    std::cout << "  specimen " << joint.specimen_names()[s] << ": distance sd "
              << d.standard_deviation << " m (" << 100.0 * d.share(d.standard_deviation)
              << "% of its length " << d.length << " m), rms " << d.rms << ", largest " << d.largest
              << " m\n";
  }
  std::cout << "  " << fitted.evaluations << " evaluations, " << fitted.seconds << " s\n";
  for (const experiment::FigureCheck& c : result.checks) std::cout << "  " << c.Describe() << "\n";
  if (!experiment::fit_result_kept(fitted.status)) std::cerr << "error: " << result.failure << "\n";
  if (const int status = experiment::fit_exit_status(fitted.status); status != kOk) return status;
  if (flags.check_expected && !result.checks_passed()) {
    std::cerr << "error: some expected figures were not met (see above)\n";
    return kChecksFailed;
  }
  return kOk;
}

// Each parameter on the other mesh beside its statistical interval; a
// warning where the mesh moves it further than the data pin it.
void print_mesh_check(const fiberfluid::fit::FitResult& fitted,
                      const experiment::MeshCheck& check) {
  if (!check.failure.empty()) {  // said as the fit's failure too
    std::cout << "  mesh check (" << check.resolution << "): failed\n";
    return;
  }
  std::cout << "  mesh check (" << check.resolution << ", "
            << fiberfluid::fit::to_string(check.fitted.status) << "):\n";
  for (size_t k = 0; k < fitted.names.size() && k < check.fitted.names.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    const double shift = check.fitted.values[i] - fitted.values[i];
    const double half_width =
        fitted.upper_95.size() > i ? 0.5 * (fitted.upper_95[i] - fitted.lower_95[i]) : 0.0;
    std::printf(
        "    %s = %.6g there: mesh shift %+.4g (%.2g%%), the 95%% interval's half-width %.4g\n",
        fitted.names[k].c_str(), check.fitted.values[i], shift, 100.0 * shift / fitted.values[i],
        half_width);
    if (std::isfinite(half_width) && std::abs(shift) > half_width)
      std::cerr << "warning: the mesh moves " << fitted.names[k]
                << " further than its statistical interval: the fitted value is this mesh's "
                   "model's more than the material's (refine the mesh, or report the shift)\n";
  }
}

// What the fit is about to do: its targets and force curves, its residuals,
// its method.
void print_fit_plan(const experiment::Experiment& ex, const experiment::FitSetup& setup,
                    int ranks) {
  namespace fit = fiberfluid::fit;
  const bool multistart = ex.fit()->multistart.has_value();
  for (const auto& t : setup.targets)
    std::cout << "target " << t.target.label << " (step " << t.step << "): " << t.target.description
              << "\n";
  const fit::Calibration& calibration = *setup.calibration;
  int force_rows = 0;
  for (size_t k = 0; k < setup.force_curves.size(); ++k) {
    const fit::ForceCurve& f = setup.force_curves[k];
    force_rows += static_cast<int>(f.force.size());
    std::cout << "force curve " << f.label << ": " << f.force.size() << " rows at "
              << (f.by_step ? "load steps" : "travels") << ", weight "
              << calibration.force_weight(k) << " m per N"
              << (f.relative ? ", each row's misfit as a share of its force" : "") << "\n";
  }
  const int counted = calibration.num_counted_vertices();
  const int forward = counted * static_cast<int>(setup.targets.size());
  const int distances = calibration.num_residuals() - force_rows;
  std::cout << "fitting " << calibration.parameters().size() << " parameters to ";
  if (!setup.targets.empty()) {
    std::cout << distances << " distances (" << counted << " model vertices to each of "
              << setup.targets.size() << " target(s)";
    if (distances > forward)
      std::cout << ", and " << distances - forward << " target points to the simulated surface";
    std::cout << ")" << (force_rows > 0 ? " and " : "");
  }
  if (force_rows > 0) std::cout << force_rows << " force misfits";
  if (const auto& others = ex.fit()->kind_targets; !others.empty()) {
    std::cout << (setup.targets.empty() && force_rows == 0 ? "" : " and ") << others.size()
              << " target(s) of other kinds (";
    for (size_t k = 0; k < others.size(); ++k) std::cout << (k ? ", " : "") << others[k].kind;
    std::cout << ")";
  }
  std::cout << " (" << fit::to_string(ex.fit()->options.method) << ", "
            << (setup.calibration->analytic_jacobian() ? "analytic Jacobian"
                                                       : "finite differences");
  if (multistart)
    std::cout << ", from each of " << ex.fit()->multistart->starts << " starts over " << ranks
              << " rank(s)";
  std::cout << ")\n";
}

}  // namespace

// Calibrates the material of an experiment to its "fit" targets, then runs
// it at the fitted values and writes the usual outputs with the fit's files.
// Every fit file is in the folder before it moves into place: DIR for a fit
// that converged, DIR.failed for one that did not, DIR.interrupted (the best
// point so far, for fit.start_from) for one stopped by SIGINT or SIGTERM.
int fit_command(const std::string& path, const RunFlags& flags,
                const fiberfluid::parallel::Ranks& ranks) {
  namespace fit = fiberfluid::fit;
  fiberfluid::set_memory_budget(flags.max_memory);
  fiberfluid::set_time_budget(flags.max_time);
  ProgressPrinter printer;
  // Every rank reads the experiment and its targets; rank 0 alone checks the
  // output folder (refused now, not after the fit).
  std::optional<experiment::Experiment> loaded;
  std::filesystem::path folder;
  experiment::FitSetup setup;
  experiment::JointSetup joint;
  std::vector<std::string> names;
  bool multistart = false;
  on_every_rank(ranks, [&] {
    loaded.emplace(load_showing_progress(path, flags.quiet || !ranks.root(), printer));
  });
  require_one_experiment(ranks, *loaded, path);
  on_every_rank(ranks, [&] {
    fiberfluid::set_progress_sink({});  // the fit's many runs: one line per iteration instead
    if (ranks.root()) folder = experiment::output_folder(flags.output, loaded->name);
    if (loaded->kind() == experiment::Experiment::Kind::Calibration) {
      joint = experiment::setup_joint(*loaded, [&](const fit::IterationRecord& r) {
        if (!flags.quiet) print_iteration(r, joint.joint->names());
      });
      return;
    }
    if (loaded->fit())
      for (const auto& p : loaded->fit()->parameters) names.push_back(p.request.name);
    multistart = loaded->fit() && loaded->fit()->multistart;
    // A multi-start search prints a line per start instead of per iteration.
    setup = experiment::setup_fit(*loaded, [&](const fit::IterationRecord& r) {
      if (!flags.quiet && !multistart) print_iteration(r, names);
    });
  });
  const experiment::Experiment& ex = *loaded;
  if (ex.kind() == experiment::Experiment::Kind::Calibration)
    return calibrate_specimens(ex, joint, folder, flags, ranks);
  const fiberfluid::WorkDealer dealer = ranks.dealer();
  if (!ranks.root()) {  // the ranks' share of the starts; a single fit is rank 0's alone
    if (multistart) fit::serve_multistart(*setup.calibration, *ex.fit()->multistart, dealer);
    stop_if_interrupted("the fit");
    return kOk;
  }
  if (ranks.size() > 1 && !multistart)
    std::cerr << "note: a single fit runs on rank 0 alone; \"method\": \"multistart\" deals "
                 "its starts out over the ranks\n";
  print_fit_plan(ex, setup, ranks.size());
  experiment::FitHooks hooks;
  hooks.on_start = [&](size_t s, const fit::StartOutcome& o) {
    if (!flags.quiet) print_start(s, o, names);
  };
  hooks.on_phase = [&](const std::string& phase) {
    if (!flags.quiet) std::cerr << phase << "\n";
  };
  const experiment::FitOutcome outcome = experiment::run_fit(ex, setup, folder, dealer, hooks);
  const fit::FitResult& fitted = outcome.fitted;
  const experiment::ExperimentResult& result = outcome.result;
  if (outcome.interrupted()) {
    const std::string fit_json = (outcome.folder / "fit.json").string();
    std::cerr
        << "\nerror: the fit was interrupted (SIGINT or SIGTERM); its best point so far is in "
        << fit_json << " (continue with \"start_from\": \"" << fit_json
        << "\" in the fit section)\n";
    return experiment::fit_exit_status(fitted.status);
  }
  for (const std::string& w : outcome.warnings) std::cerr << "warning: " << w << "\n";

  std::cout << ex.name << ": " << fit::to_string(fitted.status) << ": " << fitted.message
            << "; results in " << outcome.folder.string() << "\n";
  if (!fitted.status_detail.empty()) std::cout << "  " << fitted.status_detail << "\n";
  if (outcome.search) print_optima(*outcome.search, names);
  print_fit(fitted);
  if (outcome.mesh_check) print_mesh_check(fitted, *outcome.mesh_check);
  for (const experiment::FigureCheck& c : result.checks) std::cout << "  " << c.Describe() << "\n";
  if (!result.runs_succeeded()) {
    for (const experiment::RunResult& run : result.runs)
      if (!run.summary.success) std::cerr << "error: " << run.summary.message << "\n";
    return kSolverFailed;
  }
  if (fitted.status == fit::FitStatus::ConvergedAtBounds)
    std::cerr << "warning: the fit converged on bounds: " << fitted.status_detail
              << ". A bound is no estimate: widen it, fix the parameter, or check the model\n";
  else if (!fitted.unseen.empty())
    std::cerr << "warning: the data cannot see " << fitted.unseen.size()
              << " of the fitted parameters: " << fitted.status_detail
              << ". Fix them, or add targets that see them\n";
  else if (!experiment::fit_result_kept(fitted.status))
    std::cerr << "error: " << result.failure << "\n";
  if (const int status = experiment::fit_exit_status(fitted.status); status != kOk) return status;
  if (flags.check_expected && !result.checks_passed()) {
    std::cerr << "error: some expected figures were not met (see above)\n";
    return kChecksFailed;
  }
  return kOk;
}

}  // namespace fiberfluid::app
