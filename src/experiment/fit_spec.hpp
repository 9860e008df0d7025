// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "experiment/case_spec.hpp"
#include "fit/calibration.hpp"

namespace fiberfluid::experiment {

// The "fit" section of an experiment file, as parsed (no file opened yet).
struct FitTargetSpec {
  FieldName field;
  std::filesystem::path file;
  int step = 0;        // the load step it was measured at; 0: the last
  double scale = 1.0;  // the scan's coordinates times this are in m ("units": "mm" is 1e-3)
};

struct FitParameterSpec {
  FieldName field;
  fit::ParameterRequest request;
};

struct FitSpec {
  FieldName field;
  std::vector<FitTargetSpec> targets;
  std::vector<FitParameterSpec> parameters;
  // A fit.json whose parameters' values are the starts (an interrupted or
  // earlier fit, continued).
  std::optional<std::filesystem::path> start_from;
  fit::FitOptions options;               // all but counted_vertices and progress
  std::optional<SelectionSpec> exclude;  // vertices whose distances do not count
};

}  // namespace fiberfluid::experiment
