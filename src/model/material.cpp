// SPDX-License-Identifier: GPL-3.0-or-later
#include <algorithm>
#include <stdexcept>

#include "fiberfluid/model/model.hpp"

namespace fiberfluid::model {

std::vector<std::string> Material::parameter_names(int dim) const {
  std::vector<std::string> names = law.parameter_names();
  names.push_back("gamma");
  for (int a = 0; a < dim; ++a) names.push_back(std::string("factor_") + "xyz"[a]);
  names.push_back("friction");
  return names;
}

MaterialParameter Material::resolve(const std::string& name, int dim) const {
  const std::vector<std::string>& law_names = law.parameter_names();
  const auto in_law = std::find(law_names.begin(), law_names.end(), name);
  if (in_law != law_names.end())
    return {MaterialParameter::Kind::Law, static_cast<int>(in_law - law_names.begin())};
  if (name == "gamma") return {MaterialParameter::Kind::SurfaceTension, 0};
  for (int a = 0; a < dim; ++a)
    if (name == std::string("factor_") + "xyz"[a]) return {MaterialParameter::Kind::AxisFactor, a};
  if (name == "friction") return {MaterialParameter::Kind::Friction, 0};
  std::string known;
  for (const std::string& n : parameter_names(dim)) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("\"" + name + "\" is not a parameter of this material (" + known +
                              ")");
}

bool Material::has_parameter(const std::string& name, int dim) const {
  const std::vector<std::string> names = parameter_names(dim);
  return std::find(names.begin(), names.end(), name) != names.end();
}

double Material::parameter(const MaterialParameter& p) const {
  switch (p.kind) {
    case MaterialParameter::Kind::Law:
      return law.parameters()[static_cast<size_t>(p.index)];
    case MaterialParameter::Kind::SurfaceTension:
      return surface_tension;
    case MaterialParameter::Kind::AxisFactor:
      return axis_factors[p.index];
    case MaterialParameter::Kind::Friction:
      return friction;
  }
  return 0.0;
}

void Material::set_parameter(const MaterialParameter& p, double value) {
  switch (p.kind) {
    case MaterialParameter::Kind::Law:
      law.set_parameter(law.parameter_names()[static_cast<size_t>(p.index)], value);
      return;
    case MaterialParameter::Kind::SurfaceTension:
      surface_tension = value;
      return;
    case MaterialParameter::Kind::AxisFactor:
      axis_factors[p.index] = value;
      return;
    case MaterialParameter::Kind::Friction:
      friction = value;
      return;
  }
}

bool Material::is_positive_parameter(const std::string& name) const {
  const MaterialParameter p = resolve(name);
  // Friction is fitted in its own units: 0 (frictionless) is a value it takes.
  if (p.kind == MaterialParameter::Kind::Friction) return false;
  return p.kind != MaterialParameter::Kind::Law || law.model().is_positive(p.index);
}

}  // namespace fiberfluid::model
