// SPDX-License-Identifier: GPL-3.0-or-later
#include "model/fiber_network.hpp"

#include <string>

#include "geom/error.hpp"

namespace fiberfluid::model {
namespace {

void add_fiber(Eigen::MatrixXd& L, int i, int j, double weight) {
  L(i, i) += weight;
  L(j, j) += weight;
  L(i, j) -= weight;
  L(j, i) -= weight;
}

double fiber_length(const Eigen::MatrixXd& X, int i, int j) {
  const double length = (X.row(i) - X.row(j)).norm();
  if (!(length > 0.0))
    throw InputError("vertices " + std::to_string(i) + " and " + std::to_string(j) +
                     " coincide: the fiber between them has zero length");
  return length;
}

}  // namespace

FiberLaplacians fiber_laplacians(const Eigen::MatrixXd& X, const Eigen::VectorXd& area,
                                 const Eigen::MatrixXi& edges) {
  const int n = static_cast<int>(X.rows());
  FiberLaplacians out;
  out.bulk = Eigen::MatrixXd::Zero(n, n);
  out.surface = Eigen::MatrixXd::Zero(n, n);
  // The paper divides by N-1, the fibers per vertex, so that Y does not
  // depend on the discretisation.
  const double connections = n - 1;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      add_fiber(out.bulk, i, j, (area[i] + area[j]) / (2.0 * connections * fiber_length(X, i, j)));
  for (Eigen::Index e = 0; e < edges.rows(); ++e) {
    const int i = edges(e, 0), k = edges(e, 1);
    const double length = fiber_length(X, i, k);
    add_fiber(out.surface, i, k, (area[i] + area[k]) / (2.0 * length * length));
  }
  return out;
}

Eigen::MatrixXd axis_block(const FiberLaplacians& laplacians, const Material& material, int axis) {
  return material.young_modulus[axis] * laplacians.bulk +
         material.surface_tension * laplacians.surface;
}

}  // namespace fiberfluid::model
