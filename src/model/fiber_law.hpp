// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "fiberfluid/util/status.hpp"

namespace fiberfluid::model {

// One kind of stress-strain law of a bulk fiber (model.md section 7): its
// secant modulus Y(e) = sigma(e) / e as a function of the fiber's strain
// e = |x_i - x_j| / L_ij - 1 and of a parameter vector p, with Y(0) the
// small-strain modulus, and the derivatives the Newton tangent and the
// calibration need. Everything else (the stencil, the kernels, Newton, the
// sensitivities, the fitter, the JSON reader) works from this interface, so
// a new law is one class: derive, then register_law() it (see the test
// FiberLaw.ALawAddedFromOutsideTheLibraryRunsNewtonAndSensitivities).
class LawModel {
 public:
  virtual ~LawModel() = default;
  // The name experiment files give as the law's "type".
  virtual std::string name() const = 0;
  // The parameters p by name, in order ("Y", "Y0", "beta", ...): what a fit varies.
  virtual std::vector<std::string> parameter_names() const = 0;
  virtual double modulus(const double* p, double e) const = 0;  // Y(e)
  virtual double slope(const double* p, double e) const = 0;    // dY/de
  // dY/dp_k at e.
  virtual double modulus_derivative(const double* p, int k, double e) const = 0;
  // Y and dY/de at n strains (a loop over modulus and slope unless overridden).
  virtual void evaluate(const double* p, const double* strain, size_t n, double* Y,
                        double* Yp) const;
  // dY/dp_k at n strains (a loop over modulus_derivative unless overridden):
  // one call per row of pairs, not one per pair.
  virtual void evaluate_derivative(const double* p, int k, const double* strain, size_t n,
                                   double* dY) const;
  // Whether the law is usable (why not, naming the parameter). The
  // default: every parameter finite, and Y positive and finite at 65 strains
  // spread over [lowest, highest].
  virtual Status check(const double* p, double lowest, double highest) const;
  // True when Y does not depend on the strain (the linear model).
  virtual bool is_constant() const { return false; }
  // A tension every fiber carries at rest (Pa, as Y e): the fiber's stress
  // is T(e) = T0 + Y(e) e. The fluid's pressure balances it at rest (a
  // network of chains in tension, as the neo-Hookean one). Zero by default.
  virtual double rest_tension(const double* /*p*/) const { return 0.0; }
  // dT0/dp_k.
  virtual double rest_tension_derivative(const double* /*p*/, int /*k*/) const { return 0.0; }
  // Whether parameter k is positive by nature (a modulus: a fit may vary it
  // in log scale), or may take either sign (an exponent).
  virtual bool is_positive(int /*k*/) const { return true; }

  // Fixed settings that are not fitted (a transition width, a table), for
  // output files: name and values (one value for a scalar).
  struct Setting {
    std::string name;
    std::vector<double> values;
    bool scalar = true;
  };
  virtual std::vector<Setting> settings() const { return {}; }
};

// A law: its kind (a LawModel, shared) and its parameter values.
class FiberLaw {
 public:
  // Throws std::invalid_argument when the values do not match the names.
  FiberLaw(std::shared_ptr<const LawModel> model, std::vector<double> parameters);

  // The built-in laws.
  static FiberLaw constant(double Y);  // the paper's linear model
  // Y0 exp(beta e): stiffening in tension, softening in compression.
  static FiberLaw exponential(double Y0, double beta);
  // Y_t in tension, Y_c in compression. The secant modulus jumps at e = 0, and
  // with the paper's vector spring so does the force (u_i - u_j need not
  // vanish where e does), which stalls Newton. A C1 blend over
  // |e| < transition (a strain; 0 for the sharp law) removes the jump; Y(0)
  // is then the mean of Y_t and Y_c.
  static FiberLaw bilinear(double Y_t, double Y_c, double transition = 0.005);
  // A piecewise-linear sigma(e), e.g. from a tensile test, times the
  // parameter `scale`: strain strictly increasing, one point (0, 0); outside
  // the table the end segments are extended. Where the slopes on the two
  // sides of zero differ, the moduli are blended C1 over |e| < transition as
  // in the bilinear law (0: the sharp table).
  static FiberLaw tabulated(std::vector<double> strain, std::vector<double> stress,
                            double transition = 0.005);

  // The affine network of a neo-Hookean solid of shear modulus mu: fibers
  // whose tension grows as their stretch, T = 0.6 mu l, that is Y = 0.6 mu
  // and a rest tension 0.6 mu (material_response.hpp: 5 <0.3 mu (l_d^2 - 1)>
  // = mu/2 (I1 - 3); the Gaussian chains of Treloar's network theory).
  static FiberLaw neo_hookean(double mu);

  // The data-driven law: a fiber's tension T(l) as a monotone quadratic
  // spline of its stretch l = 1 + e on knots `stretches` (increasing, one
  // below 1 and one above), T(1) = rest_tension, and rises[k] >= 0 the rise
  // of its B-spline coefficients at knot k (spline_law.cpp): parameters
  // "T1", "rise1".."riseN", one rise per knot. Beyond the knots the end
  // tangents extend it. Throws std::invalid_argument for fewer than two
  // knots or a rise count that differs.
  static FiberLaw spline(std::vector<double> stretches, double rest_tension,
                         const std::vector<double>& rises);

  std::string name() const { return model_->name(); }
  bool is_constant() const { return model_->is_constant(); }
  double rest_tension() const { return model_->rest_tension(p()); }  // T0
  double rest_tension_derivative(int index) const {
    return model_->rest_tension_derivative(p(), index);
  }
  const LawModel& model() const { return *model_; }

  double modulus(double strain) const { return model_->modulus(p(), strain); }  // Y(e)
  double slope(double strain) const { return model_->slope(p(), strain); }      // dY/de
  // Y and dY/de at n strains (strain may alias neither output): the pair
  // kernels call this once per row, with the law's dispatch outside the loop.
  void evaluate(const double* strain, size_t n, double* modulus, double* slope) const {
    model_->evaluate(p(), strain, n, modulus, slope);
  }

  const std::vector<std::string>& parameter_names() const { return names_; }
  const std::vector<double>& parameters() const { return parameters_; }
  double parameter(const std::string& name) const;  // throws std::invalid_argument
  void set_parameter(const std::string& name, double value);
  // The position of a parameter among parameter_names() (throws
  // std::invalid_argument for an unknown name), and dY/dtheta by that
  // position: resolved once, outside the pair loops.
  int parameter_index(const std::string& name) const;
  double modulus_derivative(int index, double strain) const {
    return model_->modulus_derivative(p(), index, strain);
  }
  double modulus_derivative(const std::string& name, double strain) const {
    return modulus_derivative(parameter_index(name), strain);
  }
  // dY/dtheta at n strains, for the parameter at `index`.
  void evaluate_derivative(int index, const double* strain, size_t n, double* dY) const {
    model_->evaluate_derivative(p(), index, strain, n, dY);
  }

  // Whether the law is usable (why not, naming the parameter): a
  // non-positive or non-finite modulus at a strain in [lowest, highest], a
  // table that is not strictly increasing, or one without the point (0, 0).
  Status check(double lowest_strain = -0.9, double highest_strain = 2.0) const {
    return model_->check(p(), lowest_strain, highest_strain);
  }
  std::vector<LawModel::Setting> settings() const { return model_->settings(); }

 private:
  const double* p() const { return parameters_.data(); }

  std::shared_ptr<const LawModel> model_;
  std::vector<std::string> names_;
  std::vector<double> parameters_;
};

// The law kinds that experiment files can name besides the built-ins
// (constant, exponential, bilinear, tabulated, neo_hookean, spline): a registered law is read as
// {"type": name, <each parameter>: number}. Throws std::invalid_argument when
// the name is taken or empty. Thread-safe.
void register_law(std::shared_ptr<const LawModel> model);
// The registered law of that name, or null.
std::shared_ptr<const LawModel> find_registered_law(const std::string& name);
std::vector<std::string> registered_law_names();
// Every "type" an experiment file may give a law: the built-ins, then the registered.
std::vector<std::string> law_type_names();

}  // namespace fiberfluid::model
