// SPDX-License-Identifier: GPL-3.0-or-later
// Arc-length continuation (Crisfield 1981, the cylindrical constraint): the
// load factor is an unknown, so the path is traced through a limit point
// where the load peaks.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "fiberfluid/solve/newton/newton_solver.hpp"
#include "fiberfluid/util/progress.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::solve {

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
std::string NewtonSolver::follow_arc_length(int n, SteppingSummary& summary, const KeepStep& keep) {
  Eigen::VectorXd& x = summary.unknowns;
  const model::DofMap dofs = held_map();
  const Eigen::Index m = dofs.num_reduced() - 1;  // the displacements (the pressure last)
  Eigen::VectorXd previous = dofs.reduce(x);      // the last step's increment (from 0)
  const double first_arc = previous.head(m).norm();
  if (!(first_arc > 0.0)) return "newton.control arc_length: the first step did not move the body";
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
  return "arc length: the final load was not reached in " + std::to_string(newton_.max_arc_steps) +
         " steps (newton.max_arc_steps; load factor " + std::to_string(t / n) + ")" +
         limit_note(summary);
}

// The largest t of the parabola through the path's last three points (arc
// length, t): the limit load between the points, where the path turned.
double NewtonSolver::parabola_peak(const std::vector<std::array<double, 2>>& path) {
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
std::string NewtonSolver::limit_note(const SteppingSummary& summary) {
  if (std::isnan(summary.limit_load_factor)) return {};
  std::ostringstream out;
  out << "; a limit point: the load peaked at " << summary.limit_load_factor
      << " of the final load (the body cannot carry more along this path)";
  return out.str();
}

// The load factors at a path parameter t, the end segments extended
// beyond [0, n] (an arc-length corrector may step past the final load).
std::vector<double> NewtonSolver::factors_at(double t, int n) const {
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
Eigen::VectorXd NewtonSolver::path_derivative(const model::DofMap& dofs, const Eigen::VectorXd& x,
                                              double t, int n, bool ahead) const {
  double lo = ahead ? std::floor(t) : std::ceil(t) - 1.0;
  lo = std::clamp(lo, 0.0, n - 1.0);
  const Eigen::VectorXd difference = equilibrium_->external_forces(x, factors_at(lo, n)) -
                                     equilibrium_->external_forces(x, factors_at(lo + 1.0, n));
  return dofs.reduce(difference);
}

// One arc-length step from (x0, t0): the predictor along du/dt, then
// corrections that keep |x - x0| = arc on the displacements (the root of
// the constraint's quadratic closest to the step's direction). "" or why not.
std::string NewtonSolver::arc_step(int n, const model::DofMap& dofs, const Eigen::VectorXd& x0,
                                   double t0, double arc, const Eigen::VectorXd& previous,
                                   double previous_dt, Eigen::VectorXd* x, double* t,
                                   StepRecord& record) {
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
  std::string why = solve_with_tangent(
      x0, t0, -path_derivative(dofs, x0, t0, n, previous_dt >= 0.0), newton_.krylov_tolerance, &v);
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

}  // namespace fiberfluid::solve
