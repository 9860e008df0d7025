// SPDX-License-Identifier: GPL-3.0-or-later
// The mirror layer of a clamped support (model.hpp, MirrorLayer): fibers that
// reach across the clamp plane to the odd reflection of the body, so that a
// body of fibers with a horizon does not hinge where it is held.
//
// A layer fiber joins vertex i to the image of vertex j, at 2 q_j - x_j (q_j
// the foot of s_j on the plane): its vector is b = x_i + x_j - 2 q_j, its
// displacement difference d = u_i + u_j, its reference length
// L = |s_i + s_j - 2 q_j|. It is stored once per ordered pair (i, j),
// i = j included, with half the weight of a bulk fiber of that length,
//   w = omega(L) (|S_i| + |S_j|) / (2 (c_i + c_j) L),
// and acts on both i and j alike (the derivative of its energy in x_i and in
// x_j is the same): summed over (i, j) and (j, i), each vertex meets about
// one fiber per image in its horizon, as a peridynamic point beside a
// fictitious layer does. The fiber follows the bulk fibers' kinematics and
// law through the pair stencil (pair_stencil.hpp).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "fiberfluid/model/model.hpp"
#include "fiberfluid/model/terms.hpp"
#include "fiberfluid/util/status.hpp"

namespace fiberfluid::model {

// The plane of a clamped group: its held vertices' best plane (a line in
// 2D), its normal pointing into the body, into `layer`; or why there is none: no
// vertex held, vertices that do not span a plane or lie off it by more than
// 1e-6 of the body's size, or a body on both sides of it.
Status find_clamp_plane(const Eigen::MatrixXd& reference, const std::vector<int>& held,
                        MirrorLayer* layer);

struct LayerFiber {
  int i = 0, j = 0;                                      // the vertex and the mirrored one
  Eigen::Vector3d twice_foot = Eigen::Vector3d::Zero();  // 2 q_j
  double length = 0.0;                                   // L, in the reference
  double weight = 0.0;                                   // w (above)
};

// The layer's fibers: ordered pairs (i, j) of vertices off the plane whose
// pair is a bulk fiber (or i = j) with L below the layer's depth.
std::vector<LayerFiber> mirror_layer_fibers(const Model& model, const MirrorLayer& layer,
                                            const PairFactors& factors,
                                            const Eigen::VectorXd& area0);

// The equilibrium term of one layer (role Support: its forces are the
// clamp's, and add to its group's reaction).
std::unique_ptr<EquilibriumTerm> make_mirror_layer_term(const TermContext& context,
                                                        const MirrorLayer& layer);

}  // namespace fiberfluid::model
