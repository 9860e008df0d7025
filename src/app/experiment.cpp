// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/experiment.hpp"

#include "app/json_fields.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "geom/error.hpp"
#include "geom/fiber_pruning.hpp"
#include "geom/generators.hpp"
#include "geom/mesh_check.hpp"
#include "geom/mesh_io.hpp"
#include "model/boundary_conditions.hpp"

namespace fiberfluid::app {
namespace {

using nlohmann::json;

// ------------------------------------------------------------ surfaces
geom::Surface read_generator(Fields& f) {
  const std::string kind =
      f.choice("generator", "", {"icosphere", "tetrahedron", "octahedron", "icosahedron", "cube",
                                 "box", "dome", "rectangle", "polygon"});
  if (kind == "icosphere")
    return geom::icosphere(f.integer("subdivisions", 2, 0, 7), f.positive("radius", 1.0));
  if (kind == "tetrahedron") return geom::tetrahedron(f.positive("radius", 1.0));
  if (kind == "octahedron") return geom::octahedron(f.positive("radius", 1.0));
  if (kind == "icosahedron") return geom::icosahedron(f.positive("radius", 1.0));
  if (kind == "cube") return geom::cube(f.positive("edge", 1.0));
  if (kind == "box") {
    const Eigen::Vector3d min = f.vector("min", 3), max = f.vector("max", 3);
    Eigen::Vector3i segments = Eigen::Vector3i::Ones();
    if (f.has("segments")) segments = f.vector("segments", 3).cast<int>();
    if ((min.array() >= max.array()).any()) f.fail("max", "must exceed min on every axis");
    if ((segments.array() < 1).any() || (segments.array() > 200).any())
      f.fail("segments", "expected 3 whole numbers from 1 to 200");
    return geom::box(min, max, segments);
  }
  if (kind == "dome")
    return geom::dome(f.vector("semi_axes", 3), f.integer("subdivisions", 2, 0, 6));
  if (kind == "rectangle") {
    const Eigen::Vector2d min = f.vector("min", 2), max = f.vector("max", 2);
    Eigen::Vector2i segments = Eigen::Vector2i::Ones();
    if (f.has("segments")) segments = f.vector("segments", 2).cast<int>();
    if ((min.array() >= max.array()).any()) f.fail("max", "must exceed min on both axes");
    if ((segments.array() < 1).any()) f.fail("segments", "expected 2 whole numbers from 1");
    return geom::rectangle(min, max, segments.x(), segments.y());
  }
  // polygon
  const json& points = f.raw("points");
  if (!points.is_array() || points.size() < 3)
    f.fail("points", "expected a list of at least 3 [x, y] points");
  Eigen::MatrixXd P(static_cast<Eigen::Index>(points.size()), 2);
  for (size_t k = 0; k < points.size(); ++k) {
    if (!points[k].is_array() || points[k].size() != 2 || !points[k][0].is_number() ||
        !points[k][1].is_number())
      f.fail("points", "expected [x, y] pairs, got " + points[k].dump());
    P.row(static_cast<Eigen::Index>(k)) << points[k][0].get<double>(), points[k][1].get<double>();
  }
  return geom::polygon(P);
}

// Reads a surface from "file" (with "flip") or "generator", then "scale".
geom::Surface read_surface_spec(Fields& f, const std::filesystem::path& folder,
                                std::vector<std::string>* warnings) {
  geom::Surface surface;
  if (f.has("file") == f.has("generator"))
    f.fail("", "expected exactly one of \"file\" or \"generator\"");
  if (f.has("file")) {
    std::filesystem::path path = f.string("file");
    if (path.is_relative()) path = folder / path;
    const bool flip = f.boolean("flip", false);
    try {
      surface = load_checked_surface(path, flip, warnings);
    } catch (const InputError& e) {
      f.fail("file", e.what());  // names the experiment field as well as the mesh
    }
  } else {
    surface = read_generator(f);
    const geom::MeshReport report = geom::inspect(surface);
    geom::require_usable(report, f.file() + ": " + f.name("generator"));
  }
  surface.V *= f.positive("scale", 1.0);
  return surface;
}

// ------------------------------------------------------------ selections
model::Schedule read_schedule(Fields& f, const std::string& fallback) {
  model::Schedule schedule;
  if (f.has("schedule") && f.raw("schedule").is_array()) {
    schedule.kind = model::Schedule::Kind::Table;
    const Eigen::VectorXd values = f.vector("schedule", -1);
    schedule.values.assign(values.data(), values.data() + values.size());
    return schedule;
  }
  const std::string name = f.choice("schedule", fallback, {"ramp", "final", "up_down"});
  schedule.kind = name == "ramp"    ? model::Schedule::Kind::Ramp
                  : name == "final" ? model::Schedule::Kind::Final
                                    : model::Schedule::Kind::UpDown;
  return schedule;
}

// The model vertices chosen by exactly one of "vertices" (input indices),
// "where" (a half-space) or "box".
std::vector<int> read_selection(Fields& f, const geom::Surface& model_surface,
                                const std::vector<int>& input_to_model) {
  const int chosen = f.has("vertices") + f.has("where") + f.has("box");
  if (chosen != 1) f.fail("", "expected exactly one of \"vertices\", \"where\" or \"box\"");
  std::vector<int> selected;
  if (f.has("vertices")) {
    for (int input : f.indices("vertices")) {
      if (input >= static_cast<int>(input_to_model.size()))
        f.fail("vertices", "vertex " + std::to_string(input) + " does not exist (the mesh has " +
                               std::to_string(input_to_model.size()) + " vertices, from 0)");
      if (input_to_model[static_cast<size_t>(input)] < 0)
        f.fail("vertices", "vertex " + std::to_string(input) + " belongs to no face");
      selected.push_back(input_to_model[static_cast<size_t>(input)]);
    }
  } else if (f.has("where")) {
    const std::string text = f.string("where");
    try {
      selected = model::select_half_space(model_surface.V,
                                          model::parse_half_space(text, model_surface.dim));
    } catch (const InputError& e) {
      f.fail("where", e.what());
    }
    if (selected.empty()) f.fail("where", "\"" + text + "\" selects no vertex");
  } else {
    Fields box = f.object("box");
    const Eigen::VectorXd min = box.vector("min", model_surface.dim);
    const Eigen::VectorXd max = box.vector("max", model_surface.dim);
    box.finish();
    selected = model::select_box(model_surface.V, min, max);
    if (selected.empty()) f.fail("box", "the box selects no vertex");
  }
  return selected;
}

std::vector<int> read_axes(Fields& f, int dim) {
  const std::string text = f.string("axes", dim == 3 ? "xyz" : "xy");
  std::vector<int> axes;
  for (char c : text) {
    const int a = c - 'x';
    if (a < 0 || a >= dim || std::count(text.begin(), text.end(), c) > 1)
      f.fail("axes", "expected distinct letters from \"" + std::string("xyz").substr(0, dim) +
                         "\", got \"" + text + "\"");
    axes.push_back(a);
  }
  return axes;
}

// ------------------------------------------------------------ model parts
double required_positive(Fields& f, const std::string& key) {
  const double x = f.number(key);
  if (!(x > 0.0)) f.fail(key, "expected a positive number, got " + std::to_string(x));
  return x;
}

model::FiberLaw read_law(Fields f) {
  const std::string type =
      f.choice("type", "constant", {"constant", "exponential", "bilinear", "tabulated"});
  model::FiberLaw law;
  if (type == "constant") {
    const double Y = f.number("Y");
    if (Y < 0.0) f.fail("Y", "expected a number >= 0, got " + std::to_string(Y));
    law = model::FiberLaw::constant(Y);
  } else if (type == "exponential") {
    law = model::FiberLaw::exponential(required_positive(f, "Y0"), f.number("beta"));
  } else if (type == "bilinear") {
    const double Y_t = required_positive(f, "Y_t"), Y_c = required_positive(f, "Y_c");
    law = model::FiberLaw::bilinear(Y_t, Y_c, f.non_negative("transition", 0.005));
  } else {
    const Eigen::VectorXd strain = f.vector("strain", -1), stress = f.vector("stress", -1);
    if (stress.size() != strain.size())
      f.fail("stress", "expected as many stresses as strains (" + std::to_string(strain.size()) +
                           "), got " + std::to_string(stress.size()));
    law = model::FiberLaw::tabulated({strain.data(), strain.data() + strain.size()},
                                     {stress.data(), stress.data() + stress.size()});
    law.set_parameter("scale", f.positive("scale", 1.0));
  }
  f.finish();
  const std::string why = law.check();
  if (!why.empty()) f.fail(type == "tabulated" ? "stress" : "", why);
  return law;
}

model::Material read_material(Fields f, int dim) {
  model::Material m;
  if (f.has("law") && f.has("Y"))
    f.fail("Y", "give either Y (the linear model) or a law with its parameters, not both");
  if (f.has("law")) {
    m.law = read_law(f.object("law"));
    if (f.has("axis_factors")) {
      const Eigen::VectorXd factors = f.vector("axis_factors", dim);
      if (!(factors.array() > 0).all()) f.fail("axis_factors", "expected positive numbers");
      m.axis_factors.head(dim) = factors;
    }
  } else if (f.raw("Y").is_array()) {
    // The paper's per-axis moduli: the constant law 1 times exact factors.
    const Eigen::VectorXd values = f.vector("Y", dim);
    if ((values.array() < 0).any()) f.fail("Y", "expected numbers >= 0");
    m.law = model::FiberLaw::constant(1.0);
    m.axis_factors.setZero();
    m.axis_factors.head(dim) = values;
  } else {
    m.law = model::FiberLaw::constant(f.non_negative("Y", 0.0));
  }
  m.surface_tension = f.non_negative("gamma", 0.0);
  f.finish();
  return m;
}

std::vector<model::Load> read_loads(Fields& root, const geom::Surface& surface,
                                    const std::vector<int>& input_to_model) {
  std::vector<model::Load> loads;
  for (Fields f : root.objects("loads")) {
    model::Load load;
    const std::string type = f.choice("type", "", {"gravity", "point"});
    load.label = f.string("label", type + "_" + std::to_string(loads.size()));
    if (type == "gravity") {
      load.kind = model::Load::Kind::Hydrostatic;
      load.acceleration.head(surface.dim) = f.vector("acceleration", surface.dim);
      load.density = f.positive("density", 1000.0);
      load.schedule = read_schedule(f, "ramp");
    } else {
      load.kind = model::Load::Kind::Point;
      const int input = f.integer("vertex", 0, 0, static_cast<int>(input_to_model.size()) - 1);
      if (input_to_model[static_cast<size_t>(input)] < 0)
        f.fail("vertex", "vertex " + std::to_string(input) + " belongs to no face");
      load.vertex = input_to_model[static_cast<size_t>(input)];
      load.force.head(surface.dim) = f.vector("force", surface.dim);
      load.schedule = read_schedule(f, "ramp");
    }
    f.finish();
    loads.push_back(load);
  }
  return loads;
}

// Each entry of "supports" and "prescribed" is a group with its own reaction
// force, named by "label" (default support_K / prescribed_K).
void read_constraints(Fields& root, const geom::Surface& surface,
                      const std::vector<int>& input_to_model, model::Model& model) {
  auto add_group = [&](Fields& f, const std::string& fallback) {
    const std::string label = f.string("label", fallback);
    for (const std::string& other : model.constraint_groups)
      if (other == label) f.fail("label", "\"" + label + "\" names another group already");
    model.constraint_groups.push_back(label);
    return static_cast<int>(model.constraint_groups.size()) - 1;
  };
  int k = 0;
  for (Fields f : root.objects("supports")) {
    const int group = add_group(f, "support_" + std::to_string(k++));
    const std::vector<int> vertices = read_selection(f, surface, input_to_model);
    const std::vector<int> axes = read_axes(f, surface.dim);
    f.finish();
    for (int v : vertices)
      for (int a : axes) model.constraints.push_back({v, a, 0.0, {}, group});
  }
  k = 0;
  for (Fields f : root.objects("prescribed")) {
    const int group = add_group(f, "prescribed_" + std::to_string(k++));
    const std::vector<int> vertices = read_selection(f, surface, input_to_model);
    const Eigen::VectorXd displacement = f.vector("displacement", surface.dim);
    const model::Schedule schedule = read_schedule(f, "ramp");
    f.finish();
    for (int v : vertices)
      for (int a = 0; a < surface.dim; ++a)
        model.constraints.push_back({v, a, displacement[a], schedule, group});
  }
}

// Rigid paddles: planes normal to an axis on one side of the body, moving by
// "travel" (m) or by "compression" (a share of the body's extent along the
// axis, towards the body). "position" defaults to touching the body.
std::vector<model::Paddle> read_paddles(Fields& root, const geom::Surface& surface) {
  std::vector<model::Paddle> paddles;
  for (Fields f : root.objects("paddles")) {
    model::Paddle p;
    p.label = f.string("label", "paddle_" + std::to_string(paddles.size()));
    for (const model::Paddle& other : paddles)
      if (other.label == p.label) f.fail("label", "\"" + p.label + "\" names another paddle");
    const std::string axis = f.string("axis");
    if (axis.size() != 1 || axis[0] < 'x' || axis[0] >= 'x' + surface.dim)
      f.fail("axis", "expected one of \"" + std::string("xyz").substr(0, surface.dim) +
                         "\" (the paddle's normal), got \"" + axis + "\"");
    p.axis = axis[0] - 'x';
    p.above = f.choice("side", "", {"above", "below"}) == "above";
    const Eigen::VectorXd along = surface.V.col(p.axis);
    const double extent = along.maxCoeff() - along.minCoeff();
    p.position = f.number("position", p.above ? along.maxCoeff() : along.minCoeff());
    if (p.penetration(p.above ? along.maxCoeff() : along.minCoeff(), p.position) >
        1e-9 * extent)
      f.fail("position", "the paddle starts inside the body: it must be " +
                             std::string(p.above ? "at or above " : "at or below ") +
                             std::to_string(p.above ? along.maxCoeff() : along.minCoeff()));
    if (f.has("travel") == f.has("compression"))
      f.fail("travel", "give either travel (m, along the axis) or compression (a share of "
                       "the body's extent), one of them");
    if (f.has("travel")) {
      p.travel = f.number("travel");
    } else {
      const double share = f.number("compression");
      if (!(share > 0.0 && share < 1.0))
        f.fail("compression", "expected a share of the body's extent between 0 and 1");
      p.travel = (p.above ? -1.0 : 1.0) * share * extent;
    }
    p.schedule = read_schedule(f, "ramp");
    p.sticking = f.choice("contact", "frictionless", {"frictionless", "sticking"}) == "sticking";
    f.finish();
    paddles.push_back(p);
  }
  // Two paddles on one axis may not meet (checked at every step by the solver too).
  for (const model::Paddle& a : paddles)
    for (const model::Paddle& b : paddles)
      if (a.axis == b.axis && a.above && !b.above &&
          !(a.plane(1.0) > b.plane(1.0) && a.position > b.position))
        root.fail("paddles", "paddles " + a.label + " and " + b.label +
                                 " meet or pass each other: their travels leave no room for "
                                 "the body");
  return paddles;
}

solve::NewtonOptions read_newton(Fields f, solve::NewtonOptions o) {
  o.residual_tolerance = f.positive("residual_tolerance", o.residual_tolerance);
  o.increment_tolerance = f.positive("increment_tolerance", o.increment_tolerance);
  o.max_iterations = f.integer("max_iterations", o.max_iterations, 1, 10000);
  o.max_step_cuts = f.integer("max_step_cuts", o.max_step_cuts, 0, 30);
  o.line_search = f.boolean("line_search", o.line_search);
  const std::string tangent = f.choice("tangent", "auto", {"auto", "dense", "krylov"});
  o.tangent = tangent == "dense"    ? solve::TangentSolver::Dense
              : tangent == "krylov" ? solve::TangentSolver::Krylov
                                    : solve::TangentSolver::Auto;
  o.krylov_tolerance = f.positive("krylov_tolerance", o.krylov_tolerance);
  o.krylov_restart = f.integer("krylov_restart", o.krylov_restart, 1, 1000);
  o.krylov_max_iterations = f.integer("krylov_max_iterations", o.krylov_max_iterations, 1, 100000);
  o.max_contact_rounds = f.integer("max_contact_rounds", o.max_contact_rounds, 1, 1000);
  f.finish();
  return o;
}

solve::SteppingOptions read_stepping(Fields f, solve::SteppingOptions options) {
  options.scheme = f.choice("scheme", "incremental", {"incremental", "newton"}) == "newton"
                       ? solve::Scheme::Newton
                       : solve::Scheme::Incremental;
  if (f.has("newton")) {
    if (options.scheme != solve::Scheme::Newton)
      f.fail("newton", "Newton options need \"scheme\": \"newton\"");
    options.newton = read_newton(f.object("newton"), options.newton);
  }
  options.steps = f.integer("steps", options.steps, 1, 100000);
  options.rebuild_matrix = f.boolean("rebuild_matrix", options.rebuild_matrix);
  options.update_load_geometry = f.boolean("update_load_geometry", options.update_load_geometry);
  const std::string method = f.choice("boundary_method",
                                      model::to_string(options.boundary_method),
                                      {"elimination", "penalty"});
  options.boundary_method = method == "penalty" ? model::BoundaryMethod::Penalty
                                                : model::BoundaryMethod::Elimination;
  options.penalty = f.positive("penalty", options.penalty);
  const std::string solver = f.choice("solver", solve::to_string(options.solver),
                                      {"auto", "dense-lu", "block-cholesky", "cholmod", "pcg"});
  options.solver = *solve::solver_kind_from_string(solver);
  options.pcg.tolerance = f.positive("tolerance", options.pcg.tolerance);
  options.pcg.max_iterations = f.integer("max_iterations", options.pcg.max_iterations, 1, 1000000);
  options.max_volume_change = f.positive("max_volume_change", options.max_volume_change);
  options.stop_on_inverted_faces =
      f.boolean("stop_on_inverted_faces", options.stop_on_inverted_faces);
  f.finish();
  return options;
}

void check_tables(const Fields& root, const Case& c) {
  auto check = [&](const model::Schedule& s, const std::string& what) {
    if (s.kind == model::Schedule::Kind::Table &&
        static_cast<int>(s.values.size()) != c.stepping.steps)
      root.fail(what, "the schedule lists " + std::to_string(s.values.size()) +
                          " factors but stepping.steps is " + std::to_string(c.stepping.steps));
  };
  for (size_t l = 0; l < c.model.loads.size(); ++l)
    check(c.model.loads[l].schedule, "loads[" + std::to_string(l) + "].schedule");
  for (const model::Constraint& k : c.model.constraints) check(k.schedule, "prescribed.schedule");
  for (size_t p = 0; p < c.model.paddles.size(); ++p)
    check(c.model.paddles[p].schedule, "paddles[" + std::to_string(p) + "].schedule");
}

std::vector<ExpectedFigure> read_expected(Fields& root) {
  std::vector<ExpectedFigure> expected;
  for (Fields f : root.objects("expected")) {
    ExpectedFigure e;
    e.figure = f.string("figure");
    e.note = f.string("note", "");
    if (f.has("value") && f.raw("value").is_array()) {
      const json& rows = f.raw("value");
      e.matrix.resize(static_cast<Eigen::Index>(rows.size()),
                      rows.empty() ? 0 : static_cast<Eigen::Index>(rows[0].size()));
      for (size_t r = 0; r < rows.size(); ++r) {
        if (!rows[r].is_array() || rows[r].size() != static_cast<size_t>(e.matrix.cols()))
          f.fail("value", "expected a number or a matrix (a list of equal-length rows)");
        for (size_t c = 0; c < rows[r].size(); ++c) {
          if (!rows[r][c].is_number()) f.fail("value", "expected numbers in the matrix");
          e.matrix(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) =
              rows[r][c].get<double>();
        }
      }
    } else if (f.has("value")) {
      e.value = f.number("value");
    }
    e.tolerance = f.non_negative("tolerance", 0.0);
    if (f.has("at_most")) e.at_most = f.number("at_most");
    if (f.has("at_least")) e.at_least = f.number("at_least");
    if (!e.value && e.matrix.size() == 0 && !e.at_most && !e.at_least)
      f.fail("", "expected \"value\", \"at_most\" or \"at_least\"");
    f.finish();
    expected.push_back(e);
  }
  return expected;
}

// Reads "fibers" and prunes the fibers that leave a concave body.
void read_fibers(Fields& root, Case& c) {
  std::string mode = "auto", count = "symmetric";
  if (root.has("fibers")) {
    Fields f = root.object("fibers");
    mode = f.choice("pruning", "auto", {"auto", "off"});
    count = f.choice("connection_count", "symmetric", {"symmetric", "global"});
    c.fibers.write = f.choice("write", "none", {"none", "kept", "pruned"});
    f.finish();
  }
  model::Model& m = c.model;
  m.connection_count =
      count == "global" ? model::ConnectionCount::Global : model::ConnectionCount::Symmetric;
  FiberReport& report = c.fibers;
  report.pruning = mode == "auto";
  const int n = m.num_vertices();
  report.pairs = static_cast<long long>(n) * (n - 1) / 2;
  report.kept = report.pairs;
  report.min_per_vertex = report.max_per_vertex = n - 1;
  report.mean_per_vertex = n - 1;
  if (!report.pruning) return;
  report.convex = geom::is_convex(m.surface);
  if (report.convex) return;
  // N^2 pair tests (5,000 vertices: about 2 minutes here) and an N^2 byte table.
  constexpr int kLargestPruned = 10000;
  if (n > kLargestPruned)
    root.fail("fibers.pruning", "a concave body of " + std::to_string(n) +
                                    " vertices is beyond exact pruning (at most " +
                                    std::to_string(kLargestPruned) + "); set \"off\"");
  geom::PruningResult pruned = geom::prune_fibers(m.surface);
  report.seconds = pruned.seconds;
  report.exact_fallbacks = pruned.exact_fallbacks;
  report.kept = pruned.mask.num_kept();
  const std::vector<int> per_vertex = pruned.mask.kept_per_vertex();
  report.min_per_vertex = *std::min_element(per_vertex.begin(), per_vertex.end());
  report.max_per_vertex = *std::max_element(per_vertex.begin(), per_vertex.end());
  report.mean_per_vertex = 2.0 * report.kept / n;
  if (report.min_per_vertex == 0)
    root.fail("fibers.pruning", "vertex " +
                                    std::to_string(std::find(per_vertex.begin(), per_vertex.end(), 0) -
                                                   per_vertex.begin()) +
                                    " keeps no fiber: is the mesh self-intersecting?");
  m.fibers = std::make_shared<const geom::FiberMask>(std::move(pruned.mask));
}

// The surface, its compaction and its fibers: what several variants that
// share "surface" and "fibers" build once (pruning a large mesh takes seconds).
struct SurfaceKey {
  std::string surface, fibers;
  bool operator==(const SurfaceKey& o) const { return surface == o.surface && fibers == o.fibers; }
};

// Builds one case from a complete simulation document, reusing the surface
// and fibers of an earlier case with the same "surface" and "fibers".
void build_case(Fields& root, const std::filesystem::path& folder, std::vector<Case>& built,
                std::vector<SurfaceKey>& keys, std::vector<std::string>* warnings, Case& c) {
  const SurfaceKey key{root.raw("surface").dump(),
                       root.has("fibers") ? root.raw("fibers").dump() : std::string()};
  const auto same = std::find(keys.begin(), keys.end(), key);
  if (same != keys.end()) {
    const Case& earlier = built[static_cast<size_t>(same - keys.begin())];
    c.input_surface = earlier.input_surface;
    c.model_to_input = earlier.model_to_input;
    c.model.surface = earlier.model.surface;
    c.model.fibers = earlier.model.fibers;
    c.model.connection_count = earlier.model.connection_count;
    c.fibers = earlier.fibers;
  } else {
    Fields surface = root.object("surface");
    c.input_surface = read_surface_spec(surface, folder, warnings);
    surface.finish();
    const geom::CompactSurface compact = geom::remove_unused_vertices(c.input_surface);
    c.model_to_input = compact.to_input;
    c.model.surface = compact.surface;
    read_fibers(root, c);
  }
  std::vector<int> from_input(static_cast<size_t>(c.input_surface.num_vertices()), -1);
  for (size_t m = 0; m < c.model_to_input.size(); ++m)
    from_input[static_cast<size_t>(c.model_to_input[m])] = static_cast<int>(m);
  const int dim = c.model.dim();
  c.model.material = read_material(root.object("material"), dim);
  c.model.loads = read_loads(root, c.model.surface, from_input);
  read_constraints(root, c.model.surface, from_input, c.model);
  c.model.paddles = read_paddles(root, c.model.surface);
  c.stepping = root.has("stepping") ? read_stepping(root.object("stepping"), {})
                                    : solve::SteppingOptions{};
  if (!c.model.paddles.empty() && c.stepping.scheme != solve::Scheme::Newton)
    root.fail("paddles", "paddles need \"stepping\": {\"scheme\": \"newton\"} (contact is "
                         "an active set inside the equilibrium iterations)");
  if (!c.model.material.law.is_constant() && c.stepping.scheme == solve::Scheme::Incremental &&
      !c.stepping.rebuild_matrix && warnings != nullptr)
    warnings->push_back("material.law: the incremental scheme without stepping.rebuild_matrix "
                        "uses the small-strain modulus Y(0) throughout; set rebuild_matrix or "
                        "scheme \"newton\" for the strain-dependent law");
  check_tables(root, c);
  root.finish();
  keys.push_back(key);
}

// Fields of the experiment that a variant may not patch.
const char* const kExperimentFields[] = {"name", "description", "kind", "variants", "expected",
                                         "output"};

void check_variant_name(const Fields& f, const std::string& name,
                        const std::vector<Case>& earlier) {
  const bool safe = !name.empty() && name != "." && name != ".." &&
                    std::all_of(name.begin(), name.end(), [](unsigned char ch) {
                      return std::isalnum(ch) || ch == '_' || ch == '-' || ch == '.';
                    });
  if (!safe)
    f.fail("name", "expected a non-empty name of letters, digits, '_', '-' or '.' (it names "
                   "the variant's output folder), got \"" + name + "\"");
  for (const Case& c : earlier)
    if (c.variant == name) f.fail("name", "\"" + name + "\" names another variant already");
}

// A simulation: the base document, or one case per variant, each the base
// with the variant's JSON merge patch (RFC 7386) applied.
void read_simulation(Fields& root, const nlohmann::json& document,
                     const std::filesystem::path& folder, Experiment& ex) {
  json base = document;
  for (const char* field : kExperimentFields) base.erase(field);
  std::vector<SurfaceKey> keys;
  if (!root.has("variants")) {
    Fields f(base, "", root.file());
    Case c;
    build_case(f, folder, ex.cases, keys, &ex.warnings, c);
    ex.cases.push_back(std::move(c));
  } else {
    const json& variants = root.raw("variants");
    if (!variants.is_array() || variants.empty())
      root.fail("variants", "expected a non-empty list of objects");
    for (size_t k = 0; k < variants.size(); ++k) {
      Fields v(variants[k], "variants[" + std::to_string(k) + "]", root.file());
      Case c;
      c.variant = v.string("name");
      check_variant_name(v, c.variant, ex.cases);
      c.patch = variants[k];
      c.patch.erase("name");
      for (const char* field : kExperimentFields)
        if (c.patch.contains(field))
          v.fail(field, "belongs to the whole experiment; a variant cannot change it");
      json patched = base;
      patched.merge_patch(c.patch);
      Fields f(patched, "", root.file() + " [variant " + c.variant + "]");
      build_case(f, folder, ex.cases, keys, &ex.warnings, c);
      ex.cases.push_back(std::move(c));
    }
  }
  if (root.has("output")) {
    Fields f = root.object("output");
    ex.output.vtk = f.boolean("vtk", true);
    ex.output.obj = f.boolean("obj", true);
    ex.output.every = f.integer("every", 1, 1, 1000000);
    f.finish();
  }
}

void read_areas(Fields& root, const std::filesystem::path& folder, Experiment& ex) {
  for (Fields f : root.objects("surfaces")) {
    NamedSurface named;
    named.name = f.string("name");
    named.surface = read_surface_spec(f, folder, &ex.warnings);
    f.finish();
    ex.area_surfaces.push_back(named);
  }
  if (ex.area_surfaces.empty()) root.fail("surfaces", "expected at least one surface");
}

}  // namespace

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

Experiment parse_experiment(const json& document, const std::filesystem::path& folder,
                            const std::string& label) {
  Fields root(document, "", label);
  Experiment ex;
  ex.name = root.string("name", "experiment");
  ex.description = root.string("description", "");
  ex.kind = root.choice("kind", "simulate", {"simulate", "areas"}) == "areas"
                ? Experiment::Kind::Areas
                : Experiment::Kind::Simulate;
  ex.expected = read_expected(root);
  if (ex.kind == Experiment::Kind::Simulate) {
    read_simulation(root, document, folder, ex);  // each case checks its own fields
  } else {
    read_areas(root, folder, ex);
    root.finish();
  }
  return ex;
}

Experiment load_experiment(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string() + ": cannot open the experiment file");
  json document;
  try {
    document = json::parse(in);
  } catch (const json::parse_error& e) {
    throw InputError(path.string() + ": not valid JSON: " + e.what());
  }
  if (document.is_object() && !document.contains("name")) document["name"] = path.stem().string();
  Experiment ex = parse_experiment(document, path.parent_path(), path.string());
  ex.source = path;
  return ex;
}

}  // namespace fiberfluid::app
