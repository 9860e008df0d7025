// SPDX-License-Identifier: GPL-3.0-or-later
// CGAL stays in this file (see CMakeLists.txt: -g0).
#include "fiberfluid/geom/self_intersection.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <vector>

namespace fiberfluid::geom {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;

std::optional<std::pair<int, int>> crossing_segments(const Surface& s) {
  // O(n^2) with exact orientation tests: outlines have few segments.
  using P = Kernel::Point_2;
  auto point = [&](int v) { return P(s.V(v, 0), s.V(v, 1)); };
  for (int a = 0; a < s.num_faces(); ++a)
    for (int b = a + 1; b < s.num_faces(); ++b) {
      const int a0 = s.F(a, 0), a1 = s.F(a, 1), b0 = s.F(b, 0), b1 = s.F(b, 1);
      const bool adjacent = a0 == b0 || a0 == b1 || a1 == b0 || a1 == b1;
      const Kernel::Segment_2 sa(point(a0), point(a1)), sb(point(b0), point(b1));
      if (!adjacent) {
        if (CGAL::do_intersect(sa, sb)) return std::make_pair(a, b);
      } else if (CGAL::collinear(sa.source(), sa.target(), sb.source()) &&
                 CGAL::collinear(sa.source(), sa.target(), sb.target())) {
        // Adjacent segments meet at their shared end; they overlap only when
        // they fold back on each other along one line.
        const int shared = (a0 == b0 || a0 == b1) ? a0 : a1;
        const int other_a = shared == a0 ? a1 : a0, other_b = (b0 == shared) ? b1 : b0;
        const auto da = point(other_a) - point(shared), db = point(other_b) - point(shared);
        if (da * db > 0) return std::make_pair(a, b);
      }
    }
  return std::nullopt;
}

}  // namespace

std::optional<std::pair<int, int>> find_self_intersection(const Surface& s) {
  if (s.dim == 2) return crossing_segments(s);
  Mesh mesh;
  std::vector<Mesh::Vertex_index> vertex;
  for (int v = 0; v < s.num_vertices(); ++v)
    vertex.push_back(mesh.add_vertex(Kernel::Point_3(s.V(v, 0), s.V(v, 1), s.V(v, 2))));
  std::vector<int> face_of;  // CGAL's face index -> ours
  for (int f = 0; f < s.num_faces(); ++f) {
    const auto face = mesh.add_face(vertex[static_cast<size_t>(s.F(f, 0))],
                                    vertex[static_cast<size_t>(s.F(f, 1))],
                                    vertex[static_cast<size_t>(s.F(f, 2))]);
    if (face == Mesh::null_face()) return std::nullopt;  // not manifold: inspect() says so
    face_of.resize(static_cast<size_t>(face.idx()) + 1, -1);
    face_of[face.idx()] = f;
  }
  std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> pairs;
  // The first pair is enough: stop at it.
  struct Found {};
  try {
    struct Stop {
      std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>>* out;
      Stop& operator=(const std::pair<Mesh::Face_index, Mesh::Face_index>& p) {
        out->push_back(p);
        throw Found{};
      }
      Stop& operator*() { return *this; }
      Stop& operator++() { return *this; }
      Stop operator++(int) { return *this; }
    };
    CGAL::Polygon_mesh_processing::self_intersections(mesh, Stop{&pairs});
  } catch (const Found&) {
  }
  if (pairs.empty()) return std::nullopt;
  return std::make_pair(face_of[pairs.front().first.idx()], face_of[pairs.front().second.idx()]);
}

}  // namespace fiberfluid::geom
