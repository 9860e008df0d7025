// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fem/mesh_tools.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <map>

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
  if (dim == 2) return corners == 4 ? quad : triangle;
  return corners == 8 ? hex : tet;
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
      std::vector<int> key = face;
      std::sort(key.begin(), key.end());
      if (++count[key] == 1) faces[key] = face;
    }
  std::vector<std::vector<int>> kept;  // as mesh nodes; quadrilaterals split into triangles
  for (const auto& [key, face] : faces) {
    if (count[key] != 1) continue;
    if (face.size() == 4) {
      kept.push_back({face[0], face[1], face[2]});
      kept.push_back({face[0], face[2], face[3]});
    } else {
      kept.push_back(face);
    }
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

Eigen::VectorXd node_measures(const Mesh& mesh) {
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
