// SPDX-License-Identifier: GPL-3.0-or-later
#include "fit/calibration.hpp"

#include <ceres/jet.h>
#include <ceres/rotation.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>

#include "fit/optimizers.hpp"
#include "geom/error.hpp"
#include "model/assembly.hpp"

namespace fiberfluid::fit {
namespace {

using Jet = ceres::Jet<double, 3>;

// The rigid alignment of the targets, T(p) = R(omega) p + t, with the
// derivatives of its action on one point by the rotation vector (Jets).
struct Alignment {
  Eigen::Vector3d rotation = Eigen::Vector3d::Zero(), translation = Eigen::Vector3d::Zero();

  // T(p) and dT(p)/domega (3 x 3).
  Eigen::Vector3d apply(const Eigen::Vector3d& p, Eigen::Matrix3d* d_rotation) const {
    return rotate(rotation, p, d_rotation) + translation;
  }
  // T^-1(x) = R^T (x - t), with d/domega (3 x 3); d/dt is -R^T.
  Eigen::Vector3d inverse(const Eigen::Vector3d& x, Eigen::Matrix3d* d_rotation) const {
    Eigen::Matrix3d d;
    const Eigen::Vector3d q = rotate(-rotation, x - translation, &d);
    if (d_rotation) *d_rotation = -d;  // the rotation vector enters with a minus sign
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

// The barycentric coordinates of c in the triangle (a, b, e).
Eigen::Vector3d barycentric(const Eigen::Vector3d& c, const Eigen::Vector3d& a,
                            const Eigen::Vector3d& b, const Eigen::Vector3d& e) {
  const Eigen::Vector3d u = b - a, v = e - a, w = c - a;
  const double uu = u.dot(u), uv = u.dot(v), vv = v.dot(v), wu = w.dot(u), wv = w.dot(v);
  const double det = uu * vv - uv * uv;
  const double s = (vv * wu - uv * wv) / det, t = (uu * wv - uv * wu) / det;
  return {1.0 - s - t, s, t};
}

Eigen::Vector3d bounding_low(const Eigen::MatrixXd& P) { return P.colwise().minCoeff().transpose(); }
Eigen::Vector3d bounding_high(const Eigen::MatrixXd& P) { return P.colwise().maxCoeff().transpose(); }

}  // namespace

const char* to_string(Method method) {
  switch (method) {
    case Method::LevenbergMarquardt: return "levenberg-marquardt";
    case Method::Bobyqa: return "bobyqa";
    case Method::DirectL: return "direct-l";
    case Method::Crs2: return "crs2";
  }
  return "?";
}

const char* to_string(Loss loss) {
  switch (loss) {
    case Loss::Squared: return "squared";
    case Loss::Huber: return "huber";
    case Loss::Cauchy: return "cauchy";
  }
  return "?";
}

struct Calibration::Impl {
  model::Model model;
  solve::SteppingOptions stepping;
  std::vector<MeasuredStep> targets;
  std::vector<TargetDistance> distances;  // one per target
  ParameterMap map;
  FitOptions options;
  std::vector<int> counted;               // model vertices whose distances count
  std::vector<int> target_steps;          // the distinct steps, ascending
  bool analytic = true;
  double length = 0.0;
  int residuals = 0;

  Impl(model::Model m, solve::SteppingOptions s, std::vector<MeasuredStep> t,
       std::vector<Parameter> p, FitOptions o)
      : model(std::move(m)),
        stepping(std::move(s)),
        targets(std::move(t)),
        map(std::move(p), model.material, model.dim()),
        options(std::move(o)) {}
};

Calibration::Calibration(model::Model model, solve::SteppingOptions stepping,
                         std::vector<MeasuredStep> targets, std::vector<Parameter> parameters,
                         FitOptions options)
    : impl_(std::make_unique<Impl>(std::move(model), std::move(stepping), std::move(targets),
                                   std::move(parameters), std::move(options))) {
  Impl& m = *impl_;
  if (m.model.dim() != 3) throw InputError("calibration fits 3D surfaces; this model is 2D");
  if (m.targets.empty()) throw InputError("nothing to fit to: no target surface");
  const int n = m.model.num_vertices();
  if (m.options.counted_vertices.empty()) {
    for (int i = 0; i < n; ++i) m.counted.push_back(i);
  } else {
    m.counted = m.options.counted_vertices;
    std::sort(m.counted.begin(), m.counted.end());
    m.counted.erase(std::unique(m.counted.begin(), m.counted.end()), m.counted.end());
    if (m.counted.front() < 0 || m.counted.back() >= n)
      throw InputError("counted vertices: vertex " +
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
    const Eigen::Vector3d t_low = bounding_low(t.target.points), t_high = bounding_high(t.target.points);
    if (((t_low.array() > (high + margin).array()) || (t_high.array() < (low - margin).array())).any())
      throw InputError(t.target.label + ": the target does not overlap the body (its bounding box "
                       "lies more than half the body's length away): wrong units or another "
                       "specimen?");
    m.distances.emplace_back(t.target);
    if (std::find(m.target_steps.begin(), m.target_steps.end(), t.step) == m.target_steps.end())
      m.target_steps.push_back(t.step);
    m.residuals += static_cast<int>(m.counted.size());
    if (m.options.symmetric) m.residuals += static_cast<int>(t.target.points.rows());
  }
  std::sort(m.target_steps.begin(), m.target_steps.end());
  m.analytic = !m.options.finite_differences && m.stepping.scheme == solve::Scheme::Newton;
  if (m.residuals < m.map.size())
    throw InputError("fewer distances (" + std::to_string(m.residuals) + ") than parameters (" +
                     std::to_string(m.map.size()) + ")");
  m.stepping.keep_final_tangent = false;
  // The material with the starts, so that model() shows what the fit begins from.
  m.model.material = m.map.material(m.model.material, m.map.values(m.map.initial_phi()));
  const std::string why = m.model.material.law.check();
  if (!why.empty()) throw InputError("the starting material: " + why);
}

Calibration::~Calibration() = default;

const ParameterMap& Calibration::parameters() const { return impl_->map; }
const model::Model& Calibration::model() const { return impl_->model; }
bool Calibration::analytic_jacobian() const { return impl_->analytic; }
int Calibration::num_residuals() const { return impl_->residuals; }
double Calibration::body_length() const { return impl_->length; }

double Calibration::cost(const Eigen::VectorXd& r) const {
  const double d = impl_->options.loss_scale, d2 = d * d;
  double sum = 0.0;
  for (Eigen::Index i = 0; i < r.size(); ++i) {
    const double s = r[i] * r[i];
    switch (impl_->options.loss) {
      case Loss::Squared: sum += s; break;
      case Loss::Huber: sum += s <= d2 ? s : 2.0 * d * std::sqrt(s) - d2; break;  // Ceres' HuberLoss
      case Loss::Cauchy: sum += d2 * std::log1p(s / d2); break;                    // Ceres' CauchyLoss
    }
  }
  return 0.5 * sum;
}

Evaluation Calibration::evaluate(const Eigen::VectorXd& phi, bool with_jacobian) const {
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
  solve::SteppingOptions stepping = m.stepping;
  if (sensitivities_wanted && m.analytic)
    stepping.sensitivities = {map.material_names(), m.target_steps};
  std::map<int, Eigen::VectorXd> states;
  auto run = [&](const model::Model& model, const solve::SteppingOptions& options,
                 std::map<int, Eigen::VectorXd>& at) {
    return solve::solve_load_steps(model, options,
                                   [&](const solve::StepRecord& r, const Eigen::VectorXd& x) {
                                     if (std::binary_search(m.target_steps.begin(),
                                                            m.target_steps.end(), r.step))
                                       at[r.step] = x;
                                   });
  };
  e.summary = run(changed, stepping, states);
  e.forward_runs = 1;
  if (!e.summary.success) {
    e.message = e.summary.message;
    return e;
  }
  const Eigen::VectorXd dvalue = map.value_derivatives(phi);
  std::map<int, Eigen::MatrixXd> sensitivity;  // per target step: #unknowns x material parameters
  if (sensitivities_wanted && m.analytic) {
    for (int step : m.target_steps) {
      sensitivity[step] = e.summary.steps[static_cast<size_t>(step - 1)].sensitivities;
      e.sensitivity_solves += static_cast<int>(sensitivity[step].cols());
    }
  } else if (sensitivities_wanted) {
    const int nm = static_cast<int>(map.material_names().size());
    for (int step : m.target_steps) sensitivity[step].resize(states.at(step).size(), nm);
    for (int j = 0; j < nm; ++j) {
      const int k = map.material_indices()[static_cast<size_t>(j)];
      const double h = m.options.difference_step * std::max(1.0, std::abs(phi[k]));
      std::map<int, Eigen::VectorXd> plus, minus;
      for (double sign : {1.0, -1.0}) {
        Eigen::VectorXd shifted = phi;
        shifted[k] += sign * h;
        model::Model moved = m.model;
        moved.material = map.material(m.model.material, map.values(shifted));
        const solve::SteppingSummary s = run(moved, m.stepping, sign > 0 ? plus : minus);
        ++e.forward_runs;
        if (!s.success) {
          e.message = "a finite-difference run failed: " + s.message;
          return e;
        }
      }
      for (int step : m.target_steps)  // du/dtheta, as the stepper gives it
        sensitivity[step].col(j) = (plus.at(step) - minus.at(step)) / (2.0 * h * dvalue[k]);
    }
  }
  // The chain through the closest points is the same for both kinds of sensitivity.
  Alignment align;
  map.alignment(values, &align.rotation, &align.translation);
  const Eigen::Matrix3d R_inverse = align.inverse_rotation();
  e.residuals.resize(m.residuals);
  if (with_jacobian) e.jacobian = Eigen::MatrixXd::Zero(m.residuals, P);

  // d x_i / d phi_k for the material parameters, 3 x P (zero columns elsewhere).
  auto vertex_sensitivity = [&](const Eigen::MatrixXd& S, int i) {
    Eigen::Matrix<double, 3, Eigen::Dynamic> dx = Eigen::MatrixXd::Zero(3, P);
    for (size_t j = 0; j < map.material_indices().size(); ++j) {
      const int k = map.material_indices()[j];
      for (int a = 0; a < 3; ++a) dx(a, k) = S(a * nv + i, static_cast<Eigen::Index>(j)) * dvalue[k];
    }
    return dx;
  };
  // Adds the alignment's columns: d residual / d (rotation, translation) = n . dq.
  auto add_alignment = [&](Eigen::Index row, const Eigen::Vector3d& n, const Eigen::Matrix3d& dq_domega,
                           const Eigen::Matrix3d& dq_dt) {
    for (int a = 0; a < 3; ++a) {
      const int r = map.alignment_index(a), t = map.alignment_index(3 + a);
      if (r >= 0) e.jacobian(row, r) += n.dot(dq_domega.col(a)) * dvalue[r];
      if (t >= 0) e.jacobian(row, t) += n.dot(dq_dt.col(a)) * dvalue[t];
    }
  };

  Eigen::Index row = 0;
  for (size_t t = 0; t < m.targets.size(); ++t) {
    const int step = m.targets[t].step;
    const Eigen::MatrixXd X = model::positions(changed, states.at(step));
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
    for (size_t c = 0; c < m.counted.size(); ++c, ++row) {
      const Eigen::Vector3d q = queries.row(static_cast<Eigen::Index>(c)).transpose();
      e.residuals[row] = hits[c].distance;
      if (!with_jacobian) continue;
      const Eigen::Vector3d n = direction(q, hits[c].point, target, hits[c].primitive);
      if (S) e.jacobian.row(row) += n.transpose() * R_inverse * vertex_sensitivity(*S, m.counted[c]);
      add_alignment(row, n, dq_domega[c], -R_inverse);
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
      moved.row(j) = align.apply(target.points.row(j).transpose(), &dp_domega[static_cast<size_t>(j)]).transpose();
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
      const Eigen::Vector3d b = barycentric(hit.point, X.row(corners[0]).transpose(),
                                            X.row(corners[1]).transpose(), X.row(corners[2]).transpose());
      if (S)
        for (int k = 0; k < 3; ++k)
          e.jacobian.row(row) -= b[k] * n.transpose() * vertex_sensitivity(*S, corners[k]);
      add_alignment(row, n, dp_domega[static_cast<size_t>(j)], Eigen::Matrix3d::Identity());
    }
  }

  e.ok = e.residuals.allFinite() && (!with_jacobian || e.jacobian.allFinite());
  if (!e.ok) e.message = "non-finite distances";
  return e;
}

const Evaluation& EvaluationCache::at(const Eigen::VectorXd& phi, bool with_jacobian) {
  for (auto entry = kept_.begin(); entry != kept_.end(); ++entry)
    if (entry->phi.size() == phi.size() && entry->phi == phi &&
        (entry->has_jacobian || !with_jacobian)) {
      if (entry != kept_.begin()) std::rotate(kept_.begin(), entry, std::next(entry));
      return kept_.front().evaluation;
    }
  Entry entry{phi, with_jacobian, calibration_.evaluate(phi, with_jacobian)};
  forward_runs += entry.evaluation.forward_runs;
  sensitivity_solves += entry.evaluation.sensitivity_solves;
  if (!entry.evaluation.ok) ++failed_runs;
  kept_.push_front(std::move(entry));
  if (kept_.size() > kKept) kept_.pop_back();
  return kept_.front().evaluation;
}

FitResult Calibration::run() const {
  const Impl& m = *impl_;
  const auto start = std::chrono::steady_clock::now();
  FitResult result;
  result.method = m.options.method;
  result.analytic_jacobian = m.analytic;
  result.names = m.map.names();
  result.initial = m.map.values(m.map.initial_phi());
  EvaluationCache evaluations(*this);
  auto count_runs = [&] {
    result.forward_runs = evaluations.forward_runs;
    result.sensitivity_solves = evaluations.sensitivity_solves;
    result.failed_runs = evaluations.failed_runs;
  };
  // The start, as Levenberg-Marquardt will ask for it (with analytic
  // sensitivities): a failure here is the user's to fix, not a rejected step.
  const bool levenberg_marquardt = m.options.method == Method::LevenbergMarquardt;
  const Evaluation& first = evaluations.at(m.map.initial_phi(), levenberg_marquardt && m.analytic);
  if (!first.ok) {
    count_runs();
    result.message = "the forward run at the starting parameters failed: " + first.message;
    return result;
  }
  result.initial_cost = cost(first.residuals);

  const OptimizerOutcome outcome = levenberg_marquardt ? fit_levenberg_marquardt(evaluations, m.options)
                                                       : fit_nlopt(evaluations, m.options);
  result.success = outcome.success;
  result.message = outcome.message;
  result.iterations = outcome.iterations;
  result.values = m.map.values(outcome.phi);

  // At the optimum (usually kept from the optimiser): the run, the distances,
  // and the covariance. A copy: the cache's entries move.
  const Evaluation best = evaluations.at(outcome.phi, false);
  count_runs();
  if (!best.ok) {
    result.success = false;
    result.message = "the forward run at the fitted parameters failed: " + best.message;
    return result;
  }
  result.final_cost = cost(best.residuals);
  result.summary = best.summary;
  result.positions = best.positions;
  const int nv = m.model.num_vertices();
  Eigen::Index row = 0;
  std::vector<double> all;
  for (size_t t = 0; t < m.targets.size(); ++t) {
    Eigen::VectorXd per_vertex = Eigen::VectorXd::Constant(nv, std::numeric_limits<double>::quiet_NaN());
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
  result.overall = distance_statistics(Eigen::Map<const Eigen::VectorXd>(all.data(), static_cast<Eigen::Index>(all.size())), m.length);

  Eigen::MatrixXd covariance;
  result.covariance_ok = phi_covariance(evaluations, m.options, outcome.phi, &covariance);
  count_runs();
  const int P = m.map.size();
  result.standard_errors = result.lower_95 = result.upper_95 =
      Eigen::VectorXd::Constant(P, std::numeric_limits<double>::quiet_NaN());
  result.correlation = Eigen::MatrixXd::Constant(P, P, std::numeric_limits<double>::quiet_NaN());
  if (result.covariance_ok) {
    const int dof = m.residuals - P;
    const double variance = dof > 0 ? 2.0 * result.final_cost / dof : 0.0;
    const Eigen::MatrixXd scaled = variance * covariance;
    for (int k = 0; k < P; ++k) {
      const double sigma = std::sqrt(std::max(0.0, scaled(k, k)));
      const bool log = m.map.parameters()[static_cast<size_t>(k)].log_scale;
      const double phi = outcome.phi[k];
      result.standard_errors[k] = log ? result.values[k] * sigma : sigma;
      result.lower_95[k] = log ? std::exp(phi - 1.96 * sigma) : phi - 1.96 * sigma;
      result.upper_95[k] = log ? std::exp(phi + 1.96 * sigma) : phi + 1.96 * sigma;
      for (int j = 0; j < P; ++j) {
        const double denominator = std::sqrt(covariance(k, k) * covariance(j, j));
        result.correlation(k, j) = denominator > 0.0 ? covariance(k, j) / denominator : 0.0;
      }
    }
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace fiberfluid::fit
