// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// Shape functions and quadrature of the linear (4-node) and quadratic
// (10-node) tetrahedron, for the elements that integrate over points rather
// than in closed form (the quadratic ones, straight or curved).
//
// Reference coordinates xi = (xi1, xi2, xi3) with the barycentric coordinates
// L0 = 1 - xi1 - xi2 - xi3, L1 = xi1, L2 = xi2, L3 = xi3. Node order (VTK's
// VTK_TETRA and VTK_QUADRATIC_TETRA): the corners 0..3, then the edges' middle
// nodes 4:(0,1) 5:(1,2) 6:(0,2) 7:(0,3) 8:(1,3) 9:(2,3). Quadratic shape
// functions: L_i (2 L_i - 1) at a corner, 4 L_i L_j on an edge (Zienkiewicz,
// Taylor and Zhu, "The Finite Element Method: Its Basis and Fundamentals",
// 7th ed., section 6.5).

#include <Eigen/Core>
#include <array>
#include <vector>

namespace fiberfluid::fem {

// The corners joined by each edge, in the order of the middle nodes 4..9.
inline constexpr std::array<std::array<int, 2>, 6> kTetrahedronEdges = {
    {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}}};

// Linear (4 nodes) or quadratic (10 nodes); anything else throws InputError.
bool is_quadratic_tetrahedron(int nodes_per_element);

// Values N (nodes) and reference derivatives dN (nodes x 3, dN(a, k) =
// dN_a / dxi_k) of the shape functions at xi.
void tetrahedron_shape(int nodes_per_element, const Eigen::Vector3d& xi, Eigen::VectorXd* N,
                       Eigen::MatrixXd* dN);

// Points in reference coordinates with weights summing to the reference
// volume 1/6.
struct TetrahedronRule {
  std::vector<Eigen::Vector3d> points;
  std::vector<double> weights;
};
// Exact for polynomials of the given degree: 1 the centroid, 2 the symmetric
// 4-point rule (barycentric (a, b, b, b), a = (5 + 3 sqrt 5) / 20, weights
// equal; exact for a quadratic element's stiffness on straight edges), and
// above that a conical product of Gauss-Legendre rules (Stroud, "Approximate
// calculation of multiple integrals", 1971, section 2.7), all weights
// positive.
TetrahedronRule tetrahedron_rule(int degree);

}  // namespace fiberfluid::fem
