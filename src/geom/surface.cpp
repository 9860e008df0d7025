// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/geom/surface.hpp"

#include <algorithm>
#include <utility>

namespace fiberfluid::geom {

CompactSurface remove_unused_vertices(const Surface& surface) {
  CompactSurface out;
  const int n = surface.num_vertices();
  std::vector<char> used(n, 0);
  for (int f = 0; f < surface.num_faces(); ++f)
    for (int k = 0; k < surface.F.cols(); ++k) used[surface.F(f, k)] = 1;

  out.from_input.assign(n, -1);
  for (int i = 0; i < n; ++i) {
    if (!used[i]) continue;
    out.from_input[i] = static_cast<int>(out.to_input.size());
    out.to_input.push_back(i);
  }
  out.surface.dim = surface.dim;
  out.surface.V.resize(static_cast<Eigen::Index>(out.to_input.size()), surface.dim);
  for (size_t c = 0; c < out.to_input.size(); ++c)
    out.surface.V.row(static_cast<Eigen::Index>(c)) = surface.V.row(out.to_input[c]);
  out.surface.F = surface.F;
  for (int f = 0; f < surface.num_faces(); ++f)
    for (int k = 0; k < surface.F.cols(); ++k)
      out.surface.F(f, k) = out.from_input[surface.F(f, k)];
  return out;
}

Eigen::MatrixXi unique_edges(const Surface& surface) {
  std::vector<std::pair<int, int>> edges;
  const int corners = static_cast<int>(surface.F.cols());
  // A segment (2D face) is one edge; a triangle has three.
  const int edges_per_face = corners == 2 ? 1 : corners;
  for (int f = 0; f < surface.num_faces(); ++f) {
    for (int k = 0; k < edges_per_face; ++k) {
      int a = surface.F(f, k), b = surface.F(f, (k + 1) % corners);
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  Eigen::MatrixXi E(static_cast<Eigen::Index>(edges.size()), 2);
  for (size_t e = 0; e < edges.size(); ++e) {
    E(static_cast<Eigen::Index>(e), 0) = edges[e].first;
    E(static_cast<Eigen::Index>(e), 1) = edges[e].second;
  }
  return E;
}

void flip_orientation(Surface& surface) {
  for (int f = 0; f < surface.num_faces(); ++f) std::swap(surface.F(f, 0), surface.F(f, 1));
}

double bounding_box_diagonal(const Eigen::MatrixXd& V) {
  if (V.rows() == 0) return 0.0;
  return (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm();
}

}  // namespace fiberfluid::geom
