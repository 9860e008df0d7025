// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// Calibration: the material parameters (and optionally a rigid alignment of
// the scans) whose simulated deformed surfaces come closest to measured ones.
// Built on the Newton scheme: the sensitivities du/dtheta = -K_T^{-1}
// dR/dtheta come from the stepper, one tangent solve per parameter, and are
// chained through the closest point's direction. The paper's incremental
// scheme can be fitted too, with finite-difference Jacobians.

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "fiberfluid/fit/fit_types.hpp"
#include "fiberfluid/fit/force_curve.hpp"
#include "fiberfluid/fit/parameters.hpp"
#include "fiberfluid/fit/residuals/residual_block.hpp"
#include "fiberfluid/fit/target.hpp"
#include "fiberfluid/model/model.hpp"
#include "fiberfluid/solve/stepping.hpp"

namespace fiberfluid::fit {

class FitProblem;

class Calibration {
 public:
  // The model's material holds the values of the parameters that are not
  // fitted; the parameters' starts replace the fitted ones. The residuals
  // are the surfaces' distances (m), then the force curves' weighted misfits
  // (m), then the rows of the blocks `more_blocks` make (targets of other
  // kinds, residual_block.hpp); any kind may be absent, not all. Throws InputError
  // (naming the parameter or the target) for a bad parameter, a target step
  // outside the run, a counted vertex that does not exist, a target that
  // does not overlap the body, or a force curve beyond the run's travel.
  Calibration(model::Model model, solve::SteppingOptions stepping,
              std::vector<MeasuredStep> targets, std::vector<Parameter> parameters,
              FitOptions options = {}, std::vector<ForceCurve> force_curves = {},
              std::vector<BlockMaker> more_blocks = {});
  ~Calibration();

  const ParameterMap& parameters() const;
  const FitOptions& options() const;
  const model::Model& model() const;
  bool analytic_jacobian() const;
  int num_residuals() const;
  // The model vertices whose distances count (all unless excluded).
  int num_counted_vertices() const;
  // The body's length the distance shares refer to: its largest extent.
  double body_length() const;
  // The force curves, and each one's weight as used (m per N).
  const std::vector<ForceCurve>& force_curves() const;
  double force_weight(size_t curve) const;

  // The residuals (and with_jacobian, their Jacobian) at the fitted variables
  // phi. `warm_start`: the unknowns of a nearby point's final state
  // (Evaluation::summary.unknowns) to solve this one's from, used when
  // warm_starts() (else, or empty, the load path is walked).
  Evaluation evaluate(const Eigen::VectorXd& phi, bool with_jacobian,
                      const Eigen::VectorXd& warm_start = {}) const;
  // Whether evaluate() takes warm starts: FitOptions::warm_start, every
  // target and force curve on the final step, and a path whose end does not
  // depend on the way there.
  bool warm_starts() const;
  // 1/2 sum rho(r^2) under the chosen loss.
  double cost(const Eigen::VectorXd& residuals) const;

  // The fit from the parameters' starts.
  FitResult run() const;
  // The fit from the fitted variables `start_phi` (ParameterMap: log or
  // linear), within the bounds: one start of a multi-start search.
  FitResult run_from(const Eigen::VectorXd& start_phi) const;
  // No fit: the run and the distances at the fitted variables phi (as a
  // fit's result; status Converged when the run succeeded, with no standard
  // errors): one specimen's share of a calibration over several.
  FitResult result_at(const Eigen::VectorXd& phi) const;

  // The problem the calibration poses (fit/problem.hpp): what its parts run on.
  const FitProblem& problem() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fiberfluid::fit
