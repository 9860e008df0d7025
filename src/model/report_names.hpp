// SPDX-License-Identifier: GPL-3.0-or-later
// The names a model's parts are reported by (summary.json, CSV headers, the
// Python module): an axis's letter and a support group's name.
#pragma once

#include <string>

#include "fiberfluid/model/model.hpp"

namespace fiberfluid::model {

// 'x', 'y' or 'z' for axis 0, 1, 2.
inline char axis_name(int axis) { return "xyz"[axis]; }

// Support group g's name (Model::constraint_groups: one per experiment
// entry); "supports" for the one group of a model built without names.
inline std::string constraint_group_name(const Model& model, size_t g) {
  return g < model.constraint_groups.size() ? model.constraint_groups[g] : "supports";
}

}  // namespace fiberfluid::model
