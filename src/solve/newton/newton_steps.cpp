// SPDX-License-Identifier: GPL-3.0-or-later
// The Newton scheme's run along the load path: its checks, the warm start,
// the steps by load control (then, by arc length, on to the final load).
#include "fiberfluid/solve/newton/newton.hpp"

#include <algorithm>
#include <memory>

#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/model/line_measure.hpp"
#include "fiberfluid/model/loads.hpp"
#include "fiberfluid/solve/newton/contact_set.hpp"
#include "fiberfluid/solve/newton/newton_solver.hpp"
#include "fiberfluid/solve/newton/path_walk.hpp"
#include "fiberfluid/solve/newton/step_finisher.hpp"
#include "fiberfluid/solve/stepping_common.hpp"
#include "fiberfluid/util/error.hpp"
#include "fiberfluid/util/progress.hpp"

namespace fiberfluid::solve {

using model::Model;

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

// The first paddle that holds a vertex where it touched (sticking or
// Coulomb contact), or null.
const model::Paddle* paddle_holding_where_touched(const Model& model) {
  for (const model::Paddle& paddle : model.paddles)
    if (paddle.holds_where_touched()) return &paddle;
  return nullptr;
}

// How a paddle holds what it touched, for a message.
std::string how_it_holds(const model::Paddle& paddle) {
  return paddle.sticking() ? " sticks: it holds" : " has Coulomb friction: it holds or slides";
}

}  // namespace

Status check_sensitivities(const Model& model) {
  if (const model::Paddle* paddle = paddle_holding_where_touched(model))
    return Status::failure("paddle " + paddle->label + how_it_holds(*paddle) +
                           " each vertex from where it touched, a place that moves with the "
                           "parameters (fit with finite differences)");
  return {};
}

Status check_warm_start(const Model& model, const SteppingOptions& options) {
  if (options.warm_start.size() == 0) return {};
  if (options.scheme != Scheme::Newton)
    return Status::failure("a warm start needs the Newton scheme");
  if (options.newton.control != NewtonOptions::Control::Load)
    return Status::failure(
        "a warm start needs load control (arc length follows the path from its start)");
  const Eigen::Index expected = static_cast<Eigen::Index>(model.dim()) * model.num_vertices() + 1;
  if (options.warm_start.size() != expected)
    return Status::failure("expected " + std::to_string(expected) +
                           " unknowns (displacements and pressure), got " +
                           std::to_string(options.warm_start.size()));
  if (!options.warm_start.allFinite()) return Status::failure("the start has non-finite values");
  if (const model::Paddle* paddle = paddle_holding_where_touched(model))
    return Status::failure(
        "paddle " + paddle->label + how_it_holds(*paddle) +
        " each vertex from where it touched, which depends on the way there, so the end of "
        "the path cannot be solved from elsewhere");
  return {};
}

namespace {

// Whether the path can be followed by arc length (why not): the arc-length
// constraint acts on the loads' factor, so the held values must not move
// along the path (prescribed motions and paddles are displacement control).
Status check_arc_length(const Model& model, int steps) {
  if (!model.paddles.empty())
    return Status::failure(
        "newton.control arc_length: paddles move the body by displacement, which load "
        "control already follows; use control \"load\"");
  for (int k = 1; k <= steps; ++k)
    if (model::constrained_displacements(model, k, steps).cwiseAbs().maxCoeff() > 0.0)
      return Status::failure(
          "newton.control arc_length: a prescribed displacement or rotation moves along the "
          "path; arc length follows loads only (use control \"load\")");
  if (model.loads.empty())
    return Status::failure("newton.control arc_length: there is no load to follow");
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

// A step that fails on a body whose fibers are in tension at rest: its rest
// state is a saddle on a mesh, which the failure is most likely about.
std::string rest_tension_note(const model::Model& model) {
  if (model.material.law.rest_tension() == 0.0) return "";
  return "; the " + model.material.law.name() +
         " law's fibers are in tension at rest, balanced by the fluid's pressure, and that rest "
         "state is not stable on a mesh: a load that is not symmetric (gravity, a clamp, a "
         "point load) leaves it at the first step (docs/model.md, \"The neo-Hookean network\")";
}

}  // namespace

SteppingSummary solve_newton_steps(const model::Model& model, const SteppingOptions& options,
                                   const StepObserver& observer) {
  const Clock::time_point start = Clock::now();
  SteppingSummary summary = empty_summary(model, Scheme::Newton);
  auto fail = [&](const std::string& why) { return failed(summary, why, start); };
  const bool by_arc = options.newton.control == NewtonOptions::Control::ArcLength;
  // Each check once the ones before passed: the paddles' schedule needs valid steps.
  Status setup = check_setup(model, options);
  if (setup.ok) setup = check_paddles(model, options.steps);
  if (setup.ok && by_arc) setup = check_arc_length(model, options.steps);
  if (!setup.ok) return fail(setup.message);
  for (const std::string& name : options.sensitivities.parameters)
    if (!model.material.has_parameter(name, model.dim()))
      return fail("sensitivities: \"" + name + "\" is not a parameter of the material");
  if (!options.sensitivities.parameters.empty())
    if (const Status s = check_sensitivities(model); !s.ok)
      return fail("sensitivities: " + s.message);
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
    if (const Status s = check_warm_start(model, options); !s.ok)
      return fail("warm_start: " + s.message);
    if (solve_from_warm_start(*solver, finisher, options.warm_start, n, keep, summary)) {
      summary.success = true;
      summary.total_seconds = seconds_since(start);
      return summary;
    }
  }

  // A law with a rest tension is at rest an equilibrium at the pressure that
  // balances it (line_measure.hpp): the path starts there, not at P = 0.
  x[model.pressure_dof()] = model::rest_pressure(model.material.law.rest_tension());
  PathPredictor predictor(options.newton.predictor ? 2 : 0);
  predictor.add(0.0, x);
  report_progress("step", 0, n);
  std::string why;
  int depth = 0;  // the pieces' halvings, carried from step to step
  // Load control: each step to t = k (t = 1 only, the arc's first step, by arc length).
  for (int k = 1; k <= (by_arc ? 1 : n); ++k) {
    const Clock::time_point step_start = Clock::now();
    StepRecord record;
    record.step = k;
    why = walk_step(
        *solver, [&](double t) { return scheduled_point(model, t, n); }, k - 1.0, k, options.newton,
        predictor, x, record, depth);
    if (!why.empty())
      return fail("step " + std::to_string(k) + ": " + why + rest_tension_note(model));
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

}  // namespace fiberfluid::solve
