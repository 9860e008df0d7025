// SPDX-License-Identifier: GPL-3.0-or-later
// Isotropic incompressible hyperelastic laws as researchers fit them, with
// their parameters in the continuum's units (Pa), and their response to the
// homogeneous tests of a material (uniaxial, equibiaxial, pure shear) with no
// body: the material-level curve a body's response is checked against and a
// material test is fitted to.
//
//   neo-Hookean     W = mu/2 (I1 - 3)
//   Mooney-Rivlin   W = C10 (I1 - 3) + C01 (I2 - 3)
//   Yeoh            W = C10 (I1 - 3) + C20 (I1 - 3)^2 + C30 (I1 - 3)^3
//   Ogden           W = sum_p mu_p / alpha_p (l1^alpha_p + l2^alpha_p + l3^alpha_p - 3)
//
// with I1 = l1^2 + l2^2 + l3^2, I2 = l1^-2 + l2^-2 + l3^-2 (l1 l2 l3 = 1).
// Ogden's convention is Ogden's (1972) and Ogden, Saccomandi and Sgura's
// (Comput. Mech. 34 (2004) 484): the shear modulus is 1/2 sum_p mu_p alpha_p.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fiberfluid/util/status.hpp"

namespace fiberfluid::material {

class HyperelasticLaw {
 public:
  enum class Kind { NeoHookean, MooneyRivlin, Yeoh, Ogden };

  static HyperelasticLaw neo_hookean(double mu);
  static HyperelasticLaw mooney_rivlin(double c10, double c01);
  static HyperelasticLaw yeoh(double c10, double c20, double c30);
  // Terms (mu_p, alpha_p), in Pa and without unit.
  static HyperelasticLaw ogden(const std::vector<std::pair<double, double>>& terms);
  // By name ("neo_hookean", "mooney_rivlin", "yeoh", "ogden1", "ogden2",
  // "ogden3") with every parameter zero but a first modulus of `mu`: a
  // start to fit from. Throws InputError naming the valid names.
  static HyperelasticLaw named(const std::string& name, double mu);

  Kind kind() const { return kind_; }
  const std::string& name() const { return name_; }
  // mu; C10, C01; C10, C20, C30; mu_1, alpha_1, mu_2, alpha_2, ...
  const std::vector<std::string>& parameter_names() const { return names_; }
  const Eigen::VectorXd& parameters() const { return p_; }
  HyperelasticLaw with_parameters(const Eigen::VectorXd& p) const;
  // Whether parameter k is a modulus (Pa) rather than an exponent.
  bool is_modulus(int k) const;

  // The shear modulus at small strain (Pa).
  double shear_modulus() const;
  // W at principal stretches l (l1 l2 l3 = 1).
  double energy(const Eigen::Vector3d& l) const;
  // l_i dW/dl_i for each i: the principal Cauchy stress but for the
  // pressure, sigma_i = l_i dW/dl_i - p.
  Eigen::Vector3d stretch_work(const Eigen::Vector3d& l) const;
  // Whether the law is a material: finite parameters, a positive shear
  // modulus (why not, naming the parameter).
  Status check() const;

 private:
  HyperelasticLaw(Kind kind, std::string name, std::vector<std::string> names, Eigen::VectorXd p);
  Kind kind_;
  std::string name_;
  std::vector<std::string> names_;
  Eigen::VectorXd p_;
};

// The homogeneous tests of an incompressible material, stretch l along axis 1:
//   uniaxial     (l, l^-1/2, l^-1/2), sides free
//   equibiaxial  (l, l, l^-2), axis 3 free
//   pure shear   (l, 1, 1/l), axis 3 free, axis 2 held (a wide strip)
enum class HomogeneousTest { Uniaxial, Equibiaxial, PureShear };
const char* to_string(HomogeneousTest test);
// Reads "uniaxial", "equibiaxial", "pure_shear"; throws InputError otherwise.
HomogeneousTest homogeneous_test(const std::string& name);

// The principal stretches of `test` at stretch l.
Eigen::Vector3d test_stretches(HomogeneousTest test, double l);
// The nominal (first Piola) stress along axis 1 in `test` at stretch l: the
// force per undeformed area a test machine reports (Pa), the pressure taken
// from the free axis's zero stress.
double nominal_stress(const HyperelasticLaw& law, HomogeneousTest test, double l);

}  // namespace fiberfluid::material
