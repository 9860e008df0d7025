// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer's entry for one target, named at compile time (FIBERFLUID_FUZZ_TARGET).
#include <cstdio>
#include <cstdlib>

#include "fuzz_entries.hpp"

namespace {
const fiberfluid::fuzz::Target& target() {
  static const fiberfluid::fuzz::Target* t = fiberfluid::fuzz::find_target(FIBERFLUID_FUZZ_TARGET);
  if (t == nullptr) {
    std::fprintf(stderr, "no fuzz target '%s'\n", FIBERFLUID_FUZZ_TARGET);
    std::abort();
  }
  return *t;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  target().run(data, size);
  return 0;
}
