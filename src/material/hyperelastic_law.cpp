// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/material/hyperelastic_law.hpp"

#include <cmath>
#include <stdexcept>

#include "fiberfluid/util/error.hpp"

namespace fiberfluid::material {
namespace {

Eigen::VectorXd vector_of(std::initializer_list<double> values) {
  Eigen::VectorXd v(static_cast<Eigen::Index>(values.size()));
  Eigen::Index k = 0;
  for (double x : values) v[k++] = x;
  return v;
}

std::vector<std::string> ogden_names(size_t terms) {
  std::vector<std::string> names;
  for (size_t p = 1; p <= terms; ++p) {
    names.push_back("mu_" + std::to_string(p));
    names.push_back("alpha_" + std::to_string(p));
  }
  return names;
}

}  // namespace

HyperelasticLaw::HyperelasticLaw(Kind kind, std::string name, std::vector<std::string> names,
                                 Eigen::VectorXd p)
    : kind_(kind), name_(std::move(name)), names_(std::move(names)), p_(std::move(p)) {}

HyperelasticLaw HyperelasticLaw::neo_hookean(double mu) {
  return {Kind::NeoHookean, "neo_hookean", {"mu"}, vector_of({mu})};
}

HyperelasticLaw HyperelasticLaw::mooney_rivlin(double c10, double c01) {
  return {Kind::MooneyRivlin, "mooney_rivlin", {"C10", "C01"}, vector_of({c10, c01})};
}

HyperelasticLaw HyperelasticLaw::yeoh(double c10, double c20, double c30) {
  return {Kind::Yeoh, "yeoh", {"C10", "C20", "C30"}, vector_of({c10, c20, c30})};
}

HyperelasticLaw HyperelasticLaw::ogden(const std::vector<std::pair<double, double>>& terms) {
  if (terms.empty()) throw InputError("an Ogden law needs at least one term (mu_p, alpha_p)");
  Eigen::VectorXd p(2 * static_cast<Eigen::Index>(terms.size()));
  for (size_t k = 0; k < terms.size(); ++k) {
    p[2 * static_cast<Eigen::Index>(k)] = terms[k].first;
    p[2 * static_cast<Eigen::Index>(k) + 1] = terms[k].second;
  }
  return {Kind::Ogden, "ogden" + std::to_string(terms.size()), ogden_names(terms.size()), p};
}

HyperelasticLaw HyperelasticLaw::named(const std::string& name, double mu) {
  if (name == "neo_hookean") return neo_hookean(mu);
  if (name == "mooney_rivlin") return mooney_rivlin(0.5 * mu, 0.0);
  if (name == "yeoh") return yeoh(0.5 * mu, 0.0, 0.0);
  // Ogden's terms start at distinct exponents of both signs, each its share
  // of mu (1/2 sum mu_p alpha_p = mu).
  if (name == "ogden1") return ogden({{mu, 2.0}});
  if (name == "ogden2") return ogden({{0.5 * mu, 2.0}, {-0.5 * mu, -2.0}});
  if (name == "ogden3") return ogden({{mu / 3.0, 2.0}, {mu / 15.0, 5.0}, {-mu / 3.0, -2.0}});
  throw InputError("\"" + name +
                   "\" is not a hyperelastic law (expected neo_hookean, mooney_rivlin, yeoh, "
                   "ogden1, ogden2 or ogden3)");
}

HyperelasticLaw HyperelasticLaw::with_parameters(const Eigen::VectorXd& p) const {
  if (p.size() != p_.size())
    throw std::invalid_argument("HyperelasticLaw::with_parameters: " + std::to_string(p_.size()) +
                                " values expected");
  HyperelasticLaw law = *this;
  law.p_ = p;
  return law;
}

bool HyperelasticLaw::is_modulus(int k) const { return kind_ != Kind::Ogden || k % 2 == 0; }

double HyperelasticLaw::shear_modulus() const {
  switch (kind_) {
    case Kind::NeoHookean:
      return p_[0];
    case Kind::MooneyRivlin:
      return 2.0 * (p_[0] + p_[1]);
    case Kind::Yeoh:
      return 2.0 * p_[0];
    case Kind::Ogden:
      break;
  }
  double mu = 0.0;
  for (Eigen::Index k = 0; k + 1 < p_.size(); k += 2) mu += 0.5 * p_[k] * p_[k + 1];
  return mu;
}

double HyperelasticLaw::energy(const Eigen::Vector3d& l) const {
  const double I1 = l.squaredNorm(), I2 = l.cwiseInverse().squaredNorm();
  switch (kind_) {
    case Kind::NeoHookean:
      return 0.5 * p_[0] * (I1 - 3.0);
    case Kind::MooneyRivlin:
      return p_[0] * (I1 - 3.0) + p_[1] * (I2 - 3.0);
    case Kind::Yeoh: {
      const double e = I1 - 3.0;
      return e * (p_[0] + e * (p_[1] + e * p_[2]));
    }
    case Kind::Ogden:
      break;
  }
  double W = 0.0;
  for (Eigen::Index k = 0; k + 1 < p_.size(); k += 2) {
    const double a = p_[k + 1];
    W += p_[k] / a * (std::pow(l[0], a) + std::pow(l[1], a) + std::pow(l[2], a) - 3.0);
  }
  return W;
}

// With I2 written as sum l_i^-2 (l1 l2 l3 = 1): l_i dI1/dl_i = 2 l_i^2 and
// l_i dI2/dl_i = -2 l_i^-2. (The unconstrained form 2 l_i^2 (I1 - l_i^2)
// differs from it by 2 I2 on every axis: the pressure takes it.)
Eigen::Vector3d HyperelasticLaw::stretch_work(const Eigen::Vector3d& l) const {
  const Eigen::Vector3d l2 = l.cwiseProduct(l);
  const double I1 = l2.sum();
  switch (kind_) {
    case Kind::NeoHookean:
      return p_[0] * l2;
    case Kind::MooneyRivlin:
      return 2.0 * p_[0] * l2 - 2.0 * p_[1] * l2.cwiseInverse();
    case Kind::Yeoh: {
      const double e = I1 - 3.0;
      return 2.0 * (p_[0] + e * (2.0 * p_[1] + 3.0 * e * p_[2])) * l2;
    }
    case Kind::Ogden:
      break;
  }
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  for (Eigen::Index k = 0; k + 1 < p_.size(); k += 2)
    for (int i = 0; i < 3; ++i) t[i] += p_[k] * std::pow(l[i], p_[k + 1]);
  return t;
}

Status HyperelasticLaw::check() const {
  for (Eigen::Index k = 0; k < p_.size(); ++k)
    if (!std::isfinite(p_[k]))
      return Status::failure("the " + name_ + " law's " + names_[static_cast<size_t>(k)] +
                             " is not a finite number");
  if (kind_ == Kind::Ogden)
    for (Eigen::Index k = 1; k < p_.size(); k += 2)
      if (p_[k] == 0.0)
        return Status::failure("the " + name_ + " law's " + names_[static_cast<size_t>(k)] +
                               " is 0: an Ogden term needs a non-zero exponent");
  if (!(shear_modulus() > 0.0))
    return Status::failure("the " + name_ + " law's shear modulus " +
                           std::to_string(shear_modulus()) +
                           " Pa is not positive: no material (check its moduli)");
  return {};
}

const char* to_string(HomogeneousTest test) {
  switch (test) {
    case HomogeneousTest::Uniaxial:
      return "uniaxial";
    case HomogeneousTest::Equibiaxial:
      return "equibiaxial";
    case HomogeneousTest::PureShear:
      return "pure_shear";
  }
  return "?";
}

HomogeneousTest homogeneous_test(const std::string& name) {
  for (HomogeneousTest t :
       {HomogeneousTest::Uniaxial, HomogeneousTest::Equibiaxial, HomogeneousTest::PureShear})
    if (name == to_string(t)) return t;
  throw InputError("\"" + name +
                   "\" is not a homogeneous test (expected uniaxial, equibiaxial "
                   "or pure_shear)");
}

Eigen::Vector3d test_stretches(HomogeneousTest test, double l) {
  switch (test) {
    case HomogeneousTest::Uniaxial:
      return {l, 1.0 / std::sqrt(l), 1.0 / std::sqrt(l)};
    case HomogeneousTest::Equibiaxial:
      return {l, l, 1.0 / (l * l)};
    case HomogeneousTest::PureShear:
      break;
  }
  return {l, 1.0, 1.0 / l};
}

// Axis 3 is free in every test (sigma_3 = 0 gives the pressure), so
// sigma_1 = t_1 - t_3 and the nominal stress is sigma_1 / l.
double nominal_stress(const HyperelasticLaw& law, HomogeneousTest test, double l) {
  const Eigen::Vector3d t = law.stretch_work(test_stretches(test, l));
  return (t[0] - t[2]) / l;
}

}  // namespace fiberfluid::material
