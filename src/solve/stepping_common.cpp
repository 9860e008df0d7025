// SPDX-License-Identifier: GPL-3.0-or-later
// What both schemes share: the checks before a run and after every step,
// the options' validation, and the summary's report.
#include "fiberfluid/solve/stepping_common.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/geom/folds.hpp"
#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/solve/linear_solver.hpp"

namespace fiberfluid::solve {

// Whether the state reached after a step is a result, not a runaway (why not).
Status check_no_runaway(const model::Model& model, const SteppingOptions& options,
                        const Eigen::VectorXd& unknowns, const Eigen::MatrixXd& X, double volume,
                        double reference_volume, Eigen::MatrixXd& last_face_areas) {
  if (!unknowns.allFinite())
    return Status::failure("the solution (displacements or pressure) is not finite");
  if (options.stop_on_inverted_faces) {
    // Against the last accepted step, not the reference: only a fold since
    // then stops the run, not a body that rotated far (find_fold).
    geom::Surface now = model.surface;
    now.V = X;
    if (const auto fold = geom::find_fold(now, last_face_areas)) {
      const std::string face = "face " + std::to_string(fold->face) + " turned over ";
      if (!fold->crossing)
        return Status::failure(
            face +
            "(its normal reversed against its neighbours'): the load is too large for "
            "the material");
      return Status::failure(face + "and the surface passes through itself (faces " +
                             std::to_string(fold->crossing->first) + " and " +
                             std::to_string(fold->crossing->second) +
                             " cross): the load is too large for the material");
    }
    last_face_areas = geom::face_area_vectors(X, model.surface.F);
  }
  const double change = (volume - reference_volume) / reference_volume;
  if (!std::isfinite(change) || std::abs(change) > options.max_volume_change) {
    std::ostringstream out;
    out << "the enclosed volume changed by " << 100.0 * change << "% (limit "
        << 100.0 * options.max_volume_change
        << "%, stepping.max_volume_change): the load is too large for the material";
    return Status::failure(out.str());
  }
  return {};
}

Status check_treecode(const model::Model& model, const SteppingOptions& options) {
  if (!(model.treecode_tolerance > 0.0)) return {};
  const std::string what = "the treecode product (treecode_tolerance) ";
  if (!(model.treecode_tolerance >= 1e-10 && model.treecode_tolerance <= 1e-2))
    return Status::failure(what + "takes a relative error from 1e-10 to 1e-2, got " +
                           std::to_string(model.treecode_tolerance));
  if (options.scheme != Scheme::Incremental)
    return Status::failure(
        what +
        "approximates the incremental scheme's linear product; Newton's tangent is "
        "exact (the incremental scheme)");
  if (!model.material.law.is_constant())
    return Status::failure(what + "needs a linear material (a constant law)");
  if (options.solver != SolverKind::Auto && options.solver != SolverKind::PCG)
    return Status::failure(what + "is matrix-free: it goes with the pcg solver, not " +
                           std::string(to_string(options.solver)));
  return {};
}

Status check_kinematics(const model::Model& model, const SteppingOptions& options) {
  const model::FiberKinematics k = model.material.kinematics;
  if (k == model::FiberKinematics::VectorSpring || options.scheme == Scheme::Newton) return {};
  return Status::failure(
      std::string("the ") + model::kinematics_name(k) +
      " fiber kinematics needs the Newton scheme (stepping.scheme \"newton\"): the "
      "incremental scheme's matrix is the paper's vector spring");
}

Status check_fiber_weights(const model::Model& model, const SteppingOptions& options) {
  if (model.material.law.rest_tension() != 0.0) {
    const std::string what =
        "the " + model.material.law.name() + " law's fibers carry a tension at rest: it ";
    if (model.material.kinematics != model::FiberKinematics::Central)
      return Status::failure(what + "acts along the fibers (fibers.kinematics \"central\")");
    if (options.scheme != Scheme::Newton)
      return Status::failure(what + "needs the Newton scheme (stepping.scheme \"newton\")");
    if (model.fiber_weights != model::FiberWeights::Lines)
      return Status::failure(what +
                             "needs fibers.weights \"lines\": only the line measure puts the "
                             "tensions' sum at each vertex where the fluid's pressure balances it");
    if (!model.held_edges.empty())
      return Status::failure(what + "has no split edge yet (leave out supports[].edge)");
    if (model.material.axis_factors != Eigen::Vector3d::Ones())
      return Status::failure(what + "is isotropic: it takes no axis factors");
  }
  if (model.fiber_weights != model::FiberWeights::Lines) return {};
  const std::string what = "the line measure (fibers.weights \"lines\") ";
  if (model.dim() != 3)
    return Status::failure(what + "weighs fibers through a 3D body: a " +
                           std::to_string(model.dim()) + "D surface has no such weights");
  if (model.treecode_tolerance > 0.0)
    return Status::failure(what + "varies from pair to pair: the treecode needs one count");
  if (!model.mirror_layers.empty())
    return Status::failure(what +
                           "has no mirror layer yet: its images' area vectors are not "
                           "weighed (hold the clamp without \"layer\")");
  if (options.scheme != Scheme::Newton && options.rebuild_matrix)
    return Status::failure(what +
                           "weighs the fibers at the reference: a matrix rebuilt from "
                           "the deformed geometry has no measure (use the Newton scheme)");
  return {};
}

Status check_support_terms(const model::Model& model, const SteppingOptions& options) {
  if (options.scheme == Scheme::Newton) return {};
  if (!model.mirror_layers.empty())
    return Status::failure(
        "a support's mirror layer needs the Newton scheme (stepping.scheme \"newton\"): the "
        "incremental scheme's matrix has no layer fibers");
  if (!model.held_edges.empty())
    return Status::failure(
        "a support's split edge needs the Newton scheme (stepping.scheme \"newton\"): the "
        "incremental scheme's matrix has no edge fibers");
  return {};
}

SolverKind automatic_solver(const model::Model& model, double largest_block, int factors,
                            double budget_bytes) {
  if (model.treecode_tolerance > 0.0) return SolverKind::PCG;  // the only matrix-free backend
  if (model.fibers && model.fibers->sparse() && largest_block > 600)
    return SolverKind::Cholmod;  // a horizon's sparse blocks (choose_solver's rule)
  return choose_solver(largest_block, factors, budget_bytes);
}

Status check_setup(const model::Model& model, const SteppingOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) return Status::failure(why);
  // In order, each only once the ones before it passed (a later check may
  // rely on what an earlier one refused).
  Status status = check_treecode(model, options);
  if (status.ok) status = check_kinematics(model, options);
  if (status.ok) status = check_support_terms(model, options);
  if (status.ok) status = check_fiber_weights(model, options);
  if (status.ok) status = model::check_not_singular(model);
  return status;
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
      return *why =
                 "sensitivities need the Newton scheme (the incremental one has no tangent "
                 "at equilibrium)",
             false;
    for (int k : sensitivities.steps)
      if (k < 1 || k > steps)
        return *why = "sensitivities at step " + std::to_string(k) + ": expected 1.." +
                      std::to_string(steps),
               false;
  }
  return scheme != Scheme::Newton || newton.IsValid(why);
}

bool NewtonOptions::IsValid(std::string* why) const {
  if (!(residual_tolerance > 0.0) || !(increment_tolerance > 0.0) || !(krylov_tolerance > 0.0) ||
      !(friction_tolerance > 0.0))
    return *why = "newton tolerances must be positive", false;
  if (max_iterations < 1 || max_step_cuts < 0 || krylov_restart < 1 || krylov_max_iterations < 1 ||
      max_contact_rounds < 1)
    return *why = "newton iteration limits must be at least 1 (max_step_cuts at least 0)", false;
  return true;
}

std::string SteppingSummary::BriefReport() const {
  std::ostringstream out;
  out << (success ? "success" : "failure") << ": ";
  if (scheme == Scheme::Newton) {
    out << "newton (" << to_string(tangent);
    if (tangent == TangentSolver::Krylov) out << ", preconditioner " << to_string(solver);
    out << "), " << steps.size() << " steps, " << newton_iterations << " newton iterations";
    if (!tangent_fallback.empty()) out << " (" << tangent_fallback << ")";
    if (tangent == TangentSolver::Krylov || tangent == TangentSolver::Reused)
      out << ", " << krylov_iterations << " gmres iterations, " << factorizations
          << (tangent == TangentSolver::Reused ? " tangent LU" : " preconditioner")
          << " factorizations";
    if (single_precision_factorizations > 0)
      out << " (" << single_precision_factorizations << " rounded to single precision)";
    if (tangent == TangentSolver::Sparse)
      out << ", " << factorizations << " sparse LU factorizations";
  } else {
    out << to_string(solver) << ", " << steps.size() << " steps, " << factorizations
        << " factorizations";
  }
  if (solver == SolverKind::PCG) out << ", " << solver_statistics.iterations << " pcg iterations";
  out << ", " << total_seconds << " s";
  if (!success) out << ": " << message;
  return out.str();
}

}  // namespace fiberfluid::solve
