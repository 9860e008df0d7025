// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include "fiberfluid/geom/surface.hpp"

namespace fiberfluid::geom {

// The closed triangle surface `s` remeshed isotropically to about `vertices`
// vertices: nearly equilateral triangles of one edge length, on the same
// shape (Botsch and Kobbelt 2004, "A remeshing approach to multiresolution
// modeling", through CGAL's Polygon_mesh_processing::isotropic_remeshing).
// The edge length is the one whose equilateral triangles, 2 V of them (a
// closed surface's Euler count), tile the surface's area; the count reached
// is near the one asked (within 2% where three tries reach it). Deterministic: the same surface and
// count give the same mesh. Throws InputError for a 2D outline or a surface
// CGAL cannot take as a closed triangle mesh.
Surface remesh_to_vertices(const Surface& s, int vertices, int iterations = 5);

}  // namespace fiberfluid::geom
