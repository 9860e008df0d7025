// SPDX-License-Identifier: GPL-3.0-or-later
#include "solve/load_stepper.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <sstream>

#include "geom/area_vectors.hpp"
#include "geom/error.hpp"
#include "geom/progress.hpp"
#include "geom/run_control.hpp"
#include "model/assembly.hpp"
#include "model/equilibrium.hpp"
#include "model/fiber_system.hpp"
#include "model/loads.hpp"
#include "solve/stepping_common.hpp"

namespace fiberfluid::solve {
namespace {

// The force each support exerts on the body: at every held unknown, the
// unreduced row of the step's A times the step's increment, less the load
// increment there, summed over the steps (the incremental scheme's own
// equilibrium, whatever A and the loads were built from).
class Reactions {
 public:
  // Throws InputError when one unknown is held at two different values.
  explicit Reactions(const model::Model& model)
      : model_(model),
        partition_(model::partition_dofs(model)),
        per_vertex_(Eigen::MatrixXd::Zero(model.num_vertices(), model.dim())) {
    const int n = model.num_vertices();
    for (int d : partition_.constrained) held_vertices_.push_back(d % n);
    std::sort(held_vertices_.begin(), held_vertices_.end());
    held_vertices_.erase(std::unique(held_vertices_.begin(), held_vertices_.end()),
                         held_vertices_.end());
  }

  void add_step(const model::FiberSystem& system, const Eigen::VectorXd& dx,
                const Eigen::VectorXd& dB) {
    const Eigen::MatrixXd rows = system.unreduced_rows(
        held_vertices_, model::displacements(model_, dx), dx[model_.pressure_dof()]);
    const int n = model_.num_vertices();
    for (int d : partition_.constrained) {
      const int vertex = d % n, axis = d / n;
      const auto row = std::lower_bound(held_vertices_.begin(), held_vertices_.end(), vertex) -
                       held_vertices_.begin();
      per_vertex_(vertex, axis) += rows(row, axis) - dB[d];
    }
  }

  // #V by dim: zero where nothing is held.
  const Eigen::MatrixXd& per_vertex() const { return per_vertex_; }

  // The sum over each group of Model::constraint_groups (one group when none is named).
  std::vector<Eigen::Vector3d> per_group() const {
    std::vector<Eigen::Vector3d> sums(std::max<size_t>(1, model_.constraint_groups.size()),
                                      Eigen::Vector3d::Zero());
    const int n = model_.num_vertices();
    for (size_t k = 0; k < partition_.constrained.size(); ++k) {
      const int d = partition_.constrained[k];
      const model::Constraint& c =
          model_.constraints[static_cast<size_t>(partition_.constraint_of[k])];
      sums[static_cast<size_t>(c.group) % sums.size()][d / n] += per_vertex_(d % n, d / n);
    }
    return sums;
  }

 private:
  const model::Model& model_;
  model::DofPartition partition_;    // each held unknown once, with its constraint
  std::vector<int> held_vertices_;   // ascending
  Eigen::MatrixXd per_vertex_;
};

}  // namespace

// Why the state reached after a step is a runaway rather than a result, or "".
std::string runaway_reason(const model::Model& model, const SteppingOptions& options,
                           const Eigen::VectorXd& unknowns, const Eigen::MatrixXd& X,
                           double volume, double reference_volume,
                           const Eigen::MatrixXd& reference_face_areas) {
  if (!unknowns.allFinite()) return "the solution (displacements or pressure) is not finite";
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


std::string treecode_problem(const model::Model& model, const SteppingOptions& options) {
  if (!(model.treecode_tolerance > 0.0)) return {};
  const std::string what = "the treecode product (treecode_tolerance) ";
  if (!(model.treecode_tolerance >= 1e-10 && model.treecode_tolerance <= 1e-2))
    return what + "takes a relative error from 1e-10 to 1e-2, got " +
           std::to_string(model.treecode_tolerance);
  if (options.scheme != Scheme::Incremental)
    return what + "approximates the incremental scheme's linear product; Newton's tangent is "
                  "exact (the incremental scheme)";
  if (!model.material.law.is_constant())
    return what + "needs a linear material (a constant law)";
  if (options.solver != SolverKind::Auto && options.solver != SolverKind::PCG)
    return what + "is matrix-free: it goes with the pcg solver, not " +
           std::string(to_string(options.solver));
  return {};
}

SolverKind automatic_solver(const model::Model& model, double largest_block, int factors,
                            double budget_bytes) {
  if (model.treecode_tolerance > 0.0) return SolverKind::PCG;  // the only matrix-free backend
  return choose_solver(largest_block, factors, budget_bytes);
}

std::string setup_problem(const model::Model& model, const SteppingOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) return why;
  why = treecode_problem(model, options);
  if (!why.empty()) return why;
  return model::singular_setup_reason(model);
}

bool SteppingOptions::IsValid(std::string* why) const {
  if (steps < 1) return *why = "steps must be at least 1", false;
  if (!(penalty > 0.0) || !std::isfinite(penalty))
    return *why = "penalty must be a positive number", false;
  if (!(pcg.tolerance > 0.0) || pcg.max_iterations < 1)
    return *why = "pcg tolerance must be positive and max_iterations at least 1", false;
  if (!(max_volume_change > 0.0)) return *why = "max_volume_change must be positive", false;
  if (!sensitivities.parameters.empty()) {
    if (scheme != Scheme::Newton)
      return *why = "sensitivities need the Newton scheme (the incremental one has no tangent "
                    "at equilibrium)", false;
    for (int k : sensitivities.steps)
      if (k < 1 || k > steps)
        return *why = "sensitivities at step " + std::to_string(k) + ": expected 1.." +
                      std::to_string(steps), false;
  }
  return scheme != Scheme::Newton || newton.IsValid(why);
}

bool NewtonOptions::IsValid(std::string* why) const {
  if (!(residual_tolerance > 0.0) || !(increment_tolerance > 0.0) || !(krylov_tolerance > 0.0))
    return *why = "newton tolerances must be positive", false;
  if (max_iterations < 1 || max_step_cuts < 0 || krylov_restart < 1 ||
      krylov_max_iterations < 1 || max_contact_rounds < 1)
    return *why = "newton iteration limits must be at least 1 (max_step_cuts at least 0)", false;
  return true;
}

const char* to_string(Scheme scheme) {
  return scheme == Scheme::Newton ? "newton" : "incremental";
}

const char* to_string(TangentSolver solver) {
  switch (solver) {
    case TangentSolver::Auto: return "auto";
    case TangentSolver::Dense: return "dense";
    case TangentSolver::Krylov: return "krylov";
  }
  return "?";
}

TangentSolver choose_tangent(TangentSolver requested, int reduced_unknowns) {
  if (requested != TangentSolver::Auto) return requested;
  return reduced_unknowns <= 600 ? TangentSolver::Dense : TangentSolver::Krylov;
}

std::string SteppingSummary::BriefReport() const {
  std::ostringstream out;
  out << (success ? "success" : "failure") << ": ";
  if (scheme == Scheme::Newton) {
    out << "newton (" << to_string(tangent);
    if (tangent == TangentSolver::Krylov) out << ", preconditioner " << to_string(solver);
    out << "), " << steps.size() << " steps, " << newton_iterations << " newton iterations";
    if (tangent == TangentSolver::Krylov)
      out << ", " << krylov_iterations << " gmres iterations, " << factorizations
          << " preconditioner factorizations";
  } else {
    out << to_string(solver) << ", " << steps.size() << " steps, " << factorizations
        << " factorizations";
  }
  if (solver == SolverKind::PCG) out << ", " << solver_statistics.iterations << " pcg iterations";
  out << ", " << total_seconds << " s";
  if (!success) out << ": " << message;
  return out.str();
}

SteppingSummary solve_load_steps(const model::Model& model, const SteppingOptions& options,
                                 const StepObserver& observer) {
  if (options.scheme == Scheme::Newton) return solve_newton_steps(model, options, observer);
  const Clock::time_point start = Clock::now();
  SteppingSummary summary = empty_summary(model, Scheme::Incremental);
  auto fail = [&](const std::string& why) { return failed(summary, why, start); };
  std::string why = setup_problem(model, options);
  if (!why.empty()) return fail(why);
  if (!model.paddles.empty())
    return fail("paddles need the Newton scheme (stepping.scheme \"newton\"): contact is an "
                "active set inside its equilibrium iterations");

  const int n = options.steps;
  const Eigen::MatrixXd& reference = model.surface.V;
  const double reference_volume = geom::enclosed_volume(reference, model.surface.F);
  const Eigen::MatrixXd reference_face_areas = geom::face_area_vectors(reference, model.surface.F);
  std::optional<Reactions> reactions;
  std::optional<model::Equilibrium> problem;
  try {
    reactions.emplace(model);  // throws when one unknown is held at two values
    problem.emplace(model);    // or when two vertices coincide
  } catch (const InputError& e) {
    return fail(e.what());
  }
  const model::DofMap dofs = model::DofMap::from_constraints(model);
  const int nv = model.num_vertices();
  Eigen::Vector3d applied = Eigen::Vector3d::Zero();  // the loads so far, summed over vertices
  ResidualGauge residual_gauge;
  std::shared_ptr<const model::FiberSystem> system;  // outlives its factorisation
  std::shared_ptr<LinearSolver> solver;

  report_progress("step", 0, n);
  for (int k = 1; k <= n; ++k) {
    if (cancel_requested()) return fail("step " + std::to_string(k) + ": interrupted");
    const Clock::time_point step_start = Clock::now();
    const Eigen::MatrixXd X = model::positions(model, summary.unknowns);

    if (k == 1 || options.rebuild_matrix) {
      Clock::time_point t = Clock::now();
      try {
        // Rebuilt: lengths, area vectors and (for a strain-dependent law) the
        // secant moduli from x_{k-1}, the paper's words (model.md section 7).
        system = problem->linear_system(options.rebuild_matrix ? X : reference, dofs,
                                        options.boundary_method, options.penalty,
                                        options.rebuild_matrix);
      } catch (const InputError& e) {  // e.g. two vertices pressed onto each other
        return fail("step " + std::to_string(k) + ": " + e.what());
      }
      summary.assemble_seconds += seconds_since(t);
      if (!solver) {
        summary.solver = options.solver == SolverKind::Auto
                             ? automatic_solver(model, system->largest_block(),
                                                system->blocks_equal() ? 1 : system->num_blocks(),
                                                memory_budget_bytes())
                             : options.solver;
        solver = make_linear_solver(summary.solver, options.pcg);
        const Status status = solver->analyze_pattern(*system);
        if (!status.ok) return fail(status.message);
      }
      t = Clock::now();
      report_progress("factorize", 0.0, 0.0);  // one call: elapsed time only
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
        problem->load_vector(options.update_load_geometry ? X : reference, increment);
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
    why = runaway_reason(model, options, summary.unknowns, X_now, volume, reference_volume,
                         reference_face_areas);
    if (!why.empty()) return fail("step " + std::to_string(k) + ": runaway: " + why);

    reactions->add_step(*system, dx, dB);
    for (int a = 0; a < model.dim(); ++a) applied[a] += dB.segment(a * nv, nv).sum();

    StepRecord record;
    record.step = k;
    record.load_factors = now;
    record.pressure = summary.unknowns[model.pressure_dof()];
    record.volume = volume;
    record.applied_force = applied;
    record.reactions = reactions->per_group();
    record.max_displacement = (X_now - reference).rowwise().norm().maxCoeff();
    if (options.measure_residual)
      record.residual = residual_gauge.measure(*problem, dofs, summary.unknowns, now);
    record.seconds = seconds_since(step_start);
    summary.steps.push_back(record);
    report_progress("step", k, n);
    if (observer) observer(record, summary.unknowns);
  }
  summary.reaction_forces = reactions->per_vertex();
  summary.system = system;
  summary.factorization = solver;
  summary.success = true;
  summary.total_seconds = seconds_since(start);
  return summary;
}

}  // namespace fiberfluid::solve
