// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <cstdint>
#include <vector>

#include "geom/surface.hpp"

namespace fiberfluid::geom {

// Which pairs of vertices are joined by a bulk fiber: a symmetric N x N
// table of bytes (row-major, so a vertex's fibers are contiguous for the
// solvers' pair loops).
class FiberMask {
 public:
  explicit FiberMask(int num_vertices);  // every pair kept
  bool kept(int i, int j) const { return kept_[index(i, j)] != 0; }
  void prune(int i, int j);
  const uint8_t* row(int i) const { return kept_.data() + index(i, 0); }
  int num_vertices() const { return n_; }
  long long num_pairs() const { return static_cast<long long>(n_) * (n_ - 1) / 2; }
  long long num_kept() const;
  std::vector<int> kept_per_vertex() const;  // n_i

 private:
  size_t index(int i, int j) const { return static_cast<size_t>(i) * n_ + j; }
  int n_;
  std::vector<uint8_t> kept_;  // diagonal 0
};

struct PruningResult {
  FiberMask mask;
  bool convex = false;  // the fast path: nothing to prune
  double seconds = 0.0;
  long long exact_fallbacks = 0;     // pairs decided by exact constructions
  long long decided_in_doubles = 0;  // pairs the float pre-filter certified (3D)
};

// True when no vertex lies strictly outside the plane of any face (exact
// orientation predicates): every fiber of a convex body stays inside.
bool is_convex(const Surface& surface);

// Keeps a fiber iff its segment lies in the closed solid (inside, or on the
// surface: fibers along a flat face or an edge are kept). In 3D a float
// pre-filter with certified signs decides most pairs (segment_filter.hpp);
// the rest are decided with CGAL's exact predicates and an AABB tree over the
// faces; where a segment
// touches the surface other than by crossing a face's interior (through a
// vertex, along an edge, in a face's plane), exact constructions split it
// into pieces and each piece is classified. 3D triangle meshes and 2D
// polygons.
// With convex_fast_path (the default), a convex body skips the pair tests.
PruningResult prune_fibers(const Surface& surface, bool convex_fast_path = true);

}  // namespace fiberfluid::geom
