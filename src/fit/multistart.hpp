// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// A multi-start search: one local fit (Calibration::run_from) from each of
// several starts spread over the parameters' bounds, so that a real optimum
// can be told from a local one. The starts are the parameters' own starts
// and then the points of a Halton sequence (Halton, Numer. Math. 2 (1960)
// 84) over the box of the fitted variables: the log of a log-scaled
// parameter, so a modulus between 1 kPa and 1 MPa is sampled evenly per
// decade. The local optima are clustered: two are one when every fitted
// variable agrees to `same_optimum` of its range.
//
// The starts are independent: they are dealt out through a WorkDealer (one
// process: in order; under MPI: over the ranks, parallel::Ranks::deal), and
// the result is the same whichever rank ran which start.

#include <functional>
#include <string>
#include <vector>

#include "fiberfluid/fit/calibration.hpp"
#include "fiberfluid/util/work_dealer.hpp"

namespace fiberfluid::fit {

struct MultistartOptions {
  int starts = 8;              // the parameters' starts, then starts - 1 Halton points
  double same_optimum = 1e-3;  // of each fitted variable's range (bounds, in phi)
};
// Throws InputError naming the option ("starts", "same_optimum").
void check_options(const MultistartOptions& options);

// The first `count` Halton points (index 1, 2, ...; index 0 is the box's
// corner), one per row, in the box [lower, upper] of `lower.size()`
// dimensions (at most 20: the first 20 primes are the bases).
Eigen::MatrixXd halton_points(int count, const Eigen::VectorXd& lower,
                              const Eigen::VectorXd& upper);

// The starts of a multi-start search in the fitted variables phi, one per
// row: the parameters' starts, then Halton points in the bounds. Throws
// InputError naming a parameter without both bounds.
Eigen::MatrixXd spread_starts(const ParameterMap& map, int count);

// Local optima found by more than one start.
struct Optimum {
  Eigen::VectorXd values;   // the parameters' values at its cheapest start's end
  double cost = 0.0;        // the least cost among its starts
  std::vector<int> starts;  // which starts reached it (0-based), cheapest first
};

struct StartOutcome {
  Eigen::VectorXd start;  // the parameters' values it started from
  FitResult fit;          // its local fit, whole
  int rank = 0;           // the MPI rank that ran it
};

struct MultistartResult {
  std::vector<StartOutcome> starts;  // in start order
  // Distinct optima of the starts whose fit converged, cheapest first.
  std::vector<Optimum> optima;
  int best_start = -1;  // the start whose fit is the result; -1: none converged
  // The best optimum was reached from one start only: there may be cheaper
  // ones no start came near (more starts, or narrower bounds, would tell).
  bool best_found_once = false;
  double seconds = 0.0;
  // The best start's fit (a copy), or the first start's when none converged.
  const FitResult& best() const;
};

// The search. `progress` is called on the gathering process after each start
// (its index, outcome); `dealer` empty: the starts in order, here. On other
// MPI ranks, serve_multistart with the same dealer runs their share.
MultistartResult run_multistart(
    const Calibration& calibration, const MultistartOptions& options, const WorkDealer& dealer = {},
    const std::function<void(size_t, const StartOutcome&)>& progress = {});
void serve_multistart(const Calibration& calibration, const MultistartOptions& options,
                      const WorkDealer& dealer);

// Clusters the converged fits of `starts` (see the file's comment).
std::vector<Optimum> cluster_optima(const std::vector<StartOutcome>& starts,
                                    const ParameterMap& map, double same_optimum);

}  // namespace fiberfluid::fit
