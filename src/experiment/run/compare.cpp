// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/run/compare.hpp"

#include <sstream>

#include "fiberfluid/geom/mesh_io.hpp"
#include "fiberfluid/metrics/metrics.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::experiment {

namespace {

// A scan in mm beside a model in m gives metrics that mean nothing: say so.
void warn_of_scale_mismatch(const geom::Surface& a, const geom::Surface& b,
                            const std::string& a_label, const std::string& b_label, Comparison& c) {
  const double size_a = geom::bounding_box_diagonal(a.V), size_b = geom::bounding_box_diagonal(b.V);
  if (!(size_a > 0.0 && size_b > 0.0)) return;
  const double ratio = std::max(size_a, size_b) / std::min(size_a, size_b);
  if (ratio <= kScaleMismatch) return;
  std::ostringstream out;
  out.precision(3);
  out << b_label << " is " << ratio << " times " << (size_b > size_a ? "larger" : "smaller")
      << " than " << a_label << " (bounding-box diagonals " << size_b << " and " << size_a
      << "): are they in the same units?";
  c.warnings.push_back(out.str());
}

}  // namespace

Comparison compare_surfaces(const geom::Surface& reference, const geom::Surface& approximation,
                            const geom::Surface* undeformed, const std::string& reference_label,
                            const std::string& approximation_label,
                            const std::string& undeformed_label) {
  Comparison c;
  c.reference = reference_label;
  c.approximation = approximation_label;
  c.undeformed = undeformed ? undeformed_label : "";
  c.dim = reference.dim;
  metrics::require_representable(reference, reference_label);
  metrics::require_representable(approximation, approximation_label);
  warn_of_scale_mismatch(reference, approximation, reference_label, approximation_label, c);
  if (undeformed)
    warn_of_scale_mismatch(reference, *undeformed, reference_label, undeformed_label, c);
  try {
    c.surface_error =
        metrics::surface_error(reference, approximation, reference_label, approximation_label);
    c.reference_measure = metrics::enclosed_measure(reference);
    c.symmetric_difference = *c.surface_error * *c.reference_measure;
  } catch (const InputError& e) {
    if (c.dim != 3) throw;  // a 2D comparison has nothing else to give
    c.surface_error_missing = e.what();
  }

  if (undeformed) {
    const int n = undeformed->num_vertices();
    if (reference.num_vertices() != n || approximation.num_vertices() != n ||
        undeformed->dim != c.dim)
      throw InputError("E_n and E_i compare node by node: " + reference_label + " has " +
                       std::to_string(reference.num_vertices()) + " vertices, " +
                       approximation_label + " " + std::to_string(approximation.num_vertices()) +
                       ", " + undeformed_label + " " + std::to_string(n));
    c.energy_norm =
        metrics::relative_energy_norm(reference.V - undeformed->V, approximation.V - undeformed->V);
    c.interior_error = metrics::interior_error(reference.V, approximation.V,
                                               metrics::boundary_node_measures(*undeformed),
                                               metrics::enclosed_measure(*undeformed), c.dim);
  }
  if (c.dim == 3) {
    if (!approximation.V.allFinite())
      throw InputError(approximation_label + ": a vertex coordinate is not finite");
    const geom::TargetDistance distance(
        geom::make_target(reference_label, reference.V, reference.F));
    const std::vector<geom::TargetDistance::Closest> closest = distance.closest(approximation.V);
    Eigen::VectorXd d(static_cast<Eigen::Index>(closest.size()));
    for (size_t i = 0; i < closest.size(); ++i)
      d[static_cast<Eigen::Index>(i)] = closest[i].distance;
    const Eigen::RowVectorXd extent =
        reference.V.colwise().maxCoeff() - reference.V.colwise().minCoeff();
    c.distances = fit::distance_statistics(d, extent.maxCoeff());
  }
  return c;
}

Comparison compare_files(const std::filesystem::path& reference,
                         const std::filesystem::path& approximation,
                         const std::optional<std::filesystem::path>& undeformed) {
  const geom::Surface m = geom::read_surface(reference).surface;
  const geom::Surface m_prime = geom::read_surface(approximation).surface;
  std::optional<geom::Surface> m0;
  if (undeformed) m0 = geom::read_surface(*undeformed).surface;
  return compare_surfaces(m, m_prime, m0 ? &*m0 : nullptr, reference.string(),
                          approximation.string(), undeformed ? undeformed->string() : "");
}

std::string comparison_text(const Comparison& c) {
  std::ostringstream out;
  out.precision(6);
  const char* measure = c.dim == 2 ? "area" : "volume";
  out << "reference (M): " << c.reference << "\napproximation (M'): " << c.approximation << "\n";
  if (!c.undeformed.empty()) out << "undeformed (M0): " << c.undeformed << "\n";
  if (c.surface_error)
    out << "E_s = " << *c.surface_error << "  (|M xor M'| = " << *c.symmetric_difference
        << " of the " << measure << " |M| = " << *c.reference_measure << ", exact Booleans)\n";
  else
    out << "E_s: not computed: it needs two closed solids: " << c.surface_error_missing << "\n";
  if (c.energy_norm) out << "E_n = " << *c.energy_norm << "  (|u' - u| / |u|)\n";
  if (c.interior_error)
    out << "E_i = " << *c.interior_error
        << "  (surface nodes weighted by |S_i| of M0: a surface mesh has no interior nodes)\n";
  if (!c.energy_norm) out << "E_n, E_i: need the undeformed mesh (--reference M0)\n";
  if (c.distances) {
    const fit::DistanceStatistics& d = *c.distances;
    out << "distance from M' to M: mean " << d.mean << ", rms " << d.rms << ", sd "
        << d.standard_deviation << " (" << 100.0 * d.share(d.standard_deviation)
        << "% of M's length " << d.length << "), largest " << d.largest << "\n";
  }
  return out.str();
}

nlohmann::json comparison_json(const Comparison& c) {
  nlohmann::json j = {
      {"reference", c.reference},
      {"approximation", c.approximation},
      {"dim", c.dim},
      {"reference_measure",
       c.reference_measure ? nlohmann::json(*c.reference_measure) : nlohmann::json()},
      {"symmetric_difference",
       c.symmetric_difference ? nlohmann::json(*c.symmetric_difference) : nlohmann::json()},
      {"E_s", c.surface_error ? nlohmann::json(*c.surface_error) : nlohmann::json()}};
  if (!c.surface_error) j["E_s_missing"] = c.surface_error_missing;
  if (!c.undeformed.empty()) j["undeformed"] = c.undeformed;
  if (c.energy_norm) j["E_n"] = *c.energy_norm;
  if (c.interior_error) {
    j["E_i"] = *c.interior_error;
    j["E_i_nodes"] = "surface nodes weighted by |S_i| of the undeformed mesh";
  }
  if (c.distances) {
    const fit::DistanceStatistics& d = *c.distances;
    j["distance"] = {{"count", d.count},
                     {"mean", d.mean},
                     {"rms", d.rms},
                     {"standard_deviation", d.standard_deviation},
                     {"largest", d.largest},
                     {"length", d.length},
                     {"standard_deviation_share", d.share(d.standard_deviation)}};
  }
  j["warnings"] = c.warnings;
  return j;
}

}  // namespace fiberfluid::experiment
