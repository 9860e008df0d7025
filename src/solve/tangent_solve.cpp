// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/solve/tangent_solve.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>

#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/solve/backends.hpp"
#include "fiberfluid/solve/dense_lu.hpp"
#include "fiberfluid/solve/gmres.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::solve {
namespace {

// The most unknowns held beyond the preconditioner's that the capacitance
// correction takes (each costs one preconditioner solve when first held).
constexpr size_t kMostCapacitanceHeld = 256;

// The power of two that brings `largest` nearest 1 (1 for zero or non-finite).
double power_of_two(double largest) {
  return largest > 0.0 && std::isfinite(largest) ? std::exp2(-std::round(std::log2(largest))) : 1.0;
}

// J <- R J C with R, C diagonal powers of two (exact scaling): each row's
// largest entry near 1, then each column's (LAPACK's dgeequ rule).
void equilibrate(Eigen::MatrixXd& J, Eigen::VectorXd* rows, Eigen::VectorXd* columns) {
  *rows = Eigen::VectorXd::Ones(J.rows());
  *columns = Eigen::VectorXd::Ones(J.cols());
  for (Eigen::Index i = 0; i < J.rows(); ++i) {
    (*rows)[i] = power_of_two(J.row(i).cwiseAbs().maxCoeff());
    J.row(i) *= (*rows)[i];
  }
  for (Eigen::Index j = 0; j < J.cols(); ++j) {
    (*columns)[j] = power_of_two(J.col(j).cwiseAbs().maxCoeff());
    J.col(j) *= (*columns)[j];
  }
}

// The same for a sparse J, by its stored entries.
void equilibrate(Eigen::SparseMatrix<double>& J, Eigen::VectorXd* rows, Eigen::VectorXd* columns) {
  Eigen::VectorXd largest = Eigen::VectorXd::Zero(J.rows());
  for (int c = 0; c < J.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(J, c); it; ++it)
      largest[it.row()] = std::max(largest[it.row()], std::abs(it.value()));
  *rows = largest.unaryExpr([](double v) { return power_of_two(v); });
  *columns = Eigen::VectorXd::Ones(J.cols());
  for (int c = 0; c < J.outerSize(); ++c) {
    double column_largest = 0.0;
    for (Eigen::SparseMatrix<double>::InnerIterator it(J, c); it; ++it) {
      it.valueRef() *= (*rows)[it.row()];
      column_largest = std::max(column_largest, std::abs(it.value()));
    }
    (*columns)[c] = power_of_two(column_largest);
    for (Eigen::SparseMatrix<double>::InnerIterator it(J, c); it; ++it)
      it.valueRef() *= (*columns)[c];
  }
}

// The rows and columns of a full-layout sparse J that `dofs` leaves free.
Eigen::SparseMatrix<double> reduce(const model::DofMap& dofs,
                                   const Eigen::SparseMatrix<double>& J) {
  std::vector<int> reduced(static_cast<size_t>(J.rows()), -1);
  const std::vector<int>& full = dofs.full_index();
  for (size_t k = 0; k < full.size(); ++k)
    reduced[static_cast<size_t>(full[k])] = static_cast<int>(k);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<size_t>(J.nonZeros()));
  for (int c = 0; c < J.outerSize(); ++c) {
    const int rc = reduced[static_cast<size_t>(c)];
    if (rc < 0) continue;
    for (Eigen::SparseMatrix<double>::InnerIterator it(J, c); it; ++it) {
      const int rr = reduced[static_cast<size_t>(it.row())];
      if (rr >= 0) entries.emplace_back(rr, rc, it.value());
    }
  }
  const auto n = static_cast<Eigen::Index>(full.size());
  Eigen::SparseMatrix<double> out(n, n);
  out.setFromTriplets(entries.begin(), entries.end());
  return out;
}

}  // namespace

TangentSolve::TangentSolve(std::shared_ptr<const model::Equilibrium> equilibrium,
                           const SteppingOptions& options, TangentSolver kind)
    : equilibrium_(std::move(equilibrium)), options_(options), kind_(kind) {
  // The pair coefficients are stored when they fit in a quarter of the
  // memory budget; else each product recomputes them.
  store_ = equilibrium_->stored_tangent_bytes() < 0.25 * memory_budget_bytes();
  preconditioner_kind_ = kind_ == TangentSolver::Dense || kind_ == TangentSolver::Reused
                             ? SolverKind::DenseLU
                             : options.solver;
  reuses_sparse_lu_ = kind_ == TangentSolver::Reused && equilibrium_->sparse_fibers();
  if (reuses_sparse_lu_) preconditioner_kind_ = options.solver;  // as the sparse tangent's
}

Status TangentSolve::prepare(const Eigen::VectorXd& x, const std::vector<double>& factors,
                             const model::DofMap& dofs, const model::DofMap* preconditioner_dofs) {
  x_ = x;
  factors_ = factors;
  dofs_ = dofs;
  preconditioner_dofs_ = preconditioner_dofs ? *preconditioner_dofs : dofs;
  ready_ = false;
  if (kind_ == TangentSolver::Dense) {
    const Status status = factor_dense_tangent(dofs_);
    if (!status.ok) return Status::failure("newton: the tangent: " + status.message);
  } else if (kind_ == TangentSolver::Sparse) {
    const Status status = factor_sparse_tangent(dofs_);
    ++factorizations_;
    if (!status.ok) return Status::failure("newton: the tangent: " + status.message);
  } else if (kind_ == TangentSolver::Reused) {
    if (store_) equilibrium_->linearize(x_, factors_, stored_);  // reuses the arrays
    if (reused_factor_still_serves()) {
      preconditioner_dofs_ = model::DofMap(dofs_.dim(), dofs_.num_vertices(), preconditioned_held_);
    } else {
      preconditioner_dofs_ = dofs_;
      const Status status = factor_tangent_preconditioner();
      if (!status.ok) return status;
    }
    const Status status = update_capacitance();
    if (!status.ok) return status;
  } else {
    if (store_) equilibrium_->linearize(x_, factors_, stored_);  // reuses the arrays
    const bool same_set =
        preconditioner_ && preconditioner_dofs_.held_flags() == preconditioned_held_;
    if (!same_set || refactor_) {
      const Status status = factor_preconditioner();
      if (!status.ok) return status;
    }
    const Status status = update_capacitance();
    if (!status.ok) return status;
  }
  ready_ = true;
  return {};
}

// The reused factor serves while GMRES converges quickly with it and every
// unknown it holds is still held: the unknowns held since (new contacts, up
// to update_capacitance's limit) are held in its solve by the capacitance
// correction. An unknown released since (a contact let go) would be missing
// from its solve: refactor.
bool TangentSolve::reused_factor_still_serves() const {
  if (!reused_factor_ok_ || refactor_) return false;
  const std::vector<char>& now = dofs_.held_flags();
  if (now.size() != preconditioned_held_.size()) return false;
  size_t added = 0;
  for (size_t d = 0; d < now.size(); ++d) {
    if (preconditioned_held_[d] && !now[d]) return false;
    added += now[d] && !preconditioned_held_[d];
  }
  return added <= kMostCapacitanceHeld;
}

Eigen::VectorXd TangentSolve::residual(const Eigen::VectorXd& x,
                                       const std::vector<double>& factors) {
  if (kind_ == TangentSolver::Dense || kind_ == TangentSolver::Sparse || !store_)
    return equilibrium_->residual(x, factors);
  ready_ = false;  // stored_ now holds the tangent at x
  return equilibrium_->residual(x, factors, stored_);
}

Eigen::VectorXd TangentSolve::apply(const Eigen::VectorXd& reduced) const {
  Eigen::VectorXd w = Eigen::VectorXd::Zero(equilibrium_->num_unknowns());
  dofs_.scatter(reduced, w);  // held entries stay zero
  return dofs_.reduce(store_ ? stored_.apply(w) : equilibrium_->tangent_product(x_, factors_, w));
}

// The held unknowns of the tangent that the preconditioner leaves free (at
// most a few hundred: beyond, they stay free in its solve, as GMRES can
// still cope), with the preconditioner's solve of each one's unit vector
// and the capacitance matrix C = E^T P^-1 E of their rows.
Status TangentSolve::update_capacitance() {
  extra_held_.clear();
  if (preconditioner_dofs_.num_reduced() == dofs_.num_reduced()) return {};
  std::vector<int> position(static_cast<size_t>(equilibrium_->num_unknowns()), -1);
  const std::vector<int>& index = preconditioner_dofs_.full_index();
  for (size_t k = 0; k < index.size(); ++k)
    position[static_cast<size_t>(index[k])] = static_cast<int>(k);
  std::vector<int> dofs;
  for (int d : dofs_.held_dofs())
    if (!preconditioner_dofs_.held(d)) dofs.push_back(d);
  if (dofs.empty() || dofs.size() > kMostCapacitanceHeld) return {};
  // Contacts wander over a long run: the solves of unknowns no longer held
  // go once the cache holds twice the most that are held at once.
  if (unit_solves_.size() > 2 * kMostCapacitanceHeld)
    for (auto it = unit_solves_.begin(); it != unit_solves_.end();)
      it = std::binary_search(dofs.begin(), dofs.end(), it->first) ? std::next(it)
                                                                   : unit_solves_.erase(it);
  const Eigen::Index m = preconditioner_dofs_.num_reduced();
  extra_columns_.resize(m, static_cast<Eigen::Index>(dofs.size()));
  for (size_t c = 0; c < dofs.size(); ++c) {
    auto cached = unit_solves_.find(dofs[c]);
    if (cached == unit_solves_.end()) {
      Eigen::VectorXd unit = Eigen::VectorXd::Zero(m), column;
      unit[position[static_cast<size_t>(dofs[c])]] = 1.0;
      const Status status = preconditioner_solve(unit, &column);
      if (!status.ok) return Status::failure("newton: the preconditioner: " + status.message);
      cached = unit_solves_.emplace(dofs[c], std::move(column)).first;
    }
    extra_columns_.col(static_cast<Eigen::Index>(c)) = cached->second;
  }
  for (int d : dofs) extra_held_.push_back(position[static_cast<size_t>(d)]);
  Eigen::MatrixXd C(extra_held_.size(), extra_held_.size());
  for (size_t r = 0; r < extra_held_.size(); ++r)
    C.row(static_cast<Eigen::Index>(r)) = extra_columns_.row(extra_held_[r]);
  capacitance_.compute(C);
  return {};
}

// The preconditioner's solve, through its own layout when it holds fewer
// unknowns: the tangent's held unknowns enter as zeros, and the capacitance
// correction keeps them at zero in the solution, y = P^-1 b - Z C^-1 (P^-1 b)_H
// with Z = P^-1 E: the solve of the preconditioner's block over the
// tangent's free unknowns alone.
Eigen::VectorXd TangentSolve::precondition(const Eigen::VectorXd& reduced) const {
  const bool same_layout = preconditioner_dofs_.num_reduced() == dofs_.num_reduced();
  Eigen::VectorXd in = reduced;
  if (!same_layout) {
    Eigen::VectorXd full = Eigen::VectorXd::Zero(equilibrium_->num_unknowns());
    dofs_.scatter(reduced, full);
    in = preconditioner_dofs_.reduce(full);
  }
  Eigen::VectorXd out;
  if (!preconditioner_solve(in, &out).ok) return Eigen::VectorXd::Constant(reduced.size(), NAN);
  if (same_layout) return out;
  if (!extra_held_.empty()) {
    Eigen::VectorXd at_held(static_cast<Eigen::Index>(extra_held_.size()));
    for (size_t r = 0; r < extra_held_.size(); ++r)
      at_held[static_cast<Eigen::Index>(r)] = out[extra_held_[r]];
    out -= extra_columns_ * capacitance_.solve(at_held);
  }
  Eigen::VectorXd full = Eigen::VectorXd::Zero(equilibrium_->num_unknowns());
  preconditioner_dofs_.scatter(out, full);
  return dofs_.reduce(full);
}

Status TangentSolve::solve(const Eigen::VectorXd& b, double tolerance, Eigen::VectorXd* y,
                           int* iterations) {
  if (!ready_) return Status::failure("newton: the tangent was not prepared");
  if (kind_ == TangentSolver::Dense) {
    *y = column_scale_.cwiseProduct(lu_->solve(row_scale_.cwiseProduct(b)));
    return {};
  }
  if (kind_ == TangentSolver::Sparse) {
    *y = column_scale_.cwiseProduct(sparse_lu_->solve(row_scale_.cwiseProduct(b)));
    if (!y->allFinite()) return Status::failure("newton: the sparse tangent's solve failed");
    return {};
  }
  const LinearOperator apply_tangent = [this](const Eigen::VectorXd& v) { return apply(v); };
  const LinearOperator precondition = [this](const Eigen::VectorXd& v) {
    return this->precondition(v);
  };
  GmresOptions gmres_options;
  gmres_options.tolerance = tolerance;
  gmres_options.restart = options_.newton.krylov_restart;
  gmres_options.max_iterations = options_.newton.krylov_max_iterations;
  const auto run_gmres = [&] {
    y->resize(0);
    GmresResult run = gmres(apply_tangent, precondition, b, *y, gmres_options);
    if (iterations != nullptr) *iterations += run.iterations;
    return run;
  };
  GmresResult result = run_gmres();
  // The factor ages as the strains move: refactor when gmres needs clearly
  // more iterations per decade of residual reduction than it did just after
  // the last factorisation. A reused tangent LU costs about n / 3 of its own
  // solves (n unknowns; LU 2n^3/3 flops, a solve 2n^2): it is kept while
  // gmres needs at most 10 iterations per decade.
  const double rate = result.iterations / std::max(1.0, -std::log10(tolerance));
  const double floor = kind_ == TangentSolver::Reused ? 10.0 : 0.0;
  if (baseline_rate_ < 0.0)
    baseline_rate_ = rate;
  else if (rate > std::max(2.0 * baseline_rate_ + 1.0, floor))
    refactor_ = true;
  // A failure with an aged factor refactors and tries again. One just after a
  // factorisation is final, unless that factor was rounded to single
  // precision: then it and the rest of the run's are factored in double.
  while (!result.status.ok) {
    const bool rounded = kind_ == TangentSolver::Reused && lu_ && lu_->single();
    if (just_factored_ && !rounded) break;
    if (just_factored_) single_factor_ = false;
    if (kind_ == TangentSolver::Reused) preconditioner_dofs_ = dofs_;
    Status status =
        kind_ == TangentSolver::Reused ? factor_tangent_preconditioner() : factor_preconditioner();
    if (status.ok) status = update_capacitance();
    if (!status.ok) return status;
    result = run_gmres();
  }
  just_factored_ = false;
  return result.status.ok ? Status{} : Status::failure("newton: " + result.status.message);
}

Status TangentSolve::solve_full(const Eigen::VectorXd& b, Eigen::VectorXd* y, double tolerance) {
  Eigen::VectorXd reduced;
  const Status status = solve(dofs_.reduce(b), tolerance, &reduced);
  if (!status.ok) return status;
  *y = Eigen::VectorXd::Zero(b.size());
  dofs_.scatter(reduced, *y);
  return {};
}

Status TangentSolve::preconditioner_solve(const Eigen::VectorXd& in, Eigen::VectorXd* out) const {
  if (kind_ != TangentSolver::Reused) return preconditioner_->solve(in, out);
  const Eigen::VectorXd scaled = row_scale_.cwiseProduct(in);
  *out = column_scale_.cwiseProduct(reuses_sparse_lu_ ? sparse_lu_->solve(scaled)
                                                      : lu_->solve(scaled));
  return out->allFinite() ? Status{} : Status::failure("the tangent's LU solve is not finite");
}

// The reused preconditioner: the equilibrated LU of the exact tangent at the
// current state over the current held set; sparse for a horizon's lists,
// whose dense tangent would be mostly zeros.
Status TangentSolve::factor_tangent_preconditioner() {
  reused_factor_ok_ = false;
  // Only a preconditioner, so the dense factor may be single precision:
  // GMRES restores the exact step from the rounded one.
  const Status status = reuses_sparse_lu_
                            ? factor_sparse_tangent(preconditioner_dofs_)
                            : factor_dense_tangent(preconditioner_dofs_, single_factor_);
  if (!status.ok) return Status::failure("newton: the tangent: " + status.message);
  reused_factor_ok_ = true;
  note_new_factor();
  return {};
}

// The equilibrated LU of the exact tangent at x_ over the unknowns `dofs`
// leaves free, dense (LAPACK; its factors rounded to single precision when
// asked and DenseLU's check allows) or sparse (UMFPACK, its symbolic analysis
// kept while the pattern stays).
Status TangentSolve::factor_dense_tangent(const model::DofMap& dofs, bool single) {
  Eigen::MatrixXd J = dofs.reduce(equilibrium_->tangent(x_, factors_));
  equilibrate(J, &row_scale_, &column_scale_);
  lu_ = std::make_unique<DenseLU>();
  const Status status = lu_->factorize(std::move(J));
  if (status.ok && single && lu_->round_to_single()) ++single_precision_factorizations_;
  return status;
}

Status TangentSolve::factor_sparse_tangent(const model::DofMap& dofs) {
  Eigen::SparseMatrix<double> J = reduce(dofs, equilibrium_->sparse_tangent(x_, factors_));
  equilibrate(J, &row_scale_, &column_scale_);
  if (!sparse_lu_) sparse_lu_ = std::make_unique<SparseLU>();
  return sparse_lu_->factorize(J);
}

Status TangentSolve::factor_preconditioner() {
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
  if (!preconditioner_ || !(preconditioner_dofs_.held_flags() == preconditioned_held_)) {
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

void TangentSolve::note_new_factor() {
  ++factorizations_;
  unit_solves_.clear();  // solves with the factor replaced
  preconditioned_held_ = preconditioner_dofs_.held_flags();
  baseline_rate_ = -1.0;
  refactor_ = false;
  just_factored_ = true;
}

}  // namespace fiberfluid::solve
