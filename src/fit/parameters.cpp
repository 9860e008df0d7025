// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fit/parameters.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "fiberfluid/model/equilibrium.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::fit {
namespace {

const char* const kAlignment[7] = {"rotation_x",    "rotation_y",    "rotation_z", "translation_x",
                                   "translation_y", "translation_z", "scale"};

std::string number(double x) {
  std::ostringstream out;
  out << x;
  return out.str();
}

}  // namespace

bool is_alignment_parameter(const std::string& name) {
  return std::find(std::begin(kAlignment), std::end(kAlignment), name) != std::end(kAlignment);
}

Parameter make_parameter(const ParameterRequest& request, const model::Material& material) {
  Parameter p;
  p.name = request.name;
  const bool alignment = is_alignment_parameter(p.name);
  if (!alignment && !material.has_parameter(p.name)) {
    std::string known;
    for (const std::string& n : material.parameter_names())
      known += (known.empty() ? "" : ", ") + n;
    throw InputError("\"" + p.name + "\" is not a parameter of this material (" + known +
                     ") or of the alignment (rotation_x..z, translation_x..z, scale)");
  }
  p.initial = request.start ? *request.start
              : alignment   ? (p.name == "scale" ? 1.0 : 0.0)
                            : material.parameter(p.name);
  if (request.lower) p.lower = *request.lower;
  if (request.upper) p.upper = *request.upper;
  p.log_scale = request.log_scale.value_or(log_scale_by_default(p.name, material));
  return p;
}

bool log_scale_by_default(const std::string& name, const model::Material& material) {
  if (is_alignment_parameter(name)) return name == "scale";
  return material.is_positive_parameter(name);
}

ParameterMap::ParameterMap(std::vector<Parameter> parameters, const model::Material& material,
                           int dim)
    : Variables(std::move(parameters)) {
  if (parameters_.empty()) throw InputError("nothing to fit: no parameter given");
  const std::vector<std::string> known = material.parameter_names(dim);
  for (size_t k = 0; k < parameters_.size(); ++k) {
    // A friction coefficient below 0 has no meaning: an open lower bound is 0.
    if (parameters_[k].name == "friction" && std::isinf(parameters_[k].lower))
      parameters_[k].lower = 0.0;
    const Parameter& p = parameters_[k];
    const std::string who = "parameter \"" + p.name + "\"";
    for (size_t j = 0; j < k; ++j)
      if (parameters_[j].name == p.name) throw InputError(who + " is given twice");
    if (is_alignment_parameter(p.name)) {
      const int a = static_cast<int>(
          std::find(std::begin(kAlignment), std::end(kAlignment), p.name) - std::begin(kAlignment));
      alignment_index_[a] = static_cast<int>(k);
      has_alignment_ = true;
    } else if (std::find(known.begin(), known.end(), p.name) != known.end()) {
      material_names_.push_back(p.name);
      material_parameters_.push_back(material.resolve(p.name, dim));
      material_indices_.push_back(static_cast<int>(k));
    } else {
      std::string list;
      for (const std::string& n : known) list += (list.empty() ? "" : ", ") + n;
      throw InputError(who +
                       " is not a parameter of this material or of the alignment "
                       "(expected one of " +
                       list + ", rotation_x..z, translation_x..z)");
    }
    if (!std::isfinite(p.initial)) throw InputError(who + ": the start is not finite");
    if (p.name == "friction" && p.lower < 0.0)
      throw InputError(who + ": expected a lower bound of at least 0, got " + number(p.lower));
    if (std::isnan(p.lower) || std::isnan(p.upper) || (std::isinf(p.lower) && p.lower > 0) ||
        (std::isinf(p.upper) && p.upper < 0))
      throw InputError(who + ": expected numbers for the bounds, got [" + number(p.lower) + ", " +
                       number(p.upper) + "]");
    if (!(p.lower < p.upper))
      throw InputError(who + ": expected a lower bound below the upper one, got [" +
                       number(p.lower) + ", " + number(p.upper) +
                       "] (to hold a parameter at a "
                       "value, leave it out of the fit and set it in the material)");
    if (p.initial < p.lower || p.initial > p.upper)
      throw InputError(who + ": the start " + number(p.initial) + " lies outside the bounds [" +
                       number(p.lower) + ", " + number(p.upper) + "]");
    if (p.log_scale && (!(p.initial > 0.0) || (std::isfinite(p.lower) && p.lower < 0.0)))
      throw InputError(who +
                       ": fitted in log scale, so its start must be positive and its lower "
                       "bound at least 0 (or set log_scale false)");
  }
}

std::vector<std::string> Variables::names() const {
  std::vector<std::string> out;
  for (const Parameter& p : parameters_) out.push_back(p.name);
  return out;
}

Eigen::VectorXd Variables::initial_phi() const {
  Eigen::VectorXd phi(size());
  for (int k = 0; k < size(); ++k) {
    const Parameter& p = parameters_[static_cast<size_t>(k)];
    phi[k] = p.to_phi(p.initial);
  }
  return phi;
}

Eigen::VectorXd Variables::lower_phi() const {
  Eigen::VectorXd phi(size());
  for (int k = 0; k < size(); ++k) {
    const Parameter& p = parameters_[static_cast<size_t>(k)];
    phi[k] = p.log_scale && !(p.lower > 0.0) ? -HUGE_VAL : p.to_phi(p.lower);
  }
  return phi;
}

Eigen::VectorXd Variables::upper_phi() const {
  Eigen::VectorXd phi(size());
  for (int k = 0; k < size(); ++k) {
    const Parameter& p = parameters_[static_cast<size_t>(k)];
    phi[k] = p.to_phi(p.upper);
  }
  return phi;
}

Eigen::VectorXd Variables::values(const Eigen::VectorXd& phi) const {
  Eigen::VectorXd v(size());
  for (int k = 0; k < size(); ++k) v[k] = parameters_[static_cast<size_t>(k)].to_value(phi[k]);
  return v;
}

Eigen::VectorXd Variables::value_derivatives(const Eigen::VectorXd& phi) const {
  Eigen::VectorXd d(size());
  for (int k = 0; k < size(); ++k)
    d[k] = parameters_[static_cast<size_t>(k)].value_derivative(phi[k]);
  return d;
}

model::Material ParameterMap::material(const model::Material& base,
                                       const Eigen::VectorXd& values) const {
  model::Material m = base;
  for (size_t j = 0; j < material_parameters_.size(); ++j)
    m.set_parameter(material_parameters_[j], values[material_indices_[j]]);
  return m;
}

void ParameterMap::alignment(const Eigen::VectorXd& values, Eigen::Vector3d* rotation,
                             Eigen::Vector3d* translation, double* scale) const {
  for (int a = 0; a < 3; ++a) {
    (*rotation)[a] = alignment_index_[a] >= 0 ? values[alignment_index_[a]] : 0.0;
    (*translation)[a] = alignment_index_[3 + a] >= 0 ? values[alignment_index_[3 + a]] : 0.0;
  }
  *scale = alignment_index_[6] >= 0 ? values[alignment_index_[6]] : 1.0;
}

bool on_bound(double phi, double lower, double upper) {
  const double range = std::isfinite(upper - lower) ? upper - lower : std::max(1.0, std::abs(phi));
  const double tolerance = 1e-6 * range;
  return (std::isfinite(lower) && phi - lower <= tolerance) ||
         (std::isfinite(upper) && upper - phi <= tolerance);
}

}  // namespace fiberfluid::fit
