// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fiberfluid/model/model.hpp"

namespace fiberfluid::model {

// A rigid motion of the whole body that nothing holds: the tangent is then
// singular along it (Newton cannot factor it) and the answer is fixed only up
// to it.
struct FreeMotion {
  // The motion as a field: a translation plus a rotation about `point`.
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();  // unit, or zero
  Eigen::Vector3d rotation = Eigen::Vector3d::Zero();     // unit axis, or zero
  Eigen::Vector3d point = Eigen::Vector3d::Zero();        // on the rotation's axis
  // How much the model's loads at full schedule drive it: their work along
  // the motion over (total load x body size), 0 when they do not.
  double driven = 0.0;
  // "translation along x", "rotation about the axis (1, 0, 0) through (0, 0, 0.015)".
  std::string describe() const;
};

// The rigid motions (translations, and rotations in 3D) that the model's
// supports, prescribed groups and mirror layers hold none of, and its paddles
// neither: a paddle holds the translation along its axis and the tilts about
// the two axes across it (frictionless), or everything (sticking), once the
// body presses on it. The motions returned span the free ones, each a unit
// mode, translations first.
std::vector<FreeMotion> free_rigid_motions(const Model& model);

// For a free motion that the loads do not drive: the unknown (vertex, axis)
// that moves most along it and is not held, whose holding at zero fixes the
// motion (a gauge: the answer up to that motion, where it does not depend on
// it). {-1, -1} when none is found.
std::pair<int, int> gauge_unknown(const Model& model, const FreeMotion& motion);

}  // namespace fiberfluid::model
