// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/model/material_response.hpp"

#include <cmath>
#include <vector>

#include "fiberfluid/util/quadrature.hpp"

namespace fiberfluid::model {
namespace {

// Directions over one octant (the integrand is even in each component under
// a diagonal stretch): Gauss-Legendre in cos(theta) and in phi, 24 x 24
// points, their weights summing to 1 (the mean over the sphere).
struct Direction {
  Eigen::Vector3d d;
  double weight;
};
const std::vector<Direction>& octant_directions() {
  static const std::vector<Direction> directions = [] {
    constexpr int kPoints = 24;
    std::vector<double> x, w;
    gauss_legendre_unit(kPoints, &x, &w);
    std::vector<Direction> out;
    for (int a = 0; a < kPoints; ++a)
      for (int b = 0; b < kPoints; ++b) {
        const double u = x[static_cast<size_t>(a)], phi = 0.5 * M_PI * x[static_cast<size_t>(b)];
        const double s = std::sqrt(1.0 - u * u);
        out.push_back({{s * std::cos(phi), s * std::sin(phi), u},
                       w[static_cast<size_t>(a)] * w[static_cast<size_t>(b)]});
      }
    return out;
  }();
  return directions;
}

constexpr double kNetworkFactor = 5.0;  // a constant law Y: Young's modulus Y

}  // namespace

// l_i dW/dl_i = 5 < f(l_d) l_i^2 d_i^2 / l_d >, f(l) = T0 + Y(l - 1) (l - 1), l_d = |F d|.
Eigen::Vector3d fiber_network_stretch_work(const FiberLaw& law, const Eigen::Vector3d& l) {
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  const Eigen::Vector3d l2 = l.cwiseProduct(l);
  for (const Direction& dir : octant_directions()) {
    const Eigen::Vector3d d2 = dir.d.cwiseProduct(dir.d);
    const double ld = std::sqrt(l2.dot(d2)), e = ld - 1.0;
    const double stress = law.modulus(e) * e + law.rest_tension();
    t += dir.weight * stress / ld * l2.cwiseProduct(d2);
  }
  return kNetworkFactor * t;
}

double fiber_network_nominal_stress(const FiberLaw& law, material::HomogeneousTest test, double l) {
  const Eigen::Vector3d t = fiber_network_stretch_work(law, material::test_stretches(test, l));
  return (t[0] - t[2]) / l;  // axis 3 free: its zero stress gives the pressure
}

}  // namespace fiberfluid::model
