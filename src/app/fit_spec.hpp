// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "app/case_spec.hpp"
#include "fit/calibration.hpp"

namespace fiberfluid::app {

// The "fit" section of an experiment file, as parsed (no file opened yet).
struct FitTargetSpec {
  FieldName field;
  std::filesystem::path file;
  int step = 0;  // the load step it was measured at; 0: the last
};

struct FitParameterSpec {
  FieldName field;
  std::string name;
  std::optional<double> start;  // default: the material's value (0 for the alignment)
  std::optional<double> lower, upper;
  std::optional<bool> log_scale;  // default: fit::log_scale_by_default(name)
};

struct FitSpec {
  FieldName field;
  std::vector<FitTargetSpec> targets;
  std::vector<FitParameterSpec> parameters;
  fit::FitOptions options;                // all but counted_vertices and progress
  std::optional<SelectionSpec> exclude;   // vertices whose distances do not count
};

}  // namespace fiberfluid::app
