// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The linear-algebra floor's steps report the project's Status (util/status.hpp).

#include "fiberfluid/util/status.hpp"

namespace fiberfluid::linalg {
using fiberfluid::Status;
}  // namespace fiberfluid::linalg
