// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// Linear-elastic finite elements for the accuracy benchmarks (Alterovitz and
// Goldberg; docs: benchmarks.md): bilinear quadrilaterals (Q1, 2D) and
// trilinear hexahedra (3D) with 2 x 2 (x 2) Gauss quadrature, linear
// triangles and tetrahedra (P1, for organ shapes) exact with one point, and
// quadratic tetrahedra (P2, 10 nodes, straight or curved; fem/tetrahedra.hpp)
// by quadrature; small strains.
// Unknowns are ordered node by node: u = (u0x, u0y[, u0z], u1x, ...).

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

#include "fiberfluid/linalg/status.hpp"

namespace fiberfluid::fem {

// A mesh of one element kind, told by the nodes per element: Q1
// quadrilaterals (dim 2, 4 nodes counterclockwise), hexahedra (dim 3, 8
// nodes: the bottom face counterclockwise seen from above, then the top face
// above it), positively oriented simplices (dim + 1 nodes), or quadratic
// tetrahedra (dim 3, 10 nodes: a positively oriented tetrahedron's corners,
// then its edges' middle nodes in VTK's order, fem/tetrahedra.hpp).
struct Mesh {
  int dim = 2;
  Eigen::MatrixXd nodes;     // #nodes x dim
  Eigen::MatrixXi elements;  // #elements x nodes per element
  int num_nodes() const { return static_cast<int>(nodes.rows()); }
  int num_dofs() const { return dim * num_nodes(); }
};

// A structured grid of the box [0, size] with `cells` elements per axis
// (size and cells of length dim). Node (i, j[, k]) is i + (nx+1) (j + (ny+1) k).
Mesh structured_grid(const Eigen::VectorXd& size, const Eigen::VectorXi& cells);

// 2D elements model a slab: plane strain (thick: no strain across it, the
// default, as for a block of tissue) or plane stress (thin: no stress
// across it).
enum class PlaneModel { Strain, Stress };

struct Material {
  double young = 1.0;  // Pa
  double poisson = 0.3;
  double density = 1.0;  // kg/m^3 (per unit thickness in 2D)
  PlaneModel plane = PlaneModel::Strain;
};

// The isotropic elasticity matrix D (3 x 3 in 2D with Voigt strains
// exx, eyy, 2exy; 6 x 6 in 3D with exx, eyy, ezz, 2eyz, 2exz, 2exy).
Eigen::MatrixXd elasticity_matrix(const Material& m, int dim);

// Element matrices at the element's node coordinates (#nodes x dim).
Eigen::MatrixXd element_stiffness(const Eigen::MatrixXd& corners, const Material& m);
Eigen::MatrixXd element_mass(const Eigen::MatrixXd& corners, const Material& m);

// Global matrices (symmetric, #dofs square). The lumped mass is the row sums
// of the consistent one (positive for linear elements; a quadratic
// tetrahedron's corners get a negative share).
Eigen::SparseMatrix<double> stiffness_matrix(const Mesh& mesh, const Material& m);
Eigen::SparseMatrix<double> mass_matrix(const Mesh& mesh, const Material& m);
Eigen::VectorXd lumped_mass(const Mesh& mesh, const Material& m);

// Body force per unit mass (e.g. gravity), as consistent nodal forces M g.
Eigen::VectorXd body_forces(const Mesh& mesh, const Material& m, const Eigen::VectorXd& g);

// Prescribed values of some unknowns (held), the rest free.
struct Constraints {
  std::vector<int> dofs;
  std::vector<double> values;
  void hold(int dof, double value) {
    dofs.push_back(dof);
    values.push_back(value);
  }
};

// K u = f with the held unknowns eliminated (CHOLMOD). `u` has every
// unknown; the status fails when K restricted to the free unknowns is not
// positive definite (too few supports).
linalg::Status solve_static(const Eigen::SparseMatrix<double>& K, const Eigen::VectorXd& f,
                            const Constraints& held, Eigen::VectorXd* u);

}  // namespace fiberfluid::fem
