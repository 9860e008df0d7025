// SPDX-License-Identifier: GPL-3.0-or-later
// The fuzz targets' bodies: each takes one input and either accepts it or
// rejects it with an InputError; anything else (a crash, another exception,
// a broken invariant: abort) is a finding. libFuzzer drives them
// (fuzz_main.cpp, scripts/fuzz.sh); the test suite replays the seed corpora
// and every input that once failed (replay_test.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace fiberfluid::fuzz {

struct Target {
  const char* name;       // "obj", "experiment", ... (the seeds' folder name)
  const char* extension;  // what the inputs are, for the corpora: ".obj", ".json"
  void (*run)(const uint8_t* data, size_t size);
};

// obj, off, stl_ascii, stl_binary, ply_ascii, ply_binary: read, check, and
// for a usable surface its area vectors and volume.
// experiment: parse the JSON and read every field (no file is opened).
// model_setup: build the experiment (meshes named relative to the
// experiments folder) and run it when its estimate is small.
// fit_section: read and set up a fit, one forward run when small.
// compare_2d, compare_3d: `compare` between an OBJ and a unit square or cube.
// Names that make paths (the experiment's, the variants') are checked to
// stay one folder below out/ in experiment, model_setup and fit_section.
const std::vector<Target>& targets();
const Target* find_target(const std::string& name);

}  // namespace fiberfluid::fuzz
