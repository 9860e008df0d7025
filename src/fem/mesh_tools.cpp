// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fem/mesh_tools.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include "fiberfluid/fem/tetrahedra.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::fem {
namespace {

double simplex_orientation(const Eigen::MatrixXd& nodes, const std::vector<int>& s) {
  const int dim = static_cast<int>(nodes.cols());
  Eigen::MatrixXd edges(dim, dim);
  for (int k = 0; k < dim; ++k)
    edges.col(k) = (nodes.row(s[static_cast<size_t>(k + 1)]) - nodes.row(s[0])).transpose();
  return edges.determinant();
}

// The outward faces of one element, as local corner indices. A face of a
// quadrilateral is an edge; of a hexahedron, a quadrilateral; of a
// tetrahedron (corners 0..3 positively oriented), a triangle.
const std::vector<std::vector<int>>& element_faces(int dim, int corners) {
  static const std::vector<std::vector<int>> quad = {{0, 1}, {1, 2}, {2, 3}, {3, 0}};
  static const std::vector<std::vector<int>> triangle = {{0, 1}, {1, 2}, {2, 0}};
  static const std::vector<std::vector<int>> hex = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                                    {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  static const std::vector<std::vector<int>> tet = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  // A quadratic tetrahedron's faces: the corners as above, then the middle
  // nodes of the edges (c0 c1), (c1 c2), (c2 c0).
  static const std::vector<std::vector<int>> quadratic_tet = {
      {1, 2, 3, 5, 9, 8}, {0, 3, 2, 7, 9, 6}, {0, 1, 3, 4, 8, 7}, {0, 2, 1, 6, 5, 4}};
  if (dim == 2) return corners == 4 ? quad : triangle;
  if (corners == 10) return quadratic_tet;
  return corners == 8 ? hex : tet;
}

// The flat pieces of a boundary face: a quadrilateral's two triangles, a
// 6-node triangle's four (corners c0 c1 c2, middles m01 m12 m20).
void split_face(const std::vector<int>& face, std::vector<std::vector<int>>* kept) {
  if (face.size() == 4) {
    kept->push_back({face[0], face[1], face[2]});
    kept->push_back({face[0], face[2], face[3]});
  } else if (face.size() == 6) {
    kept->push_back({face[0], face[3], face[5]});
    kept->push_back({face[3], face[1], face[4]});
    kept->push_back({face[5], face[4], face[2]});
    kept->push_back({face[3], face[4], face[5]});
  } else {
    kept->push_back(face);
  }
}

// Middle nodes (numbered from `corners`) at the mean distance of their
// edge's ends from the origin (a sphere's centre) or from the z axis (a
// cylinder's), on the ray through the chord's middle.
void curve_middle_nodes(Mesh& mesh, int corners, bool about_axis) {
  const auto reach = [&](int v) -> double {
    return about_axis ? mesh.nodes.row(v).head<2>().norm() : mesh.nodes.row(v).norm();
  };
  for (Eigen::Index e = 0; e < mesh.elements.rows(); ++e)
    for (size_t edge = 0; edge < kTetrahedronEdges.size(); ++edge) {
      const int a = mesh.elements(e, kTetrahedronEdges[edge][0]),
                b = mesh.elements(e, kTetrahedronEdges[edge][1]),
                middle = mesh.elements(e, 4 + static_cast<Eigen::Index>(edge));
      if (middle < corners) continue;
      const double radius = 0.5 * (reach(a) + reach(b));
      if (about_axis) {
        const Eigen::Vector2d chord = mesh.nodes.row(middle).head<2>();
        mesh.nodes.row(middle).head<2>() = radius * chord.normalized();
      } else {
        const Eigen::RowVector3d chord = mesh.nodes.row(middle);
        mesh.nodes.row(middle) = radius * chord.normalized();
      }
    }
}

}  // namespace

Mesh to_simplices(const Mesh& mesh) {
  const int per = static_cast<int>(mesh.elements.cols());
  if (per == mesh.dim + 1) return mesh;
  // Corner bit patterns (x, y, z) of the node order of Mesh.
  static const int corner_of_bits[8] = {0, 1, 3, 2, 4, 5, 7, 6};
  std::vector<std::vector<int>> pieces;
  if (mesh.dim == 2) {
    pieces = {{0, 1, 2}, {0, 2, 3}};
  } else {
    std::array<int, 3> axes = {0, 1, 2};
    do {  // 0 -> e_a -> e_a + e_b -> 6 for each order of the axes
      const int a = 1 << axes[0], ab = a | (1 << axes[1]);
      pieces.push_back({0, corner_of_bits[a], corner_of_bits[ab], 6});
    } while (std::next_permutation(axes.begin(), axes.end()));
  }
  Mesh out;
  out.dim = mesh.dim;
  out.nodes = mesh.nodes;
  out.elements.resize(mesh.elements.rows() * static_cast<Eigen::Index>(pieces.size()),
                      mesh.dim + 1);
  Eigen::Index e = 0;
  for (Eigen::Index cell = 0; cell < mesh.elements.rows(); ++cell)
    for (const std::vector<int>& piece : pieces) {
      std::vector<int> s;
      for (int corner : piece) s.push_back(mesh.elements(cell, corner));
      if (simplex_orientation(mesh.nodes, s) < 0.0) std::swap(s[1], s[2]);
      for (int k = 0; k <= mesh.dim; ++k) out.elements(e, k) = s[static_cast<size_t>(k)];
      ++e;
    }
  return out;
}

Boundary boundary(const Mesh& mesh) { return boundary(mesh, mesh.nodes); }

Boundary boundary(const Mesh& mesh, const Eigen::MatrixXd& positions) {
  if (positions.rows() != mesh.nodes.rows() || positions.cols() != mesh.dim)
    throw InputError("fem: boundary positions need one row per node");
  // A face on the boundary belongs to one element only.
  std::map<std::vector<int>, std::vector<int>> faces;  // sorted corners -> oriented corners
  std::map<std::vector<int>, int> count;
  const int per = static_cast<int>(mesh.elements.cols());
  for (Eigen::Index e = 0; e < mesh.elements.rows(); ++e)
    for (const std::vector<int>& local : element_faces(mesh.dim, per)) {
      std::vector<int> face;
      for (int c : local) face.push_back(mesh.elements(e, c));
      std::vector<int> key(face.begin(), face.begin() + (face.size() == 6 ? 3 : face.size()));
      std::sort(key.begin(), key.end());  // by its corners
      if (++count[key] == 1) faces[key] = face;
    }
  std::vector<std::vector<int>> kept;  // as mesh nodes; quadrilaterals split into triangles
  for (const auto& [key, face] : faces) {
    if (count[key] == 1) split_face(face, &kept);
  }
  if (kept.empty()) throw InputError("fem: the mesh has no boundary (no elements)");
  Boundary b;
  std::map<int, int> vertex_of;
  if (mesh.dim == 2) {  // chain the segments: each node starts exactly one
    std::map<int, int> next;
    for (const std::vector<int>& s : kept) next[s[0]] = s[1];
    int node = next.begin()->first;
    do {
      vertex_of[node] = static_cast<int>(b.nodes.size());
      b.nodes.push_back(node);
      node = next.at(node);
    } while (node != b.nodes.front() && b.nodes.size() <= kept.size());
  } else {
    for (const std::vector<int>& f : kept)
      for (int node : f)
        if (vertex_of.emplace(node, static_cast<int>(b.nodes.size())).second)
          b.nodes.push_back(node);
  }
  if (mesh.dim == 2 && b.nodes.size() != kept.size())
    throw InputError("fem: the mesh's boundary is not one closed polygon");
  b.surface.dim = mesh.dim;
  b.surface.V.resize(static_cast<Eigen::Index>(b.nodes.size()), mesh.dim);
  for (size_t v = 0; v < b.nodes.size(); ++v)
    b.surface.V.row(static_cast<Eigen::Index>(v)) = positions.row(b.nodes[v]);
  b.surface.F.resize(static_cast<Eigen::Index>(kept.size()), mesh.dim);
  if (mesh.dim == 2) {
    const int n = static_cast<int>(b.nodes.size());
    for (int v = 0; v < n; ++v) b.surface.F.row(v) << v, (v + 1) % n;
  } else {
    for (size_t f = 0; f < kept.size(); ++f)
      for (int k = 0; k < 3; ++k)
        b.surface.F(static_cast<Eigen::Index>(f), k) =
            vertex_of.at(kept[f][static_cast<size_t>(k)]);
  }
  return b;
}

Mesh to_quadratic(const Mesh& linear) {
  if (linear.dim != 3 || linear.elements.cols() != 4)
    throw InputError("fem: only linear tetrahedra (dim 3, 4 nodes) are made quadratic");
  Mesh out;
  out.dim = 3;
  std::map<std::pair<int, int>, int> middle;  // sorted corners -> node
  std::vector<Eigen::RowVector3d> added;
  out.elements.resize(linear.elements.rows(), 10);
  for (Eigen::Index e = 0; e < linear.elements.rows(); ++e) {
    for (int k = 0; k < 4; ++k) out.elements(e, k) = linear.elements(e, k);
    for (size_t edge = 0; edge < kTetrahedronEdges.size(); ++edge) {
      const int a = linear.elements(e, kTetrahedronEdges[edge][0]),
                b = linear.elements(e, kTetrahedronEdges[edge][1]);
      const auto [it, is_new] = middle.emplace(
          std::minmax(a, b), linear.num_nodes() + static_cast<int>(added.size()));
      if (is_new) added.push_back(0.5 * (linear.nodes.row(a) + linear.nodes.row(b)));
      out.elements(e, 4 + static_cast<Eigen::Index>(edge)) = it->second;
    }
  }
  out.nodes.resize(linear.num_nodes() + static_cast<Eigen::Index>(added.size()), 3);
  out.nodes.topRows(linear.num_nodes()) = linear.nodes;
  for (size_t k = 0; k < added.size(); ++k)
    out.nodes.row(linear.num_nodes() + static_cast<Eigen::Index>(k)) = added[k];
  return out;
}

Mesh tube_mesh(const TubeMeshSpec& spec) {
  if (!(spec.inner_radius > 0.0 && spec.outer_radius > spec.inner_radius && spec.length > 0.0) ||
      spec.radial < 1 || spec.around < 3 || spec.along < 1 || (spec.order != 1 && spec.order != 2))
    throw InputError("fem: a tube needs 0 < inner < outer radius, a positive length, at least "
                     "1 x 3 x 1 cells and order 1 or 2");
  const int nr = spec.radial, nt = spec.around, nz = spec.along;
  const auto id = [&](int i, int j, int k) { return i + (nr + 1) * ((j % nt) + nt * k); };
  Mesh hexahedra;
  hexahedra.dim = 3;
  hexahedra.nodes.resize((nr + 1) * nt * (nz + 1), 3);
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j < nt; ++j)
      for (int i = 0; i <= nr; ++i) {
        const double r = spec.inner_radius + (spec.outer_radius - spec.inner_radius) * i / nr;
        const double theta = 2.0 * M_PI * j / nt;
        hexahedra.nodes.row(id(i, j, k)) << r * std::cos(theta), r * std::sin(theta),
            spec.length * k / nz;
      }
  hexahedra.elements.resize(nr * nt * nz, 8);
  int e = 0;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < nt; ++j)  // the last ring of cells closes on the first (j % nt)
      for (int i = 0; i < nr; ++i, ++e)
        for (int layer = 0; layer < 2; ++layer) {
          const int bottom[4] = {id(i, j, k + layer), id(i + 1, j, k + layer),
                                 id(i + 1, j + 1, k + layer), id(i, j + 1, k + layer)};
          for (int a = 0; a < 4; ++a) hexahedra.elements(e, 4 * layer + a) = bottom[a];
        }
  Mesh mesh = to_simplices(hexahedra);
  if (spec.order == 1) return mesh;
  const int corners = mesh.num_nodes();
  mesh = to_quadratic(mesh);
  curve_middle_nodes(mesh, corners, true);
  return mesh;
}

Mesh shell_octant_mesh(const ShellMeshSpec& spec) {
  if (!(spec.inner_radius > 0.0 && spec.outer_radius > spec.inner_radius) || spec.around < 1 ||
      spec.radial < 1 || (spec.order != 1 && spec.order != 2))
    throw InputError("fem: a shell needs 0 < inner < outer radius, at least 1 x 1 cells and "
                     "order 1 or 2");
  const int n = spec.around, layers = spec.radial;
  // The octant's sphere triangle: points (i, j) with i + j <= n.
  std::vector<Eigen::RowVector3d> directions;
  std::map<std::pair<int, int>, int> point;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i + j <= n; ++i) {
      point[{i, j}] = static_cast<int>(directions.size());
      directions.push_back(Eigen::RowVector3d(i, j, n - i - j).normalized());
    }
  std::vector<std::array<int, 3>> triangles;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i + j < n; ++i) {
      triangles.push_back({point[{i, j}], point[{i + 1, j}], point[{i, j + 1}]});
      if (i + j + 1 < n) triangles.push_back({point[{i + 1, j}], point[{i + 1, j + 1}], point[{i, j + 1}]});
    }
  const int per_layer = static_cast<int>(directions.size());
  Mesh mesh;
  mesh.dim = 3;
  mesh.nodes.resize(per_layer * (layers + 1), 3);
  for (int k = 0; k <= layers; ++k) {
    const double r = spec.inner_radius + (spec.outer_radius - spec.inner_radius) * k / layers;
    for (int v = 0; v < per_layer; ++v) mesh.nodes.row(k * per_layer + v) = r * directions[v];
  }
  std::vector<std::array<int, 4>> tets;
  for (int k = 0; k < layers; ++k)
    for (const auto& t : triangles) {
      std::array<int, 6> prism = {t[0] + k * per_layer,       t[1] + k * per_layer,
                                  t[2] + k * per_layer,       t[0] + (k + 1) * per_layer,
                                  t[1] + (k + 1) * per_layer, t[2] + (k + 1) * per_layer};
      // Renumber the prism so that its smallest node is V0 (a rotation of the
      // triangles, and a swap of bottom and top), then split by the smaller
      // of the two diagonals through V0's opposite quadrilateral.
      const int smallest = static_cast<int>(std::min_element(prism.begin(), prism.end()) - prism.begin());
      static const int rotations[6][6] = {{0, 1, 2, 3, 4, 5}, {1, 2, 0, 4, 5, 3},
                                          {2, 0, 1, 5, 3, 4}, {3, 5, 4, 0, 2, 1},
                                          {4, 3, 5, 1, 0, 2}, {5, 4, 3, 2, 1, 0}};
      std::array<int, 6> V;
      for (int a = 0; a < 6; ++a) V[a] = prism[rotations[smallest][a]];
      if (std::min(V[1], V[5]) < std::min(V[2], V[4]))
        for (const auto& tet : {std::array<int, 4>{V[0], V[1], V[2], V[5]},
                                std::array<int, 4>{V[0], V[1], V[5], V[4]},
                                std::array<int, 4>{V[0], V[4], V[5], V[3]}})
          tets.push_back(tet);
      else
        for (const auto& tet : {std::array<int, 4>{V[0], V[1], V[2], V[4]},
                                std::array<int, 4>{V[0], V[4], V[2], V[5]},
                                std::array<int, 4>{V[0], V[4], V[5], V[3]}})
          tets.push_back(tet);
    }
  mesh.elements.resize(static_cast<Eigen::Index>(tets.size()), 4);
  for (size_t e = 0; e < tets.size(); ++e) {
    std::vector<int> s(tets[e].begin(), tets[e].end());
    if (simplex_orientation(mesh.nodes, s) < 0.0) std::swap(s[1], s[2]);
    for (int k = 0; k < 4; ++k) mesh.elements(static_cast<Eigen::Index>(e), k) = s[static_cast<size_t>(k)];
  }
  if (spec.order == 1) return mesh;
  const int corners = mesh.num_nodes();
  mesh = to_quadratic(mesh);
  curve_middle_nodes(mesh, corners, false);
  return mesh;
}

Eigen::VectorXd node_measures(const Mesh& mesh) {
  if (mesh.dim == 3 && mesh.elements.cols() == 10)
    throw InputError("fem: node measures are for linear elements (a quadratic tetrahedron's "
                     "corners have negative shares)");
  Material unit;
  unit.density = 1.0;
  const Eigen::VectorXd lumped = lumped_mass(mesh, unit);
  Eigen::VectorXd out(mesh.num_nodes());
  for (int v = 0; v < mesh.num_nodes(); ++v) out[v] = lumped[mesh.dim * v];
  return out;
}

Eigen::MatrixXd displacement_rows(const Eigen::VectorXd& u, int dim) {
  Eigen::MatrixXd rows(u.size() / dim, dim);
  for (Eigen::Index v = 0; v < rows.rows(); ++v) rows.row(v) = u.segment(dim * v, dim).transpose();
  return rows;
}

}  // namespace fiberfluid::fem
