// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// A measured force curve as a fit target: the force a paddle (or a support
// group) exerts on the body, against its travel or at load steps. The most
// common measurement of a compression or indentation test; with a surface
// scan it also fixes the scale that shapes alone cannot (under paddles
// alone a modulus and the surface tension act only through their ratio).

#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "fiberfluid/model/model.hpp"
#include "fiberfluid/util/status.hpp"

namespace fiberfluid::fit {

struct ForceCurve {
  std::string label;  // for messages: the file, or a name given by the program
  enum class Source {
    Paddle,   // Model::paddles[index]: its push on the body along its axis (positive)
    Support,  // Model::constraint_groups[index]: its reaction's component `axis`
  };
  Source source = Source::Paddle;
  int index = 0;
  int axis = 0;  // Support: 0, 1, 2 = x, y, z (a paddle's is its own)
  // Rows at load steps (1..steps), or at the travel: a paddle's distance
  // from its start, a support group's mean held displacement along `axis`
  // (m), interpolated linearly between the steps around it.
  bool by_step = false;
  std::vector<double> at;     // per row: the travel (m) or the step
  std::vector<double> force;  // per row (N)
  // Per row, the measurement's own scatter (N: the sd over repeat tests),
  // when the file has it; else empty. It weighs nothing: it tells whether the
  // misfit left is the data's noise or the model's form (ForceMisfit).
  std::vector<double> sd;
  // Misfits in newtons (the largest forces rule the fit) or each as a share
  // of its measured force (every part of the curve counts alike).
  bool relative = false;
  // How a force misfit counts against the surface distances: a misfit of
  // 1 N is a residual of `weight` m. 0: the body's length over the largest
  // measured force (a misfit of the whole force weighs as one body length).
  double weight = 0.0;
};

// How to read a curve's file: which columns, in which units, which rows.
struct ForceCurveColumns {
  std::string travel = "travel", step = "step", force = "force";
  std::string sd;  // the scatter's column, or none
  // "travel" or "step"; "": by travel when the file has that column, else by step.
  std::string rows_at;
  double travel_scale = 1.0, force_scale = 1.0;  // the file's units to m and N (mm: 1e-3)
  // Only the rows whose travel (or step), in the file's units, lies in
  // [from, to]: the part of a measured curve the fit sees.
  double from = -std::numeric_limits<double>::infinity();
  double to = std::numeric_limits<double>::infinity();
};

// Reads a curve from CSV: a header naming the columns (other columns are
// ignored); '#' starts a comment line. Throws InputError naming the file,
// and the line for a bad value, or the range when it holds no row.
ForceCurve read_force_curve(const std::filesystem::path& path,
                            const ForceCurveColumns& columns = {});

// The largest measured |force| (N).
double largest_measured(const ForceCurve& curve);

// Each row's weight (m per N) from the curve's `weight`: that weight, or for
// a relative misfit weight max|F| / |F_r| (a share of 1 weighs what the
// largest force's whole miss weighs in newtons). Throws InputError naming a
// row of zero force under a relative misfit.
std::vector<double> row_weights(const ForceCurve& curve, double weight);

// A curve's force at a step from the run's record, by the curve's
// convention: a paddle's push into the body, a support's reaction component.
double curve_force(const ForceCurve& curve, const model::Model& model,
                   const Eigen::Vector3d& paddle_or_reaction_force);

// The travel of the curve's paddle or support group after step k of n, by
// the schedules alone (it does not depend on the material).
double curve_travel(const ForceCurve& curve, const model::Model& model, int step, int steps);

// Whether the curve fits the model (its paddle or group exists, the axis is
// one of the model's, a mirror layer does not carry the group's reaction),
// and if not, why not.
Status check_force_curve(const ForceCurve& curve, const model::Model& model);

}  // namespace fiberfluid::fit
