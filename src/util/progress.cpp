// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/util/progress.hpp"

#include <utility>

namespace fiberfluid {
namespace {

ProgressSink& sink() {
  static ProgressSink installed;
  return installed;
}

NoteSink& note_sink() {
  static NoteSink installed;
  return installed;
}

thread_local std::string current_label;

}  // namespace

void set_progress_sink(ProgressSink s) { sink() = std::move(s); }

void report_progress(const char* phase, double done, double total) {
  if (sink()) sink()(current_label, phase, done, total);
}

void set_note_sink(NoteSink s) { note_sink() = std::move(s); }

void report_note(const std::string& text) {
  if (note_sink()) note_sink()(current_label, text);
}

ProgressLabel::ProgressLabel(std::string label) : previous_(std::move(current_label)) {
  current_label = std::move(label);
}

ProgressLabel::~ProgressLabel() { current_label = std::move(previous_); }

}  // namespace fiberfluid
