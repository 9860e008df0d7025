// SPDX-License-Identifier: GPL-3.0-or-later
// E_s's symmetric difference, exactly (CGAL, kept inside this file: its
// headers compile slowly). |A xor B| = |A| + |B| - 2 |A and B| with exact
// arithmetic for the intersection: 2D Boolean operations on polygons, 3D
// corefinement of closed triangle meshes.
#include <CGAL/Boolean_set_operations_2.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_2.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_with_holes_2.h>
#include <CGAL/Surface_mesh.h>

#include <Eigen/Geometry>
#include <cmath>
#include <iterator>
#include <vector>

#include "fiberfluid/geom/cgal_surface_mesh.hpp"
#include "fiberfluid/metrics/metrics.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::metrics {
namespace {

using Kernel = CGAL::Exact_predicates_exact_constructions_kernel;
using Polygon = CGAL::Polygon_2<Kernel>;
using PolygonWithHoles = CGAL::Polygon_with_holes_2<Kernel>;
using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;
// The checks need exact predicates only: filtered doubles are many times
// faster than exact constructions on meshes of thousands of triangles.
using CheckKernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using CheckMesh = CGAL::Surface_mesh<CheckKernel::Point_3>;
namespace PMP = CGAL::Polygon_mesh_processing;

// The 2D surface's segments as one closed loop, counterclockwise.
Polygon polygon(const geom::Surface& s, const std::string& what) {
  require_representable(s, what);
  const int n = s.num_vertices();
  std::vector<int> next(static_cast<size_t>(n), -1);
  for (int f = 0; f < s.num_faces(); ++f) {
    const int a = s.F(f, 0), b = s.F(f, 1);
    if (a < 0 || a >= n || b < 0 || b >= n || next[static_cast<size_t>(a)] >= 0)
      throw InputError(what + ": its segments do not form one closed polygon (segment " +
                       std::to_string(f) + ")");
    next[static_cast<size_t>(a)] = b;
  }
  Polygon p;
  int v = s.num_faces() > 0 ? s.F(0, 0) : -1;
  for (int k = 0; k < s.num_faces(); ++k) {
    if (v < 0) break;
    p.push_back(Kernel::Point_2(s.V(v, 0), s.V(v, 1)));
    v = next[static_cast<size_t>(v)];
  }
  if (s.num_faces() < 3 || v != s.F(0, 0) || static_cast<int>(p.size()) != s.num_faces())
    throw InputError(what + ": its segments do not form one closed polygon");
  if (!p.is_simple())
    throw InputError(what + ": the polygon crosses itself, so it bounds no region");
  if (p.orientation() == CGAL::CLOCKWISE) p.reverse_orientation();
  return p;
}

double area(const PolygonWithHoles& p) {
  Kernel::FT a = p.outer_boundary().area();
  for (auto h = p.holes_begin(); h != p.holes_end(); ++h) a += h->area();  // holes are clockwise
  return CGAL::to_double(a);
}

double symmetric_difference_2d(const geom::Surface& a, const geom::Surface& b,
                               const std::string& what_a, const std::string& what_b) {
  const Polygon p = polygon(a, what_a), q = polygon(b, what_b);
  std::vector<PolygonWithHoles> both;
  CGAL::intersection(p, q, std::back_inserter(both));
  double common = 0.0;
  for (const PolygonWithHoles& piece : both) common += area(piece);
  return CGAL::to_double(p.area()) + CGAL::to_double(q.area()) - 2.0 * common;
}

// A closed, outward, self-intersection-free triangle mesh (checked with
// filtered predicates, built again with exact constructions).
Mesh solid(const geom::Surface& s, const std::string& what) {
  require_representable(s, what);
  if (s.num_faces() == 0)
    throw InputError(what + ": has no faces (a point cloud), so it bounds no solid");
  CheckMesh check = geom::to_surface_mesh<CheckMesh>(s, what);
  if (check.is_empty() || !CGAL::is_closed(check))
    throw InputError(what + ": the mesh is not closed, so it bounds no solid");
  if (PMP::does_self_intersect(check))
    throw InputError(what + ": the mesh intersects itself (an inverted or overlapping part)");
  Mesh mesh = geom::to_surface_mesh<Mesh>(s, what);
  const bool outward = PMP::is_outward_oriented(check);
  if (!outward) {
    PMP::reverse_face_orientations(check);
    PMP::reverse_face_orientations(mesh);
  }
  // Nested shells bound a solid only if they alternate (a shell inside a
  // shell is a cavity and faces inward); corefinement is undefined otherwise.
  if (!PMP::does_bound_a_volume(check))
    throw InputError(what +
                     ": the mesh bounds no volume: its shells are nested but not oriented "
                     "alternately (a shell inside another is a cavity and must face inward)");
  return mesh;
}

// The enclosed volume, summed in doubles from the exactly placed vertices:
// an exact sum of thousands of rational tetrahedra (PMP::volume on this
// kernel) spends seconds on gcds for digits a double result drops anyway.
// About the centre of the mesh's bounding box: about the origin, the terms
// of a body far from it cancel (geom::enclosed_volume does the same).
double volume(const Mesh& mesh) {
  Eigen::Vector3d low = Eigen::Vector3d::Constant(HUGE_VAL), high = -low;
  for (const auto v : mesh.vertices()) {
    const Kernel::Point_3& point = mesh.point(v);
    const Eigen::Vector3d x(CGAL::to_double(point.x()), CGAL::to_double(point.y()),
                            CGAL::to_double(point.z()));
    low = low.cwiseMin(x);
    high = high.cwiseMax(x);
  }
  const Eigen::Vector3d centre = 0.5 * (low + high);
  double sum = 0.0;
  for (const auto f : mesh.faces()) {
    Eigen::Vector3d corner[3];
    int k = 0;
    for (const auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
      const Kernel::Point_3& point = mesh.point(v);
      corner[k++] = Eigen::Vector3d(CGAL::to_double(point.x()), CGAL::to_double(point.y()),
                                    CGAL::to_double(point.z())) -
                    centre;
    }
    sum += corner[0].dot(corner[1].cross(corner[2]));
  }
  return sum / 6.0;
}

double symmetric_difference_3d(const geom::Surface& a, const geom::Surface& b,
                               const std::string& what_a, const std::string& what_b) {
  Mesh p = solid(a, what_a), q = solid(b, what_b);
  const double volume_p = volume(p), volume_q = volume(q);
  Mesh common;
  if (!PMP::corefine_and_compute_intersection(p, q, common))
    throw InputError("the intersection of " + what_a + " and " + what_b +
                     " is not a closed solid (CGAL corefinement)");
  return volume_p + volume_q - 2.0 * volume(common);
}

}  // namespace

// The exact Booleans are given only what they and doubles can carry: finite
// coordinates of magnitude at most 1e50 (their constructions multiply up to
// six of them; beyond, CGAL's interval filters overflow), and a body whose
// extent keeps at least six digits of its coordinates.
void require_representable(const geom::Surface& s, const std::string& what) {
  constexpr double kLargest = 1e50, kDigits = 1e-6 / 1.1e-16;
  double largest = 0.0;
  for (Eigen::Index i = 0; i < s.V.rows(); ++i)
    for (Eigen::Index a = 0; a < s.V.cols(); ++a) {
      const double x = s.V(i, a);
      if (!std::isfinite(x) || std::abs(x) > kLargest)
        throw InputError(what + ": vertex " + std::to_string(i) + " has " + "xyz"[a] + " = " +
                         std::to_string(x) +
                         ": expected a finite coordinate of magnitude at most "
                         "1e50 (rescale the meshes, e.g. to m)");
      largest = std::max(largest, std::abs(x));
    }
  const double extent =
      s.V.rows() > 0 ? (s.V.colwise().maxCoeff() - s.V.colwise().minCoeff()).maxCoeff() : 0.0;
  if (!(extent > 0.0) || largest / extent > kDigits)
    throw InputError(what + ": the body (extent " + std::to_string(extent) +
                     ") is too small for "
                     "its distance from the origin (" +
                     std::to_string(largest) +
                     ") to keep six "
                     "digits in doubles: move it nearer the origin");
}

double symmetric_difference_measure(const geom::Surface& a, const geom::Surface& b,
                                    const std::string& what_a, const std::string& what_b) {
  if (a.dim != b.dim)
    throw InputError(what_a + " is " + std::to_string(a.dim) + "D and " + what_b + " " +
                     std::to_string(b.dim) + "D");
  return a.dim == 2 ? symmetric_difference_2d(a, b, what_a, what_b)
                    : symmetric_difference_3d(a, b, what_a, what_b);
}

}  // namespace fiberfluid::metrics
