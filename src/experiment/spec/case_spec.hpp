// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// An experiment is read in two phases. Parsing checks every field that can be
// checked without the mesh (types, ranges, names, the stepping) and keeps
// what it read as a CaseSpec; it opens no file. Building loads or generates
// the surface (or takes one from the caller), prunes the fibers of a concave
// body, and resolves what needs the mesh: selections, vertex indices, the
// length of per-axis lists, a paddle's starting position. A program or the
// fitter builds a model from a spec and a surface it already has.

#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "fiberfluid/experiment/spec/resource_estimate.hpp"
#include "fiberfluid/geom/surface.hpp"
#include "fiberfluid/model/model.hpp"
#include "fiberfluid/solve/stepping.hpp"

namespace fiberfluid::experiment {

// A field of the experiment, kept with what was parsed from it, so that an
// error found while building still names it ("file: supports[0].where: ...").
struct FieldName {
  std::string file;  // the experiment file (or the label of a document built in a program)
  std::string path;  // e.g. "supports[0]" ("" for the document itself)
  [[noreturn]] void fail(const std::string& key, const std::string& what) const;
};

// Where the rest surface comes from: a mesh file or a generator, then a scale.
struct SurfaceSpec {
  FieldName field;
  std::filesystem::path file;  // a mesh file (made absolute against the experiment's folder)
  bool flip = false;           // the file's faces point inward: flip them
  std::function<geom::Surface()> generate;  // a generator whose parameters were checked
  std::string generator;                    // its name, for messages
  double expected_vertices = 0.0;           // about how many it makes (0: few)
  double scale = 1.0;
  int remesh_vertices = 0;  // > 0: remeshed isotropically to about this many vertices
  bool empty() const { return file.empty() && !generate; }
};

// Exactly one of: input vertex indices, a half-space ("z <= 0.1"), a box.
struct SelectionSpec {
  FieldName field;
  std::vector<int> vertices;
  std::string where;
  Eigen::VectorXd box_min, box_max;
};

struct LoadSpec {
  FieldName field;
  model::Load load;        // everything but the vertex and the vector
  int input_vertex = 0;    // a point load's vertex, in input order
  Eigen::VectorXd vector;  // the acceleration (gravity) or the force (point): one entry per axis
};

// A "supports" entry (held axes) or a "prescribed" one (a displacement).
struct ConstraintSpec {
  FieldName field;
  bool prescribed = false;
  std::string label;
  SelectionSpec selection;
  std::string axes;              // supports: the held axes, e.g. "xyz"
  bool mirror_layer = false;     // supports: "layer": "mirror" (model::MirrorLayer)
  bool split_edge = false;       // supports: "edge": "split" (model::HeldEdge)
  Eigen::VectorXd displacement;  // prescribed: one entry per axis (a rotation's translation)
  // prescribed "rotation": {"axis": [x, y, z] (3D), "angle_degrees": a,
  // "centre": [...]}: the group moves rigidly (model::RigidMotion).
  struct Rotation {
    FieldName field;
    Eigen::VectorXd axis, centre;
    double angle_degrees = 0.0;
  };
  std::optional<Rotation> rotation;
  model::Schedule schedule;
};

struct PaddleSpec {
  FieldName field;
  model::Paddle paddle;                       // label, axis, side, schedule, contact
  std::optional<double> position;             // default: touching the body
  std::optional<double> travel, compression;  // exactly one
};

struct MaterialSpec {
  FieldName field;
  model::Material material;  // the law and gamma
  // "axis_factors" (multipliers of the law) or the paper's per-axis "Y"
  // list (the constant law 1 times exact factors): one entry per axis.
  Eigen::VectorXd per_axis;
  bool per_axis_moduli = false;
};

struct FiberSpec {
  bool pruning = true;  // "auto": prune the fibers that leave a concave body
  // "connection_count": the reader's default is "area" for central fibers,
  // "symmetric" for the vector spring.
  model::ConnectionCount count = model::ConnectionCount::Symmetric;
  std::string write = "none";       // "kept" or "pruned": DIR/fibers.vtu
  double treecode_tolerance = 0.0;  // "product": "treecode": its relative error
  // "kinematics": "vector" (the paper's) or "central" (fibers that bend).
  model::FiberKinematics kinematics = model::FiberKinematics::VectorSpring;
  // "horizon" (m): only vertices at most this far apart are joined; 0: every
  // pair (the paper's).
  double horizon = 0.0;
  // "influence": "constant" or "conical" (1 - L / horizon), the default for
  // central fibers with a horizon.
  model::Influence::Kind influence = model::Influence::Kind::Constant;
  // "weights": "paper" (Eq. 6, with the count) or "lines" (the line
  // measure: a body of fibers that is a material, model.hpp FiberWeights).
  model::FiberWeights weights = model::FiberWeights::Paper;
  FieldName field;
};

// One simulation as parsed: the whole experiment, or one variant of a sweep.
struct CaseSpec {
  std::string variant;   // "" unless the experiment sweeps
  nlohmann::json patch;  // the variant's merge patch (null without a sweep)
  SurfaceSpec surface;   // empty when the document has no "surface" (a program gives one)
  FiberSpec fibers;
  // Variants whose "surface" and "fibers" read the same share one built
  // surface and one pruning.
  std::string surface_key;
  MaterialSpec material;
  std::vector<LoadSpec> loads;
  std::vector<ConstraintSpec> constraints;
  std::vector<PaddleSpec> paddles;
  FieldName paddles_field;  // "paddles", for the check that two paddles leave room for the body
  solve::SteppingOptions stepping;
};

// What the fiber pruning did (issue 4), for the summary.
struct FiberReport {
  bool pruning = true;   // "fibers.pruning": "auto" (prune a concave body) or "off"
  bool convex = false;   // the fast path: nothing to prune
  double horizon = 0.0;  // "fibers.horizon" (m), 0: none
  long long pairs = 0;   // fibers in all, N (N-1) / 2
  long long kept = 0;
  int min_per_vertex = 0, max_per_vertex = 0;
  double mean_per_vertex = 0.0;
  double seconds = 0.0;
  long long exact_fallbacks = 0;  // pairs decided by exact constructions
  std::string write = "none";     // "kept" or "pruned": DIR/fibers.vtu
};

// One simulation, fully built.
struct Case {
  std::string variant;
  nlohmann::json patch;
  // The surface as given (input vertex order), the model on its used
  // vertices, and the map between the two.
  geom::Surface input_surface;
  std::vector<int> model_to_input;
  model::Model model;
  solve::SteppingOptions stepping;
  FiberReport fibers;
  ResourceEstimate estimate;  // memory and time, estimated before pruning
  // What the builder decided that the file did not say (a gauge that holds a
  // free rotation), for the run's warnings.
  std::vector<std::string> notes;
};

}  // namespace fiberfluid::experiment
