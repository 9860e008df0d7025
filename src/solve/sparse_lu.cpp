// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/solve/sparse_lu.hpp"

#include <umfpack.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace fiberfluid::solve {

struct SparseLU::Impl {
  Eigen::SparseMatrix<double> A;                  // compressed, column-major: UMFPACK's layout
  std::vector<int> pattern_outer, pattern_inner;  // of the analysed pattern
  void* symbolic = nullptr;
  void* numeric = nullptr;
  double control[UMFPACK_CONTROL];
  double info[UMFPACK_INFO];
  double rcond = 0.0, entries = 0.0;

  Impl() {
    umfpack_di_defaults(control);
    // The tangent's pattern is symmetric (each pair's block both ways, the
    // pressure's row and column): UMFPACK's symmetric strategy orders A + A^T,
    // and METIS's nested dissection keeps the fill of a surface's
    // neighbourhood graph far below AMD's.
    control[UMFPACK_STRATEGY] = UMFPACK_STRATEGY_SYMMETRIC;
    control[UMFPACK_ORDERING] = UMFPACK_ORDERING_METIS;
    for (double& v : info) v = 0.0;
  }
  ~Impl() { release(); }
  void release() {
    if (numeric != nullptr) umfpack_di_free_numeric(&numeric);
    if (symbolic != nullptr) umfpack_di_free_symbolic(&symbolic);
    numeric = symbolic = nullptr;
  }
  bool same_pattern() const {
    if (symbolic == nullptr || pattern_outer.size() != static_cast<size_t>(A.outerSize() + 1) ||
        pattern_inner.size() != static_cast<size_t>(A.nonZeros()))
      return false;
    for (size_t k = 0; k < pattern_outer.size(); ++k)
      if (pattern_outer[k] != A.outerIndexPtr()[k]) return false;
    for (size_t k = 0; k < pattern_inner.size(); ++k)
      if (pattern_inner[k] != A.innerIndexPtr()[k]) return false;
    return true;
  }
};

SparseLU::SparseLU() : impl_(std::make_unique<Impl>()) {}
SparseLU::~SparseLU() = default;
SparseLU::SparseLU(SparseLU&&) noexcept = default;
SparseLU& SparseLU::operator=(SparseLU&&) noexcept = default;

Status SparseLU::factorize(const Eigen::SparseMatrix<double>& A) {
  Impl& m = *impl_;
  if (A.rows() != A.cols()) return Status::failure("sparse LU: the matrix is not square");
  m.A = A;
  m.A.makeCompressed();
  const int n = static_cast<int>(m.A.rows());
  if (m.numeric != nullptr) umfpack_di_free_numeric(&m.numeric);
  m.numeric = nullptr;
  if (!m.same_pattern()) {
    if (m.symbolic != nullptr) umfpack_di_free_symbolic(&m.symbolic);
    m.symbolic = nullptr;
    const int status = umfpack_di_symbolic(n, n, m.A.outerIndexPtr(), m.A.innerIndexPtr(),
                                           m.A.valuePtr(), &m.symbolic, m.control, m.info);
    if (status != UMFPACK_OK)
      return Status::failure("sparse LU: UMFPACK's analysis failed (status " +
                             std::to_string(status) + ")");
    m.pattern_outer.assign(m.A.outerIndexPtr(), m.A.outerIndexPtr() + n + 1);
    m.pattern_inner.assign(m.A.innerIndexPtr(), m.A.innerIndexPtr() + m.A.nonZeros());
  }
  const int status = umfpack_di_numeric(m.A.outerIndexPtr(), m.A.innerIndexPtr(), m.A.valuePtr(),
                                        m.symbolic, &m.numeric, m.control, m.info);
  m.rcond = m.info[UMFPACK_RCOND];
  m.entries = m.info[UMFPACK_LNZ] + m.info[UMFPACK_UNZ];
  if (status < 0)
    return Status::failure(status == UMFPACK_ERROR_out_of_memory
                               ? std::string("sparse LU: out of memory")
                               : "sparse LU: UMFPACK's factorisation failed (status " +
                                     std::to_string(status) + ")");
  if (status == UMFPACK_WARNING_singular_matrix ||
      !(m.rcond >= 10.0 * std::numeric_limits<double>::epsilon()))
    return Status::failure(
        "the matrix is numerically singular (UMFPACK's reciprocal condition "
        "estimate " +
        std::to_string(m.rcond) + ")");
  return {};
}

Eigen::VectorXd SparseLU::solve(const Eigen::VectorXd& b) const {
  const Impl& m = *impl_;
  Eigen::VectorXd x(b.size());
  double info[UMFPACK_INFO];
  const int status =
      umfpack_di_solve(UMFPACK_A, m.A.outerIndexPtr(), m.A.innerIndexPtr(), m.A.valuePtr(),
                       x.data(), b.data(), m.numeric, m.control, info);
  if (status != UMFPACK_OK) x.setConstant(std::numeric_limits<double>::quiet_NaN());
  return x;
}

double SparseLU::reciprocal_condition() const { return impl_->rcond; }
double SparseLU::factor_entries() const { return impl_->entries; }

}  // namespace fiberfluid::solve
