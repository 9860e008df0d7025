// SPDX-License-Identifier: GPL-3.0-or-later
// What this build of fiberfluid is: its version, compiler and build type, the
// threads it runs on, and the libraries behind its solvers (for `--version`
// and summary.json, so that a result says what produced it).
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace fiberfluid::experiment {

// The program's version ("0.1.0").
std::string program_version();

// (name, value) pairs in a fixed order: version, compiler, build type,
// sanitizers, OpenMP threads, LAPACK/BLAS libraries, SuiteSparse, Eigen,
// CGAL, Ceres, NLopt.
std::vector<std::pair<std::string, std::string>> build_info();

}  // namespace fiberfluid::experiment
