// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// `fiberfluid compare`: the benchmarks paper's metrics and the calibration's
// distance statistics between two deformed surfaces.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "fiberfluid/fit/target.hpp"
#include "fiberfluid/geom/surface.hpp"

namespace fiberfluid::experiment {

struct Comparison {
  std::string reference, approximation, undeformed;  // the files ("" : no undeformed mesh)
  int dim = 3;
  // E_s needs two closed solids: in 3D, a scan that is a triangle soup or a
  // point cloud still gets the distances, and E_s says why it is missing.
  std::optional<double> reference_measure;     // |Int(M)|: area (2D) or volume (3D)
  std::optional<double> symmetric_difference;  // |Int(M) xor Int(M')|
  std::optional<double> surface_error;         // E_s
  std::string surface_error_missing;           // why E_s is not there
  // With the undeformed mesh and the same vertices in all three:
  std::optional<double> energy_norm;     // E_n
  std::optional<double> interior_error;  // E_i, over the surface nodes weighted by |S_i|
  // 3D: each vertex of M' to the surface of M.
  std::optional<fit::DistanceStatistics> distances;
  // Sizes that differ by more than kScaleMismatch (the bounding boxes'
  // diagonals): likely another unit (a scan in mm, a model in m).
  std::vector<std::string> warnings;
};

// Two surfaces whose sizes differ by more than this factor are warned about.
constexpr double kScaleMismatch = 3.0;

// Compares two surfaces (M the reference, M' the approximation; M0 the
// undeformed one, optional). The labels name them in errors. In 3D, M and M'
// may be triangle soups or point clouds (M' a point cloud, M triangles or
// points): then only the distances are computed.
Comparison compare_surfaces(const geom::Surface& reference, const geom::Surface& approximation,
                            const geom::Surface* undeformed, const std::string& reference_label,
                            const std::string& approximation_label,
                            const std::string& undeformed_label = "");

// The same on files (any format read_surface reads). Throws InputError
// naming the file.
Comparison compare_files(const std::filesystem::path& reference,
                         const std::filesystem::path& approximation,
                         const std::optional<std::filesystem::path>& undeformed);

std::string comparison_text(const Comparison& c);
nlohmann::json comparison_json(const Comparison& c);

}  // namespace fiberfluid::experiment
