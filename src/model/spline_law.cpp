// SPDX-License-Identifier: GPL-3.0-or-later
// The data-driven fiber law (FiberLaw::spline): a fiber's tension as a
// monotone quadratic spline of its stretch, whose values are fitted.
//
// T(l) = sum_j c_j B_j(l), B_j the quadratic B-splines on the clamped knots
// (l_0, l_0, l_0, l_1, ..., l_n, l_n, l_n). The coefficients are the rest
// tension's offset and the rises a_k = c_k - c_{k-1} >= 0: a spline whose
// coefficients never fall never falls (de Boor, A Practical Guide to
// Splines, ch. IX; Ramsay, Statist. Sci. 3 (1988) 425, "I-splines"), so a
// fit that keeps the rises positive keeps the law monotone. In the rises the
// law is linear: T(l) = T1 + sum_k a_k (J_k(l) - J_k(1)), J_k = sum_{j>=k}
// B_j, so its parameter derivatives are exact. Beyond the knots the spline
// is extended by its end tangents.
#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "fiberfluid/model/fiber_law.hpp"

namespace fiberfluid::model {
namespace {

// The quadratic B-splines on clamped knots: at a stretch, the three that do
// not vanish, and their first and second derivatives.
class QuadraticBasis {
 public:
  explicit QuadraticBasis(const std::vector<double>& breaks) : breaks_(breaks) {
    knots_.assign(3, breaks.front());
    knots_.insert(knots_.end(), breaks.begin() + 1, breaks.end() - 1);
    knots_.insert(knots_.end(), 3, breaks.back());
  }

  int functions() const { return static_cast<int>(breaks_.size()) + 1; }
  double lowest() const { return breaks_.front(); }
  double highest() const { return breaks_.back(); }

  struct Values {
    int first = 0;  // B_first, B_first+1, B_first+2 are the non-zero ones
    std::array<double, 3> value{}, slope{}, curvature{};
  };

  // At l within [lowest, highest]; the piece is the one l lies in (the one
  // to the left at a knot when `from_left`).
  Values at(double l, bool from_left = false) const {
    // The knot span [t_s, t_s+1) with 2 <= s <= functions() - 1.
    const int last = functions() - 1;
    int s = 2;
    while (s < last && (from_left ? l > knots_[s + 1] : l >= knots_[s + 1])) ++s;
    const double* t = knots_.data();
    Values v;
    v.first = s - 2;
    // Degree 1 on the span, then degree 2 (Cox-de Boor).
    const double h = t[s + 1] - t[s];
    const double b1_left = (t[s + 1] - l) / h, b1_right = (l - t[s]) / h;
    const double d_left = t[s + 1] - t[s - 1], d_right = t[s + 2] - t[s];
    v.value[0] = (t[s + 1] - l) / d_left * b1_left;
    v.value[1] = (l - t[s - 1]) / d_left * b1_left + (t[s + 2] - l) / d_right * b1_right;
    v.value[2] = (l - t[s]) / d_right * b1_right;
    // The derivatives of degree 2 from the degree-1 splines on the span.
    v.slope[0] = -2.0 / d_left * b1_left;
    v.slope[1] = 2.0 / d_left * b1_left - 2.0 / d_right * b1_right;
    v.slope[2] = 2.0 / d_right * b1_right;
    v.curvature[0] = 2.0 / (d_left * h);
    v.curvature[1] = -2.0 / (d_left * h) - 2.0 / (d_right * h);
    v.curvature[2] = 2.0 / (d_right * h);
    return v;
  }

 private:
  std::vector<double> breaks_, knots_;
};

class SplineLaw final : public LawModel {
 public:
  explicit SplineLaw(std::vector<double> stretches)
      : stretches_(std::move(stretches)), basis_(valid_or_placeholder(stretches_)) {
    names_.push_back("T1");
    for (size_t k = 1; k < stretches_.size() + 1; ++k) names_.push_back("rise" + std::to_string(k));
    // J_k(1), which sets the offset c_0 from T1: the knots' alone.
    rest_share_.assign(static_cast<size_t>(basis_.functions()), 0.0);
    for (int k = 1; k < basis_.functions(); ++k)
      rest_share_[static_cast<size_t>(k)] = tension(indicator(k).data(), 1.0, false).value;
  }

  std::string name() const override { return "spline"; }
  std::vector<std::string> parameter_names() const override { return names_; }

  double modulus(const double* p, double e) const override {
    return secant(coefficients(p).data(), p[0], e).value;
  }
  double slope(const double* p, double e) const override {
    return secant(coefficients(p).data(), p[0], e).slope;
  }
  double modulus_derivative(const double* p, int k, double e) const override {
    double dY = 0.0;
    evaluate_derivative(p, k, &e, 1, &dY);
    return dY;
  }
  // One row of pairs: J_k's coefficients built once, not once per pair.
  void evaluate_derivative(const double*, int k, const double* strain, size_t n,
                           double* dY) const override {
    if (k == 0) {  // T1 shifts the tension, not its secant modulus
      std::fill(dY, dY + n, 0.0);
      return;
    }
    const std::vector<double> c = indicator(k);
    for (size_t j = 0; j < n; ++j)
      dY[j] = secant(c.data(), rest_share_[static_cast<size_t>(k)], strain[j]).value;
  }
  void evaluate(const double* p, const double* strain, size_t n, double* Y,
                double* Yp) const override {
    const std::vector<double> c = coefficients(p);
    for (size_t j = 0; j < n; ++j) {
      const Secant s = secant(c.data(), p[0], strain[j]);
      Y[j] = s.value;
      Yp[j] = s.slope;
    }
  }
  double rest_tension(const double* p) const override { return p[0]; }
  double rest_tension_derivative(const double*, int k) const override { return k == 0 ? 1.0 : 0.0; }

  Status check(const double* p, double, double) const override {
    for (size_t k = 0; k < stretches_.size(); ++k) {
      if (!std::isfinite(stretches_[k]) || !(stretches_[k] > 0.0))
        return Status::failure("the stretches must be positive numbers (knot " +
                               std::to_string(k + 1) + " is not)");
      if (k > 0 && !(stretches_[k] > stretches_[k - 1]))
        return Status::failure("the stretches must be strictly increasing");
    }
    if (!(stretches_.front() < 1.0 && stretches_.back() > 1.0))
      return Status::failure(
          "the stretches must span the rest stretch 1 (a knot below it and one above)");
    for (size_t k = 0; k < names_.size(); ++k)
      if (!std::isfinite(p[k]) || p[k] < 0.0)
        return Status::failure(names_[k] + " must be a number >= 0" +
                               (k == 0 ? std::string(" (the tension at rest)")
                                       : std::string(" (the tension never falls)")));
    // Rises >= 0 keep the tension from falling, so the secant modulus is
    // never negative; where the tension is flat it is 0, which a fiber in
    // tension at rest bears (its tension stiffens it across). What a body
    // needs is a network stiff at rest: its small-strain Young's modulus
    // T'(1) + 4 T(1) (material_response.hpp) positive.
    const std::vector<double> c = coefficients(p);
    const double stiffness = tension(c.data(), 1.0, false).slope + 4.0 * p[0];
    if (!(stiffness > 0.0) || !std::isfinite(stiffness))
      return Status::failure("the spline's network has no stiffness at rest (T'(1) + 4 T1 is " +
                             std::to_string(stiffness) +
                             "): give T1 > 0 or a rise where the knots meet 1");
    return {};
  }

  std::vector<Setting> settings() const override { return {{"stretches", stretches_, false}}; }

 private:
  // The B-spline coefficients c_j = c_0 + sum_{k <= j} a_k, c_0 so that T(1) = T1.
  std::vector<double> coefficients(const double* p) const {
    std::vector<double> c(static_cast<size_t>(basis_.functions()));
    double c0 = p[0];
    for (size_t k = 1; k < c.size(); ++k) c0 -= p[k] * rest_share_[k];
    c[0] = c0;
    for (size_t j = 1; j < c.size(); ++j) c[j] = c[j - 1] + p[j];
    return c;
  }
  // The coefficients of J_k = sum_{j >= k} B_j: dT / da_k up to a constant.
  std::vector<double> indicator(int k) const {
    std::vector<double> c(static_cast<size_t>(basis_.functions()), 0.0);
    std::fill(c.begin() + k, c.end(), 1.0);
    return c;
  }

  // Y(e) = (T(1 + e) - T(1)) / e and dY/de for the spline of coefficients c
  // whose value at rest is `rest`.
  struct Secant {
    double value = 0.0, slope = 0.0;
  };
  Secant secant(const double* c, double rest, double e) const {
    // Near rest the difference quotient cancels: use the piece's Taylor
    // form, exact for a quadratic piece (Y = T'(1) + T''(1) e / 2).
    if (std::abs(e) < 1e-4) {
      const Tension at_rest = tension(c, 1.0, e < 0.0);
      return {at_rest.slope + 0.5 * at_rest.curvature * e, 0.5 * at_rest.curvature};
    }
    const Tension t = tension(c, 1.0 + e, false);
    const double Y = (t.value - rest) / e;
    return {Y, (t.slope - Y) / e};
  }

  // T(l), T'(l) and T''(l) of the spline of coefficients c, extended beyond
  // the knots by its end tangent.
  struct Tension {
    double value = 0.0, slope = 0.0, curvature = 0.0;
  };
  Tension tension(const double* c, double l, bool from_left) const {
    const double end = std::clamp(l, basis_.lowest(), basis_.highest());
    const QuadraticBasis::Values b = basis_.at(end, from_left);
    Tension t;
    for (int i = 0; i < 3; ++i) {
      const double ci = c[b.first + i];
      t.value += ci * b.value[i];
      t.slope += ci * b.slope[i];
      t.curvature += ci * b.curvature[i];
    }
    if (end != l) {
      t.value += t.slope * (l - end);
      t.curvature = 0.0;
    }
    return t;
  }

  // check() refuses bad knots by name; until then the basis is built on
  // evenly spread ones of the same count (at least two: FiberLaw::spline).
  static std::vector<double> valid_or_placeholder(const std::vector<double>& stretches) {
    bool valid = true;
    for (size_t k = 0; valid && k < stretches.size(); ++k)
      valid = std::isfinite(stretches[k]) && (k == 0 || stretches[k] > stretches[k - 1]);
    if (valid) return stretches;
    std::vector<double> even(stretches.size());
    for (size_t k = 0; k < even.size(); ++k)
      even[k] = 0.5 + 1.5 * static_cast<double>(k) / static_cast<double>(even.size() - 1);
    return even;
  }

  std::vector<double> stretches_;
  QuadraticBasis basis_;
  std::vector<std::string> names_;
  std::vector<double> rest_share_;  // J_k(1), k = 1..functions - 1 (0 unused)
};

}  // namespace

FiberLaw FiberLaw::spline(std::vector<double> stretches, double rest_tension,
                          const std::vector<double>& rises) {
  if (stretches.size() < 2)
    throw std::invalid_argument("a spline law needs at least two stretches (its knots), got " +
                                std::to_string(stretches.size()));
  if (rises.size() != stretches.size())
    throw std::invalid_argument("a spline law needs one rise per stretch (" +
                                std::to_string(stretches.size()) + "), got " +
                                std::to_string(rises.size()));
  auto model = std::make_shared<const SplineLaw>(std::move(stretches));
  std::vector<double> p = {rest_tension};
  p.insert(p.end(), rises.begin(), rises.end());
  return {model, p};
}

}  // namespace fiberfluid::model
