// SPDX-License-Identifier: GPL-3.0-or-later
// The threaded Cholesky solve behind block-cholesky: it agrees with Eigen's
// LLT on matrices whose sizes straddle its column blocks, for one to three
// right-hand sides in double and single precision, and its bits do not depend
// on the thread count (issue 25).
#include "fiberfluid/solve/cholesky_solve.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Cholesky>

namespace fiberfluid::solve {
namespace {

// A symmetric positive definite matrix, its eigenvalues between 1 and about 5.
Eigen::MatrixXd spd(int n, unsigned seed) {
  std::srand(seed);
  const Eigen::MatrixXd A = Eigen::MatrixXd::Random(n, n);
  return A * A.transpose() / n + Eigen::MatrixXd::Identity(n, n);
}

template <class Scalar>
Eigen::Matrix<Scalar, -1, -1> solved(const Eigen::MatrixXd& K, const Eigen::MatrixXd& B,
                                     int ldx) {
  using Matrix = Eigen::Matrix<Scalar, -1, -1>;
  const Matrix L = Eigen::LLT<Eigen::MatrixXd>(K).matrixL().toDenseMatrix().cast<Scalar>();
  Matrix X = Matrix::Constant(ldx, B.cols(), Scalar(-7));  // rows past n must stay untouched
  X.topRows(B.rows()) = B.cast<Scalar>();
  cholesky_solve_in_place(static_cast<int>(K.rows()), L.data(), X.data(),
                          static_cast<int>(B.cols()), ldx);
  return X;
}

TEST(CholeskySolve, AgreesWithLltAcrossBlockSizes) {
  for (const int n : {1, 2, 7, 63, 64, 65, 129, 300}) {
    const Eigen::MatrixXd K = spd(n, 11 + n);
    for (int nrhs = 1; nrhs <= 3; ++nrhs) {
      const Eigen::MatrixXd B = Eigen::MatrixXd::Random(n, nrhs);
      const Eigen::MatrixXd exact = K.llt().solve(B);
      const int ldx = n + 3;
      const Eigen::MatrixXd x = solved<double>(K, B, ldx);
      EXPECT_LT((x.topRows(n) - exact).norm(), 1e-12 * exact.norm()) << "n " << n;
      EXPECT_TRUE((x.bottomRows(3).array() == -7.0).all());
      const Eigen::MatrixXf xf = solved<float>(K, B, ldx);
      const double single_error = (xf.topRows(n).cast<double>() - exact).norm() / exact.norm();
      EXPECT_LT(single_error, 1e-5) << "n " << n;
      EXPECT_GT(single_error, 0.0) << "n " << n;  // it did run in single precision
    }
  }
}

TEST(CholeskySolve, GivesTheSameBitsOnOneThreadAsOnTwo) {
  const int n = 257;
  const Eigen::MatrixXd K = spd(n, 5);
  const Eigen::MatrixXd B = Eigen::MatrixXd::Random(n, 3);
  const int before = omp_get_max_threads();
  omp_set_num_threads(1);
  const Eigen::MatrixXd one = solved<double>(K, B, n);
  omp_set_num_threads(2);
  const Eigen::MatrixXd two = solved<double>(K, B, n);
  omp_set_num_threads(before);
  EXPECT_TRUE((one.array() == two.array()).all());
}

TEST(CholeskySolve, MoreThanThreeRightHandSidesAreRefused) {
  const double L[1] = {1.0};
  double X[4] = {1, 2, 3, 4};
  EXPECT_THROW(cholesky_solve_in_place(1, L, X, 4, 1), std::invalid_argument);
}

}  // namespace
}  // namespace fiberfluid::solve
