// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fem/scenes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>

#include "fiberfluid/fem/mesh_tools.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::fem {

MaterialPreset material_preset(const std::string& name) {
  MaterialPreset p;
  if (name == "MP1") {
    p.material.young = 200.0;
    p.material.poisson = 0.47;
    p.material.density = 2000.0;
  } else if (name == "MP2") {
    p.material.young = 60000.0;
    p.material.poisson = 0.495;
    p.material.density = 1140.0;
  } else if (name == "MP3") {
    p.material.young = 7000.0;
    p.material.poisson = 0.2;
    p.material.density = 10000.0;
  } else {
    throw InputError("unknown material preset \"" + name + "\": expected MP1, MP2 or MP3");
  }
  return p;
}

double Scene::load_factor(double t) const {
  if (push_time > 0.0) return std::clamp(t / push_time, 0.0, 1.0);
  return t > 0.0 ? 1.0 : 0.0;  // gravity switched on at t = 0
}

Scene needle_block(const BlockOptions& o) {
  if (o.cells.minCoeff() < 1 || o.cells[1] % 2 != 0)
    throw InputError(
        "block: expected at least one cell per axis and an even number along y "
        "(the needle sits on the node in the middle of the right side)");
  if (!(o.needle_speed > 0.0) || !(o.push_time > 0.0))
    throw InputError("block: the needle's speed and push time must be positive");
  Scene s;
  s.name = "block-needle";
  const Mesh grid = structured_grid(Eigen::Vector2d(1.0, 1.0), o.cells);
  s.mesh = o.simplices ? to_simplices(grid) : grid;
  s.material = o.material.material;
  s.dynamics = make_dynamics(s.mesh, s.material, o.material.alpha, o.material.beta);
  s.dynamics.divergence_scale = 10.0;  // ten times the block
  const double eps = 1e-9;
  for (int v = 0; v < s.mesh.num_nodes(); ++v) {
    const double x = s.mesh.nodes(v, 0), y = s.mesh.nodes(v, 1);
    if (x < eps || y < eps || y > 1.0 - eps) s.fixed_nodes.push_back(v);
    if (x > 1.0 - eps && std::abs(y - 0.5) < eps) s.needle = v;
  }
  for (int v : s.fixed_nodes)
    for (int a = 0; a < 2; ++a) s.dynamics.held.push_back(2 * v + a);
  s.dynamics.held.push_back(2 * s.needle);  // the needle moves along x; y is free
  s.push_time = o.push_time;
  s.needle_travel = o.needle_speed * o.push_time;
  const auto supports = static_cast<Eigen::Index>(s.dynamics.held.size() - 1);
  const double speed = o.needle_speed, push = o.push_time;
  s.dynamics.held_values = [supports, speed, push](double t) {
    Eigen::VectorXd values = Eigen::VectorXd::Zero(supports + 1);
    values[supports] = -speed * std::min(t, push);
    return values;
  };
  return s;
}

Scene bending_rod(const RodOptions& o) {
  if (o.cells.minCoeff() < 1) throw InputError("rod: expected at least one cell per axis");
  Scene s;
  s.name = "bending-rod";
  const Mesh grid = structured_grid(Eigen::Vector3d(0.5, 0.25, 0.25), o.cells);
  s.mesh = o.simplices ? to_simplices(grid) : grid;
  s.material = o.material.material;
  s.dynamics = make_dynamics(s.mesh, s.material, o.material.alpha, o.material.beta);
  s.dynamics.divergence_scale = 5.0;  // ten times the rod
  for (int v = 0; v < s.mesh.num_nodes(); ++v)
    if (s.mesh.nodes(v, 0) < 1e-9) s.fixed_nodes.push_back(v);
  for (int v : s.fixed_nodes)
    for (int a = 0; a < 3; ++a) s.dynamics.held.push_back(3 * v + a);
  s.gravity = Eigen::Vector3d(0.0, 0.0, -o.gravity);
  const Eigen::VectorXd weight = body_forces(s.mesh, s.material, s.gravity);
  s.dynamics.force = [weight](double t) {
    return t >= 0.0 ? weight : Eigen::VectorXd(Eigen::VectorXd::Zero(weight.size()));
  };
  return s;
}

// The FEM's static state under the full load.
Eigen::VectorXd static_state(const Scene& scene) {
  const Dynamics& d = scene.dynamics;
  Constraints held;
  const double late = 1e9;
  const Eigen::VectorXd values =
      d.held_values ? d.held_values(late)
                    : Eigen::VectorXd::Zero(static_cast<Eigen::Index>(d.held.size()));
  for (size_t k = 0; k < d.held.size(); ++k)
    held.hold(d.held[k], values[static_cast<Eigen::Index>(k)]);
  Eigen::VectorXd u;
  const Eigen::VectorXd f = d.force ? d.force(late) : Eigen::VectorXd::Zero(d.K.rows());
  const linalg::Status status = solve_static(d.K, f, held, &u);
  if (!status.ok) throw InputError("benchmark: the static problem is singular: " + status.message);
  return u;
}

Eigen::MatrixXd boundary_rows(const Boundary& b, const Eigen::MatrixXd& node_rows) {
  Eigen::MatrixXd out(static_cast<Eigen::Index>(b.nodes.size()), node_rows.cols());
  for (size_t v = 0; v < b.nodes.size(); ++v)
    out.row(static_cast<Eigen::Index>(v)) = node_rows.row(b.nodes[v]);
  return out;
}

namespace {

// Each row of `points` (nodes of a coarser grid over the same box) as a node
// of `grid`, whose lattice spacing per axis is `spacing`.
std::vector<int> grid_nodes_at(const Eigen::MatrixXd& grid, const Eigen::MatrixXd& points,
                               const Eigen::Vector3d& spacing) {
  const auto key = [&](const Eigen::MatrixXd& rows, Eigen::Index v) {
    std::array<long, 3> k{};
    for (int a = 0; a < 3; ++a) k[static_cast<size_t>(a)] = std::lround(rows(v, a) / spacing[a]);
    return k;
  };
  std::map<std::array<long, 3>, int> index;
  for (Eigen::Index v = 0; v < grid.rows(); ++v) index[key(grid, v)] = static_cast<int>(v);
  std::vector<int> out(static_cast<size_t>(points.rows()));
  for (Eigen::Index v = 0; v < points.rows(); ++v) {
    const auto it = index.find(key(points, v));
    if (it == index.end() || (grid.row(it->second) - points.row(v)).norm() > 1e-9 * spacing.norm())
      throw std::logic_error("a node of the rod is not a node of its refined grid");
    out[static_cast<size_t>(v)] = it->second;
  }
  return out;
}

}  // namespace

Eigen::MatrixXd rod_statics_at(const RodOptions& options, const Eigen::MatrixXd& nodes) {
  const Scene fine = bending_rod(options);
  const Eigen::MatrixXd u = displacement_rows(static_state(fine), 3);
  const Eigen::Vector3d box = fine.mesh.nodes.colwise().maxCoeff().transpose();  // from 0
  const Eigen::Vector3d spacing = box.cwiseQuotient(options.cells.cast<double>());
  const std::vector<int> at = grid_nodes_at(fine.mesh.nodes, nodes, spacing);
  Eigen::MatrixXd out(nodes.rows(), 3);
  for (Eigen::Index v = 0; v < nodes.rows(); ++v) out.row(v) = u.row(at[static_cast<size_t>(v)]);
  return out;
}

}  // namespace fiberfluid::fem
