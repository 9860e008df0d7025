// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/write/output_folder.hpp"

#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "fiberfluid/geom/mesh_io.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::experiment {

const char* const kOutputMarker = ".fiberfluid-output.json";

namespace {

namespace fs = std::filesystem;

constexpr const char* kMarkerFormat = "fiberfluid-output";
constexpr int kMarkerVersion = 1;
// A name typed with -o may be longer than one from a file, as long as the
// staging name built from it stays below NAME_MAX (255): ".running-" + host
// (at most 32) + "-" + pid (at most 10) + "-" + 8 hex digits is 61 more.
constexpr size_t kLongestTypedName = 190;
constexpr size_t kLongestHost = 32;

bool safe_character(unsigned char ch) {
  return std::isalnum(ch) || ch == '_' || ch == '-' || ch == '.';
}

// This host's name in the folder-name alphabet: staging folders of two hosts
// sharing a volume never collide, and only this host's are cleaned up here.
std::string host_name() {
  char buffer[256] = {};
  if (gethostname(buffer, sizeof buffer - 1) != 0 || buffer[0] == '\0') return "host";
  std::string name = folder_name_from(buffer);
  if (name.size() > kLongestHost) name.resize(kLongestHost);
  return name;
}

std::string random_hex() {
  std::random_device device;
  char text[9];
  std::snprintf(text, sizeof text, "%08x", static_cast<unsigned>(device()));
  return text;
}

bool process_alive(long pid) {
  return pid > 0 && (kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM);
}

bool has_marker(const fs::path& folder) {
  std::ifstream in(folder / kOutputMarker);
  if (!in) return false;
  const nlohmann::json marker = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  return marker.is_object() && marker.value("format", "") == kMarkerFormat &&
         marker.contains("version") && marker["version"].is_number_integer();
}

// Whether `folder` may be replaced (why not): absent, an empty folder, or
// one with the marker.
Status may_be_replaced(const fs::path& folder) {
  std::error_code error;
  const fs::file_status status = fs::symlink_status(folder, error);
  if (status.type() == fs::file_type::not_found) return {};
  if (error) return Status::failure("cannot be examined: " + error.message());
  if (fs::is_symlink(status))
    return Status::failure(
        "is a symbolic link (give the folder it points to, or another one, with -o)");
  if (!fs::is_directory(status)) return Status::failure("exists and is not a folder");
  if (fs::is_empty(folder, error) || has_marker(folder)) return {};
  const std::string marker = std::string(kOutputMarker);
  std::ifstream summary(folder / "summary.json");
  const nlohmann::json old = nlohmann::json::parse(summary, nullptr, /*allow_exceptions=*/false);
  if (old.is_object() && old.contains("fiberfluid_version"))  // before the marker existed
    return Status::failure(
        "holds results of an older fiberfluid (it has no " + marker +
        "), and only folders "
        "with it are replaced: remove it by hand, or choose another output folder with -o");
  return Status::failure("exists and was not written by fiberfluid (it has no " + marker +
                         "), so it is never replaced; choose another output folder with -o");
}

// Removes the previous result that a swap left at `old`; a failure is a warning.
void remove_previous(const fs::path& old, const fs::path& target,
                     std::vector<std::string>* warnings) {
  std::error_code error;
  fs::remove_all(old, error);
  if (error && warnings != nullptr)
    warnings->push_back(target.string() + " holds the new results; the previous ones, moved to " +
                        old.string() + ", could not be removed (" + error.message() +
                        "): remove that folder by hand");
}

// Without renameat2's flags (some network file systems): the earlier folder
// is renamed aside first (atomic), then the new one takes its name.
void move_by_two_renames(const fs::path& from, const fs::path& to,
                         std::vector<std::string>* warnings) {
  if (const Status replaceable = may_be_replaced(to); !replaceable.ok)
    throw InputError(to.string() + ": " + replaceable.message + "; the results are in " +
                     from.string());
  fs::path old = to;
  old += ".old-" + random_hex();
  const bool had_old = ::rename(to.c_str(), old.c_str()) == 0;
  if (!had_old && errno != ENOENT)
    throw InputError(to.string() + ": cannot move the earlier results aside (" +
                     std::strerror(errno) + "); the new results are in " + from.string());
  if (::rename(from.c_str(), to.c_str()) != 0) {
    const std::string why = std::strerror(errno);
    if (had_old) ::rename(old.c_str(), to.c_str());
    throw InputError(to.string() + ": cannot move the results into place (" + why +
                     "); they are in " + from.string());
  }
  if (had_old) remove_previous(old, to, warnings);
}

}  // namespace

Status check_folder_name(const std::string& name) {
  if (name.empty() || name == "." || name == ".." ||
      !std::all_of(name.begin(), name.end(), [](unsigned char ch) { return safe_character(ch); }))
    return Status::failure(
        "a name of letters, digits, '_', '-' or '.' (it names an output folder), got \"" +
        (name.size() > 60 ? name.substr(0, 60) + "..." : name) + "\"");
  if (name.size() > kLongestName)
    return Status::failure("a name of at most " + std::to_string(kLongestName) +
                           " characters (it names an output "
                           "folder), got one of " +
                           std::to_string(name.size()));
  return {};
}

std::string folder_name_from(const std::string& stem) {
  std::string name = stem.substr(0, std::min(stem.size(), kLongestName));
  for (char& ch : name)
    if (!safe_character(static_cast<unsigned char>(ch))) ch = '_';
  if (name.empty() || name == "." || name == "..") return "experiment";
  return name;
}

fs::path output_folder(const std::string& flag, const std::string& experiment_name) {
  fs::path folder;
  if (flag.empty()) {
    if (const Status name = check_folder_name(experiment_name); !name.ok)
      throw InputError("the experiment's name: expected " + name.message);
    folder = fs::path("out") / experiment_name;
  } else {
    folder = fs::path(flag).lexically_normal();
    // "out/small/" (as tab completion gives it) is the folder out/small.
    if (!folder.has_filename() && folder.has_relative_path()) folder = folder.parent_path();
  }
  const std::string name = folder.filename().string();
  if (folder.empty() || name.empty() || name == "." || name == ".." || !folder.has_relative_path())
    throw InputError("-o " + flag +
                     ": expected a folder of its own for the results (it is "
                     "replaced as a whole), not \"" +
                     folder.string() + "\"");
  if (name.size() > kLongestTypedName)
    throw InputError("-o " + flag + ": expected a folder name of at most " +
                     std::to_string(kLongestTypedName) + " characters");
  check_replaceable(folder);
  check_not_nested(folder);
  return folder;
}

// One result folder never sits inside another (issue 43): the outer one is
// replaced as a whole when its experiment runs again, and the inner one
// would go with it. Refused both ways: a folder inside a result, and a
// result folder to replace that holds another result.
void check_not_nested(const fs::path& folder) {
  std::error_code error;
  const fs::path absolute = fs::absolute(folder, error).lexically_normal();
  if (error) return;
  for (fs::path above = absolute.parent_path(); above.has_relative_path();
       above = above.parent_path())
    if (has_marker(above))
      throw InputError(folder.string() + ": inside " + above.string() +
                       ", a fiberfluid result folder (replaced as a whole when its experiment "
                       "runs again, with everything in it): choose an output folder outside it");
  if (!fs::is_directory(absolute, error) || fs::is_symlink(absolute, error)) return;
  for (fs::recursive_directory_iterator it(absolute, error), end; !error && it != end;
       it.increment(error)) {
    if (it->is_symlink(error)) {
      it.disable_recursion_pending();
      continue;
    }
    if (it->is_directory(error) && has_marker(it->path()))
      throw InputError(folder.string() + ": holds another fiberfluid result folder (" +
                       it->path().string() +
                       "), which replacing it would delete: move that one out first, or "
                       "choose another output folder");
  }
}

void check_replaceable(const fs::path& folder) {
  if (const Status replaceable = may_be_replaced(folder); !replaceable.ok)
    throw InputError(folder.string() + ": " + replaceable.message);
}

fs::path create_staging_folder(const fs::path& target, const std::string& experiment_name) {
  const fs::path parent = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  fs::create_directories(parent);
  const std::string host = host_name();
  const std::string prefix = target.filename().string() + ".running-" + host + "-";
  // Staging folders of this host whose process has gone (killed runs).
  for (const fs::directory_entry& entry : fs::directory_iterator(parent)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    char* end = nullptr;
    const long pid = std::strtol(name.c_str() + prefix.size(), &end, 10);
    if (end != nullptr && *end == '-' && !process_alive(pid)) {
      std::error_code ignored;
      fs::remove_all(entry.path(), ignored);
    }
  }
  for (int attempt = 0;; ++attempt) {
    fs::path staging = parent / (prefix + std::to_string(getpid()) + "-" + random_hex());
    std::error_code error;
    if (fs::create_directory(staging, error)) {  // exclusive: false when it existed
      const nlohmann::json marker = {{"format", kMarkerFormat},
                                     {"version", kMarkerVersion},
                                     {"program", "fiberfluid " FIBERFLUID_VERSION},
                                     {"experiment", experiment_name}};
      geom::write_text_file(staging / kOutputMarker, marker.dump(2) + "\n");
      return staging;
    }
    if (error || attempt == 16)
      throw InputError(parent.string() + ": cannot create a staging folder for " +
                       target.filename().string() + (error ? ": " + error.message() : ""));
  }
}

void move_into_place(const fs::path& from, const fs::path& to, std::vector<std::string>* warnings) {
  if (renameat2(AT_FDCWD, from.c_str(), AT_FDCWD, to.c_str(), RENAME_NOREPLACE) == 0) return;
  if (errno == EINVAL || errno == ENOSYS) return move_by_two_renames(from, to, warnings);
  if (errno != EEXIST && errno != ENOTEMPTY)
    throw InputError(to.string() + ": cannot move the results into place (" + std::strerror(errno) +
                     "); they are in " + from.string());
  if (renameat2(AT_FDCWD, from.c_str(), AT_FDCWD, to.c_str(), RENAME_EXCHANGE) != 0) {
    if (errno == EINVAL || errno == ENOSYS) return move_by_two_renames(from, to, warnings);
    throw InputError(to.string() + ": cannot replace the folder (" + std::strerror(errno) +
                     "); the results are in " + from.string());
  }
  // `from` now holds what was at `to`: checked after the swap, not before it,
  // so that nothing can slip in between.
  if (const Status replaceable = may_be_replaced(from); !replaceable.ok) {
    renameat2(AT_FDCWD, from.c_str(), AT_FDCWD, to.c_str(), RENAME_EXCHANGE);
    throw InputError(to.string() + ": " + replaceable.message +
                     " (it appeared while this run went on); the "
                     "results are in " +
                     from.string());
  }
  remove_previous(from, to, warnings);
}

}  // namespace fiberfluid::experiment
