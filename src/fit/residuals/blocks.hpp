// SPDX-License-Identifier: GPL-3.0-or-later
// The kinds of residual block a fit stacks (internal to fit/). Each
// constructor throws InputError naming its target for one that cannot be
// fitted.
#pragma once

#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "fiberfluid/fit/fit_types.hpp"
#include "fiberfluid/fit/force_curve.hpp"
#include "fiberfluid/fit/residuals/residual_block.hpp"
#include "fiberfluid/fit/target.hpp"
#include "fiberfluid/model/model.hpp"

namespace fiberfluid::fit {

// A scan's distances (m): from each counted vertex, taken into the scan's
// frame by the fit's alignment, to the scan; with `symmetric`, also from
// each scan point, taken into the body's frame, to the simulated surface.
class ScanDistances : public ResidualBlock {
 public:
  // `index`: the scan's place among the fit's (Evaluation::positions,
  // FitResult::statistics); `length`: the body's, which the shares refer to.
  ScanDistances(const MeasuredStep& scan, size_t index, const model::Model& model, int steps,
                const std::vector<int>& counted, bool symmetric, double length);

  int rows() const override;
  std::vector<int> steps() const override { return {scan_.step}; }
  std::string evaluate(const ForwardRun& run, const std::map<int, StepReadings>& readings,
                       Eigen::Index row, Evaluation& e) const override;
  void describe(const Evaluation& e, Eigen::Index row, FitResult& result) const override;

 private:
  MeasuredStep scan_;
  size_t index_;
  const std::vector<int>& counted_;  // the problem's, sorted
  bool symmetric_;
  double length_;
  TargetDistance distance_;
};

// A force curve's weighted misfits, w (F(t) - F_measured) (m), with F
// interpolated between the steps around each row's travel (or read at the
// row's step), F(0) = 0 at the unloaded reference.
class ForceCurveMisfits : public ResidualBlock {
 public:
  // `index`: the curve's place among the fit's (Evaluation::forces,
  // FitResult::force_misfits). The weight is the curve's, or the body's
  // length over the largest measured |force|.
  ForceCurveMisfits(const ForceCurve& curve, size_t index, const model::Model& model, int steps,
                    double length);

  double weight() const { return weight_; }  // m per N

  int rows() const override { return static_cast<int>(curve_.force.size()); }
  std::vector<int> steps() const override;
  std::vector<double> observe(const model::Model& model,
                              const solve::StepRecord& record) const override;
  Eigen::MatrixXd observed_sensitivities(const model::Model& model, const solve::StepRecord& record,
                                         int material_parameters) const override;
  std::string evaluate(const ForwardRun& run, const std::map<int, StepReadings>& readings,
                       Eigen::Index row, Evaluation& e) const override;
  void describe(const Evaluation& e, Eigen::Index row, FitResult& result) const override;

 private:
  // Where a row reads the run: F = (1 - s) F(k0) + s F(k1).
  struct Row {
    int k0 = 0, k1 = 0;
    double s = 0.0;
  };
  std::vector<Row> plan(const model::Model& model, int steps) const;

  ForceCurve curve_;
  size_t index_;
  std::vector<Row> rows_;
  double weight_ = 0.0;
  std::vector<double> row_weights_;  // weight_, or for a relative misfit weight_ max|F| / |F_r|
};

}  // namespace fiberfluid::fit
