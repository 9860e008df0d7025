// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// Where a run may write, and how a finished folder takes the place of an
// earlier one. Every rule that keeps a result from being lost or a foreign
// folder from being touched lives here:
// - names from an experiment file (the experiment's, a variant's) are one
//   path component of a fixed alphabet, so a shared file can never choose a
//   place outside the output root;
// - only a folder that fiberfluid wrote (it holds the marker file, with its
//   format and version inside) or an empty one is ever replaced;
// - staging folders have names no other writer can take (host, process and
//   a random part), created exclusively;
// - the swap is one atomic rename (RENAME_NOREPLACE, else RENAME_EXCHANGE),
//   checked after the fact, never test-then-rename; removing the previous
//   result afterwards may fail with a warning, never with a lost result.

#include <filesystem>
#include <string>
#include <vector>

#include "fiberfluid/util/status.hpp"

namespace fiberfluid::experiment {

// The marker every output folder holds: ".fiberfluid-output.json".
extern const char* const kOutputMarker;
// The marks of a folder that is not a complete result: being written (or
// stopped while it was), failed (DIR.failed), interrupted (DIR.interrupted).
inline constexpr const char* kIncompleteMark = "INCOMPLETE";
inline constexpr const char* kFailedMark = "FAILED";
inline constexpr const char* kInterruptedMark = "INTERRUPTED";

// The longest experiment or variant name: the folder names built from it
// (NAME.running-HOST-PID-XXXXXXXX, NAME.failed) stay below NAME_MAX.
constexpr size_t kLongestName = 100;

// Whether `name` can be a folder name of its own (letters, digits, '_',
// '-', '.'; not "." or ".."; at most kLongestName characters); if not, the
// message says what was expected, to follow "expected ...".
Status check_folder_name(const std::string& name);

// A usable stand-in for a file's stem as a default experiment name: every
// other character becomes '_', cut to kLongestName.
std::string folder_name_from(const std::string& stem);

// The output folder of a run: `flag` (-o) as typed, normalised (a trailing
// '/', "a/./b", "a/../b"), or out/NAME. Throws InputError, before anything
// runs, for a folder that could never be written or replaced: ".", "/",
// a symbolic link, a file, or an existing folder that fiberfluid did not write.
std::filesystem::path output_folder(const std::string& flag, const std::string& experiment_name);

// Throws InputError naming the folder when it exists and may not be replaced.
// Throws InputError when `folder` lies inside a fiberfluid result folder or
// holds one below it: replacing the outer one would delete the inner.
void check_not_nested(const std::filesystem::path& folder);
void check_replaceable(const std::filesystem::path& folder);

// A new, empty staging folder beside `target` ("TARGET.running-HOST-PID-XXXXXXXX"),
// holding the marker; folders of this form left by a process of this host that
// is gone (a killed run) are removed first.
std::filesystem::path create_staging_folder(const std::filesystem::path& target,
                                            const std::string& experiment_name);

// Puts the finished folder `from` at `to` in one atomic step. A folder at
// `to` is replaced only if it is replaceable (checked on the folder that was
// actually swapped out; a foreign one is swapped back and InputError names
// both). Removing the previous result afterwards is best effort: a failure
// is appended to `warnings`.
void move_into_place(const std::filesystem::path& from, const std::filesystem::path& to,
                     std::vector<std::string>* warnings);

}  // namespace fiberfluid::experiment
