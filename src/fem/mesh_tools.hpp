// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// What the benchmarks need of a finite-element mesh besides its matrices:
// simplices from a structured grid, its boundary as a closed surface (for
// the surface error and the fiber model), and each node's share of the body.

#include <Eigen/Core>
#include <vector>

#include "fiberfluid/fem/fem.hpp"
#include "fiberfluid/geom/surface.hpp"

namespace fiberfluid::fem {

// Each quadrilateral split into 2 triangles, each hexahedron into 6
// tetrahedra around its diagonal from corner 0 to corner 6 (the Kuhn
// split: neighbouring cells of a structured grid split shared faces alike,
// so the result is conforming). Simplices stay positively oriented.
Mesh to_simplices(const Mesh& mesh);

// The boundary of a mesh as a closed, outward surface: a polygon (2D; its
// segments chained counterclockwise) or triangles (3D; quadrilateral faces
// split in two). surface.V are the positions of `nodes` (mesh node indices)
// at `positions` (#nodes x dim, e.g. the deformed nodes).
struct Boundary {
  geom::Surface surface;
  std::vector<int> nodes;  // surface vertex -> mesh node
};
Boundary boundary(const Mesh& mesh);
Boundary boundary(const Mesh& mesh, const Eigen::MatrixXd& positions);

// Each node's share of the body's area or volume (the lumped mass at unit
// density): the weights of the interior error E_i. They sum to the body's measure.
Eigen::VectorXd node_measures(const Mesh& mesh);

// Displacements u (node by node) as #nodes x dim, and positions x0 + u.
Eigen::MatrixXd displacement_rows(const Eigen::VectorXd& u, int dim);

}  // namespace fiberfluid::fem
