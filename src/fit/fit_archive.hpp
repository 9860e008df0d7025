// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// A fit's result and an evaluation of the residuals as bytes, bit for bit:
// how a start of a multi-start search or a specimen's residuals come back
// from another MPI rank (util/byte_archive.hpp). The run's live objects stay
// where they were made.

#include <string>

#include "fiberfluid/fit/calibration.hpp"

namespace fiberfluid::fit {

std::string pack_fit_result(const FitResult& result);
// Throws std::runtime_error when the bytes are not a packed result.
FitResult unpack_fit_result(const std::string& bytes);

std::string pack_evaluation(const Evaluation& evaluation);
Evaluation unpack_evaluation(const std::string& bytes);

}  // namespace fiberfluid::fit
