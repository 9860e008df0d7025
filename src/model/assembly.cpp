// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/model/assembly.hpp"

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/model/loads.hpp"

namespace fiberfluid::model {

Eigen::MatrixXd displacements(const Model& model, const Eigen::VectorXd& unknowns) {
  const int n = model.num_vertices();
  Eigen::MatrixXd U(n, model.dim());
  for (int a = 0; a < model.dim(); ++a) U.col(a) = unknowns.segment(a * n, n);
  return U;
}

Eigen::MatrixXd positions(const Model& model, const Eigen::VectorXd& unknowns) {
  return model.surface.V + displacements(model, unknowns);
}

Eigen::VectorXd right_hand_side(const Model& model, const Eigen::MatrixXd& X,
                                const std::vector<double>& factors) {
  const geom::VertexAreaVectors areas = geom::vertex_area_vectors(X, model.surface.F);
  return load_vector(model, X, areas.S, factors);
}

}  // namespace fiberfluid::model
