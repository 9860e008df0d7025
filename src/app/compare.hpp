// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// `fiberfluid compare`: the benchmarks paper's metrics and the calibration's
// distance statistics between two deformed surfaces.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "fit/target.hpp"
#include "geom/surface.hpp"

namespace fiberfluid::app {

struct Comparison {
  std::string reference, approximation, undeformed;  // the files ("" : no undeformed mesh)
  int dim = 3;
  double reference_measure = 0.0;       // |Int(M)|: area (2D) or volume (3D)
  double symmetric_difference = 0.0;    // |Int(M) xor Int(M')|
  double surface_error = 0.0;           // E_s
  // With the undeformed mesh and the same vertices in all three:
  std::optional<double> energy_norm;    // E_n
  std::optional<double> interior_error; // E_i, over the surface nodes weighted by |S_i|
  // 3D: each vertex of M' to the surface of M.
  std::optional<fit::DistanceStatistics> distances;
};

// Compares two surfaces (M the reference, M' the approximation; M0 the
// undeformed one, optional). The labels name them in errors.
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

}  // namespace fiberfluid::app
