// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/model/boundary_conditions.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <regex>
#include <set>

#include "fiberfluid/util/error.hpp"

namespace fiberfluid::model {

HalfSpace parse_half_space(const std::string& text, int dim) {
  static const std::regex form(
      R"(^\s*([xyz])\s*(>=|<=|>|<)\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*$)");
  std::smatch match;
  if (!std::regex_match(text, match, form))
    throw InputError("'" + text + "' is not a half-space: expected e.g. \"z >= 0.8\"");
  HalfSpace h;
  h.axis = match[1].str()[0] - 'x';
  if (h.axis >= dim)
    throw InputError("'" + text + "' uses axis " + match[1].str() + " in a " + std::to_string(dim) +
                     "D problem");
  const std::string op = match[2].str();
  h.greater = op[0] == '>';
  h.inclusive = op.size() == 2;
  // strtod, not stod: a threshold beyond a double (1e999) is an input error, not an exception.
  h.threshold = std::strtod(match[3].str().c_str(), nullptr);
  if (!std::isfinite(h.threshold))
    throw InputError("'" + text + "': the threshold " + match[3].str() +
                     " is beyond a double's range");
  return h;
}

std::vector<int> select_half_space(const Eigen::MatrixXd& X, const HalfSpace& h) {
  std::vector<int> selected;
  for (int i = 0; i < X.rows(); ++i) {
    const double c = X(i, h.axis);
    const bool inside = h.greater ? (h.inclusive ? c >= h.threshold : c > h.threshold)
                                  : (h.inclusive ? c <= h.threshold : c < h.threshold);
    if (inside) selected.push_back(i);
  }
  return selected;
}

std::vector<int> select_box(const Eigen::MatrixXd& X, const Eigen::VectorXd& min,
                            const Eigen::VectorXd& max) {
  std::vector<int> selected;
  for (int i = 0; i < X.rows(); ++i) {
    const Eigen::VectorXd p = X.row(i).transpose();
    if ((p.array() >= min.array()).all() && (p.array() <= max.array()).all()) selected.push_back(i);
  }
  return selected;
}

Status check_not_singular(const Model& model) {
  if (model.constraints.empty())
    return Status::failure(
        "no supports: nothing holds the body, so rigid motion makes the system singular; "
        "fix some vertices");
  std::set<int> held;
  for (const Constraint& c : model.constraints) held.insert(model.dof(c.vertex, c.axis));
  if (static_cast<int>(held.size()) == model.dim() * model.num_vertices())
    return Status::failure(
        "the supports fix every vertex on every axis: nothing is left free to deform "
        "(select fewer vertices)");
  const char* names = "xyz";
  for (int a = 0; a < model.dim(); ++a) {
    const bool held = std::any_of(model.constraints.begin(), model.constraints.end(),
                                  [a](const Constraint& c) { return c.axis == a; }) ||
                      std::any_of(model.paddles.begin(), model.paddles.end(), [&](const Paddle& p) {
                        return p.axis == a && !touching_at_start(model, p).empty();
                      });
    if (!held)
      return Status::failure(std::string("no support along ") + names[a] +
                             ": the body can translate along " + names[a] +
                             ", so the system is singular (a support, or a paddle on " + names[a] +
                             " touching the body at its start, holds it)");
    // Zero stiffness is singular; a negative one is left to the solvers,
    // which report a matrix that is not positive definite.
    // A tension at rest stiffens every fiber across its length (T0 / L).
    if (model.material.young_modulus()[a] == 0.0 && model.material.surface_tension == 0.0 &&
        model.material.law.rest_tension() == 0.0)
      return Status::failure(std::string("no stiffness along ") + names[a] +
                             ": Y, gamma and the fibers' rest tension are all zero, so the "
                             "system is singular");
  }
  return {};
}

std::vector<int> touching_at_start(const Model& model, const Paddle& paddle) {
  const Eigen::MatrixXd& V = model.surface.V;
  if (paddle.axis < 0 || paddle.axis >= model.dim() || V.rows() == 0) return {};
  const double diagonal = (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm();
  std::vector<int> touching;
  for (int v = 0; v < V.rows(); ++v)
    if (std::abs(paddle.penetration(V(v, paddle.axis), paddle.position)) <= 1e-9 * diagonal)
      touching.push_back(v);
  return touching;
}

Eigen::Vector3d RigidMotion::displacement(const Eigen::Vector3d& s, double factor) const {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(factor * angle, axis).toRotationMatrix();
  return R * (s - centre) + centre + factor * translation - s;
}

double held_value(const Model& model, const Constraint& c, int step, int steps) {
  const double factor = c.schedule.factor(step, steps);
  if (c.motion < 0) return c.value * factor;
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  s.head(model.dim()) = model.surface.V.row(c.vertex).transpose();
  return model.motions.at(static_cast<size_t>(c.motion)).displacement(s, factor)[c.axis];
}

DofPartition partition_dofs(const Model& model) {
  std::map<int, int> constraint_at;  // unknown -> constraint index
  for (size_t c = 0; c < model.constraints.size(); ++c) {
    const Constraint& constraint = model.constraints[c];
    const int d = model.dof(constraint.vertex, constraint.axis);
    auto [it, inserted] = constraint_at.emplace(d, static_cast<int>(c));
    if (inserted) continue;
    const Constraint& other = model.constraints[static_cast<size_t>(it->second)];
    if (other.value != constraint.value || other.motion != constraint.motion ||
        other.schedule.kind != constraint.schedule.kind)
      throw InputError("vertex " + std::to_string(constraint.vertex) + " axis " +
                       std::string(1, "xyz"[constraint.axis]) +
                       " is given two different prescribed displacements");
  }
  DofPartition p;
  for (int d = 0; d < model.num_unknowns(); ++d) {
    auto it = constraint_at.find(d);
    if (it == constraint_at.end()) {
      p.free.push_back(d);
    } else {
      p.constrained.push_back(d);
      p.constraint_of.push_back(it->second);
    }
  }
  return p;
}

}  // namespace fiberfluid::model
