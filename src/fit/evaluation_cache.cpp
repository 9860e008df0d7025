// SPDX-License-Identifier: GPL-3.0-or-later
// The forward runs of one fit: kept, counted, and their failures by cause.
#include <algorithm>
#include <cctype>

#include "fiberfluid/fit/evaluation_cache.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::fit {

namespace {

// A failure's message with its numbers taken out, so that failures of one
// kind count together: "step 3: runaway: face 12 turned over" ->
// "step #: runaway: face # turned over".
std::string failure_cause(const std::string& message) {
  std::string cause;
  for (size_t i = 0; i < message.size(); ++i) {
    const char ch = message[i];
    const bool digit = std::isdigit(static_cast<unsigned char>(ch)) != 0;
    const bool in_number =
        digit || ((ch == '.' || ch == 'e' || ch == '-' || ch == '+') && !cause.empty() &&
                  cause.back() == '#' && i + 1 < message.size() &&
                  std::isdigit(static_cast<unsigned char>(message[i + 1])));
    if (!in_number)
      cause += ch;
    else if (cause.empty() || cause.back() != '#')
      cause += '#';
  }
  return cause;
}

}  // namespace

std::deque<EvaluationCache::Entry>::const_iterator EvaluationCache::find(const Eigen::VectorXd& phi,
                                                                         bool with_jacobian) const {
  return std::find_if(kept_.begin(), kept_.end(), [&](const Entry& entry) {
    if (entry.phi.size() != phi.size() || entry.phi != phi) return false;
    // A point whose forward run failed fails with a Jacobian too: one run.
    if (with_jacobian) return entry.has_jacobian || !entry.evaluation.ok;
    // A point whose finite-difference runs failed still has valid residuals
    // in its Jacobian-free entry: a failed Jacobian must not hide them.
    return !entry.has_jacobian || entry.evaluation.ok;
  });
}

const Evaluation* EvaluationCache::kept(const Eigen::VectorXd& phi, bool with_jacobian) const {
  const auto entry = find(phi, with_jacobian);
  return entry == kept_.end() ? nullptr : &entry->evaluation;
}

const Evaluation& EvaluationCache::at(const Eigen::VectorXd& phi, bool with_jacobian) {
  if (const auto entry = find(phi, with_jacobian); entry != kept_.end()) {
    const auto position = kept_.begin() + (entry - kept_.cbegin());
    if (position != kept_.begin()) std::rotate(kept_.begin(), position, std::next(position));
    return kept_.front().evaluation;
  }
  ++evaluations;
  return count({phi, with_jacobian, objective_.evaluate(phi, with_jacobian, nearest_state(phi))},
               true);
}

const Evaluation* EvaluationCache::add(const Eigen::VectorXd& phi, bool with_jacobian,
                                       Evaluation evaluation) {
  const bool keep = evaluation.ok;
  const Evaluation& counted = count({phi, with_jacobian, std::move(evaluation)}, keep);
  return keep ? &counted : nullptr;
}

const Evaluation& EvaluationCache::count(Entry entry, bool keep) {
  forward_runs += entry.evaluation.forward_runs;
  warm_started_runs += entry.evaluation.warm_started_runs;
  sensitivity_solves += entry.evaluation.sensitivity_solves;
  // A run cut short by an interrupt did not fail: it is neither counted nor
  // kept (the same point may be run again later).
  if (!entry.evaluation.ok && cancel_requested()) return interrupted_ = entry.evaluation;
  if (!entry.evaluation.ok) {
    ++failed_runs;
    last_failure = entry.evaluation.message;
    ++failures_by_cause[failure_cause(last_failure)];
    if (failed_examples.size() < kKeptFailures)
      failed_examples.push_back({objective_.variables().values(entry.phi), last_failure});
  }
  if (!keep) return unkept_ = std::move(entry.evaluation);
  kept_.push_front(std::move(entry));
  if (kept_.size() > kKept) kept_.pop_back();
  return kept_.front().evaluation;
}

Eigen::VectorXd EvaluationCache::nearest_state(const Eigen::VectorXd& phi) const {
  if (!objective_.warm_starts()) return {};
  const Entry* nearest = nullptr;
  for (const Entry& entry : kept_)
    if (entry.evaluation.ok && entry.phi.size() == phi.size() &&
        (nearest == nullptr || (entry.phi - phi).norm() < (nearest->phi - phi).norm()))
      nearest = &entry;
  return nearest != nullptr ? nearest->evaluation.summary.unknowns : Eigen::VectorXd();
}

}  // namespace fiberfluid::fit
