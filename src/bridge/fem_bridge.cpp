// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/bridge/fem_bridge.hpp"

#include <chrono>
#include <cmath>
#include <functional>
#include <map>
#include <sstream>
#include <vector>

#include "fiberfluid/fem/mesh_tools.hpp"
#include "fiberfluid/fem/setup_diagnosis.hpp"
#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/geom/surface.hpp"
#include "fiberfluid/geom/target.hpp"
#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/util/error.hpp"
#include "fiberfluid/util/run_control.hpp"

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

// The body of a model posed for the FEM: its tetrahedra, their boundary, and
// what holds and loads them at each load step (1..steps). `state` refers to
// the model: it lives while the model does.
struct PosedFem {
  fem::Mesh mesh;
  fem::Boundary boundary;
  double mesh_seconds = 0.0;
  fem::LoadPath state;
};

PosedFem pose_fem(const model::Model& m, int steps, const fem::TetMeshOptions& mesh_options,
                  int order) {
  if (const Status posable = check_fem_posable(m); !posable.ok) fail(posable.message);
  PosedFem posed;
  const auto start = std::chrono::steady_clock::now();
  posed.mesh = fem::tetrahedralize(m.surface, mesh_options);
  if (order == 2) posed.mesh = fem::to_quadratic(posed.mesh);
  posed.mesh_seconds = seconds_since(start);
  posed.boundary = fem::boundary(posed.mesh);
  const fem::Mesh& mesh = posed.mesh;
  const fem::Boundary& boundary = posed.boundary;

  // A boundary node is held on an axis where the surface under it is: when
  // every vertex spanning its closest surface point (a vertex, an edge's two,
  // a triangle's three) is held on that axis, at their interpolated values:
  // the weights, found once, interpolate each step's held values.
  const Eigen::MatrixXd& V = m.surface.V;
  std::vector<std::map<int, const model::Constraint*>> vertex_held(
      static_cast<size_t>(m.num_vertices()));  // axis -> its constraint
  for (const model::Constraint& k : m.constraints)
    vertex_held[static_cast<size_t>(k.vertex)][k.axis] = &k;
  const geom::TargetDistance surface(geom::make_target("the surface", V, m.surface.F));
  // (node, axis) -> the constraints it interpolates, with their weights.
  std::map<std::pair<int, int>, std::vector<std::pair<const model::Constraint*, double>>> held;
  std::vector<bool> vertex_reached(static_cast<size_t>(m.num_vertices()), false);
  for (int node : boundary.nodes) {
    const geom::TargetDistance::Closest closest =
        surface.closest(Eigen::Vector3d(mesh.nodes.row(node)));
    const Eigen::Vector3i corners = m.surface.F.row(closest.primitive);
    const Eigen::Vector3d weights = geom::barycentric_coordinates(
        closest.point, V.row(corners[0]), V.row(corners[1]), V.row(corners[2]));
    for (int axis = 0; axis < 3; ++axis) {
      std::vector<std::pair<const model::Constraint*, double>> terms;
      bool all = true;
      for (int k = 0; k < 3; ++k) {
        if (weights[k] <= 1e-9) continue;  // not spanning the point
        const auto& h = vertex_held[static_cast<size_t>(corners[k])];
        const auto it = h.find(axis);
        if (it == h.end())
          all = false;
        else
          terms.emplace_back(it->second, weights[k]);
      }
      if (!all) continue;
      held[{node, axis}] = terms;
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
    for (const auto& [axis, constraint] : vertex_held[static_cast<size_t>(v)])
      held.emplace(std::make_pair(node, axis),
                   std::vector<std::pair<const model::Constraint*, double>>{{constraint, 1.0}});
  }
  // Each load at factor 1: a point load on the node nearest its vertex,
  // gravity as a body force of the fluid's density.
  std::vector<Eigen::VectorXd> unit_loads;
  for (const model::Load& load : m.loads) {
    Eigen::VectorXd f = Eigen::VectorXd::Zero(mesh.num_dofs());
    if (load.kind == model::Load::Kind::Point) {
      const int node =
          boundary.nodes[static_cast<size_t>(nearest_row(boundary.surface.V, V.row(load.vertex)))];
      f.segment(3 * node, 3) = load.force;
    } else if (load.kind == model::Load::Kind::Hydrostatic) {
      fem::Material fluid;
      fluid.density = load.density;
      f = fem::body_forces(mesh, fluid, load.acceleration);
    } else {
      fail("a load of an unknown kind");
    }
    unit_loads.push_back(std::move(f));
  }
  posed.state = [&m, steps, held, unit_loads, dofs = mesh.num_dofs()](int step) {
    fem::LoadState state;
    for (const auto& [key, terms] : held) {
      double value = 0.0;
      for (const auto& [constraint, weight] : terms)
        value += weight * model::held_value(m, *constraint, step, steps);
      state.held.hold(3 * key.first + key.second, value);
    }
    state.forces = Eigen::VectorXd::Zero(dofs);
    for (size_t l = 0; l < m.loads.size(); ++l)
      state.forces += m.loads[l].schedule.factor(step, steps) * unit_loads[l];
    return state;
  };
  return posed;
}

// The outputs of a solve: displacements and the boundary before and after.
void finish(const PosedFem& posed, const Eigen::VectorXd& u, FemOfModel* out) {
  out->mesh = posed.mesh;
  out->mesh_seconds = posed.mesh_seconds;
  out->displacement = fem::displacement_rows(u, 3);
  out->rest_boundary = posed.boundary.surface;
  out->deformed_boundary = fem::boundary(posed.mesh, posed.mesh.nodes + out->displacement).surface;
}

// A solve that failed: stopped by a request, or a numerical failure named
// with what in the setup likely caused it.
[[noreturn]] void solve_failed(const PosedFem& posed, double poisson, const Status& status) {
  throw_if_cancelled("the FEM reference");
  std::string why = status.message;
  const Status setup = fem::diagnose_singular_setup(posed.mesh, poisson, posed.state(1).held.dofs);
  if (!setup.ok) why += " (likely cause: " + setup.message + ")";
  throw FemSolveFailure(why);
}

// Displacements that are not finite, or a hundred times the body's size,
// are no result (a modulus so small that the loads overflow them): a
// failure, never a success with empty or absurd figures.
void check_displacements(const PosedFem& posed, double poisson, const Eigen::VectorXd& u) {
  const double size = geom::bounding_box_diagonal(posed.mesh.nodes);
  const double largest =
      u.allFinite() ? fem::displacement_rows(u, 3).rowwise().norm().maxCoeff() : HUGE_VAL;
  if (!std::isfinite(largest))
    solve_failed(posed, poisson,
                 Status::failure("the displacements are not finite (a modulus too small for "
                                 "the loads?)"));
  if (largest > 100.0 * size) {
    std::ostringstream why;
    why << "the largest displacement, " << largest << " m, is " << largest / size
        << " times the body's size (a modulus too small for the loads?)";
    solve_failed(posed, poisson, Status::failure(why.str()));
  }
}

}  // namespace

Status check_fem_posable(const model::Model& m) {
  if (m.dim() != 3) return Status::failure("needs a closed 3D surface (this one is 2D)");
  if (!m.paddles.empty())
    return Status::failure(
        "paddles (contact) are not supported: use supports, prescribed displacements and loads");
  return {};
}

FemOfModel solve_fem_of_model(const model::Model& m, int steps, const fem::Material& material,
                              const fem::TetMeshOptions& mesh_options, int order) {
  const PosedFem posed = pose_fem(m, steps, mesh_options, order);
  const fem::LoadState last = posed.state(steps);
  FemOfModel out;
  const auto solve_start = std::chrono::steady_clock::now();
  Eigen::VectorXd u;
  if (order == 2) {  // quadratic with a linear pressure: the neo-Hookean tangent at rest
    fem::HyperelasticMaterial solid;
    solid.young = material.young;
    solid.poisson = material.poisson;
    fem::HyperelasticOptions options;
    options.mixed = true;
    fem::HyperelasticSolution solution;
    const linalg::Status status =
        fem::solve_small_strain(posed.mesh, solid, last, options, &solution);
    if (!status.ok) solve_failed(posed, material.poisson, status);
    u = solution.u;
  } else {
    const linalg::Status status =
        fem::solve_static(fem::stiffness_matrix(posed.mesh, material), last.forces, last.held, &u);
    if (!status.ok) solve_failed(posed, material.poisson, status);
  }
  check_displacements(posed, material.poisson, u);
  out.solve_seconds = seconds_since(solve_start);
  finish(posed, u, &out);
  out.path.push_back(out.displacement);
  return out;
}

FemOfModel solve_hyperelastic_fem_of_model(const model::Model& m, int steps,
                                           const fem::HyperelasticMaterial& material,
                                           const fem::TetMeshOptions& mesh_options, int order,
                                           fem::HyperelasticOptions options) {
  const PosedFem posed = pose_fem(m, steps, mesh_options, order);
  options.steps = steps;
  options.mixed = order == 2;
  FemOfModel out;
  const auto solve_start = std::chrono::steady_clock::now();
  fem::HyperelasticSolution solution;
  const linalg::Status status =
      fem::solve_hyperelastic(posed.mesh, material, posed.state, options, &solution);
  if (!status.ok) solve_failed(posed, material.poisson, status);
  check_displacements(posed, material.poisson, solution.u);
  out.solve_seconds = seconds_since(solve_start);
  out.newton_iterations = solution.newton_iterations;
  finish(posed, solution.u, &out);
  for (const Eigen::VectorXd& u : solution.path) out.path.push_back(fem::displacement_rows(u, 3));
  return out;
}

}  // namespace fiberfluid::bridge
