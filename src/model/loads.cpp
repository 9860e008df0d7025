// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/model/loads.hpp"

#include <cassert>
#include <stdexcept>
#include <string>

#include "fiberfluid/geom/area_vectors.hpp"

namespace fiberfluid::model {

double Schedule::factor(int step, int steps) const {
  assert(steps >= 1 && step >= 0 && step <= steps);
  if (step == 0) return 0.0;
  switch (kind) {
    case Kind::Ramp:
      return static_cast<double>(step) / steps;
    case Kind::Final:
      return step == steps ? 1.0 : 0.0;
    case Kind::UpDown: {
      const double half = steps / 2.0;
      return step <= half ? step / half : (steps - step) / half;
    }
    case Kind::Table:
      return values.at(static_cast<size_t>(step - 1));
  }
  return 0.0;
}

double hydrostatic_level(const Eigen::MatrixXd& X, const Eigen::Vector3d& acceleration) {
  const double magnitude = acceleration.norm();
  if (magnitude == 0.0 || X.rows() == 0) return 0.0;
  return (X * (acceleration.head(X.cols()) / magnitude)).minCoeff();
}

Eigen::VectorXd hydrostatic_heads(const Eigen::MatrixXd& X, const Eigen::Vector3d& acceleration,
                                  double level) {
  const double magnitude = acceleration.norm();
  if (magnitude == 0.0) return Eigen::VectorXd::Zero(X.rows());
  const Eigen::VectorXd along = X * (acceleration.head(X.cols()) / magnitude);
  return along.array() - level;
}

Eigen::VectorXd hydrostatic_depths(const Eigen::MatrixXd& X, const Eigen::Vector3d& acceleration) {
  return hydrostatic_heads(X, acceleration, hydrostatic_level(X, acceleration));
}

double hydrostatic_pressure_per_depth(const Load& load, double factor) {
  return factor * load.density * load.acceleration.norm();
}

Eigen::MatrixXd exact_pressure_forces(const Eigen::MatrixXd& X, const Eigen::MatrixXi& F,
                                      const Eigen::VectorXd& q) {
  const Eigen::MatrixXd A = geom::face_area_vectors(X, F);
  const ExactFaceShares shares(F, q);
  Eigen::MatrixXd forces = Eigen::MatrixXd::Zero(X.rows(), X.cols());
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (Eigen::Index k = 0; k < F.cols(); ++k)
      forces.row(F(f, k)) += shares.w(F(f, k), f) * A.row(f);
  return forces;
}

ExactFaceShares::ExactFaceShares(const Eigen::MatrixXi& F, const Eigen::VectorXd& q_)
    : q(q_),
      face_sum(Eigen::VectorXd::Zero(F.rows())),
      per_pressure(1.0 / static_cast<double>(F.cols() * (F.cols() + 1))) {
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (Eigen::Index k = 0; k < F.cols(); ++k) face_sum[f] += q[F(f, k)];
}

Eigen::VectorXd load_vector(const Model& model, const Eigen::MatrixXd& X, const Eigen::MatrixXd& S,
                            const std::vector<double>& factors) {
  const int n = model.num_vertices(), dim = model.dim();
  Eigen::VectorXd B = Eigen::VectorXd::Zero(model.num_unknowns());
  for (size_t l = 0; l < model.loads.size(); ++l) {
    const Load& load = model.loads[l];
    const double f = factors[l];
    if (f == 0.0) continue;
    switch (load.kind) {
      case Load::Kind::Point:
        for (int a = 0; a < dim; ++a) B[model.dof(load.vertex, a)] += f * load.force[a];
        continue;
      case Load::Kind::Hydrostatic: {
        // Outward on each vertex, rho |a| h_i S_i (hydrostatic_heads).
        const double scale = hydrostatic_pressure_per_depth(load, f);
        const Eigen::VectorXd h = hydrostatic_depths(X, load.acceleration);
        if (load.integration == Load::Integration::Exact) {
          const Eigen::MatrixXd forces = exact_pressure_forces(X, model.surface.F, scale * h);
          for (int a = 0; a < dim; ++a) B.segment(a * n, n) += forces.col(a);
        } else {
          for (int a = 0; a < dim; ++a) B.segment(a * n, n) += scale * h.cwiseProduct(S.col(a));
        }
        continue;
      }
    }
    throw std::invalid_argument("load " + std::to_string(l) + " is of an unknown kind");
  }
  return B;
}

std::vector<double> load_factors(const Model& model, int step, int steps) {
  std::vector<double> factors;
  for (const Load& load : model.loads) factors.push_back(load.schedule.factor(step, steps));
  return factors;
}

}  // namespace fiberfluid::model
