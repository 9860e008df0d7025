// SPDX-License-Identifier: GPL-3.0-or-later
// What a process allows a run: how much memory it may plan for, and whether
// it has been asked to stop (Ctrl-C). Both are process-wide, like a ulimit:
// the application sets them, long loops and the memory checks read them.
#pragma once

#include <atomic>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <string>

namespace fiberfluid {

// ---------------------------------------------------------------- memory
// This machine's physical memory in bytes (0 when unknown).
double physical_memory_bytes();

// The memory a run may plan for: set_memory_budget's value, or 80% of the
// physical memory. Dense factors, pruning tables and stored tangents are
// checked against it before they are allocated.
double memory_budget_bytes();
// 0 restores the default. Not thread-safe: set it before starting work.
void set_memory_budget(double bytes);
// True when set_memory_budget chose the value (an error then names the option).
bool memory_budget_is_set();

// The time a run may be estimated to take before it is refused: infinite
// unless set (0 restores that). For batch jobs and the fuzzer.
double time_budget_seconds();
void set_time_budget(double seconds);

// "1.5 GiB", "640 MiB", "12 KiB"...
std::string format_bytes(double bytes);

// Asks the kernel for 2 MiB pages behind a large allocation not yet touched
// (Linux, where transparent huge pages are often "madvise" only): an N x N
// matrix then takes one page fault per 2 MiB instead of one per 4 KiB, which
// at 10,000 vertices is most of the time of filling it. A hint: nothing
// happens elsewhere or when refused.
void advise_huge_pages(void* data, double bytes);
// Parses "8G", "512M", "1.5GiB", "2e9" (bytes); nothing on a malformed or
// non-positive size.
bool parse_bytes(const std::string& text, double* bytes);

// ---------------------------------------------------------------- interruption
// Asks every long loop (pruning, load steps, Newton, PCG, GMRES, time
// integration, a fit) to stop at its next check. Async-signal-safe: a SIGINT
// handler may call it.
void request_cancel() noexcept;
bool cancel_requested() noexcept;
void clear_cancel() noexcept;

// Thrown where a requested stop leaves nothing to return (the pruning of a
// case being built); solvers return a failed status instead.
class Interrupted : public std::runtime_error {
 public:
  explicit Interrupted(const std::string& what) : std::runtime_error(what) {}
};
// Throws Interrupted("interrupted during WHAT") when a stop was requested.
void throw_if_cancelled(const std::string& what);

// ---------------------------------------------------------------- threads
// An exception thrown inside an OpenMP region ends the process
// (std::terminate). Loops whose bodies can throw (CGAL's exact arithmetic
// allocates) catch into one of these, skip the rest, and rethrow the first
// after the region: the caller sees it as from a serial loop.
class ThreadFailure {
 public:
  // Call from a catch block: keeps the first exception of any thread.
  void capture() noexcept;
  bool happened() const noexcept { return happened_.load(std::memory_order_relaxed); }
  void rethrow_if_any() const;

 private:
  std::atomic<bool> happened_{false};
  std::mutex mutex_;
  std::exception_ptr first_;
};

}  // namespace fiberfluid
