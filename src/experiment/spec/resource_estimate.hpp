// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// What a case will cost, as the estimate before the run keeps it (each Case
// holds one; run/resources.hpp makes it and says it).

#include <string>
#include <vector>

namespace fiberfluid::experiment {

struct ResourcePart {
  std::string name;    // "pruning", "factorisation", "10 load steps" ...
  double bytes = 0.0;  // held while this part runs (and after, for the kept parts)
  double seconds = 0.0;
  bool kept = false;  // still held by the later parts (the model, the fiber table)
};

struct ResourceEstimate {
  std::vector<ResourcePart> parts;
  std::string solver;       // the backend assumed ("block-cholesky", ...)
  double peak_bytes = 0.0;  // the largest part plus what the kept parts hold
  double seconds = 0.0;     // all parts
  // "about 1.2 GiB and 40 s (pruning 30 s, factorisation 8 s / 1.1 GiB, ...; block-cholesky)".
  std::string describe() const;
};

}  // namespace fiberfluid::experiment
