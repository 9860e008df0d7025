// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The experiment library's front: an experiment file read (read/) and built
// on its meshes (run/case_builder), as `fiberfluid run` and `fiberfluid fit`
// load it. The library is laid out by phase: spec/ (what an experiment is),
// read/ (the JSON fields and the schema), run/ (building, running, fitting,
// the benchmarks), write/ (the output folder and its files).

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "fiberfluid/experiment/read/experiment_reader.hpp"
#include "fiberfluid/experiment/spec/experiment.hpp"
#include "fiberfluid/geom/surface.hpp"

namespace fiberfluid::experiment {

// Reads and validates an experiment file, then builds it. Throws InputError
// naming the file and the field (e.g. "sphere.json: material.Y: expected a
// positive number") for an unknown field, a wrong type, a missing or bad
// mesh, a selection that selects nothing; nothing is written.
Experiment load_experiment(const std::filesystem::path& path);

// The same from a JSON document built in a program (e.g. a Python dict):
// relative mesh paths are taken from `folder`, and errors name `label`.
Experiment parse_experiment(const nlohmann::json& document, const std::filesystem::path& folder,
                            const std::string& label);

// The second phase of parse_experiment, after read_experiment: loads the
// meshes, prunes and builds every case, on `surface` when given (for
// documents without a "surface": a program's own mesh).
void build_experiment(Experiment& experiment, const geom::Surface* surface = nullptr);

// A digest of what a built experiment will run: the resolved document, every
// case's surface and the bytes of every file it names, a calibration's
// specimens with theirs (FNV-1a, 64 bits). MPI ranks compare it before they
// work: a file read later (a fit's target.obj, a force curve) counts as much
// as the mesh, or a rank with another one would decide a multi-start fit
// silently. The readers resolve every file they read to an absolute path;
// that is how the digest finds them.
std::string experiment_digest(const Experiment& experiment);

}  // namespace fiberfluid::experiment
