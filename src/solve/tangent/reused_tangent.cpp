// SPDX-License-Identifier: GPL-3.0-or-later
// The reused tangent: GMRES on the tangent, right-preconditioned by the LU
// of the tangent at an earlier state (a modified Newton's factor, whose
// GMRES restores the exact Newton step): dense, its factors rounded to
// single precision where that serves, or sparse where the fibers are a
// horizon's lists, whose dense tangent would be mostly zeros.
#include "fiberfluid/solve/tangent/krylov_tangent.hpp"
#include "fiberfluid/solve/tangent/strategies.hpp"
#include "fiberfluid/solve/tangent/tangent_lu.hpp"

namespace fiberfluid::solve {
namespace {

// A reused tangent LU ages over the steps between its factorisations: 9 to
// 16 GMRES products per Newton iteration (issue 42's specimens: the
// compressed cylinder 10 and 9, the bending phantoms 12 and 16).
constexpr double kReusedKrylovProducts = 12.0;
// A reused tangent LU costs about n / 3 of its own solves (n unknowns; LU
// 2n^3/3 flops, a solve 2n^2): it is kept while GMRES needs at most 10
// iterations per decade.
constexpr double kKeptWhileIterationsPerDecade = 10.0;

class ReusedTangent final : public KrylovTangent {
 public:
  ReusedTangent(SharedEquilibrium equilibrium, const SteppingOptions& options, bool sparse)
      : KrylovTangent(std::move(equilibrium), options, TangentSolver::Reused,
                      sparse ? options.solver : SolverKind::DenseLU, kKeptWhileIterationsPerDecade),
        lu_(sparse ? TangentLU::Storage::Sparse : TangentLU::Storage::Dense) {}

 private:
  Status keep_or_refactor() override {
    if (factor_still_serves()) {
      preconditioner_dofs_ =
          model::DofMap(dofs_.dim(), dofs_.num_vertices(), preconditioned_held());
      return {};
    }
    return refactor();
  }
  // A failure just after a factorisation whose factors were rounded to
  // single precision: this one and the rest of the run's are factored in double.
  bool retry_with_fresh_factor() override {
    if (!lu_.rounded_to_single()) return false;
    single_factor_ = false;
    return true;
  }
  Status refactor() override {
    preconditioner_dofs_ = dofs_;
    return factor_tangent();
  }
  Status preconditioner_solve(const Eigen::VectorXd& in, Eigen::VectorXd* out) const override {
    *out = lu_.solve(in);
    return out->allFinite() ? Status{} : Status::failure("the tangent's LU solve is not finite");
  }
  bool factor_still_serves() const;
  Status factor_tangent();

  TangentLU lu_;
  bool factor_ok_ = false;  // the last factorisation succeeded (and is current)
  // The dense factor is rounded to single precision until GMRES fails just
  // after such a factorisation.
  bool single_factor_ = true;
};

// The factor serves while GMRES converges quickly with it and every unknown
// it holds is still held: the unknowns held since (new contacts, up to the
// capacitance correction's limit) are held in its solve by that correction.
// An unknown released since (a contact let go) would be missing from its
// solve: refactor.
bool ReusedTangent::factor_still_serves() const {
  if (!factor_ok_ || refactor_requested()) return false;
  const std::vector<char>& now = dofs_.held_flags();
  const std::vector<char>& factored = preconditioned_held();
  if (now.size() != factored.size()) return false;
  size_t added = 0;
  for (size_t d = 0; d < now.size(); ++d) {
    if (factored[d] && !now[d]) return false;
    added += now[d] && !factored[d];
  }
  return added <= kMostCapacitanceHeld;
}

// The equilibrated LU of the exact tangent at the current state over the
// current held set. Only a preconditioner, so the dense factor may be single
// precision: GMRES restores the exact step from the rounded one.
Status ReusedTangent::factor_tangent() {
  factor_ok_ = false;
  const Status status =
      lu_.factor(*equilibrium_, x_, factors_, preconditioner_dofs_, added_, single_factor_);
  if (!status.ok) return Status::failure("newton: the tangent: " + status.message);
  if (single_factor_ && lu_.rounded_to_single()) ++single_precision_factorizations_;
  factor_ok_ = true;
  note_new_factor();
  return {};
}

}  // namespace

std::unique_ptr<TangentSolve> make_reused_tangent(SharedEquilibrium e, const SteppingOptions& o) {
  const bool sparse = e->sparse_fibers();
  return std::make_unique<ReusedTangent>(std::move(e), o, sparse);
}

// The factor about once in four load steps (issue 42: 9 and 12 for the
// compressed cylinder's 40 steps, 1 for the bending phantom's 10). A dense
// one has its factors rounded to single precision (where that serves, as on
// every specimen measured): a solve reads 4 bytes an entry.
TangentCost reused_tangent_cost(const TangentCostCase& c, const KernelSpeed& speed) {
  const double factorizations = 1.0 + 0.25 * c.steps;
  if (c.sparse_fibers) {
    const SparseLUCost lu = sparse_tangent_lu_cost(c.vertices, c.dim, c.pairs);
    return krylov_cost(c, factorizations, lu.factor_seconds, lu.bytes, lu.solve_seconds,
                       kReusedKrylovProducts);
  }
  const double m = c.newton_unknowns;
  return krylov_cost(c, factorizations, c.factor.factor_seconds, c.factor.factor_bytes,
                     4.0 * m * m / speed.factor_bytes_read_per_second, kReusedKrylovProducts);
}

}  // namespace fiberfluid::solve
