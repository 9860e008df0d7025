// SPDX-License-Identifier: GPL-3.0-or-later
// The Newton scheme (model.md section 7): equilibrium at every load step,
// with a line search, step cutting, and rigid paddles as an active set.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/geom/self_intersection.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/model/dof_map.hpp"
#include "fiberfluid/model/equilibrium.hpp"
#include "fiberfluid/model/fiber_system.hpp"
#include "fiberfluid/model/loads.hpp"
#include "fiberfluid/solve/interactive_stepper.hpp"
#include "fiberfluid/solve/load_stepper.hpp"
#include "fiberfluid/solve/stepping_common.hpp"
#include "fiberfluid/solve/tangent_solve.hpp"
#include "fiberfluid/util/error.hpp"
#include "fiberfluid/util/progress.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::solve {

LoadPoint scheduled_point(const model::Model& m, double t, int steps) {
  const int k0 = std::clamp(static_cast<int>(std::floor(t)), 0, steps);
  const int k1 = std::min(k0 + 1, steps);
  const double s = t - k0;
  LoadPoint at;
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

namespace {

using model::DofMap;
using model::Model;

// Inexact Newton's forcing term: the relative residual a Krylov solve of
// J dx = -R stops at, for a Newton residual `norm` (relative). As accurate as
// the residual it corrects (0.1 norm: the convergence stays quadratic), but
// never sharper than the tolerance asks (0.5 tolerance / norm: the last
// iteration lands just below the tolerance, not decades below it); Eisenstat
// and Walker, SIAM J. Sci. Comput. 17 (1996) 16, with the safeguard against
// oversolving of Kelley, "Iterative Methods for Linear and Nonlinear
// Equations" (SIAM 1995), eq. 6.20.
double forcing_term(double norm, const NewtonOptions& options) {
  const double quadratic = 0.1 * norm, enough = 0.5 * options.residual_tolerance / norm;
  return std::max(options.krylov_tolerance, std::min(0.1, std::max(quadratic, enough)));
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
        choose_tangent(newton_.tangent, supports_.num_reduced(), model.material.kinematics,
                       equilibrium_->sparse_fibers());
    tangent_ = std::make_shared<TangentSolve>(equilibrium_, options, kind);
    summary_.tangent = kind;
    summary_.solver = tangent_->preconditioner_kind();
    // A body resting on a paddle is held by it from the first iterate.
    for (size_t p = 0; p < model.paddles.size(); ++p)
      for (int v : model::touching_at_start(model, model.paddles[p]))
        if (contact_paddle_[static_cast<size_t>(v)] < 0 &&
            !supports_.held(model.paddles[p].axis * model.num_vertices() + v))
          contact_paddle_[static_cast<size_t>(v)] = static_cast<int>(p);
  }

  const model::Equilibrium& equilibrium() const { return *equilibrium_; }
  const Model& model() const { return model_; }
  // The tangent solve prepared at x (the solution), for the summary.
  std::shared_ptr<TangentSolve> final_tangent(const LoadPoint& at, const Eigen::VectorXd& x) {
    if (!tangent_->prepare(x, at.factors, held_map(), &supports_).ok) return nullptr;
    return tangent_;
  }

  // Solves R = 0 at `at` from x (updated in place): Newton inside an
  // active-set loop for the paddles. "" or why it failed.
  //
  // A vertex that passes a paddle joins its set as soon as an iterate shows
  // it (feasibility first); a vertex leaves only at an equilibrium of the
  // current set, where its contact force is that of a solution and not of an
  // iterate on the way to one. Releasing on iterates made the set chatter at
  // first touch: a body held at one point rocked from one paddle to the other
  // and back, every iteration, for ever (issue 42). Holding the set fixed
  // within each solve and updating it between solves is the usual active-set
  // strategy of implicit contact (Wriggers, Computational Contact Mechanics,
  // 2nd ed. 2006, section 6.3; Sierra/SolidMechanics' "control contact").
  std::string solve(const LoadPoint& at, Eigen::VectorXd& x, StepRecord& record) {
    record.contacts_added += add_penetrating(at, x);
    for (int round = 0; round < newton_.max_contact_rounds; ++round) {
      if (!model_.paddles.empty()) ++record.contact_rounds;
      const DofMap dofs = held_map();
      apply_held_values(at, dofs, x);
      bool converged = false;
      const std::string why = newton(at, dofs, x, record, &converged);
      if (!why.empty()) return why;
      const int released = converged ? release_pulling() : 0;
      const int added = add_penetrating(at, x);
      record.contacts_released += released;
      record.contacts_added += added;
      if (converged && released == 0 && added == 0) return {};
    }
    return "the paddle contact did not settle in " + std::to_string(newton_.max_contact_rounds) +
           " active-set rounds (newton.max_contact_rounds)";
  }

  // du/dtheta = -K_T^{-1} dR/dtheta at the solution x, one tangent solve per
  // parameter, the held set (supports and contacts) fixed. "" or why not.
  // `residual_change` receives dR/dtheta along the solution's change,
  // K_T du/dtheta + dR/dtheta: zero at the free rows, and at the held ones
  // the change of the supports' and paddles' forces.
  std::string sensitivities(const LoadPoint& at, const Eigen::VectorXd& x,
                            const std::vector<std::string>& names, Eigen::MatrixXd* out,
                            Eigen::MatrixXd* residual_change) {
    const std::shared_ptr<TangentSolve> tangent = final_tangent(at, x);
    if (!tangent) return "the tangent at the solution could not be factored";
    const Eigen::MatrixXd dR = equilibrium_->parameter_derivatives(x, names);
    out->resize(x.size(), dR.cols());
    residual_change->resize(x.size(), dR.cols());
    for (Eigen::Index c = 0; c < dR.cols(); ++c) {
      Eigen::VectorXd du;
      const Status status = tangent->solve_full(-dR.col(c), &du);
      if (!status.ok) return names[static_cast<size_t>(c)] + ": " + status.message;
      out->col(c) = du;
      residual_change->col(c) = equilibrium_->tangent_product(x, at.factors, du) + dR.col(c);
    }
    return {};
  }

  using KeepStep = std::function<std::string(StepRecord&, double, Clock::time_point)>;

  // Arc-length continuation (Crisfield 1981, the cylindrical constraint: each
  // step moves the displacement unknowns by `arc` and the load parameter t
  // is an unknown) from the point t = 1 in summary.unknowns on to the final
  // load t = n, which the last step lands on by load control. The arc is the
  // first step's length, halved when a step fails, grown by half after an
  // easy one (at most 4 times the first). Where t falls, the path has passed a
  // limit point (resolved with arcs down to 1/64 of the first, the peak of a
  // parabola through the last three points): the largest load reached is
  // kept (limit_load_factor) and,
  // unless the path climbs to t = n again within max_arc_steps, the run ends
  // naming it. `keep` records each converged point. "" or why it stopped.
  std::string follow_arc_length(int n, SteppingSummary& summary, const KeepStep& keep) {
    Eigen::VectorXd& x = summary.unknowns;
    const DofMap dofs = held_map();
    const Eigen::Index m = dofs.num_reduced() - 1;  // the displacements (the pressure last)
    Eigen::VectorXd previous = dofs.reduce(x);      // the last step's increment (from 0)
    const double first_arc = previous.head(m).norm();
    if (!(first_arc > 0.0))
      return "newton.control arc_length: the first step did not move the body";
    double arc = first_arc, t = 1.0, peak = 1.0, previous_dt = 1.0;
    std::vector<std::array<double, 2>> path = {{0.0, 0.0}, {first_arc, 1.0}};  // (arc length, t)
    int cuts = 0, k = 2;
    while (k <= newton_.max_arc_steps + 1) {
      if (cancel_requested()) return "step " + std::to_string(k) + ": interrupted";
      const Clock::time_point step_start = Clock::now();
      StepRecord record;
      record.step = k;
      Eigen::VectorXd x_new;
      double t_new = t;
      std::string why = arc_step(n, dofs, x, t, arc, previous, previous_dt, &x_new, &t_new, record);
      if (why.empty() && t_new >= n) {  // past the final load: land on it by load control
        const double s = (n - t) / (t_new - t);
        Eigen::VectorXd landing = x + s * (x_new - x);
        why = solve(scheduled_point(model_, n, n), landing, record);
        if (why.empty()) {
          x = landing;
          return keep(record, n, step_start);
        }
      }
      if (!why.empty()) {
        if (cuts == newton_.max_step_cuts)
          return "step " + std::to_string(k) + ": arc length: " + why + "; the arc was halved " +
                 std::to_string(cuts) + " times (newton.max_step_cuts)" + limit_note(summary);
        ++cuts;
        arc *= 0.5;
        continue;
      }
      const double dt = t_new - t;
      // The first turn is resolved with short arcs, so that the limit load
      // is found to a fraction of the first step's load.
      if (dt < 0.0 && std::isnan(summary.limit_load_factor) && arc > first_arc / 64.0) {
        arc *= 0.25;
        continue;
      }
      path.push_back({path.back()[0] + arc, t_new});
      if (dt < 0.0 && std::isnan(summary.limit_load_factor))
        summary.limit_load_factor = std::max(peak, parabola_peak(path)) / n;
      peak = std::max(peak, t_new);
      previous = dofs.reduce(x_new) - dofs.reduce(x);
      previous_dt = dt;
      x = x_new;
      t = t_new;
      cuts = 0;
      if (t <= 0.0)
        return "step " + std::to_string(k) + ": arc length: the path returned to no load" +
               limit_note(summary);
      if (!(why = keep(record, t, step_start)).empty()) return why + limit_note(summary);
      report_progress("arc-length step", k, newton_.max_arc_steps + 1);
      if (record.newton_iterations <= 4) arc = std::min(1.5 * arc, 4.0 * first_arc);
      ++k;
    }
    return "arc length: the final load was not reached in " +
           std::to_string(newton_.max_arc_steps) + " steps (newton.max_arc_steps; load factor " +
           std::to_string(t / n) + ")" + limit_note(summary);
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
  // A warm start's contact set: the vertices that stand on a paddle's plane
  // (a nearby solution held them there) or past it.
  void touch_planes(const LoadPoint& at, const Eigen::VectorXd& x) {
    add_penetrating(at, x, true, -1e-9);
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
  void apply_held_values(const LoadPoint& at, const DofMap& dofs, Eigen::VectorXd& x) const {
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

  // Vertices past a paddle join its contact set; how many did (with `apply`
  // false, 1 when any would). `reach` (a share of the body's diagonal): how
  // far past the plane a vertex must be; a negative one takes in vertices
  // that stand that close in front of it.
  int add_penetrating(const LoadPoint& at, const Eigen::VectorXd& x, bool apply = true,
                      double reach = 1e-12) {
    const int n = model_.num_vertices();
    int added = 0;
    for (size_t p = 0; p < model_.paddles.size(); ++p) {
      const model::Paddle& paddle = model_.paddles[p];
      for (int v = 0; v < n; ++v) {
        if (contact_paddle_[static_cast<size_t>(v)] >= 0 || supports_.held(paddle.axis * n + v))
          continue;
        const double coordinate = model_.surface.V(v, paddle.axis) + x[paddle.axis * n + v];
        if (paddle.penetration(coordinate, at.planes[p]) > reach * diagonal_) {
          if (!apply) return 1;
          contact_paddle_[static_cast<size_t>(v)] = static_cast<int>(p);
          for (int a = 0; a < model_.dim(); ++a) stuck_(v, a) = x[a * n + v];
          ++added;
        }
      }
    }
    return added;
  }

  // Contact vertices whose paddle would have to pull them (the force on the
  // body in `R` at their held unknown) leave the set; how many did.
  int release_pulling(const Eigen::VectorXd& R) {
    const int n = model_.num_vertices();
    int released = 0;
    for (int v = 0; v < n; ++v) {
      const int p = contact_paddle_[static_cast<size_t>(v)];
      if (p < 0) continue;
      const model::Paddle& paddle = model_.paddles[static_cast<size_t>(p)];
      const double force = R[paddle.axis * n + v];  // on the body, along the axis
      if (paddle.above ? force > 0.0 : force < 0.0) {
        contact_paddle_[static_cast<size_t>(v)] = -1;
        ++released;
      }
    }
    return released;
  }
  int release_pulling() { return release_pulling(residual_); }

  // The relative residual of the state x (gauge: the scale of x's loads and
  // reactions, or of the states accepted before, whichever is larger).
  double measure(const LoadPoint& at, const DofMap& dofs, const Eigen::VectorXd& x,
                 const Eigen::VectorXd& R, double* scale = nullptr) const {
    const double s = gauge_.scale_at(*equilibrium_, dofs, x, at.factors, R);
    if (scale) *scale = s;
    return equilibrium_->relative_norm(dofs.reduce(R), s);
  }

  // Newton iterations with the held set `dofs`, until converged (*converged
  // true) or, after an iteration, until a vertex passes a paddle: the set
  // grows as the iterates go, rather than after a full solve with each set
  // (solve() says why it shrinks only at a solution). "" or why it failed.
  std::string newton(const LoadPoint& at, const DofMap& dofs, Eigen::VectorXd& x,
                     StepRecord& record, bool* converged) {
    *converged = false;
    Eigen::VectorXd R = tangent_->residual(x, at.factors);  // and the tangent there
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
      if (it > 0 && add_penetrating(at, x, false) > 0) {
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
      const double forcing = forcing_term(norm, newton_);
      const Status status = prepare_and_solve(x, at.factors, dofs, -r, forcing, record, &dx);
      if (!status.ok) return status.message;
      // Backtracking: halve the step until the residual falls (Armijo).
      Eigen::VectorXd step = Eigen::VectorXd::Zero(x.size());
      dofs.scatter(dx, step);
      double alpha = 1.0;
      Eigen::VectorXd trial, R_trial;
      for (int halving = 0;; ++halving) {
        trial = x + alpha * step;
        R_trial = tangent_->residual(trial, at.factors);  // and the tangent there
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

  // Solves J y = b with the tangent as last prepared (Krylov to the relative
  // residual `forcing`), counting its iterations in the step and the run.
  Status solve_prepared(const Eigen::VectorXd& b, double forcing, StepRecord& record,
                        Eigen::VectorXd* y) {
    int iterations = 0;
    const Status status = tangent_->solve(b, forcing, y, &iterations);
    record.krylov_iterations += iterations;
    summary_.krylov_iterations += iterations;
    return status;
  }
  // Prepares the tangent at (x, factors) over `dofs`, then solve_prepared;
  // the run's factorisations and preconditioner kept up to date.
  Status prepare_and_solve(const Eigen::VectorXd& x, const std::vector<double>& factors,
                           const DofMap& dofs, const Eigen::VectorXd& b, double forcing,
                           StepRecord& record, Eigen::VectorXd* y) {
    Status status = tangent_->prepare(x, factors, dofs, &supports_);
    if (status.ok) status = solve_prepared(b, forcing, record, y);
    summary_.factorizations = tangent_->factorizations();
    summary_.single_precision_factorizations = tangent_->single_precision_factorizations();
    summary_.solver = tangent_->preconditioner_kind();
    return status;
  }

  // The largest t of the parabola through the path's last three points (arc
  // length, t): the limit load between the points, where the path turned.
  static double parabola_peak(const std::vector<std::array<double, 2>>& path) {
    if (path.size() < 3) return path.back()[1];
    const auto& [s0, t0] = path[path.size() - 3];
    const auto& [s1, t1] = path[path.size() - 2];
    const auto& [s2, t2] = path[path.size() - 1];
    const double d01 = (t1 - t0) / (s1 - s0), d12 = (t2 - t1) / (s2 - s1);
    const double curvature = (d12 - d01) / (s2 - s0);
    if (!(curvature < 0.0)) return std::max({t0, t1, t2});
    // Newton form: t(s) = t0 + d01 (s - s0) + curvature (s - s0)(s - s1).
    const double s_peak = 0.5 * (s0 + s1) - d01 / (2.0 * curvature);
    if (s_peak < s0 || s_peak > s2) return std::max({t0, t1, t2});
    return t0 + d01 * (s_peak - s0) + curvature * (s_peak - s0) * (s_peak - s1);
  }

  // ": a limit point..." when the path has turned back, else "".
  static std::string limit_note(const SteppingSummary& summary) {
    if (std::isnan(summary.limit_load_factor)) return {};
    std::ostringstream out;
    out << "; a limit point: the load peaked at " << summary.limit_load_factor
        << " of the final load (the body cannot carry more along this path)";
    return out.str();
  }

  // The load factors at a path parameter t, the end segments extended
  // beyond [0, n] (an arc-length corrector may step past the final load).
  std::vector<double> factors_at(double t, int n) const {
    if (t >= 0.0 && t <= n) return scheduled_point(model_, t, n).factors;
    const double edge = t > n ? n : 0.0, inner = t > n ? n - 1.0 : 1.0;
    const std::vector<double> a = scheduled_point(model_, edge, n).factors,
                              b = scheduled_point(model_, inner, n).factors;
    std::vector<double> f(a.size());
    for (size_t l = 0; l < a.size(); ++l) f[l] = a[l] + (t - edge) / (inner - edge) * (b[l] - a[l]);
    return f;
  }

  // dR/dt at (x, t), reduced: exact, as only the loads depend on t and they
  // are affine in their factors on the path segment that holds t (the one
  // ahead in the direction `ahead`): minus the change of the external forces.
  Eigen::VectorXd path_derivative(const DofMap& dofs, const Eigen::VectorXd& x, double t, int n,
                                  bool ahead) const {
    double lo = ahead ? std::floor(t) : std::ceil(t) - 1.0;
    lo = std::clamp(lo, 0.0, n - 1.0);
    const Eigen::VectorXd difference = equilibrium_->external_forces(x, factors_at(lo, n)) -
                                       equilibrium_->external_forces(x, factors_at(lo + 1.0, n));
    return dofs.reduce(difference);
  }

  // One arc-length step from (x0, t0): the predictor along du/dt, then
  // corrections that keep |x - x0| = arc on the displacements (the root of
  // the constraint's quadratic closest to the step's direction). "" or why not.
  std::string arc_step(int n, const DofMap& dofs, const Eigen::VectorXd& x0, double t0, double arc,
                       const Eigen::VectorXd& previous, double previous_dt, Eigen::VectorXd* x,
                       double* t, StepRecord& record) {
    const Eigen::Index m = dofs.num_reduced() - 1;
    const auto solve_with_tangent = [&](const Eigen::VectorXd& at_x, double at_t,
                                        const Eigen::VectorXd& rhs, double forcing,
                                        Eigen::VectorXd* out) -> std::string {
      const Status status =
          prepare_and_solve(at_x, factors_at(at_t, n), dofs, rhs, forcing, record, out);
      return status.ok ? std::string() : status.message;
    };
    // Predictor: along du/dt = -K^-1 dR/dt, in the direction of the last step.
    Eigen::VectorXd v;
    std::string why =
        solve_with_tangent(x0, t0, -path_derivative(dofs, x0, t0, n, previous_dt >= 0.0),
                           newton_.krylov_tolerance, &v);
    if (!why.empty()) return why;
    const double speed = v.head(m).norm();
    if (!(speed > 0.0) || !std::isfinite(speed)) return "the path's tangent is not finite";
    const double sign = previous.head(m).dot(v.head(m)) >= 0.0 ? 1.0 : -1.0;
    Eigen::VectorXd delta = (sign * arc / speed) * v;
    double dt = sign * arc / speed;
    for (int it = 0;; ++it) {
      *t = t0 + dt;
      *x = x0;
      Eigen::VectorXd step = Eigen::VectorXd::Zero(x0.size());
      dofs.scatter(delta, step);
      *x += step;
      const std::vector<double> factors = factors_at(*t, n);
      const Eigen::VectorXd R = tangent_->residual(*x, factors);  // and the tangent there
      LoadPoint at;
      at.factors = factors;
      double scale = 0.0;
      const double norm = measure(at, dofs, *x, R, &scale);
      record.residual_norms.push_back(norm);
      if (!std::isfinite(norm)) return "the residual is not finite";
      if (norm <= newton_.residual_tolerance) {
        residual_ = R;
        gauge_.commit(scale);
        return {};
      }
      if (it == newton_.max_iterations)
        return "no convergence in " + std::to_string(it) + " iterations (relative residual " +
               std::to_string(norm) + ")";
      Eigen::VectorXd a, b;
      const double forcing = forcing_term(norm, newton_);
      why = solve_with_tangent(*x, *t, -dofs.reduce(R), forcing, &a);
      if (why.empty()) {  // du/dt with the same tangent
        const Status status = solve_prepared(-path_derivative(dofs, *x, *t, n, dt >= 0.0),
                                             newton_.krylov_tolerance, record, &b);
        if (!status.ok) why = "du/dt: " + status.message;
      }
      if (!why.empty()) return why;
      // |delta + a + dtc b|^2 = arc^2 on the displacements: A dtc^2 + B dtc + C = 0.
      const Eigen::VectorXd base = (delta + a).head(m), bm = b.head(m);
      const double A = bm.squaredNorm(), B = 2.0 * bm.dot(base), C = base.squaredNorm() - arc * arc;
      const double discriminant = B * B - 4.0 * A * C;
      if (!(A > 0.0) || discriminant < 0.0) return "the arc-length constraint has no real root";
      const double root = std::sqrt(discriminant);
      const double q = -0.5 * (B + std::copysign(root, B));  // the stable pair of roots
      const double r1 = q / A, r2 = q != 0.0 ? C / q : r1;
      const auto alignment = [&](double r) { return (base + r * bm).dot(delta.head(m)); };
      const double dtc = alignment(r1) >= alignment(r2) ? r1 : r2;
      delta += a + dtc * b;
      dt += dtc;
      ++record.newton_iterations;
      ++summary_.newton_iterations;
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

// Why no equilibrium continues the path, in the body's terms where it can
// be told: the surface of the last Newton iterate passes through itself (a
// self-contact ahead, which the model does not treat). "" when nothing is
// seen.
std::string physical_reason(const Model& model, const Eigen::VectorXd& iterate) {
  geom::Surface at = model.surface;
  at.V = model::positions(model, iterate);
  if (!at.V.allFinite()) return {};
  if (const auto crossing = geom::find_self_intersection(at))
    return "; the last iterate passes through itself (faces " + std::to_string(crossing->first) +
           " and " + std::to_string(crossing->second) +
           " cross): the path may run into a self-contact, which the model does not treat";
  return {};
}

// Solves one step from the solution x at path parameter `from` to the point
// at(to), along the points at(t) between: pieces of 2^-depth of a step,
// `depth` carried from step to step (the pieces the last step ended with).
// A failing piece is halved (at most newton.max_step_cuts deep); a piece that
// converged easily (in at most 3 Newton iterations) doubles the next one
// again, up to the whole step: one hard moment (first touch, a contact front
// passing) costs a few short pieces, and a hard stretch of the path is
// walked in short pieces without failing at each step's start first. A piece
// that fails from the predictor's guess is first tried again from the last
// solution. Each converged piece joins the predictor.
//
// When the line search stalls at about the same residual three cuts in a
// row, shorter pieces will not help (a step too long stalls lower as it is
// cut): the path has no equilibrium to go on to, and the walk stops there,
// saying so, rather than halving on to the limit (a fit's trial point that
// is too soft for its load failed in minutes that way).
//
// "" or why it failed (x and the contact state are then those of the last
// converged piece).
std::string walk_step(NewtonSolver& solver, const std::function<LoadPoint(double)>& at, double from,
                      double to, const NewtonOptions& options, PathPredictor& predictor,
                      Eigen::VectorXd& x, StepRecord& record, int& depth) {
  constexpr int kEasyIterations = 3;
  constexpr int kStalledCuts = 3;  // failures in a row at one residual level
  depth = std::min(depth, options.max_step_cuts);
  double reached = from, piece = (to - from) * std::ldexp(1.0, -depth);
  bool predict = options.predictor;
  std::vector<double> stalls;  // the residual of each line-search failure since the last success
  while (reached < to) {
    if (cancel_requested()) return "interrupted";
    const double target = std::min(to, reached + piece);
    const Eigen::VectorXd saved = x;
    const auto contact = solver.contact_state();
    if (predict) x = predictor.predict(target);
    const int iterations_before = record.newton_iterations;
    const size_t norms_before = record.residual_norms.size();
    const std::string why = solver.solve(at(target), x, record);
    if (why.empty()) {
      reached = target;
      ++record.pieces;
      predictor.add(reached, x);
      predict = options.predictor;
      stalls.clear();
      if (depth > 0 && record.newton_iterations - iterations_before <= kEasyIterations) {
        --depth;
        piece *= 2.0;
      }
      continue;
    }
    const Eigen::VectorXd iterate = x;
    x = saved;
    solver.restore(contact);
    if (predict && predictor.extrapolates()) {
      predict = false;
      continue;
    }
    const bool stalled = why.rfind("newton: the line search found no decrease", 0) == 0 &&
                         record.residual_norms.size() > norms_before;
    if (stalled) {
      stalls.push_back(record.residual_norms.back());
    } else {
      stalls.clear();
    }
    if (stalls.size() >= static_cast<size_t>(kStalledCuts)) {
      const auto last = stalls.end() - kStalledCuts;
      const auto [low, high] = std::minmax_element(last, stalls.end());
      if (*high <= 2.0 * *low) {
        std::ostringstream out;
        out << why << ", " << kStalledCuts << " cuts in a row (down to " << std::ldexp(1.0, -depth)
            << " of a step): shorter pieces will not help; no equilibrium continues the path "
               "here (a limit or bifurcation point, or a material too soft for the load)"
            << physical_reason(solver.model(), iterate);
        return out.str();
      }
    }
    if (depth == options.max_step_cuts)
      return why + "; the step was halved " + std::to_string(depth) +
             " times (newton.max_step_cuts): the load step is too large or the material too "
             "soft" +
             physical_reason(solver.model(), iterate);
    ++record.step_cuts;
    ++depth;
    piece *= 0.5;
  }
  return {};
}

bool partition_holds(const model::DofPartition& partition, int dof) {
  return std::binary_search(partition.constrained.begin(), partition.constrained.end(), dof);
}

}  // namespace

std::string sensitivity_problem(const Model& model) {
  for (const model::Paddle& paddle : model.paddles)
    if (paddle.sticking)
      return "paddle " + paddle.label +
             " sticks: it holds each vertex where it touched, a place that moves with the "
             "parameters (fit with finite differences)";
  return {};
}

std::string warm_start_problem(const Model& model, const SteppingOptions& options) {
  if (options.warm_start.size() == 0) return {};
  if (options.scheme != Scheme::Newton) return "a warm start needs the Newton scheme";
  if (options.newton.control != NewtonOptions::Control::Load)
    return "a warm start needs load control (arc length follows the path from its start)";
  const Eigen::Index expected = static_cast<Eigen::Index>(model.dim()) * model.num_vertices() + 1;
  if (options.warm_start.size() != expected)
    return "expected " + std::to_string(expected) + " unknowns (displacements and pressure), got " +
           std::to_string(options.warm_start.size());
  if (!options.warm_start.allFinite()) return "the start has non-finite values";
  for (const model::Paddle& paddle : model.paddles)
    if (paddle.sticking)
      return "paddle " + paddle.label +
             " sticks: where a vertex sticks depends on the way there, so the end of the path "
             "cannot be solved from elsewhere";
  return {};
}

namespace {

// Why paddles at these planes cannot work, or "": two on one axis, on
// opposite sides, that meet or pass each other (`where`: when, for the message).
std::string planes_problem(const Model& model, const std::vector<double>& planes,
                           const std::string& where = "") {
  for (size_t p = 0; p < model.paddles.size(); ++p)
    for (size_t q = p + 1; q < model.paddles.size(); ++q) {
      const model::Paddle& a = model.paddles[p];
      const model::Paddle& b = model.paddles[q];
      if (b.axis != a.axis || b.above == a.above) continue;
      const size_t top = a.above ? p : q, bottom = a.above ? q : p;
      const double gap = planes[top] - planes[bottom];
      if (!(gap > 0.0))
        return "paddles " + model.paddles[top].label + " and " + model.paddles[bottom].label +
               " meet or pass each other" + where + " (gap " + std::to_string(gap) + ")";
    }
  return {};
}

// Why a paddle setup cannot start, or "": an axis out of range, a paddle
// inside the body at its start.
std::string paddle_start_problem(const Model& model) {
  const Eigen::MatrixXd& V = model.surface.V;
  for (const model::Paddle& a : model.paddles) {
    if (a.axis < 0 || a.axis >= model.dim()) return "paddle " + a.label + ": axis out of range";
    const double extreme = a.above ? V.col(a.axis).maxCoeff() : V.col(a.axis).minCoeff();
    if (a.penetration(extreme, a.position) > 1e-9 * std::abs(extreme) + 1e-300)
      return "paddle " + a.label + ": it starts inside the body (position " +
             std::to_string(a.position) + ", body extends to " + std::to_string(extreme) + ")";
  }
  return {};
}

// Why a paddle setup cannot work over `steps` steps, or "".
std::string paddle_problem(const Model& model, int steps) {
  std::string why = paddle_start_problem(model);
  for (int k = 0; k <= steps && why.empty(); ++k) {
    why = planes_problem(model, scheduled_point(model, k, steps).planes,
                         " at step " + std::to_string(k));
  }
  return why;
}

// What every converged step leaves behind: its record (forces on the body,
// volume, pressure, sensitivities) after the runaway checks.
class StepFinisher {
 public:
  StepFinisher(const Model& model, const SteppingOptions& options, NewtonSolver& solver,
               const model::DofPartition& partition, SteppingSummary& summary)
      : model_(model),
        options_(options),
        solver_(solver),
        partition_(partition),
        summary_(summary),
        reference_volume_(solver.equilibrium().reference_volume()),
        last_face_areas_(geom::face_area_vectors(model.surface.V, model.surface.F)),
        groups_(std::max<size_t>(1, model.constraint_groups.size())) {}

  // The state the next step's runaway checks compare with (a warm start's;
  // the unloaded body at first).
  void compare_with(const Eigen::VectorXd& x) {
    last_face_areas_ = geom::face_area_vectors(model::positions(model_, x), model_.surface.F);
  }

  // "" or why the run stops (a runaway, failed sensitivities).
  std::string finish(const LoadPoint& at, const Eigen::VectorXd& x, StepRecord& record) {
    const int nv = model_.num_vertices(), dim = model_.dim(), k = record.step;
    const Eigen::MatrixXd X = model::positions(model_, x);
    const double volume = geom::enclosed_volume(X, model_.surface.F);
    std::string why =
        runaway_reason(model_, options_, x, X, volume, reference_volume_, last_face_areas_);
    if (!why.empty()) return "step " + std::to_string(k) + ": runaway: " + why;

    // Forces on the body: supports per group, paddles, and the loads.
    const Eigen::VectorXd& R = solver_.last_residual();
    const Eigen::VectorXd F = solver_.equilibrium().external_forces(x, at.factors);
    record.reactions.assign(groups_, Eigen::Vector3d::Zero());
    summary_.reaction_forces = Eigen::MatrixXd::Zero(nv, dim);
    for (size_t c = 0; c < partition_.constrained.size(); ++c) {
      const int d = partition_.constrained[c];
      const model::Constraint& constraint =
          model_.constraints[static_cast<size_t>(partition_.constraint_of[c])];
      record.reactions[static_cast<size_t>(constraint.group) % groups_][d / nv] += R[d];
      summary_.reaction_forces(d % nv, d / nv) = R[d];
    }
    // A clamp's mirror layer holds the body through its fibers, not its rows.
    const std::vector<Eigen::Vector3d> layers = solver_.equilibrium().support_forces(x);
    for (size_t g = 0; g < layers.size(); ++g) record.reactions[g % groups_] += layers[g];
    record.paddles.resize(model_.paddles.size());
    for (size_t p = 0; p < model_.paddles.size(); ++p) {
      record.paddles[p].plane = at.planes[p];
      record.paddles[p].travel = at.planes[p] - model_.paddles[p].position;
    }
    const model::DofMap held = solver_.held_map();
    for (int v = 0; v < nv; ++v) {
      const int p = solver_.contact_paddle()[static_cast<size_t>(v)];
      if (p < 0) continue;
      StepRecord::PaddleState& state = record.paddles[static_cast<size_t>(p)];
      ++state.contacts;
      for (int a = 0; a < dim; ++a)
        if (held.held(a * nv + v) && !partition_holds(partition_, a * nv + v)) {
          state.force[a] += R[a * nv + v];
          summary_.reaction_forces(v, a) = R[a * nv + v];
        }
    }
    for (int a = 0; a < dim; ++a) record.applied_force[a] = F.segment(a * nv, nv).sum();
    for (int v = 0; v < nv; ++v) {
      bool any = false;
      for (int a = 0; a < dim; ++a) any = any || held.held(a * nv + v);
      if (!any) continue;
      StepRecord::HeldForce force;
      force.vertex = v;
      force.paddle = solver_.contact_paddle()[static_cast<size_t>(v)];
      force.force.head(dim) = summary_.reaction_forces.row(v).transpose();
      record.held_forces.push_back(force);
    }
    record.load_factors = at.factors;
    record.pressure = x[model_.pressure_dof()];
    record.volume = volume;
    record.volume_drift = (volume - reference_volume_) / reference_volume_;
    record.max_displacement = (X - model_.surface.V).rowwise().norm().maxCoeff();
    record.residual = record.residual_norms.empty() ? 0.0 : record.residual_norms.back();
    const std::vector<int>& wanted = options_.sensitivities.steps;
    if (!options_.sensitivities.parameters.empty() &&
        std::find(wanted.begin(), wanted.end(), k) != wanted.end()) {
      Eigen::MatrixXd residual_change;
      why = solver_.sensitivities(at, x, options_.sensitivities.parameters, &record.sensitivities,
                                  &residual_change);
      if (!why.empty()) return "step " + std::to_string(k) + ": sensitivities: " + why;
      force_sensitivities(residual_change, record);
    }
    return {};
  }

 private:
  // The support group (an index into StepRecord::reactions) of the c-th held unknown.
  size_t group_of(size_t c) const {
    const int constraint = partition_.constraint_of[c];
    return static_cast<size_t>(model_.constraints[static_cast<size_t>(constraint)].group) % groups_;
  }

  // The reactions' and paddle forces' derivatives, read off the held rows of
  // the residual's change (columns: the parameters). A group whose mirror
  // layer carries part of its reaction gets NaN: the layer's fibers are not
  // differentiated here.
  void force_sensitivities(const Eigen::MatrixXd& residual_change, StepRecord& record) const {
    const int nv = model_.num_vertices(), dim = model_.dim();
    const Eigen::Index P = residual_change.cols();
    record.reaction_sensitivities.assign(groups_, Eigen::MatrixXd::Zero(3, P));
    for (size_t c = 0; c < partition_.constrained.size(); ++c) {
      const int d = partition_.constrained[c];
      const size_t g = group_of(c);
      record.reaction_sensitivities[g].row(d / nv) += residual_change.row(d);
    }
    for (const model::MirrorLayer& layer : model_.mirror_layers)
      record.reaction_sensitivities[static_cast<size_t>(layer.group) % groups_].setConstant(
          std::numeric_limits<double>::quiet_NaN());
    for (StepRecord::PaddleState& state : record.paddles)
      state.force_sensitivities = Eigen::MatrixXd::Zero(3, P);
    const model::DofMap held = solver_.held_map();
    for (int v = 0; v < nv; ++v) {
      const int p = solver_.contact_paddle()[static_cast<size_t>(v)];
      if (p < 0) continue;
      for (int a = 0; a < dim; ++a)
        if (held.held(a * nv + v) && !partition_holds(partition_, a * nv + v))
          record.paddles[static_cast<size_t>(p)].force_sensitivities.row(a) +=
              residual_change.row(a * nv + v);
    }
  }

  const Model& model_;
  const SteppingOptions& options_;
  NewtonSolver& solver_;
  const model::DofPartition& partition_;
  SteppingSummary& summary_;
  double reference_volume_;
  Eigen::MatrixXd last_face_areas_;
  size_t groups_;
};

// Why the path cannot be followed by arc length, or "": the arc-length
// constraint acts on the loads' factor, so the held values must not move
// along the path (prescribed motions and paddles are displacement control).
std::string arc_length_problem(const Model& model, int steps) {
  if (!model.paddles.empty())
    return "newton.control arc_length: paddles move the body by displacement, which load "
           "control already follows; use control \"load\"";
  for (int k = 1; k <= steps; ++k)
    if (model::constrained_displacements(model, k, steps).cwiseAbs().maxCoeff() > 0.0)
      return "newton.control arc_length: a prescribed displacement or rotation moves along the "
             "path; arc length follows loads only (use control \"load\")";
  if (model.loads.empty()) return "newton.control arc_length: there is no load to follow";
  return {};
}

// The final load point n solved from `start` in one piece (a Newton solve
// inside the active-set loop, no cuts): true, with summary.unknowns and step
// n's record kept, when it converged and passed the runaway checks. Else the
// solver, the finisher and the summary are as they were before (the Newton
// iterations spent stay counted), and the caller walks the path.
template <class KeepStep>
bool solve_from_warm_start(NewtonSolver& solver, StepFinisher& finisher,
                           const Eigen::VectorXd& start, int n, const KeepStep& keep,
                           SteppingSummary& summary) {
  const Clock::time_point step_start = Clock::now();
  const auto contact = solver.contact_state();
  const LoadPoint end = scheduled_point(solver.model(), n, n);
  Eigen::VectorXd x = start;
  solver.touch_planes(end, x);
  finisher.compare_with(x);
  StepRecord record;
  record.step = n;
  Eigen::VectorXd& kept = summary.unknowns;
  const Eigen::VectorXd unloaded = kept;
  if (solver.solve(end, x, record).empty()) {
    kept = x;
    if (keep(record, n, step_start).empty()) return summary.warm_started = true;
  }
  kept = unloaded;
  solver.restore(contact);
  finisher.compare_with(unloaded);
  return false;
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
  const bool by_arc = options.newton.control == NewtonOptions::Control::ArcLength;
  if (by_arc && !(why = arc_length_problem(model, options.steps)).empty()) return fail(why);
  for (const std::string& name : options.sensitivities.parameters)
    if (!model.material.has_parameter(name, model.dim()))
      return fail("sensitivities: \"" + name + "\" is not a parameter of the material");
  if (!options.sensitivities.parameters.empty() && (why = sensitivity_problem(model)) != "")
    return fail("sensitivities: " + why);
  model::DofPartition partition;
  std::unique_ptr<NewtonSolver> solver;
  try {
    partition = model::partition_dofs(model);  // one unknown held at two values throws
    solver = std::make_unique<NewtonSolver>(model, options, summary);
  } catch (const InputError& e) {
    return fail(e.what());
  }
  StepFinisher finisher(model, options, *solver, partition, summary);
  const int n = options.steps;
  Eigen::VectorXd& x = summary.unknowns;
  // A converged point of the path at t: its record, the observer.
  model::PairPasses passes_before = model::pair_passes();
  const auto keep = [&](StepRecord& record, double t, const Clock::time_point step_start) {
    const std::string stop = finisher.finish(scheduled_point(model, t, n), x, record);
    if (!stop.empty()) return stop;
    record.seconds = seconds_since(step_start);
    record.pair_passes = model::pair_passes() - passes_before;
    passes_before = model::pair_passes();
    summary.steps.push_back(record);
    if (observer) observer(record, x);
    return std::string();
  };

  if (options.warm_start.size() > 0) {
    if (!(why = warm_start_problem(model, options)).empty()) return fail("warm_start: " + why);
    if (solve_from_warm_start(*solver, finisher, options.warm_start, n, keep, summary)) {
      summary.success = true;
      summary.total_seconds = seconds_since(start);
      return summary;
    }
  }

  PathPredictor predictor(options.newton.predictor ? 2 : 0);
  predictor.add(0.0, x);
  report_progress("step", 0, n);
  int depth = 0;  // the pieces' halvings, carried from step to step
  // Load control: each step to t = k (t = 1 only, the arc's first step, by arc length).
  for (int k = 1; k <= (by_arc ? 1 : n); ++k) {
    const Clock::time_point step_start = Clock::now();
    StepRecord record;
    record.step = k;
    why = walk_step(
        *solver, [&](double t) { return scheduled_point(model, t, n); }, k - 1.0, k, options.newton,
        predictor, x, record, depth);
    if (!why.empty()) return fail("step " + std::to_string(k) + ": " + why);
    if (!(why = keep(record, k, step_start)).empty()) return fail(why);
    report_progress("step", k, n);
  }
  if (by_arc && n > 1) {
    why = solver->follow_arc_length(n, summary, keep);
    if (!why.empty()) return fail(why);
  }
  if (options.keep_final_tangent)
    summary.final_tangent = solver->final_tangent(scheduled_point(model, n, n), x);
  summary.success = true;
  summary.total_seconds = seconds_since(start);
  return summary;
}

// ------------------------------------------------------------ interactive

namespace {

// The options an interactive stepper runs with: Newton by load control, one
// step at a time, nothing kept for calibration.
SteppingOptions interactive_options(SteppingOptions options) {
  options.scheme = Scheme::Newton;
  options.steps = 1;
  options.newton.control = NewtonOptions::Control::Load;
  options.sensitivities = {};
  options.keep_final_tangent = false;
  return options;
}

// The point a share s of the way from `a` to `b` (b itself at s = 1, to the bit).
LoadPoint between(const LoadPoint& a, const LoadPoint& b, double s) {
  LoadPoint at = b;
  if (s == 1.0) return at;
  for (size_t l = 0; l < at.factors.size(); ++l)
    at.factors[l] = a.factors[l] + s * (b.factors[l] - a.factors[l]);
  at.held_values = a.held_values + s * (b.held_values - a.held_values);
  for (size_t p = 0; p < at.planes.size(); ++p)
    at.planes[p] = a.planes[p] + s * (b.planes[p] - a.planes[p]);
  return at;
}

// A point's values in one vector (load factors, planes, held values), to
// compare two moves' directions.
Eigen::VectorXd flattened(const LoadPoint& p) {
  Eigen::VectorXd out(static_cast<Eigen::Index>(p.factors.size() + p.planes.size()) +
                      p.held_values.size());
  Eigen::Index k = 0;
  for (double f : p.factors) out[k++] = f;
  for (double q : p.planes) out[k++] = q;
  out.tail(p.held_values.size()) = p.held_values;
  return out;
}

bool all_finite(const std::vector<double>& values) {
  return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
}

}  // namespace

class InteractiveStepper::Impl {
 public:
  Impl(const Model& model, const SteppingOptions& options)
      : model_(model),
        options_(interactive_options(options)),
        summary_(empty_summary(model, Scheme::Newton)) {
    std::string why = setup_problem(model, options_);
    if (why.empty()) why = paddle_start_problem(model);
    if (!why.empty()) throw InputError("interactive stepper: " + why);
    partition_ = model::partition_dofs(model);
    solver_ = std::make_unique<NewtonSolver>(model, options_, summary_);
    finisher_ = std::make_unique<StepFinisher>(model, options_, *solver_, partition_, summary_);
    point_ = scheduled_point(model, 0.0, 1);
  }

  Result step(const LoadPoint& requested) {
    const LoadPoint to = checked(requested);
    const Clock::time_point start = Clock::now();
    const model::PairPasses passes_before = model::pair_passes();
    Result result;
    StepRecord& record = result.record;
    record.step = steps_ + 1;
    const LoadPoint from = point_;
    const double t0 = steps_;
    const auto at = [&](double t) { return between(from, to, t - t0); };
    Eigen::VectorXd x = summary_.unknowns;
    const auto contact = solver_->contact_state();
    NewtonOptions newton = options_.newton;
    PathPredictor predictor = start_predictor(from, to, &newton.predictor);
    int depth = 0;  // each move starts whole
    std::string why = walk_step(*solver_, at, t0, t0 + 1.0, newton, predictor, x, record, depth);
    if (why.empty()) why = finisher_->finish(to, x, record);
    record.seconds = seconds_since(start);
    record.pair_passes = model::pair_passes() - passes_before;
    if (!why.empty()) {  // the last equilibrium stays
      solver_->restore(contact);
      result.message = "interactive step " + std::to_string(record.step) + ": " + why;
      return result;
    }
    previous_ = {from, summary_.unknowns};
    summary_.unknowns = x;
    point_ = to;
    ++steps_;
    result.success = true;
    return result;
  }

  const Model& model() const { return model_; }
  const Eigen::VectorXd& unknowns() const { return summary_.unknowns; }
  const LoadPoint& point() const { return point_; }
  int steps_taken() const { return steps_; }

 private:
  // The step's first guess. A move on in the direction of the last one (a
  // hand pressing on, a load turned further up) extrapolates the last two
  // equilibria linearly by the moves' lengths; a move that turns, stops or
  // comes first starts from the last equilibrium alone (*extrapolate false).
  // With newton.predictor false, always the last equilibrium.
  PathPredictor start_predictor(const LoadPoint& from, const LoadPoint& to,
                                bool* extrapolate) const {
    const double t0 = steps_;
    PathPredictor predictor(1);
    *extrapolate = false;
    if (options_.newton.predictor && previous_) {
      const Eigen::VectorXd ahead = flattened(to) - flattened(from),
                            behind = flattened(from) - flattened(previous_->point);
      const double a = ahead.norm(), b = behind.norm();
      if (a > 0.0 && b > 0.0 && ahead.dot(behind) >= 0.999 * a * b) {
        predictor.add(t0 - b / a, previous_->unknowns);  // where the last move started
        *extrapolate = true;
      }
    }
    predictor.add(t0, summary_.unknowns);
    return predictor;
  }

  // `requested` with its sizes and values checked, the held values filled in.
  LoadPoint checked(const LoadPoint& requested) const {
    const auto size_error = [](const std::string& what, size_t given, size_t expected) {
      return InputError("interactive step: " + what + ": " + std::to_string(given) +
                        " given, the model has " + std::to_string(expected));
    };
    LoadPoint to = requested;
    if (to.factors.size() != model_.loads.size())
      throw size_error("load factors", to.factors.size(), model_.loads.size());
    if (to.planes.size() != model_.paddles.size())
      throw size_error("paddle planes", to.planes.size(), model_.paddles.size());
    const Eigen::Index held = static_cast<Eigen::Index>(model_.dim()) * model_.num_vertices();
    if (to.held_values.size() == 0) to.held_values = Eigen::VectorXd::Zero(held);
    if (to.held_values.size() != held)
      throw size_error("held values (dim times vertices)",
                       static_cast<size_t>(to.held_values.size()), static_cast<size_t>(held));
    if (!all_finite(to.factors) || !all_finite(to.planes) || !to.held_values.allFinite())
      throw InputError("interactive step: a load factor, paddle plane or held value is not finite");
    const std::string why = planes_problem(model_, to.planes);
    if (!why.empty()) throw InputError("interactive step: " + why);
    return to;
  }

  const Model& model_;
  SteppingOptions options_;
  SteppingSummary summary_;  // the last equilibrium in its unknowns
  model::DofPartition partition_;
  std::unique_ptr<NewtonSolver> solver_;
  std::unique_ptr<StepFinisher> finisher_;
  struct Equilibrium {
    LoadPoint point;
    Eigen::VectorXd unknowns;
  };
  std::optional<Equilibrium> previous_;  // the one before the last, for the predictor
  LoadPoint point_;
  int steps_ = 0;
};

InteractiveStepper::InteractiveStepper(const model::Model& model, const SteppingOptions& options)
    : impl_(std::make_unique<Impl>(model, options)) {}
InteractiveStepper::~InteractiveStepper() = default;
InteractiveStepper::Result InteractiveStepper::step(const LoadPoint& to) { return impl_->step(to); }
const model::Model& InteractiveStepper::model() const { return impl_->model(); }
const Eigen::VectorXd& InteractiveStepper::unknowns() const { return impl_->unknowns(); }
Eigen::MatrixXd InteractiveStepper::positions() const {
  return model::positions(impl_->model(), impl_->unknowns());
}
const LoadPoint& InteractiveStepper::point() const { return impl_->point(); }
int InteractiveStepper::steps_taken() const { return impl_->steps_taken(); }

}  // namespace fiberfluid::solve
