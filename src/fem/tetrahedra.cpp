// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fem/tetrahedra.hpp"

#include <cmath>
#include <string>

#include "fiberfluid/util/error.hpp"
#include "fiberfluid/util/quadrature.hpp"

namespace fiberfluid::fem {

bool is_quadratic_tetrahedron(int nodes_per_element) {
  if (nodes_per_element != 4 && nodes_per_element != 10)
    throw InputError("fem: a tetrahedron has 4 nodes (linear) or 10 (quadratic), not " +
                     std::to_string(nodes_per_element));
  return nodes_per_element == 10;
}

void tetrahedron_shape(int nodes_per_element, const Eigen::Vector3d& xi, Eigen::VectorXd* N,
                       Eigen::MatrixXd* dN) {
  const Eigen::Vector4d L(1.0 - xi.sum(), xi[0], xi[1], xi[2]);
  Eigen::Matrix<double, 4, 3> dL;  // dL_i / dxi_k
  dL.row(0).setConstant(-1.0);
  dL.bottomRows<3>().setIdentity();
  N->resize(nodes_per_element);
  dN->resize(nodes_per_element, 3);
  if (!is_quadratic_tetrahedron(nodes_per_element)) {
    *N = L;
    *dN = dL;
    return;
  }
  for (int i = 0; i < 4; ++i) {
    (*N)[i] = L[i] * (2.0 * L[i] - 1.0);
    dN->row(i) = (4.0 * L[i] - 1.0) * dL.row(i);
  }
  for (int e = 0; e < 6; ++e) {
    const int i = kTetrahedronEdges[static_cast<size_t>(e)][0],
              j = kTetrahedronEdges[static_cast<size_t>(e)][1];
    (*N)[4 + e] = 4.0 * L[i] * L[j];
    dN->row(4 + e) = 4.0 * (L[i] * dL.row(j) + L[j] * dL.row(i));
  }
}

TetrahedronRule tetrahedron_rule(int degree) {
  TetrahedronRule rule;
  if (degree <= 1) {
    rule.points.emplace_back(0.25, 0.25, 0.25);
    rule.weights.push_back(1.0 / 6.0);
    return rule;
  }
  if (degree == 2) {
    const double a = (5.0 + 3.0 * std::sqrt(5.0)) / 20.0, b = (5.0 - std::sqrt(5.0)) / 20.0;
    rule.points = {{b, b, b}, {a, b, b}, {b, a, b}, {b, b, a}};  // L0 = a, then L1, L2, L3
    rule.weights.assign(4, 1.0 / 24.0);
    return rule;
  }
  // The collapsed cube: xi1 = s, xi2 = t (1 - s), xi3 = r (1 - s)(1 - t), with
  // Jacobian (1 - s)^2 (1 - t). A polynomial of degree p in xi becomes one
  // of degree p + 2 in s (less in t and r), which n Gauss points integrate
  // exactly when 2n - 1 >= p + 2: n = p / 2 + 2.
  const int n = degree / 2 + 2;
  std::vector<double> x, w;
  gauss_legendre_unit(n, &x, &w);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        const double s = x[static_cast<size_t>(i)], t = x[static_cast<size_t>(j)],
                     r = x[static_cast<size_t>(k)];
        rule.points.emplace_back(s, t * (1.0 - s), r * (1.0 - s) * (1.0 - t));
        rule.weights.push_back(w[static_cast<size_t>(i)] * w[static_cast<size_t>(j)] *
                               w[static_cast<size_t>(k)] * (1.0 - s) * (1.0 - s) * (1.0 - t));
      }
  return rule;
}

}  // namespace fiberfluid::fem
