// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The solvers' status is the linear-algebra floor's (linalg/status.hpp),
// which the FEM shares.

#include "fiberfluid/linalg/status.hpp"

namespace fiberfluid::solve {
using linalg::Status;
}  // namespace fiberfluid::solve
