// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// Fibers within a horizon: as in bond-based peridynamics (Silling 2000;
// the horizon delta of its bonds), only vertices at most delta apart in the
// reference are joined by a bulk fiber. With central fibers a horizon of
// about the body's thickness makes a slender body bend as a beam does
// (model.md, the fiber kinematics).

#include "fiberfluid/geom/fiber_mask.hpp"
#include "fiberfluid/geom/surface.hpp"

namespace fiberfluid::geom {

// How a horizon's mask is stored (FiberMask): Auto lists the neighbours when
// the horizon keeps at most kSparseShare of the pairs (the tiled dense loops
// are faster per pair, the lists visit only the pairs kept), else the table.
enum class MaskStorage { Auto, Dense, Sparse };
inline constexpr double kSparseShare = 0.125;

// The pairs at most `horizon` apart. They are found on a uniform grid of
// cells of the horizon's size, each vertex testing the 3^dim cells around
// its own, so the pair tests and (stored sparse) the memory grow with N times
// the neighbours, not N^2. Throws std::invalid_argument for a horizon that is
// not a positive number.
FiberMask horizon_fibers(const Surface& surface, double horizon,
                         MaskStorage storage = MaskStorage::Auto);

// The longest mesh edge: a horizon at least this long joins every vertex to
// its neighbours on the surface (the least horizon fibers.horizon accepts).
double longest_edge(const Surface& surface);

}  // namespace fiberfluid::geom
