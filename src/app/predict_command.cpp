// SPDX-License-Identifier: GPL-3.0-or-later
// fiberfluid predict: another experiment run at a fit's values, with 95%
// bands on its figures and force rows from the fit's covariance.
#include <cmath>
#include <iostream>
#include <mutex>
#include <optional>

#include "fiberfluid/app/cli.hpp"
#include "fiberfluid/experiment/run/prediction.hpp"
#include "fiberfluid/experiment/run/runner.hpp"
#include "fiberfluid/experiment/write/output_folder.hpp"
#include "fiberfluid/experiment/write/outputs.hpp"
#include "fiberfluid/experiment/write/prediction_files.hpp"
#include "fiberfluid/util/progress.hpp"

namespace fiberfluid::app {

int predict_command(const PredictFlags& predict, const RunFlags& flags) {
  fiberfluid::set_memory_budget(flags.max_memory);
  fiberfluid::set_time_budget(flags.max_time);
  // Everything read and checked before anything runs or is written.
  const experiment::FittedEstimate estimate = experiment::read_fitted_estimate(predict.fit_folder);
  if (!predict.measured.empty() && !std::filesystem::is_regular_file(predict.measured))
    throw InputError(predict.measured + ": no such file (--measured: a measured force curve)");
  ProgressPrinter printer;
  experiment::Experiment ex = load_showing_progress(predict.experiment, flags.quiet, printer);
  experiment::apply_estimate(estimate, ex);
  experiment::OutputWriter writer(ex, experiment::output_folder(flags.output, ex.name));
  for (const std::string& held : estimate.held) std::cerr << "note: " << held << "\n";

  const size_t runs = ex.simulation().cases.size();
  std::vector<std::vector<Eigen::VectorXd>> unknowns(runs);
  std::mutex guard;  // a sweep's runs report from several threads
  experiment::RunOptions options;
  options.jobs = flags.jobs;
  writer.begin();
  experiment::ExperimentResult result = experiment::run_experiment(
      ex,
      [&](size_t run, const fiberfluid::solve::StepRecord& r, const Eigen::VectorXd& x) {
        writer.on_step(run, r, x);
        const std::lock_guard<std::mutex> lock(guard);
        std::vector<Eigen::VectorXd>& states = unknowns[run];
        states.resize(static_cast<size_t>(std::max(0, r.step)));
        if (r.step >= 1) states[static_cast<size_t>(r.step - 1)] = x;
      },
      options);
  printer.close();
  fiberfluid::set_progress_sink({});
  stop_if_interrupted("the prediction");
  const std::vector<experiment::RunBands> bands =
      experiment::prediction_bands(ex, result, estimate, unknowns);
  for (size_t r = 0; r < bands.size() && r < result.runs.size(); ++r)
    result.runs[r].bands = bands[r];
  result.summary_sections["prediction"] = experiment::prediction_json(ex, estimate, bands);
  writer.finish(result);
  for (const std::string& w : writer.warnings()) std::cerr << "warning: " << w << "\n";

  std::cout << ex.name << " at the values of " << estimate.source.string() << ": results in "
            << writer.folder().string() << "\n";
  for (size_t k = 0; k < estimate.names.size(); ++k)
    std::cout << "  " << estimate.names[k] << " = " << estimate.values[static_cast<Eigen::Index>(k)]
              << "\n";
  for (size_t r = 0; r < result.runs.size(); ++r) {
    const experiment::RunResult& run = result.runs[r];
    std::cout << "  " << (run.variant.empty() ? "run" : run.variant) << ": "
              << run.summary.BriefReport() << "\n";
    if (r >= bands.size()) continue;
    for (const auto& [name, band] : bands[r].figures) {
      std::cout << "  " << name << " = " << band.value;
      if (std::isfinite(band.sd))
        std::cout << " (95%: " << band.lower95() << " .. " << band.upper95() << ")";
      std::cout << "\n";
    }
  }
  if (!result.failure.empty() || !result.runs_succeeded()) {
    if (!result.failure.empty()) std::cerr << "error: " << result.failure << "\n";
    for (const experiment::RunResult& run : result.runs)
      if (!run.summary.success) std::cerr << "error: " << run.summary.message << "\n";
    return kSolverFailed;
  }
  if (flags.plot) draw_plot(writer.folder());
  if (flags.plot || !predict.measured.empty())
    draw_prediction_plot(writer.folder(), predict.measured);
  return kOk;
}

}  // namespace fiberfluid::app
