// SPDX-License-Identifier: GPL-3.0-or-later
// A law fitted to a material test at material level (no body): its
// parameters so that its homogeneous responses meet the measured nominal
// stresses, weighed as relative misfits (a test's small stresses count as
// much as its large ones), by the single fit's Levenberg-Marquardt on an
// Objective. The law is a hyperelastic one (material::HyperelasticLaw) or a
// fiber law's network (model/material_response.hpp).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "fiberfluid/fit/fit_types.hpp"
#include "fiberfluid/material/material_test.hpp"
#include "fiberfluid/model/fiber_law.hpp"

namespace fiberfluid::fit {

// A family of material-level responses over its parameters.
struct MaterialModel {
  std::string name;
  std::vector<std::string> names;
  Eigen::VectorXd start;
  std::vector<bool> modulus;  // per parameter: a modulus (Pa), else without unit
  // Per parameter, the least value a fit may give it (empty: none): a fiber
  // law's positive parameters stay at or above 0.
  std::vector<double> lower;
  std::function<double(const Eigen::VectorXd&, material::HomogeneousTest, double)> nominal_stress;
  std::function<Status(const Eigen::VectorXd&)> check;
};
MaterialModel material_model(const material::HyperelasticLaw& start);
// The fiber law's network response; its parameters from the law's.
MaterialModel material_model(const model::FiberLaw& start);

// The model's relative misfits at parameters p to the loaded points
// (material::relative_misfits) and, when `jacobian` is given, their
// derivatives by p by central differences (a step of 1e-6 of the parameter,
// or of the largest modulus for a modulus and 1 for an exponent when that
// is larger): a law's stresses cost microseconds. Returns why they cannot
// be formed (a law the check refuses near p, a stress that is not finite),
// or "".
std::string material_misfits(const MaterialModel& model, const Eigen::VectorXd& p,
                             const std::vector<material::TestPoint>& points,
                             Eigen::VectorXd* misfits, Eigen::MatrixXd* jacobian = nullptr);

struct MaterialFitResult {
  FitStatus status = FitStatus::StartFailed;
  std::string message;
  Eigen::VectorXd parameters;           // at the fit (the start if it failed)
  double initial_rms = 0.0, rms = 0.0;  // rms relative misfit at the start and the fit
  std::vector<IterationRecord> iterations;
  int evaluations = 0;
};

// Every parameter is fitted, from the model's start. options: max_iterations
// and the tolerances (method and loss are Levenberg-Marquardt on squares).
MaterialFitResult fit_material_test(const MaterialModel& model,
                                    const std::vector<material::TestPoint>& points,
                                    const FitOptions& options = {});

}  // namespace fiberfluid::fit
