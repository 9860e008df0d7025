// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// Independent work items (a sweep's variants, a multi-start search's starts,
// a calibration's specimens) computed somewhere and gathered somewhere else,
// as bytes: the shape of parallel::Ranks::deal, which deals them out over
// MPI ranks. The libraries take a WorkDealer and stay free of MPI; one
// process deals in order, here (deal_in_order).

#include <functional>
#include <string>

#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid {

// Item i's result, computed on whichever process it was dealt to.
using WorkCompute = std::function<std::string(size_t item)>;
// Receives item i's result (and the MPI rank that computed it) where the
// results are gathered; calls for different items may come from two threads.
using WorkDeliver = std::function<void(size_t item, int rank, std::string&& bytes)>;
// Computes items 0..count-1 and delivers each; stops dealing after Ctrl-C.
using WorkDealer =
    std::function<void(size_t count, const WorkCompute& compute, const WorkDeliver& deliver)>;

// One process: the items in order, here, until Ctrl-C.
inline void deal_in_order(size_t count, const WorkCompute& compute, const WorkDeliver& deliver) {
  for (size_t item = 0; item < count && !cancel_requested(); ++item)
    deliver(item, 0, compute(item));
}

}  // namespace fiberfluid
