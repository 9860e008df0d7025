// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <string>
#include <utility>

namespace fiberfluid {

// The one shape of an outcome that can be "fine" or "not, because ...": a
// numerical step that can fail on valid input (a matrix that is not positive
// definite, no convergence) and every check of a setup, a name or a state
// (check_setup, check_folder_name, check_no_runaway, ...). The message says
// what went wrong and, for a check, what was expected; it is empty when ok.
struct Status {
  bool ok = true;
  std::string message;
  static Status failure(std::string why) { return {false, std::move(why)}; }
};

}  // namespace fiberfluid
