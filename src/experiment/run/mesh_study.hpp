// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// A mesh study: one experiment run at several resolutions, each figure's
// values with its observed order of convergence and its Richardson-
// extrapolated value with an error estimate (Roache, "Verification and
// validation in computational science and engineering", 1998, chapter 5;
// the procedure for unequal refinement ratios of Celik et al., "Procedure for
// estimation and reporting of uncertainty due to discretization in CFD
// applications", J. Fluids Eng. 130, 078001, 2008). What is refined: the
// surface (a generator's segments or subdivisions, or remesh_vertices for a
// file) or the FEM reference's element size.

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fiberfluid/metrics/convergence.hpp"

namespace fiberfluid::experiment {

enum class StudiedMesh { Surface, FemReference };

struct MeshStudySpec {
  StudiedMesh mesh = StudiedMesh::Surface;
  int levels = 3;                    // at least 3: an order needs three values
  double ratio = 1.5;                // the refinement between levels (element size, coarse / fine)
  std::vector<std::string> figures;  // empty: every figure of the runs
};

// The estimate from three levels (metrics/convergence.hpp).
using metrics::richardson;
using metrics::RichardsonEstimate;

struct StudiedFigure {
  std::string name;
  std::vector<double> values;   // per level, coarse to fine
  RichardsonEstimate estimate;  // from the three finest
};

struct MeshStudy {
  std::string experiment;
  StudiedMesh mesh = StudiedMesh::Surface;
  std::vector<std::string> resolutions;  // per level: "segments [18, 16]", "size 0.005"
  std::vector<double> sizes;             // per level: the element size relative to the coarsest
  std::vector<double> seconds;
  std::vector<StudiedFigure> figures;
};

// The experiment document refined by `factor` (> 1: finer): its surface's
// resolution or its FEM reference's size, and the description of the
// resolution. Throws InputError naming the field when the document has none
// to refine (a file without remesh_vertices, a FEM reference without size).
nlohmann::json refined_document(const nlohmann::json& document, StudiedMesh mesh, double factor,
                                std::string* resolution, double* actual_factor);

// Runs the levels one after another (progress: "level k of n: ..." lines);
// a level that fails throws InputError naming it.
MeshStudy run_mesh_study(const std::filesystem::path& experiment_file, const MeshStudySpec& spec,
                         const std::function<void(const std::string&)>& progress = {});

// study.csv (figure, level, resolution, relative size, value) and
// study.json (each figure's values and estimate) as text.
std::string mesh_study_csv(const MeshStudy& study);
nlohmann::json mesh_study_json(const MeshStudy& study);

}  // namespace fiberfluid::experiment
