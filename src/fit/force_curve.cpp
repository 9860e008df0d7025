// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fit/force_curve.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "fiberfluid/model/fiber_system.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::fit {
namespace {

std::string trimmed(const std::string& text) {
  const size_t first = text.find_first_not_of(" \t\r");
  if (first == std::string::npos) return {};
  return text.substr(first, text.find_last_not_of(" \t\r") - first + 1);
}

std::vector<std::string> cells(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream in(line);
  std::string cell;
  while (std::getline(in, cell, ',')) out.push_back(trimmed(cell));
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

}  // namespace

ForceCurve read_force_curve(const std::filesystem::path& path, const ForceCurveColumns& wanted) {
  const std::string file = path.string();
  std::ifstream in(path);
  if (!in) throw InputError(file + ": cannot open (expected a CSV force curve)");
  ForceCurve curve;
  curve.label = file;
  std::string line;
  int number = 0, force_column = -1, at_column = -1, sd_column = -1;
  size_t columns = 0, rows_read = 0;
  while (std::getline(in, line)) {
    ++number;
    const std::string text = trimmed(line);
    if (text.empty() || text[0] == '#') continue;
    const std::vector<std::string> row = cells(text);
    if (force_column < 0) {  // the header
      int travel_column = -1, step_column = -1;
      for (size_t c = 0; c < row.size(); ++c) {
        const int column = static_cast<int>(c);
        // A column named twice: which one is the force? (issue 43: a file means one thing)
        for (size_t earlier = 0; earlier < c; ++earlier)
          if (!row[c].empty() && row[earlier] == row[c])
            throw InputError(file + ": line " + std::to_string(number) + ": the header names \"" +
                             row[c].substr(0, 40) + "\" twice (columns " +
                             std::to_string(earlier + 1) + " and " + std::to_string(c + 1) +
                             "): expected each column once");
        if (row[c] == wanted.force) force_column = column;
        if (row[c] == wanted.travel) travel_column = column;
        if (row[c] == wanted.step) step_column = column;
        if (!wanted.sd.empty() && row[c] == wanted.sd) sd_column = column;
      }
      curve.by_step = wanted.rows_at == "step" || (wanted.rows_at.empty() && travel_column < 0);
      at_column = curve.by_step ? step_column : travel_column;
      const std::string at_name = wanted.rows_at == "step" ? wanted.step
                                  : wanted.rows_at == "travel"
                                      ? wanted.travel
                                      : wanted.travel + " or " + wanted.step;
      if (force_column < 0 || at_column < 0 || (!wanted.sd.empty() && sd_column < 0))
        throw InputError(
            file + ": line " + std::to_string(number) + ": expected a header with " +
            "the columns " + wanted.force +
            (wanted.sd.empty() ? " and " + at_name : ", " + at_name + ", and " + wanted.sd) +
            ", got \"" + text.substr(0, 80) + "\"");
      columns = row.size();
      continue;
    }
    if (row.size() != columns)
      throw InputError(file + ": line " + std::to_string(number) + ": expected " +
                       std::to_string(columns) + " values as in the header, got " +
                       std::to_string(row.size()));
    ++rows_read;
    double values[3] = {0.0, 0.0, 0.0};
    const int read[3] = {at_column, force_column, sd_column};
    for (int k = 0; k < 3; ++k) {
      if (read[k] < 0) continue;
      const std::string& cell = row[static_cast<size_t>(read[k])];
      char* end = nullptr;
      errno = 0;
      values[k] = std::strtod(cell.c_str(), &end);
      if (cell.empty() || end != cell.c_str() + cell.size() || errno == ERANGE ||
          !std::isfinite(values[k]) || (k == 2 && values[k] < 0.0))
        throw InputError(file + ": line " + std::to_string(number) + ": expected a finite " +
                         (k == 2 ? "scatter of 0 or more" : "number") + " in column " +
                         std::to_string(read[k] + 1) + ", got \"" + cell.substr(0, 40) + "\"");
    }
    if (curve.by_step && (values[0] < 1 || values[0] > 1e6 || values[0] != std::floor(values[0])))
      throw InputError(file + ": line " + std::to_string(number) +
                       ": expected a load step (a whole number from 1), got " +
                       row[static_cast<size_t>(at_column)]);
    if (!(values[0] >= wanted.from && values[0] <= wanted.to)) continue;
    curve.at.push_back(curve.by_step ? values[0] : values[0] * wanted.travel_scale);
    curve.force.push_back(values[1] * wanted.force_scale);
    if (sd_column >= 0) curve.sd.push_back(values[2] * wanted.force_scale);
  }
  if (force_column < 0)
    throw InputError(file + ": empty (expected a CSV force curve with a header)");
  if (rows_read == 0) throw InputError(file + ": a header but no rows: nothing to fit");
  if (curve.force.empty()) {
    std::ostringstream why;
    why << file << ": no row has its " << (curve.by_step ? wanted.step : wanted.travel)
        << " between " << wanted.from << " and " << wanted.to
        << " (the range asked): nothing to fit";
    throw InputError(why.str());
  }
  for (const double f : curve.force)
    if (!std::isfinite(f)) throw InputError(file + ": a force is not finite after scaling");
  for (const double t : curve.at)
    if (!std::isfinite(t)) throw InputError(file + ": a travel is not finite after scaling");
  return curve;
}

double largest_measured(const ForceCurve& curve) {
  double largest = 0.0;
  for (const double f : curve.force) largest = std::max(largest, std::abs(f));
  return largest;
}

std::vector<double> row_weights(const ForceCurve& curve, double weight) {
  std::vector<double> weights(curve.force.size(), weight);
  if (!curve.relative) return weights;
  const double largest = largest_measured(curve);
  for (size_t r = 0; r < curve.force.size(); ++r) {
    if (curve.force[r] == 0.0)
      throw InputError(curve.label + ": row " + std::to_string(r + 1) +
                       ": a measured force of 0 has no relative misfit (misfit: relative); "
                       "leave the row out (range) or weigh in newtons");
    weights[r] = weight * largest / std::abs(curve.force[r]);
  }
  return weights;
}

double curve_force(const ForceCurve& curve, const model::Model& model,
                   const Eigen::Vector3d& force) {
  if (curve.source == ForceCurve::Source::Support) return force[curve.axis];
  const model::Paddle& paddle = model.paddles[static_cast<size_t>(curve.index)];
  return paddle.above ? -force[paddle.axis] : force[paddle.axis];  // its push into the body
}

double curve_travel(const ForceCurve& curve, const model::Model& model, int step, int steps) {
  if (curve.source == ForceCurve::Source::Paddle) {
    const model::Paddle& paddle = model.paddles[static_cast<size_t>(curve.index)];
    return std::abs(paddle.schedule.factor(step, steps) * paddle.travel);
  }
  const Eigen::VectorXd held = model::constrained_displacements(model, step, steps);
  const int n = model.num_vertices();
  double sum = 0.0;
  int count = 0;
  for (const model::Constraint& c : model.constraints)
    if (c.group == curve.index && c.axis == curve.axis) {
      sum += held[c.axis * n + c.vertex];
      ++count;
    }
  return count > 0 ? sum / count : 0.0;
}

Status check_force_curve(const ForceCurve& curve, const model::Model& model) {
  if (curve.at.size() != curve.force.size() || curve.force.empty())
    return Status::failure("expected as many travels (or steps) as forces, and at least one");
  if (!(curve.weight >= 0.0) || !std::isfinite(curve.weight))
    return Status::failure("weight: expected a finite weight of 0 or more (m per N)");
  if (curve.source == ForceCurve::Source::Paddle) {
    if (curve.index < 0 || curve.index >= static_cast<int>(model.paddles.size()))
      return Status::failure("paddle " + std::to_string(curve.index) +
                             " does not exist (the model has " +
                             std::to_string(model.paddles.size()) + ")");
    return {};
  }
  if (curve.index < 0 || curve.index >= static_cast<int>(model.constraint_groups.size()))
    return Status::failure("support group " + std::to_string(curve.index) +
                           " does not exist (the model has " +
                           std::to_string(model.constraint_groups.size()) + ")");
  if (curve.axis < 0 || curve.axis >= model.dim())
    return Status::failure("axis " + std::to_string(curve.axis) + " is not one of the model's");
  bool held = false;
  for (const model::Constraint& c : model.constraints)
    held = held || (c.group == curve.index && c.axis == curve.axis);
  const std::string& group = model.constraint_groups[static_cast<size_t>(curve.index)];
  if (!held)
    return Status::failure("support " + group + " holds no vertex along axis " +
                           std::string(1, "xyz"[curve.axis]) + ": it has no reaction there");
  for (const model::MirrorLayer& layer : model.mirror_layers)
    if (layer.group == curve.index)
      return Status::failure(
          "support " + group +
          " has a mirror layer, whose fibers carry part of its reaction: its force curve "
          "cannot be fitted (fit a paddle's, or the support without the layer)");
  return {};
}

}  // namespace fiberfluid::fit
