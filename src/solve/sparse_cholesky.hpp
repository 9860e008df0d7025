// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// CHOLMOD's sparse Cholesky lives on the linear-algebra floor
// (linalg/sparse_cholesky.hpp), which the FEM shares.

#include "fiberfluid/linalg/sparse_cholesky.hpp"

namespace fiberfluid::solve {
using linalg::SparseCholesky;
}  // namespace fiberfluid::solve
