// SPDX-License-Identifier: GPL-3.0-or-later
// The command-line tool run as a user would: in the foreground (its output
// and exit status) or in the background (to be stopped part way).
#pragma once

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace fiberfluid::testing {

struct Outcome {
  int status = -1;
  std::string output;  // stdout and stderr
};

// A shell command line, its stdout and stderr together.
inline Outcome run_cli_command(const std::string& command_line) {
  Outcome outcome;
  const std::string command = command_line + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return outcome;
  char buffer[4096];
  size_t n = 0;
  while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0) outcome.output.append(buffer, n);
  const int raw = pclose(pipe);
  outcome.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return outcome;
}

inline Outcome run_cli(const std::string& arguments) {
  return run_cli_command(std::string(FIBERFLUID_CLI) + " " + arguments);
}

inline pid_t start_cli(const std::vector<std::string>& arguments,
                       const std::filesystem::path& log) {
  const pid_t pid = fork();
  if (pid == 0) {
    std::FILE* out = std::freopen(log.c_str(), "w", stdout);
    if (out != nullptr) dup2(fileno(stdout), STDERR_FILENO);
    std::vector<char*> argv{const_cast<char*>(FIBERFLUID_CLI)};
    for (const std::string& a : arguments) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(FIBERFLUID_CLI, argv.data());
    _exit(127);
  }
  return pid;
}

inline int count_files(const std::filesystem::path& folder) {
  if (!std::filesystem::exists(folder)) return 0;
  int n = 0;
  for (const auto& entry : std::filesystem::directory_iterator(folder))
    n += entry.is_regular_file();
  return n;
}

// The staging folder of the run `pid` writing `out`: "out.running-HOST-PID-XXXXXXXX"
// (empty while there is none).
inline std::filesystem::path staging_of(const std::filesystem::path& out, pid_t pid) {
  const std::string prefix = out.filename().string() + ".running-";
  const std::string process = "-" + std::to_string(pid) + "-";
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(out.parent_path(), error)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) == 0 && name.find(process, prefix.size()) != std::string::npos)
      return entry.path();
  }
  return {};
}

// Waits for a background run; its exit status, or -1 when it was killed by a signal.
inline int wait_for(pid_t pid, double* seconds = nullptr) {
  const auto start = std::chrono::steady_clock::now();
  int status = 0;
  waitpid(pid, &status, 0);
  if (seconds)
    *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

inline std::string read_file(const std::filesystem::path& file) {
  std::ifstream in(file);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace fiberfluid::testing
