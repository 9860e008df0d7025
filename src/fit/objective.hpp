// SPDX-License-Identifier: GPL-3.0-or-later
// What the optimisers fit (internal to fit/): residuals r(phi), and their
// Jacobian when asked, over fitted variables phi. One body's problem
// (FitProblem) is one; several specimens' stacked over shared parameters
// (JointCalibration) are another. The evaluation cache, Levenberg-Marquardt,
// NLopt and the covariance at the optimum see only this.
#pragma once

#include <Eigen/Core>

#include "fiberfluid/fit/fit_types.hpp"
#include "fiberfluid/fit/parameters.hpp"

namespace fiberfluid::fit {

class Objective {
 public:
  virtual ~Objective() = default;

  virtual const Variables& variables() const = 0;
  virtual int num_residuals() const = 0;
  // The Jacobian costs little beside the residuals (analytic sensitivities):
  // the optimiser takes it with every point it evaluates.
  virtual bool analytic_jacobian() const = 0;
  // An evaluation may start from a nearby point's final state.
  virtual bool warm_starts() const = 0;
  // The residuals at phi (with_jacobian: and their Jacobian), solved from
  // `warm_start` where the objective takes warm starts; the runs counted in
  // the Evaluation.
  virtual Evaluation evaluate(const Eigen::VectorXd& phi, bool with_jacobian,
                              const Eigen::VectorXd& warm_start) const = 0;
};

}  // namespace fiberfluid::fit
