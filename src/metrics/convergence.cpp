// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/metrics/convergence.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace fiberfluid::metrics {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The changes between successive levels, those within rounding set to 0.
std::vector<double> changes(const std::vector<double>& values) {
  double scale = 0.0;
  for (double v : values) scale = std::max(scale, std::abs(v));
  std::vector<double> out;
  for (size_t k = 1; k < values.size(); ++k) {
    const double change = values[k] - values[k - 1];
    out.push_back(std::abs(change) <= 1e-12 * scale ? 0.0 : change);
  }
  return out;
}

RichardsonEstimate without_order(Trend trend, double fine, double last_change) {
  RichardsonEstimate out;
  out.trend = trend;
  out.monotone = trend != Trend::Oscillating;
  out.order = kNaN;
  if (trend == Trend::Constant || trend == Trend::Converging) {  // converged to rounding
    out.extrapolated = fine;
    return out;
  }
  out.extrapolated = kNaN;
  // Oscillating: the last change is the estimate; not converging: none.
  out.error = trend == Trend::Oscillating ? std::abs(last_change) : kNaN;
  out.gci = trend == Trend::Oscillating ? 1.25 * std::abs(last_change / fine) : kNaN;
  return out;
}
}  // namespace

const char* trend_name(Trend trend) {
  switch (trend) {
    case Trend::Constant:
      return "constant";
    case Trend::Converging:
      return "converging";
    case Trend::Oscillating:
      return "oscillating";
    case Trend::NotConverging:
      return "not converging";
  }
  return "?";
}

Trend convergence_trend(const std::vector<double>& values) {
  if (values.size() < 2) throw std::invalid_argument("convergence_trend: fewer than two values");
  const std::vector<double> d = changes(values);
  if (std::all_of(d.begin(), d.end(), [](double c) { return c == 0.0; })) return Trend::Constant;
  bool up = false, down = false;
  for (double c : d) (c > 0.0 ? up : down) |= c != 0.0;
  if (up && down) return Trend::Oscillating;
  for (size_t k = 1; k < d.size(); ++k)
    if (std::abs(d[k]) >= std::abs(d[k - 1]) && d[k] != 0.0) return Trend::NotConverging;
  return Trend::Converging;
}

RichardsonEstimate richardson(double coarse, double medium, double fine, double h_coarse,
                              double h_medium, double h_fine) {
  // Celik et al. (2008), with 1 the finest: r21 = h2 / h1, r32 = h3 / h2,
  // e21 = phi2 - phi1, e32 = phi3 - phi2, p solving
  // p ln r21 = ln |e32 / e21| + ln((r21^p - 1) / (r32^p - 1)) for changes of
  // one sign. Celik writes the right side in an absolute value, which turns
  // changes that grow into a positive order: here they are not converging.
  const Trend trend = convergence_trend({coarse, medium, fine});
  const double e21 = medium - fine, e32 = coarse - medium;
  if (trend != Trend::Converging || e21 == 0.0) return without_order(trend, fine, e21);
  const double r21 = h_medium / h_fine, r32 = h_coarse / h_medium;
  double p = std::log(std::abs(e32 / e21)) / std::log(r21);
  for (int it = 0; it < 100; ++it) {
    const double q = std::log((std::pow(r21, p) - 1.0) / (std::pow(r32, p) - 1.0));
    const double next = (std::log(std::abs(e32 / e21)) + q) / std::log(r21);
    if (!std::isfinite(next) || next <= 0.0) break;
    const bool settled = std::abs(next - p) < 1e-12 * std::max(1.0, p);
    p = next;
    if (settled) break;
  }
  if (!(p > 0.0) || !std::isfinite(p)) return without_order(Trend::NotConverging, fine, e21);
  RichardsonEstimate out;
  out.trend = trend;
  out.monotone = true;
  out.order = p;
  const double rp = std::pow(r21, p);
  out.extrapolated = (rp * fine - medium) / (rp - 1.0);
  out.error = std::abs(out.extrapolated - fine);
  out.gci = 1.25 * std::abs(e21 / fine) / (rp - 1.0);
  return out;
}

RichardsonEstimate richardson(const std::vector<double>& values, const std::vector<double>& sizes) {
  const size_t n = values.size();
  if (n < 3 || sizes.size() != n)
    throw std::invalid_argument("richardson: expected at least three values, one per size");
  RichardsonEstimate out = richardson(values[n - 3], values[n - 2], values[n - 1], sizes[n - 3],
                                      sizes[n - 2], sizes[n - 1]);
  const Trend overall = convergence_trend(values);
  if (out.trend == Trend::NotConverging || overall == out.trend) return out;
  if (overall == Trend::Converging && out.trend == Trend::Constant) {  // settled at the finest
    out.trend = overall;
    return out;
  }
  return without_order(overall, values[n - 1], values[n - 1] - values[n - 2]);
}

}  // namespace fiberfluid::metrics
