// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <string>
#include <vector>

#include "fiberfluid/geom/surface.hpp"

namespace fiberfluid::geom {

// What inspect() finds in a surface. A surface is usable by the model when
// problems is empty (warnings are informational).
struct MeshReport {
  int dim = 3;
  int index_base = 0;     // the problems count vertices and faces from this (OBJ: 1)
  int vertices = 0;       // as listed in the input
  int used_vertices = 0;  // referenced by a face
  int faces = 0;
  int edges = 0;
  int components = 0;  // connected components of the used vertices
  int euler_characteristic = 0;
  int genus = 0;          // 3D, closed, one component: (2 - chi) / 2
  bool closed = false;    // every edge has exactly two faces (2D: every vertex two edges)
  bool manifold = false;  // no edge with more than two faces, no pinched vertex
  bool consistently_oriented = false;
  bool outward = false;               // enclosed volume (area in 2D) is positive
  double area = 0.0;                  // surface area (perimeter in 2D)
  double volume = 0.0;                // signed enclosed volume (area in 2D)
  std::vector<std::string> problems;  // each a full sentence; empty when usable
  std::vector<std::string> warnings;  // e.g. unused vertices
  bool ok() const { return problems.empty(); }
};

// Checks a surface: finite coordinates, indices in range, degenerate faces,
// closed 2-manifold, consistent and outward orientation. Never throws. The
// problems name vertices and faces counted from index_base: 0 as the
// experiment files count them, or the mesh file's own (1 for OBJ).
MeshReport inspect(const Surface& surface, int index_base = 0);

// Human-readable multi-line report (the `fiberfluid check` output).
std::string format_report(const MeshReport& report, const std::string& source);

// Throws InputError naming `source` and the first problem when the report is not ok.
void require_usable(const MeshReport& report, const std::string& source);

}  // namespace fiberfluid::geom
