// SPDX-License-Identifier: GPL-3.0-or-later
// How long phases say how far they are. The library never prints: it reports
// to one process-wide sink that the application installs (the command line
// draws a progress line). Without a sink a report costs a branch.
#pragma once

#include <functional>
#include <string>

namespace fiberfluid {

// label: the run it belongs to ("" or a sweep's variant: set per thread by
// ProgressLabel); phase: "pruning", "factorize", "pcg iteration", "step",
// "variants"; done of total in the phase's own unit (total 0 when it is not
// known; done 0 and total 0: the phase has begun).
using ProgressSink =
    std::function<void(const std::string& label, const char* phase, double done, double total)>;

// Install before starting work; the sink must be safe to call from several
// threads at once (a sweep runs variants side by side). An empty sink stops it.
void set_progress_sink(ProgressSink sink);
void report_progress(const char* phase, double done, double total);

// Notes for the user (an estimate before a long run): (label, text). Same
// rules as the progress sink; without one a note is dropped.
using NoteSink = std::function<void(const std::string& label, const std::string& text)>;
void set_note_sink(NoteSink sink);
void report_note(const std::string& text);

// Names the run that this thread's reports belong to, for its lifetime.
class ProgressLabel {
 public:
  explicit ProgressLabel(std::string label);
  ~ProgressLabel();
  ProgressLabel(const ProgressLabel&) = delete;
  ProgressLabel& operator=(const ProgressLabel&) = delete;

 private:
  std::string previous_;
};

}  // namespace fiberfluid
