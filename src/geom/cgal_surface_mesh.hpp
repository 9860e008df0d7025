// SPDX-License-Identifier: GPL-3.0-or-later
// Internal to the .cpp files that use CGAL (they include CGAL's Surface_mesh
// and choose its kernel): a Surface as a CGAL::Surface_mesh.
#pragma once

#include <string>
#include <vector>

#include "fiberfluid/geom/surface.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::geom {

// The triangle surface as a CGAL mesh (any kernel's Surface_mesh), its faces
// in order. Only the vertices of some face are added: CGAL's volume
// predicates (does_bound_a_volume) fail on isolated vertices, and remeshing
// would keep them. Throws InputError, `what` first, for a face that names a
// missing vertex or does not make a manifold.
template <class MeshType>
MeshType to_surface_mesh(const Surface& s, const std::string& what) {
  using Point = typename MeshType::Point;
  MeshType mesh;
  for (int f = 0; f < s.num_faces(); ++f)
    for (int k = 0; k < 3; ++k)
      if (s.F(f, k) < 0 || s.F(f, k) >= s.num_vertices())
        throw InputError(what + ": face " + std::to_string(f) + " refers to a missing vertex");
  std::vector<typename MeshType::Vertex_index> vertices(static_cast<size_t>(s.num_vertices()),
                                                        MeshType::null_vertex());
  for (int f = 0; f < s.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int v = s.F(f, k);
      if (vertices[static_cast<size_t>(v)] == MeshType::null_vertex())
        vertices[static_cast<size_t>(v)] = mesh.add_vertex(Point(s.V(v, 0), s.V(v, 1), s.V(v, 2)));
    }
  for (int f = 0; f < s.num_faces(); ++f) {
    if (mesh.add_face(vertices[static_cast<size_t>(s.F(f, 0))],
                      vertices[static_cast<size_t>(s.F(f, 1))],
                      vertices[static_cast<size_t>(s.F(f, 2))]) == MeshType::null_face())
      throw InputError(what + ": face " + std::to_string(f) + " makes the mesh non-manifold");
  }
  return mesh;
}

}  // namespace fiberfluid::geom
