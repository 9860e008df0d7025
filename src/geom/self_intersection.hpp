// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <optional>
#include <utility>

#include "fiberfluid/geom/surface.hpp"

namespace fiberfluid::geom {

// Two faces of a closed, manifold surface that cross each other (3D:
// triangles that intersect beyond a shared vertex or edge; 2D: segments that
// cross), or nothing when the surface is simple. Exact predicates (CGAL).
std::optional<std::pair<int, int>> find_self_intersection(const Surface& surface);

}  // namespace fiberfluid::geom
