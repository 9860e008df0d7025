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

// The relative misfits of the law at phi (its parameters, linear), and their
// Jacobian by central differences: a law's stresses cost nothing beside a
// body's run.
class MaterialTestObjective final : public Objective {
 public:
  MaterialTestObjective(const MaterialModel& model, const std::vector<material::TestPoint>& points)
      : model_(model),
        points_(points),
        variables_(model_parameters(model)),
        residuals_(static_cast<int>(misfits_of(model, model.start, points).size())),
        difference_scales_(difference_scales(model)) {}

  const Variables& variables() const override { return variables_; }
  int num_residuals() const override { return residuals_; }
  bool analytic_jacobian() const override { return true; }
  bool warm_starts() const override { return false; }

  Evaluation evaluate(const Eigen::VectorXd& phi, bool with_jacobian,
                      const Eigen::VectorXd&) const override {
    Evaluation e;
    e.forward_runs = 1;
    if (!misfits(phi, &e.residuals, &e.message)) return e;
    e.ok = true;
    if (!with_jacobian) return e;
    e.jacobian.resize(residuals_, phi.size());
    for (Eigen::Index k = 0; k < phi.size(); ++k) {
      const double h = 1e-6 * std::max(std::abs(phi[k]), difference_scales_[k]);
      Eigen::VectorXd up = phi, down = phi, r_up, r_down;
      up[k] += h, down[k] -= h;
      std::string why;
      if (!misfits(up, &r_up, &why) || !misfits(down, &r_down, &why)) {
        e.ok = false;
        e.message = "near the point: " + why;
        return e;
      }
      e.jacobian.col(k) = (r_up - r_down) / (2.0 * h);
    }
    return e;
  }

 private:
  // Per parameter, the least scale of its difference step: the start's
  // largest modulus for a modulus, 1 for an exponent.
  static Eigen::VectorXd difference_scales(const MaterialModel& m) {
    double largest_modulus = 0.0;
    for (Eigen::Index k = 0; k < m.start.size(); ++k)
      if (m.modulus[static_cast<size_t>(k)])
        largest_modulus = std::max(largest_modulus, std::abs(m.start[k]));
    Eigen::VectorXd scales(m.start.size());
    for (Eigen::Index k = 0; k < m.start.size(); ++k)
      scales[k] = m.modulus[static_cast<size_t>(k)] ? largest_modulus : 1.0;
    return scales;
  }

  bool misfits(const Eigen::VectorXd& phi, Eigen::VectorXd* r, std::string* why) const {
    if (const Status usable = model_.check(phi); !usable.ok) return *why = usable.message, false;
    *r = misfits_of(model_, phi, points_);
    if (!r->allFinite()) return *why = "a stress of the law is not finite", false;
    return true;
  }

  const MaterialModel& model_;
  const std::vector<material::TestPoint>& points_;
  Variables variables_;
  int residuals_;
  Eigen::VectorXd difference_scales_;
};

}  // namespace

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
