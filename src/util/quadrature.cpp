// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/util/quadrature.hpp"

#include <cmath>

namespace fiberfluid {

// Newton on the Legendre polynomial P_n from the usual cosine guess.
void gauss_legendre_unit(int n, std::vector<double>* x, std::vector<double>* w) {
  x->resize(static_cast<size_t>(n));
  w->resize(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    double t = std::cos(M_PI * (i + 0.75) / (n + 0.5)), dp = 0.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = t;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * t * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (t * p1 - p0) / (t * t - 1.0);
      const double step = p1 / dp;
      t -= step;
      if (std::abs(step) < 1e-16) break;
    }
    (*x)[static_cast<size_t>(i)] = 0.5 * (1.0 - t);
    (*w)[static_cast<size_t>(i)] = 1.0 / ((1.0 - t * t) * dp * dp);  // 2 / (...) on [-1, 1], halved
  }
}

}  // namespace fiberfluid
