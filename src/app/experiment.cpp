// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/experiment.hpp"

#include "app/json_fields.hpp"

#include <algorithm>
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
model::Material read_material(Fields f, int dim) {
  model::Material m;
  const json& y = f.raw("Y");
  if (y.is_array()) {
    const Eigen::VectorXd values = f.vector("Y", dim);
    m.young_modulus.setZero();
    m.young_modulus.head(dim) = values;
    if ((values.array() < 0).any()) f.fail("Y", "expected numbers >= 0");
  } else {
    m.young_modulus.setConstant(f.non_negative("Y", 0.0));
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
    load.label = f.string("label", type + " " + std::to_string(loads.size()));
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

std::vector<model::Constraint> read_constraints(Fields& root, const geom::Surface& surface,
                                                const std::vector<int>& input_to_model) {
  std::vector<model::Constraint> constraints;
  for (Fields f : root.objects("supports")) {
    const std::vector<int> vertices = read_selection(f, surface, input_to_model);
    const std::vector<int> axes = read_axes(f, surface.dim);
    f.finish();
    for (int v : vertices)
      for (int a : axes) constraints.push_back({v, a, 0.0, {}});
  }
  for (Fields f : root.objects("prescribed")) {
    const std::vector<int> vertices = read_selection(f, surface, input_to_model);
    const Eigen::VectorXd displacement = f.vector("displacement", surface.dim);
    const model::Schedule schedule = read_schedule(f, "ramp");
    f.finish();
    for (int v : vertices)
      for (int a = 0; a < surface.dim; ++a)
        constraints.push_back({v, a, displacement[a], schedule});
  }
  return constraints;
}

solve::SteppingOptions read_stepping(Fields f, solve::SteppingOptions options) {
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
  f.finish();
  return options;
}

void check_tables(const Fields& root, const model::Model& model, const Variant& variant) {
  auto check = [&](const model::Schedule& s, const std::string& what) {
    if (s.kind == model::Schedule::Kind::Table &&
        static_cast<int>(s.values.size()) != variant.stepping.steps)
      root.fail(what, "the schedule lists " + std::to_string(s.values.size()) +
                          " factors but run \"" + variant.name + "\" has " +
                          std::to_string(variant.stepping.steps) + " steps");
  };
  for (size_t l = 0; l < model.loads.size(); ++l)
    check(model.loads[l].schedule, "loads[" + std::to_string(l) + "].schedule");
  for (const model::Constraint& c : model.constraints) check(c.schedule, "prescribed.schedule");
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
void read_fibers(Fields& root, Experiment& ex) {
  std::string mode = "auto", count = "symmetric";
  if (root.has("fibers")) {
    Fields f = root.object("fibers");
    mode = f.choice("pruning", "auto", {"auto", "off"});
    count = f.choice("connection_count", "symmetric", {"symmetric", "global"});
    ex.fibers.write = f.choice("write", "none", {"none", "kept", "pruned"});
    f.finish();
  }
  model::Model& m = ex.model;
  m.connection_count =
      count == "global" ? model::ConnectionCount::Global : model::ConnectionCount::Symmetric;
  FiberReport& report = ex.fibers;
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

void read_simulation(Fields& root, const std::filesystem::path& folder, Experiment& ex) {
  Fields surface = root.object("surface");
  ex.input_surface = read_surface_spec(surface, folder, &ex.warnings);
  surface.finish();
  const geom::CompactSurface compact = geom::remove_unused_vertices(ex.input_surface);
  ex.model_to_input = compact.to_input;
  ex.model.surface = compact.surface;
  const int dim = ex.model.dim();
  ex.model.material = read_material(root.object("material"), dim);
  ex.model.loads = read_loads(root, ex.model.surface, compact.from_input);
  ex.model.constraints = read_constraints(root, ex.model.surface, compact.from_input);
  read_fibers(root, ex);

  solve::SteppingOptions base;
  if (root.has("stepping")) base = read_stepping(root.object("stepping"), base);
  for (Fields f : root.objects("variants")) {
    Variant v;
    v.name = f.string("name");
    v.stepping = f.has("stepping") ? read_stepping(f.object("stepping"), base) : base;
    f.finish();
    ex.variants.push_back(v);
  }
  if (ex.variants.empty()) ex.variants.push_back({"", base});
  for (const Variant& v : ex.variants) check_tables(root, ex.model, v);

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

Experiment load_experiment(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string() + ": cannot open the experiment file");
  json document;
  try {
    document = json::parse(in);
  } catch (const json::parse_error& e) {
    throw InputError(path.string() + ": not valid JSON: " + e.what());
  }
  Fields root(document, "", path.string());
  Experiment ex;
  ex.source = path;
  ex.name = root.string("name", path.stem().string());
  ex.description = root.string("description", "");
  ex.kind = root.choice("kind", "simulate", {"simulate", "areas"}) == "areas"
                ? Experiment::Kind::Areas
                : Experiment::Kind::Simulate;
  const std::filesystem::path folder = path.parent_path();
  if (ex.kind == Experiment::Kind::Simulate) read_simulation(root, folder, ex);
  else read_areas(root, folder, ex);
  ex.expected = read_expected(root);
  root.finish();
  return ex;
}

}  // namespace fiberfluid::app
