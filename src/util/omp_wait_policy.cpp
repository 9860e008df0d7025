// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/util/omp_wait_policy.hpp"

#include <unistd.h>

#include <cstdlib>
#include <cstring>

namespace fiberfluid::util {

namespace {
constexpr const char* kMarker = "FIBERFLUID_WAIT_POLICY";  // "default": set by the restart
bool defaulted() {
  const char* marker = std::getenv(kMarker);
  return marker != nullptr && std::strcmp(marker, "default") == 0;
}
}  // namespace

void wait_passively_unless_chosen(char** argv) {
  if (std::getenv("OMP_WAIT_POLICY") != nullptr || std::getenv("GOMP_SPINCOUNT") != nullptr) return;
  if (setenv("OMP_WAIT_POLICY", "passive", 1) != 0 || setenv(kMarker, "default", 1) != 0) return;
  execv("/proc/self/exe", argv);
  // No restart (no /proc): this process keeps libgomp's default, and says so.
  unsetenv("OMP_WAIT_POLICY");
  unsetenv(kMarker);
}

std::string omp_wait_policy() {
  if (defaulted()) return "passive (fiberfluid's default)";
  for (const char* name : {"OMP_WAIT_POLICY", "GOMP_SPINCOUNT"})
    if (const char* value = std::getenv(name)) return std::string(name) + "=" + value + " (the user's)";
  return "libgomp's default (spins, then sleeps)";
}

}  // namespace fiberfluid::util
