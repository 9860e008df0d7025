// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// A FEM benchmark scene (fem/scenes.hpp) posed as a fibers-and-fluid model on
// the mesh's boundary, so that both models solve the same problem: the
// scene's held nodes become supports in every axis, the block's needle a
// prescribed displacement along -x, the rod's gravity a hydrostatic load of
// the scene's density. Every load and displacement is ramped over the steps.

#include "fiberfluid/fem/mesh_tools.hpp"
#include "fiberfluid/fem/scenes.hpp"
#include "fiberfluid/model/model.hpp"

namespace fiberfluid::bridge {

// The model of `scene` on its rest boundary (surface vertex v is mesh node
// boundary.nodes[v]) with the given material. A concave boundary has the
// fibers that leave it pruned (geom::prune_fibers); a convex one keeps all.
// Throws InputError when the boundary has a vertex in no face.
model::Model fiber_model_of_scene(const fem::Scene& scene, const fem::Boundary& boundary,
                                  const model::Material& material);

}  // namespace fiberfluid::bridge
