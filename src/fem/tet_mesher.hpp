// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// Linear tetrahedra filling a closed surface (CGAL's Mesh_3 on the
// polyhedral domain the surface bounds, its sharp edges protected), so that
// any organ shape the fiber model runs on can be run by finite elements too.
// The boundary of the result approximates the surface (within
// facet_distance); its nodes are not the surface's vertices.

#include "fiberfluid/fem/fem.hpp"
#include "fiberfluid/geom/surface.hpp"

namespace fiberfluid::fem {

struct TetMeshOptions {
  // Target edge length of tetrahedra and boundary triangles (m); 0: a
  // twelfth of the bounding box's diagonal.
  double size = 0.0;
  // Largest distance of a boundary triangle's centre from the surface (m);
  // 0: size / 20.
  double facet_distance = 0.0;
  // Surface edges whose faces meet at more than this angle (degrees, between
  // normals) are kept as edges of the mesh; 180: none.
  double feature_angle = 60.0;
};

// Throws InputError when the surface is not a closed 3D triangle mesh or
// the mesher produces no tetrahedra. Deterministic: the same input gives the
// same mesh.
Mesh tetrahedralize(const geom::Surface& closed_surface, const TetMeshOptions& options = {});

}  // namespace fiberfluid::fem
