// SPDX-License-Identifier: GPL-3.0-or-later
// Every fuzz target on its seed corpus, the repository's own meshes and
// experiments, and every input that once crashed it or broke an invariant
// (tests/fuzz/regressions/TARGET/): an input that fails again aborts here.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz_entries.hpp"

namespace fiberfluid::fuzz {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> files_in(const fs::path& folder, const std::string& extension = "") {
  std::vector<fs::path> files;
  if (!fs::is_directory(folder)) return files;
  for (const fs::directory_entry& e : fs::directory_iterator(folder))
    if (e.is_regular_file() && (extension.empty() || e.path().extension() == extension))
      files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

std::string contents(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// What scripts/fuzz.sh starts each target from, and what it found.
std::vector<fs::path> inputs_of(const Target& t, bool regressions) {
  const fs::path root = FIBERFLUID_FUZZ_INPUTS;
  if (regressions) return files_in(root / "regressions" / t.name);
  std::vector<fs::path> all = files_in(root / "seeds" / t.name);
  const fs::path shared = std::string(t.extension) == ".json" ? fs::path(FIBERFLUID_EXPERIMENTS)
                                                              : fs::path(FIBERFLUID_MESHES);
  for (const fs::path& f : files_in(shared, t.extension)) all.push_back(f);
  return all;
}

class FuzzInputs : public ::testing::TestWithParam<std::string> {};

TEST_P(FuzzInputs, SeedsAreAcceptedOrRejectedWithAMessage) {
  const Target* target = find_target(GetParam());
  ASSERT_NE(target, nullptr);
  const std::vector<fs::path> seeds = inputs_of(*target, false);
  EXPECT_GE(seeds.size(), 2u) << "every target has seeds";
  for (const fs::path& file : seeds) {
    SCOPED_TRACE(file.string());
    const std::string bytes = contents(file);
    target->run(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
  }
}

TEST_P(FuzzInputs, RegressionsStayFixed) {
  const Target* target = find_target(GetParam());
  ASSERT_NE(target, nullptr);
  for (const fs::path& file : inputs_of(*target, true)) {
    SCOPED_TRACE(file.string());
    const std::string bytes = contents(file);
    target->run(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
  }
}

std::vector<std::string> target_names() {
  std::vector<std::string> names;
  for (const Target& t : targets()) names.push_back(t.name);
  return names;
}

INSTANTIATE_TEST_SUITE_P(AllTargets, FuzzInputs, ::testing::ValuesIn(target_names()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           return info.param;
                         });

}  // namespace
}  // namespace fiberfluid::fuzz
