// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "fiberfluid/geom/surface.hpp"

namespace fiberfluid::geom {

struct ReadResult {
  Surface surface;
  std::vector<std::string> warnings;  // e.g. polygons split into triangles
  int index_base = 0;                 // how the file counts its vertices: OBJ from 1
};

// Reads a surface, choosing the format by extension:
//  .obj  v / f (forms a, a/t, a//n, a/t/n; negative indices); polygons are
//        split into triangles with a warning. A file with only `l` lines
//        and z = 0 everywhere is a closed 2D polygon.
//  .off  OFF (polygons split as for OBJ)
//  .stl  ASCII or binary; vertices with equal coordinates are welded
//  .ply  ASCII, binary little- and big-endian
// The vertex order of the file is kept. Throws InputError naming the file
// (and line where there is one) on anything it cannot read. The result is
// not checked for being closed or manifold: see inspect().
ReadResult read_surface(const std::filesystem::path& path);

enum class MeshFormat { Obj, Off, Stl, Ply };

// The format named by a path's extension (any case), or nothing.
std::optional<MeshFormat> mesh_format_of(const std::filesystem::path& path);

// Reads a surface held in memory (a file's bytes), as read_surface does;
// errors name `name`.
ReadResult read_surface_bytes(const std::string& bytes, MeshFormat format, const std::string& name);

// Writes an OBJ: triangles as `f`; a 2D polygon as `v x y 0` and `l` lines.
// Written to a temporary file first and renamed, so no half-written file
// is left behind on failure.
void write_obj(const std::filesystem::path& path, const Surface& surface);

// Writes `content` to `path` through a temporary file and a rename.
void write_text_file(const std::filesystem::path& path, const std::string& content);

}  // namespace fiberfluid::geom
