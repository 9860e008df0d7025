// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/run/results.hpp"

#include <sstream>

namespace fiberfluid::experiment {

std::string FigureCheck::Describe() const {
  std::ostringstream out;
  out.precision(10);
  out << (passed ? "pass" : "FAIL") << "  " << expected.figure << " = ";
  if (!found) {
    out << "(no such figure)";
    return out.str();
  }
  if (expected.matrix.size() > 0) {
    out << "matrix, largest difference " << actual << " (tolerance " << expected.tolerance << ")";
    return out.str();
  }
  out << actual;
  if (expected.value) out << ", expected " << *expected.value << " +- " << expected.tolerance;
  if (expected.at_most) out << ", at most " << *expected.at_most;
  if (expected.at_least) out << ", at least " << *expected.at_least;
  return out.str();
}

bool ExperimentResult::runs_succeeded() const {
  if (!failure.empty()) return false;
  for (const RunResult& run : runs)
    if (!run.summary.success) return false;
  return true;
}

bool ExperimentResult::checks_passed() const {
  for (const FigureCheck& c : checks)
    if (!c.passed) return false;
  return true;
}

}  // namespace fiberfluid::experiment
