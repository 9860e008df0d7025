// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/targets/target_kinds.hpp"

namespace fiberfluid::experiment {

// Each kind's reader, defined in its own file here.
FitKindTargetSpec read_marker_target(Fields& target, const std::filesystem::path& folder);
FitKindTargetSpec read_material_test_target(Fields& target, const std::filesystem::path& folder);

const std::vector<TargetKind>& target_kinds() {
  static const std::vector<TargetKind> kinds = {
      {"marker", read_marker_target},                // marker_target.cpp
      {"material_test", read_material_test_target},  // material_test_target.cpp
  };
  return kinds;
}

}  // namespace fiberfluid::experiment
