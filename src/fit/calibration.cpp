// SPDX-License-Identifier: GPL-3.0-or-later
// Calibration: the fit's one public face over its parts, the problem
// (problem.hpp: the forward run and the residual blocks), the driver
// (driver.hpp: start, optimiser, ending) and the estimate's worth
// (uncertainty.hpp).
#include "fiberfluid/fit/calibration.hpp"

#include "fiberfluid/fit/driver.hpp"
#include "fiberfluid/fit/problem.hpp"

namespace fiberfluid::fit {

struct Calibration::Impl {
  FitProblem problem;
  Impl(model::Model model, solve::SteppingOptions stepping, std::vector<MeasuredStep> targets,
       std::vector<Parameter> parameters, FitOptions options, std::vector<ForceCurve> curves,
       std::vector<BlockMaker> more_blocks)
      : problem(std::move(model), std::move(stepping), std::move(targets), std::move(parameters),
                std::move(options), std::move(curves), std::move(more_blocks)) {}
};

Calibration::Calibration(model::Model model, solve::SteppingOptions stepping,
                         std::vector<MeasuredStep> targets, std::vector<Parameter> parameters,
                         FitOptions options, std::vector<ForceCurve> force_curves,
                         std::vector<BlockMaker> more_blocks)
    : impl_(std::make_unique<Impl>(std::move(model), std::move(stepping), std::move(targets),
                                   std::move(parameters), std::move(options),
                                   std::move(force_curves), std::move(more_blocks))) {}

Calibration::~Calibration() = default;

const ParameterMap& Calibration::parameters() const { return impl_->problem.parameters(); }
const FitOptions& Calibration::options() const { return impl_->problem.options(); }
const model::Model& Calibration::model() const { return impl_->problem.model(); }
bool Calibration::analytic_jacobian() const { return impl_->problem.analytic_jacobian(); }
bool Calibration::warm_starts() const { return impl_->problem.warm_starts(); }
int Calibration::num_residuals() const { return impl_->problem.num_residuals(); }
int Calibration::num_counted_vertices() const { return impl_->problem.num_counted_vertices(); }
double Calibration::body_length() const { return impl_->problem.body_length(); }
const std::vector<ForceCurve>& Calibration::force_curves() const {
  return impl_->problem.force_curves();
}
double Calibration::force_weight(size_t curve) const { return impl_->problem.force_weight(curve); }
double Calibration::cost(const Eigen::VectorXd& r) const { return impl_->problem.cost(r); }

Evaluation Calibration::evaluate(const Eigen::VectorXd& phi, bool with_jacobian,
                                 const Eigen::VectorXd& warm_start) const {
  return impl_->problem.evaluate(phi, with_jacobian, warm_start);
}

const FitProblem& Calibration::problem() const { return impl_->problem; }

FitResult Calibration::run() const { return run_from(impl_->problem.parameters().initial_phi()); }

FitResult Calibration::run_from(const Eigen::VectorXd& start_phi) const {
  return FitDriver(impl_->problem).run_from(start_phi);
}

FitResult Calibration::result_at(const Eigen::VectorXd& phi) const {
  return FitDriver(impl_->problem).result_at(phi);
}

}  // namespace fiberfluid::fit
