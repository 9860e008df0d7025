// SPDX-License-Identifier: GPL-3.0-or-later
// The forward runs of one fit (internal to fit/): kept, counted, and their
// failures by cause.
#pragma once

#include <Eigen/Core>
#include <deque>
#include <map>
#include <string>
#include <vector>

#include "fiberfluid/fit/fit_types.hpp"
#include "fiberfluid/fit/objective.hpp"

namespace fiberfluid::fit {

// The forward runs of one fit, shared by the start's check, the optimiser,
// the covariance and the report: the last few points are kept, so that a
// point asked for twice (the start, the optimum) costs one run. Counts runs.
class EvaluationCache {
 public:
  explicit EvaluationCache(const Objective& objective) : objective_(objective) {}
  const Objective& objective() const { return objective_; }
  // The evaluation at phi, with the Jacobian when asked (a kept one without
  // it is evaluated again). The reference stays valid until the next call.
  const Evaluation& at(const Eigen::VectorXd& phi, bool with_jacobian);

  // An evaluation made elsewhere (a start probe), counted as at() counts its
  // own and kept only when it succeeded (a probe's failure says nothing of
  // the full run at phi). Null when not kept.
  const Evaluation* add(const Eigen::VectorXd& phi, bool with_jacobian, Evaluation evaluation);

  // The evaluation at phi if it was kept (with the Jacobian when asked), or null.
  const Evaluation* kept(const Eigen::VectorXd& phi, bool with_jacobian) const;

  int evaluations = 0;  // points evaluated here (not add()ed)
  int forward_runs = 0, sensitivity_solves = 0;
  int warm_started_runs = 0;  // of forward_runs (Calibration::warm_starts)
  int failed_runs = 0;        // points whose forward run failed (rejected, not fatal)
  std::map<std::string, int> failures_by_cause;
  std::vector<FailedRun> failed_examples;  // the first kKeptFailures
  std::string last_failure;                // the latest failed run's message

  static constexpr size_t kKeptFailures = 5;

 private:
  static constexpr size_t kKept = 8;  // a few trial points past the optimum
  struct Entry {
    Eigen::VectorXd phi;
    bool has_jacobian = false;
    Evaluation evaluation;
  };
  const Objective& objective_;
  std::deque<Entry> kept_;  // newest first
  Evaluation interrupted_;  // the last evaluation an interrupt cut short (not kept)
  Evaluation unkept_;       // the last evaluation add() did not keep
  // The final state of the kept point nearest phi whose run succeeded, to
  // warm-start phi's run from (empty: none, or the calibration takes none).
  Eigen::VectorXd nearest_state(const Eigen::VectorXd& phi) const;
  // Counts the entry's runs and failures, and keeps it (when `keep`):
  // the kept entry, or an interrupted or unkept one's evaluation.
  const Evaluation& count(Entry entry, bool keep);
  // The kept entry that serves (phi, with_jacobian), or end().
  std::deque<Entry>::const_iterator find(const Eigen::VectorXd& phi, bool with_jacobian) const;
};

}  // namespace fiberfluid::fit
