// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <stdexcept>
#include <string>

namespace fiberfluid {

// Bad input (a mesh file, a mesh, an experiment file): the message names the
// file, line or field and says what was expected.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace fiberfluid
