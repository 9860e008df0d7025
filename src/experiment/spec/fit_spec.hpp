// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "fiberfluid/experiment/spec/case_spec.hpp"
#include "fiberfluid/fit/calibration.hpp"
#include "fiberfluid/fit/force_curve.hpp"
#include "fiberfluid/fit/multistart.hpp"

namespace fiberfluid::experiment {

// The "fit" section of an experiment file, as parsed (no file opened yet).
struct FitTargetSpec {
  FieldName field;
  std::filesystem::path file;
  int step = 0;        // the load step it was measured at; 0: the last
  double scale = 1.0;  // the scan's coordinates times this are in m ("units": "mm" is 1e-3)
};

// A measured force curve (a target of "type": "force"), as parsed.
struct FitForceSpec {
  FieldName field;
  std::filesystem::path file;
  std::string paddle, support;     // the label of one of them
  int axis = -1;                   // a support's force component (0, 1, 2); -1 for a paddle
  double weight = 0.0;             // m per N; 0: the default (fit::ForceCurve::weight)
  fit::ForceCurveColumns columns;  // which of the file's columns and rows, in which units
  bool relative = false;           // "misfit": "relative" (each row's share) or "newtons"
};

// A target of a registered kind (experiment/targets/target_kinds.hpp), as
// parsed: its reader's fields, bound to the built case when the fit is set
// up (bind: its vertices resolved, its step checked; `index` its place among
// the fit's targets of other kinds), which gives the block's maker.
struct FitKindTargetSpec {
  FieldName field;
  std::string kind;  // its "type"
  std::function<fit::BlockMaker(const Case& c, size_t index)> bind;
};

struct FitParameterSpec {
  FieldName field;
  fit::ParameterRequest request;
};

struct FitSpec {
  FieldName field;
  std::vector<FitTargetSpec> targets;           // surfaces
  std::vector<FitForceSpec> force_curves;       // and force curves
  std::vector<FitKindTargetSpec> kind_targets;  // and targets of other kinds (not all empty)
  std::vector<FitParameterSpec> parameters;
  // A fit.json whose parameters' values are the starts (an interrupted or
  // earlier fit, continued).
  std::optional<std::filesystem::path> start_from;
  fit::FitOptions options;  // all but counted_vertices and progress
  // "method": "multistart": Levenberg-Marquardt (options.method) from each of
  // several starts spread over the bounds.
  std::optional<fit::MultistartOptions> multistart;
  std::optional<SelectionSpec> exclude;  // vertices whose distances do not count
  // "coarser" or "finer": the fit is repeated on the surface refined by 1/1.5
  // or 1.5 (1/2 or 2 for subdivisions), from the fitted values, and each
  // parameter's shift reported as its mesh uncertainty. "none": not.
  std::string mesh_check = "none";
};

}  // namespace fiberfluid::experiment
