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
// split in two, a quadratic tetrahedron's 6-node faces in four at their
// middle nodes). surface.V are the positions of `nodes` (mesh node indices)
// at `positions` (#nodes x dim, e.g. the deformed nodes).
struct Boundary {
  geom::Surface surface;
  std::vector<int> nodes;  // surface vertex -> mesh node
};
Boundary boundary(const Mesh& mesh);
Boundary boundary(const Mesh& mesh, const Eigen::MatrixXd& positions);

// Each node's share of the body's area or volume (the lumped mass at unit
// density): the weights of the interior error E_i. They sum to the body's
// measure. Linear elements only (InputError for quadratic tetrahedra, whose
// corners' shares are negative).
Eigen::VectorXd node_measures(const Mesh& mesh);

// Linear tetrahedra made quadratic (10 nodes): a node in the middle of every
// edge, shared by the tetrahedra around it. The corners keep their numbers
// (0..#nodes-1); the middle nodes follow, on the straight edges.
Mesh to_quadratic(const Mesh& linear_tetrahedra);

// A thick tube about the z axis (inner radius > 0), from z = 0 to `length`:
// radial x around x along hexahedra in cylindrical coordinates, each split in
// 6 tetrahedra (to_simplices). Order 2 makes them quadratic with the middle
// nodes on the cylinders and circles the edges approximate (isoparametric: a
// quadratic mesh's boundary is the tube's within O(h^3)). The closed forms
// of torsion and inflation are posed on it (docs/benchmarks.md).
struct TubeMeshSpec {
  double inner_radius = 0.5, outer_radius = 1.0, length = 1.0;
  int radial = 1, around = 8, along = 1;
  int order = 1;
};
Mesh tube_mesh(const TubeMeshSpec& spec);

// An octant (x, y, z >= 0) of a thick spherical shell: the octant's sphere
// triangle cut into `around`^2 triangles (no pole: every cell is well
// shaped), extruded through `radial` layers into prisms, each split into 3
// tetrahedra by the smallest-index rule (Dompierre et al., "How to subdivide
// pyramids, prisms and hexahedra into tetrahedra", 1999: neighbours then
// split their shared faces alike). Order 2 puts the middle nodes on the
// spheres (isoparametric), as tube_mesh does.
struct ShellMeshSpec {
  double inner_radius = 0.5, outer_radius = 1.0;
  int around = 4, radial = 2;
  int order = 1;
};
Mesh shell_octant_mesh(const ShellMeshSpec& spec);

// Displacements u (node by node) as #nodes x dim, and positions x0 + u.
Eigen::MatrixXd displacement_rows(const Eigen::VectorXd& u, int dim);

}  // namespace fiberfluid::fem
