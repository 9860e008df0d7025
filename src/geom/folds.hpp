// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <optional>
#include <utility>

#include "fiberfluid/geom/surface.hpp"

namespace fiberfluid::geom {

// A fold between two states of a surface: a face whose normal reversed and
// that now faces against the neighbours it faced with (crossing empty), or,
// when the faces that reversed turned with their neighbours, two faces of the
// surface that cross (exact predicates, find_self_intersection).
struct Fold {
  int face = -1;  // a face whose normal reversed
  std::optional<std::pair<int, int>> crossing;
};

// The fold of `now` since the state whose face area vectors were
// `areas_before` (face_area_vectors), or nothing. A face turns over through
// zero area, so it ends against its neighbours; a body rotating far turns
// its faces past a right angle with their neighbours, and is not a fold.
// Only faces whose normal reversed are looked at: the check costs one pass
// over the faces unless some did.
std::optional<Fold> find_fold(const Surface& now, const Eigen::MatrixXd& areas_before);

}  // namespace fiberfluid::geom
