// SPDX-License-Identifier: GPL-3.0-or-later
#include "model/equilibrium.hpp"

#include <cmath>
#include <stdexcept>

#include "geom/area_vectors.hpp"
#include "geom/error.hpp"
#include "model/assembly.hpp"
#include "model/pair_stencil.hpp"

namespace fiberfluid::model {
namespace {

Eigen::Vector3d row3(const Eigen::MatrixXd& M, Eigen::Index i) {
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  v.head(M.cols()) = M.row(i).transpose();
  return v;
}

Eigen::Matrix3d cross_matrix(const Eigen::Vector3d& w) {
  Eigen::Matrix3d m;
  m << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return m;
}

// dA_f/dx_v for the k-th corner of face f (dim x dim, padded to 3x3). 3D:
// A_f = (x0 x x1 + x1 x x2 + x2 x x0) / 2, so dA_f/dx_k = [x_{k+2} - x_{k+1}]_x / 2.
// 2D: A_f = (d_y, -d_x), d = x_1 - x_0.
Eigen::Matrix3d face_area_derivative(const Eigen::MatrixXd& X, const Eigen::MatrixXi& F,
                                     Eigen::Index f, int k) {
  if (X.cols() == 3) {
    const Eigen::Vector3d next = X.row(F(f, (k + 1) % 3)), after = X.row(F(f, (k + 2) % 3));
    return 0.5 * cross_matrix(after - next);
  }
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  m(0, 1) = 1.0;
  m(1, 0) = -1.0;
  return k == 1 ? m : Eigen::Matrix3d(-m);
}

Eigen::SparseMatrix<double> reference_surface_laplacian(const Model& model,
                                                        const Eigen::VectorXd& area) {
  const Eigen::MatrixXi edges = geom::unique_edges(model.surface);
  std::vector<Eigen::Triplet<double>> entries;
  for (Eigen::Index e = 0; e < edges.rows(); ++e) {
    const int i = edges(e, 0), k = edges(e, 1);
    const double w = surface_weight(area[i], area[k],
                                    (model.surface.V.row(i) - model.surface.V.row(k)).squaredNorm());
    entries.insert(entries.end(), {{i, i, w}, {k, k, w}, {i, k, -w}, {k, i, -w}});
  }
  Eigen::SparseMatrix<double> L(model.num_vertices(), model.num_vertices());
  L.setFromTriplets(entries.begin(), entries.end());
  return L;
}

}  // namespace

struct Equilibrium::Hydrostatics {
  Eigen::VectorXd q;                                 // q_i
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();  // dq_i/dx_i, the same for every i
};

Equilibrium::Equilibrium(const Model& model)
    : model_(model),
      factors_(model.fibers.get(), model.connection_count, model.num_vertices()) {
  const Eigen::MatrixXd& V = model.surface.V;
  const geom::VertexAreaVectors areas = geom::vertex_area_vectors(V, model.surface.F);
  area0_ = areas.magnitude;
  C0_ = areas.C;
  volume0_ = geom::enclosed_volume(V, model.surface.F);
  for (int i = 0; i < V.rows(); ++i)
    for (int j = i + 1; j < V.rows(); ++j)
      if ((V.row(i) - V.row(j)).squaredNorm() == 0.0)
        throw InputError("vertices " + std::to_string(i) + " and " + std::to_string(j) +
                         " coincide: the fiber between them has zero length");
  surface_ = reference_surface_laplacian(model, area0_);
  for (const Load& load : model.loads) {
    double level = 0.0;
    const double magnitude = load.acceleration.norm();
    if (load.kind == Load::Kind::Hydrostatic && magnitude > 0.0)
      level = (V * (load.acceleration.head(model.dim()) / magnitude)).minCoeff();
    levels_.push_back(level);
  }
}

Eigen::MatrixXd Equilibrium::current_area_vectors(const Eigen::MatrixXd& X) const {
  return C0_ * geom::summed_face_area_vectors(X, model_.surface.F);
}

Equilibrium::Hydrostatics Equilibrium::hydrostatics(const Eigen::MatrixXd& X,
                                                    const std::vector<double>& factors) const {
  Hydrostatics h;
  h.q = Eigen::VectorXd::Zero(X.rows());
  for (size_t l = 0; l < model_.loads.size(); ++l) {
    const Load& load = model_.loads[l];
    const double magnitude = load.acceleration.norm();
    if (load.kind != Load::Kind::Hydrostatic || magnitude == 0.0 || factors[l] == 0.0) continue;
    const Eigen::Vector3d direction = load.acceleration / magnitude;
    const double scale = factors[l] * load.density * magnitude;
    h.q += scale * ((X * direction.head(X.cols())).array() - levels_[l]).matrix();
    h.gradient += scale * direction;
  }
  return h;
}

template <class Visit>
void Equilibrium::for_each_fiber(int i, const Eigen::MatrixXd& X, const Eigen::MatrixXd& U,
                                 std::vector<double>& row, Visit&& visit) const {
  const Eigen::MatrixXd& S = model_.surface.V;
  const FiberLaw& law = model_.material.law;
  const bool constant = law.is_constant();
  factors_.row(i, row.data());
  const Eigen::Vector3d xi = row3(X, i), si = row3(S, i), ui = row3(U, i);
  BulkFiber fiber;
  fiber.modulus = law.modulus(0.0);
  for (int j = 0; j < static_cast<int>(X.rows()); ++j) {
    const double h = row[static_cast<size_t>(j)];
    if (h == 0.0) continue;
    fiber.length = (si - row3(S, j)).norm();
    fiber.weight = bulk_weight(h, area0_[i], area0_[j], fiber.length);
    fiber.d = ui - row3(U, j);
    const Eigen::Vector3d between = xi - row3(X, j);
    const double current = between.norm();
    fiber.n = between / current;
    if (!constant) {
      const double strain = current / fiber.length - 1.0;
      fiber.modulus = law.modulus(strain);
      fiber.slope = law.slope(strain);
    }
    visit(j, fiber);
  }
}

Eigen::MatrixXd Equilibrium::fiber_forces(const Eigen::VectorXd& x) const {
  const Eigen::MatrixXd X = positions(model_, x), U = displacements(model_, x);
  const int n = model_.num_vertices(), dim = model_.dim();
  const Eigen::Vector3d m = model_.material.axis_factors;
  Eigen::MatrixXd forces(n, dim);
#pragma omp parallel
  {
    std::vector<double> row(static_cast<size_t>(n));
#pragma omp for schedule(dynamic, 16)
    for (int i = 0; i < n; ++i) {
      Eigen::Vector3d f = Eigen::Vector3d::Zero();
      for_each_fiber(i, X, U, row, [&](int, const BulkFiber& fiber) { f += fiber.force(m); });
      forces.row(i) = f.head(dim).transpose();
    }
  }
  return forces + model_.material.surface_tension * (surface_ * U);
}

Eigen::VectorXd Equilibrium::external_forces(const Eigen::VectorXd& x,
                                             const std::vector<double>& factors) const {
  const Eigen::MatrixXd X = positions(model_, x);
  const int n = model_.num_vertices(), dim = model_.dim();
  const Eigen::VectorXd q = hydrostatics(X, factors).q;
  const Eigen::MatrixXd S = current_area_vectors(X);
  Eigen::VectorXd F = Eigen::VectorXd::Zero(num_unknowns());
  for (int a = 0; a < dim; ++a) F.segment(a * n, n) = q.cwiseProduct(S.col(a));
  for (size_t l = 0; l < model_.loads.size(); ++l) {
    const Load& load = model_.loads[l];
    if (load.kind == Load::Kind::Point)
      for (int a = 0; a < dim; ++a) F[model_.dof(load.vertex, a)] += factors[l] * load.force[a];
  }
  return F;
}

Eigen::VectorXd Equilibrium::residual(const Eigen::VectorXd& x,
                                      const std::vector<double>& factors) const {
  const Eigen::MatrixXd X = positions(model_, x);
  const int n = model_.num_vertices(), dim = model_.dim();
  const double P = x[model_.pressure_dof()];
  const Eigen::MatrixXd S = current_area_vectors(X);
  const Eigen::MatrixXd fibers = fiber_forces(x);
  const Eigen::VectorXd external = external_forces(x, factors);
  Eigen::VectorXd R(num_unknowns());
  for (int a = 0; a < dim; ++a)
    R.segment(a * n, n) = fibers.col(a) + P * S.col(a) - external.segment(a * n, n);
  R[model_.pressure_dof()] =
      dim * C0_ * (geom::enclosed_volume(X, model_.surface.F) - volume0_);
  return R;
}

Eigen::MatrixXd Equilibrium::tangent(const Eigen::VectorXd& x,
                                     const std::vector<double>& factors) const {
  const Eigen::MatrixXd X = positions(model_, x), U = displacements(model_, x);
  const int n = model_.num_vertices(), dim = model_.dim(), p = model_.pressure_dof();
  const Eigen::Vector3d m = model_.material.axis_factors;
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(num_unknowns(), num_unknowns());
#pragma omp parallel
  {
    std::vector<double> row(static_cast<size_t>(n));
#pragma omp for schedule(dynamic, 16)
    for (int i = 0; i < n; ++i) {
      Eigen::Matrix3d diagonal = Eigen::Matrix3d::Zero();
      for_each_fiber(i, X, U, row, [&](int j, const BulkFiber& fiber) {
        const Eigen::Matrix3d T = fiber.tangent(m);
        diagonal += T;
        for (int a = 0; a < dim; ++a)
          for (int b = 0; b < dim; ++b) J(a * n + i, b * n + j) -= T(a, b);
      });
      for (int a = 0; a < dim; ++a)
        for (int b = 0; b < dim; ++b) J(a * n + i, b * n + i) += diagonal(a, b);
    }
  }
  const double gamma = model_.material.surface_tension;
  for (int col = 0; col < surface_.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(surface_, col); it; ++it)
      for (int a = 0; a < dim; ++a) J(a * n + it.row(), a * n + it.col()) += gamma * it.value();

  // Pressure and follower loads: (P - q_i) S_i(x), with dS_i/dx_v = C0 dA_f/dx_v
  // summed over the faces f at both i and v, and dq_i/dx_i = the gradient.
  const Hydrostatics hydro = hydrostatics(X, factors);
  const Eigen::VectorXd c = x[p] - hydro.q.array();
  const Eigen::MatrixXd S = current_area_vectors(X);
  const Eigen::MatrixXi& F = model_.surface.F;
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < F.cols(); ++k) {
      const Eigen::Matrix3d dA = C0_ * face_area_derivative(X, F, f, k);
      const int v = F(f, k);
      for (int corner = 0; corner < F.cols(); ++corner) {
        const int i = F(f, corner);
        for (int a = 0; a < dim; ++a)
          for (int b = 0; b < dim; ++b) J(a * n + i, b * n + v) += c[i] * dA(a, b);
      }
    }
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < dim; ++a) {
      for (int b = 0; b < dim; ++b) J(a * n + i, b * n + i) -= S(i, a) * hydro.gradient[b];
      J(a * n + i, p) = S(i, a);
      J(p, a * n + i) = S(i, a);
    }
  return J;
}

Eigen::VectorXd Equilibrium::tangent_product(const Eigen::VectorXd& x,
                                             const std::vector<double>& factors,
                                             const Eigen::VectorXd& v) const {
  const Eigen::MatrixXd X = positions(model_, x), U = displacements(model_, x);
  const Eigen::MatrixXd W = displacements(model_, v);
  const int n = model_.num_vertices(), dim = model_.dim(), p = model_.pressure_dof();
  const Eigen::Vector3d m = model_.material.axis_factors;
  Eigen::VectorXd out = Eigen::VectorXd::Zero(num_unknowns());
#pragma omp parallel
  {
    std::vector<double> row(static_cast<size_t>(n));
#pragma omp for schedule(dynamic, 16)
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d wi = row3(W, i);
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for_each_fiber(i, X, U, row, [&](int j, const BulkFiber& fiber) {
        sum += fiber.tangent_times(m, wi - row3(W, j));
      });
      for (int a = 0; a < dim; ++a) out[a * n + i] = sum[a];
    }
  }
  const Eigen::MatrixXd surface = model_.material.surface_tension * (surface_ * W);
  const Hydrostatics hydro = hydrostatics(X, factors);
  const Eigen::VectorXd c = x[p] - hydro.q.array();
  const Eigen::MatrixXd S = current_area_vectors(X);
  const Eigen::MatrixXi& F = model_.surface.F;
  Eigen::MatrixXd geometric = Eigen::MatrixXd::Zero(n, 3);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    // sum_v dA_f/dx_v w_v, then spread over the corners with their c_i.
    Eigen::Vector3d dA = Eigen::Vector3d::Zero();
    for (int k = 0; k < F.cols(); ++k)
      dA += face_area_derivative(X, F, f, k) * row3(W, F(f, k));
    for (int corner = 0; corner < F.cols(); ++corner)
      geometric.row(F(f, corner)) += C0_ * c[F(f, corner)] * dA.transpose();
  }
  double volume_rate = 0.0;
  for (int i = 0; i < n; ++i) {
    const double along = hydro.gradient.head(dim).dot(W.row(i).transpose());
    for (int a = 0; a < dim; ++a) {
      out[a * n + i] += surface(i, a) + geometric(i, a) - S(i, a) * along + S(i, a) * v[p];
      volume_rate += S(i, a) * W(i, a);
    }
  }
  out[p] = volume_rate;
  return out;
}

Eigen::MatrixXd Equilibrium::parameter_derivatives(const Eigen::VectorXd& x,
                                                   const std::vector<std::string>& names) const {
  const Eigen::MatrixXd X = positions(model_, x), U = displacements(model_, x);
  const int n = model_.num_vertices(), dim = model_.dim();
  const Eigen::Vector3d m = model_.material.axis_factors;
  const FiberLaw& law = model_.material.law;
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(num_unknowns(), static_cast<Eigen::Index>(names.size()));
  for (size_t k = 0; k < names.size(); ++k) {
    const std::string& name = names[k];
    const auto column = static_cast<Eigen::Index>(k);
    if (name == "gamma") {
      const Eigen::MatrixXd L = surface_ * U;
      for (int a = 0; a < dim; ++a) D.col(column).segment(a * n, n) = L.col(a);
      continue;
    }
    int axis = -1;  // factor_x: the fiber force of that axis over its factor
    if (name.rfind("factor_", 0) == 0 && name.size() == 8) axis = name[7] - 'x';
    if (axis >= dim) axis = -1;
    if (axis < 0) law.modulus_derivative(name, 0.0);  // throws for an unknown name
#pragma omp parallel
    {
      std::vector<double> row(static_cast<size_t>(n));
#pragma omp for schedule(dynamic, 16)
      for (int i = 0; i < n; ++i) {
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        const Eigen::Vector3d xi = row3(X, i);
        for_each_fiber(i, X, U, row, [&](int j, const BulkFiber& fiber) {
          if (axis >= 0) {
            sum[axis] += fiber.weight * fiber.modulus * fiber.d[axis];
          } else {
            const double strain = (xi - row3(X, j)).norm() / fiber.length - 1.0;
            sum += fiber.force_derivative(m, law.modulus_derivative(name, strain));
          }
        });
        for (int a = 0; a < dim; ++a) D(a * n + i, column) = sum[a];
      }
    }
  }
  return D;
}

}  // namespace fiberfluid::model
