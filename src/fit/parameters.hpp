// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "fiberfluid/model/model.hpp"

namespace fiberfluid::fit {

// One fitted parameter: a material parameter by name (the law's: Y, Y0, beta,
// Y_t, Y_c, scale; "gamma"; "factor_x" / "factor_y" / "factor_z"), or one of
// the rigid alignment of the targets ("rotation_x/y/z", a rotation vector in
// radians, "translation_x/y/z" in m, and "scale", a uniform scale of the
// scans: they are rarely registered, and their units may be unsure).
struct Parameter {
  std::string name;
  double initial = 0.0;
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
  // Fitted as log(value): for positive parameters (moduli, gamma, factors)
  // whose scale is unknown; the bounds must then be positive too.
  bool log_scale = false;
  // A linear parameter is fitted as value / scale (1: in its own units).
  // A scale from the start's size was tried for issue 59's "scale linear
  // variables" and left at 1: it made Treloar's three-term Ogden fit end in
  // a worse valley (9.4% rms in 629 iterations against 5.7% in 217).
  double scale = 1.0;

  // The fitted variable phi of a value, and back: log(value) in log scale,
  // value / scale otherwise. Every conversion goes through these.
  double to_phi(double value) const { return log_scale ? std::log(value) : value / scale; }
  double to_value(double phi) const { return log_scale ? std::exp(phi) : phi * scale; }
  // d value / d phi at phi.
  double value_derivative(double phi) const { return log_scale ? std::exp(phi) : scale; }
};

bool is_alignment_parameter(const std::string& name);

// A fitted parameter as every front end (JSON, Python, C++) describes it:
// a name, and optionally a start (default: the material's value, 0 for the
// alignment), bounds and a log scale (default: log_scale_by_default).
// Throws InputError when the name is neither the material's nor the
// alignment's, listing both.
struct ParameterRequest {
  std::string name;
  std::optional<double> start, lower, upper;
  std::optional<bool> log_scale;
};
Parameter make_parameter(const ParameterRequest& request, const model::Material& material);
// The default for a parameter: log scale for a positive one (a modulus,
// gamma, a factor, the alignment's scale: Material::is_positive_parameter);
// linear for an exponent (beta) and the alignment's rotation and translation.
bool log_scale_by_default(const std::string& name, const model::Material& material);

// Whether a fitted variable phi lies on one of its bounds (in phi), to a
// millionth of its range (of max(1, |phi|) when a bound is infinite).
bool on_bound(double phi, double lower, double upper);

// The parameters as the optimiser's variables phi (log or linear) and back:
// what every fit (one body's, several specimens') needs of its parameters.
class Variables {
 public:
  explicit Variables(std::vector<Parameter> parameters) : parameters_(std::move(parameters)) {}

  int size() const { return static_cast<int>(parameters_.size()); }
  const std::vector<Parameter>& parameters() const { return parameters_; }
  std::vector<std::string> names() const;

  Eigen::VectorXd initial_phi() const;
  Eigen::VectorXd lower_phi() const;
  Eigen::VectorXd upper_phi() const;
  Eigen::VectorXd values(const Eigen::VectorXd& phi) const;
  // d value / d phi, per parameter (value for a log-scaled one, else 1).
  Eigen::VectorXd value_derivatives(const Eigen::VectorXd& phi) const;

 protected:
  std::vector<Parameter> parameters_;
};

// One body's fitted parameters: the variables, and what they set in the
// material and the alignment of its targets.
class ParameterMap : public Variables {
 public:
  // Throws InputError (naming the parameter) for an unknown name, a name
  // given twice, bounds that exclude the start, or a log-scaled parameter
  // that is not positive.
  ParameterMap(std::vector<Parameter> parameters, const model::Material& material, int dim);

  // The material parameters' names and their positions among all.
  const std::vector<std::string>& material_names() const { return material_names_; }
  const std::vector<int>& material_indices() const { return material_indices_; }
  bool has_alignment() const { return has_alignment_; }

  // The material with the parameters' values set.
  model::Material material(const model::Material& base, const Eigen::VectorXd& values) const;
  // The alignment T(p) = scale R(rotation) p + translation of the targets:
  // zero rotation and translation, scale 1 where not fitted.
  void alignment(const Eigen::VectorXd& values, Eigen::Vector3d* rotation,
                 Eigen::Vector3d* translation, double* scale) const;
  // The position among all parameters of rotation_x.. translation_z, scale (k = 0..6), or -1.
  int alignment_index(int k) const { return alignment_index_[static_cast<size_t>(k)]; }

 private:
  std::vector<std::string> material_names_;
  std::vector<model::MaterialParameter> material_parameters_;  // resolved once
  std::vector<int> material_indices_;
  int alignment_index_[7] = {-1, -1, -1, -1, -1, -1, -1};
  bool has_alignment_ = false;
};

}  // namespace fiberfluid::fit
