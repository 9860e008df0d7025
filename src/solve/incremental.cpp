// SPDX-License-Identifier: GPL-3.0-or-later
// The paper's incremental scheme (model.md section 6): A(x_{k-1}) dx_k =
// B(x_{k-1}, f_k) - B(x_{k-1}, f_{k-1}), a forward-Euler walk along the load path.
#include "fiberfluid/solve/stepping.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <sstream>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/equilibrium.hpp"
#include "fiberfluid/model/fiber_system.hpp"
#include "fiberfluid/model/loads.hpp"
#include "fiberfluid/solve/stepping_common.hpp"
#include "fiberfluid/util/error.hpp"
#include "fiberfluid/util/progress.hpp"
#include "fiberfluid/util/run_control.hpp"

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
  model::DofPartition partition_;   // each held unknown once, with its constraint
  std::vector<int> held_vertices_;  // ascending
  Eigen::MatrixXd per_vertex_;
};

}  // namespace

SteppingSummary solve_incremental_steps(const model::Model& model, const SteppingOptions& options,
                                        const StepObserver& observer) {
  const Clock::time_point start = Clock::now();
  SteppingSummary summary = empty_summary(model, Scheme::Incremental);
  auto fail = [&](const std::string& why) { return failed(summary, why, start); };
  if (const Status setup = check_setup(model, options); !setup.ok) return fail(setup.message);
  if (!model.paddles.empty())
    return fail(
        "paddles need the Newton scheme (stepping.scheme \"newton\"): contact is an "
        "active set inside its equilibrium iterations");

  const int n = options.steps;
  const Eigen::MatrixXd& reference = model.surface.V;
  const double reference_volume = geom::enclosed_volume(reference, model.surface.F);
  Eigen::MatrixXd last_face_areas = geom::face_area_vectors(reference, model.surface.F);
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
    if (const Status state = check_no_runaway(model, options, summary.unknowns, X_now, volume,
                                              reference_volume, last_face_areas);
        !state.ok)
      return fail("step " + std::to_string(k) + ": runaway: " + state.message);

    reactions->add_step(*system, dx, dB);
    for (int a = 0; a < model.dim(); ++a) applied[a] += dB.segment(a * nv, nv).sum();

    StepRecord record;
    record.step = k;
    record.load_factors = now;
    record.pressure = summary.unknowns[model.pressure_dof()];
    record.volume = volume;
    record.applied_force = applied;
    record.reactions = reactions->per_group();
    const Eigen::MatrixXd per_vertex = reactions->per_vertex();
    std::vector<char> held(static_cast<size_t>(nv), 0);
    for (const model::Constraint& c : model.constraints) held[static_cast<size_t>(c.vertex)] = 1;
    for (int v = 0; v < nv; ++v)
      if (held[static_cast<size_t>(v)]) {
        StepRecord::HeldForce force;
        force.vertex = v;
        force.force.head(model.dim()) = per_vertex.row(v).transpose();
        record.held_forces.push_back(force);
      }
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
