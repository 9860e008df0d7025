// SPDX-License-Identifier: GPL-3.0-or-later
// One kind of measurement a fit is held to: its rows of the residual
// vector, the load steps it reads, and its residuals and their Jacobian from
// a forward run's states and sensitivities. FitProblem stacks the blocks in
// order, runs the model once per point and hands each block what it reads.
// The scans' and force curves' blocks are fit/'s own (blocks.hpp); a block of
// another kind comes in through a BlockMaker (Calibration's more_blocks): an
// experiment's target kinds are one file each in experiment/targets/.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "fiberfluid/fit/fit_types.hpp"
#include "fiberfluid/fit/parameters.hpp"
#include "fiberfluid/model/model.hpp"
#include "fiberfluid/solve/stepping.hpp"

namespace fiberfluid::fit {

// What one load step gave a block beyond the state: the scalars it observes
// in the step's record (ResidualBlock::observe) and, with a Jacobian, their
// derivatives by the material parameters (observed x material parameters).
struct StepReadings {
  std::vector<double> observed;
  Eigen::MatrixXd sensitivities;
};

// A forward run at one point of the parameter space, as the blocks read it.
struct ForwardRun {
  const model::Model& model;  // with the material at the point
  const ParameterMap& map;
  Eigen::VectorXd values;  // the parameters' values
  Eigen::VectorXd dvalue;  // d value / d phi
  bool with_jacobian = false;
  // Per step read: the unknowns [u.. P], and (with a Jacobian and material
  // parameters) du/dtheta, full layout, one column per material parameter.
  std::map<int, Eigen::VectorXd> states;
  std::map<int, Eigen::MatrixXd> sensitivities;

  // d x_i / d phi for the material parameters from one step's du/dtheta:
  // 3 x parameters, zero in the other parameters' columns.
  Eigen::Matrix<double, 3, Eigen::Dynamic> vertex_sensitivity(const Eigen::MatrixXd& S,
                                                              int vertex) const;
};

class ResidualBlock {
 public:
  virtual ~ResidualBlock() = default;

  virtual int rows() const = 0;
  // The load steps (1..n) whose states or readings the block needs.
  virtual std::vector<int> steps() const = 0;

  // The scalars the block reads from each of its steps' records (a paddle's
  // force), and their derivatives by the material parameters from the
  // record's analytic sensitivities (observed x material parameters). The
  // problem differentiates them by central differences when the run has no
  // analytic sensitivities. None by default.
  virtual std::vector<double> observe(const model::Model&, const solve::StepRecord&) const {
    return {};
  }
  virtual Eigen::MatrixXd observed_sensitivities(const model::Model&, const solve::StepRecord&,
                                                 int material_parameters) const {
    return Eigen::MatrixXd(0, material_parameters);
  }

  // Writes the block's rows of e.residuals (and, with a Jacobian, of
  // e.jacobian, zero on entry) from `row` on, and what the block shows of
  // the run (Evaluation::positions, Evaluation::forces). readings: per step
  // the block reads. Returns why the rows cannot be formed, or "".
  virtual std::string evaluate(const ForwardRun& run, const std::map<int, StepReadings>& readings,
                               Eigen::Index row, Evaluation& e) const = 0;

  // The block's part of a fit's report at an evaluation (its rows from
  // `row` on): FitResult::vertex_distances and statistics, force_misfits.
  virtual void describe(const Evaluation& e, Eigen::Index row, FitResult& result) const = 0;
};

// What a block is made on: the problem's model (its mesh, supports and
// loads), its load steps and the body's length (the distances' shares'
// reference).
struct BlockContext {
  const model::Model& model;
  int steps = 0;
  double length = 0.0;
};
// Makes a block of another kind when the problem is set up (after the fit's
// own blocks, in order). Throws InputError naming its target for one that
// cannot be fitted.
using BlockMaker = std::function<std::unique_ptr<ResidualBlock>(const BlockContext&)>;

}  // namespace fiberfluid::fit
