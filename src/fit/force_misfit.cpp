// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fit/force_misfit.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>

namespace fiberfluid::fit {

ForceMisfit force_misfit(const ForceCurve& curve, const std::vector<double>& simulated,
                         double weight) {
  ForceMisfit m;
  m.simulated = simulated;
  m.weight = weight;
  m.relative = curve.relative;
  const size_t n = std::min(simulated.size(), curve.force.size());
  double squares = 0.0, relative_squares = 0.0, scatter_squares = 0.0;
  size_t with_force = 0, positive = 0, negative = 0;
  int runs = 0, last_sign = 0;
  for (size_t r = 0; r < n; ++r) {
    const double miss = simulated[r] - curve.force[r];
    squares += miss * miss;
    m.largest = std::max(m.largest, std::abs(miss));
    m.scale = std::max(m.scale, std::abs(curve.force[r]));
    if (curve.force[r] != 0.0) {
      relative_squares += miss * miss / (curve.force[r] * curve.force[r]);
      ++with_force;
    }
    if (r < curve.sd.size()) scatter_squares += curve.sd[r] * curve.sd[r];
    const int sign = miss > 0.0 ? 1 : miss < 0.0 ? -1 : 0;
    if (sign == 0) continue;  // an exact row belongs to no run
    (sign > 0 ? positive : negative) += 1;
    if (sign != last_sign) ++runs;
    last_sign = sign;
  }
  if (n == 0) return m;
  m.rms = std::sqrt(squares / static_cast<double>(n));
  if (with_force > 0)
    m.rms_relative = std::sqrt(relative_squares / static_cast<double>(with_force));
  if (curve.sd.size() >= n) m.scatter = std::sqrt(scatter_squares / static_cast<double>(n));

  m.runs = runs;
  const double n1 = static_cast<double>(positive), n2 = static_cast<double>(negative);
  const double signed_rows = n1 + n2;
  std::ostringstream why;
  std::vector<std::string> reasons;
  if (signed_rows >= 2) {
    m.runs_expected = 1.0 + 2.0 * n1 * n2 / signed_rows;
    const double variance = (m.runs_expected - 1.0) * (m.runs_expected - 2.0) / (signed_rows - 1.0);
    if (variance > 0.0) m.runs_z = (runs - m.runs_expected) / std::sqrt(variance);
  }
  if (signed_rows >= 10 && (n1 == 0 || n2 == 0)) {
    reasons.push_back("every row misses on one side");
  } else if (signed_rows >= 10 && m.runs_z < -1.96) {
    std::ostringstream r;
    r << "its signs run in " << runs << " runs where random signs would give "
      << std::setprecision(3) << m.runs_expected << " (z = " << m.runs_z << ")";
    reasons.push_back(r.str());
  }
  if (std::isfinite(m.scatter) && m.scatter > 0.0 && m.rms > 2.0 * m.scatter) {
    std::ostringstream r;
    r << "its rms " << std::setprecision(3) << m.rms << " N is " << m.rms / m.scatter
      << " times the measurement's scatter (" << m.scatter << " N)";
    reasons.push_back(r.str());
  }
  m.systematic = !reasons.empty();
  if (m.systematic) {
    why << "systematic: ";
    for (size_t k = 0; k < reasons.size(); ++k) why << (k ? " and " : "") << reasons[k];
    why << ": the model's form, not the data's noise, limits this fit";
  } else if (signed_rows < 10) {
    why << "too few rows (" << signed_rows << ") to tell noise from the model's form";
  } else {
    why << "as noise: " << runs << " runs of sign where random signs would give "
        << std::setprecision(3) << m.runs_expected
        << (std::isfinite(m.scatter) ? ", within twice the measurement's scatter" : "");
  }
  m.verdict = why.str();
  return m;
}

}  // namespace fiberfluid::fit
