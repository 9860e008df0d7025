// SPDX-License-Identifier: GPL-3.0-or-later
// CGAL stays in this file (see CMakeLists.txt: -g0).
#include "fiberfluid/geom/remesh.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Surface_mesh.h>

#include <cmath>
#include <map>
#include <vector>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/geom/cgal_surface_mesh.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::geom {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;

Surface from_cgal(const Mesh& mesh) {
  Surface s;
  s.dim = 3;
  s.V.resize(static_cast<Eigen::Index>(mesh.number_of_vertices()), 3);
  std::map<Mesh::Vertex_index, int> index;
  int next = 0;
  for (const Mesh::Vertex_index v : mesh.vertices()) {
    const Kernel::Point_3& p = mesh.point(v);
    s.V.row(next) << p.x(), p.y(), p.z();
    index[v] = next++;
  }
  s.F.resize(static_cast<Eigen::Index>(mesh.number_of_faces()), 3);
  int f = 0;
  for (const Mesh::Face_index face : mesh.faces()) {
    int corner = 0;
    for (const Mesh::Vertex_index v : vertices_around_face(mesh.halfedge(face), mesh))
      s.F(f, corner++) = index.at(v);
    ++f;
  }
  return s;
}

}  // namespace

Surface remesh_to_vertices(const Surface& s, int vertices, int iterations) {
  if (s.dim != 3) throw InputError("remesh: only a 3D triangle surface can be remeshed");
  if (vertices < 4) throw InputError("remesh: at least 4 vertices are needed");
  const Mesh original = to_surface_mesh<Mesh>(s, "remesh");
  const double area = face_area_vectors(s.V, s.F).rowwise().norm().sum();
  // 2 V equilateral triangles of edge l cover the area: 2 V (sqrt(3) / 4) l^2 = A.
  double edge = std::sqrt(2.0 * area / (std::sqrt(3.0) * vertices));
  namespace PMP = CGAL::Polygon_mesh_processing;
  // The count reached differs from the estimate by the shape's curvature and
  // the remesher's tolerances, and it moves in jumps on a coarse input: the
  // edge is corrected (the count goes as 1 / l^2) until the edges that gave
  // too many and too few vertices bracket the count, then bisected; the
  // closest of a few tries is kept.
  Mesh best;
  long best_miss = -1;
  double too_short = 0.0, too_long = 0.0;  // edges that gave too many, too few vertices
  for (int attempt = 0; attempt < 6; ++attempt) {
    Mesh mesh = original;
    PMP::isotropic_remeshing(
        faces(mesh), edge, mesh,
        PMP::parameters::number_of_iterations(static_cast<unsigned>(iterations)));
    mesh.collect_garbage();
    const long reached = static_cast<long>(mesh.number_of_vertices());
    const long miss = std::abs(reached - vertices);
    if (best_miss < 0 || miss < best_miss) {
      best = mesh;
      best_miss = miss;
    }
    if (miss <= vertices / 50) break;  // within 2%
    (reached > vertices ? too_short : too_long) = edge;
    edge = too_short > 0.0 && too_long > 0.0
               ? std::sqrt(too_short * too_long)
               : edge * std::sqrt(static_cast<double>(reached) / vertices);
  }
  return from_cgal(best);
}

}  // namespace fiberfluid::geom
