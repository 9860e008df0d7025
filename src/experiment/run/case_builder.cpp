// SPDX-License-Identifier: GPL-3.0-or-later
// Building a parsed case on its surface: what needs the mesh (case_spec.hpp).
#include <algorithm>
#include <optional>
#include <sstream>
#include <string>

#include "fiberfluid/experiment/run/case_builder.hpp"
#include "fiberfluid/experiment/run/resources.hpp"
#include "fiberfluid/geom/fiber_pruning.hpp"
#include "fiberfluid/geom/horizon.hpp"
#include "fiberfluid/geom/mesh_check.hpp"
#include "fiberfluid/geom/mesh_io.hpp"
#include "fiberfluid/geom/remesh.hpp"
#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/model/free_motions.hpp"
#include "fiberfluid/model/mirror_layer.hpp"
#include "fiberfluid/solve/stepping.hpp"
#include "fiberfluid/util/error.hpp"
#include "fiberfluid/util/progress.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::experiment {

void FieldName::fail(const std::string& key, const std::string& what) const {
  const std::string name = key.empty() ? path : path.empty() ? key : path + "." + key;
  throw InputError(file + ": " + name + (name.empty() ? "" : ": ") + what);
}

geom::Surface load_checked_surface(const std::filesystem::path& path, bool flip,
                                   std::vector<std::string>* warnings) {
  geom::ReadResult read = geom::read_surface(path);
  if (flip) geom::flip_orientation(read.surface);
  const geom::MeshReport report = geom::inspect(read.surface);
  geom::require_usable(report, path.string());
  if (warnings) {
    warnings->insert(warnings->end(), read.warnings.begin(), read.warnings.end());
    for (const auto& w : report.warnings) warnings->push_back(path.string() + ": " + w);
  }
  return read.surface;
}

// The surface remeshed to about spec.remesh_vertices vertices, checked again
// (what CGAL made must be as usable as a mesh file); a warning gives the count.
geom::Surface remeshed(const SurfaceSpec& spec, const geom::Surface& surface,
                       std::vector<std::string>* warnings) {
  if (surface.dim != 3)
    spec.field.fail("remesh_vertices", "only a 3D surface can be remeshed (this one is 2D)");
  geom::Surface out;
  try {
    out = geom::remesh_to_vertices(surface, spec.remesh_vertices);
  } catch (const InputError& e) {
    spec.field.fail("remesh_vertices", e.what());
  }
  const std::string label = spec.field.file + ": " +
                            (spec.field.path.empty() ? "" : spec.field.path + ".") +
                            "remesh_vertices";
  geom::require_usable(geom::inspect(out), label);
  std::vector<int> used(surface.F.data(), surface.F.data() + surface.F.size());
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  if (warnings)
    warnings->push_back(label + ": remeshed from " + std::to_string(used.size()) + " to " +
                        std::to_string(out.num_vertices()) + " vertices (asked " +
                        std::to_string(spec.remesh_vertices) + ")");
  return out;
}

// A surface's own cost, refused before it is built when beyond the budgets:
// making and checking about `vertices` vertices (measured: a cylinder of a
// million vertices, generated and checked, 570 MB and 16 s; remeshing to a
// million, 348 MiB in 30 s; so about 600 bytes and 30 us a vertex). Before,
// such a surface grew to a gigabyte and ran past --max-time before the case's
// own estimate could refuse it (issue 43, "budgets cover every phase").
void require_surface_within_budget(const SurfaceSpec& spec, double vertices, const char* key) {
  constexpr double kBytesPerVertex = 600.0, kSecondsPerVertex = 3e-5;
  const double bytes = kBytesPerVertex * vertices, seconds = kSecondsPerVertex * vertices;
  std::ostringstream why;
  why << "about " << static_cast<long long>(vertices)
      << " vertices: making and checking them alone needs about " << format_bytes(bytes) << " and "
      << seconds_text(seconds);
  if (bytes > memory_budget_bytes())
    spec.field.fail(key, why.str() + ", more than the memory budget of " +
                             format_bytes(memory_budget_bytes()) +
                             " (--max-memory); ask for fewer vertices");
  if (seconds > time_budget_seconds())
    spec.field.fail(key, why.str() + ", more than --max-time " +
                             seconds_text(time_budget_seconds()) + "; ask for fewer vertices");
}

geom::Surface build_surface(const SurfaceSpec& spec, std::vector<std::string>* warnings) {
  if (spec.empty())
    spec.field.fail("",
                    "missing (required): the document names no surface and the program "
                    "gave none");
  geom::Surface surface;
  if (!spec.file.empty()) {
    try {
      surface = load_checked_surface(spec.file, spec.flip, warnings);
    } catch (const InputError& e) {
      spec.field.fail("file", e.what());  // names the experiment field as well as the mesh
    }
  } else {
    require_surface_within_budget(spec, spec.expected_vertices, "generator");
    throw_if_cancelled("the surface's generation");
    surface = spec.generate();
    throw_if_cancelled("the surface's generation");
    const geom::MeshReport report = geom::inspect(surface);
    throw_if_cancelled("the surface's checks");
    geom::require_usable(report, spec.field.file + ": " +
                                     (spec.field.path.empty() ? "" : spec.field.path + ".") +
                                     "generator");
  }
  surface.V *= spec.scale;
  // The checks above saw the unscaled mesh: a scale can still push coordinates
  // past what squares and cross products of them can hold (or to nothing).
  const double size = geom::bounding_box_diagonal(surface.V);
  if (!(size > 1e-100 && size < 1e100))
    spec.field.fail(
        "scale", (std::ostringstream() << "scaled by " << spec.scale << " the surface is " << size
                                       << " m across; expected a size from "
                                          "1e-100 to 1e100 m")
                     .str());
  if (spec.remesh_vertices > 0) {
    require_surface_within_budget(spec, spec.remesh_vertices, "remesh_vertices");
    surface = remeshed(spec, surface, warnings);
    throw_if_cancelled("the surface's remeshing");
  }
  return surface;
}

namespace {

std::string axis_names(int dim) { return std::string("xyz").substr(0, static_cast<size_t>(dim)); }

// A per-axis list must have one entry per axis of the surface.
void require_per_axis(const FieldName& field, const std::string& key, const Eigen::VectorXd& v,
                      int dim) {
  if (v.size() != dim)
    field.fail(key, "expected a list of " + std::to_string(dim) + " numbers (one per axis of the " +
                        std::to_string(dim) + "D surface), got " + std::to_string(v.size()));
}

// ------------------------------------------------------------ fibers
// Bodies with more fibers to test than this are not pruned: every pair of
// 20,000 vertices (a 5,000-vertex torus: about 20 s here, so 20,000 vertices
// about 6 minutes). A horizon's pairs are all that is tested.
constexpr double kLargestPruned = 0.5 * 20000.0 * 19999.0;

// The pairs within the spec's horizon, refused when it is shorter than a
// mesh edge (a vertex would lose its neighbours on the surface).
geom::FiberMask horizon_fibers(const FiberSpec& spec, const geom::Surface& surface) {
  const double edge = geom::longest_edge(surface);
  if (spec.horizon < edge)
    spec.field.fail("horizon", "expected at least the longest mesh edge, " + std::to_string(edge) +
                                   " m, so that the fibers join every "
                                   "vertex to its neighbours; got " +
                                   std::to_string(spec.horizon) + " m");
  return geom::horizon_fibers(surface, spec.horizon);
}

// The bulk fibers of the model: every pair, or those within the horizon, of
// which a concave body keeps those that stay inside it (pruning). Reports
// what it did.
FiberReport choose_fibers(const FiberSpec& spec, bool concave, model::Model& m) {
  FiberReport report;
  report.pruning = spec.pruning;
  report.horizon = spec.horizon;
  report.write = spec.write;
  m.connection_count = spec.count;
  m.treecode_tolerance = spec.treecode_tolerance;
  m.influence = {spec.influence, spec.horizon};
  m.fiber_weights = spec.weights;
  const int n = m.num_vertices();
  report.pairs = static_cast<long long>(n) * (n - 1) / 2;
  report.kept = report.pairs;
  report.min_per_vertex = report.max_per_vertex = n - 1;
  report.mean_per_vertex = n - 1;
  report.convex = report.pruning && !concave;
  // The horizon's fibers (add_fibers found them for the estimate), then the pruning's.
  std::shared_ptr<const geom::FiberMask> fibers;
  if (spec.horizon > 0.0)
    fibers = m.fibers ? m.fibers
                      : std::make_shared<const geom::FiberMask>(horizon_fibers(spec, m.surface));
  if (report.pruning && concave) {  // within a horizon, only its pairs are tested
    geom::PruningResult pruned = geom::prune_fibers(m.surface, false, fibers.get());
    report.seconds = pruned.seconds;
    report.exact_fallbacks = pruned.exact_fallbacks;
    fibers = std::make_shared<const geom::FiberMask>(std::move(pruned.mask));
  }
  if (!fibers) return report;
  const geom::FiberMask& mask = *fibers;
  report.kept = mask.num_kept();
  const std::vector<int> per_vertex = mask.kept_per_vertex();
  report.min_per_vertex = *std::min_element(per_vertex.begin(), per_vertex.end());
  report.max_per_vertex = *std::max_element(per_vertex.begin(), per_vertex.end());
  report.mean_per_vertex = 2.0 * report.kept / n;
  if (report.min_per_vertex == 0)
    spec.field.fail("pruning",
                    "vertex " +
                        std::to_string(std::find(per_vertex.begin(), per_vertex.end(), 0) -
                                       per_vertex.begin()) +
                        " keeps no fiber: is the mesh self-intersecting?");
  if (spec.treecode_tolerance > 0.0 && spec.count == model::ConnectionCount::Symmetric)
    spec.field.fail("product",
                    "\"treecode\" needs one connection count for every fiber: this "
                    "concave body prunes " +
                        std::to_string(report.pairs - report.kept) +
                        " fibers; set \"connection_count\": \"global\" (pruned "
                        "fibers are then exact corrections) or \"product\": \"exact\"");
  m.fibers = std::move(fibers);
  return report;
}

// The surface as given and its used vertices as the model's.
void set_surface(geom::Surface input, Case& c) {
  c.input_surface = std::move(input);
  const geom::CompactSurface compact = geom::remove_unused_vertices(c.input_surface);
  c.model_to_input = compact.to_input;
  c.model.surface = compact.surface;
}

// Refuses a case whose estimate exceeds the budgets; notes a long one.
void estimate(const CaseSpec& spec, PruningWork pruning, Case& c) {
  c.estimate = estimate_resources(c.model, c.stepping, pruning);
  require_within_budget(c.estimate, spec);
}

// The fibers of a case whose model parts are built: its cost is estimated
// (and refused beyond the memory or time budget) before the convexity check,
// and again before pruning once the check has said whether it prunes.
void add_fibers(const CaseSpec& spec, Case& c) {
  const int n = c.model.num_vertices();
  // A horizon's pairs are found in N times the neighbours: known before the
  // estimate, which then counts them rather than all N^2.
  if (spec.fibers.horizon > 0.0)
    c.model.fibers =
        std::make_shared<const geom::FiberMask>(horizon_fibers(spec.fibers, c.model.surface));
  estimate(spec, spec.fibers.pruning ? PruningWork::ConvexityCheck : PruningWork::None, c);
  const bool concave = spec.fibers.pruning && !geom::is_convex(c.model.surface);
  const double to_test =
      c.model.fibers ? static_cast<double>(c.model.fibers->num_kept()) : 0.5 * n * (n - 1.0);
  if (concave && to_test > kLargestPruned)
    spec.fibers.field.fail("pruning", "a concave body of " + std::to_string(n) + " vertices has " +
                                          std::to_string(static_cast<long long>(to_test)) +
                                          " fibers to test, beyond exact pruning (at most those "
                                          "of 20,000 vertices); set \"off\" or a shorter horizon");
  if (concave) estimate(spec, PruningWork::Prune, c);
  if (c.estimate.seconds >= 10.0 || c.estimate.peak_bytes >= 0.25 * memory_budget_bytes())
    report_note("estimate for a long run: " + c.estimate.describe());
  c.fibers = choose_fibers(spec.fibers, concave, c.model);
}

// ------------------------------------------------------------ model parts
// Resolves the parts that need the mesh, on a case whose geometry is built.
class ModelBuilder {
 public:
  ModelBuilder(const CaseSpec& spec, Case& c)
      : spec_(spec),
        c_(c),
        dim_(c.model.dim()),
        input_to_model_(static_cast<size_t>(c.input_surface.num_vertices()), -1) {
    for (size_t m = 0; m < c.model_to_input.size(); ++m)
      input_to_model_[static_cast<size_t>(c.model_to_input[m])] = static_cast<int>(m);
  }

  void build() {
    c_.variant = spec_.variant;
    c_.patch = spec_.patch;
    c_.stepping = spec_.stepping;
    c_.model.material = material();
    c_.model.loads.clear();
    for (const LoadSpec& l : spec_.loads) c_.model.loads.push_back(load(l));
    c_.model.constraints.clear();
    c_.model.motions.clear();
    c_.model.mirror_layers.clear();
    c_.model.held_edges.clear();
    c_.model.constraint_groups.clear();
    for (const ConstraintSpec& k : spec_.constraints) add_group(k);
    c_.model.paddles.clear();
    for (const PaddleSpec& p : spec_.paddles) c_.model.paddles.push_back(paddle(p));
    check_paddles_leave_room();
    check_friction_is_felt();
    c_.notes.clear();
    hold_free_rotations();
  }

 private:
  int model_vertex(const FieldName& field, const std::string& key, int input) const {
    if (input >= static_cast<int>(input_to_model_.size()))
      field.fail(key, "vertex " + std::to_string(input) + " does not exist (the mesh has " +
                          std::to_string(input_to_model_.size()) + " vertices, from 0)");
    const int m = input_to_model_[static_cast<size_t>(input)];
    if (m < 0) field.fail(key, "vertex " + std::to_string(input) + " belongs to no face");
    return m;
  }

  model::Material material() const {
    const MaterialSpec& spec = spec_.material;
    model::Material m = spec.material;
    m.kinematics = spec_.fibers.kinematics;
    if (spec.per_axis.size() > 0) {
      require_per_axis(spec.field, spec.per_axis_moduli ? "Y" : "axis_factors", spec.per_axis,
                       dim_);
      if (spec.per_axis_moduli) m.axis_factors.setZero();
      m.axis_factors.head(dim_) = spec.per_axis;
    }
    return m;
  }

  model::Load load(const LoadSpec& spec) const {
    model::Load load = spec.load;
    switch (load.kind) {
      case model::Load::Kind::Point:
        require_per_axis(spec.field, "force", spec.vector, dim_);
        load.vertex = model_vertex(spec.field, "vertex", spec.input_vertex);
        load.force.head(dim_) = spec.vector;
        return load;
      case model::Load::Kind::Hydrostatic:
        require_per_axis(spec.field, "acceleration", spec.vector, dim_);
        load.acceleration.head(dim_) = spec.vector;
        return load;
    }
    spec.field.fail("type", "a load of an unknown kind");
  }

  std::vector<int> select(const SelectionSpec& spec) const { return resolve_selection(spec, c_); }

  // The rigid motion of a rotating group (its rotation and translation).
  int add_motion(const ConstraintSpec& spec) {
    const ConstraintSpec::Rotation& r = *spec.rotation;
    model::RigidMotion motion;
    require_per_axis(r.field, "centre", r.centre, dim_);
    motion.centre.head(dim_) = r.centre;
    if (dim_ == 3) {
      if (r.axis.size() != 3) r.field.fail("axis", "expected the rotation's axis, 3 numbers");
      if (!(r.axis.norm() > 0.0)) r.field.fail("axis", "expected a nonzero axis");
      motion.axis = r.axis.normalized();
    } else if (r.axis.size() > 0) {
      r.field.fail("axis", "a 2D rotation turns about z: leave the axis out");
    }
    motion.angle = r.angle_degrees * M_PI / 180.0;
    if (spec.displacement.size() > 0) {
      require_per_axis(spec.field, "displacement", spec.displacement, dim_);
      motion.translation.head(dim_) = spec.displacement;
    }
    c_.model.motions.push_back(motion);
    return static_cast<int>(c_.model.motions.size()) - 1;
  }

  void add_group(const ConstraintSpec& spec) {
    model::Model& m = c_.model;
    m.constraint_groups.push_back(spec.label);
    const int group = static_cast<int>(m.constraint_groups.size()) - 1;
    const std::vector<int> vertices = select(spec.selection);
    if (spec.rotation) {
      const int motion = add_motion(spec);
      for (int v : vertices)
        for (int a = 0; a < dim_; ++a) {
          model::Constraint c{v, a, 0.0, spec.schedule, group};
          c.motion = motion;
          m.constraints.push_back(c);
        }
      return;
    }
    if (spec.prescribed) {
      require_per_axis(spec.field, "displacement", spec.displacement, dim_);
      for (int v : vertices)
        for (int a = 0; a < dim_; ++a)
          m.constraints.push_back({v, a, spec.displacement[a], spec.schedule, group});
      return;
    }
    const std::string axes = spec.axes.empty() ? axis_names(dim_) : spec.axes;
    for (char letter : axes)
      if (letter - 'x' >= dim_)
        spec.field.fail("axes", "expected distinct letters from \"" + axis_names(dim_) +
                                    "\", got \"" + axes + "\"");
    for (int v : vertices)
      for (char letter : axes) m.constraints.push_back({v, letter - 'x', 0.0, {}, group});
    if (spec.mirror_layer) add_mirror_layer(spec, group, vertices, axes);
    if (spec.split_edge) add_split_edge(spec, group, vertices, axes);
  }

  // A support whose edge vertices' free share moves with the free side.
  void add_split_edge(const ConstraintSpec& spec, int group, const std::vector<int>& vertices,
                      const std::string& axes) {
    if (static_cast<int>(axes.size()) != dim_)
      spec.field.fail("edge", "a split edge holds every axis: leave \"axes\" out");
    c_.model.held_edges.push_back({group, vertices});
    if (const Status usable = solve::check_support_terms(c_.model, c_.stepping); !usable.ok)
      spec.field.fail("edge", usable.message);
  }

  // A clamp's mirror layer: a full clamp on a plane, as deep as the horizon.
  void add_mirror_layer(const ConstraintSpec& spec, int group, const std::vector<int>& vertices,
                        const std::string& axes) {
    if (static_cast<int>(axes.size()) != dim_)
      spec.field.fail("layer", "a mirror layer clamps every axis: leave \"axes\" out");
    if (!(spec_.fibers.horizon > 0.0))
      spec.field.fail("layer",
                      "a mirror layer is as deep as the fibers' horizon: set fibers.horizon");
    model::MirrorLayer layer;
    layer.group = group;
    layer.depth = spec_.fibers.horizon;
    if (const Status plane = model::find_clamp_plane(c_.model.surface.V, vertices, &layer);
        !plane.ok)
      spec.field.fail("layer", "the support has no clamp plane: " + plane.message);
    c_.model.mirror_layers.push_back(layer);
    if (const Status usable = solve::check_support_terms(c_.model, c_.stepping); !usable.ok)
      spec.field.fail("layer", usable.message);
  }

  model::Paddle paddle(const PaddleSpec& spec) const {
    model::Paddle p = spec.paddle;
    if (p.axis >= dim_)
      spec.field.fail("axis", "expected one of \"" + axis_names(dim_) +
                                  "\" (the paddle's normal), got \"" +
                                  std::string(1, static_cast<char>('x' + p.axis)) + "\"");
    const Eigen::VectorXd along = c_.model.surface.V.col(p.axis);
    const double extent = along.maxCoeff() - along.minCoeff();
    const double touching = p.above ? along.maxCoeff() : along.minCoeff();
    p.position = spec.position.value_or(touching);
    if (p.penetration(touching, p.position) > 1e-9 * extent)
      spec.field.fail("position", "the paddle starts inside the body: it must be " +
                                      std::string(p.above ? "at or above " : "at or below ") +
                                      std::to_string(touching));
    p.travel = spec.travel ? *spec.travel
                           : (p.above ? -1.0 : 1.0) * spec.compression.value_or(0.0) * extent;
    return p;
  }

  // Central fibers resist no rigid rotation (a vector spring does): one that
  // the supports, mirror layers and paddles leave free makes Newton's tangent
  // singular (a body between frictionless paddles held at one point spins
  // freely about the paddles' axis). Where the loads do not turn the body
  // about it, the answer does not depend on it: one unknown that the
  // rotation moves most is held at zero (a gauge, in its own group "gauge",
  // whose reaction is zero at equilibrium) and a note says so. Where the
  // loads turn the body, no equilibrium exists: refused, naming the rotation.
  // Free translations are check_not_singular's (solve/stepping_common).
  void hold_free_rotations() {
    model::Model& m = c_.model;
    if (spec_.stepping.scheme != solve::Scheme::Newton ||
        m.material.kinematics != model::FiberKinematics::Central || m.constraints.empty())
      return;
    for (int held = 0; held < 3; ++held) {  // at most three rotations
      const std::vector<model::FreeMotion> free = model::free_rigid_motions(m);
      const auto rotation = std::find_if(free.begin(), free.end(), [](const model::FreeMotion& f) {
        return !f.rotation.isZero();
      });
      if (rotation == free.end()) return;
      const std::string motion = rotation->describe();
      const auto [vertex, axis] = model::gauge_unknown(m, *rotation);
      if (rotation->driven > 1e-9 || vertex < 0)  // m.constraints come from the file's groups
        spec_.constraints.front().field.fail(
            "", "the supports leave the " + motion +
                    " free, and the loads turn the body about it: no equilibrium exists: hold "
                    "a vertex away from the axis (a support with \"axes\" across it), make the "
                    "paddles \"sticking\", or clamp a face");
      if (m.constraint_groups.back() != "gauge") m.constraint_groups.push_back("gauge");
      const int group = static_cast<int>(m.constraint_groups.size()) - 1;
      m.constraints.push_back({vertex, axis, 0.0, {}, group});
      const int input =
          c_.model_to_input.empty() ? vertex : c_.model_to_input[static_cast<size_t>(vertex)];
      c_.notes.push_back("the supports and paddles leave the " + motion +
                         " free and the loads do not turn the body about it: vertex " +
                         std::to_string(input) + " is held along " +
                         std::string(1, static_cast<char>('x' + axis)) +
                         " as a gauge (group \"gauge\", its reaction zero at equilibrium); "
                         "a support that holds the rotation replaces it");
    }
  }
  // Two paddles on one axis may not meet (checked at every step by the solver too).
  void check_paddles_leave_room() const {
    for (const model::Paddle& a : c_.model.paddles)
      for (const model::Paddle& b : c_.model.paddles)
        if (a.axis == b.axis && a.above && !b.above &&
            !(a.plane(1.0) > b.plane(1.0) && a.position > b.position))
          spec_.paddles_field.fail("", "paddles " + a.label + " and " + b.label +
                                           " meet or pass each other: their travels leave no "
                                           "room for the body");
  }

  // A friction coefficient acts through Coulomb paddles only: refused where
  // none would feel it, rather than ignored.
  void check_friction_is_felt() const {
    if (c_.model.material.friction == 0.0 || c_.model.has_coulomb_paddle()) return;
    spec_.material.field.fail("friction",
                              "a friction coefficient acts at paddles with \"contact\": "
                              "\"coulomb\", and this experiment has none");
  }

  const CaseSpec& spec_;
  Case& c_;
  int dim_;
  std::vector<int> input_to_model_;
};

}  // namespace

std::vector<int> resolve_selection(const SelectionSpec& spec, const Case& c) {
  const Eigen::MatrixXd& V = c.model.surface.V;
  const int dim = c.model.dim();
  std::vector<int> selected;
  if (!spec.vertices.empty()) {
    std::vector<int> input_to_model(static_cast<size_t>(c.input_surface.num_vertices()), -1);
    for (size_t m = 0; m < c.model_to_input.size(); ++m)
      input_to_model[static_cast<size_t>(c.model_to_input[m])] = static_cast<int>(m);
    for (int input : spec.vertices) {
      if (input >= static_cast<int>(input_to_model.size()))
        spec.field.fail("vertices",
                        "vertex " + std::to_string(input) + " does not exist (the mesh has " +
                            std::to_string(input_to_model.size()) + " vertices, from 0)");
      const int m = input_to_model[static_cast<size_t>(input)];
      if (m < 0)
        spec.field.fail("vertices", "vertex " + std::to_string(input) + " belongs to no face");
      selected.push_back(m);
    }
  } else if (!spec.where.empty()) {
    try {
      selected = model::select_half_space(V, model::parse_half_space(spec.where, dim));
    } catch (const InputError& e) {
      spec.field.fail("where", e.what());
    }
    if (selected.empty()) spec.field.fail("where", "\"" + spec.where + "\" selects no vertex");
  } else {
    require_per_axis(spec.field, "box.min", spec.box_min, dim);
    require_per_axis(spec.field, "box.max", spec.box_max, dim);
    selected = model::select_box(V, spec.box_min, spec.box_max);
    if (selected.empty()) spec.field.fail("box", "the box selects no vertex");
  }
  return selected;
}

Case build_case(const CaseSpec& spec, std::vector<std::string>* warnings) {
  Case c;
  set_surface(build_surface(spec.surface, warnings), c);
  ModelBuilder(spec, c).build();
  add_fibers(spec, c);
  return c;
}

Case build_case(const CaseSpec& spec, const geom::Surface& surface,
                std::vector<std::string>* warnings) {
  if (!spec.surface.empty())
    spec.surface.field.fail("",
                            "the program gives the surface; the document must not name "
                            "one too");
  const std::string label = spec.surface.field.file + ": the given surface";
  const geom::MeshReport report = geom::inspect(surface);
  geom::require_usable(report, label);
  if (warnings)
    for (const auto& w : report.warnings) warnings->push_back(label + ": " + w);
  Case c;
  set_surface(surface, c);
  ModelBuilder(spec, c).build();
  add_fibers(spec, c);
  return c;
}

Case build_case(const CaseSpec& spec, const Case& earlier) {
  // The earlier case's surface_key is this one's: its surface and its
  // "fibers" section read the same, so the whole model built from them is
  // this case's too (copying some of its settings and not others lost the
  // influence: issue 43). ModelBuilder then sets every part that comes from
  // the rest of the spec.
  Case c;
  c.input_surface = earlier.input_surface;
  c.model_to_input = earlier.model_to_input;
  c.model = earlier.model;
  c.fibers = earlier.fibers;
  ModelBuilder(spec, c).build();
  estimate(spec, PruningWork::None, c);  // pruned once, for the earlier case
  return c;
}

}  // namespace fiberfluid::experiment
