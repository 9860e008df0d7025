// SPDX-License-Identifier: GPL-3.0-or-later
// The float pre-filter of the convexity check (is_convex): every vertex
// against every face's plane, in doubles with certified signs, skipping whole
// clusters of vertices that a box bound puts behind a face. What it cannot
// certify it lists for CGAL's exact predicates.
#pragma once

#include <optional>
#include <utility>
#include <vector>

#include "fiberfluid/geom/surface.hpp"

namespace fiberfluid::geom {

struct ConvexityScreen {
  bool vertex_in_front = false;             // certified: the body is not convex
  std::vector<std::pair<int, int>> unsure;  // (face, vertex) to test exactly
};

// A 3D surface with outward faces; nothing when its coordinates are outside
// the range the certified signs hold in (certified_sign.hpp).
std::optional<ConvexityScreen> screen_convexity(const Surface& surface);

}  // namespace fiberfluid::geom
