// SPDX-License-Identifier: GPL-3.0-or-later
// Factories of the linear backends; make_linear_solver() picks among them.
#pragma once

#include <memory>

#include "fiberfluid/solve/linear_solver.hpp"

namespace fiberfluid::solve {

std::unique_ptr<LinearSolver> make_dense_lu_solver();
// single_precision: the factors in float (a preconditioner's: half the
// memory and time; its solves then hold about 7 digits).
std::unique_ptr<LinearSolver> make_block_cholesky_solver(bool single_precision = false);
std::unique_ptr<LinearSolver> make_cholmod_solver();
std::unique_ptr<LinearSolver> make_pcg_solver(const PcgOptions& options);

}  // namespace fiberfluid::solve
