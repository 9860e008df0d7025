// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <string>
#include <vector>

namespace fiberfluid::model {

// The stress-strain law of a bulk fiber (model.md section 7): its secant
// modulus Y(e) = sigma(e) / e as a function of the fiber's strain
// e = |x_i - x_j| / L_ij - 1, with Y(0) the small-strain modulus, and the
// derivatives that the Newton tangent and the calibration need. Parameters
// have names so that a fitter can vary them ("Y", "Y0", "beta", ...).
class FiberLaw {
 public:
  enum class Kind {
    Constant,     // Y: the paper's linear model
    Exponential,  // Y0 exp(beta e): stiffening in tension, softening in compression
    Bilinear,     // Y_t in tension, Y_c in compression, joined smoothly over |e| < transition
    Tabulated,    // a piecewise-linear sigma(e), e.g. from a tensile test, times `scale`
  };

  static FiberLaw constant(double Y);
  static FiberLaw exponential(double Y0, double beta);
  // The secant modulus jumps at e = 0, and with the paper's vector spring so
  // does the force (u_i - u_j need not vanish where e does), which stalls
  // Newton. A C1 blend over |e| < transition (a strain; 0 for the sharp law)
  // removes the jump; Y(0) is then the mean of Y_t and Y_c.
  static FiberLaw bilinear(double Y_t, double Y_c, double transition = 0.005);
  double transition() const { return c_; }
  // strain strictly increasing, one point (0, 0); outside the table the end
  // segments are extended.
  static FiberLaw tabulated(std::vector<double> strain, std::vector<double> stress);

  Kind kind() const { return kind_; }
  const char* name() const;  // "constant", "exponential", "bilinear", "tabulated"
  bool is_constant() const { return kind_ == Kind::Constant; }

  double modulus(double strain) const;  // Y(e)
  double slope(double strain) const;    // dY/de
  // Y and dY/de at n strains (strain may alias neither output): the pair
  // kernels call this once per row, with the law's switch outside the loop.
  void evaluate(const double* strain, size_t n, double* modulus, double* slope) const;

  const std::vector<std::string>& parameter_names() const;
  double parameter(const std::string& name) const;  // throws std::invalid_argument
  void set_parameter(const std::string& name, double value);
  // dY/dtheta at a strain, for the parameter `name`.
  double modulus_derivative(const std::string& name, double strain) const;
  // The position of a parameter among parameter_names() (throws
  // std::invalid_argument for an unknown name), and dY/dtheta by that
  // position: resolved once, outside the pair loops.
  int parameter_index(const std::string& name) const;
  double modulus_derivative(int index, double strain) const;

  // "" when the law is usable, else why not (naming the parameter): a
  // non-positive or non-finite modulus at a strain in [lowest, highest], a
  // table that is not strictly increasing, or one without the point (0, 0).
  std::string check(double lowest_strain = -0.9, double highest_strain = 2.0) const;

  const std::vector<double>& table_strain() const { return strain_; }
  const std::vector<double>& table_stress() const { return stress_; }

 private:
  // The table segment holding `strain` (end segments extended).
  size_t segment(double strain) const;

  Kind kind_ = Kind::Constant;
  double a_ = 1.0;  // Y, Y0, Y_t, or the table's scale
  double b_ = 0.0;  // beta or Y_c
  double c_ = 0.0;  // the bilinear law's transition width
  std::vector<double> strain_, stress_;  // Tabulated
};

}  // namespace fiberfluid::model
