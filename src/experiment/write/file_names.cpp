// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/write/file_names.hpp"

#include <algorithm>

#include "fiberfluid/experiment/write/output_folder.hpp"

namespace fiberfluid::experiment {

const std::vector<std::string>& reserved_result_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> all = {kOutputMarker, kFailedMark, kIncompleteMark};
    all.insert(all.end(), output_files::kAll.begin(), output_files::kAll.end());
    all.insert(all.end(), fit_files::kAll.begin(), fit_files::kAll.end());
    all.insert(all.end(), benchmark_files::kAll.begin(), benchmark_files::kAll.end());
    return all;
  }();
  return names;
}

Status check_not_reserved(const std::string& name) {
  const std::vector<std::string>& names = reserved_result_names();
  const auto numbered = [&](const fit_files::Numbered& form) {
    const std::string prefix = form.prefix, suffix = form.suffix;
    return name.size() > prefix.size() + suffix.size() && name.rfind(prefix, 0) == 0 &&
           name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  const bool reserved =
      std::find(names.begin(), names.end(), name) != names.end() ||
      std::any_of(fit_files::kNumberedForms.begin(), fit_files::kNumberedForms.end(), numbered);
  if (!reserved) return {};
  return Status::failure(
      "a name that is not one of the result's own files (\"" + name +
      "\" is written at the top of the result folder, beside the folder this name would "
      "make)");
}

}  // namespace fiberfluid::experiment
