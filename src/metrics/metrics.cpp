// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/metrics/metrics.hpp"

#include <cmath>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::metrics {

double relative_energy_norm(const Eigen::MatrixXd& u_reference, const Eigen::MatrixXd& u) {
  if (u.rows() != u_reference.rows() || u.cols() != u_reference.cols())
    throw InputError("E_n needs the same nodes: the reference has " +
                     std::to_string(u_reference.rows()) + " by " +
                     std::to_string(u_reference.cols()) + " displacements, the approximation " +
                     std::to_string(u.rows()) + " by " + std::to_string(u.cols()));
  const double reference = u_reference.norm();
  if (!(reference > 0.0)) throw InputError("E_n: the reference does not move (|u| = 0)");
  return (u - u_reference).norm() / reference;
}

double enclosed_measure(const geom::Surface& surface) {
  return geom::enclosed_volume(surface.V, surface.F);
}

double surface_error(const geom::Surface& reference, const geom::Surface& approximation,
                     const std::string& what_reference, const std::string& what_approximation) {
  // The Booleans first: they check both surfaces (coordinates, closedness).
  const double difference =
      symmetric_difference_measure(reference, approximation, what_reference, what_approximation);
  const double measure = enclosed_measure(reference);
  if (!(measure > 0.0))
    throw InputError(what_reference + ": encloses no positive " +
                     std::string(reference.dim == 2 ? "area" : "volume") +
                     " (is it closed and outward?)");
  return difference / measure;
}

Eigen::VectorXd boundary_node_measures(const geom::Surface& surface) {
  return geom::vertex_area_vectors(surface.V, surface.F).magnitude;
}

double interior_error(const Eigen::MatrixXd& reference, const Eigen::MatrixXd& approximation,
                      const Eigen::VectorXd& weights, double undeformed_measure, int dim) {
  if (approximation.rows() != reference.rows() || approximation.cols() != reference.cols() ||
      weights.size() != reference.rows())
    throw InputError("E_i needs the same nodes in both meshes and a weight per node (" +
                     std::to_string(reference.rows()) + " reference nodes, " +
                     std::to_string(approximation.rows()) + " approximate, " +
                     std::to_string(weights.size()) + " weights)");
  if (!(undeformed_measure > 0.0)) throw InputError("E_i: the undeformed body has no measure");
  const double integral = weights.dot((approximation - reference).rowwise().norm());
  return integral / std::pow(undeformed_measure, 1.0 / dim);
}

}  // namespace fiberfluid::metrics
