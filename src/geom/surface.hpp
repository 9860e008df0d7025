// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <vector>

namespace fiberfluid::geom {

// A closed surface. In 3D a triangle mesh; in 2D a closed polygon whose
// "faces" are its edges (the paper's worked example is 2D).
struct Surface {
  int dim = 3;        // 2 or 3
  Eigen::MatrixXd V;  // #V by dim vertex positions
  Eigen::MatrixXi F;  // #F by dim vertex indices: triangles (3D) or segments (2D)

  int num_vertices() const { return static_cast<int>(V.rows()); }
  int num_faces() const { return static_cast<int>(F.rows()); }
};

// A surface without the vertices no face references, and the maps between
// its vertex indices and those of the input (output meshes keep the input's
// vertex order and count, so results are mapped back through to_input).
struct CompactSurface {
  Surface surface;
  std::vector<int> to_input;    // compact index -> input index
  std::vector<int> from_input;  // input index -> compact index, or -1 if unused
};

CompactSurface remove_unused_vertices(const Surface& surface);

// Unique undirected edges, #E by 2 with the smaller index first, sorted.
Eigen::MatrixXi unique_edges(const Surface& surface);

// Reverses the orientation of every face (inward <-> outward).
void flip_orientation(Surface& surface);

// Length of the diagonal of the axis-aligned bounding box of V.
double bounding_box_diagonal(const Eigen::MatrixXd& V);

}  // namespace fiberfluid::geom
