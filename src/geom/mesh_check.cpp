// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/geom/mesh_check.hpp"

#include "fiberfluid/geom/self_intersection.hpp"
#include "fiberfluid/util/run_control.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <sstream>
#include <utility>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::geom {
namespace {

// A vertex, face or edge as the report names it: counted from the file's own base.
std::string id(const MeshReport& r, int index) { return std::to_string(index + r.index_base); }

std::string edge_name(const MeshReport& r, int a, int b) {
  return "(" + id(r, a) + ", " + id(r, b) + ")";
}

int find_root(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

int count_components(const Surface& s, const std::vector<char>& used) {
  std::vector<int> parent(s.num_vertices());
  std::iota(parent.begin(), parent.end(), 0);
  for (int f = 0; f < s.num_faces(); ++f)
    for (int k = 1; k < s.F.cols(); ++k)
      parent[find_root(parent, s.F(f, k))] = find_root(parent, s.F(f, 0));
  int components = 0;
  for (int i = 0; i < s.num_vertices(); ++i)
    if (used[i] && find_root(parent, i) == i) ++components;
  return components;
}

// Faces around a vertex of a closed manifold triangle mesh must form a single
// fan; two fans joined at the vertex (a "bowtie") are not a 2-manifold.
int first_pinched_vertex(const Surface& s) {
  // For each vertex, the link edges (opposite edges of its faces), then count
  // cycles by walking them.
  std::vector<std::vector<std::pair<int, int>>> link(s.num_vertices());
  for (int f = 0; f < s.num_faces(); ++f)
    for (int k = 0; k < 3; ++k)
      link[s.F(f, k)].emplace_back(s.F(f, (k + 1) % 3), s.F(f, (k + 2) % 3));
  for (int v = 0; v < s.num_vertices(); ++v) {
    if (link[v].empty()) continue;
    std::map<int, int> next;
    for (auto [a, b] : link[v]) next[a] = b;
    int start = link[v].front().first, walked = 0, at = start;
    do {
      auto it = next.find(at);
      if (it == next.end()) break;
      at = it->second;
      ++walked;
    } while (at != start && walked <= static_cast<int>(link[v].size()));
    if (walked != static_cast<int>(link[v].size())) return v;
  }
  return -1;
}

void check_coordinates_and_indices(const Surface& s, MeshReport& r) {
  for (int i = 0; i < s.num_vertices(); ++i) {
    if (!s.V.row(i).allFinite()) {
      r.problems.push_back("vertex " + id(r, i) + " has a non-finite coordinate (NaN or infinity)");
      return;
    }
  }
  for (int f = 0; f < s.num_faces(); ++f)
    for (int k = 0; k < s.F.cols(); ++k)
      if (s.F(f, k) < 0 || s.F(f, k) >= s.num_vertices()) {
        r.problems.push_back("face " + id(r, f) + " refers to vertex " + id(r, s.F(f, k)) +
                             ", outside " + id(r, 0) + ".." + id(r, s.num_vertices() - 1));
        return;
      }
}

void check_degenerate_faces(const Surface& s, MeshReport& r) {
  const double diagonal = bounding_box_diagonal(s.V);
  // Relative to the size of the object: a face whose area is below 1e-12 of
  // the bounding box diagonal squared carries no usable normal.
  const double tiny = 1e-12 * std::pow(diagonal, s.dim - 1);
  const Eigen::MatrixXd A = face_area_vectors(s.V, s.F);
  for (int f = 0; f < s.num_faces(); ++f) {
    bool repeated = false;
    for (int k = 0; k < s.F.cols(); ++k)
      for (int m = k + 1; m < s.F.cols(); ++m) repeated |= s.F(f, k) == s.F(f, m);
    if (repeated || A.row(f).norm() <= tiny) {
      r.problems.push_back("face " + id(r, f) + " is degenerate (" +
                           (repeated ? "a repeated vertex" : "zero area") + ")");
      return;
    }
  }
}

// 3D: every undirected edge must have two faces that traverse it in
// opposite directions.
void check_triangle_topology(const Surface& s, MeshReport& r) {
  std::map<std::pair<int, int>, std::pair<int, int>> uses;  // edge -> (forward, backward)
  for (int f = 0; f < s.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      int a = s.F(f, k), b = s.F(f, (k + 1) % 3);
      auto& count = uses[{std::min(a, b), std::max(a, b)}];
      (a < b ? count.first : count.second) += 1;
    }
  r.edges = static_cast<int>(uses.size());
  int boundary = 0, nonmanifold = 0, misoriented = 0;
  std::string first_boundary, first_nonmanifold, first_misoriented;
  for (const auto& [edge, count] : uses) {
    const int faces = count.first + count.second;
    if (faces == 1 && boundary++ == 0) first_boundary = edge_name(r, edge.first, edge.second);
    if (faces > 2 && nonmanifold++ == 0)
      first_nonmanifold = edge_name(r, edge.first, edge.second) + " is shared by " +
                          std::to_string(faces) + " faces";
    if (faces == 2 && count.first != 1 && misoriented++ == 0)
      first_misoriented = edge_name(r, edge.first, edge.second);
  }
  r.closed = boundary == 0 && nonmanifold == 0;
  r.manifold = nonmanifold == 0;
  r.consistently_oriented = misoriented == 0;
  if (nonmanifold > 0) {
    r.problems.push_back("not a 2-manifold: edge " + first_nonmanifold + " (" +
                         std::to_string(nonmanifold) + " such edges)");
    return;
  }
  if (boundary > 0) {
    r.problems.push_back("not closed: edge " + first_boundary + " borders only one face (" +
                         std::to_string(boundary) + " boundary edges)");
    return;
  }
  if (misoriented > 0) {
    r.problems.push_back("inconsistent orientation: the two faces at edge " + first_misoriented +
                         " traverse it in the same direction (" + std::to_string(misoriented) +
                         " such edges)");
    return;
  }
  const int pinched = first_pinched_vertex(s);
  if (pinched >= 0) {
    r.manifold = false;
    r.problems.push_back("not a 2-manifold: the faces around vertex " + id(r, pinched) +
                         " form more than one fan");
  }
}

// 2D: every used vertex starts exactly one edge and ends exactly one.
void check_polygon_topology(const Surface& s, MeshReport& r) {
  std::vector<int> starts(s.num_vertices(), 0), ends(s.num_vertices(), 0);
  for (int f = 0; f < s.num_faces(); ++f) {
    ++starts[s.F(f, 0)];
    ++ends[s.F(f, 1)];
  }
  r.edges = s.num_faces();
  r.closed = r.manifold = r.consistently_oriented = true;
  for (int i = 0; i < s.num_vertices(); ++i) {
    const int degree = starts[i] + ends[i];
    if (degree == 0) continue;
    if (degree > 2) {
      r.manifold = r.closed = false;
      r.problems.push_back("not a simple closed polygon: vertex " + id(r, i) + " has " +
                           std::to_string(degree) + " edges");
      return;
    }
    if (degree == 1) {
      r.closed = false;
      r.problems.push_back("not closed: vertex " + id(r, i) + " ends an open polyline");
      return;
    }
    if (starts[i] != 1) {
      r.consistently_oriented = false;
      r.problems.push_back("inconsistent orientation: the two edges at vertex " + id(r, i) +
                           " both " + (starts[i] == 2 ? "start" : "end") + " there");
      return;
    }
  }
}

}  // namespace

MeshReport inspect(const Surface& s, int index_base) {
  MeshReport r;
  r.index_base = index_base;
  r.dim = s.dim;
  r.vertices = s.num_vertices();
  r.faces = s.num_faces();
  if (s.dim != 2 && s.dim != 3) {
    r.problems.push_back("dimension must be 2 or 3, got " + std::to_string(s.dim));
    return r;
  }
  if (r.faces == 0) {
    r.problems.push_back("the surface has no faces");
    return r;
  }
  check_coordinates_and_indices(s, r);
  if (!r.ok()) return r;

  std::vector<char> used(s.num_vertices(), 0);
  for (int f = 0; f < s.num_faces(); ++f)
    for (int k = 0; k < s.F.cols(); ++k) used[s.F(f, k)] = 1;
  r.used_vertices = static_cast<int>(std::count(used.begin(), used.end(), 1));
  if (r.used_vertices < r.vertices)
    r.warnings.push_back(std::to_string(r.vertices - r.used_vertices) +
                         " vertices are referenced by no face; they are kept in place and left "
                         "out of the model");
  r.components = count_components(s, used);
  // A large surface takes seconds to check: an interrupt stops it between parts.
  throw_if_cancelled("the surface's checks");

  check_degenerate_faces(s, r);
  if (!r.ok()) return r;
  if (s.dim == 3)
    check_triangle_topology(s, r);
  else
    check_polygon_topology(s, r);

  r.area = surface_area(s.V, s.F);
  r.volume = enclosed_volume(s.V, s.F);
  r.euler_characteristic = s.dim == 3 ? r.used_vertices - r.edges + r.faces : 0;
  if (s.dim == 3 && r.closed && r.components == 1) r.genus = (2 - r.euler_characteristic) / 2;
  r.outward = r.volume > 0.0;
  throw_if_cancelled("the surface's checks");
  // A surface that crosses itself bounds no solid: its enclosed volume (the
  // fluid's) and the exact pruning's inside test mean nothing there.
  if (r.ok())
    if (const auto crossing = find_self_intersection(s))
      r.problems.push_back(
          "the surface intersects itself: " + std::string(s.dim == 3 ? "triangles " : "segments ") +
          id(r, crossing->first) + " and " + id(r, crossing->second) +
          " cross (it bounds no solid, so its volume and the fiber pruning are meaningless)");
  if (r.ok() && !r.outward)
    r.problems.push_back(std::string("inverted: the faces point inward (enclosed ") +
                         (s.dim == 3 ? "volume " : "area ") + std::to_string(r.volume) +
                         " < 0); fix the file or set \"flip\": true in the experiment");
  return r;
}

std::string format_report(const MeshReport& r, const std::string& source) {
  std::ostringstream out;
  out << source << "\n"
      << "  dimension:     " << r.dim << "\n"
      << "  vertices:      " << r.vertices << " (" << r.used_vertices << " used)\n"
      << "  faces:         " << r.faces << "\n"
      << "  edges:         " << r.edges << "\n"
      << "  components:    " << r.components << "\n"
      << "  closed:        " << (r.closed ? "yes" : "no") << "\n"
      << "  manifold:      " << (r.manifold ? "yes" : "no") << "\n"
      << "  orientation:   "
      << (!r.consistently_oriented ? "inconsistent"
          : r.outward              ? "consistent, outward"
                                   : "consistent, inward")
      << "\n";
  if (r.dim == 3) out << "  genus:         " << r.genus << "\n";
  out << "  " << (r.dim == 3 ? "area:          " : "perimeter:     ") << r.area << "\n"
      << "  " << (r.dim == 3 ? "volume:        " : "area:          ") << r.volume << "\n";
  for (const auto& w : r.warnings) out << "  warning: " << w << "\n";
  for (const auto& p : r.problems) out << "  error: " << p << "\n";
  if (!r.problems.empty())
    out << "  (vertices and faces counted from " << r.index_base
        << (r.index_base == 1 ? ", as the file counts them)\n" : ")\n");
  return out.str();
}

void require_usable(const MeshReport& report, const std::string& source) {
  if (!report.ok()) throw InputError(source + ": " + report.problems.front());
}

}  // namespace fiberfluid::geom
