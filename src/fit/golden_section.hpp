// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <functional>

namespace fiberfluid::fit {

struct LineMinimum {
  double x = 0.0, value = 0.0;
  int evaluations = 0;
};

// The minimum of a unimodal f on [lower, upper] by golden-section search
// (Kiefer 1953; Press et al., Numerical Recipes, section 10.2): each
// iteration shrinks the bracket by 0.618 with one evaluation of f. A
// non-finite value counts as +infinity (a failed run is never the minimum).
LineMinimum golden_section_minimum(const std::function<double(double)>& f, double lower,
                                   double upper, int iterations);

}  // namespace fiberfluid::fit
