// SPDX-License-Identifier: GPL-3.0-or-later
#include "model/fiber_law.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace fiberfluid::model {

FiberLaw FiberLaw::constant(double Y) {
  FiberLaw law;
  law.kind_ = Kind::Constant;
  law.a_ = Y;
  return law;
}

FiberLaw FiberLaw::exponential(double Y0, double beta) {
  FiberLaw law;
  law.kind_ = Kind::Exponential;
  law.a_ = Y0;
  law.b_ = beta;
  return law;
}

FiberLaw FiberLaw::bilinear(double Y_t, double Y_c, double transition) {
  FiberLaw law;
  law.kind_ = Kind::Bilinear;
  law.a_ = Y_t;
  law.b_ = Y_c;
  law.c_ = transition;
  return law;
}

namespace {

// The share of Y_t in the bilinear law: 0 below -w, 1 above w, and the C1
// cubic 1/2 + 3t/4 - t^3/4 (t = e / w) between; w = 0 is a sharp step.
double tension_share(double e, double w) {
  if (w <= 0.0) return e >= 0.0 ? 1.0 : 0.0;
  const double t = std::clamp(e / w, -1.0, 1.0);
  return 0.5 + 0.75 * t - 0.25 * t * t * t;
}

double tension_share_slope(double e, double w) {
  if (w <= 0.0 || std::abs(e) >= w) return 0.0;
  const double t = e / w;
  return 0.75 * (1.0 - t * t) / w;
}

}  // namespace

FiberLaw FiberLaw::tabulated(std::vector<double> strain, std::vector<double> stress) {
  FiberLaw law;
  law.kind_ = Kind::Tabulated;
  law.a_ = 1.0;
  law.strain_ = std::move(strain);
  law.stress_ = std::move(stress);
  return law;
}

const char* FiberLaw::name() const {
  switch (kind_) {
    case Kind::Constant: return "constant";
    case Kind::Exponential: return "exponential";
    case Kind::Bilinear: return "bilinear";
    case Kind::Tabulated: return "tabulated";
  }
  return "?";
}

size_t FiberLaw::segment(double strain) const {
  // Segment k spans [strain_[k], strain_[k+1]]; e = 0 falls in the segment
  // that starts there, so Y(0) is the initial slope in tension.
  const auto it = std::upper_bound(strain_.begin(), strain_.end(), strain);
  const auto k = static_cast<size_t>(std::max<std::ptrdiff_t>(1, it - strain_.begin()) - 1);
  return std::min(k, strain_.size() - 2);
}

double FiberLaw::modulus(double e) const {
  switch (kind_) {
    case Kind::Constant: return a_;
    case Kind::Exponential: return a_ * std::exp(b_ * e);
    case Kind::Bilinear: return b_ + (a_ - b_) * tension_share(e, c_);
    case Kind::Tabulated: {
      // sigma = s_k + m (e - e_k) = m e + c on the segment: Y = m + c / e. The
      // segments that end at (0, 0) have c = 0 exactly, so Y is finite there.
      const size_t k = segment(e);
      const double m = (stress_[k + 1] - stress_[k]) / (strain_[k + 1] - strain_[k]);
      const bool through_origin = strain_[k] == 0.0 || strain_[k + 1] == 0.0;
      const double c = through_origin ? 0.0 : stress_[k] - m * strain_[k];
      return a_ * (c == 0.0 ? m : m + c / e);
    }
  }
  return a_;
}

double FiberLaw::slope(double e) const {
  switch (kind_) {
    case Kind::Constant: return 0.0;
    case Kind::Bilinear: return (a_ - b_) * tension_share_slope(e, c_);
    case Kind::Exponential: return a_ * b_ * std::exp(b_ * e);
    case Kind::Tabulated: {
      const size_t k = segment(e);
      const double m = (stress_[k + 1] - stress_[k]) / (strain_[k + 1] - strain_[k]);
      const bool through_origin = strain_[k] == 0.0 || strain_[k + 1] == 0.0;
      const double c = through_origin ? 0.0 : stress_[k] - m * strain_[k];
      return c == 0.0 ? 0.0 : -a_ * c / (e * e);
    }
  }
  return 0.0;
}

void FiberLaw::evaluate(const double* strain, size_t n, double* Y, double* Yp) const {
  switch (kind_) {
    case Kind::Constant:
      std::fill(Y, Y + n, a_);
      std::fill(Yp, Yp + n, 0.0);
      return;
    case Kind::Exponential:
      for (size_t k = 0; k < n; ++k) {
        Y[k] = a_ * std::exp(b_ * strain[k]);
        Yp[k] = b_ * Y[k];
      }
      return;
    case Kind::Bilinear:
    case Kind::Tabulated:  // named, so that a new kind is a -Wswitch warning here
      for (size_t k = 0; k < n; ++k) {
        Y[k] = modulus(strain[k]);
        Yp[k] = slope(strain[k]);
      }
      return;
  }
}

const std::vector<std::string>& FiberLaw::parameter_names() const {
  static const std::vector<std::string> constant{"Y"}, exponential{"Y0", "beta"},
      bilinear{"Y_t", "Y_c"}, tabulated{"scale"};
  switch (kind_) {
    case Kind::Constant: return constant;
    case Kind::Exponential: return exponential;
    case Kind::Bilinear: return bilinear;
    case Kind::Tabulated: return tabulated;
  }
  return constant;
}

double FiberLaw::parameter(const std::string& name) const {
  return parameter_index(name) == 0 ? a_ : b_;
}

void FiberLaw::set_parameter(const std::string& name, double value) {
  (parameter_index(name) == 0 ? a_ : b_) = value;
}

int FiberLaw::parameter_index(const std::string& name) const {
  const auto& names = parameter_names();
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end())
    throw std::invalid_argument("the " + std::string(this->name()) + " law has no parameter '" +
                                name + "'");
  return static_cast<int>(it - names.begin());
}

double FiberLaw::modulus_derivative(const std::string& name, double e) const {
  return modulus_derivative(parameter_index(name), e);
}

double FiberLaw::modulus_derivative(int index, double e) const {
  const bool first = index == 0;
  switch (kind_) {
    case Kind::Constant: return 1.0;
    case Kind::Exponential: return first ? std::exp(b_ * e) : a_ * e * std::exp(b_ * e);
    case Kind::Bilinear: {
      const double share = tension_share(e, c_);
      return first ? share : 1.0 - share;
    }
    case Kind::Tabulated: return modulus(e) / a_;
  }
  return 0.0;
}

std::string FiberLaw::check(double lowest, double highest) const {
  std::ostringstream out;
  if (kind_ == Kind::Tabulated) {
    if (strain_.size() != stress_.size() || strain_.size() < 2)
      return "the table needs at least two (strain, stress) points, as many strains as stresses";
    for (size_t k = 0; k < strain_.size(); ++k)
      if (!std::isfinite(strain_[k]) || !std::isfinite(stress_[k]))
        return "the table has a non-finite value at point " + std::to_string(k);
    for (size_t k = 1; k < strain_.size(); ++k) {
      if (!(strain_[k] > strain_[k - 1])) return "the strains must be strictly increasing";
      if (!(stress_[k] > stress_[k - 1]))
        return "the stresses must be strictly increasing (a monotone stress-strain curve)";
    }
    const auto zero = std::find(strain_.begin(), strain_.end(), 0.0);
    if (zero == strain_.end() || stress_[static_cast<size_t>(zero - strain_.begin())] != 0.0)
      return "the table must contain the point (0, 0): no stress at zero strain";
    if (!(a_ > 0.0) || !std::isfinite(a_)) return "scale must be a positive number";
    return {};
  }
  const std::vector<std::string>& names = parameter_names();
  for (const std::string& name : names)
    if (!std::isfinite(parameter(name))) return name + " must be a finite number";
  if (kind_ == Kind::Constant)
    return a_ >= 0.0 ? "" : "Y must be a number >= 0";
  if (kind_ == Kind::Bilinear && !(c_ >= 0.0 && c_ < 1.0))
    return "transition must be a strain from 0 to 1";
  for (const std::string& name : {names.front(), kind_ == Kind::Bilinear ? names.back() : ""})
    if (!name.empty() && !(parameter(name) > 0.0)) return name + " must be positive";
  // The modulus is monotone in e for these laws: its ends bound it.
  for (double e : {lowest, highest}) {
    const double y = modulus(e);
    if (!(y > 0.0) || !std::isfinite(y)) {
      out << "the modulus is " << y << " at strain " << e << " (it must be a positive number "
          << "for strains from " << lowest << " to " << highest << "): check " << names.back();
      return out.str();
    }
  }
  return {};
}

}  // namespace fiberfluid::model
