// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/util/run_control.hpp"

#include <sys/mman.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

namespace fiberfluid {
namespace {

double budget_set = 0.0;
double time_budget = HUGE_VAL;
std::atomic<bool> cancel_flag{false};
static_assert(std::atomic<bool>::is_always_lock_free, "a signal handler sets the flag");

}  // namespace

double physical_memory_bytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  return pages > 0 && page > 0 ? static_cast<double>(pages) * static_cast<double>(page) : 0.0;
}

double memory_budget_bytes() {
  if (budget_set > 0.0) return budget_set;
  const double physical = physical_memory_bytes();
  return physical > 0.0 ? 0.8 * physical : HUGE_VAL;
}

void set_memory_budget(double bytes) { budget_set = bytes > 0.0 ? bytes : 0.0; }
bool memory_budget_is_set() { return budget_set > 0.0; }

double time_budget_seconds() { return time_budget; }
void set_time_budget(double seconds) { time_budget = seconds > 0.0 ? seconds : HUGE_VAL; }

std::string format_bytes(double bytes) {
  static const char* units[] = {"bytes", "KiB", "MiB", "GiB", "TiB", "PiB"};
  int u = 0;
  while (bytes >= 1024.0 && u < 5) bytes /= 1024.0, ++u;
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, u == 0 ? "%.0f %s" : "%.3g %s", bytes, units[u]);
  return buffer;
}

bool parse_bytes(const std::string& text, double* bytes) {
  const char* begin = text.c_str();
  char* end = nullptr;
  const double value = std::strtod(begin, &end);
  if (end == begin || !std::isfinite(value) || !(value > 0.0)) return false;
  std::string unit(end);
  for (char& c : unit) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  double scale = 0.0;
  if (unit.empty() || unit == "B")
    scale = 1.0;
  else if (unit == "K" || unit == "KB" || unit == "KIB")
    scale = 1024.0;
  else if (unit == "M" || unit == "MB" || unit == "MIB")
    scale = 1024.0 * 1024.0;
  else if (unit == "G" || unit == "GB" || unit == "GIB")
    scale = 1024.0 * 1024.0 * 1024.0;
  else if (unit == "T" || unit == "TB" || unit == "TIB")
    scale = 1024.0 * 1024.0 * 1024.0 * 1024.0;
  if (scale == 0.0 || !std::isfinite(value * scale)) return false;
  *bytes = value * scale;
  return true;
}

void request_cancel() noexcept { cancel_flag.store(true, std::memory_order_relaxed); }
bool cancel_requested() noexcept { return cancel_flag.load(std::memory_order_relaxed); }
void clear_cancel() noexcept { cancel_flag.store(false, std::memory_order_relaxed); }

void throw_if_cancelled(const std::string& what) {
  if (cancel_requested()) throw Interrupted("interrupted during " + what);
}

void advise_huge_pages(void* data, double bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr std::uintptr_t kHuge = 2u << 20;
  if (bytes < 4.0 * kHuge) return;
  const auto begin = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t first = (begin + kHuge - 1) & ~(kHuge - 1);
  const std::uintptr_t last = (begin + static_cast<std::uintptr_t>(bytes)) & ~(kHuge - 1);
  if (last > first) madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);
#else
  (void)data, (void)bytes;
#endif
}

void ThreadFailure::capture() noexcept {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!first_) first_ = std::current_exception();
  happened_ = true;
}

void ThreadFailure::rethrow_if_any() const {
  if (first_) std::rethrow_exception(first_);
}

}  // namespace fiberfluid
