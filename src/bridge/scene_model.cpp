// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/bridge/scene_model.hpp"

#include <algorithm>
#include <memory>

#include "fiberfluid/geom/fiber_pruning.hpp"
#include "fiberfluid/geom/surface.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::bridge {
namespace {

// Holds every axis of a vertex at the displacement `value` (0 for a support).
void hold(model::Model& m, int vertex, const Eigen::Vector3d& value, int group) {
  for (int axis = 0; axis < m.dim(); ++axis) {
    model::Constraint c;
    c.vertex = vertex;
    c.axis = axis;
    c.value = value[axis];
    c.group = group;
    m.constraints.push_back(c);
  }
}

}  // namespace

model::Model fiber_model_of_scene(const fem::Scene& scene, const fem::Boundary& boundary,
                                  const model::Material& material) {
  model::Model m;
  m.surface = boundary.surface;
  if (geom::remove_unused_vertices(m.surface).surface.num_vertices() != m.num_vertices())
    throw InputError("the boundary of scene \"" + scene.name + "\" has a vertex in no face");
  m.material = material;

  m.constraint_groups = {"supports"};
  const int needle_group = scene.needle >= 0 ? 1 : -1;
  if (needle_group > 0) m.constraint_groups.push_back("needle");
  for (size_t v = 0; v < boundary.nodes.size(); ++v) {
    const int node = boundary.nodes[v], vertex = static_cast<int>(v);
    if (std::binary_search(scene.fixed_nodes.begin(), scene.fixed_nodes.end(), node))
      hold(m, vertex, Eigen::Vector3d::Zero(), 0);
    if (node == scene.needle) hold(m, vertex, {-scene.needle_travel, 0.0, 0.0}, needle_group);
  }

  if (scene.gravity.size() > 0) {
    model::Load gravity;
    gravity.kind = model::Load::Kind::Hydrostatic;
    gravity.label = "gravity";
    gravity.acceleration.head(scene.gravity.size()) = scene.gravity;
    gravity.density = scene.material.density;
    m.loads.push_back(gravity);
  }

  if (!geom::is_convex(m.surface))
    m.fibers = std::make_shared<const geom::FiberMask>(geom::prune_fibers(m.surface, false).mask);
  return m;
}

}  // namespace fiberfluid::bridge
