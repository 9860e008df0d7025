// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Fit target kinds beyond the two that fit::Calibration takes itself (a
// scanned surface and a force curve): each kind is one file in this folder,
// holding its fields' reader and its residual block (fit/residuals/
// residual_block.hpp), and one line in target_kinds.cpp's list. The reader
// reads a target's "type" against this list, the schema shows each kind's
// fields (they are read through Fields), and setup_fit hands each target's
// block maker to the calibration. docs/architecture.md: "A fit target kind".

#include <filesystem>
#include <string>
#include <vector>

#include "fiberfluid/experiment/spec/fit_spec.hpp"

namespace fiberfluid::experiment {

class Fields;

struct TargetKind {
  const char* type;  // the target's "type" in fit.targets[]
  // Reads the target's other fields (relative files from `folder`); throws
  // InputError naming the field. Opens no file: what needs the mesh is
  // resolved when the spec is bound to the built case (FitKindTargetSpec::bind).
  FitKindTargetSpec (*read)(Fields& target, const std::filesystem::path& folder);
};

// The registered kinds, in the order a reader's message lists them.
const std::vector<TargetKind>& target_kinds();

}  // namespace fiberfluid::experiment
