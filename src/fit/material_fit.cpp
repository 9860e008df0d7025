// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fit/material_fit.hpp"

#include <cmath>
#include <limits>

#include "fiberfluid/fit/evaluation_cache.hpp"
#include "fiberfluid/fit/objective.hpp"
#include "fiberfluid/fit/optimizers.hpp"

namespace fiberfluid::fit {
namespace {

std::vector<Parameter> law_parameters(const material::HyperelasticLaw& law) {
  std::vector<Parameter> out;
  for (size_t k = 0; k < law.parameter_names().size(); ++k)
    out.push_back({law.parameter_names()[k], law.parameters()[static_cast<Eigen::Index>(k)]});
  return out;
}

// The relative misfits of the law at phi (its parameters, linear), and their
// Jacobian by central differences: a law's stresses cost nothing beside a
// body's run.
class MaterialTestObjective final : public Objective {
 public:
  MaterialTestObjective(const material::HyperelasticLaw& start,
                        const std::vector<material::TestPoint>& points)
      : start_(start),
        points_(points),
        variables_(law_parameters(start)),
        residuals_(static_cast<int>(material::relative_misfits(start, points).size())) {}

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
    const double modulus_scale = std::abs(start_.shear_modulus());
    for (Eigen::Index k = 0; k < phi.size(); ++k) {
      const double scale = start_.is_modulus(static_cast<int>(k)) ? modulus_scale : 1.0;
      const double h = 1e-6 * std::max(std::abs(phi[k]), scale);
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
  bool misfits(const Eigen::VectorXd& phi, Eigen::VectorXd* r, std::string* why) const {
    const material::HyperelasticLaw law = start_.with_parameters(phi);
    if (const Status usable = law.check(); !usable.ok) return *why = usable.message, false;
    const std::vector<double> m = material::relative_misfits(law, points_);
    *r = Eigen::Map<const Eigen::VectorXd>(m.data(), static_cast<Eigen::Index>(m.size()));
    if (!r->allFinite()) return *why = "a stress of the law is not finite", false;
    return true;
  }

  material::HyperelasticLaw start_;
  const std::vector<material::TestPoint>& points_;
  Variables variables_;
  int residuals_;
};

}  // namespace

MaterialFitResult fit_material_test(const material::HyperelasticLaw& start,
                                    const std::vector<material::TestPoint>& points,
                                    const FitOptions& given) {
  MaterialFitResult result;
  result.law = start;
  const MaterialTestObjective objective(start, points);
  if (objective.num_residuals() < objective.variables().size()) {
    result.message = "fewer loaded test points (" + std::to_string(objective.num_residuals()) +
                     ") than the " + start.name() + " law's parameters";
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
  result.law = start.with_parameters(outcome.phi);
  result.rms = material::rms_relative_misfit(result.law, points);
  result.evaluations = evaluations.evaluations;
  return result;
}

}  // namespace fiberfluid::fit
