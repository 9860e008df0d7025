// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/model/fiber_law.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "fiberfluid/model/vector_clones.hpp"
#include "fiberfluid/model/vector_math.hpp"

namespace fiberfluid::model {

void LawModel::evaluate(const double* p, const double* strain, size_t n, double* Y,
                        double* Yp) const {
  for (size_t k = 0; k < n; ++k) {
    Y[k] = modulus(p, strain[k]);
    Yp[k] = slope(p, strain[k]);
  }
}

void LawModel::evaluate_derivative(const double* p, int k, const double* strain, size_t n,
                                   double* dY) const {
  for (size_t j = 0; j < n; ++j) dY[j] = modulus_derivative(p, k, strain[j]);
}

namespace {

Status finite_parameters(const LawModel& law, const double* p) {
  const std::vector<std::string> names = law.parameter_names();
  for (size_t k = 0; k < names.size(); ++k)
    if (!std::isfinite(p[k])) return Status::failure(names[k] + " must be a finite number");
  return {};
}

// "" when Y is positive and finite at every strain of `strains`, else the
// first strain where it is not, and which parameter to look at.
Status positive_modulus(const LawModel& law, const double* p, const std::vector<double>& strains,
                        double lowest, double highest, const std::string& suspect) {
  for (double e : strains) {
    const double y = law.modulus(p, e);
    if (!(y > 0.0) || !std::isfinite(y)) {
      std::ostringstream out;
      out << "the modulus is " << y << " at strain " << e << " (it must be a positive number "
          << "for strains from " << lowest << " to " << highest << "): check " << suspect;
      return Status::failure(out.str());
    }
  }
  return {};
}

}  // namespace

Status LawModel::check(const double* p, double lowest, double highest) const {
  if (Status finite = finite_parameters(*this, p); !finite.ok) return finite;
  std::vector<double> strains;
  constexpr int kSamples = 64;
  for (int k = 0; k <= kSamples; ++k) strains.push_back(lowest + (highest - lowest) * k / kSamples);
  const std::vector<std::string> names = parameter_names();
  return positive_modulus(*this, p, strains, lowest, highest,
                          names.empty() ? std::string("the law") : names.back());
}

namespace {

// ---- The built-in laws -----------------------------------------------------

class ConstantLaw final : public LawModel {
 public:
  std::string name() const override { return "constant"; }
  std::vector<std::string> parameter_names() const override { return {"Y"}; }
  double modulus(const double* p, double) const override { return p[0]; }
  double slope(const double*, double) const override { return 0.0; }
  double modulus_derivative(const double*, int, double) const override { return 1.0; }
  void evaluate(const double* p, const double*, size_t n, double* Y, double* Yp) const override {
    std::fill(Y, Y + n, p[0]);
    std::fill(Yp, Yp + n, 0.0);
  }
  Status check(const double* p, double, double) const override {
    if (Status finite = finite_parameters(*this, p); !finite.ok) return finite;
    return p[0] >= 0.0 ? Status{} : Status::failure("Y must be a number >= 0");
  }
  bool is_constant() const override { return true; }
};

// The neo-Hookean network (FiberLaw::neo_hookean): T = 0.6 mu (1 + e).
class NeoHookeanLaw final : public LawModel {
 public:
  std::string name() const override { return "neo_hookean"; }
  std::vector<std::string> parameter_names() const override { return {"mu"}; }
  double modulus(const double* p, double) const override { return kShare * p[0]; }
  double slope(const double*, double) const override { return 0.0; }
  double modulus_derivative(const double*, int, double) const override { return kShare; }
  void evaluate(const double* p, const double*, size_t n, double* Y, double* Yp) const override {
    std::fill(Y, Y + n, kShare * p[0]);
    std::fill(Yp, Yp + n, 0.0);
  }
  double rest_tension(const double* p) const override { return kShare * p[0]; }
  double rest_tension_derivative(const double*, int) const override { return kShare; }
  Status check(const double* p, double, double) const override {
    if (Status finite = finite_parameters(*this, p); !finite.ok) return finite;
    return p[0] > 0.0 ? Status{} : Status::failure("mu must be a positive number");
  }

 private:
  // 5 <0.3 mu l^2> = mu/2 I1 (material_response.hpp's factor 5, <d_i^2> = 1/3).
  static constexpr double kShare = 0.6;
};

// Y0 exp(beta e) and its slope at n strains, vectorised (vector_exp): the
// Newton kernels call this once per row of pairs.
FIBERFLUID_VECTOR_CLONES
void exponential_moduli(double Y0, double beta, const double* strain, size_t n, double* Y,
                        double* Yp) {
#pragma omp simd
  for (size_t k = 0; k < n; ++k) {
    Y[k] = Y0 * vector_exp(beta * strain[k]);
    Yp[k] = beta * Y[k];
  }
}

FIBERFLUID_VECTOR_CLONES
void exponential_derivatives(double Y0, double beta, int parameter, const double* strain, size_t n,
                             double* dY) {
#pragma omp simd
  for (size_t k = 0; k < n; ++k) {
    const double growth = vector_exp(beta * strain[k]);
    dY[k] = parameter == 0 ? growth : Y0 * strain[k] * growth;
  }
}

class ExponentialLaw final : public LawModel {
 public:
  std::string name() const override { return "exponential"; }
  std::vector<std::string> parameter_names() const override { return {"Y0", "beta"}; }
  double modulus(const double* p, double e) const override { return p[0] * vector_exp(p[1] * e); }
  double slope(const double* p, double e) const override { return p[1] * modulus(p, e); }
  double modulus_derivative(const double* p, int k, double e) const override {
    return k == 0 ? vector_exp(p[1] * e) : p[0] * e * vector_exp(p[1] * e);
  }
  bool is_positive(int k) const override { return k == 0; }  // beta takes either sign
  void evaluate(const double* p, const double* strain, size_t n, double* Y,
                double* Yp) const override {
    exponential_moduli(p[0], p[1], strain, n, Y, Yp);
  }
  void evaluate_derivative(const double* p, int k, const double* strain, size_t n,
                           double* dY) const override {
    exponential_derivatives(p[0], p[1], k, strain, n, dY);
  }
  Status check(const double* p, double lowest, double highest) const override {
    if (Status finite = finite_parameters(*this, p); !finite.ok) return finite;
    if (!(p[0] > 0.0)) return Status::failure("Y0 must be positive");
    // Monotone in e: the ends bound it.
    return positive_modulus(*this, p, {lowest, highest}, lowest, highest, "beta");
  }
};

// The share of Y_t in the bilinear law: 0 below -w, 1 above w, and the C1
// cubic 1/2 + 3t/4 - t^3/4 (t = e / w) between; w = 0 is a sharp step.
double tension_share(double e, double w) {
  if (w <= 0.0) return e >= 0.0 ? 1.0 : 0.0;
  double t = e / w;  // clamped to [-1, 1] by selects (std::clamp's reference stops the vectoriser)
  t = t < -1.0 ? -1.0 : t;
  t = t > 1.0 ? 1.0 : t;
  return 0.5 + 0.75 * t - 0.25 * t * t * t;
}

double tension_share_slope(double e, double w) {
  if (w <= 0.0 || std::abs(e) >= w) return 0.0;
  const double t = e / w;
  return 0.75 * (1.0 - t * t) / w;
}

// The bilinear law's Y and dY/de at n strains, vectorised (the share's clamp
// and its branch become blends).
FIBERFLUID_VECTOR_CLONES
void bilinear_moduli(double Y_t, double Y_c, double w, const double* strain, size_t n, double* Y,
                     double* Yp) {
#pragma omp simd
  for (size_t k = 0; k < n; ++k) {
    Y[k] = Y_c + (Y_t - Y_c) * tension_share(strain[k], w);
    Yp[k] = (Y_t - Y_c) * tension_share_slope(strain[k], w);
  }
}

class BilinearLaw final : public LawModel {
 public:
  explicit BilinearLaw(double transition) : w_(transition) {}
  std::string name() const override { return "bilinear"; }
  std::vector<std::string> parameter_names() const override { return {"Y_t", "Y_c"}; }
  double modulus(const double* p, double e) const override {
    return p[1] + (p[0] - p[1]) * tension_share(e, w_);
  }
  double slope(const double* p, double e) const override {
    return (p[0] - p[1]) * tension_share_slope(e, w_);
  }
  double modulus_derivative(const double*, int k, double e) const override {
    const double share = tension_share(e, w_);
    return k == 0 ? share : 1.0 - share;
  }
  void evaluate(const double* p, const double* strain, size_t n, double* Y,
                double* Yp) const override {
    bilinear_moduli(p[0], p[1], w_, strain, n, Y, Yp);
  }
  Status check(const double* p, double lowest, double highest) const override {
    if (Status finite = finite_parameters(*this, p); !finite.ok) return finite;
    if (!(w_ >= 0.0 && w_ < 1.0)) return Status::failure("transition must be a strain from 0 to 1");
    if (!(p[0] > 0.0)) return Status::failure("Y_t must be positive");
    if (!(p[1] > 0.0)) return Status::failure("Y_c must be positive");
    return positive_modulus(*this, p, {lowest, highest}, lowest, highest, "Y_c");
  }
  std::vector<Setting> settings() const override { return {{"transition", {w_}, true}}; }

 private:
  double w_;
};

// A table's segments for the block evaluation: the interior breakpoints
// (segment k of e: how many of them e is not below), each segment's
// sigma = m e + c, and each side's slope through zero for the blend.
struct TableArrays {
  const double *breaks, *m, *c;
  int num_breaks;
  double tension_slope, compression_slope, transition;
};

// The tabulated law's Y and dY/de at n strains (before its scale), without
// a branch or a search: the segment's m and c by one vector pass of selects
// per breakpoint over a block of strains (the last breakpoint passed wins),
// the sides and the blend by selects. The same operations as TabulatedLaw::modulus
// and slope, value by value.
FIBERFLUID_VECTOR_CLONES
void tabulated_moduli(const TableArrays& t, double scale, const double* strain, size_t n, double* Y,
                      double* Yp) {
  constexpr size_t kBlock = 256;
  const double w = t.transition;
  alignas(64) double slope_of[kBlock], offset_of[kBlock];  // the segment's m and c
  for (size_t k0 = 0; k0 < n; k0 += kBlock) {
    const size_t len = std::min(kBlock, n - k0);
    const double* e = strain + k0;
#pragma omp simd
    for (size_t k = 0; k < len; ++k) slope_of[k] = t.m[0], offset_of[k] = t.c[0];
    for (int b = 0; b < t.num_breaks; ++b) {  // past breakpoint b: segment b + 1 or later
      const double at = t.breaks[b], m = t.m[b + 1], c = t.c[b + 1];
#pragma omp simd
      for (size_t k = 0; k < len; ++k) {
        const bool past = !(e[k] < at);
        slope_of[k] = past ? m : slope_of[k];
        offset_of[k] = past ? c : offset_of[k];
      }
    }
#pragma omp simd
    for (size_t k = 0; k < len; ++k) {
      const double m = slope_of[k], c = offset_of[k], x = e[k];
      const double table_modulus = c == 0.0 ? m : m + c / x;
      const double table_slope = c == 0.0 ? 0.0 : -c / (x * x);
      const double share = tension_share(x, w);
      const double tension_modulus = x >= 0.0 ? table_modulus : t.tension_slope;
      const double compression_modulus = x >= 0.0 ? t.compression_slope : table_modulus;
      const double tension_side_slope = x >= 0.0 ? table_slope : 0.0;
      const double compression_side_slope = x >= 0.0 ? 0.0 : table_slope;
      const double blended_modulus = (1.0 - share) * compression_modulus + share * tension_modulus;
      const double blended_slope =
          (1.0 - share) * compression_side_slope + share * tension_side_slope +
          tension_share_slope(x, w) * (tension_modulus - compression_modulus);
      const double blends = std::abs(x) < w ? 1.0 : 0.0;  // never when w <= 0
      Y[k0 + k] = scale * (blends != 0.0 ? blended_modulus : table_modulus);
      Yp[k0 + k] = scale * (blends != 0.0 ? blended_slope : table_slope);
    }
  }
}

// A piecewise-linear sigma(e) from a table. Its slope may differ on the two
// sides of e = 0 (a tissue softer in compression), where the secant modulus,
// and with the vector spring the force, would jump and stall Newton: over
// |e| < transition the two sides' moduli are blended by the bilinear law's C1
// share, each side's segment through (0, 0) extended across zero.
class TabulatedLaw final : public LawModel {
 public:
  TabulatedLaw(std::vector<double> strain, std::vector<double> stress, double transition)
      : strain_(std::move(strain)), stress_(std::move(stress)), w_(transition) {
    // The block evaluation's arrays, for a table check() will accept in shape.
    if (strain_.size() < 2 || stress_.size() != strain_.size()) return;
    breaks_.assign(strain_.begin() + 1, strain_.end() - 1);
    for (size_t k = 0; k + 1 < strain_.size(); ++k) {
      const Segment s = segment(strain_[k]);  // segment k (it starts at strain_k)
      m_.push_back(s.m);
      c_.push_back(s.c);
    }
  }
  void evaluate(const double* p, const double* strain, size_t n, double* Y,
                double* Yp) const override {
    if (m_.empty()) return LawModel::evaluate(p, strain, n, Y, Yp);
    const TableArrays arrays{breaks_.data(),
                             m_.data(),
                             c_.data(),
                             static_cast<int>(breaks_.size()),
                             zero_segment_slope(true),
                             zero_segment_slope(false),
                             w_};
    tabulated_moduli(arrays, p[0], strain, n, Y, Yp);
  }
  std::string name() const override { return "tabulated"; }
  std::vector<std::string> parameter_names() const override { return {"scale"}; }
  double modulus(const double* p, double e) const override {
    if (!blends(e)) return p[0] * table_modulus(e);
    const double share = tension_share(e, w_);
    return p[0] * ((1.0 - share) * side_modulus(e, false) + share * side_modulus(e, true));
  }
  double slope(const double* p, double e) const override {
    if (!blends(e)) return p[0] * table_slope(e);
    const double share = tension_share(e, w_);
    return p[0] * ((1.0 - share) * side_slope(e, false) + share * side_slope(e, true) +
                   tension_share_slope(e, w_) * (side_modulus(e, true) - side_modulus(e, false)));
  }
  double modulus_derivative(const double* p, int, double e) const override {
    return modulus(p, e) / p[0];
  }
  Status check(const double* p, double, double) const override {
    if (strain_.size() != stress_.size() || strain_.size() < 2)
      return Status::failure(
          "the table needs at least two (strain, stress) points, as many strains as stresses");
    for (size_t k = 0; k < strain_.size(); ++k)
      if (!std::isfinite(strain_[k]) || !std::isfinite(stress_[k]))
        return Status::failure("the table has a non-finite value at point " + std::to_string(k));
    for (size_t k = 1; k < strain_.size(); ++k) {
      if (!(strain_[k] > strain_[k - 1]))
        return Status::failure("the strains must be strictly increasing");
      if (!(stress_[k] > stress_[k - 1]))
        return Status::failure(
            "the stresses must be strictly increasing (a monotone stress-strain curve)");
    }
    const auto zero = std::find(strain_.begin(), strain_.end(), 0.0);
    if (zero == strain_.end() || stress_[static_cast<size_t>(zero - strain_.begin())] != 0.0)
      return Status::failure("the table must contain the point (0, 0): no stress at zero strain");
    if (!(w_ >= 0.0 && w_ < 1.0)) return Status::failure("transition must be a strain from 0 to 1");
    if (!(p[0] > 0.0) || !std::isfinite(p[0]))
      return Status::failure("scale must be a positive number");
    return {};
  }
  std::vector<Setting> settings() const override {
    return {{"strain", strain_, false}, {"stress", stress_, false}, {"transition", {w_}, true}};
  }

 private:
  struct Segment {
    double m, c;  // sigma = m e + c on it
  };
  // The segment holding e (end segments extended). Segment k spans
  // [strain_k, strain_k+1]; e = 0 falls in the segment that starts there.
  Segment segment(double e) const {
    // A table without a segment (check() names it) gives NaN, never a read past it.
    if (strain_.size() < 2 || stress_.size() != strain_.size()) return {std::nan(""), 0.0};
    const auto it = std::upper_bound(strain_.begin(), strain_.end(), e);
    const auto k =
        std::min(static_cast<size_t>(std::max<std::ptrdiff_t>(1, it - strain_.begin()) - 1),
                 strain_.size() - 2);
    const double m = (stress_[k + 1] - stress_[k]) / (strain_[k + 1] - strain_[k]);
    const bool through_origin = strain_[k] == 0.0 || strain_[k + 1] == 0.0;
    return {m, through_origin ? 0.0 : stress_[k] - m * strain_[k]};
  }
  // sigma = m e + c on the segment: Y = m + c / e. The segments that end at
  // (0, 0) have c = 0 exactly, so Y is finite there.
  double table_modulus(double e) const {
    const Segment s = segment(e);
    return s.c == 0.0 ? s.m : s.m + s.c / e;
  }
  double table_slope(double e) const {
    const Segment s = segment(e);
    return s.c == 0.0 ? 0.0 : -s.c / (e * e);
  }
  bool blends(double e) const { return w_ > 0.0 && std::abs(e) < w_; }
  // The tension side (e >= 0 of the table, its first segment extended below
  // zero) or the compression side, at e.
  double side_modulus(double e, bool tension) const {
    return (e >= 0.0) == tension ? table_modulus(e) : zero_segment_slope(tension);
  }
  // The slope of the table's segment that starts (tension) or ends at zero
  // strain; a table that starts at zero extends its first segment.
  double zero_segment_slope(bool tension) const {
    const auto zero = std::find(strain_.begin(), strain_.end(), 0.0);
    if (zero == strain_.end() || strain_.size() < 2) return std::nan("");
    const size_t z = static_cast<size_t>(zero - strain_.begin());
    const size_t k = tension ? std::min(z, strain_.size() - 2) : (z > 0 ? z - 1 : 0);
    return (stress_[k + 1] - stress_[k]) / (strain_[k + 1] - strain_[k]);
  }
  double side_slope(double e, bool tension) const {
    return (e >= 0.0) == tension ? table_slope(e) : 0.0;
  }

  std::vector<double> strain_, stress_;
  double w_;
  std::vector<double> breaks_, m_, c_;  // for the block evaluation
};

}  // namespace

FiberLaw::FiberLaw(std::shared_ptr<const LawModel> model, std::vector<double> parameters)
    : model_(std::move(model)), parameters_(std::move(parameters)) {
  if (!model_) throw std::invalid_argument("a fiber law needs a law model");
  names_ = model_->parameter_names();
  if (names_.size() != parameters_.size())
    throw std::invalid_argument("the " + model_->name() + " law takes " +
                                std::to_string(names_.size()) + " parameters, got " +
                                std::to_string(parameters_.size()));
}

FiberLaw FiberLaw::constant(double Y) {
  static const auto model = std::make_shared<const ConstantLaw>();
  return {model, {Y}};
}

FiberLaw FiberLaw::exponential(double Y0, double beta) {
  static const auto model = std::make_shared<const ExponentialLaw>();
  return {model, {Y0, beta}};
}

FiberLaw FiberLaw::neo_hookean(double mu) {
  static const auto model = std::make_shared<const NeoHookeanLaw>();
  return {model, {mu}};
}

FiberLaw FiberLaw::bilinear(double Y_t, double Y_c, double transition) {
  return {std::make_shared<const BilinearLaw>(transition), {Y_t, Y_c}};
}

FiberLaw FiberLaw::tabulated(std::vector<double> strain, std::vector<double> stress,
                             double transition) {
  return {std::make_shared<const TabulatedLaw>(std::move(strain), std::move(stress), transition),
          {1.0}};
}

int FiberLaw::parameter_index(const std::string& name) const {
  const auto it = std::find(names_.begin(), names_.end(), name);
  if (it == names_.end())
    throw std::invalid_argument("the " + this->name() + " law has no parameter '" + name + "'");
  return static_cast<int>(it - names_.begin());
}

double FiberLaw::parameter(const std::string& name) const {
  return parameters_[static_cast<size_t>(parameter_index(name))];
}

void FiberLaw::set_parameter(const std::string& name, double value) {
  parameters_[static_cast<size_t>(parameter_index(name))] = value;
}

// ---- The registry ------------------------------------------------------------

namespace {

struct Registry {
  std::mutex mutex;
  std::map<std::string, std::shared_ptr<const LawModel>> laws;
};

Registry& registry() {
  static Registry r;
  return r;
}

const std::vector<std::string>& builtin_law_names() {
  static const std::vector<std::string> names = {"constant", "exponential", "bilinear", "tabulated",
                                                 "neo_hookean", "spline"};
  return names;
}

bool is_builtin(const std::string& name) {
  const std::vector<std::string>& names = builtin_law_names();
  return std::find(names.begin(), names.end(), name) != names.end();
}

}  // namespace

void register_law(std::shared_ptr<const LawModel> model) {
  if (!model) throw std::invalid_argument("register_law: no law model");
  const std::string name = model->name();
  if (name.empty()) throw std::invalid_argument("register_law: a law needs a name");
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  if (is_builtin(name) || r.laws.count(name) != 0)
    throw std::invalid_argument("register_law: a law named '" + name + "' exists already");
  r.laws.emplace(name, std::move(model));
}

std::shared_ptr<const LawModel> find_registered_law(const std::string& name) {
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  const auto it = r.laws.find(name);
  return it == r.laws.end() ? nullptr : it->second;
}

std::vector<std::string> law_type_names() {
  std::vector<std::string> names = builtin_law_names();
  for (const std::string& name : registered_law_names()) names.push_back(name);
  return names;
}

std::vector<std::string> registered_law_names() {
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  std::vector<std::string> names;
  for (const auto& entry : r.laws) names.push_back(entry.first);
  return names;
}

}  // namespace fiberfluid::model
