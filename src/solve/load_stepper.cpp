// SPDX-License-Identifier: GPL-3.0-or-later
#include "solve/load_stepper.hpp"

#include <algorithm>
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
#include "geom/progress.hpp"

namespace fiberfluid::solve {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The vertices with at least one constrained axis, ascending.
std::vector<int> constrained_vertices(const model::Model& model) {
  std::vector<char> held(static_cast<size_t>(model.num_vertices()), 0);
  for (const model::Constraint& c : model.constraints) held[static_cast<size_t>(c.vertex)] = 1;
  std::vector<int> vertices;
  for (int i = 0; i < model.num_vertices(); ++i)
    if (held[static_cast<size_t>(i)]) vertices.push_back(i);
  return vertices;
}

// Why the state reached after a step is a runaway rather than a result, or "".
std::string runaway_reason(const model::Model& model, const SteppingOptions& options,
                           const Eigen::MatrixXd& X, double volume, double reference_volume,
                           const Eigen::MatrixXd& reference_face_areas) {
  if (!X.allFinite()) return "the displacements are not finite";
  if (options.stop_on_inverted_faces) {
    const Eigen::MatrixXd now = geom::face_area_vectors(X, model.surface.F);
    for (Eigen::Index f = 0; f < now.rows(); ++f)
      if (now.row(f).dot(reference_face_areas.row(f)) <= 0.0)
        return "face " + std::to_string(f) +
               " turned over (its normal reversed): the load is too large for the material";
  }
  const double change = (volume - reference_volume) / reference_volume;
  if (!std::isfinite(change) || std::abs(change) > options.max_volume_change) {
    std::ostringstream out;
    out << "the enclosed volume changed by " << 100.0 * change << "% (limit "
        << 100.0 * options.max_volume_change
        << "%, stepping.max_volume_change): the load is too large for the material";
    return out.str();
  }
  return {};
}

}  // namespace

bool SteppingOptions::IsValid(std::string* why) const {
  if (steps < 1) return *why = "steps must be at least 1", false;
  if (!(penalty > 0.0) || !std::isfinite(penalty))
    return *why = "penalty must be a positive number", false;
  if (!(pcg.tolerance > 0.0) || pcg.max_iterations < 1)
    return *why = "pcg tolerance must be positive and max_iterations at least 1", false;
  if (!(max_volume_change > 0.0)) return *why = "max_volume_change must be positive", false;
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
  const double reference_volume = geom::enclosed_volume(reference, model.surface.F);
  const Eigen::MatrixXd reference_face_areas = geom::face_area_vectors(reference, model.surface.F);
  const std::vector<int> held = constrained_vertices(model);
  const size_t groups = std::max<size_t>(1, model.constraint_groups.size());
  const int dim = model.dim(), nv = model.num_vertices();
  summary.reaction_forces = Eigen::MatrixXd::Zero(nv, dim);
  Eigen::Vector3d applied = Eigen::Vector3d::Zero();
  Eigen::MatrixXd reaction_before = summary.reaction_forces;
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
      report_progress("factorize", 0.0, 1.0);
      const Status status = solver->factorize(*system);
      report_progress("factorize", 1.0, 1.0);
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
    const Eigen::VectorXd dx = system->expand(increment_reduced, dU_c);
    summary.unknowns += dx;
    const Eigen::MatrixXd X_now = model::positions(model, summary.unknowns);
    const double volume = geom::enclosed_volume(X_now, model.surface.F);
    why = runaway_reason(model, options, X_now, volume, reference_volume, reference_face_areas);
    if (!why.empty()) return fail("step " + std::to_string(k) + ": runaway: " + why);

    // Reactions: the unreduced rows of this step's A times the increment,
    // less the load increment, accumulated at the constrained unknowns.
    const Eigen::MatrixXd forces = system->unreduced_rows(
        held, model::displacements(model, dx), dx[model.pressure_dof()]);
    for (const model::Constraint& c : model.constraints) {
      const auto r = std::lower_bound(held.begin(), held.end(), c.vertex) - held.begin();
      summary.reaction_forces(c.vertex, c.axis) =
          reaction_before(c.vertex, c.axis) + forces(r, c.axis) - dB[model.dof(c.vertex, c.axis)];
    }
    reaction_before = summary.reaction_forces;
    for (int a = 0; a < dim; ++a) applied[a] += dB.segment(a * nv, nv).sum();

    StepRecord record;
    record.step = k;
    record.load_factors = now;
    record.pressure = summary.unknowns[model.pressure_dof()];
    record.volume = volume;
    record.applied_force = applied;
    record.reactions.assign(groups, Eigen::Vector3d::Zero());
    std::vector<char> counted(static_cast<size_t>(dim * nv), 0);  // a unknown held twice counts once
    for (const model::Constraint& c : model.constraints) {
      char& seen = counted[static_cast<size_t>(model.dof(c.vertex, c.axis))];
      if (seen) continue;
      seen = 1;
      record.reactions[static_cast<size_t>(c.group) % groups][c.axis] +=
          summary.reaction_forces(c.vertex, c.axis);
    }
    record.max_displacement =
        model::displacements(model, summary.unknowns).rowwise().norm().maxCoeff();
    record.seconds = seconds_since(step_start);
    summary.steps.push_back(record);
    report_progress("step", k, n);
    if (observer) observer(record, summary.unknowns);
  }
  summary.success = true;
  summary.total_seconds = seconds_since(start);
  return summary;
}

}  // namespace fiberfluid::solve
