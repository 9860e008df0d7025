// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fit/golden_section.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace fiberfluid::fit {

LineMinimum golden_section_minimum(const std::function<double(double)>& f, double lower,
                                   double upper, int iterations) {
  if (!(lower < upper) || iterations < 0)
    throw std::invalid_argument("golden_section_minimum: needs lower < upper and iterations >= 0");
  LineMinimum out;
  const auto value = [&](double x) {
    ++out.evaluations;
    const double y = f(x);
    return std::isnan(y) ? std::numeric_limits<double>::infinity() : y;
  };
  const double ratio = (std::sqrt(5.0) - 1.0) / 2.0;
  double lo = lower, hi = upper;
  double a = hi - ratio * (hi - lo), b = lo + ratio * (hi - lo);
  double fa = value(a), fb = value(b);
  for (int k = 0; k < iterations; ++k) {
    if (fa < fb) {
      hi = b, b = a, fb = fa, a = hi - ratio * (hi - lo), fa = value(a);
    } else {
      lo = a, a = b, fa = fb, b = lo + ratio * (hi - lo), fb = value(b);
    }
  }
  out.x = fa < fb ? a : b;
  out.value = fa < fb ? fa : fb;
  return out;
}

}  // namespace fiberfluid::fit
