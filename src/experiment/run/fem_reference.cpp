// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/run/fem_reference.hpp"

#include <limits>

#include "fiberfluid/bridge/fem_bridge.hpp"
#include "fiberfluid/experiment/run/run_result.hpp"
#include "fiberfluid/experiment/spec/case_spec.hpp"
#include "fiberfluid/fit/target.hpp"
#include "fiberfluid/metrics/metrics.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/model.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::experiment {
namespace {

[[noreturn]] void fail(const std::string& what) { throw InputError("fem_reference: " + what); }

}  // namespace

FemReferenceResult solve_fem_reference(const Case& c, const RunResult& run,
                                       const FemReferenceSpec& spec) {
  const model::Model& m = c.model;
  fem::Material material;
  material.young = spec.young;
  material.poisson = spec.poisson;
  FemReferenceResult out;
  bridge::FemOfModel fem;
  try {
    if (spec.nonlinear) {
      fem::HyperelasticMaterial solid;
      solid.kind = spec.hyperelastic;
      solid.young = spec.young;
      solid.poisson = spec.poisson;
      fem = bridge::solve_hyperelastic_fem_of_model(m, c.stepping.steps, solid, spec.mesh,
                                                    spec.order);
    } else {
      fem = bridge::solve_fem_of_model(m, c.stepping.steps, material, spec.mesh, spec.order);
    }
  } catch (const InputError& e) {
    fail(e.what());
  }
  out.mesh = std::move(fem.mesh);
  out.displacement = std::move(fem.displacement);
  out.path = std::move(fem.path);
  out.rest_boundary = std::move(fem.rest_boundary);
  out.deformed_boundary = std::move(fem.deformed_boundary);
  const double mesh_seconds = fem.mesh_seconds, solve_seconds = fem.solve_seconds;
  const Eigen::MatrixXd& V = m.surface.V;

  auto& fig = out.figures;
  fig["fem_reference.nodes"] = out.mesh.num_nodes();
  fig["fem_reference.tetrahedra"] = static_cast<double>(out.mesh.elements.rows());
  fig["fem_reference.element_order"] = spec.order;
  fig["fem_reference.mesh_seconds"] = mesh_seconds;
  fig["fem_reference.solve_seconds"] = solve_seconds;
  if (spec.nonlinear) fig["fem_reference.newton_iterations"] = fem.newton_iterations;
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
    const geom::TargetDistance distance(
        geom::make_target("the FEM reference", out.deformed_boundary.V, out.deformed_boundary.F));
    const std::vector<geom::TargetDistance::Closest> closest = distance.closest(fiber.V);
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

}  // namespace fiberfluid::experiment
