// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fiberfluid/model/model.hpp"
#include "fiberfluid/util/names.hpp"
#include "fiberfluid/util/status.hpp"

namespace fiberfluid::model {

enum class BoundaryMethod {
  Elimination,  // fixed unknowns removed from the system (default)
  Penalty,      // the paper's: the diagonal entry replaced by a large number
};
inline constexpr auto kBoundaryMethodNames = names_of<BoundaryMethod>(
    {{BoundaryMethod::Elimination, "elimination"}, {BoundaryMethod::Penalty, "penalty"}});
inline const char* to_string(BoundaryMethod method) { return kBoundaryMethodNames.name(method); }

// ---------------------------------------------------------------- selection
// A half-space written as "z >= 0.8", "x < 0", "y<=1.5".
struct HalfSpace {
  int axis = 0;
  bool greater = true;    // >= (or >) versus <= (or <)
  bool inclusive = true;  // >= or <= versus > or <
  double threshold = 0.0;
};
// Throws InputError quoting `text` when it is not of that form.
HalfSpace parse_half_space(const std::string& text, int dim);

// Vertices of X (#V by dim) in the half-space, or in the closed box.
std::vector<int> select_half_space(const Eigen::MatrixXd& X, const HalfSpace& half_space);
std::vector<int> select_box(const Eigen::MatrixXd& X, const Eigen::VectorXd& min,
                            const Eigen::VectorXd& max);

// The displacement a constraint holds its unknown at after step `step` of
// `steps`: its value times its schedule's factor, or its rigid motion's.
double held_value(const Model& model, const Constraint& constraint, int step, int steps);

// ---------------------------------------------------------------- checking
// Whether the constraints remove rigid motion; if not, the message says why
// the system is singular (e.g. no axis-x constraint: the body can translate along x).
// A paddle on an axis that no support holds counts when it touches the body
// at its start: its contact then holds the body along its axis from the
// first iterate (a body resting on a floor).
Status check_not_singular(const Model& model);

// The vertices a paddle touches before the first step: on its starting
// plane, within a billionth of the body's diagonal.
std::vector<int> touching_at_start(const Model& model, const Paddle& paddle);

// ---------------------------------------------------------------- reduction
// The constrained and free unknowns of the paper's layout (P is always free).
// Throws InputError when one unknown is given two different displacements.
struct DofPartition {
  std::vector<int> free;           // ascending
  std::vector<int> constrained;    // ascending
  std::vector<int> constraint_of;  // per constrained unknown: an index into model.constraints
};
DofPartition partition_dofs(const Model& model);

}  // namespace fiberfluid::model
