// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Building a case: the phase of an experiment that needs its mesh (the
// surface loaded or generated and checked, the fibers pruned, selections
// resolved). read/ parses a CaseSpec without opening a file; this makes the
// Case that runs.

#include <filesystem>
#include <string>
#include <vector>

#include "fiberfluid/experiment/spec/case_spec.hpp"
#include "fiberfluid/geom/surface.hpp"

namespace fiberfluid::experiment {

// Loads or generates the spec's surface and checks it (closed, manifold,
// outward, ...). Throws InputError naming the field and the file.
geom::Surface build_surface(const SurfaceSpec& spec, std::vector<std::string>* warnings);

// Builds a case on the spec's own surface, or on `surface` (in input vertex
// order; checked like a mesh file) when the program has one. Throws
// InputError naming the field for what only the mesh reveals: a selection
// that selects nothing, a vertex that does not exist, a list with one entry
// per axis of the wrong length. Warnings (the mesh reader's) go to `warnings`.
Case build_case(const CaseSpec& spec, std::vector<std::string>* warnings = nullptr);
Case build_case(const CaseSpec& spec, const geom::Surface& surface,
                std::vector<std::string>* warnings = nullptr);
// The same, reusing the surface, compaction and fibers of `earlier`, built
// from a spec with the same surface_key (a sweep prunes once).
Case build_case(const CaseSpec& spec, const Case& earlier);

// The model vertices a selection picks on a built case. Throws InputError
// naming the field when it picks nothing or names a vertex that does not exist.
std::vector<int> resolve_selection(const SelectionSpec& spec, const Case& c);

// Reads a mesh file and checks it (closed, manifold, outward, ...), optionally
// flipping an inward mesh first. Throws InputError naming the file.
geom::Surface load_checked_surface(const std::filesystem::path& path, bool flip,
                                   std::vector<std::string>* warnings);

}  // namespace fiberfluid::experiment
