// SPDX-License-Identifier: GPL-3.0-or-later
// The free share of a held group's edge (supports[].edge: "split"; model.hpp,
// HeldEdge).
//
// Held vertices on a surface are a local condition on a nonlocal body: the
// free side's displacement does not fall to zero at the held edge but jumps
// there (docs/model.md, "A sphere under gravity"). An edge vertex j stands
// for area on both sides of the jump, and held it gives its free side's share
// the held side's zero: a ring one cell wide with the wrong value, an error
// of first order in the mesh size. Split, j keeps its held share of area
// (1 - s_j) and its free share s_j (the share of its faces' area on faces
// with a free vertex) becomes a ghost point that moves with j's nearest free
// neighbour k along a mesh edge, at x_k + (s_j - s_k): the free side's value
// extrapolated by one cell, O(h) off on a ring of width O(h), an error of
// second order (a ghost node at a fictitious boundary; the split is the
// variational one: the ghost takes part in every equation j's area does).
//
//   fibers   every bulk fiber (i, j) to an edge vertex becomes (1 - s_j) of
//            it at j and s_j of it at the ghost (both ends split when both
//            are edge vertices): the fibers' part at j's ghost is a fiber
//            from i to the point x_k + (s_j - s_k) (OffsetFiber), and the
//            bulk fiber (i, j) is taken back with the ghost's weight;
//   fluid    the ghost's share of the pressure force, P S^g_j(x) with S^g_j
//            = C0 times the free faces' area vectors at j, moves from j to k,
//            and the volume row gains S^g_j . (u_k - u_j), the volume the
//            ghost's area sweeps (the pressure and volume stay work-conjugate).
//
//   loads    a hydrostatic load's force on j from j's free faces (its
//            vertex or exact form at j's pressure) moves from j to k too.
//
// The mirror layer of the same support joins the ghosts to the images of the
// free vertices (mirror_layer.cpp).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "fiberfluid/model/fiber_network.hpp"
#include "fiberfluid/model/model.hpp"
#include "fiberfluid/model/terms.hpp"

namespace fiberfluid::model {

// A fiber from vertex i to a point that moves with vertex p: its vector is
// b = x_i - x_p - offset, its displacement difference d = u_i - u_p.
struct OffsetFiber {
  int i = 0, p = 0;
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  double length = 0.0;  // L, in the reference (|s_i - s_p - offset|)
  double weight = 0.0;  // signed: the part taken back from a bulk fiber is negative
};

// An edge vertex of a held group: its free share of area, the free faces
// that make it and the free neighbour its ghost moves with.
struct EdgeVertex {
  int vertex = 0, neighbour = 0;
  double free_share = 0.0;      // s_j in (0, 1]
  std::vector<int> free_faces;  // j's faces with a free vertex
};

// The edge vertices of a group that holds `held` (every axis): held vertices
// with a face that has a free vertex, each with its nearest free vertex along
// a mesh edge (vertices of no such face are not edge vertices).
std::vector<EdgeVertex> held_edge_vertices(const Model& model, const std::vector<int>& held);

// The split edge of a support group, or null when it has none.
const HeldEdge* held_edge_of(const Model& model, int group);

// The fibers of the split: for every bulk fiber (i, j) at an edge vertex j,
// the fiber (i, j) taken back with weight -w_ij and the fibers between the
// points of i and of j (each vertex itself with share 1 - s, its ghost with
// share s) with the shares' product times w_ij.
std::vector<OffsetFiber> held_edge_fibers(const Model& model, const HeldEdge& edge,
                                          const PairFactors& factors, const Eigen::VectorXd& area0);

// The terms of one split edge: its fibers (role Fibers: the body's own, so
// that the part taken from (i, j) lowers j's reaction as it should), the
// ghosts' shares of pressure and volume (role Fluid) and of each hydrostatic
// load (role Load).
std::vector<std::unique_ptr<EquilibriumTerm>> make_held_edge_terms(const TermContext& context,
                                                                   const HeldEdge& edge);

}  // namespace fiberfluid::model
