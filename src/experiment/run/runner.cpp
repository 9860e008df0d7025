// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/run/runner.hpp"

#include <omp.h>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "fiberfluid/bridge/fem_bridge.hpp"
#include "fiberfluid/experiment/run/fem_reference.hpp"
#include "fiberfluid/experiment/run/run_archive.hpp"
#include "fiberfluid/experiment/spec/figures.hpp"
#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/util/error.hpp"
#include "fiberfluid/util/progress.hpp"

namespace fiberfluid::experiment {
namespace {

// "position.12.y" -> (12, 1); nothing when the form does not match.
std::optional<std::pair<int, int>> vertex_axis(const std::string& rest, int dim) {
  const size_t dot = rest.find('.');
  if (dot == std::string::npos || dot + 2 != rest.size()) return std::nullopt;
  const int axis = rest.back() - 'x';
  if (axis < 0 || axis >= dim) return std::nullopt;
  try {
    size_t used = 0;
    const int index = std::stoi(rest.substr(0, dot), &used);
    if (used != dot || index < 0) return std::nullopt;
    return std::make_pair(index, axis);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

void add_area_figures(const Experiment& ex, ExperimentResult& result) {
  for (const NamedSurface& s : ex.areas().surfaces) {
    const geom::VertexAreaVectors areas = geom::vertex_area_vectors(s.surface.V, s.surface.F);
    result.figures[s.name + ".vertices"] = s.surface.num_vertices();
    result.figures[s.name + ".faces"] = s.surface.num_faces();
    result.figures[s.name + ".area_faces"] = areas.surface_area;        // sum |A_f|
    result.figures[s.name + ".area_vertices"] = areas.magnitude.sum();  // sum |S_i|
    result.figures[s.name + ".volume"] = geom::enclosed_volume(s.surface.V, s.surface.F);
  }
}

// Splits "variant.figure" when the prefix names a run; a single run also
// answers unprefixed names.
// The index of that run, or -1.
int run_for(const ExperimentResult& result, const std::string& name, std::string* figure) {
  for (size_t r = 0; r < result.runs.size(); ++r) {
    const std::string& variant = result.runs[r].variant;
    if (!variant.empty() && name.rfind(variant + ".", 0) == 0) {
      *figure = name.substr(variant.size() + 1);
      return static_cast<int>(r);
    }
  }
  *figure = name;
  return result.runs.size() == 1 ? 0 : -1;
}

FigureCheck check_figure(const Experiment& ex, const ExperimentResult& result,
                         const ExpectedFigure& expected) {
  FigureCheck check;
  check.expected = expected;
  std::string figure;
  const int r = run_for(result, expected.figure, &figure);
  if (expected.matrix.size() > 0) {
    if (r < 0 || figure != "system_matrix") return check;
    // The matrix the run's backend factored for its last step, not a second assembly.
    const Eigen::MatrixXd& A = result.runs[static_cast<size_t>(r)].system_matrix;
    if (A.size() == 0) return check;
    check.found = A.rows() == expected.matrix.rows() && A.cols() == expected.matrix.cols();
    if (!check.found) return check;
    check.actual = (A - expected.matrix).cwiseAbs().maxCoeff();
    check.passed = check.actual <= expected.tolerance;
    return check;
  }
  std::optional<double> value;
  auto it = result.figures.find(expected.figure);
  if (it != result.figures.end())
    value = it->second;
  else if (r >= 0)
    value = run_figure(ex.simulation().cases[static_cast<size_t>(r)],
                       result.runs[static_cast<size_t>(r)], figure);
  if (!value) return check;
  check.found = true;
  check.actual = *value;
  check.passed = std::isfinite(*value);
  if (expected.value) check.passed &= std::abs(*value - *expected.value) <= expected.tolerance;
  if (expected.at_most) check.passed &= *value <= *expected.at_most;
  if (expected.at_least) check.passed &= *value >= *expected.at_least;
  return check;
}

}  // namespace

Eigen::MatrixXd input_positions(const Case& ex, const Eigen::VectorXd& unknowns) {
  Eigen::MatrixXd X = ex.input_surface.V;
  const Eigen::MatrixXd model_X = model::positions(ex.model, unknowns);
  for (size_t m = 0; m < ex.model_to_input.size(); ++m)
    X.row(ex.model_to_input[m]) = model_X.row(static_cast<Eigen::Index>(m));
  return X;
}

std::optional<double> run_figure(const Case& ex, const RunResult& run, const std::string& name) {
  const model::Model& m = ex.model;
  const Eigen::VectorXd& x = run.summary.unknowns;
  const Eigen::MatrixXd U = model::displacements(m, x);
  const Eigen::MatrixXd X = m.surface.V + U;
  const double initial_volume = geom::enclosed_volume(m.surface.V, m.surface.F);
  const double final_volume = geom::enclosed_volume(X, m.surface.F);
  if (name == "max_displacement") return U.rowwise().norm().maxCoeff();
  if (name == "final_pressure") return x[m.pressure_dof()];
  if (name == "final_volume") return final_volume;
  if (name == "initial_volume") return initial_volume;
  if (name == "volume_change_relative") return (final_volume - initial_volume) / initial_volume;
  if (name == "mean_displacement_over_diagonal")  // the paper's Eq. 9
    return U.rowwise().norm().mean() / geom::bounding_box_diagonal(m.surface.V);
  if (name == "surface_area") return geom::surface_area(m.surface.V, m.surface.F);
  if (name == "steps") return static_cast<double>(run.summary.steps.size());
  if (name == "factorizations") return run.summary.factorizations;
  if (name == "newton_iterations") return run.summary.newton_iterations;
  if (name == "limit_load_factor") {  // arc length: where the path turned back
    if (std::isnan(run.summary.limit_load_factor)) return std::nullopt;
    return run.summary.limit_load_factor;
  }
  if (name == "max_newton_iterations_per_step" || name == "step_cuts" ||
      name == "max_equilibrium_residual") {
    double value = 0.0;
    for (const solve::StepRecord& r : run.summary.steps)
      value = std::max(value, name == "step_cuts"                        ? r.step_cuts
                              : name == "max_newton_iterations_per_step" ? r.newton_iterations
                                                                         : r.residual);
    return value;
  }
  if (name.rfind("paddle_force.", 0) == 0 || name.rfind("paddle_contacts.", 0) == 0) {
    // The final force of a paddle on the body along its axis, or its contacts.
    const bool force = name[7] == 'f';
    const std::string label = name.substr(force ? 13 : 16);
    for (size_t p = 0; p < m.paddles.size(); ++p)
      if (m.paddles[p].label == label && !run.summary.steps.empty()) {
        const auto& state = run.summary.steps.back().paddles.at(p);
        return force ? state.force[m.paddles[p].axis] : state.contacts;
      }
    return std::nullopt;
  }

  for (const std::string prefix : {"position.", "displacement."}) {
    if (name.rfind(prefix, 0) != 0) continue;
    const auto va = vertex_axis(name.substr(prefix.size()), m.dim());
    if (!va || va->first >= ex.input_surface.num_vertices()) return std::nullopt;
    const Eigen::MatrixXd P = input_positions(ex, x);
    const double position = P(va->first, va->second);
    return prefix == "position." ? position : position - ex.input_surface.V(va->first, va->second);
  }
  return std::nullopt;
}

static int core_count() {
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

static int effective_jobs(const RunOptions& options, size_t cases) {
  const int wanted = options.jobs > 0 ? options.jobs : core_count();
  return std::max(1, std::min(wanted, static_cast<int>(cases)));
}

// Calls run_case(r) for every case, on `jobs` threads: each worker takes the
// next case, and OpenMP threads are shared out so that jobs x threads stays
// at the core count. An exception in a worker (a write that failed: a full
// disk, a file-size limit) stops the others from taking new cases and is
// rethrown here, the first by case order, as if the cases ran one by one.
static void for_each_case(size_t count, int jobs, const std::function<void(size_t)>& run_case) {
  if (jobs == 1) {
    for (size_t r = 0; r < count; ++r) run_case(r);
    return;
  }
  const int threads_per_job = std::max(1, core_count() / jobs);
  std::atomic<size_t> next{0};
  std::atomic<bool> failed{false};
  std::vector<std::exception_ptr> errors(count);
  std::vector<std::thread> workers;
  for (int w = 0; w < jobs; ++w)
    workers.emplace_back([&] {
      omp_set_num_threads(threads_per_job);
      for (size_t r = next++; r < count && !failed; r = next++) {
        try {
          run_case(r);
        } catch (...) {
          errors[r] = std::current_exception();
          failed = true;
        }
      }
    });
  for (std::thread& worker : workers) worker.join();
  for (const std::exception_ptr& error : errors)
    if (error) std::rethrow_exception(error);
}

namespace {

// True when an expected figure compares a run's system matrix.
bool checks_system_matrix(const Experiment& ex) {
  for (const ExpectedFigure& e : ex.expected)
    if (e.matrix.size() > 0) return true;
  return false;
}

// Runs case r here, reporting its steps to `observer`.
RunResult run_case(const Experiment& ex, size_t r, const solve::StepObserver& observer) {
  const ProgressLabel label(ex.simulation().cases[r].variant);
  RunResult run;
  run.variant = ex.simulation().cases[r].variant;
  run.summary = solve::solve_load_steps(ex.simulation().cases[r].model,
                                        ex.simulation().cases[r].stepping, observer);
  if (run.summary.system && checks_system_matrix(ex))
    run.system_matrix = run.summary.system->dense_matrix();
  return run;
}

void report_variants(const Experiment& ex, size_t finished) {
  if (ex.simulation().cases.size() > 1)
    report_progress("variants", static_cast<double>(finished),
                    static_cast<double>(ex.simulation().cases.size()));
}

// The cases in this process, `options.jobs` at a time.
void run_local_cases(const Experiment& ex, const RunObserver& observer, const RunOptions& options,
                     ExperimentResult& result) {
  std::atomic<size_t> finished{0};
  report_variants(ex, 0);
  for_each_case(ex.simulation().cases.size(), effective_jobs(options, ex.simulation().cases.size()),
                [&](size_t r) {
                  solve::StepObserver step_observer;
                  if (observer)
                    step_observer = [&observer, r](const solve::StepRecord& record,
                                                   const Eigen::VectorXd& x) {
                      observer(r, record, x);
                    };
                  result.runs[r] = run_case(ex, r, step_observer);
                  report_variants(ex, ++finished);
                });
}

// Case r wherever it is dealt, packed with its unknowns after each step. A
// failure that is not the solver's (an exception) becomes the run's message,
// so the rank goes on with the next case.
std::string run_case_packed(const Experiment& ex, size_t r) {
  RunOutcome outcome;
  try {
    outcome.run = run_case(ex, r, [&](const solve::StepRecord&, const Eigen::VectorXd& x) {
      outcome.step_unknowns.push_back(x);
    });
  } catch (const std::exception& e) {
    outcome = RunOutcome{};
    outcome.run.variant = ex.simulation().cases[r].variant;
    outcome.run.summary.message = e.what();
  }
  return pack_run_outcome(outcome);
}

// The cases dealt out (over MPI ranks); each outcome replayed into the
// observer where it arrives, as if it had run here.
void run_dealt_cases(const Experiment& ex, const RunObserver& observer, const WorkDealer& dealer,
                     ExperimentResult& result) {
  std::atomic<size_t> finished{0};
  report_variants(ex, 0);
  dealer(
      ex.simulation().cases.size(), [&ex](size_t r) { return run_case_packed(ex, r); },
      [&](size_t r, int rank, std::string&& bytes) {
        RunOutcome outcome = unpack_run_outcome(bytes);
        const std::vector<solve::StepRecord>& steps = outcome.run.summary.steps;
        if (outcome.step_unknowns.size() != steps.size())
          throw std::runtime_error("rank " + std::to_string(rank) + " sent " +
                                   std::to_string(outcome.step_unknowns.size()) + " states for " +
                                   std::to_string(steps.size()) + " steps");
        if (observer)
          for (size_t k = 0; k < steps.size(); ++k) observer(r, steps[k], outcome.step_unknowns[k]);
        outcome.run.rank = rank;
        result.runs[r] = std::move(outcome.run);
        report_variants(ex, ++finished);
      });
}

// The FEM reference after the fiber runs. A FEM that fails keeps the runs:
// the folder becomes DIR.failed with the reason (exit 2), never bad input.
void add_fem_reference(const Experiment& ex, ExperimentResult& result) {
  report_progress("FEM reference", 0.0, 1.0);
  std::shared_ptr<FemReferenceResult> reference;
  try {
    reference = std::make_shared<FemReferenceResult>(solve_fem_reference(
        ex.simulation().cases.front(), result.runs.front(), *ex.fem_reference()));
  } catch (const bridge::FemSolveFailure& e) {
    result.failure = std::string("fem_reference: ") + e.what();
    return;
  }
  report_progress("FEM reference", 1.0, 1.0);
  for (const auto& [name, value] : reference->figures) {
    if (!std::isfinite(value)) {
      result.failure = "fem_reference: its figure " + name + " is not finite";
      return;
    }
    result.figures[name] = value;
  }
  result.fem_reference = reference;
}

}  // namespace

void serve_cases(const Experiment& ex, const WorkDealer& dealer) {
  require_built(ex);
  if (ex.kind() != Experiment::Kind::Simulate) return;  // rank 0 says why, or runs it alone
  dealer(
      ex.simulation().cases.size(), [&ex](size_t r) { return run_case_packed(ex, r); },
      [](size_t, int, std::string&&) {});
}

ExperimentResult run_experiment(const Experiment& ex, const RunObserver& observer,
                                const RunOptions& options) {
  require_built(ex);
  if (ex.kind() == Experiment::Kind::Calibration)
    throw InputError(ex.source.string() +
                     ": a calibration over specimens runs with `fiberfluid "
                     "fit` (its specimens run with `fiberfluid run`)");
  ExperimentResult result;
  if (ex.kind() == Experiment::Kind::Areas) {
    add_area_figures(ex, result);
  } else if (ex.kind() == Experiment::Kind::Benchmark) {
    auto benchmark =
        std::make_shared<BenchmarkResult>(run_benchmark(ex.benchmark(), [](int done, int total) {
          report_progress("benchmark runs", done, total);
        }));
    result.figures = benchmark->figures;
    if (!benchmark->ok) result.failure = benchmark->message;
    result.benchmark = benchmark;
  } else {
    result.runs.resize(ex.simulation().cases.size());
    if (options.dealer)
      run_dealt_cases(ex, observer, options.dealer, result);
    else
      run_local_cases(ex, observer, options, result);
    if (ex.fem_reference() && !ex.simulation().cases.empty()) {
      add_fem_reference(ex, result);
    }
    const FiberReport& fibers = ex.simulation().cases.front().fibers;
    result.figures["fibers.in_all"] = static_cast<double>(fibers.pairs);
    result.figures["fibers.kept"] = static_cast<double>(fibers.kept);
    result.figures["fibers.pruned"] = static_cast<double>(fibers.pairs - fibers.kept);
    for (size_t r = 0; r < ex.simulation().cases.size(); ++r) {
      const RunResult& run = result.runs[r];
      const std::string prefix = run.variant.empty() ? "" : run.variant + ".";
      if (run.summary.success)
        for (const std::string& name : run_figure_names(ex.simulation().cases[r].model))
          if (const std::optional<double> value = run_figure(ex.simulation().cases[r], run, name))
            result.figures[prefix + name] = *value;
    }
  }
  result.checks = check_expected(ex, result);
  return result;
}

std::vector<FigureCheck> check_expected(const Experiment& ex, const ExperimentResult& result) {
  std::vector<FigureCheck> checks;
  for (const ExpectedFigure& expected : ex.expected)
    checks.push_back(check_figure(ex, result, expected));
  return checks;
}

}  // namespace fiberfluid::experiment
