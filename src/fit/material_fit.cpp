// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fit/material_fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "fiberfluid/fit/evaluation_cache.hpp"
#include "fiberfluid/fit/objective.hpp"
#include "fiberfluid/fit/optimizers.hpp"
#include "fiberfluid/model/material_response.hpp"

namespace fiberfluid::fit {
namespace {

std::vector<Parameter> model_parameters(const MaterialModel& m) {
  std::vector<Parameter> out;
  for (size_t k = 0; k < m.names.size(); ++k) {
    out.push_back({m.names[k], m.start[static_cast<Eigen::Index>(k)]});
    if (k < m.lower.size()) out.back().lower = m.lower[k];
  }
  return out;
}

// The model's response at parameters p.
material::StressResponse response_at(const MaterialModel& m, const Eigen::VectorXd& p) {
  return [&m, p](material::HomogeneousTest test, double l) { return m.nominal_stress(p, test, l); };
}

Eigen::VectorXd misfits_of(const MaterialModel& m, const Eigen::VectorXd& p,
                           const std::vector<material::TestPoint>& points) {
  const std::vector<double> r = material::relative_misfits(response_at(m, p), points);
  return Eigen::Map<const Eigen::VectorXd>(r.data(), static_cast<Eigen::Index>(r.size()));
}

// The relative misfits of the law at phi (its parameters, linear) and their
// Jacobian (material_misfits).
class MaterialTestObjective final : public Objective {
 public:
  MaterialTestObjective(const MaterialModel& model, const std::vector<material::TestPoint>& points)
      : model_(model),
        points_(points),
        variables_(model_parameters(model)),
        residuals_(static_cast<int>(material::loaded_points(points).size())) {}

  const Variables& variables() const override { return variables_; }
  int num_residuals() const override { return residuals_; }
  bool analytic_jacobian() const override { return true; }
  bool warm_starts() const override { return false; }

  Evaluation evaluate(const Eigen::VectorXd& phi, bool with_jacobian,
                      const Eigen::VectorXd&) const override {
    Evaluation e;
    e.forward_runs = 1;
    e.message =
        material_misfits(model_, phi, points_, &e.residuals, with_jacobian ? &e.jacobian : nullptr);
    e.ok = e.message.empty();
    return e;
  }

 private:
  const MaterialModel& model_;
  const std::vector<material::TestPoint>& points_;
  Variables variables_;
  int residuals_;
};

// Why the model cannot be evaluated at p, or "", with its misfits.
std::string misfits_at(const MaterialModel& m, const Eigen::VectorXd& p,
                       const std::vector<material::TestPoint>& points, Eigen::VectorXd* r) {
  if (const Status usable = m.check(p); !usable.ok) return usable.message;
  *r = misfits_of(m, p, points);
  if (!r->allFinite()) return "a stress of the law is not finite";
  return "";
}

}  // namespace

std::string material_misfits(const MaterialModel& m, const Eigen::VectorXd& p,
                             const std::vector<material::TestPoint>& points, Eigen::VectorXd* r,
                             Eigen::MatrixXd* jacobian) {
  if (std::string why = misfits_at(m, p, points, r); !why.empty()) return why;
  if (jacobian == nullptr) return "";
  double largest_modulus = 0.0;
  for (Eigen::Index k = 0; k < p.size(); ++k)
    if (m.modulus[static_cast<size_t>(k)])
      largest_modulus = std::max(largest_modulus, std::abs(p[k]));
  jacobian->resize(r->size(), p.size());
  for (Eigen::Index k = 0; k < p.size(); ++k) {
    const double scale = m.modulus[static_cast<size_t>(k)] ? largest_modulus : 1.0;
    const double h = 1e-6 * std::max(std::abs(p[k]), scale);
    Eigen::VectorXd up = p, down = p, r_up, r_down;
    up[k] += h, down[k] -= h;
    // At a lower bound (a rise at 0) the step is one-sided.
    const bool at_lower =
        k < static_cast<Eigen::Index>(m.lower.size()) && down[k] < m.lower[static_cast<size_t>(k)];
    if (at_lower) down[k] = p[k];
    std::string why = misfits_at(m, up, points, &r_up);
    if (why.empty()) why = misfits_at(m, down, points, &r_down);
    if (!why.empty()) return "near the point: " + why;
    jacobian->col(k) = (r_up - r_down) / (up[k] - down[k]);
  }
  return "";
}

MaterialModel material_model(const material::HyperelasticLaw& start) {
  MaterialModel m;
  m.name = start.name();
  m.names = start.parameter_names();
  m.start = start.parameters();
  for (size_t k = 0; k < m.names.size(); ++k)
    m.modulus.push_back(start.is_modulus(static_cast<int>(k)));
  m.nominal_stress = [start](const Eigen::VectorXd& p, material::HomogeneousTest t, double l) {
    return material::nominal_stress(start.with_parameters(p), t, l);
  };
  m.check = [start](const Eigen::VectorXd& p) { return start.with_parameters(p).check(); };
  return m;
}

MaterialModel material_model(const model::FiberLaw& start) {
  MaterialModel m;
  m.name = start.name();
  m.names = start.parameter_names();
  m.start = Eigen::Map<const Eigen::VectorXd>(start.parameters().data(),
                                              static_cast<Eigen::Index>(start.parameters().size()));
  for (size_t k = 0; k < m.names.size(); ++k) {
    m.modulus.push_back(start.model().is_positive(static_cast<int>(k)));
    m.lower.push_back(m.modulus.back() ? 0.0 : -std::numeric_limits<double>::infinity());
  }
  const auto law_at = [start](const Eigen::VectorXd& p) {
    model::FiberLaw law = start;
    for (size_t k = 0; k < start.parameter_names().size(); ++k)
      law.set_parameter(start.parameter_names()[k], p[static_cast<Eigen::Index>(k)]);
    return law;
  };
  m.nominal_stress = [law_at](const Eigen::VectorXd& p, material::HomogeneousTest t, double l) {
    return model::fiber_network_nominal_stress(law_at(p), t, l);
  };
  m.check = [law_at](const Eigen::VectorXd& p) { return law_at(p).check(); };
  return m;
}

MaterialFitResult fit_material_test(const MaterialModel& model,
                                    const std::vector<material::TestPoint>& points,
                                    const FitOptions& given) {
  MaterialFitResult result;
  result.parameters = model.start;
  const MaterialTestObjective objective(model, points);
  if (objective.num_residuals() < objective.variables().size()) {
    result.message = "fewer loaded test points (" + std::to_string(objective.num_residuals()) +
                     ") than the " + model.name + " law's parameters";
    return result;
  }
  FitOptions options = given;
  options.method = Method::LevenbergMarquardt;
  options.loss = Loss::Squared;
  options.max_evaluations = std::numeric_limits<int>::max();
  EvaluationCache evaluations(objective);
  const Eigen::VectorXd phi0 = objective.variables().initial_phi();
  const Evaluation& first = evaluations.at(phi0, true);
  if (!first.ok) {
    result.message = "the start is no material: " + first.message;
    return result;
  }
  result.initial_rms = std::sqrt(first.residuals.squaredNorm() / first.residuals.size());
  const OptimizerOutcome outcome = fit_levenberg_marquardt(evaluations, options, phi0);
  result.status = outcome.status;
  result.message = outcome.message;
  result.iterations = outcome.iterations;
  result.parameters = outcome.phi;
  result.rms = material::rms_relative_misfit(response_at(model, outcome.phi), points);
  result.evaluations = evaluations.evaluations;
  return result;
}

}  // namespace fiberfluid::fit
