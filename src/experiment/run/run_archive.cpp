// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/run/run_archive.hpp"

#include <stdexcept>

#include "fiberfluid/solve/summary_fields.hpp"
#include "fiberfluid/util/byte_archive.hpp"

namespace fiberfluid::experiment {

// The fields of each type, once, for both directions (util/byte_archive.hpp).

template <class A>
void fields(A& a, RunResult& r) {
  a(r.variant, r.rank, r.summary, r.system_matrix);
}
template <class A>
void fields(A& a, RunOutcome& o) {
  a(o.run, o.step_unknowns);
}

std::string pack_run_outcome(const RunOutcome& outcome) {
  ByteWriter out;
  out(outcome);
  return out.take();
}

RunOutcome unpack_run_outcome(const std::string& bytes) {
  RunOutcome outcome;
  ByteReader in(bytes);
  in(outcome);
  if (!in.finished()) throw std::runtime_error("a run's outcome has bytes left over");
  return outcome;
}

}  // namespace fiberfluid::experiment
