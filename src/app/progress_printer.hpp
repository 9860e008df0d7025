// SPDX-License-Identifier: GPL-3.0-or-later
// The command line's progress line on stderr (the library reports, the
// command draws).
#pragma once

#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <map>
#include <mutex>
#include <string>
#include <thread>

namespace fiberfluid::app {

// Draws the library's progress reports on stderr, for phases that run longer
// than a moment: one line redrawn in place on a terminal; plain lines (every
// tenth, or every 10 s, and the end) when stderr is a file or a pipe. Each
// line has the elapsed time of the phase and, when its total is known, an
// estimate of what remains. A phase that reports rarely (a factorisation is
// one call) is redrawn by a heartbeat, so a long run always shows life.
class ProgressPrinter {
 public:
  ProgressPrinter() : tty_(isatty(STDERR_FILENO) != 0), heartbeat_([this] { beat(); }) {}
  ~ProgressPrinter() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_all();
    heartbeat_.join();
  }

  void operator()(const std::string& label, const char* phase, double done, double total) {
    const std::lock_guard<std::mutex> lock(mutex_);
    const Clock::time_point now = Clock::now();
    Phase& p = phases_[label + "|" + phase];
    if (p.start == Clock::time_point{} || done < p.done)  // a new phase
      p = Phase{label, phase, now, Clock::time_point{}};
    const bool repeat = done == p.done && p.printed;
    p.done = done;
    p.total = total;
    latest_ = &p;
    const double elapsed = seconds(now - p.start);
    const bool finished = total > 0.0 && done >= total;
    const int tenth = total > 0.0 ? static_cast<int>(10.0 * done / total) : -1;
    if (repeat || (elapsed < kQuietSeconds && !(finished && p.printed))) return;
    const double since_last = seconds(now - p.drawn);
    if (!finished && (tty_ ? since_last < 0.1 : tenth == p.tenth && since_last < 10.0)) return;
    p.tenth = tenth;
    print(p, now);
  }

  // Clears a redrawn line, so that what follows starts on its own.
  void close() {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (line_open_) std::fprintf(stderr, "\r\033[K");
    line_open_ = false;
    latest_ = nullptr;
  }

 private:
  using Clock = std::chrono::steady_clock;
  static constexpr double kQuietSeconds = 2.0;  // shorter phases print nothing
  struct Phase {
    std::string label;
    const char* name = "";
    Clock::time_point start, drawn;
    double done = 0.0, total = 0.0;
    int tenth = -1;
    bool printed = false;
  };
  static double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

  void print(Phase& p, Clock::time_point now) {
    p.drawn = now;
    p.printed = true;
    const double elapsed = seconds(now - p.start);
    std::string line = (p.label.empty() ? "" : "[" + p.label + "] ") + p.name;
    char buffer[160];
    if (p.total > 0.0) {
      std::snprintf(buffer, sizeof buffer, " %g/%g (%.0f%%), %.1f s", p.done, p.total,
                    100.0 * p.done / p.total, elapsed);
      line += buffer;
      if (p.done > 0.0 && p.done < p.total) {
        std::snprintf(buffer, sizeof buffer, ", about %.0f s left",
                      elapsed * (p.total - p.done) / p.done);
        line += buffer;
      }
    } else {  // a count with no known end, or only a start
      if (p.done > 0.0) line += " " + std::to_string(static_cast<long long>(p.done));
      std::snprintf(buffer, sizeof buffer, ", %.1f s", elapsed);
      line += buffer;
    }
    if (tty_)
      std::fprintf(stderr, "\r\033[K%s", line.c_str());
    else
      std::fprintf(stderr, "%s\n", line.c_str());
    std::fflush(stderr);
    line_open_ = tty_;
  }

  // Redraws the latest unfinished phase when nothing was printed for a while.
  void beat() {
    std::unique_lock<std::mutex> lock(mutex_);
    const auto interval = tty_ ? std::chrono::seconds(1) : std::chrono::seconds(10);
    while (!wake_.wait_for(lock, interval, [this] { return stopping_; })) {
      if (latest_ == nullptr || (latest_->total > 0.0 && latest_->done >= latest_->total)) continue;
      const Clock::time_point now = Clock::now();
      if (seconds(now - latest_->start) >= kQuietSeconds && now - latest_->drawn >= interval)
        print(*latest_, now);
    }
  }

  std::mutex mutex_;
  std::condition_variable wake_;
  bool tty_;
  bool stopping_ = false;
  bool line_open_ = false;
  std::map<std::string, Phase> phases_;  // std::map: latest_ stays valid as it grows
  Phase* latest_ = nullptr;
  std::thread heartbeat_;  // last: it starts once the rest is ready
};

}  // namespace fiberfluid::app
