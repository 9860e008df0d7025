// SPDX-License-Identifier: GPL-3.0-or-later
// A fit's problem (internal to fit/): the model, its load path and the
// fitted parameters, the residual blocks stacked in order (the scans'
// distances, then the force curves' misfits), and the evaluation at one
// point: the forward run, its sensitivities (the Newton stepper's analytic
// ones, or central differences of whole runs) and each block's rows.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "fiberfluid/fit/fit_types.hpp"
#include "fiberfluid/fit/objective.hpp"
#include "fiberfluid/fit/residuals/residual_block.hpp"

namespace fiberfluid::fit {

// The stiffest start a fit tries: the moduli and gamma 2, 4, ... this many
// times the start's (the driver's stiffer start; a failed probe keeps its
// states for each).
constexpr double kStiffest = 1024.0;

// The step of n nearest the load share 1/s (at least 1): where the start
// stiffened s times ends on the start's own path.
inline long step_at_share(int n, double s) { return std::max(1L, std::lround(n / s)); }

// The steps nearest n/2, n/4, ... n/1024: where a start probe's run is kept,
// for the starts stiffened 2, 4, ... 1024 times.
inline bool near_a_halving(int step, int n) {
  for (double s = 2.0; s <= kStiffest; s *= 2.0)
    if (step_at_share(n, s) == step) return true;
  return false;
}

class FitProblem final : public Objective {
 public:
  // Throws InputError as Calibration's constructor says.
  FitProblem(model::Model model, solve::SteppingOptions stepping, std::vector<MeasuredStep> targets,
             std::vector<Parameter> parameters, FitOptions options,
             std::vector<ForceCurve> force_curves, std::vector<BlockMaker> more_blocks = {});
  ~FitProblem() override;
  // The blocks refer to the problem's members: it stays where it was made.
  FitProblem(const FitProblem&) = delete;
  FitProblem& operator=(const FitProblem&) = delete;

  const model::Model& model() const { return model_; }
  const solve::SteppingOptions& stepping() const { return stepping_; }
  const ParameterMap& parameters() const { return map_; }
  const Variables& variables() const override { return map_; }
  const FitOptions& options() const { return options_; }
  bool analytic_jacobian() const override { return analytic_; }
  bool warm_starts() const override { return warm_starts_; }
  int num_residuals() const override { return residuals_; }
  int num_counted_vertices() const { return static_cast<int>(counted_.size()); }
  double body_length() const { return length_; }
  const std::vector<ForceCurve>& force_curves() const { return curves_; }
  double force_weight(size_t curve) const { return curve_weights_.at(curve); }

  // Calibration::evaluate: the residuals at phi, the final state solved from
  // `warm_start` where the problem takes warm starts.
  Evaluation evaluate(const Eigen::VectorXd& phi, bool with_jacobian,
                      const Eigen::VectorXd& warm_start) const override;
  // The residuals (with_jacobian: and their Jacobian) at phi, run with these
  // stepping options (a warm start in them is used as given);
  // keep_path_states: a failed run's Evaluation::path_states (near_a_halving).
  Evaluation evaluate(const Eigen::VectorXd& phi, bool with_jacobian,
                      solve::SteppingOptions stepping, bool keep_path_states) const;
  // 1/2 sum rho(r^2) under the chosen loss.
  double cost(const Eigen::VectorXd& residuals) const;
  // An evaluation's run, positions, distances and force misfits, into result.
  void describe(const Evaluation& at, FitResult& result) const;

 private:
  // Per step read: the state, and each block's readings of its record.
  struct StepState {
    Eigen::VectorXd x;
    std::vector<std::vector<double>> observed;  // per block
  };
  // A run of `model` along the path, its states at the steps read into `at`
  // (and, with path_states, its states near n/2, n/4, ...).
  solve::SteppingSummary run_forward(const model::Model& model,
                                     const solve::SteppingOptions& options,
                                     std::map<int, StepState>& at,
                                     std::map<int, Eigen::VectorXd>* path_states) const;
  // du/dtheta and the blocks' readings' derivatives by central differences
  // of whole runs in phi (two per material parameter), into run and
  // readings; the runs counted in e (and, as a probe's, their path states
  // kept: a failed one's are where a stiffer start may begin). "" or why a
  // run failed.
  std::string central_differences(const Eigen::VectorXd& phi,
                                  const std::map<int, StepState>& states, ForwardRun& run,
                                  std::vector<std::map<int, StepReadings>>& readings,
                                  std::map<int, Eigen::VectorXd>* path_states, Evaluation& e) const;

  model::Model model_;
  solve::SteppingOptions stepping_;
  std::vector<ForceCurve> curves_;
  ParameterMap map_;
  FitOptions options_;
  std::vector<int> counted_;  // model vertices whose distances count, ascending
  double length_ = 0.0;
  std::vector<std::unique_ptr<ResidualBlock>> blocks_;  // in row order
  std::vector<double> curve_weights_;                   // m per N, per force curve
  std::vector<int> state_steps_;                        // the distinct steps the blocks read
  bool analytic_ = true;
  bool warm_starts_ = false;
  int residuals_ = 0;
};

}  // namespace fiberfluid::fit
