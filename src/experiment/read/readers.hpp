// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// One reader per section of an experiment document, for read/'s own files
// (experiment_reader.cpp calls them). Each checks its fields and throws
// InputError naming the file and the field; none opens a file.

#include <filesystem>
#include <string>
#include <vector>

#include "fiberfluid/experiment/spec/benchmark_spec.hpp"
#include "fiberfluid/experiment/spec/case_spec.hpp"
#include "fiberfluid/experiment/spec/fem_reference_spec.hpp"
#include "fiberfluid/experiment/spec/fit_spec.hpp"

namespace fiberfluid::experiment {

class Fields;

// A path as the resolved document records it (absolute, normalised).
std::string absolute_path(const std::filesystem::path& path);

// A "surface" object: a mesh file (relative to `folder`) or a generator
// (surface_reader.cpp).
SurfaceSpec read_surface_spec(Fields& f, const std::filesystem::path& folder);

// One case from a complete simulation document (case_reader.cpp); the mesh
// reader's and the stepping's warnings go to `warnings`.
CaseSpec read_case(Fields& root, const std::filesystem::path& folder,
                   std::vector<std::string>* warnings);

// A file's length unit ("m", "cm", "mm", "um"; default m) as the factor to m
// (fit_reader.cpp).
double length_units(Fields& f, const std::string& key);

// A vertex selection ("vertices", "where", "nearest", ...; case_reader.cpp).
SelectionSpec read_selection(Fields& f);

// The "fit" section (fit_reader.cpp).
FitSpec read_fit(Fields f, const std::filesystem::path& folder);

// The benchmark fields: everything but name, description, kind and expected
// (benchmark_reader.cpp).
BenchmarkSpec read_benchmark(Fields& root);

// The "fem_reference" section (fem_reference_reader.cpp).
FemReferenceSpec read_fem_reference(Fields& f);

}  // namespace fiberfluid::experiment
