// SPDX-License-Identifier: GPL-3.0-or-later
#include "solve/load_stepper.hpp"

#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <sstream>

#include "geom/area_vectors.hpp"
#include "model/assembly.hpp"
#include "model/loads.hpp"
#include "geom/error.hpp"
#include "model/fiber_system.hpp"

namespace fiberfluid::solve {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

bool SteppingOptions::IsValid(std::string* why) const {
  if (steps < 1) return *why = "steps must be at least 1", false;
  if (!(penalty > 0.0) || !std::isfinite(penalty))
    return *why = "penalty must be a positive number", false;
  if (!(pcg.tolerance > 0.0) || pcg.max_iterations < 1)
    return *why = "pcg tolerance must be positive and max_iterations at least 1", false;
  return true;
}

std::string SteppingSummary::BriefReport() const {
  std::ostringstream out;
  out << (success ? "success" : "failure") << ": " << to_string(solver) << ", " << steps.size()
      << " steps, " << factorizations << " factorizations";
  if (solver == SolverKind::PCG) out << ", " << solver_statistics.iterations << " pcg iterations";
  out << ", " << total_seconds << " s";
  if (!success) out << ": " << message;
  return out.str();
}

SteppingSummary solve_load_steps(const model::Model& model, const SteppingOptions& options,
                                 const StepObserver& observer) {
  const Clock::time_point start = Clock::now();
  SteppingSummary summary;
  summary.unknowns = Eigen::VectorXd::Zero(model.num_unknowns());
  auto fail = [&](const std::string& why) {
    summary.message = why;
    summary.total_seconds = seconds_since(start);
    return summary;
  };
  std::string why;
  if (!options.IsValid(&why)) return fail(why);
  why = model::singular_setup_reason(model);
  if (!why.empty()) return fail(why);

  const int n = options.steps;
  const Eigen::MatrixXd& reference = model.surface.V;
  std::optional<model::FiberSystem> system;  // outlives its factorisation
  std::unique_ptr<LinearSolver> solver;

  for (int k = 1; k <= n; ++k) {
    const Clock::time_point step_start = Clock::now();
    const Eigen::MatrixXd X = model::positions(model, summary.unknowns);

    if (k == 1 || options.rebuild_matrix) {
      Clock::time_point t = Clock::now();
      try {
        system.emplace(model, options.rebuild_matrix ? X : reference, options.boundary_method,
                       options.penalty);
      } catch (const InputError& e) {  // e.g. two vertices pressed onto each other
        return fail("step " + std::to_string(k) + ": " + e.what());
      }
      summary.assemble_seconds += seconds_since(t);
      if (!solver) {
        summary.solver = options.solver == SolverKind::Auto ? choose_solver(*system)
                                                            : options.solver;
        solver = make_linear_solver(summary.solver, options.pcg);
        const Status status = solver->analyze_pattern(*system);
        if (!status.ok) return fail(status.message);
      }
      t = Clock::now();
      const Status status = solver->factorize(*system);
      summary.factorize_seconds += seconds_since(t);
      ++summary.factorizations;
      summary.solver_statistics = solver->statistics();
      if (!status.ok) return fail("step " + std::to_string(k) + ": " + status.message);
    }

    Clock::time_point t = Clock::now();
    const std::vector<double> now = model::load_factors(model, k, n);
    const std::vector<double> before = model::load_factors(model, k - 1, n);
    std::vector<double> increment(now.size());
    for (size_t l = 0; l < now.size(); ++l) increment[l] = now[l] - before[l];
    const Eigen::VectorXd dB =
        model::right_hand_side(model, options.update_load_geometry ? X : reference, increment);
    const Eigen::VectorXd dU_c = model::constrained_displacements(model, k, n) -
                                 model::constrained_displacements(model, k - 1, n);
    const Eigen::VectorXd rhs = system->reduce_rhs(dB.head(dB.size() - 1), dU_c);
    summary.assemble_seconds += seconds_since(t);

    t = Clock::now();
    Eigen::VectorXd increment_reduced;
    const Status status = solver->solve(rhs, &increment_reduced);
    summary.solve_seconds += seconds_since(t);
    summary.solver_statistics = solver->statistics();
    if (!status.ok) return fail("step " + std::to_string(k) + ": " + status.message);
    summary.unknowns += system->expand(increment_reduced, dU_c);
    if (!summary.unknowns.allFinite())
      return fail("step " + std::to_string(k) + ": the solution is not finite");

    StepRecord record;
    record.step = k;
    record.load_factors = now;
    record.pressure = summary.unknowns[model.pressure_dof()];
    record.volume = geom::enclosed_volume(model::positions(model, summary.unknowns),
                                          model.surface.F);
    record.max_displacement =
        model::displacements(model, summary.unknowns).rowwise().norm().maxCoeff();
    record.seconds = seconds_since(step_start);
    summary.steps.push_back(record);
    if (observer) observer(record, summary.unknowns);
  }
  summary.success = true;
  summary.total_seconds = seconds_since(start);
  return summary;
}

}  // namespace fiberfluid::solve
