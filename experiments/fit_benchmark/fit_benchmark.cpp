// SPDX-License-Identifier: GPL-3.0-or-later
// The calibration benchmark (issue 9): a 3-parameter fit (Y0, beta, gamma)
// of an experiment's Newton run to its own deformed surface, from a start a
// factor 3 away, with the analytic Jacobian (the stepper's sensitivities;
// Levenberg-Marquardt's first trust region Ceres' 1e4 and 10) and with
// central differences of whole runs, in one process. Prints the time to
// convergence, forward runs, sensitivity solves and the recovered values.
//   fiberfluid_fit_benchmark [EXPERIMENT.json] [--skip-differences]
#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <vector>

#include "fiberfluid/experiment/experiment.hpp"
#include "fiberfluid/fit/calibration.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/util/omp_wait_policy.hpp"

namespace ff = fiberfluid;

int main(int argc, char** argv) {
  fiberfluid::util::wait_passively_unless_chosen(argv);  // as the fiberfluid program runs
  CLI::App cli{"fiberfluid calibration benchmark"};
  std::string experiment = FIBERFLUID_BENCHMARK_EXPERIMENT;
  bool skip_differences = false;
  cli.add_option("experiment", experiment, "A Newton experiment with an exponential law");
  cli.add_flag("--skip-differences", skip_differences, "Only the analytic Jacobian");
  CLI11_PARSE(cli, argc, argv);

  const auto load_start = std::chrono::steady_clock::now();
  const ff::experiment::Experiment ex = ff::experiment::load_experiment(experiment);
  const ff::experiment::Case& c = ex.simulation().cases.front();
  const double load_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - load_start).count();
  std::printf(
      "%s: %d vertices, %lld of %lld fibers kept, %d Newton steps; loaded and pruned in %.1f s\n",
      ex.name.c_str(), c.model.num_vertices(), c.fibers.kept, c.fibers.pairs, c.stepping.steps,
      load_seconds);
  std::fflush(stdout);

  // The truth and its deformed surface at the last step: the target.
  const auto truth_start = std::chrono::steady_clock::now();
  const ff::solve::SteppingSummary truth = ff::solve::solve_load_steps(c.model, c.stepping);
  if (!truth.success) {
    std::cerr << "error: the truth run failed: " << truth.message << "\n";
    return 2;
  }
  const double run_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - truth_start).count();
  std::printf("one forward run: %.2f s, %d Newton iterations\n", run_seconds,
              truth.newton_iterations);
  std::fflush(stdout);
  const std::vector<ff::fit::MeasuredStep> targets = {
      {ff::fit::make_target("truth", ff::model::positions(c.model, truth.unknowns),
                            c.model.surface.F),
       c.stepping.steps}};

  const ff::model::Material& truth_material = c.model.material;
  std::vector<ff::fit::Parameter> parameters;
  for (const char* name : {"Y0", "beta", "gamma"}) {
    ff::fit::Parameter p;
    p.name = name;
    const double value = truth_material.parameter(name);
    p.initial = std::string(name) == "gamma" ? 3.0 * value : value / 3.0;  // a factor 3 away
    p.log_scale = ff::fit::log_scale_by_default(name, truth_material);
    parameters.push_back(p);
  }

  // The analytic Jacobian with Ceres' first trust region and with a damped
  // one (initial_trust_region_radius 10), then central differences.
  struct Setting {
    bool differences;
    double radius;
  };
  std::vector<Setting> settings = {{false, 1e4}, {false, 10.0}};
  if (!skip_differences) settings.push_back({true, 1e4});
  std::printf(
      "\n| Jacobian | first trust region | iterations | forward runs | sensitivity solves | "
      "seconds | Y0 | beta | gamma |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  for (const Setting& setting : settings) {
    const bool differences = setting.differences;
    ff::fit::FitOptions options;
    options.finite_differences = differences;
    options.initial_trust_region_radius = setting.radius;
    options.progress = [](const ff::fit::IterationRecord& r) {  // stderr: unbuffered
      std::fprintf(stderr, "  iteration %d: cost %.6g%s, %d forward runs, %.1f s\n", r.iteration,
                   r.cost, r.accepted ? "" : " (step rejected)", r.forward_runs, r.seconds);
    };
    const ff::fit::Calibration calibration(c.model, c.stepping, targets, parameters, options);
    const ff::fit::FitResult r = calibration.run();
    std::printf("| %s | %g | %zu | %d | %d | %.1f | %.6g | %.6g | %.6g |%s\n",
                differences ? "central differences" : "analytic (Newton sensitivities)",
                setting.radius, r.iterations.empty() ? 0 : r.iterations.size() - 1, r.forward_runs,
                r.sensitivity_solves, r.seconds, r.values[0], r.values[1], r.values[2],
                r.success ? "" : (" " + r.message).c_str());
    std::fflush(stdout);
  }
  std::printf("\ntruth: Y0 %.6g, beta %.6g, gamma %.6g; start a factor 3 away\n",
              truth_material.parameter("Y0"), truth_material.parameter("beta"),
              truth_material.parameter("gamma"));
  return 0;
}
