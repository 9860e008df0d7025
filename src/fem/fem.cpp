// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fem/fem.hpp"

#include <Eigen/LU>
#include <array>
#include <cmath>

#include "fiberfluid/fem/free_unknowns.hpp"
#include "fiberfluid/fem/tetrahedra.hpp"
#include "fiberfluid/linalg/sparse_cholesky.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::fem {
namespace {

// The corners of the reference element [-1, 1]^dim in the node order of Mesh.
double corner_sign(int node, int axis) {
  static const int signs2[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  if (axis == 2) return node < 4 ? -1.0 : 1.0;
  return signs2[node % 4][axis];
}

// Shape functions and their derivatives in the reference coordinates xi.
void shape(const Eigen::VectorXd& xi, int dim, Eigen::VectorXd* N, Eigen::MatrixXd* dN) {
  const int n = 1 << dim;
  N->resize(n);
  dN->resize(n, dim);  // dN(a, i) = dN_a / dxi_i
  for (int a = 0; a < n; ++a) {
    double value = 1.0;
    for (int i = 0; i < dim; ++i) value *= 0.5 * (1.0 + corner_sign(a, i) * xi[i]);
    (*N)[a] = value;
    for (int i = 0; i < dim; ++i) {
      double d = 0.5 * corner_sign(a, i);
      for (int j = 0; j < dim; ++j)
        if (j != i) d *= 0.5 * (1.0 + corner_sign(a, j) * xi[j]);
      (*dN)(a, i) = d;
    }
  }
}

// The 2^dim Gauss points (weights 1) of the 2-point rule per axis.
std::vector<Eigen::VectorXd> gauss_points(int dim) {
  const double g = 1.0 / std::sqrt(3.0);
  std::vector<Eigen::VectorXd> points;
  for (int p = 0; p < (1 << dim); ++p) {
    Eigen::VectorXd xi(dim);
    for (int i = 0; i < dim; ++i) xi[i] = (p >> i) & 1 ? g : -g;
    points.push_back(xi);
  }
  return points;
}

// At a Gauss point: the physical derivatives dN/dx (#nodes x dim) and
// det J; throws for an inverted or degenerate element.
double physical_derivatives(const Eigen::MatrixXd& corners, const Eigen::MatrixXd& dN_dxi,
                            Eigen::MatrixXd* dN_dx) {
  const Eigen::MatrixXd J = corners.transpose() * dN_dxi;  // J(i, k) = dx_i / dxi_k
  const double det = J.determinant();
  if (!(det > 0.0)) throw InputError("fem: an element is inverted or degenerate (det J <= 0)");
  *dN_dx = dN_dxi * J.inverse();
  return det;
}

// The strain-displacement matrix B (Voigt rows of elasticity_matrix).
Eigen::MatrixXd strain_matrix(const Eigen::MatrixXd& dN, int dim) {
  const int n = static_cast<int>(dN.rows());
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(dim == 2 ? 3 : 6, dim * n);
  for (int a = 0; a < n; ++a) {
    const int c = dim * a;
    if (dim == 2) {
      B(0, c) = dN(a, 0);
      B(1, c + 1) = dN(a, 1);
      B(2, c) = dN(a, 1);
      B(2, c + 1) = dN(a, 0);
    } else {
      for (int i = 0; i < 3; ++i) B(i, c + i) = dN(a, i);
      B(3, c + 1) = dN(a, 2);  // 2 eyz
      B(3, c + 2) = dN(a, 1);
      B(4, c) = dN(a, 2);  // 2 exz
      B(4, c + 2) = dN(a, 0);
      B(5, c) = dN(a, 1);  // 2 exy
      B(5, c + 1) = dN(a, 0);
    }
  }
  return B;
}

enum class ElementKind { Box, Simplex, QuadraticTetrahedron };

// Quadrilaterals and hexahedra have 2^dim corners, triangles and tetrahedra
// dim + 1 nodes, quadratic tetrahedra 10.
ElementKind element_kind(const Eigen::MatrixXd& nodes) {
  const int dim = static_cast<int>(nodes.cols()), n = static_cast<int>(nodes.rows());
  if (dim == 3 && n == 10) return ElementKind::QuadraticTetrahedron;
  if ((dim != 2 && dim != 3) || (n != (1 << dim) && n != dim + 1))
    throw InputError(
        "fem: an element needs 4 corners (a quadrilateral) or 3 (a triangle) in "
        "2D, 8 (a hexahedron), 4 (a tetrahedron) or 10 nodes (a quadratic "
        "tetrahedron) in 3D");
  return n == dim + 1 ? ElementKind::Simplex : ElementKind::Box;
}

// The stiffness or the mass of a quadratic tetrahedron (straight or curved)
// by quadrature: degree 2 for the stiffness (exact on straight edges),
// degree 4 for the mass.
Eigen::MatrixXd quadratic_tetrahedron_matrix(const Eigen::MatrixXd& nodes, const Material& m,
                                             bool stiffness) {
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(30, 30);
  const Eigen::MatrixXd D = elasticity_matrix(m, 3);
  const TetrahedronRule rule = tetrahedron_rule(stiffness ? 2 : 4);
  Eigen::VectorXd N;
  Eigen::MatrixXd dN_dxi, dN_dx;
  for (size_t q = 0; q < rule.points.size(); ++q) {
    tetrahedron_shape(10, rule.points[q], &N, &dN_dxi);
    const double dV = rule.weights[q] * physical_derivatives(nodes, dN_dxi, &dN_dx);
    if (stiffness) {
      const Eigen::MatrixXd B = strain_matrix(dN_dx, 3);
      out += dV * B.transpose() * D * B;
    } else {
      for (int a = 0; a < 10; ++a)
        for (int b = 0; b < 10; ++b)
          for (int i = 0; i < 3; ++i) out(3 * a + i, 3 * b + i) += m.density * dV * N[a] * N[b];
    }
  }
  return out;
}

// A linear simplex: constant shape derivatives (#nodes x dim) and its measure.
double simplex_derivatives(const Eigen::MatrixXd& corners, Eigen::MatrixXd* dN_dx) {
  const int dim = static_cast<int>(corners.cols());
  Eigen::MatrixXd dN_dxi = Eigen::MatrixXd::Zero(dim + 1, dim);  // N0 = 1 - sum xi, Ni = xi_i
  dN_dxi.row(0).setConstant(-1.0);
  dN_dxi.bottomRows(dim).setIdentity();
  const double det = physical_derivatives(corners, dN_dxi, dN_dx);
  return det / (dim == 2 ? 2.0 : 6.0);
}

Eigen::SparseMatrix<double> assemble(const Mesh& mesh, const Material& m, bool stiffness) {
  const int dim = mesh.dim, per = static_cast<int>(mesh.elements.cols());
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<size_t>(mesh.elements.rows()) * (dim * per) * (dim * per));
  Eigen::MatrixXd corners(per, dim);
  for (Eigen::Index e = 0; e < mesh.elements.rows(); ++e) {
    for (int a = 0; a < per; ++a) corners.row(a) = mesh.nodes.row(mesh.elements(e, a));
    const Eigen::MatrixXd k = stiffness ? element_stiffness(corners, m) : element_mass(corners, m);
    for (int a = 0; a < per; ++a)
      for (int i = 0; i < dim; ++i)
        for (int b = 0; b < per; ++b)
          for (int j = 0; j < dim; ++j)
            entries.emplace_back(dim * mesh.elements(e, a) + i, dim * mesh.elements(e, b) + j,
                                 k(dim * a + i, dim * b + j));
  }
  Eigen::SparseMatrix<double> A(mesh.num_dofs(), mesh.num_dofs());
  A.setFromTriplets(entries.begin(), entries.end());
  A.prune(0.0);
  return A;
}

}  // namespace

Mesh structured_grid(const Eigen::VectorXd& size, const Eigen::VectorXi& cells) {
  const int dim = static_cast<int>(size.size());
  if ((dim != 2 && dim != 3) || cells.size() != dim || (cells.array() < 1).any() ||
      !(size.array() > 0.0).all())
    throw InputError("fem: a grid needs 2 or 3 positive sizes and at least one cell per axis");
  Mesh mesh;
  mesh.dim = dim;
  const int nx = cells[0], ny = cells[1], nz = dim == 3 ? cells[2] : 0;
  const int layers = nz + 1;
  mesh.nodes.resize((nx + 1) * (ny + 1) * layers, dim);
  auto id = [&](int i, int j, int k) { return i + (nx + 1) * (j + (ny + 1) * k); };
  for (int k = 0; k < layers; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        mesh.nodes(id(i, j, k), 0) = size[0] * i / nx;
        mesh.nodes(id(i, j, k), 1) = size[1] * j / ny;
        if (dim == 3) mesh.nodes(id(i, j, k), 2) = size[2] * k / nz;
      }
  mesh.elements.resize(nx * ny * std::max(nz, 1), 1 << dim);
  int e = 0;
  for (int k = 0; k < std::max(nz, 1); ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i, ++e) {
        const std::array<int, 4> bottom = {id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k),
                                           id(i, j + 1, k)};
        for (int a = 0; a < 4; ++a) mesh.elements(e, a) = bottom[static_cast<size_t>(a)];
        if (dim == 3)
          for (int a = 0; a < 4; ++a)
            mesh.elements(e, 4 + a) = bottom[static_cast<size_t>(a)] + (nx + 1) * (ny + 1);
      }
  return mesh;
}

Eigen::MatrixXd elasticity_matrix(const Material& m, int dim) {
  if (!(m.young > 0.0) || !(m.poisson > -1.0 && m.poisson < 0.5))
    throw InputError("fem: the material needs E > 0 and -1 < nu < 0.5");
  const double E = m.young, nu = m.poisson;
  const double lambda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), mu = E / (2.0 * (1.0 + nu));
  if (dim == 2) {
    Eigen::MatrixXd D = Eigen::MatrixXd::Zero(3, 3);
    if (m.plane == PlaneModel::Strain) {
      D << lambda + 2 * mu, lambda, 0, lambda, lambda + 2 * mu, 0, 0, 0, mu;
    } else {
      const double c = E / (1.0 - nu * nu);
      D << c, c * nu, 0, c * nu, c, 0, 0, 0, c * (1.0 - nu) / 2.0;
    }
    return D;
  }
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(6, 6);
  D.topLeftCorner(3, 3).setConstant(lambda);
  for (int i = 0; i < 3; ++i) {
    D(i, i) += 2.0 * mu;
    D(3 + i, 3 + i) = mu;
  }
  return D;
}

Eigen::MatrixXd element_stiffness(const Eigen::MatrixXd& corners, const Material& m) {
  const ElementKind kind = element_kind(corners);
  if (kind == ElementKind::QuadraticTetrahedron)
    return quadratic_tetrahedron_matrix(corners, m, true);
  const bool simplex = kind == ElementKind::Simplex;
  const int dim = static_cast<int>(corners.cols());
  const Eigen::MatrixXd D = elasticity_matrix(m, dim);
  if (simplex) {  // constant strain: one point is exact
    Eigen::MatrixXd dN_dx;
    const double measure = simplex_derivatives(corners, &dN_dx);
    const Eigen::MatrixXd B = strain_matrix(dN_dx, dim);
    return measure * B.transpose() * D * B;
  }
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(dim * corners.rows(), dim * corners.rows());
  Eigen::VectorXd N;
  Eigen::MatrixXd dN_dxi, dN_dx;
  for (const Eigen::VectorXd& xi : gauss_points(dim)) {
    shape(xi, dim, &N, &dN_dxi);
    const double det = physical_derivatives(corners, dN_dxi, &dN_dx);
    const Eigen::MatrixXd B = strain_matrix(dN_dx, dim);
    K += det * B.transpose() * D * B;
  }
  return K;
}

Eigen::MatrixXd element_mass(const Eigen::MatrixXd& corners, const Material& m) {
  const ElementKind kind = element_kind(corners);
  if (kind == ElementKind::QuadraticTetrahedron)
    return quadratic_tetrahedron_matrix(corners, m, false);
  const bool simplex = kind == ElementKind::Simplex;
  const int dim = static_cast<int>(corners.cols()), n = static_cast<int>(corners.rows());
  Eigen::MatrixXd scalar = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd N;
  Eigen::MatrixXd dN_dxi, dN_dx;
  if (simplex) {  // the exact integral of N_a N_b: |T| (1 + delta_ab) / ((d + 1)(d + 2))
    const double measure = simplex_derivatives(corners, &dN_dx);
    scalar.setConstant(m.density * measure / ((dim + 1) * (dim + 2)));
    scalar.diagonal() *= 2.0;
  } else {
    for (const Eigen::VectorXd& xi : gauss_points(dim)) {
      shape(xi, dim, &N, &dN_dxi);
      const double det = physical_derivatives(corners, dN_dxi, &dN_dx);
      scalar += m.density * det * N * N.transpose();
    }
  }
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(dim * n, dim * n);
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b)
      for (int i = 0; i < dim; ++i) M(dim * a + i, dim * b + i) = scalar(a, b);
  return M;
}

Eigen::SparseMatrix<double> stiffness_matrix(const Mesh& mesh, const Material& m) {
  return assemble(mesh, m, true);
}
Eigen::SparseMatrix<double> mass_matrix(const Mesh& mesh, const Material& m) {
  return assemble(mesh, m, false);
}
Eigen::VectorXd lumped_mass(const Mesh& mesh, const Material& m) {
  const Eigen::SparseMatrix<double> M = mass_matrix(mesh, m);
  return M * Eigen::VectorXd::Ones(M.cols());
}

Eigen::VectorXd body_forces(const Mesh& mesh, const Material& m, const Eigen::VectorXd& g) {
  if (g.size() != mesh.dim) throw InputError("fem: the body force needs one value per axis");
  Eigen::VectorXd per_unit(mesh.num_dofs());
  for (int v = 0; v < mesh.num_nodes(); ++v) per_unit.segment(mesh.dim * v, mesh.dim) = g;
  return mass_matrix(mesh, m) * per_unit;
}

linalg::Status solve_static(const Eigen::SparseMatrix<double>& K, const Eigen::VectorXd& f,
                            const Constraints& held, Eigen::VectorXd* u) {
  const int n = static_cast<int>(K.rows());
  Eigen::VectorXd fixed = Eigen::VectorXd::Zero(n);
  for (size_t c = 0; c < held.dofs.size(); ++c) {
    const int d = held.dofs[c];
    if (d < 0 || d >= n) return linalg::Status::failure("fem: a held unknown is out of range");
    fixed[d] = held.values[c];
  }
  // K_ff u_f = f_f - K_fh u_h.
  const FreeUnknowns split(n, held.dofs);
  const Eigen::SparseMatrix<double> Kff = split.free_block(K);
  const Eigen::VectorXd rhs = split.restrict(f - K * fixed);
  linalg::SparseCholesky cholesky;
  cholesky.analyze_pattern(Kff);
  const linalg::Status status = cholesky.factorize(Kff);
  if (!status.ok)
    return linalg::Status::failure("fem: the stiffness is singular on the free unknowns: " +
                                   status.message);
  *u = fixed;
  split.scatter(cholesky.solve(rhs), *u);
  return {};
}

}  // namespace fiberfluid::fem
