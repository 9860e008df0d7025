// SPDX-License-Identifier: GPL-3.0-or-later
#include "model/assembly.hpp"

#include "geom/area_vectors.hpp"
#include "model/fiber_network.hpp"
#include "model/loads.hpp"

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

Eigen::MatrixXd system_matrix(const Model& model, const Eigen::MatrixXd& X) {
  const int n = model.num_vertices(), dim = model.dim();
  const geom::VertexAreaVectors areas = geom::vertex_area_vectors(X, model.surface.F);
  const FiberLaplacians laplacians =
      fiber_laplacians(X, areas.magnitude, geom::unique_edges(model.surface), model.fibers.get(),
                       model.connection_count);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(model.num_unknowns(), model.num_unknowns());
  const int p = model.pressure_dof();
  for (int a = 0; a < dim; ++a) {
    A.block(a * n, a * n, n, n) = axis_block(laplacians, model.material, a);
    A.block(a * n, p, n, 1) = areas.S.col(a);
    A.block(p, a * n, 1, n) = areas.S.col(a).transpose();
  }
  return A;
}

Eigen::VectorXd right_hand_side(const Model& model, const Eigen::MatrixXd& X,
                                const std::vector<double>& factors) {
  const geom::VertexAreaVectors areas = geom::vertex_area_vectors(X, model.surface.F);
  return load_vector(model, X, areas.S, factors);
}

Eigen::VectorXd linear_residual(const Model& model, const Eigen::VectorXd& unknowns,
                                const std::vector<double>& factors) {
  const Eigen::MatrixXd& s = model.surface.V;
  return system_matrix(model, s) * unknowns - right_hand_side(model, s, factors);
}

}  // namespace fiberfluid::model
