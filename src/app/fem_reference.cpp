// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/fem_reference.hpp"

#include <chrono>
#include <limits>

#include "app/case_spec.hpp"
#include "app/json_fields.hpp"
#include "app/runner.hpp"
#include "fem/mesh_tools.hpp"
#include "fit/target.hpp"
#include "metrics/metrics.hpp"
#include "model/assembly.hpp"
#include "model/model.hpp"
#include "util/error.hpp"

namespace fiberfluid::app {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

int nearest_row(const Eigen::MatrixXd& points, const Eigen::RowVectorXd& p) {
  Eigen::Index best = 0;
  (points.rowwise() - p).rowwise().squaredNorm().minCoeff(&best);
  return static_cast<int>(best);
}

// Barycentric coordinates of p (in the triangle's plane) in triangle abc.
Eigen::Vector3d barycentric(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                            const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d u = b - a, v = c - a, w = p - a;
  const double uu = u.dot(u), uv = u.dot(v), vv = v.dot(v), wu = w.dot(u), wv = w.dot(v);
  const double det = uu * vv - uv * uv;
  const double beta = (vv * wu - uv * wv) / det, gamma = (uu * wv - uv * wu) / det;
  return {1.0 - beta - gamma, beta, gamma};
}

[[noreturn]] void fail(const std::string& what) { throw InputError("fem_reference: " + what); }

}  // namespace

FemReferenceSpec read_fem_reference(Fields& f) {
  FemReferenceSpec spec;
  spec.young = f.positive("E", 1.0);
  spec.poisson = f.number("nu");
  if (!(spec.poisson > -1.0 && spec.poisson < 0.5))
    f.fail("nu", "expected a Poisson ratio between -1 and 0.5 (exclusive)");
  spec.mesh.size = f.non_negative("size", 0.0);
  spec.mesh.facet_distance = f.non_negative("facet_distance", 0.0);
  spec.mesh.feature_angle = f.positive("feature_angle", spec.mesh.feature_angle);
  if (spec.mesh.feature_angle > 180.0) f.fail("feature_angle", "expected degrees up to 180");
  f.finish();
  return spec;
}

FemReferenceResult solve_fem_reference(const Case& c, const RunResult& run,
                                       const FemReferenceSpec& spec) {
  const model::Model& m = c.model;
  if (m.dim() != 3) fail("needs a closed 3D surface (this one is 2D)");
  if (!m.paddles.empty())
    fail("paddles (contact) are not supported: use supports, prescribed displacements and loads");
  const int steps = c.stepping.steps;
  FemReferenceResult out;
  const auto start = std::chrono::steady_clock::now();
  out.mesh = fem::tetrahedralize(m.surface, spec.mesh);
  const double mesh_seconds = seconds_since(start);
  const fem::Boundary boundary = fem::boundary(out.mesh);
  out.rest_boundary = boundary.surface;

  // A boundary node is held on an axis where the surface under it is: when
  // every vertex spanning its closest surface point (a vertex, an edge's two,
  // a triangle's three) is held on that axis, at their interpolated values.
  const Eigen::MatrixXd& V = m.surface.V;
  std::vector<std::map<int, double>> vertex_held(
      static_cast<size_t>(m.num_vertices()));  // axis -> value
  for (const model::Constraint& k : m.constraints)
    vertex_held[static_cast<size_t>(k.vertex)][k.axis] = k.value * k.schedule.factor(steps, steps);
  const fit::TargetDistance surface(fit::make_target("the surface", V, m.surface.F));
  std::map<std::pair<int, int>, double> held;  // (node, axis) -> value
  std::vector<bool> vertex_reached(static_cast<size_t>(m.num_vertices()), false);
  for (int node : boundary.nodes) {
    const fit::TargetDistance::Closest closest =
        surface.closest(Eigen::Vector3d(out.mesh.nodes.row(node)));
    const Eigen::Vector3i corners = m.surface.F.row(closest.primitive);
    const Eigen::Vector3d weights =
        barycentric(closest.point, V.row(corners[0]), V.row(corners[1]), V.row(corners[2]));
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

  fem::Material material;
  material.young = spec.young;
  material.poisson = spec.poisson;
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
  const double solve_seconds = seconds_since(solve_start);
  out.displacement = fem::displacement_rows(u, 3);
  out.deformed_boundary = fem::boundary(out.mesh, out.mesh.nodes + out.displacement).surface;

  auto& fig = out.figures;
  fig["fem_reference.nodes"] = out.mesh.num_nodes();
  fig["fem_reference.tetrahedra"] = static_cast<double>(out.mesh.elements.rows());
  fig["fem_reference.mesh_seconds"] = mesh_seconds;
  fig["fem_reference.solve_seconds"] = solve_seconds;
  fig["fem_reference.max_displacement"] = out.displacement.rowwise().norm().maxCoeff();
  try {  // how far the tetrahedra's boundary is from the surface before any load
    fig["fem_reference.rest_surface_error"] = metrics::surface_error(m.surface, out.rest_boundary);
  } catch (const InputError&) {
  }
  fig["fem_reference.volume_change"] = metrics::enclosed_measure(out.deformed_boundary) /
                                           metrics::enclosed_measure(out.rest_boundary) -
                                       1.0;
  if (run.summary.success) {  // the fiber model's final surface against the FEM's
    geom::Surface fiber = m.surface;
    fiber.V = V + model::displacements(m, run.summary.unknowns);
    const fit::TargetDistance distance(
        fit::make_target("the FEM reference", out.deformed_boundary.V, out.deformed_boundary.F));
    const std::vector<fit::TargetDistance::Closest> closest = distance.closest(fiber.V);
    Eigen::VectorXd d(static_cast<Eigen::Index>(closest.size()));
    for (size_t k = 0; k < closest.size(); ++k)
      d[static_cast<Eigen::Index>(k)] = closest[k].distance;
    const fit::DistanceStatistics stats =
        fit::distance_statistics(d, geom::bounding_box_diagonal(V));
    fig["fem_reference.distance_mean"] = stats.mean;
    fig["fem_reference.distance_sd"] = stats.standard_deviation;
    fig["fem_reference.distance_sd_share"] = stats.share(stats.standard_deviation);
    fig["fem_reference.distance_largest"] = stats.largest;
    try {
      fig["fem_reference.surface_error"] = metrics::surface_error(
          out.deformed_boundary, fiber, "the FEM reference", "the fiber model");
    } catch (const InputError&) {  // a surface that crosses itself has no E_s; the distances stand
    }
  }
  return out;
}

}  // namespace fiberfluid::app
