// SPDX-License-Identifier: GPL-3.0-or-later
// GMRES solves, and each way it can fail is a status with a message, never
// a NaN in x passed on as an answer (issue 11).
#include "fiberfluid/solve/gmres.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <limits>

namespace fiberfluid::solve {
namespace {

LinearOperator matrix(const Eigen::MatrixXd& M) {
  return [M](const Eigen::VectorXd& v) { return Eigen::VectorXd(M * v); };
}
const LinearOperator identity = [](const Eigen::VectorXd& v) { return v; };

void expect_failure(const GmresResult& r, const std::string& part) {
  EXPECT_FALSE(r.status.ok);
  EXPECT_NE(r.status.message.find(part), std::string::npos) << r.status.message;
}

TEST(Gmres, SolvesANonsymmetricSystem) {
  std::srand(3);
  const Eigen::MatrixXd M =
      Eigen::MatrixXd::Random(40, 40) + 40.0 * Eigen::MatrixXd::Identity(40, 40);
  const Eigen::VectorXd b = Eigen::VectorXd::Random(40);
  Eigen::VectorXd x;
  GmresOptions options;
  options.restart = 10;
  const GmresResult r = gmres(matrix(M), identity, b, x, options);
  ASSERT_TRUE(r.status.ok) << r.status.message;
  EXPECT_LT((M * x - b).norm(), 1e-10 * b.norm());
}

// A rotation by 90 degrees: GMRES(1) minimises over x + a b, and b is
// orthogonal to A b, so no restart cycle ever lowers the residual.
TEST(Gmres, StagnationIsNamed) {
  Eigen::MatrixXd rotation(2, 2);
  rotation << 0, -1, 1, 0;
  Eigen::VectorXd x;
  GmresOptions options;
  options.restart = 1;
  const GmresResult r = gmres(matrix(rotation), identity, Eigen::Vector2d(1, 0), x, options);
  expect_failure(
      r, "gmres: stagnation: a restart cycle of 1 iterations left the relative residual at 1");
  EXPECT_LT(r.iterations, 5);  // stopped at once, not after max_iterations
}

TEST(Gmres, TooFewIterationsIsNamed) {
  std::srand(4);
  const Eigen::MatrixXd M =
      Eigen::MatrixXd::Random(30, 30) + 5.0 * Eigen::MatrixXd::Identity(30, 30);
  Eigen::VectorXd x;
  GmresOptions options;
  options.max_iterations = 3;
  expect_failure(gmres(matrix(M), identity, Eigen::VectorXd::Ones(30), x, options),
                 "gmres: no convergence in 3 iterations");
}

TEST(Gmres, BreakdownAndNonFiniteValuesAreNamed) {
  Eigen::VectorXd x;
  const LinearOperator zero = [](const Eigen::VectorXd& v) {
    return Eigen::VectorXd(Eigen::VectorXd::Zero(v.size()));
  };
  expect_failure(gmres(zero, identity, Eigen::Vector3d(1, 2, 3), x, {}), "gmres: breakdown");
  const LinearOperator poisoned = [](const Eigen::VectorXd& v) {
    return Eigen::VectorXd(
        Eigen::VectorXd::Constant(v.size(), std::numeric_limits<double>::quiet_NaN()));
  };
  x.resize(0);
  expect_failure(gmres(identity, poisoned, Eigen::Vector3d(1, 2, 3), x, {}), "gmres: breakdown");
  x = Eigen::Vector3d(std::numeric_limits<double>::infinity(), 0, 0);  // a poisoned start
  expect_failure(gmres(identity, identity, Eigen::Vector3d(1, 2, 3), x, {}),
                 "gmres: the residual is not finite");
}

}  // namespace
}  // namespace fiberfluid::solve
