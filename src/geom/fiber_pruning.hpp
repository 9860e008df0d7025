// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include "fiberfluid/geom/fiber_mask.hpp"
#include "fiberfluid/geom/surface.hpp"

namespace fiberfluid::geom {

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
// With `candidates` (a horizon's fibers), only its kept pairs are tested and
// the mask returned is those of them that stay inside, in the candidates'
// storage: the work grows with the horizon's pairs, not N^2.
PruningResult prune_fibers(const Surface& surface, bool convex_fast_path = true,
                           const FiberMask* candidates = nullptr);

}  // namespace fiberfluid::geom
