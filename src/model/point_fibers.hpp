// SPDX-License-Identifier: GPL-3.0-or-later
// Fibers from a vertex to a point that moves with another vertex: the one
// equilibrium term of the supports' extra fibers. A clamp's mirror layer
// joins i to the image of j through the clamp plane (mirror_layer.hpp), a
// split edge joins i to a ghost that moves with a free vertex
// (held_edge.hpp). Both follow the bulk fibers' kinematics and law
// (pair_stencil.hpp), with their own reference lengths and weights.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "fiberfluid/model/terms.hpp"

namespace fiberfluid::model {

// A fiber from vertex i to the point offset - x_p (mirrored: an image
// through a plane) or x_p + offset (a point carried by p). Its vector is
// b = x_i + sign x_p - offset with sign +1 mirrored and -1 carried, its
// displacement difference u_i + sign u_p.
struct PointFiber {
  int i = 0, p = 0;
  bool mirrored = false;
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  double length = 0.0;  // L, in the reference
  double weight = 0.0;  // w (signed: a part taken back from a bulk fiber is negative)
};

// The term of a set of point fibers: `name` and `role` as the term reports
// them, `support_group` for role Support (Model::constraint_groups).
std::unique_ptr<EquilibriumTerm> make_point_fiber_term(const TermContext& context,
                                                       std::vector<PointFiber> fibers,
                                                       const char* name, EquilibriumTerm::Role role,
                                                       int support_group = -1);

}  // namespace fiberfluid::model
