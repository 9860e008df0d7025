// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fit/multistart.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

#include "fiberfluid/fit/fit_archive.hpp"
#include "fiberfluid/util/error.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::fit {

void check_options(const MultistartOptions& options) {
  if (options.starts < 2 || options.starts > 100000)
    throw InputError("starts: expected a whole number from 2 to 100000 (got " +
                     std::to_string(options.starts) + ")");
  if (!(options.same_optimum > 0.0 && options.same_optimum < 1.0))
    throw InputError(
        "same_optimum: expected a share of each parameter's range, above 0 and "
        "below 1 (got " +
        std::to_string(options.same_optimum) + ")");
}

namespace {

constexpr int kPrimes[] = {2,  3,  5,  7,  11, 13, 17, 19, 23, 29,
                           31, 37, 41, 43, 47, 53, 59, 61, 67, 71};

// The radical inverse of i in base b: i's digits mirrored about the point.
double radical_inverse(long long i, int b) {
  double value = 0.0, digit_weight = 1.0 / b;
  for (; i > 0; i /= b, digit_weight /= b) value += static_cast<double>(i % b) * digit_weight;
  return value;
}

// The fitted variables of parameter values (ParameterMap::values inverted).
Eigen::VectorXd phi_of(const ParameterMap& map, const Eigen::VectorXd& values) {
  Eigen::VectorXd phi = values;
  for (int k = 0; k < map.size(); ++k)
    phi[k] = map.parameters()[static_cast<size_t>(k)].to_phi(values[k]);
  return phi;
}

}  // namespace

Eigen::MatrixXd halton_points(int count, const Eigen::VectorXd& lower,
                              const Eigen::VectorXd& upper) {
  const Eigen::Index dims = lower.size();
  if (dims > static_cast<Eigen::Index>(std::size(kPrimes)))
    throw InputError("a multi-start search spreads its starts over at most " +
                     std::to_string(std::size(kPrimes)) + " parameters (got " +
                     std::to_string(dims) + ")");
  Eigen::MatrixXd points(count, dims);
  for (int i = 0; i < count; ++i)
    for (Eigen::Index k = 0; k < dims; ++k)
      points(i, k) = lower[k] + (upper[k] - lower[k]) * radical_inverse(i + 1, kPrimes[k]);
  return points;
}

Eigen::MatrixXd spread_starts(const ParameterMap& map, int count) {
  const Eigen::VectorXd lower = map.lower_phi(), upper = map.upper_phi();
  for (int k = 0; k < map.size(); ++k)
    if (!std::isfinite(lower[k]) || !std::isfinite(upper[k]))
      throw InputError("parameter \"" + map.names()[static_cast<size_t>(k)] +
                       "\": a multi-start search spreads its starts between the bounds: give "
                       "both \"lower\" and \"upper\"");
  Eigen::MatrixXd starts(count, map.size());
  starts.row(0) = map.initial_phi().transpose();
  if (count > 1) starts.bottomRows(count - 1) = halton_points(count - 1, lower, upper);
  return starts;
}

const FitResult& MultistartResult::best() const {
  return starts.at(static_cast<size_t>(std::max(best_start, 0))).fit;
}

std::vector<Optimum> cluster_optima(const std::vector<StartOutcome>& starts,
                                    const ParameterMap& map, double same_optimum) {
  std::vector<int> converged_starts;
  for (size_t s = 0; s < starts.size(); ++s)
    if (converged(starts[s].fit.status)) converged_starts.push_back(static_cast<int>(s));
  // Cheapest first; a tie goes to the earlier start, so the order is the same
  // whichever rank finished first.
  std::stable_sort(converged_starts.begin(), converged_starts.end(), [&](int a, int b) {
    return starts[static_cast<size_t>(a)].fit.final_cost <
           starts[static_cast<size_t>(b)].fit.final_cost;
  });
  const Eigen::VectorXd range = map.upper_phi() - map.lower_phi();
  std::vector<Optimum> optima;
  std::vector<Eigen::VectorXd> where;  // each optimum's phi
  for (int s : converged_starts) {
    const FitResult& fit = starts[static_cast<size_t>(s)].fit;
    const Eigen::VectorXd phi = phi_of(map, fit.values);
    size_t o = 0;
    for (; o < optima.size(); ++o)
      if (((phi - where[o]).cwiseAbs().array() <= same_optimum * range.array()).all()) break;
    if (o == optima.size()) {
      optima.push_back({fit.values, fit.final_cost, {}});
      where.push_back(phi);
    }
    optima[o].starts.push_back(s);
  }
  return optima;
}

namespace {

// The local fit from start s, packed.
std::string run_start(const Calibration& calibration, const Eigen::MatrixXd& starts, size_t s) {
  return pack_fit_result(
      calibration.run_from(starts.row(static_cast<Eigen::Index>(s)).transpose()));
}

}  // namespace

MultistartResult run_multistart(const Calibration& calibration, const MultistartOptions& options,
                                const WorkDealer& dealer,
                                const std::function<void(size_t, const StartOutcome&)>& progress) {
  check_options(options);
  const auto began = std::chrono::steady_clock::now();
  const ParameterMap& map = calibration.parameters();
  const Eigen::MatrixXd starts = spread_starts(map, options.starts);
  MultistartResult result;
  result.starts.resize(static_cast<size_t>(options.starts));
  for (size_t s = 0; s < result.starts.size(); ++s) {
    StartOutcome& outcome = result.starts[s];
    outcome.start = map.values(starts.row(static_cast<Eigen::Index>(s)).transpose());
    outcome.fit.status = FitStatus::Interrupted;  // until it has run
    outcome.fit.message = "not run: the search was interrupted";
    outcome.fit.names = map.names();
    outcome.fit.initial = outcome.fit.values = outcome.start;
    outcome.fit.initial_cost = outcome.fit.final_cost = std::numeric_limits<double>::quiet_NaN();
  }
  (dealer ? dealer : WorkDealer(deal_in_order))(
      result.starts.size(), [&](size_t s) { return run_start(calibration, starts, s); },
      [&](size_t s, int rank, std::string&& bytes) {
        StartOutcome& outcome = result.starts[s];
        outcome.fit = unpack_fit_result(bytes);
        outcome.rank = rank;
        if (progress) progress(s, outcome);
      });
  result.optima = cluster_optima(result.starts, map, options.same_optimum);
  if (!result.optima.empty()) {
    result.best_start = result.optima.front().starts.front();
    result.best_found_once = result.optima.front().starts.size() == 1;
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
  return result;
}

void serve_multistart(const Calibration& calibration, const MultistartOptions& options,
                      const WorkDealer& dealer) {
  check_options(options);
  const Eigen::MatrixXd starts = spread_starts(calibration.parameters(), options.starts);
  dealer(
      starts.rows(), [&](size_t s) { return run_start(calibration, starts, s); },
      [](size_t, int, std::string&&) {});
}

}  // namespace fiberfluid::fit
