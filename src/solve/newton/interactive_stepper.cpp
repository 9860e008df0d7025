// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/solve/newton/interactive_stepper.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>

#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/solve/newton/contact_set.hpp"
#include "fiberfluid/solve/newton/newton_solver.hpp"
#include "fiberfluid/solve/newton/path_walk.hpp"
#include "fiberfluid/solve/newton/step_finisher.hpp"
#include "fiberfluid/solve/stepping_common.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::solve {

using model::Model;

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
    Status setup = check_setup(model, options_);
    if (setup.ok) setup = check_paddle_start(model);
    if (!setup.ok) throw InputError("interactive stepper: " + setup.message);
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
    if (const Status planes = check_planes(model_, to.planes); !planes.ok)
      throw InputError("interactive step: " + planes.message);
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
