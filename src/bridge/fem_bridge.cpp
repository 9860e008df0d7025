// SPDX-License-Identifier: GPL-3.0-or-later
#include "bridge/fem_bridge.hpp"

#include <chrono>
#include <map>
#include <vector>

#include "fem/mesh_tools.hpp"
#include "fit/target.hpp"
#include "geom/area_vectors.hpp"
#include "model/boundary_conditions.hpp"
#include "util/error.hpp"

namespace fiberfluid::bridge {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

int nearest_row(const Eigen::MatrixXd& points, const Eigen::RowVectorXd& p) {
  Eigen::Index best = 0;
  (points.rowwise() - p).rowwise().squaredNorm().minCoeff(&best);
  return static_cast<int>(best);
}

[[noreturn]] void fail(const std::string& what) { throw InputError(what); }

}  // namespace

FemOfModel solve_fem_of_model(const model::Model& m, int steps, const fem::Material& material,
                              const fem::TetMeshOptions& mesh_options) {
  if (m.dim() != 3) fail("needs a closed 3D surface (this one is 2D)");
  if (!m.paddles.empty())
    fail("paddles (contact) are not supported: use supports, prescribed displacements and loads");
  FemOfModel out;
  const auto start = std::chrono::steady_clock::now();
  out.mesh = fem::tetrahedralize(m.surface, mesh_options);
  out.mesh_seconds = seconds_since(start);
  const fem::Boundary boundary = fem::boundary(out.mesh);
  out.rest_boundary = boundary.surface;

  // A boundary node is held on an axis where the surface under it is: when
  // every vertex spanning its closest surface point (a vertex, an edge's two,
  // a triangle's three) is held on that axis, at their interpolated values.
  const Eigen::MatrixXd& V = m.surface.V;
  std::vector<std::map<int, double>> vertex_held(
      static_cast<size_t>(m.num_vertices()));  // axis -> value
  for (const model::Constraint& k : m.constraints)
    vertex_held[static_cast<size_t>(k.vertex)][k.axis] = model::held_value(m, k, steps, steps);
  const fit::TargetDistance surface(fit::make_target("the surface", V, m.surface.F));
  std::map<std::pair<int, int>, double> held;  // (node, axis) -> value
  std::vector<bool> vertex_reached(static_cast<size_t>(m.num_vertices()), false);
  for (int node : boundary.nodes) {
    const fit::TargetDistance::Closest closest =
        surface.closest(Eigen::Vector3d(out.mesh.nodes.row(node)));
    const Eigen::Vector3i corners = m.surface.F.row(closest.primitive);
    const Eigen::Vector3d weights = geom::barycentric_coordinates(
        closest.point, V.row(corners[0]), V.row(corners[1]), V.row(corners[2]));
    for (int axis = 0; axis < 3; ++axis) {
      double value = 0.0;
      bool all = true;
      for (int k = 0; k < 3; ++k) {
        if (weights[k] <= 1e-9) continue;  // not spanning the point
        const auto& h = vertex_held[static_cast<size_t>(corners[k])];
        const auto it = h.find(axis);
        if (it == h.end())
          all = false;
        else
          value += weights[k] * it->second;
      }
      if (!all) continue;
      held[{node, axis}] = value;
      for (int k = 0; k < 3; ++k)
        if (weights[k] > 1e-9) vertex_reached[static_cast<size_t>(corners[k])] = true;
    }
  }
  // A held vertex that no node's closest point reached (a single vertex, or
  // a patch smaller than the tetrahedra) holds its nearest node.
  for (int v = 0; v < m.num_vertices(); ++v) {
    if (vertex_reached[static_cast<size_t>(v)] || vertex_held[static_cast<size_t>(v)].empty())
      continue;
    const int node = boundary.nodes[static_cast<size_t>(nearest_row(boundary.surface.V, V.row(v)))];
    for (const auto& [axis, value] : vertex_held[static_cast<size_t>(v)])
      held.emplace(std::make_pair(node, axis), value);
  }
  fem::Constraints constraints;
  for (const auto& [key, value] : held) constraints.hold(3 * key.first + key.second, value);

  Eigen::VectorXd f = Eigen::VectorXd::Zero(out.mesh.num_dofs());
  for (const model::Load& load : m.loads) {
    const double factor = load.schedule.factor(steps, steps);
    switch (load.kind) {
      case model::Load::Kind::Point: {
        const int node =
            boundary
                .nodes[static_cast<size_t>(nearest_row(boundary.surface.V, V.row(load.vertex)))];
        f.segment(3 * node, 3) += factor * load.force;
        continue;
      }
      case model::Load::Kind::Hydrostatic: {
        // The fluid's weight as the solid's body force of the same density.
        fem::Material fluid = material;
        fluid.density = load.density;
        f += fem::body_forces(out.mesh, fluid, factor * load.acceleration);
        continue;
      }
    }
    fail("a load of an unknown kind");
  }
  const auto solve_start = std::chrono::steady_clock::now();
  Eigen::VectorXd u;
  const solve::Status status =
      fem::solve_static(fem::stiffness_matrix(out.mesh, material), f, constraints, &u);
  if (!status.ok) fail(status.message);
  out.solve_seconds = seconds_since(solve_start);
  out.displacement = fem::displacement_rows(u, 3);
  out.deformed_boundary = fem::boundary(out.mesh, out.mesh.nodes + out.displacement).surface;

  return out;
}

}  // namespace fiberfluid::bridge
