// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/metrics/convergence.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fiberfluid::metrics {

RichardsonEstimate richardson(double coarse, double medium, double fine, double h_coarse,
                              double h_medium, double h_fine) {
  // Celik et al. (2008), with 1 the finest: r21 = h2 / h1, r32 = h3 / h2,
  // e21 = phi2 - phi1, e32 = phi3 - phi2, p solving
  // p ln r21 = |ln |e32 / e21| + ln((r21^p - s) / (r32^p - s))|, s = sign(e32 / e21).
  RichardsonEstimate out;
  const double e21 = medium - fine, e32 = coarse - medium;
  const double r21 = h_medium / h_fine, r32 = h_coarse / h_medium;
  out.extrapolated = fine;
  if (e21 == 0.0) {  // converged to rounding: nothing left to extrapolate
    out.monotone = e32 == 0.0;
    return out;
  }
  out.monotone = e32 / e21 > 0.0;
  if (!out.monotone || e32 == 0.0) {
    out.order = std::numeric_limits<double>::quiet_NaN();
    out.error = std::abs(e21);  // no order: the last change is the estimate
    out.gci = 1.25 * std::abs(e21 / fine);
    return out;
  }
  double p = std::abs(std::log(std::abs(e32 / e21))) / std::log(r21);
  for (int it = 0; it < 100; ++it) {
    const double q = std::log((std::pow(r21, p) - 1.0) / (std::pow(r32, p) - 1.0));
    const double next = std::abs(std::log(std::abs(e32 / e21)) + q) / std::log(r21);
    if (!std::isfinite(next)) break;
    const bool settled = std::abs(next - p) < 1e-12 * std::max(1.0, p);
    p = next;
    if (settled) break;
  }
  out.order = p;
  const double rp = std::pow(r21, p);
  out.extrapolated = (rp * fine - medium) / (rp - 1.0);
  out.error = std::abs(out.extrapolated - fine);
  out.gci = 1.25 * std::abs(e21 / fine) / (rp - 1.0);
  return out;
}

}  // namespace fiberfluid::metrics
