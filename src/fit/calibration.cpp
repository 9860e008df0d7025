// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fit/calibration.hpp"

#include <ceres/jet.h>
#include <ceres/rotation.h>

#include <Eigen/Cholesky>
#include <Eigen/SVD>
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>

#include "fiberfluid/fit/optimizers.hpp"
#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/util/error.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::fit {
namespace {

using Jet = ceres::Jet<double, 3>;

// The rigid alignment of the targets, T(p) = R(omega) p + t, with the
// derivatives of its action on one point by the rotation vector (Jets).
// A similarity: distances in the target's frame are 1/scale of the body's.
struct Alignment {
  Eigen::Vector3d rotation = Eigen::Vector3d::Zero(), translation = Eigen::Vector3d::Zero();
  double scale = 1.0;

  // T(p) = s R p + t and dT(p)/domega (3 x 3).
  Eigen::Vector3d apply(const Eigen::Vector3d& p, Eigen::Matrix3d* d_rotation) const {
    const Eigen::Vector3d q = scale * rotate(rotation, p, d_rotation) + translation;
    if (d_rotation) *d_rotation *= scale;
    return q;
  }
  // T^-1(x) = R^T (x - t) / s, with d/domega (3 x 3); d/dt is -R^T / s.
  Eigen::Vector3d inverse(const Eigen::Vector3d& x, Eigen::Matrix3d* d_rotation) const {
    Eigen::Matrix3d d;
    const Eigen::Vector3d q = rotate(-rotation, x - translation, &d) / scale;
    if (d_rotation) *d_rotation = -d / scale;  // the rotation vector enters with a minus sign
    return q;
  }
  Eigen::Matrix3d inverse_rotation() const {
    Eigen::Matrix3d R;
    for (int a = 0; a < 3; ++a) {
      Eigen::Vector3d e = Eigen::Vector3d::Unit(a);
      R.col(a) = rotate(-rotation, e, nullptr);
    }
    return R;
  }

  static Eigen::Vector3d rotate(const Eigen::Vector3d& omega, const Eigen::Vector3d& p,
                                Eigen::Matrix3d* d_omega) {
    Jet w[3], pt[3], out[3];
    for (int a = 0; a < 3; ++a) {
      w[a] = Jet(omega[a], a);
      pt[a] = Jet(p[a]);
    }
    ceres::AngleAxisRotatePoint(w, pt, out);
    Eigen::Vector3d q;
    for (int a = 0; a < 3; ++a) {
      q[a] = out[a].a;
      if (d_omega) d_omega->row(a) = out[a].v.transpose();
    }
    return q;
  }
};

// The unit direction of the distance from c to q; at zero distance, the
// normal of the triangle (or nothing, for a point cloud).
Eigen::Vector3d direction(const Eigen::Vector3d& q, const Eigen::Vector3d& c, const Target& target,
                          int primitive) {
  const Eigen::Vector3d d = q - c;
  const double norm = d.norm();
  if (norm > 0.0) return d / norm;
  if (target.is_point_cloud()) return Eigen::Vector3d::Zero();
  const Eigen::Vector3i t = target.triangles.row(primitive).transpose();
  const Eigen::Vector3d a = target.points.row(t[0]), b = target.points.row(t[1]),
                        e = target.points.row(t[2]);
  return (b - a).cross(e - a).normalized();
}

// The force a curve reads from a step's record: its paddle's or its
// support group's (before the curve's sign convention).
Eigen::Vector3d curve_force_vector(const ForceCurve& curve, const solve::StepRecord& record) {
  const size_t i = static_cast<size_t>(curve.index);
  if (curve.source == ForceCurve::Source::Paddle)
    return i < record.paddles.size() ? record.paddles[i].force : Eigen::Vector3d::Zero();
  return i < record.reactions.size() ? record.reactions[i] : Eigen::Vector3d::Zero();
}

Eigen::Vector3d bounding_low(const Eigen::MatrixXd& P) {
  return P.colwise().minCoeff().transpose();
}
Eigen::Vector3d bounding_high(const Eigen::MatrixXd& P) {
  return P.colwise().maxCoeff().transpose();
}

}  // namespace

const char* to_string(Method method) {
  switch (method) {
    case Method::LevenbergMarquardt:
      return "levenberg-marquardt";
    case Method::Bobyqa:
      return "bobyqa";
    case Method::DirectL:
      return "direct-l";
    case Method::Crs2:
      return "crs2";
  }
  return "?";
}

const char* to_string(Loss loss) {
  switch (loss) {
    case Loss::Squared:
      return "squared";
    case Loss::Huber:
      return "huber";
    case Loss::Cauchy:
      return "cauchy";
  }
  return "?";
}

Method method_from_string(const std::string& name) {
  for (Method m : {Method::LevenbergMarquardt, Method::Bobyqa, Method::DirectL, Method::Crs2})
    if (name == to_string(m)) return m;
  throw InputError("method: expected levenberg-marquardt, bobyqa, direct-l or crs2, got \"" +
                   name.substr(0, 40) + "\"");
}

Loss loss_from_string(const std::string& name) {
  for (Loss l : {Loss::Squared, Loss::Huber, Loss::Cauchy})
    if (name == to_string(l)) return l;
  throw InputError("loss: expected squared, huber or cauchy, got \"" + name.substr(0, 40) + "\"");
}

void check_options(const FitOptions& o) {
  auto positive = [](const char* name, double x, double largest, const char* what) {
    if (!(x > 0.0 && x <= largest)) {
      std::ostringstream message;
      message << name << ": expected " << what << ", got " << x;
      throw InputError(message.str());
    }
  };
  positive("difference_step", o.difference_step, 0.5,
           "a step in the fitted variable above 0 and at most 0.5 (a share of the value, or of "
           "its logarithm)");
  positive("loss_scale", o.loss_scale, std::numeric_limits<double>::max(),
           "a positive finite length in m");
  positive("function_tolerance", o.function_tolerance, 1.0, "a relative change in (0, 1]");
  positive("parameter_tolerance", o.parameter_tolerance, 1.0, "a relative change in (0, 1]");
  positive("initial_trust_region_radius", o.initial_trust_region_radius,
           std::numeric_limits<double>::max(), "a positive finite number");
  if (!(o.max_step_factor > 1.0 && o.max_step_factor <= std::numeric_limits<double>::max()))
    throw InputError("max_step_factor: expected a finite factor above 1, got " +
                     std::to_string(o.max_step_factor));
  if (o.max_iterations < 1 || o.max_iterations > 100000)
    throw InputError("max_iterations: expected 1 to 100000, got " +
                     std::to_string(o.max_iterations));
  if (o.max_evaluations < 1 || o.max_evaluations > 10000000)
    throw InputError("max_evaluations: expected 1 to 10000000, got " +
                     std::to_string(o.max_evaluations));
}

// Where a force curve's row reads the run: F = (1 - s) F(k0) + s F(k1),
// with F(0) = 0 (the unloaded reference).
struct CurveRow {
  int k0 = 0, k1 = 0;
  double s = 0.0;
};

struct Calibration::Impl {
  model::Model model;
  solve::SteppingOptions stepping;
  std::vector<MeasuredStep> targets;
  std::vector<ForceCurve> curves;
  std::vector<std::vector<CurveRow>> curve_rows;  // per curve, per row
  std::vector<double> curve_weights;              // m per N, as used
  std::vector<int> force_steps;                   // the distinct steps the curves read (>= 1)
  std::vector<int> state_steps;                   // target_steps and force_steps
  std::vector<TargetDistance> distances;          // one per target
  ParameterMap map;
  FitOptions options;
  std::vector<int> counted;       // model vertices whose distances count
  std::vector<int> target_steps;  // the distinct steps, ascending
  bool analytic = true;
  bool warm_starts = false;  // Calibration::warm_starts()
  double length = 0.0;
  int residuals = 0;

  Impl(model::Model m, solve::SteppingOptions s, std::vector<MeasuredStep> t,
       std::vector<Parameter> p, FitOptions o, std::vector<ForceCurve> c)
      : model(std::move(m)),
        stepping(std::move(s)),
        targets(std::move(t)),
        curves(std::move(c)),
        map(std::move(p), model.material, model.dim()),
        options(std::move(o)) {
    check_options(options);
  }
};

namespace {

// The rows of a force curve: where each reads the run. Throws InputError
// naming the curve for a step outside the run, a travel the run does not
// reach, or a travel that does not change with every step.
std::vector<CurveRow> plan_curve(const ForceCurve& curve, const model::Model& model, int steps) {
  std::vector<CurveRow> rows;
  if (curve.by_step) {
    for (size_t r = 0; r < curve.at.size(); ++r) {
      const double k = curve.at[r];
      if (!(k >= 1 && k <= steps && k == std::floor(k))) {
        std::ostringstream why;
        why << curve.label << ": row " << r + 1 << ": step " << k
            << " is not one of the run's steps 1.." << steps;
        throw InputError(why.str());
      }
      rows.push_back({static_cast<int>(k), static_cast<int>(k), 0.0});
    }
    return rows;
  }
  std::vector<double> travel(static_cast<size_t>(steps) + 1);
  for (int k = 0; k <= steps; ++k)
    travel[static_cast<size_t>(k)] = curve_travel(curve, model, k, steps);
  const double direction = travel[1] > travel[0] ? 1.0 : -1.0;  // as the first step goes
  for (int k = 1; k <= steps; ++k) {
    const double change = travel[static_cast<size_t>(k)] - travel[static_cast<size_t>(k) - 1];
    if (!(direction * change > 0.0)) {
      std::ostringstream why;
      why << curve.label << ": the travel does not move on with every step (step " << k << ": from "
          << travel[static_cast<size_t>(k) - 1] << " to " << travel[static_cast<size_t>(k)]
          << " m): rows cannot be placed by travel; tie them to steps (a step column)";
      throw InputError(why.str());
    }
  }
  for (size_t r = 0; r < curve.at.size(); ++r) {
    const double t = curve.at[r];
    int k = 0;
    while (k < steps && direction * (t - travel[static_cast<size_t>(k) + 1]) > 0.0) ++k;
    if (k == steps || direction * (t - travel[static_cast<size_t>(k)]) < 0.0) {
      std::ostringstream why;
      why << curve.label << ": row " << r + 1 << ": travel " << t
          << " m is outside the run's, from " << travel.front() << " to " << travel.back() << " m";
      throw InputError(why.str());
    }
    const double low = travel[static_cast<size_t>(k)], high = travel[static_cast<size_t>(k) + 1];
    rows.push_back({k, k + 1, (t - low) / (high - low)});
  }
  return rows;
}

}  // namespace

Calibration::Calibration(model::Model model, solve::SteppingOptions stepping,
                         std::vector<MeasuredStep> targets, std::vector<Parameter> parameters,
                         FitOptions options, std::vector<ForceCurve> force_curves)
    : impl_(std::make_unique<Impl>(std::move(model), std::move(stepping), std::move(targets),
                                   std::move(parameters), std::move(options),
                                   std::move(force_curves))) {
  Impl& m = *impl_;
  if (m.model.dim() != 3) throw InputError("calibration fits 3D surfaces; this model is 2D");
  if (m.targets.empty() && m.curves.empty())
    throw InputError("nothing to fit to: no target surface and no force curve");
  const int n = m.model.num_vertices();
  if (m.options.counted_vertices.empty()) {
    for (int i = 0; i < n; ++i) m.counted.push_back(i);
  } else {
    m.counted = m.options.counted_vertices;
    std::sort(m.counted.begin(), m.counted.end());
    m.counted.erase(std::unique(m.counted.begin(), m.counted.end()), m.counted.end());
    if (m.counted.front() < 0 || m.counted.back() >= n)
      throw InputError(
          "counted vertices: vertex " +
          std::to_string(m.counted.front() < 0 ? m.counted.front() : m.counted.back()) +
          " does not exist (the model has " + std::to_string(n) + ")");
  }
  const Eigen::MatrixXd& V = m.model.surface.V;
  const Eigen::Vector3d low = bounding_low(V), high = bounding_high(V);
  m.length = (high - low).maxCoeff();
  for (const MeasuredStep& t : m.targets) {
    if (t.step < 1 || t.step > m.stepping.steps)
      throw InputError(t.target.label + ": tied to load step " + std::to_string(t.step) +
                       ", but the run has steps 1.." + std::to_string(m.stepping.steps));
    // A scan may be unregistered, but it must be near the body to be fitted.
    const Eigen::Vector3d margin = Eigen::Vector3d::Constant(0.5 * m.length);
    const Eigen::Vector3d t_low = bounding_low(t.target.points),
                          t_high = bounding_high(t.target.points);
    if (((t_low.array() > (high + margin).array()) || (t_high.array() < (low - margin).array()))
            .any())
      throw InputError(t.target.label +
                       ": the target does not overlap the body (its bounding box "
                       "lies more than half the body's length away): wrong units or another "
                       "specimen?");
    // Nor of another size altogether: a scan in mm against a body in m.
    const double size = (t_high - t_low).maxCoeff();
    if (size > 10.0 * m.length || size < 0.01 * m.length) {
      std::ostringstream why;
      why << t.target.label << ": the target is " << size / m.length << " times the body's size ("
          << size << " against " << m.length << " m): wrong units? (give the scan's \"units\" "
          << "or \"scale\")";
      throw InputError(why.str());
    }
    m.distances.emplace_back(t.target);
    if (std::find(m.target_steps.begin(), m.target_steps.end(), t.step) == m.target_steps.end())
      m.target_steps.push_back(t.step);
    m.residuals += static_cast<int>(m.counted.size());
    if (m.options.symmetric) m.residuals += static_cast<int>(t.target.points.rows());
  }
  std::sort(m.target_steps.begin(), m.target_steps.end());
  for (const ForceCurve& curve : m.curves) {
    const std::string why = force_curve_problem(curve, m.model);
    if (!why.empty()) throw InputError(curve.label + ": " + why);
    m.curve_rows.push_back(plan_curve(curve, m.model, m.stepping.steps));
    for (const CurveRow& row : m.curve_rows.back())
      for (int k : {row.k0, row.k1})
        if (k >= 1) m.force_steps.push_back(k);
    double largest = 0.0;
    for (const double f : curve.force) largest = std::max(largest, std::abs(f));
    if (curve.weight == 0.0 && largest == 0.0)
      throw InputError(curve.label +
                       ": every measured force is 0: give the curve a weight (m per N)");
    m.curve_weights.push_back(curve.weight > 0.0 ? curve.weight : m.length / largest);
    m.residuals += static_cast<int>(curve.force.size());
  }
  std::sort(m.force_steps.begin(), m.force_steps.end());
  m.force_steps.erase(std::unique(m.force_steps.begin(), m.force_steps.end()), m.force_steps.end());
  std::set_union(m.target_steps.begin(), m.target_steps.end(), m.force_steps.begin(),
                 m.force_steps.end(), std::back_inserter(m.state_steps));
  m.analytic = !m.options.finite_differences && m.stepping.scheme == solve::Scheme::Newton &&
               solve::sensitivity_problem(m.model).empty();
  if (m.residuals < m.map.size())
    throw InputError("fewer distances (" + std::to_string(m.residuals) + ") than parameters (" +
                     std::to_string(m.map.size()) + ")");
  m.stepping.keep_final_tangent = false;
  {
    solve::SteppingOptions probe = m.stepping;  // any start of the right size
    probe.warm_start = Eigen::VectorXd::Zero(m.model.dim() * m.model.num_vertices() + 1);
    m.warm_starts = m.options.warm_start && m.stepping.scheme == solve::Scheme::Newton &&
                    m.state_steps == std::vector<int>{m.stepping.steps} &&
                    solve::warm_start_problem(m.model, probe).empty();
  }
  // The material with the starts, so that model() shows what the fit begins from.
  m.model.material = m.map.material(m.model.material, m.map.values(m.map.initial_phi()));
  const std::string why = m.model.material.law.check();
  if (!why.empty()) throw InputError("the starting material: " + why);
}

Calibration::~Calibration() = default;

const ParameterMap& Calibration::parameters() const { return impl_->map; }
const FitOptions& Calibration::options() const { return impl_->options; }
const model::Model& Calibration::model() const { return impl_->model; }
bool Calibration::analytic_jacobian() const { return impl_->analytic; }
bool Calibration::warm_starts() const { return impl_->warm_starts; }
int Calibration::num_residuals() const { return impl_->residuals; }
int Calibration::num_counted_vertices() const { return static_cast<int>(impl_->counted.size()); }
double Calibration::body_length() const { return impl_->length; }
const std::vector<ForceCurve>& Calibration::force_curves() const { return impl_->curves; }
double Calibration::force_weight(size_t curve) const { return impl_->curve_weights.at(curve); }

double Calibration::cost(const Eigen::VectorXd& r) const {
  const double d = impl_->options.loss_scale, d2 = d * d;
  double sum = 0.0;
  for (Eigen::Index i = 0; i < r.size(); ++i) {
    const double s = r[i] * r[i];
    switch (impl_->options.loss) {
      case Loss::Squared:
        sum += s;
        break;
      case Loss::Huber:
        sum += s <= d2 ? s : 2.0 * d * std::sqrt(s) - d2;
        break;  // Ceres' HuberLoss
      case Loss::Cauchy:
        sum += d2 * std::log1p(s / d2);
        break;  // Ceres' CauchyLoss
    }
  }
  return 0.5 * sum;
}

namespace {

// The record of step k in a run (a warm-started run holds its last step only).
const solve::StepRecord& record_of(const solve::SteppingSummary& summary, int k) {
  for (const solve::StepRecord& record : summary.steps)
    if (record.step == k) return record;
  throw std::logic_error("calibration: the run has no record of step " + std::to_string(k));
}

}  // namespace

Evaluation Calibration::evaluate(const Eigen::VectorXd& phi, bool with_jacobian,
                                 const Eigen::VectorXd& warm_start) const {
  solve::SteppingOptions stepping = impl_->stepping;
  if (impl_->warm_starts) stepping.warm_start = warm_start;
  return evaluate_with(phi, with_jacobian, std::move(stepping), false);
}

namespace {

// The stiffest start tried: the moduli and gamma 2, 4, ... this many times
// the start's (stiffer_start; the probe keeps its states for each).
constexpr double kStiffest = 1024.0;

// The step of n nearest the load share 1/s (at least 1): where the start
// stiffened s times ends on the start's own path (stiffer_start).
long step_at_share(int n, double s) { return std::max(1L, std::lround(n / s)); }

// The steps nearest n/2, n/4, ... n/1024: where a start probe's run is kept,
// for the starts stiffened 2, 4, ... 1024 times.
bool near_a_halving(int step, int n) {
  for (double s = 2.0; s <= kStiffest; s *= 2.0)
    if (step_at_share(n, s) == step) return true;
  return false;
}

}  // namespace

Evaluation Calibration::evaluate_with(const Eigen::VectorXd& phi, bool with_jacobian,
                                      solve::SteppingOptions stepping,
                                      bool keep_path_states) const {
  const Impl& m = *impl_;
  const ParameterMap& map = m.map;
  const int P = map.size(), nv = m.model.num_vertices();
  Evaluation e;
  const Eigen::VectorXd values = map.values(phi);
  model::Model changed = m.model;
  changed.material = map.material(m.model.material, values);
  const std::string bad_law = changed.material.law.check();
  if (!bad_law.empty()) {
    e.message = "the material at these parameters: " + bad_law;
    return e;
  }
  // Sensitivities du/dtheta of the states at the target steps: from the
  // Newton stepper, or central differences of whole runs in phi.
  const bool sensitivities_wanted = with_jacobian && !map.material_names().empty();
  if (sensitivities_wanted && m.analytic)
    stepping.sensitivities = {map.material_names(), m.state_steps};
  // Per step read: the state, and each force curve's force.
  struct StepState {
    Eigen::VectorXd x;
    std::vector<double> forces;
  };
  std::map<int, StepState> states;
  auto run = [&](const model::Model& model, const solve::SteppingOptions& options,
                 std::map<int, StepState>& at) {
    return solve::solve_load_steps(
        model, options, [&](const solve::StepRecord& r, const Eigen::VectorXd& x) {
          if (keep_path_states && near_a_halving(r.step, options.steps)) e.path_states[r.step] = x;
          if (!std::binary_search(m.state_steps.begin(), m.state_steps.end(), r.step)) return;
          StepState& state = at[r.step];
          state.x = x;
          for (const ForceCurve& curve : m.curves)
            state.forces.push_back(curve_force(curve, model, curve_force_vector(curve, r)));
        });
  };
  e.summary = run(changed, stepping, states);
  e.forward_runs = 1;
  e.warm_started_runs = e.summary.warm_started ? 1 : 0;
  if (!e.summary.success) {
    e.message = e.summary.message;
    return e;
  }
  e.path_states.clear();  // only a failed probe's are wanted
  const Eigen::VectorXd dvalue = map.value_derivatives(phi);
  const int nm = static_cast<int>(map.material_names().size());
  std::map<int, Eigen::MatrixXd> sensitivity;  // per target step: #unknowns x material parameters
  // Per step read, per force curve: dF/dtheta (material parameters).
  std::map<int, std::vector<Eigen::RowVectorXd>> force_sensitivity;
  if (sensitivities_wanted && m.analytic) {
    for (int step : m.state_steps) {
      const solve::StepRecord& record = record_of(e.summary, step);
      sensitivity[step] = record.sensitivities;
      e.sensitivity_solves += static_cast<int>(sensitivity[step].cols());
      for (const ForceCurve& curve : m.curves) {
        const Eigen::MatrixXd& d =
            curve.source == ForceCurve::Source::Paddle
                ? record.paddles[static_cast<size_t>(curve.index)].force_sensitivities
                : record.reaction_sensitivities[static_cast<size_t>(curve.index)];
        Eigen::RowVectorXd row(nm);
        for (int j = 0; j < nm; ++j) {
          Eigen::Vector3d column = d.col(j);
          row[j] = curve_force(curve, changed, column);
        }
        force_sensitivity[step].push_back(row);
      }
    }
  } else if (sensitivities_wanted) {
    for (int step : m.state_steps) {
      sensitivity[step].resize(states.at(step).x.size(), nm);
      force_sensitivity[step].assign(m.curves.size(), Eigen::RowVectorXd(nm));
    }
    for (int j = 0; j < nm; ++j) {
      const int k = map.material_indices()[static_cast<size_t>(j)];
      const double h = m.options.difference_step * std::max(1.0, std::abs(phi[k]));
      std::map<int, StepState> plus, minus;
      for (double sign : {1.0, -1.0}) {
        Eigen::VectorXd shifted = phi;
        shifted[k] += sign * h;
        model::Model moved = m.model;
        moved.material = map.material(m.model.material, map.values(shifted));
        solve::SteppingOptions shifted_stepping = m.stepping;
        if (m.warm_starts) shifted_stepping.warm_start = e.summary.unknowns;  // phi's, next door
        const solve::SteppingSummary s = run(moved, shifted_stepping, sign > 0 ? plus : minus);
        ++e.forward_runs;
        e.warm_started_runs += s.warm_started ? 1 : 0;
        if (!s.success) {
          e.message = "a finite-difference run failed: " + s.message;
          return e;
        }
      }
      for (int step : m.state_steps) {  // du/dtheta, as the stepper gives it
        const double denominator = 2.0 * h * dvalue[k];
        sensitivity[step].col(j) = (plus.at(step).x - minus.at(step).x) / denominator;
        for (size_t c = 0; c < m.curves.size(); ++c)
          force_sensitivity[step][c][j] =
              (plus.at(step).forces[c] - minus.at(step).forces[c]) / denominator;
      }
    }
  }
  // The chain through the closest points is the same for both kinds of sensitivity.
  Alignment align;
  map.alignment(values, &align.rotation, &align.translation, &align.scale);
  const Eigen::Matrix3d R_inverse = align.inverse_rotation();
  e.residuals.resize(m.residuals);
  if (with_jacobian) e.jacobian = Eigen::MatrixXd::Zero(m.residuals, P);

  // d x_i / d phi_k for the material parameters, 3 x P (zero columns elsewhere).
  auto vertex_sensitivity = [&](const Eigen::MatrixXd& S, int i) {
    Eigen::Matrix<double, 3, Eigen::Dynamic> dx = Eigen::MatrixXd::Zero(3, P);
    for (size_t j = 0; j < map.material_indices().size(); ++j) {
      const int k = map.material_indices()[j];
      for (int a = 0; a < 3; ++a)
        dx(a, k) = S(a * nv + i, static_cast<Eigen::Index>(j)) * dvalue[k];
    }
    return dx;
  };
  // Adds the alignment's columns: d residual / d (rotation, translation) =
  // n . dq (dq in the body's frame), and d residual / d scale.
  auto add_alignment = [&](Eigen::Index row, const Eigen::Vector3d& n,
                           const Eigen::Matrix3d& dq_domega, const Eigen::Matrix3d& dq_dt,
                           double d_scale) {
    for (int a = 0; a < 3; ++a) {
      const int r = map.alignment_index(a), t = map.alignment_index(3 + a);
      if (r >= 0) e.jacobian(row, r) += n.dot(dq_domega.col(a)) * dvalue[r];
      if (t >= 0) e.jacobian(row, t) += n.dot(dq_dt.col(a)) * dvalue[t];
    }
    const int s = map.alignment_index(6);
    if (s >= 0) e.jacobian(row, s) += d_scale * dvalue[s];
  };

  Eigen::Index row = 0;
  for (size_t t = 0; t < m.targets.size(); ++t) {
    const int step = m.targets[t].step;
    const Eigen::MatrixXd X = model::positions(changed, states.at(step).x);
    e.positions.push_back(X);
    const Eigen::MatrixXd* S = sensitivity.count(step) ? &sensitivity.at(step) : nullptr;
    const Target& target = m.targets[t].target;
    // Forward: each counted vertex, taken into the target's frame, to the target.
    Eigen::MatrixXd queries(static_cast<Eigen::Index>(m.counted.size()), 3);
    std::vector<Eigen::Matrix3d> dq_domega(m.counted.size());
    for (size_t c = 0; c < m.counted.size(); ++c)
      queries.row(static_cast<Eigen::Index>(c)) =
          align.inverse(X.row(m.counted[c]).transpose(), &dq_domega[c]).transpose();
    const std::vector<TargetDistance::Closest> hits = m.distances[t].closest(queries);
    // The distance in the body's frame: s times the one in the target's
    // (T is a similarity), so that both directions measure alike.
    for (size_t c = 0; c < m.counted.size(); ++c, ++row) {
      const Eigen::Vector3d q = queries.row(static_cast<Eigen::Index>(c)).transpose();
      e.residuals[row] = align.scale * hits[c].distance;
      if (!with_jacobian) continue;
      const Eigen::Vector3d n = direction(q, hits[c].point, target, hits[c].primitive);
      if (S)
        e.jacobian.row(row) += n.transpose() * R_inverse * vertex_sensitivity(*S, m.counted[c]);
      add_alignment(row, n, align.scale * dq_domega[c], -R_inverse, hits[c].distance - n.dot(q));
    }
    if (!m.options.symmetric) continue;
    // Symmetric: each target point, taken into the body's frame, to the simulated surface.
    const Target simulated = make_target("the simulated surface", X, changed.surface.F);
    if (simulated.triangles.rows() != changed.surface.F.rows() || simulated.points.rows() != nv) {
      e.message = "a simulated face collapsed to zero area";
      return e;
    }
    const TargetDistance to_simulated(simulated);
    const Eigen::Index np = target.points.rows();
    Eigen::MatrixXd moved(np, 3);
    std::vector<Eigen::Matrix3d> dp_domega(static_cast<size_t>(np));
    for (Eigen::Index j = 0; j < np; ++j)
      moved.row(j) =
          align.apply(target.points.row(j).transpose(), &dp_domega[static_cast<size_t>(j)])
              .transpose();
    const std::vector<TargetDistance::Closest> back = to_simulated.closest(moved);
    for (Eigen::Index j = 0; j < np; ++j, ++row) {
      const TargetDistance::Closest& hit = back[static_cast<size_t>(j)];
      e.residuals[row] = hit.distance;
      if (!with_jacobian) continue;
      const Eigen::Vector3d p = moved.row(j).transpose();
      const Eigen::Vector3d n = direction(p, hit.point, simulated, hit.primitive);
      // make_target keeps every vertex of a closed surface in order, so the
      // simulated triangle's corners are model vertices.
      const Eigen::Vector3i corners = simulated.triangles.row(hit.primitive).transpose();
      const Eigen::Vector3d b = geom::barycentric_coordinates(
          hit.point, X.row(corners[0]).transpose(), X.row(corners[1]).transpose(),
          X.row(corners[2]).transpose());
      if (S)
        for (int k = 0; k < 3; ++k)
          e.jacobian.row(row) -= b[k] * n.transpose() * vertex_sensitivity(*S, corners[k]);
      add_alignment(row, n, dp_domega[static_cast<size_t>(j)], Eigen::Matrix3d::Identity(),
                    n.dot(p - align.translation) / align.scale);  // dT(p)/ds = R p
    }
  }

  // The force curves: w (F(t) - F_measured), F between the steps around t.
  for (size_t c = 0; c < m.curves.size(); ++c) {
    const ForceCurve& curve = m.curves[c];
    const double w = m.curve_weights[c];
    e.forces.emplace_back();
    for (size_t r = 0; r < curve.force.size(); ++r, ++row) {
      const CurveRow& at = m.curve_rows[c][r];
      double force = 0.0;
      Eigen::RowVectorXd gradient = Eigen::RowVectorXd::Zero(nm);
      for (const auto& [k, share] : {std::pair{at.k0, 1.0 - at.s}, std::pair{at.k1, at.s}}) {
        if (k == 0 || share == 0.0) continue;  // the unloaded reference: no force
        force += share * states.at(k).forces[c];
        if (with_jacobian && nm > 0) gradient += share * force_sensitivity.at(k)[c];
      }
      e.forces.back().push_back(force);
      e.residuals[row] = w * (force - curve.force[r]);
      if (!with_jacobian) continue;
      for (int j = 0; j < nm; ++j) {
        const int k = map.material_indices()[static_cast<size_t>(j)];
        e.jacobian(row, k) = w * gradient[j] * dvalue[k];
      }
    }
  }

  e.ok = e.residuals.allFinite() && (!with_jacobian || e.jacobian.allFinite());
  if (!e.ok) e.message = "non-finite distances or forces";
  return e;
}

namespace {

// A failure's message with its numbers taken out, so that failures of one
// kind count together: "step 3: runaway: face 12 turned over" ->
// "step #: runaway: face # turned over".
std::string failure_cause(const std::string& message) {
  std::string cause;
  for (size_t i = 0; i < message.size(); ++i) {
    const char ch = message[i];
    const bool digit = std::isdigit(static_cast<unsigned char>(ch)) != 0;
    const bool in_number =
        digit || ((ch == '.' || ch == 'e' || ch == '-' || ch == '+') && !cause.empty() &&
                  cause.back() == '#' && i + 1 < message.size() &&
                  std::isdigit(static_cast<unsigned char>(message[i + 1])));
    if (!in_number)
      cause += ch;
    else if (cause.empty() || cause.back() != '#')
      cause += '#';
  }
  return cause;
}

}  // namespace

std::deque<EvaluationCache::Entry>::const_iterator EvaluationCache::find(const Eigen::VectorXd& phi,
                                                                         bool with_jacobian) const {
  return std::find_if(kept_.begin(), kept_.end(), [&](const Entry& entry) {
    if (entry.phi.size() != phi.size() || entry.phi != phi) return false;
    // A point whose forward run failed fails with a Jacobian too: one run.
    if (with_jacobian) return entry.has_jacobian || !entry.evaluation.ok;
    // A point whose finite-difference runs failed still has valid residuals
    // in its Jacobian-free entry: a failed Jacobian must not hide them.
    return !entry.has_jacobian || entry.evaluation.ok;
  });
}

const Evaluation* EvaluationCache::kept(const Eigen::VectorXd& phi, bool with_jacobian) const {
  const auto entry = find(phi, with_jacobian);
  return entry == kept_.end() ? nullptr : &entry->evaluation;
}

const Evaluation& EvaluationCache::at(const Eigen::VectorXd& phi, bool with_jacobian) {
  if (const auto entry = find(phi, with_jacobian); entry != kept_.end()) {
    const auto position = kept_.begin() + (entry - kept_.cbegin());
    if (position != kept_.begin()) std::rotate(kept_.begin(), position, std::next(position));
    return kept_.front().evaluation;
  }
  return count({phi, with_jacobian, calibration_.evaluate(phi, with_jacobian, nearest_state(phi))},
               true);
}

const Evaluation* EvaluationCache::add(const Eigen::VectorXd& phi, bool with_jacobian,
                                       Evaluation evaluation) {
  const bool keep = evaluation.ok;
  const Evaluation& counted = count({phi, with_jacobian, std::move(evaluation)}, keep);
  return keep ? &counted : nullptr;
}

const Evaluation& EvaluationCache::count(Entry entry, bool keep) {
  forward_runs += entry.evaluation.forward_runs;
  warm_started_runs += entry.evaluation.warm_started_runs;
  sensitivity_solves += entry.evaluation.sensitivity_solves;
  // A run cut short by an interrupt did not fail: it is neither counted nor
  // kept (the same point may be run again later).
  if (!entry.evaluation.ok && cancel_requested()) return interrupted_ = entry.evaluation;
  if (!entry.evaluation.ok) {
    ++failed_runs;
    last_failure = entry.evaluation.message;
    ++failures_by_cause[failure_cause(last_failure)];
    if (failed_examples.size() < kKeptFailures)
      failed_examples.push_back({calibration_.parameters().values(entry.phi), last_failure});
  }
  if (!keep) return unkept_ = std::move(entry.evaluation);
  kept_.push_front(std::move(entry));
  if (kept_.size() > kKept) kept_.pop_back();
  return kept_.front().evaluation;
}

Eigen::VectorXd EvaluationCache::nearest_state(const Eigen::VectorXd& phi) const {
  if (!calibration_.warm_starts()) return {};
  const Entry* nearest = nullptr;
  for (const Entry& entry : kept_)
    if (entry.evaluation.ok && entry.phi.size() == phi.size() &&
        (nearest == nullptr || (entry.phi - phi).norm() < (nearest->phi - phi).norm()))
      nearest = &entry;
  return nearest != nullptr ? nearest->evaluation.summary.unknowns : Eigen::VectorXd();
}

const char* to_string(FitStatus status) {
  switch (status) {
    case FitStatus::Converged:
      return "converged";
    case FitStatus::ConvergedAtBounds:
      return "converged_at_bounds";
    case FitStatus::IterationLimit:
      return "iteration_limit";
    case FitStatus::NotIdentifiable:
      return "not_identifiable";
    case FitStatus::ForwardRunsFailed:
      return "forward_runs_failed";
    case FitStatus::StartFailed:
      return "start_failed";
    case FitStatus::OptimizerFailed:
      return "optimizer_failed";
    case FitStatus::Interrupted:
      return "interrupted";
  }
  return "?";
}

namespace {

// Why a Jacobian cannot separate its parameters: a column that is zero or
// not finite (no distance changes with that parameter), else the
// combination its smallest singular value leaves unseen.
std::string unidentifiable_because(const Eigen::MatrixXd& J,
                                   const std::vector<std::string>& names) {
  for (Eigen::Index k = 0; k < J.cols(); ++k) {
    if (!J.col(k).allFinite())
      return "the derivatives of the distances by \"" + names[static_cast<size_t>(k)] +
             "\" are not finite";
    if (J.col(k).norm() == 0.0)
      return "no distance changes with \"" + names[static_cast<size_t>(k)] +
             "\" (does the load act? is difference_step large enough to move the result?)";
  }
  if (J.cols() < 2) return "the Jacobian is rank deficient";
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeThinV);
  const Eigen::VectorXd v = svd.matrixV().col(J.cols() - 1);
  std::string which;
  for (Eigen::Index k = 0; k < v.size(); ++k)
    if (std::abs(v[k]) >= 0.3)
      which += (which.empty() ? "\"" : ", \"") + names[static_cast<size_t>(k)] + "\"";
  return "the distances cannot tell " + which +
         " apart (the Jacobian is rank deficient): fix "
         "one of them, or add targets that separate them";
}

}  // namespace

void Calibration::describe_at(const Evaluation& best, FitResult& result) const {
  const Impl& m = *impl_;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  result.final_cost = cost(best.residuals);
  result.summary = best.summary;
  result.positions = best.positions;
  result.vertex_distances.clear();  // described afresh (a warm start's check describes twice)
  result.statistics.clear();
  result.force_misfits.clear();
  const int nv = m.model.num_vertices();
  Eigen::Index row = 0;
  std::vector<double> all;
  for (size_t t = 0; t < m.targets.size(); ++t) {
    Eigen::VectorXd per_vertex = Eigen::VectorXd::Constant(nv, nan);
    Eigen::VectorXd counted(static_cast<Eigen::Index>(m.counted.size()));
    for (size_t c = 0; c < m.counted.size(); ++c, ++row) {
      per_vertex[m.counted[c]] = best.residuals[row];
      counted[static_cast<Eigen::Index>(c)] = best.residuals[row];
      all.push_back(best.residuals[row]);
    }
    if (m.options.symmetric) row += m.targets[t].target.points.rows();
    result.vertex_distances.push_back(per_vertex);
    result.statistics.push_back(distance_statistics(counted, m.length));
  }
  result.overall = distance_statistics(
      Eigen::Map<const Eigen::VectorXd>(all.data(), static_cast<Eigen::Index>(all.size())),
      m.length);
  for (size_t c = 0; c < m.curves.size(); ++c) {
    ForceMisfit misfit;
    misfit.simulated = best.forces[c];
    misfit.weight = m.curve_weights[c];
    double squares = 0.0;
    for (size_t r = 0; r < misfit.simulated.size(); ++r) {
      const double miss = misfit.simulated[r] - m.curves[c].force[r];
      squares += miss * miss;
      misfit.largest = std::max(misfit.largest, std::abs(miss));
      misfit.scale = std::max(misfit.scale, std::abs(m.curves[c].force[r]));
    }
    misfit.rms = std::sqrt(squares / static_cast<double>(misfit.simulated.size()));
    result.force_misfits.push_back(misfit);
  }
}

void Calibration::check_along_path(const Eigen::VectorXd& phi, const Evaluation& warm,
                                   FitResult& result) const {
  const Evaluation path = evaluate(phi, false);
  if (!path.ok) {
    if (cancel_requested()) return;
    result.warm_start_note = "the run along the load path at the fitted values failed (" +
                             path.message +
                             "): the fit's warm-started equilibrium is not reached from the "
                             "unloaded body";
    return;
  }
  // Both are equilibria to Newton's tolerance: the same one agrees far below
  // the distances' scale; another one (a branch) differs at it.
  const double gap = (path.residuals - warm.residuals).lpNorm<Eigen::Infinity>();
  const double scale = std::max(warm.residuals.lpNorm<Eigen::Infinity>(), 1e-9 * impl_->length);
  if (gap > 1e-4 * scale) {
    std::ostringstream note;
    note << "the run along the load path at the fitted values differs from the warm-started one "
            "by up to "
         << gap << " m in a residual (the residuals reach " << scale
         << " m): another equilibrium; the path's is reported (fit with \"warm_start\": false)";
    result.warm_start_note = note.str();
  }
  describe_at(path, result);  // the path's run: every step's record
}

// A linearised interval is the quadratic model's: where a parameter's
// effect fades (gamma far below what the load feels, so the cost flattens
// as it goes to zero) the quadratic closes an interval the data leave open,
// and the truth can lie outside it. Each end is checked on the profile
// likelihood (Venzon and Moolgavkar 1988, Appl. Stat. 37:87; Raue et al.
// 2009, Bioinformatics 25:1923): phi_k moved by t, the other parameters
// re-fitted by Gauss-Newton steps. The 95% level is a rise of the cost by
// chi^2_1(0.95)/2 s^2 (s^2 the residual variance). Where the profile at the
// linearised end has risen by less than half of it, the end is moved out:
// by doubling (to the bound, where the cost never rises enough), then by
// interpolation in sqrt(rise), which is linear for a quadratic cost. An end
// is only moved out: a re-fit that stops early leaves the profile above its
// true value, so it can show that an end lies further out, never that it
// lies further in.
void Calibration::check_interval_ends(EvaluationCache& evaluations, const Eigen::VectorXd& phi,
                                      const Eigen::MatrixXd& covariance, double variance,
                                      FitResult& result) const {
  const Impl& m = *impl_;
  const int P = m.map.size();
  const Eigen::VectorXd lower = m.map.lower_phi(), upper = m.map.upper_phi();
  const double level = 0.5 * 3.841458820694124 * variance;
  constexpr double kSmallest = 1e-4;  // a half-width in phi below which rounding rules the rise
  constexpr int kDoublings = 10, kRefinements = 3, kRefits = 3, kRunsPerParameter = 8;
  const bool refit = m.analytic && P > 1;  // else the others stay at the optimum
  // How far one move may take each other parameter: a log-scaled one by
  // max_step_factor (as a Levenberg-Marquardt step), a linear one by its
  // linearised 95% half-width (nothing for one on its bound). A parameter
  // the data barely see has a huge variance, and an uncapped move would
  // throw the run far off, to where it may not even run.
  Eigen::VectorXd reach(P);
  for (int j = 0; j < P; ++j)
    reach[j] = on_bound(phi[j], lower[j], upper[j]) ? 0.0
               : m.map.parameters()[static_cast<size_t>(j)].log_scale
                   ? std::log(m.options.max_step_factor)
                   : 1.96 * std::sqrt(std::max(0.0, variance * covariance(j, j)));
  // The checks' forward runs, at most kRunsPerParameter per parameter: past
  // it a profile point is not run, and an end moves out only as far as the
  // points already run show (each run's cost is an upper bound of the
  // profile there, so what they show holds).
  const int budget = kRunsPerParameter;
  result.interval_notes.assign(static_cast<size_t>(P), "");
  for (int k = 0; k < P && !cancel_requested(); ++k) {
    const int runs_before = evaluations.forward_runs;
    const Parameter& parameter = m.map.parameters()[static_cast<size_t>(k)];
    const double half = 1.96 * std::sqrt(std::max(0.0, variance * covariance(k, k)));
    if (on_bound(phi[k], lower[k], upper[k]) || !(half > kSmallest) || !(level > 0.0)) continue;
    const Eigen::VectorXd path = covariance.col(k) / covariance(k, k);  // the linearised profile
    auto value = [&](double phi_k) { return parameter.log_scale ? std::exp(phi_k) : phi_k; };
    std::ostringstream note;
    for (const int side : {-1, 1}) {
      const double farthest = side < 0 ? lower[k] - phi[k] : upper[k] - phi[k];
      auto clip = [&](double t) { return side < 0 ? std::max(t, farthest) : std::min(t, farthest); };
      auto capped = [&](const Eigen::VectorXd& from, Eigen::VectorXd to) {
        for (int j = 0; j < P; ++j)
          if (j != k) to[j] = from[j] + std::clamp(to[j] - from[j], -reach[j], reach[j]);
        return Eigen::VectorXd(to.cwiseMax(lower).cwiseMin(upper));
      };
      // The profile's rise at t (infinite where the run fails: no parameters
      // there), re-fitted from the nearest profile point already found (a
      // continuation along the profile), the first from the linearised one.
      std::vector<std::pair<double, Eigen::VectorXd>> found;  // (t, the re-fitted point)
      auto rise = [&](double t) {
        Eigen::VectorXd at = capped(phi, phi + t * path);
        const auto nearest = std::min_element(found.begin(), found.end(), [&](auto& a, auto& b) {
          return std::abs(a.first - t) < std::abs(b.first - t);
        });
        if (nearest != found.end()) {
          at = nearest->second;
          at[k] = std::clamp(phi[k] + t, lower[k], upper[k]);
        }
        double best = std::numeric_limits<double>::infinity();
        Eigen::VectorXd best_at = at;
        for (int step = 0; step <= kRefits && !cancel_requested(); ++step) {
          if (evaluations.forward_runs - runs_before >= budget) break;
          const bool more = refit && step < kRefits;
          const Evaluation& e = evaluations.at(at, more);
          if (!e.ok) break;
          const double before = best, here = cost(e.residuals) - result.final_cost;
          if (here < best) best = here, best_at = at;
          if (!more || before - here < 0.05 * level) {  // re-fitted, or as good as
            found.emplace_back(t, best_at);
            break;
          }
          Eigen::MatrixXd J = e.jacobian;
          J.col(k).setZero();  // phi_k stays where the profile puts it
          Eigen::MatrixXd H = J.transpose() * J;
          H(k, k) = 1.0;
          const Eigen::VectorXd g = J.transpose() * e.residuals;
          const Eigen::LDLT<Eigen::MatrixXd> normal(H);
          if (normal.info() != Eigen::Success) break;
          const Eigen::VectorXd move = normal.solve(g);
          if (0.5 * g.dot(move) < 0.05 * level) {  // the step would hardly gain: re-fitted
            found.emplace_back(t, best_at);
            break;
          }
          at = capped(at, at - move);
        }
        return best;
      };
      // The first probe goes at most two Levenberg-Marquardt steps out: the
      // linearised end of a parameter the data barely see lies decades
      // away, where runs are slow or fail.
      const double linearised = clip(side * half);
      const double first = clip(side * std::min(half, parameter.log_scale
                                                          ? 2.0 * std::log(m.options.max_step_factor)
                                                          : half));
      double t_in = first, rise_in = rise(t_in);
      if (!(rise_in < 0.5 * level)) continue;  // the profile's end lies inside the linearised one
      double t = t_in, r = rise_in;
      bool unbounded = false;
      for (int d = 0; d < kDoublings && r < level && !cancel_requested(); ++d) {
        if (t == farthest) {
          unbounded = true;
          break;
        }
        t_in = t, rise_in = r;
        t = clip(2.0 * t);
        r = rise(t);
      }
      if (r < level) unbounded = true;
      if (!unbounded && std::abs(t) <= std::abs(linearised)) continue;  // crossed inside it
      double end = t;
      if (!unbounded) {  // the crossing lies between t_in and t
        for (int i = 0; i < kRefinements && !cancel_requested(); ++i) {
          const double a = std::sqrt(std::max(0.0, rise_in));
          const double b = std::isfinite(r) ? std::sqrt(r) : 2.0 * std::sqrt(level) + a;
          double s = (std::sqrt(level) - a) / (b - a);
          s = std::clamp(std::isfinite(s) ? s : 0.5, 0.1, 0.9);  // keep the bracket shrinking
          const double mid = t_in + s * (t - t_in), r_mid = rise(mid);
          if (r_mid < level) {
            t_in = mid, rise_in = r_mid;
          } else {
            t = mid, r = r_mid;
          }
          if (std::abs(r_mid / level - 1.0) < 0.1) break;
        }
        end = t_in;  // the profile is below the level here: inside the 95% region
        if (std::abs(end) <= std::abs(linearised)) continue;  // none further out below the level
      }
      (side < 0 ? result.lower_95 : result.upper_95)[k] = value(phi[k] + end);
      note << (note.tellp() > 0 ? "; " : "") << (side < 0 ? "lower" : "upper") << " end ";
      if (unbounded)
        note << "at the " << (side < 0 ? "lower" : "upper") << " bound, " << value(phi[k] + end)
             << ": the cost rises by less than the 95% level out there (the data do not bound "
             << parameter.name << (side < 0 ? " from below" : " from above") << ")";
      else
        note << "moved out to at least " << value(phi[k] + end)
             << " (the cost rises more slowly than the quadratic's out to the linearised end, "
             << value(phi[k] + side * half) << ")";
    }
    result.interval_notes[static_cast<size_t>(k)] = note.str();
  }
}

FitResult Calibration::result_from(const Eigen::VectorXd& phi) const {
  const Impl& m = *impl_;
  const int P = m.map.size();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  FitResult result;
  result.method = m.options.method;
  result.analytic_jacobian = m.analytic;
  result.names = m.map.names();
  result.initial = result.values = m.map.values(phi);
  result.standard_errors = result.lower_95 = result.upper_95 = Eigen::VectorXd::Constant(P, nan);
  result.correlation = Eigen::MatrixXd::Constant(P, P, nan);
  result.initial_cost = result.final_cost = nan;
  return result;
}

FitResult Calibration::result_at(const Eigen::VectorXd& phi) const {
  FitResult result = result_from(phi);
  const Evaluation at = evaluate(phi, false);
  result.forward_runs = at.forward_runs;
  if (!at.ok) {
    result.status = cancel_requested() ? FitStatus::Interrupted : FitStatus::ForwardRunsFailed;
    result.message = "the forward run failed: " + at.message;
    return result;
  }
  describe_at(at, result);
  result.initial_cost = result.final_cost;
  result.status = FitStatus::Converged;
  result.success = true;
  return result;
}

FitResult Calibration::run() const { return run_from(impl_->map.initial_phi()); }

namespace {

// The fitted parameters that scale the body's stiffness: the law's moduli
// (Y, Y0, Y_t, Y_c), gamma and the axis factors.
bool scales_stiffness(const std::string& name) {
  return (!name.empty() && name[0] == 'Y') || name == "gamma" || name.rfind("factor_", 0) == 0;
}

// A start probe's limits: a step cut at most twice, a piece given at most 12
// Newton iterations. A start that needs more is too soft for its load more
// often than not, and a stiffer start costs less than the failing step's
// remaining cuts (the layered phantom from Y/5: the probe gives up after
// 72 s, the full run after 109 s).
constexpr int kProbeCuts = 2;
constexpr int kProbeIterations = 12;

}  // namespace

Evaluation Calibration::probe_start(const Eigen::VectorXd& phi, bool with_jacobian,
                                    const Eigen::VectorXd& warm_start) const {
  solve::SteppingOptions stepping = impl_->stepping;
  stepping.newton.max_step_cuts = std::min(stepping.newton.max_step_cuts, kProbeCuts);
  stepping.newton.max_iterations = std::min(stepping.newton.max_iterations, kProbeIterations);
  if (impl_->warm_starts) stepping.warm_start = warm_start;
  return evaluate_with(phi, with_jacobian, std::move(stepping), true);
}

// A forward run that fails at the start is most often a material too soft
// for its load: a face turns over, or the run runs away. With every modulus
// and gamma times s the equilibrium at the full load is the start's at 1/s
// of it (the pressure times s): the same body with the load divided by s.
// So the start is stiffened by 2, 4, ... 1024, within the bounds, and a
// stiffened start whose end the failed probe passed (its state at step n/s)
// is solved from there, warm; the others walk their paths (a runaway at a
// step too large for a soft body need not recur on a stiffer one). A body
// moved only by prescribed motions and paddles has nothing to stiffen
// against.
std::optional<Eigen::VectorXd> Calibration::stiffer_start(const Eigen::VectorXd& start_phi,
                                                          const Evaluation& failed_probe,
                                                          EvaluationCache& evaluations,
                                                          bool with_sensitivities,
                                                          double* factor) const {
  const Impl& m = *impl_;
  if (m.model.loads.empty()) return std::nullopt;
  const std::vector<Parameter>& parameters = m.map.parameters();
  const Eigen::VectorXd upper = m.map.upper_phi();
  std::vector<int> stiffness;
  for (int k = 0; k < m.map.size(); ++k)
    if (scales_stiffness(parameters[static_cast<size_t>(k)].name)) stiffness.push_back(k);
  if (stiffness.empty()) return std::nullopt;
  const Eigen::VectorXd start = m.map.values(start_phi);
  const int n = m.stepping.steps;
  for (double s = 2.0; s <= kStiffest && !cancel_requested(); s *= 2.0) {
    Eigen::VectorXd phi = start_phi;
    bool moved = false;
    for (int k : stiffness) {
      const Parameter& p = parameters[static_cast<size_t>(k)];
      const double value = s * start[k];
      const double wanted = p.log_scale ? std::log(value) : value;
      phi[k] = std::min(wanted, upper[k]);
      moved |= phi[k] > start_phi[k];
    }
    if (!moved) return std::nullopt;  // every stiffness on its upper bound
    Eigen::VectorXd warm;  // the probe's state at n/s, its pressure times s
    if (const auto at = failed_probe.path_states.find(static_cast<int>(step_at_share(n, s)));
        at != failed_probe.path_states.end()) {
      warm = at->second;
      warm[warm.size() - 1] *= s;
    }
    if (evaluations.add(phi, with_sensitivities, probe_start(phi, with_sensitivities, warm))) {
      *factor = s;
      return phi;
    }
  }
  return std::nullopt;
}

FitResult Calibration::run_from(const Eigen::VectorXd& start_phi) const {
  const Impl& m = *impl_;
  const auto start = std::chrono::steady_clock::now();
  const int P = m.map.size();
  // Sized from the start, whatever the ending: a report never reads past them.
  FitResult result = result_from(start_phi);
  EvaluationCache evaluations(*this);
  auto finish = [&](FitStatus status, std::string message) {
    result.status = status;
    result.success = converged(status);
    if (!message.empty()) result.message = std::move(message);
    result.forward_runs = evaluations.forward_runs;
    result.warm_started_runs = evaluations.warm_started_runs;
    result.sensitivity_solves = evaluations.sensitivity_solves;
    result.failed_runs = evaluations.failed_runs;
    result.failures_by_cause = evaluations.failures_by_cause;
    result.failed_examples = evaluations.failed_examples;
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
  };
  // The start, as Levenberg-Marquardt will ask for it (with analytic
  // sensitivities): a failure here is the user's to fix, not a rejected step.
  const bool levenberg_marquardt = m.options.method == Method::LevenbergMarquardt;
  Eigen::VectorXd phi0 = start_phi;
  const bool with_sensitivities = levenberg_marquardt && m.analytic;
  // A start too soft for its load fails fast in a probe, and a stiffer start
  // is looked for; only when none runs is the start run in full.
  if (evaluations.kept(start_phi, with_sensitivities) == nullptr) {
    const Evaluation probe = probe_start(start_phi, with_sensitivities);
    if (evaluations.add(start_phi, with_sensitivities, probe) == nullptr) {
      if (cancel_requested()) return finish(FitStatus::Interrupted, "interrupted at the start");
      double factor = 1.0;
      const std::optional<Eigen::VectorXd> stiffer =
          stiffer_start(start_phi, probe, evaluations, with_sensitivities, &factor);
      if (cancel_requested()) return finish(FitStatus::Interrupted, "interrupted at the start");
      if (stiffer) {
        phi0 = *stiffer;
        std::ostringstream note;
        note << "the forward run at the starting parameters failed, in a probe that gives up "
                "after "
             << kProbeCuts << " halvings of a step or " << kProbeIterations
             << " Newton iterations (" << probe.message
             << "); the fit started from the moduli and gamma times " << factor
             << ", the softest such start whose run succeeds";
        result.start_note = note.str();
      } else if (const Evaluation& given = evaluations.at(start_phi, with_sensitivities);
                 !given.ok) {
        if (cancel_requested()) return finish(FitStatus::Interrupted, "interrupted at the start");
        return finish(FitStatus::StartFailed,
                      "the forward run at the starting parameters failed: " + given.message +
                          (m.model.loads.empty()
                               ? ""
                               : " (and with the moduli and gamma up to 1024 times the start's, "
                                 "within their bounds)"));
      }
    }
  }
  const Evaluation& first = evaluations.at(phi0, with_sensitivities);
  result.initial_cost = cost(first.residuals);
  if (!std::isfinite(result.initial_cost))
    return finish(FitStatus::NotIdentifiable, "the cost at the start is not finite");

  const OptimizerOutcome outcome = levenberg_marquardt
                                       ? fit_levenberg_marquardt(evaluations, m.options, phi0)
                                       : fit_nlopt(evaluations, m.options, phi0);
  result.message = outcome.message;
  result.iterations = outcome.iterations;
  result.values = m.map.values(outcome.phi);
  if (!result.iterations.empty()) result.final_cost = result.iterations.back().cost;

  // At the optimum (usually kept from the optimiser): the run and the
  // distances. An interrupted fit takes only what it has already run.
  const Evaluation* kept = evaluations.kept(outcome.phi, false);
  if (outcome.status == FitStatus::Interrupted && (kept == nullptr || !kept->ok))
    return finish(FitStatus::Interrupted, "");
  const Evaluation best =
      kept != nullptr ? *kept : evaluations.at(outcome.phi, false);  // a copy: entries move
  if (!best.ok) {
    if (cancel_requested()) return finish(FitStatus::Interrupted, "");
    return finish(FitStatus::ForwardRunsFailed,
                  "the forward run at the fitted parameters failed: " + best.message);
  }
  describe_at(best, result);
  if (best.summary.warm_started) {
    check_along_path(outcome.phi, best, result);
    evaluations.forward_runs += 1;
  }
  // The parameters on a bound, said whatever the ending (a fit that ran out
  // of iterations against a bound is the usual sign of a wrong model).
  const Eigen::VectorXd lower = m.map.lower_phi(), upper = m.map.upper_phi();
  auto describe_bounds = [&](bool with_correlation) {
    result.at_bounds.clear();
    result.status_detail.clear();
    for (int k = 0; k < P; ++k) {
      const double phi = outcome.phi[k];
      if (!on_bound(phi, lower[k], upper[k])) continue;
      const std::string& name = result.names[static_cast<size_t>(k)];
      result.at_bounds.push_back(name);
      std::ostringstream why;
      why << name << " = " << result.values[k] << " is on its "
          << (phi - lower[k] <= upper[k] - phi ? "lower" : "upper") << " bound";
      int partner = -1;
      for (int j = 0; j < P && with_correlation; ++j)
        if (j != k && (partner < 0 || std::abs(result.correlation(k, j)) >
                                          std::abs(result.correlation(k, partner))))
          partner = j;
      if (partner >= 0)
        why << " (its correlation with " << result.names[static_cast<size_t>(partner)] << " is "
            << result.correlation(k, partner) << ")";
      result.status_detail += (result.status_detail.empty() ? "" : "; ") + why.str();
    }
  };
  describe_bounds(false);
  if (outcome.status != FitStatus::Converged) return finish(outcome.status, "");

  // Converged: is it an estimate? The covariance needs a full-rank Jacobian.
  Eigen::MatrixXd covariance;
  result.covariance_ok = phi_covariance(evaluations, m.options, outcome.phi, &covariance);
  if (cancel_requested()) return finish(FitStatus::Interrupted, "");
  if (!result.covariance_ok) {
    const Evaluation* with_jacobian = evaluations.kept(outcome.phi, true);
    result.status_detail =
        with_jacobian != nullptr && with_jacobian->ok
            ? unidentifiable_because(with_jacobian->jacobian, result.names)
            : "the Jacobian at the optimum could not be evaluated: " + evaluations.last_failure;
    return finish(FitStatus::NotIdentifiable, "");
  }
  const int dof = m.residuals - P;
  const double variance = dof > 0 ? 2.0 * result.final_cost / dof : 0.0;
  const Eigen::MatrixXd scaled = variance * covariance;
  for (int k = 0; k < P; ++k)
    for (int j = 0; j < P; ++j) {
      const double denominator = std::sqrt(covariance(k, k) * covariance(j, j));
      result.correlation(k, j) = denominator > 0.0 ? covariance(k, j) / denominator : 0.0;
    }
  describe_bounds(true);
  for (int k = 0; k < P; ++k) {
    if (on_bound(outcome.phi[k], lower[k], upper[k]))
      continue;  // a bound is no estimate: no standard error
    const double sigma = std::sqrt(std::max(0.0, scaled(k, k)));
    const bool log = m.map.parameters()[static_cast<size_t>(k)].log_scale;
    const double phi = outcome.phi[k];
    result.standard_errors[k] = log ? result.values[k] * sigma : sigma;
    result.lower_95[k] = log ? std::exp(phi - 1.96 * sigma) : phi - 1.96 * sigma;
    result.upper_95[k] = log ? std::exp(phi + 1.96 * sigma) : phi + 1.96 * sigma;
  }
  if (m.options.check_intervals) {
    const int runs_before = evaluations.forward_runs;
    check_interval_ends(evaluations, outcome.phi, covariance, variance, result);
    result.interval_runs = evaluations.forward_runs - runs_before;
    if (cancel_requested()) return finish(FitStatus::Interrupted, "");
  }
  return finish(result.at_bounds.empty() ? FitStatus::Converged : FitStatus::ConvergedAtBounds, "");
}

}  // namespace fiberfluid::fit
