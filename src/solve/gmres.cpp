// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/solve/gmres.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::solve {

GmresResult gmres(const LinearOperator& A, const LinearOperator& preconditioner,
                  const Eigen::VectorXd& b, Eigen::VectorXd& x, const GmresOptions& options) {
  GmresResult result;
  if (x.size() != b.size()) x = Eigen::VectorXd::Zero(b.size());
  const double norm_b = b.norm();
  if (norm_b == 0.0) {
    x.setZero();
    return result;
  }
  const int m = std::max(1, options.restart);
  double previous = std::numeric_limits<double>::infinity();  // the last restart's residual
  while (true) {
    Eigen::VectorXd r = b - A(x);
    double beta = r.norm();
    result.relative_residual = beta / norm_b;
    if (!std::isfinite(beta)) {
      result.status = Status::failure("gmres: the residual is not finite");
      return result;
    }
    if (result.relative_residual <= options.tolerance) return result;
    if (result.iterations >= options.max_iterations) break;
    if (cancel_requested()) {
      result.status = Status::failure("gmres: interrupted after " +
                                      std::to_string(result.iterations) + " iterations");
      return result;
    }
    // A whole restart cycle that did not lower the residual will not on the
    // next one either (the same Krylov space): stagnation, not slow progress.
    if (!(beta < previous * (1.0 - 1e-12))) {
      std::ostringstream out;
      out << "gmres: stagnation: a restart cycle of " << m << " iterations left the relative "
          << "residual at " << result.relative_residual << " (tolerance " << options.tolerance
          << "); a larger restart or a better preconditioner may help";
      result.status = Status::failure(out.str());
      return result;
    }
    previous = beta;
    // Arnoldi with modified Gram-Schmidt; Givens rotations keep the small
    // least-squares problem triangular.
    std::vector<Eigen::VectorXd> V{r / beta}, Z;
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(m + 1, m);
    Eigen::VectorXd g = Eigen::VectorXd::Zero(m + 1), cs(m), sn(m);
    g[0] = beta;
    int k = 0;
    for (; k < m && result.iterations < options.max_iterations; ++k) {
      ++result.iterations;
      Z.push_back(preconditioner(V[static_cast<size_t>(k)]));
      Eigen::VectorXd w = A(Z.back());
      for (int i = 0; i <= k; ++i) {
        H(i, k) = w.dot(V[static_cast<size_t>(i)]);
        w -= H(i, k) * V[static_cast<size_t>(i)];
      }
      H(k + 1, k) = w.norm();
      for (int i = 0; i < k; ++i) {
        const double t = cs[i] * H(i, k) + sn[i] * H(i + 1, k);
        H(i + 1, k) = -sn[i] * H(i, k) + cs[i] * H(i + 1, k);
        H(i, k) = t;
      }
      const double rho = std::hypot(H(k, k), H(k + 1, k));
      if (!(rho > 0.0) || !std::isfinite(rho)) {
        result.status = Status::failure(
            "gmres: breakdown (the operator or preconditioner "
            "gave a zero or non-finite vector)");
        return result;
      }
      cs[k] = H(k, k) / rho;
      sn[k] = H(k + 1, k) / rho;
      H(k, k) = rho;
      H(k + 1, k) = 0.0;
      g[k + 1] = -sn[k] * g[k];
      g[k] = cs[k] * g[k];
      if (std::abs(g[k + 1]) / norm_b <= options.tolerance) {
        ++k;
        break;
      }
      V.push_back(w / w.norm());  // w != 0 here: else g[k + 1] = 0 ended the loop
    }
    // x += Z y with H(0:k, 0:k) y = g(0:k).
    const Eigen::VectorXd y = H.topLeftCorner(k, k).triangularView<Eigen::Upper>().solve(g.head(k));
    for (int i = 0; i < k; ++i) x += y[i] * Z[static_cast<size_t>(i)];
  }
  std::ostringstream out;
  out << "gmres: no convergence in " << result.iterations << " iterations (relative residual "
      << result.relative_residual << ", tolerance " << options.tolerance << ")";
  result.status = Status::failure(out.str());
  return result;
}

}  // namespace fiberfluid::solve
