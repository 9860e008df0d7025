// SPDX-License-Identifier: GPL-3.0-or-later
// The secant-preconditioned Krylov tangent (kind "krylov"): GMRES on the
// tangent, preconditioned by the structured secant solve, the reference
// bordered system with each bulk weight times Y(e_ij); for central fibers
// each axis block's weights also times that axis's share of the fiber's
// direction. Its factor is the structured backend's, so it scales as the
// linear scheme does.
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/fiber_system.hpp"
#include "fiberfluid/solve/backends.hpp"
#include "fiberfluid/solve/tangent/krylov_tangent.hpp"
#include "fiberfluid/solve/tangent/strategies.hpp"

namespace fiberfluid::solve {
namespace {

// Typical GMRES products per Newton iteration (scripts/resources.sh: the
// sphere's Newton steps).
constexpr double kKrylovProducts = 6.0;

class SecantKrylov final : public KrylovTangent {
 public:
  SecantKrylov(SharedEquilibrium equilibrium, const SteppingOptions& options)
      : KrylovTangent(std::move(equilibrium), options, TangentSolver::Krylov, options.solver,
                      /*refresh_floor=*/0.0) {}

 private:
  Status keep_or_refactor() override {
    const bool same_set =
        preconditioner_ && preconditioner_dofs_.held_flags() == preconditioned_held();
    return !same_set || refactor_requested() ? factor_preconditioner() : Status{};
  }
  Status refactor() override { return factor_preconditioner(); }
  Status preconditioner_solve(const Eigen::VectorXd& in, Eigen::VectorXd* out) const override {
    return preconditioner_->solve(in, out);
  }
  Status factor_preconditioner();

  std::unique_ptr<model::FiberSystem> secant_;
  std::unique_ptr<LinearSolver> preconditioner_;
};

Status SecantKrylov::factor_preconditioner() {
  const model::Model& model = equilibrium_->model();
  const Eigen::MatrixXd X = model::positions(model, x_);
  secant_ = std::make_unique<model::FiberSystem>(model, model.surface.V, preconditioner_dofs_,
                                                 model::BoundaryMethod::Elimination,
                                                 options_.penalty, &X);
  // A central fiber resists only along itself: each axis block keeps the
  // share of that axis in each fiber's current direction (separate
  // displacement components; Blaheta 1994), not the vector spring's
  // isotropic weight, which leaves GMRES stalling on a central tangent.
  if (model.material.kinematics == model::FiberKinematics::Central) secant_->project_on_axes(X);
  if (!preconditioner_ || !(preconditioner_dofs_.held_flags() == preconditioned_held())) {
    // By size as for the linear scheme, but never the dense LU of the whole
    // bordered system: block Cholesky does the same job in a fraction of the flops.
    SolverKind kind =
        options_.solver == SolverKind::Auto ? choose_solver(*secant_) : options_.solver;
    if (options_.solver == SolverKind::Auto && kind == SolverKind::DenseLU)
      kind = SolverKind::BlockCholesky;
    // Block Cholesky in single precision: a preconditioner needs no more
    // digits (GMRES keeps the tangent's), and it halves the factor's memory
    // and the time of its factorisation and of every solve with it.
    preconditioner_ = kind == SolverKind::BlockCholesky ? make_block_cholesky_solver(true)
                                                        : make_linear_solver(kind, options_.pcg);
    preconditioner_kind_ = kind;
    const Status status = preconditioner_->analyze_pattern(*secant_);
    if (!status.ok) return status;
  }
  Status status = preconditioner_->factorize(*secant_);
  if (!status.ok && preconditioner_kind_ == SolverKind::BlockCholesky) {
    // Not positive definite in single precision (a stiff, badly scaled
    // secant): the same in double.
    preconditioner_ = make_block_cholesky_solver(false);
    status = preconditioner_->analyze_pattern(*secant_);
    if (status.ok) status = preconditioner_->factorize(*secant_);
  }
  if (!status.ok) return Status::failure("newton: the preconditioner: " + status.message);
  note_new_factor();
  return {};
}

}  // namespace

std::unique_ptr<TangentSolve> make_secant_krylov(SharedEquilibrium e, const SteppingOptions& o) {
  return std::make_unique<SecantKrylov>(std::move(e), o);
}

// The structured backend's factor once per load step and its solve in every
// GMRES product.
TangentCost secant_krylov_cost(const TangentCostCase& c, const KernelSpeed&) {
  return krylov_cost(c, c.steps, c.factor.factor_seconds, c.factor.factor_bytes,
                     c.factor.solve_seconds, kKrylovProducts);
}

}  // namespace fiberfluid::solve
