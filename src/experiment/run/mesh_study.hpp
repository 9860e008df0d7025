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

#include "fiberfluid/geom/surface.hpp"
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
  bool estimated = false;       // three levels or more ran: `estimate` holds
  RichardsonEstimate estimate;  // the order from the three finest, the trend over all
};

struct MeshStudy {
  std::string experiment;
  StudiedMesh mesh = StudiedMesh::Surface;
  std::vector<std::string> resolutions;  // per level: "segments [18, 16]", "size 0.005"
  // per level: the surface's mean element size (Celik et al.'s h: the
  // square root of the area per face), or the FEM's size asked for,
  // relative to the coarsest
  std::vector<double> sizes;
  std::vector<double> seconds;
  std::vector<StudiedFigure> figures;
  int planned_levels = 0;
  std::string failure;  // the level that failed and why; the levels before it ran
  std::vector<std::string> warnings;
};

// The experiment document refined by `factor` (> 1: finer): its surface's
// resolution or its FEM reference's size, and the description of the
// resolution. Throws InputError naming the field when the document has none
// to refine (a file without remesh_vertices, a FEM reference without size).
nlohmann::json refined_document(const nlohmann::json& document, StudiedMesh mesh, double factor,
                                std::string* resolution, double* actual_factor);

// The surface an experiment document makes (its generator run, its file
// read and remeshed), without building the case.
geom::Surface surface_of(const nlohmann::json& document, const std::filesystem::path& folder,
                         const std::string& label);

// `other` (the document on another mesh, `other_surface`) with every input
// vertex index that `document` names on `surface` -- a point load's or a
// marker's "vertex", a selection's "vertices"; the fit section's too with
// `with_fit` -- mapped to the vertex at the same point. An index names
// another point on another mesh: where `other_surface` has no vertex there,
// InputError names the field, the point and `what` (the other mesh).
nlohmann::json with_same_vertices(const nlohmann::json& document, const geom::Surface& surface,
                                  nlohmann::json other, const geom::Surface& other_surface,
                                  const std::string& what, bool with_fit);

// Plans every level before any runs: each level's surface must refine every
// direction (a generator's counts all grow) and differ from the one before;
// every vertex index the experiment names (a point load's "vertex", a
// selection's "vertices", a vertex figure) is mapped to the same point of
// each level, or the study is refused naming the field; the figures asked
// for are checked. Then runs the levels one after another (progress: "level
// k of n: ..." lines). Bad input throws InputError before anything runs; a
// level that fails after others ran ends the study with `failure` set and
// the finished levels kept; Ctrl-C throws Interrupted.
MeshStudy run_mesh_study(const std::filesystem::path& experiment_file, const MeshStudySpec& spec,
                         const std::function<void(const std::string&)>& progress = {});

// study.csv (figure, level, resolution, relative size, value) and
// study.json (each figure's values and estimate) as text.
std::string mesh_study_csv(const MeshStudy& study);
nlohmann::json mesh_study_json(const MeshStudy& study);

}  // namespace fiberfluid::experiment
