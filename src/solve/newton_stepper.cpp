// SPDX-License-Identifier: GPL-3.0-or-later
// The Newton scheme (model.md section 7): equilibrium at every load step,
// with a line search, step cutting, and rigid paddles as an active set.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>

#include "geom/area_vectors.hpp"
#include "model/assembly.hpp"
#include "model/dof_map.hpp"
#include "model/equilibrium.hpp"
#include "model/fiber_system.hpp"
#include "model/loads.hpp"
#include "solve/load_stepper.hpp"
#include "solve/stepping_common.hpp"
#include "solve/tangent_solve.hpp"
#include "util/error.hpp"
#include "util/progress.hpp"
#include "util/run_control.hpp"

namespace fiberfluid::solve {
namespace {

using model::DofMap;
using model::Model;

// Loads, prescribed displacements and paddle planes at a point t of the load
// path: t = k after step k, linear in between (for the pieces of a cut step).
struct PathPoint {
  std::vector<double> factors;  // per load
  Eigen::VectorXd held_values;  // dim N: prescribed displacements, zero where free
  std::vector<double> planes;   // per paddle
};

PathPoint path_point(const Model& m, double t, int steps) {
  const int k0 = std::clamp(static_cast<int>(std::floor(t)), 0, steps);
  const int k1 = std::min(k0 + 1, steps);
  const double s = t - k0;
  PathPoint at;
  const std::vector<double> f0 = model::load_factors(m, k0, steps),
                            f1 = model::load_factors(m, k1, steps);
  for (size_t l = 0; l < f0.size(); ++l) at.factors.push_back(f0[l] + s * (f1[l] - f0[l]));
  const Eigen::VectorXd u0 = model::constrained_displacements(m, k0, steps),
                        u1 = model::constrained_displacements(m, k1, steps);
  at.held_values = u0 + s * (u1 - u0);
  for (const model::Paddle& p : m.paddles) {
    const double a = p.schedule.factor(k0, steps), b = p.schedule.factor(k1, steps);
    at.planes.push_back(p.plane(a + s * (b - a)));
  }
  return at;
}

class NewtonSolver {
 public:
  NewtonSolver(const Model& model, const SteppingOptions& options, SteppingSummary& summary)
      : model_(model),
        newton_(options.newton),
        summary_(summary),
        equilibrium_(std::make_shared<const model::Equilibrium>(model)),
        supports_(DofMap::from_constraints(model)),
        contact_paddle_(static_cast<size_t>(model.num_vertices()), -1),
        stuck_(Eigen::MatrixXd::Zero(model.num_vertices(), model.dim())) {
    const Eigen::MatrixXd& V = model.surface.V;
    diagonal_ = (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm();
    const TangentSolver kind =
        choose_tangent(newton_.tangent, supports_.num_reduced(), model.material.kinematics);
    tangent_ = std::make_shared<TangentSolve>(equilibrium_, options, kind);
    summary_.tangent = kind;
    summary_.solver = tangent_->preconditioner_kind();
  }

  const model::Equilibrium& equilibrium() const { return *equilibrium_; }
  // The tangent solve prepared at x (the solution), for the summary.
  std::shared_ptr<TangentSolve> final_tangent(const PathPoint& at, const Eigen::VectorXd& x) {
    if (!tangent_->prepare(x, at.factors, held_map(), &supports_).ok) return nullptr;
    return tangent_;
  }

  // Solves R = 0 at `at` from x (updated in place): Newton inside an
  // active-set loop for the paddles. "" or why it failed.
  std::string solve(const PathPoint& at, Eigen::VectorXd& x, StepRecord& record) {
    add_penetrating(at, x);
    for (int round = 0; round < newton_.max_contact_rounds; ++round) {
      const DofMap dofs = held_map();
      apply_held_values(at, dofs, x);
      bool converged = false;
      const std::string why = newton(at, dofs, x, record, &converged);
      if (!why.empty()) return why;
      const bool released = release_pulling();
      const bool added = add_penetrating(at, x);
      if (converged && !released && !added) return {};
    }
    return "the paddle contact did not settle in " + std::to_string(newton_.max_contact_rounds) +
           " active-set rounds (newton.max_contact_rounds)";
  }

  // du/dtheta = -K_T^{-1} dR/dtheta at the solution x, one tangent solve per
  // parameter, the held set (supports and contacts) fixed. "" or why not.
  std::string sensitivities(const PathPoint& at, const Eigen::VectorXd& x,
                            const std::vector<std::string>& names, Eigen::MatrixXd* out) {
    const std::shared_ptr<TangentSolve> tangent = final_tangent(at, x);
    if (!tangent) return "the tangent at the solution could not be factored";
    const Eigen::MatrixXd dR = equilibrium_->parameter_derivatives(x, names);
    out->resize(x.size(), dR.cols());
    for (Eigen::Index c = 0; c < dR.cols(); ++c) {
      Eigen::VectorXd du;
      const Status status = tangent->solve_full(-dR.col(c), &du);
      if (!status.ok) return names[static_cast<size_t>(c)] + ": " + status.message;
      out->col(c) = du;
    }
    return {};
  }

  // After a successful solve: the residual at the held unknowns is the force
  // each support or paddle exerts on the body.
  const Eigen::VectorXd& last_residual() const { return residual_; }
  const std::vector<int>& contact_paddle() const { return contact_paddle_; }
  // The supports' map with the contact unknowns held too.
  DofMap held_map() const {
    std::vector<int> contacts;
    const int n = model_.num_vertices();
    for (int v = 0; v < n; ++v) {
      const int p = contact_paddle_[static_cast<size_t>(v)];
      if (p < 0) continue;
      const model::Paddle& paddle = model_.paddles[static_cast<size_t>(p)];
      for (int a = 0; a < model_.dim(); ++a)
        if (a == paddle.axis || paddle.sticking) contacts.push_back(a * n + v);
    }
    return supports_.with_held(contacts);
  }
  // Snapshot and restore of the contact state, for a step that is cut.
  struct ContactState {
    std::vector<int> paddle;
    Eigen::MatrixXd stuck;
  };
  ContactState contact_state() const { return {contact_paddle_, stuck_}; }
  void restore(const ContactState& state) {
    contact_paddle_ = state.paddle;
    stuck_ = state.stuck;
  }

 private:
  // Held values: supports and prescribed values from the path, contact
  // vertices on their planes (and, sticking, where they first touched).
  void apply_held_values(const PathPoint& at, const DofMap& dofs, Eigen::VectorXd& x) const {
    const int n = model_.num_vertices();
    for (int d = 0; d < model_.dim() * n; ++d)
      if (supports_.held(d)) x[d] = at.held_values[d];
    for (int v = 0; v < n; ++v) {
      const int p = contact_paddle_[static_cast<size_t>(v)];
      if (p < 0) continue;
      const model::Paddle& paddle = model_.paddles[static_cast<size_t>(p)];
      for (int a = 0; a < model_.dim(); ++a) {
        const int d = a * n + v;
        if (supports_.held(d) || !dofs.held(d)) continue;
        x[d] = a == paddle.axis ? at.planes[static_cast<size_t>(p)] - model_.surface.V(v, a)
                                : stuck_(v, a);
      }
    }
  }

  // Vertices past a paddle join its contact set; true when any did (with
  // `apply` false, only whether any would).
  bool add_penetrating(const PathPoint& at, const Eigen::VectorXd& x, bool apply = true) {
    const int n = model_.num_vertices();
    bool added = false;
    for (size_t p = 0; p < model_.paddles.size(); ++p) {
      const model::Paddle& paddle = model_.paddles[p];
      for (int v = 0; v < n; ++v) {
        if (contact_paddle_[static_cast<size_t>(v)] >= 0 || supports_.held(paddle.axis * n + v))
          continue;
        const double coordinate = model_.surface.V(v, paddle.axis) + x[paddle.axis * n + v];
        if (paddle.penetration(coordinate, at.planes[p]) > 1e-12 * diagonal_) {
          if (!apply) return true;
          contact_paddle_[static_cast<size_t>(v)] = static_cast<int>(p);
          for (int a = 0; a < model_.dim(); ++a) stuck_(v, a) = x[a * n + v];
          added = true;
        }
      }
    }
    return added;
  }

  // Contact vertices whose paddle would have to pull them (the force on the
  // body in `R` at their held unknown) leave the set; true when any did.
  bool release_pulling(const Eigen::VectorXd& R, bool apply = true) {
    const int n = model_.num_vertices();
    bool released = false;
    for (int v = 0; v < n; ++v) {
      const int p = contact_paddle_[static_cast<size_t>(v)];
      if (p < 0) continue;
      const model::Paddle& paddle = model_.paddles[static_cast<size_t>(p)];
      const double force = R[paddle.axis * n + v];  // on the body, along the axis
      if (paddle.above ? force > 0.0 : force < 0.0) {
        if (!apply) return true;
        contact_paddle_[static_cast<size_t>(v)] = -1;
        released = true;
      }
    }
    return released;
  }
  bool release_pulling() { return release_pulling(residual_); }
  bool contact_would_change(const PathPoint& at, const Eigen::VectorXd& x,
                            const Eigen::VectorXd& R) {
    return !model_.paddles.empty() && (release_pulling(R, false) || add_penetrating(at, x, false));
  }

  // The relative residual of the state x (gauge: the scale of x's loads and
  // reactions, or of the states accepted before, whichever is larger).
  double measure(const PathPoint& at, const DofMap& dofs, const Eigen::VectorXd& x,
                 const Eigen::VectorXd& R, double* scale = nullptr) const {
    const double s = gauge_.scale_at(*equilibrium_, dofs, x, at.factors, R);
    if (scale) *scale = s;
    return equilibrium_->relative_norm(dofs.reduce(R), s);
  }

  // Newton iterations with the held set `dofs`, until converged (*converged
  // true) or, after an iteration, until the paddles' active set would change:
  // the set is updated as the iterates go (a semi-smooth Newton), rather than
  // after a full solve with each set. "" or why it failed.
  std::string newton(const PathPoint& at, const DofMap& dofs, Eigen::VectorXd& x,
                     StepRecord& record, bool* converged) {
    *converged = false;
    Eigen::VectorXd R = equilibrium_->residual(x, at.factors);
    double last_move = std::numeric_limits<double>::infinity();
    for (int it = 0;; ++it) {
      if (cancel_requested()) return "interrupted";
      const Eigen::VectorXd r = dofs.reduce(R);
      double scale = 0.0;
      const double norm = measure(at, dofs, x, R, &scale);
      record.residual_norms.push_back(norm);
      if (!std::isfinite(norm)) return "the residual is not finite";
      // Converged: the residual is small, or it has stalled at rounding
      // level (a little above the tolerance) while the corrections vanish.
      const bool small_move = last_move <= newton_.increment_tolerance * diagonal_;
      if (norm <= newton_.residual_tolerance ||
          (small_move && norm <= 1e3 * newton_.residual_tolerance)) {
        residual_ = R;
        gauge_.commit(scale);
        *converged = true;
        return {};
      }
      if (it > 0 && contact_would_change(at, x, R)) {
        residual_ = R;
        return {};
      }
      if (it == newton_.max_iterations) {
        std::ostringstream out;
        out << "newton: no convergence in " << it << " iterations (relative residual " << norm
            << ", newton.residual_tolerance " << newton_.residual_tolerance << ")";
        return out.str();
      }
      Eigen::VectorXd dx;
      // Inexact Newton: a Krylov solve only as accurate as the residual it
      // corrects (relative to it), which keeps the convergence quadratic.
      const double forcing = std::max(newton_.krylov_tolerance, std::min(0.1, 0.1 * norm));
      Status status = tangent_->prepare(x, at.factors, dofs, &supports_);
      if (status.ok) {
        int iterations = 0;
        status = tangent_->solve(-r, forcing, &dx, &iterations);
        record.krylov_iterations += iterations;
        summary_.krylov_iterations += iterations;
      }
      summary_.factorizations = tangent_->factorizations();
      summary_.solver = tangent_->preconditioner_kind();
      if (!status.ok) return status.message;
      // Backtracking: halve the step until the residual falls (Armijo).
      Eigen::VectorXd step = Eigen::VectorXd::Zero(x.size());
      dofs.scatter(dx, step);
      double alpha = 1.0;
      Eigen::VectorXd trial, R_trial;
      for (int halving = 0;; ++halving) {
        trial = x + alpha * step;
        R_trial = equilibrium_->residual(trial, at.factors);
        const double trial_norm = measure(at, dofs, trial, R_trial);
        if (!newton_.line_search || trial_norm <= (1.0 - 1e-4 * alpha) * norm ||
            trial_norm <= newton_.residual_tolerance)
          break;
        if (halving == 12)
          return "newton: the line search found no decrease of the residual (relative " +
                 std::to_string(norm) + ")";
        alpha *= 0.5;
        ++record.line_search_halvings;
      }
      x = trial;
      R = R_trial;
      last_move = alpha * dx.head(dx.size() - 1).cwiseAbs().maxCoeff();
      ++record.newton_iterations;
      ++summary_.newton_iterations;
      report_progress("newton iteration", record.newton_iterations, 0.0);
    }
  }

  const Model& model_;
  const NewtonOptions& newton_;
  SteppingSummary& summary_;
  std::shared_ptr<const model::Equilibrium> equilibrium_;
  DofMap supports_;                  // supports and prescribed values
  std::vector<int> contact_paddle_;  // per vertex: its paddle, or -1
  Eigen::MatrixXd stuck_;            // sticking contact: displacement at first touch
  Eigen::VectorXd residual_;
  double diagonal_ = 1.0;
  ResidualGauge gauge_;
  std::shared_ptr<TangentSolve> tangent_;
};

// Extrapolates the solution along the load path from the last converged
// points (Lagrange, up to quadratic): each step's starting guess. On a smooth
// path it leaves Newton little to do, and it shows the paddles' new contacts
// before the first iteration.
class PathPredictor {
 public:
  explicit PathPredictor(int order) : order_(order) {}
  void add(double t, const Eigen::VectorXd& x) {
    points_.push_back({t, x});
    if (static_cast<int>(points_.size()) > order_ + 1) points_.erase(points_.begin());
  }
  bool extrapolates() const { return points_.size() > 1; }
  // The guess at t; the last point when there is nothing to extrapolate from.
  Eigen::VectorXd predict(double t) const {
    Eigen::VectorXd guess = Eigen::VectorXd::Zero(points_.back().x.size());
    for (size_t i = 0; i < points_.size(); ++i) {
      double weight = 1.0;
      for (size_t j = 0; j < points_.size(); ++j)
        if (j != i) weight *= (t - points_[j].t) / (points_[i].t - points_[j].t);
      guess += weight * points_[i].x;
    }
    return guess;
  }

 private:
  struct Point {
    double t;
    Eigen::VectorXd x;
  };
  int order_;
  std::vector<Point> points_;
};

bool partition_holds(const model::DofPartition& partition, int dof) {
  return std::binary_search(partition.constrained.begin(), partition.constrained.end(), dof);
}

// Why a paddle setup cannot work, or "".
std::string paddle_problem(const Model& model, int steps) {
  const Eigen::MatrixXd& V = model.surface.V;
  for (size_t p = 0; p < model.paddles.size(); ++p) {
    const model::Paddle& a = model.paddles[p];
    if (a.axis < 0 || a.axis >= model.dim()) return "paddle " + a.label + ": axis out of range";
    const double extreme = a.above ? V.col(a.axis).maxCoeff() : V.col(a.axis).minCoeff();
    if (a.penetration(extreme, a.position) > 1e-9 * std::abs(extreme) + 1e-300)
      return "paddle " + a.label + ": it starts inside the body (position " +
             std::to_string(a.position) + ", body extends to " + std::to_string(extreme) + ")";
    for (size_t q = p + 1; q < model.paddles.size(); ++q) {
      const model::Paddle& b = model.paddles[q];
      if (b.axis != a.axis || b.above == a.above) continue;
      const model::Paddle& top = a.above ? a : b;
      const model::Paddle& bottom = a.above ? b : a;
      for (int k = 0; k <= steps; ++k) {
        const double gap = top.plane(top.schedule.factor(k, steps)) -
                           bottom.plane(bottom.schedule.factor(k, steps));
        if (!(gap > 0.0))
          return "paddles " + top.label + " and " + bottom.label + " meet or pass each other " +
                 "at step " + std::to_string(k) + " (gap " + std::to_string(gap) + ")";
      }
    }
  }
  return {};
}

}  // namespace

SteppingSummary solve_newton_steps(const model::Model& model, const SteppingOptions& options,
                                   const StepObserver& observer) {
  const Clock::time_point start = Clock::now();
  SteppingSummary summary = empty_summary(model, Scheme::Newton);
  auto fail = [&](const std::string& why) { return failed(summary, why, start); };
  std::string why = setup_problem(model, options);
  if (!why.empty()) return fail(why);
  why = paddle_problem(model, options.steps);
  if (!why.empty()) return fail(why);
  for (const std::string& name : options.sensitivities.parameters)
    if (!model.material.has_parameter(name, model.dim()))
      return fail("sensitivities: \"" + name + "\" is not a parameter of the material");
  model::DofPartition partition;
  std::unique_ptr<NewtonSolver> solver;
  try {
    partition = model::partition_dofs(model);  // one unknown held at two values throws
    solver = std::make_unique<NewtonSolver>(model, options, summary);
  } catch (const InputError& e) {
    return fail(e.what());
  }

  const int n = options.steps, nv = model.num_vertices(), dim = model.dim();
  const Eigen::MatrixXd& reference = model.surface.V;
  const double reference_volume = solver->equilibrium().reference_volume();
  Eigen::MatrixXd last_face_areas = geom::face_area_vectors(reference, model.surface.F);
  const size_t groups = std::max<size_t>(1, model.constraint_groups.size());
  Eigen::VectorXd& x = summary.unknowns;

  PathPredictor predictor(options.newton.predictor ? 2 : 0);
  predictor.add(0.0, x);
  report_progress("step", 0, n);
  for (int k = 1; k <= n; ++k) {
    const Clock::time_point step_start = Clock::now();
    StepRecord record;
    record.step = k;
    // Pieces of the step: the whole step, halved on failure. A piece that
    // fails from the predicted guess is first tried again from the last
    // solution.
    double reached = k - 1, piece = 1.0;
    bool predict = options.newton.predictor;
    while (reached < k) {
      if (cancel_requested()) return fail("step " + std::to_string(k) + ": interrupted");
      const double target = std::min<double>(k, reached + piece);
      const PathPoint at = path_point(model, target, n);
      const Eigen::VectorXd saved = x;
      const auto contact = solver->contact_state();
      if (predict) x = predictor.predict(target);
      why = solver->solve(at, x, record);
      if (why.empty()) {
        reached = target;
        predictor.add(reached, x);
        predict = options.newton.predictor;
        continue;
      }
      x = saved;
      solver->restore(contact);
      if (predict && predictor.extrapolates()) {
        predict = false;
        continue;
      }
      if (record.step_cuts == options.newton.max_step_cuts)
        return fail("step " + std::to_string(k) + ": " + why + "; the step was halved " +
                    std::to_string(record.step_cuts) +
                    " times (newton.max_step_cuts): the load step is too large or the "
                    "material too soft");
      ++record.step_cuts;
      piece *= 0.5;
    }

    const Eigen::MatrixXd X = model::positions(model, x);
    const double volume = geom::enclosed_volume(X, model.surface.F);
    why = runaway_reason(model, options, x, X, volume, reference_volume, last_face_areas);
    if (!why.empty()) return fail("step " + std::to_string(k) + ": runaway: " + why);

    // Forces on the body: supports per group, paddles, and the loads.
    const PathPoint at = path_point(model, k, n);
    const Eigen::VectorXd& R = solver->last_residual();
    const Eigen::VectorXd F = solver->equilibrium().external_forces(x, at.factors);
    record.reactions.assign(groups, Eigen::Vector3d::Zero());
    summary.reaction_forces = Eigen::MatrixXd::Zero(nv, dim);
    for (size_t c = 0; c < partition.constrained.size(); ++c) {
      const int d = partition.constrained[c];
      const model::Constraint& constraint =
          model.constraints[static_cast<size_t>(partition.constraint_of[c])];
      record.reactions[static_cast<size_t>(constraint.group) % groups][d / nv] += R[d];
      summary.reaction_forces(d % nv, d / nv) = R[d];
    }
    record.paddles.resize(model.paddles.size());
    for (size_t p = 0; p < model.paddles.size(); ++p) {
      record.paddles[p].plane = at.planes[p];
      record.paddles[p].travel = at.planes[p] - model.paddles[p].position;
    }
    const model::DofMap held = solver->held_map();
    for (int v = 0; v < nv; ++v) {
      const int p = solver->contact_paddle()[static_cast<size_t>(v)];
      if (p < 0) continue;
      StepRecord::PaddleState& state = record.paddles[static_cast<size_t>(p)];
      ++state.contacts;
      for (int a = 0; a < dim; ++a)
        if (held.held(a * nv + v) && !partition_holds(partition, a * nv + v)) {
          state.force[a] += R[a * nv + v];
          summary.reaction_forces(v, a) = R[a * nv + v];
        }
    }
    for (int a = 0; a < dim; ++a) record.applied_force[a] = F.segment(a * nv, nv).sum();
    for (size_t l = 0; l < model.loads.size(); ++l) record.load_factors.push_back(at.factors[l]);
    record.pressure = x[model.pressure_dof()];
    record.volume = volume;
    record.volume_drift = (volume - reference_volume) / reference_volume;
    record.max_displacement = (X - reference).rowwise().norm().maxCoeff();
    record.residual = record.residual_norms.empty() ? 0.0 : record.residual_norms.back();
    const std::vector<int>& wanted = options.sensitivities.steps;
    if (!options.sensitivities.parameters.empty() &&
        std::find(wanted.begin(), wanted.end(), k) != wanted.end()) {
      why = solver->sensitivities(at, x, options.sensitivities.parameters, &record.sensitivities);
      if (!why.empty()) return fail("step " + std::to_string(k) + ": sensitivities: " + why);
    }
    record.seconds = seconds_since(step_start);
    summary.steps.push_back(record);
    report_progress("step", k, n);
    if (observer) observer(record, x);
  }
  if (options.keep_final_tangent)
    summary.final_tangent = solver->final_tangent(path_point(model, n, n), x);
  summary.success = true;
  summary.total_seconds = seconds_since(start);
  return summary;
}

}  // namespace fiberfluid::solve
