// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/model/reference/dense_assembly.hpp"

#include <string>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/fiber_network.hpp"
#include "fiberfluid/model/pair_stencil.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::model::reference {
namespace {

void add_fiber(Eigen::MatrixXd& L, int i, int j, double weight) {
  L(i, i) += weight;
  L(j, j) += weight;
  L(i, j) -= weight;
  L(j, i) -= weight;
}

}  // namespace

FiberLaplacians fiber_laplacians(const Eigen::MatrixXd& X, const Eigen::VectorXd& area,
                                 const Eigen::MatrixXi& edges, const geom::FiberMask* fibers,
                                 ConnectionCount count) {
  const int n = static_cast<int>(X.rows());
  FiberLaplacians out;
  out.bulk = Eigen::MatrixXd::Zero(n, n);
  out.surface = Eigen::MatrixXd::Zero(n, n);
  const PairFactors factors(fibers, count, n);
  std::vector<double> h(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    factors.row(i, h.data());
    for (int j = i + 1; j < n; ++j)
      if (h[static_cast<size_t>(j)] != 0.0)
        add_fiber(out.bulk, i, j,
                  bulk_weight(h[static_cast<size_t>(j)], area[i], area[j],
                              checked_fiber_length(X, i, j)));
  }
  out.surface = Eigen::MatrixXd(surface_tension_laplacian(X, area, edges));
  return out;
}

Eigen::MatrixXd axis_block(const FiberLaplacians& laplacians, const Material& material, int axis) {
  return material.young_modulus()[axis] * laplacians.bulk +
         material.surface_tension * laplacians.surface;
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

Eigen::VectorXd linear_residual(const Model& model, const Eigen::VectorXd& unknowns,
                                const std::vector<double>& factors) {
  const Eigen::MatrixXd& s = model.surface.V;
  return system_matrix(model, s) * unknowns - right_hand_side(model, s, factors);
}

void apply_penalty(const DofPartition& partition, const Eigen::VectorXd& values, double penalty,
                   Eigen::MatrixXd& A, Eigen::VectorXd& B) {
  for (size_t k = 0; k < partition.constrained.size(); ++k) {
    const int d = partition.constrained[k];
    A(d, d) = penalty;
    B[d] = penalty * values[static_cast<Eigen::Index>(k)];
  }
}

Eigen::VectorXd reduce_rhs(const DofPartition& partition, const Eigen::VectorXd& values,
                           const Eigen::MatrixXd& A, const Eigen::VectorXd& B) {
  const auto nf = static_cast<Eigen::Index>(partition.free.size());
  Eigen::VectorXd B_free(nf);
  for (Eigen::Index r = 0; r < nf; ++r) {
    const int row = partition.free[static_cast<size_t>(r)];
    double b = B[row];
    for (size_t k = 0; k < partition.constrained.size(); ++k)
      b -= A(row, partition.constrained[k]) * values[static_cast<Eigen::Index>(k)];
    B_free[r] = b;
  }
  return B_free;
}

void reduce_system(const DofPartition& partition, const Eigen::VectorXd& values,
                   const Eigen::MatrixXd& A, const Eigen::VectorXd& B, Eigen::MatrixXd& A_free,
                   Eigen::VectorXd& B_free) {
  const auto nf = static_cast<Eigen::Index>(partition.free.size());
  A_free.resize(nf, nf);
  for (Eigen::Index c = 0; c < nf; ++c)
    for (Eigen::Index r = 0; r < nf; ++r)
      A_free(r, c) =
          A(partition.free[static_cast<size_t>(r)], partition.free[static_cast<size_t>(c)]);
  B_free = reduce_rhs(partition, values, A, B);
}

}  // namespace fiberfluid::model::reference
