// SPDX-License-Identifier: GPL-3.0-or-later
// pcg: conjugate gradients on K (the Schur complement takes P) that never
// stores the dense bulk block: products are computed pair by pair. The
// preconditioner is the sparse part of each block, the surface-tension
// Laplacian plus the bulk diagonal, factored by CHOLMOD (model.md section 5).
#include <cmath>
#include <sstream>
#include <vector>

#include "fiberfluid/solve/backends.hpp"
#include "fiberfluid/solve/schur_solver.hpp"
#include "fiberfluid/solve/sparse_cholesky.hpp"
#include "fiberfluid/util/progress.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::solve {
namespace {

class PcgSolver final : public SchurSolver {
 public:
  explicit PcgSolver(const PcgOptions& options) : options_(options) {}
  SolverKind kind() const override { return SolverKind::PCG; }

  Status analyze_pattern(const model::BorderedSystem&) override {
    if (!(options_.tolerance > 0.0) || options_.max_iterations < 1)
      return Status::failure("pcg: the tolerance must be positive and max_iterations at least 1");
    return {};
  }

 protected:
  Status factorize_K(const model::BorderedSystem& system) override {
    system_ = &system;
    const int count = system.blocks_equal() ? 1 : system.num_blocks();
    preconditioners_.resize(static_cast<size_t>(count));
    offsets_ = system.block_offsets();
    for (int a = 0; a < count; ++a) {
      const Status status =
          preconditioners_[static_cast<size_t>(a)].factorize(system.preconditioner_block(a));
      if (!status.ok)
        return Status::failure("pcg: the preconditioner of " + system.block_name(a) + ": " +
                               status.message);
    }
    return {};
  }

  Status solve_K(const Eigen::VectorXd& f, Eigen::VectorXd* w) override {
    *w = Eigen::VectorXd::Zero(f.size());
    if (!f.allFinite()) return Status::failure("pcg: the right-hand side is not finite");
    const double norm_f = f.stableNorm();  // no overflow of the squares
    if (norm_f == 0.0) return {};
    Eigen::VectorXd r = f, z = precondition(r), p = z;
    double rz = r.dot(z);
    for (int it = 1; it <= options_.max_iterations; ++it) {
      const Eigen::VectorXd q = system_->apply_K(p);
      const double pq = p.dot(q);
      if (!std::isfinite(pq))
        return Status::failure("pcg: a product with the matrix is not finite at iteration " +
                               std::to_string(it));
      if (!(pq > 0.0))
        return Status::failure(
            "pcg: the system is not positive definite (p.Kp = " + std::to_string(pq) + ")");
      const double alpha = rz / pq;
      *w += alpha * p;
      r -= alpha * q;
      ++statistics_.iterations;
      report_progress("pcg iteration", it, 0.0);
      const double residual = r.stableNorm();
      if (residual <= options_.tolerance * norm_f) return {};
      if (!std::isfinite(residual))
        return Status::failure("pcg: the residual is not finite at iteration " +
                               std::to_string(it));
      if (cancel_requested())
        return Status::failure("pcg: interrupted at iteration " + std::to_string(it));
      z = precondition(r);
      const double rz_next = r.dot(z);
      p = z + (rz_next / rz) * p;
      rz = rz_next;
    }
    std::ostringstream out;
    out << "pcg: no convergence in " << options_.max_iterations << " iterations (relative residual "
        << r.norm() / norm_f << " > tolerance " << options_.tolerance << ")";
    return Status::failure(out.str());
  }

 private:
  Eigen::VectorXd precondition(const Eigen::VectorXd& r) const {
    Eigen::VectorXd z(r.size());
    for (size_t a = 0; a + 1 < offsets_.size(); ++a) {
      const int n = offsets_[a + 1] - offsets_[a];
      if (n == 0) continue;
      const SparseCholesky& M = preconditioners_[preconditioners_.size() == 1 ? 0 : a];
      z.segment(offsets_[a], n) = M.solve(r.segment(offsets_[a], n));
    }
    return z;
  }

  PcgOptions options_;
  const model::BorderedSystem* system_ = nullptr;
  std::vector<SparseCholesky> preconditioners_;
  std::vector<int> offsets_;
};

}  // namespace

std::unique_ptr<LinearSolver> make_pcg_solver(const PcgOptions& options) {
  return std::make_unique<PcgSolver>(options);
}

}  // namespace fiberfluid::solve
