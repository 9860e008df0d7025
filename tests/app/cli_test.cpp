// SPDX-License-Identifier: GPL-3.0-or-later
// The command-line tool, run as a user would.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <fstream>

#include "test_support.hpp"

namespace fiberfluid {
namespace {

using testing::ScratchDir;

struct Outcome {
  int status = -1;
  std::string output;  // stdout and stderr
};

Outcome run_cli(const std::string& arguments) {
  Outcome outcome;
  const std::string command = std::string(FIBERFLUID_CLI) + " " + arguments + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return outcome;
  char buffer[4096];
  size_t n = 0;
  while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0) outcome.output.append(buffer, n);
  const int raw = pclose(pipe);
  outcome.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return outcome;
}

TEST(Cli, CheckReportsAGoodMesh) {
  const Outcome o = run_cli("check " + testing::data_mesh("torus.obj").string());
  EXPECT_EQ(o.status, 0) << o.output;
  for (const char* part : {"vertices:      800", "closed:        yes", "genus:         1",
                           "consistent, outward"})
    EXPECT_NE(o.output.find(part), std::string::npos) << part << "\n" << o.output;
}

TEST(Cli, CheckRejectsABadMesh) {
  ScratchDir dir;
  const auto open_mesh = dir.write("open.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                               "f 1 3 2\nf 1 2 4\nf 1 4 3\n");
  const Outcome o = run_cli("check " + open_mesh.string());
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.output.find("open.obj: not closed"), std::string::npos) << o.output;
}

TEST(Cli, RunWritesItsOutputsAndChecksTheExpectedFigures) {
  ScratchDir dir;
  const Outcome o = run_cli("run " + testing::experiment_file("rectangle.json").string() +
                            " -o " + (dir.path() / "rect").string() + " --check");
  EXPECT_EQ(o.status, 0) << o.output;
  EXPECT_NE(o.output.find("pass  final_pressure = 32"), std::string::npos) << o.output;
  for (const char* file : {"summary.json", "final.obj", "series.pvd", "vtk/step_0001.vtu"})
    EXPECT_TRUE(std::filesystem::exists(dir.path() / "rect" / file)) << file;
}

TEST(Cli, BadExperimentWritesNothing) {
  ScratchDir dir;
  const auto config = dir.write("bad.json", R"({"name": "bad",
    "surface": {"generator": "icosphere"}, "material": {"Y": 1, "colour": "red"}})");
  const Outcome o = run_cli("run " + config.string() + " -o " + (dir.path() / "out").string());
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.output.find("material.colour: unknown field"), std::string::npos) << o.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out"));
}

TEST(Cli, SingularSetupIsAFailureStatusNotACrash) {
  ScratchDir dir;
  const auto config = dir.write("free.json", R"({"name": "free",
    "surface": {"generator": "icosphere", "subdivisions": 1},
    "material": {"Y": 1000},
    "loads": [{"type": "gravity", "acceleration": [0, 0, -9.81]}]})");
  const Outcome o = run_cli("run " + config.string() + " -o " + (dir.path() / "out").string());
  EXPECT_EQ(o.status, 2);
  EXPECT_NE(o.output.find("no supports"), std::string::npos) << o.output;
}

TEST(Cli, UsageErrors) {
  EXPECT_NE(run_cli("").status, 0);
  EXPECT_NE(run_cli("run").status, 0);
  EXPECT_NE(run_cli("frobnicate").status, 0);
}

}  // namespace
}  // namespace fiberfluid
