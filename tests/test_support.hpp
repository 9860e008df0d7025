// SPDX-License-Identifier: GPL-3.0-or-later
// Shared helpers for the tests: data folders and scratch files.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

namespace fiberfluid::testing {

inline std::filesystem::path data_mesh(const std::string& name) {
  return std::filesystem::path(FIBERFLUID_MESHES) / name;
}

// data/targets/NAME: the measured (or made) deformed surfaces the fits use.
inline std::filesystem::path data_target(const std::string& name) {
  return std::filesystem::path(FIBERFLUID_MESHES).parent_path() / "targets" / name;
}

inline std::filesystem::path experiment_file(const std::string& name) {
  return std::filesystem::path(FIBERFLUID_EXPERIMENTS) / name;
}

// A fresh folder per test, removed at the end of the test. The process id is
// part of its name: two test runs at once (two build folders, two clones)
// must not remove each other's files.
class ScratchDir {
 public:
  ScratchDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() / "fiberfluid_tests" /
            (std::string(info->test_suite_name()) + "." + info->name() + "." +
             std::to_string(::getpid()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() { std::filesystem::remove_all(path_); }
  const std::filesystem::path& path() const { return path_; }

  std::filesystem::path write(const std::string& name, const std::string& content) const {
    const std::filesystem::path file = path_ / name;
    std::ofstream(file, std::ios::binary) << content;
    return file;
  }

 private:
  std::filesystem::path path_;
};

}  // namespace fiberfluid::testing
