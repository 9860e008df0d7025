// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <string>
#include <utility>

namespace fiberfluid::linalg {

// The outcome of a numerical step that can fail on valid input (a matrix
// that is not positive definite, no convergence): a status and a message.
struct Status {
  bool ok = true;
  std::string message;
  static Status failure(std::string why) { return {false, std::move(why)}; }
};

}  // namespace fiberfluid::linalg
