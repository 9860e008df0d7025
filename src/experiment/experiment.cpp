// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/experiment.hpp"

#include "fiberfluid/experiment/figures.hpp"
#include "fiberfluid/experiment/json_fields.hpp"
#include "fiberfluid/experiment/output_folder.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <functional>
#include <istream>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::experiment {
namespace {

using nlohmann::json;

// ------------------------------------------------------------ surfaces
// A generator's parameters, checked now; the surface is made when the case is
// built. *vertices: about how many vertices it will make (its cost is
// checked against the budgets before it is built).
std::function<geom::Surface()> read_generator(Fields& f, double* vertices) {
  const std::string kind =
      f.choice("generator", "",
               {"icosphere", "tetrahedron", "octahedron", "icosahedron", "cube", "box", "dome",
                "cylinder", "torus", "rectangle", "polygon"});
  if (kind == "icosphere") {
    const int subdivisions = f.integer("subdivisions", 2, 0, 7);
    const double radius = f.positive("radius", 1.0);
    *vertices = 10.0 * std::pow(4.0, subdivisions) + 2.0;
    return [=] { return geom::icosphere(subdivisions, radius); };
  }
  if (kind == "tetrahedron" || kind == "octahedron" || kind == "icosahedron") {
    const double radius = f.positive("radius", 1.0);
    if (kind == "tetrahedron") return [=] { return geom::tetrahedron(radius); };
    if (kind == "octahedron") return [=] { return geom::octahedron(radius); };
    return [=] { return geom::icosahedron(radius); };
  }
  if (kind == "cube") {
    const double edge = f.positive("edge", 1.0);
    return [=] { return geom::cube(edge); };
  }
  if (kind == "box") {
    const Eigen::Vector3d min = f.vector("min", 3), max = f.vector("max", 3);
    Eigen::Vector3i segments = Eigen::Vector3i::Ones();
    if (f.has("segments")) segments = f.counts("segments", 3, 1, 200);
    if ((min.array() >= max.array()).any()) f.fail("max", "must exceed min on every axis");
    const Eigen::Vector3d n = (segments.array() + 1).cast<double>();
    *vertices = 2.0 * (n.x() * n.y() + n.y() * n.z() + n.z() * n.x());
    return [=] { return geom::box(min, max, segments); };
  }
  if (kind == "dome") {
    const Eigen::Vector3d semi_axes = f.vector("semi_axes", 3);
    const int subdivisions = f.integer("subdivisions", 2, 0, 6);
    const geom::DomeBase base =
        f.enumeration("base", geom::DomeBase::Icosahedron, geom::kDomeBaseNames);
    const bool octahedral = base == geom::DomeBase::Octahedron;
    *vertices = (octahedral ? 4.0 : 10.0) * std::pow(4.0, subdivisions) + 2.0;
    return [=] { return geom::dome(semi_axes, subdivisions, base); };
  }
  if (kind == "cylinder") {
    const double radius = f.positive("radius", 1.0), length = f.positive("length", 1.0);
    Eigen::Vector2i segments(24, 24);
    if (f.has("segments")) segments = f.counts("segments", 2, 1, 1000);
    if (segments.y() < 3) f.fail("segments", "expected at least 3 segments around");
    const int cap_rings = f.integer("cap_rings", 0, 0, 1000);
    const double rings =
        segments.x() + 1.0 + 2.0 * (cap_rings > 0 ? cap_rings : segments.y() / 6.0);
    *vertices = rings * segments.y() + 2.0;
    return [=] { return geom::cylinder(radius, length, segments.x(), segments.y(), cap_rings); };
  }
  if (kind == "torus") {
    const double major = f.positive("major_radius", 2.0), minor = f.positive("minor_radius", 0.7);
    if (minor >= major)
      f.fail("minor_radius", "must be below major_radius (a ring, not a spindle)");
    Eigen::Vector2i segments(40, 20);
    if (f.has("segments")) segments = f.counts("segments", 2, 3, 1000);
    *vertices = static_cast<double>(segments.x()) * segments.y();
    return [=] { return geom::torus(major, minor, segments.x(), segments.y()); };
  }
  if (kind == "rectangle") {
    const Eigen::Vector2d min = f.vector("min", 2), max = f.vector("max", 2);
    Eigen::Vector2i segments = Eigen::Vector2i::Ones();
    if (f.has("segments")) segments = f.counts("segments", 2, 1, 1000);
    if ((min.array() >= max.array()).any()) f.fail("max", "must exceed min on both axes");
    return [=] { return geom::rectangle(min, max, segments.x(), segments.y()); };
  }
  // polygon
  const json& points = f.raw("points");
  if (!points.is_array() || points.size() < 3)
    f.fail("points", "expected a list of at least 3 [x, y] points");
  Eigen::MatrixXd P(static_cast<Eigen::Index>(points.size()), 2);
  for (size_t k = 0; k < points.size(); ++k) {
    if (!points[k].is_array() || points[k].size() != 2 || !points[k][0].is_number() ||
        !points[k][1].is_number())
      f.fail("points", "expected [x, y] pairs, got " + excerpt(points[k]));
    P.row(static_cast<Eigen::Index>(k)) << points[k][0].get<double>(), points[k][1].get<double>();
  }
  return [=] { return geom::polygon(P); };
}

// "file" (with "flip") or "generator", then "scale" and "remesh_vertices".
// A file's path as the resolved experiment gives it: absolute, so that it
// reads the same file from any folder.
std::string absolute_path(const std::filesystem::path& path) {
  return std::filesystem::absolute(path).lexically_normal().string();
}

SurfaceSpec read_surface_spec(Fields& f, const std::filesystem::path& folder) {
  SurfaceSpec spec;
  spec.field = f.field();
  if (f.has("file") == f.has("generator"))
    f.fail("", "expected exactly one of \"file\" or \"generator\"");
  if (f.has("file")) {
    spec.file = f.string("file");
    if (spec.file.is_relative()) spec.file = folder / spec.file;
    f.resolve("file", absolute_path(spec.file));
    spec.flip = f.boolean("flip", false);
  } else {
    spec.generate = read_generator(f, &spec.expected_vertices);
    spec.generator = f.string("generator");
  }
  spec.scale = f.positive("scale", 1.0);
  if (f.has("remesh_vertices")) spec.remesh_vertices = f.integer("remesh_vertices", 0, 20, 1000000);
  return spec;
}

// ------------------------------------------------------------ selections
model::Schedule read_schedule(Fields& f, model::Schedule::Kind fallback) {
  model::Schedule schedule;
  if (f.has("schedule") && f.peek("schedule")->is_array()) {  // a table (typed below)
    schedule.kind = model::Schedule::Kind::Table;
    const Eigen::VectorXd values = f.vector("schedule", -1);
    schedule.values.assign(values.data(), values.data() + values.size());
    return schedule;
  }
  schedule.kind = f.enumeration("schedule", fallback, model::kScheduleNames);
  return schedule;
}

// A list with one number per axis: 2 or 3 now, the surface's dimension when built.
Eigen::VectorXd per_axis_vector(Fields& f, const std::string& key) {
  const Eigen::VectorXd v = f.vector(key, -1);
  if (v.size() != 2 && v.size() != 3)
    f.fail(key, "expected one number per axis (2 or 3), got " + std::to_string(v.size()));
  return v;
}

// Exactly one of "vertices" (input indices), "where" (a half-space) or "box".
SelectionSpec read_selection(Fields& f) {
  const int chosen = f.has("vertices") + f.has("where") + f.has("box");
  if (chosen != 1) f.fail("", "expected exactly one of \"vertices\", \"where\" or \"box\"");
  SelectionSpec spec;
  spec.field = f.field();
  if (f.has("vertices")) {
    spec.vertices = f.indices("vertices");
  } else if (f.has("where")) {
    spec.where = f.string("where");
    try {
      model::parse_half_space(spec.where, 3);  // the syntax; the axis is checked when built
    } catch (const InputError& e) {
      f.fail("where", e.what());
    }
  } else {
    Fields box = f.object("box");
    spec.box_min = per_axis_vector(box, "min");
    spec.box_max = per_axis_vector(box, "max");
    box.finish();
  }
  return spec;
}

// The held axes: distinct letters of "xyz" ("" for all of the surface's axes).
std::string read_axes(Fields& f) {
  if (!f.has("axes")) return "";  // every axis of the surface, whose dimension is not known yet
  const std::string text = f.string("axes");
  for (char c : text)
    if (c < 'x' || c > 'z' || std::count(text.begin(), text.end(), c) > 1)
      f.fail("axes", "expected distinct letters from \"xyz\", got \"" + text + "\"");
  if (f.has("axes") && text.empty()) f.fail("axes", "expected at least one axis");
  return text;
}

// ------------------------------------------------------------ model parts
double required_positive(Fields& f, const std::string& key) {
  const double x = f.number(key);
  if (!(x > 0.0)) f.fail(key, "expected a positive number, got " + std::to_string(x));
  return x;
}

model::FiberLaw read_law(Fields f) {
  const std::string type = f.choice("type", "constant", model::law_type_names());
  model::FiberLaw law = model::FiberLaw::constant(1.0);
  if (type == "constant") {
    const double Y = f.number("Y");
    if (Y < 0.0) f.fail("Y", "expected a number >= 0, got " + std::to_string(Y));
    law = model::FiberLaw::constant(Y);
  } else if (type == "exponential") {
    law = model::FiberLaw::exponential(required_positive(f, "Y0"), f.number("beta"));
  } else if (type == "bilinear") {
    const double Y_t = required_positive(f, "Y_t"), Y_c = required_positive(f, "Y_c");
    law = model::FiberLaw::bilinear(Y_t, Y_c, f.non_negative("transition", 0.005));
  } else if (type != "tabulated") {
    // A law registered by the program that links the library: its parameters by name.
    const std::shared_ptr<const model::LawModel> registered = model::find_registered_law(type);
    std::vector<double> values;
    for (const std::string& name : registered->parameter_names()) values.push_back(f.number(name));
    law = model::FiberLaw(registered, values);
  } else {
    const Eigen::VectorXd strain = f.vector("strain", -1), stress = f.vector("stress", -1);
    if (stress.size() != strain.size())
      f.fail("stress", "expected as many stresses as strains (" + std::to_string(strain.size()) +
                           "), got " + std::to_string(stress.size()));
    law = model::FiberLaw::tabulated({strain.data(), strain.data() + strain.size()},
                                     {stress.data(), stress.data() + stress.size()},
                                     f.non_negative("transition", 0.005));
    law.set_parameter("scale", f.positive("scale", 1.0));
  }
  f.finish();
  const std::string why = law.check();
  if (!why.empty()) f.fail(type == "tabulated" ? "stress" : "", why);
  return law;
}

MaterialSpec read_material(Fields f) {
  MaterialSpec spec;
  spec.field = f.field();
  model::Material& m = spec.material;
  if (f.has("law") && f.has("Y"))
    f.fail("Y", "give either Y (the linear model) or a law with its parameters, not both");
  if (f.has("law")) {
    m.law = read_law(f.object("law"));
    if (f.has("axis_factors")) {
      spec.per_axis = per_axis_vector(f, "axis_factors");
      if (!(spec.per_axis.array() > 0).all()) f.fail("axis_factors", "expected positive numbers");
    }
  } else if (f.peek("Y") != nullptr && f.peek("Y")->is_array()) {
    // The paper's per-axis moduli: the constant law 1 times exact factors.
    spec.per_axis = per_axis_vector(f, "Y");
    if ((spec.per_axis.array() < 0).any()) f.fail("Y", "expected numbers >= 0");
    spec.per_axis_moduli = true;
    m.law = model::FiberLaw::constant(1.0);
  } else {
    m.law = model::FiberLaw::constant(f.non_negative("Y", 0.0));
  }
  m.surface_tension = f.non_negative("gamma", 0.0);
  f.finish();
  return spec;
}

std::vector<LoadSpec> read_loads(Fields& root) {
  std::vector<LoadSpec> loads;
  for (Fields f : root.objects("loads")) {
    LoadSpec spec;
    spec.field = f.field();
    model::Load& load = spec.load;
    const std::string type = f.choice("type", "", {"gravity", "point"});
    load.label = f.string("label", type + "_" + std::to_string(loads.size()));
    if (type == "gravity") {
      load.kind = model::Load::Kind::Hydrostatic;
      spec.vector = per_axis_vector(f, "acceleration");
      load.density = f.positive("density", 1000.0);
      load.integration =
          f.enumeration("integration", model::Load::Integration::Vertex, model::kIntegrationNames);
    } else {
      load.kind = model::Load::Kind::Point;
      if (!f.has("vertex")) f.fail("vertex", "missing (required): the vertex the force acts on");
      spec.input_vertex = f.integer("vertex", 0, 0, std::numeric_limits<int>::max());
      spec.vector = per_axis_vector(f, "force");
    }
    load.schedule = read_schedule(f, model::Schedule::Kind::Ramp);
    f.finish();
    loads.push_back(spec);
  }
  return loads;
}

// Each entry of "supports" and "prescribed" is a group with its own reaction
// force, named by "label" (default support_K / prescribed_K).
std::vector<ConstraintSpec> read_constraints(Fields& root) {
  std::vector<ConstraintSpec> groups;
  auto read_group = [&](Fields& f, bool prescribed, const std::string& fallback) {
    ConstraintSpec spec;
    spec.field = f.field();
    spec.prescribed = prescribed;
    spec.label = f.string("label", fallback);
    for (const ConstraintSpec& other : groups)
      if (other.label == spec.label)
        f.fail("label", "\"" + spec.label + "\" names another group already");
    spec.selection = read_selection(f);
    if (prescribed && f.has("rotation")) {
      Fields r = f.object("rotation");
      ConstraintSpec::Rotation rotation;
      rotation.field = r.field();
      if (r.has("axis")) rotation.axis = r.vector("axis", 3);
      rotation.angle_degrees = r.number("angle_degrees");
      rotation.centre = per_axis_vector(r, "centre");
      r.finish();
      spec.rotation = rotation;
      if (f.has("displacement")) spec.displacement = per_axis_vector(f, "displacement");
      spec.schedule = read_schedule(f, model::Schedule::Kind::Ramp);
    } else if (prescribed) {
      spec.displacement = per_axis_vector(f, "displacement");
      spec.schedule = read_schedule(f, model::Schedule::Kind::Ramp);
    } else {
      spec.axes = read_axes(f);
      spec.mirror_layer = f.choice("layer", "none", {"none", "mirror"}) == "mirror";
      spec.split_edge = f.choice("edge", "held", {"held", "split"}) == "split";
    }
    if (prescribed && f.has("layer"))
      f.refuse("layer",
               "a mirror layer belongs to a fixed clamp (\"supports\"), not to a "
               "prescribed group");
    if (prescribed && f.has("edge"))
      f.refuse("edge",
               "a split edge belongs to a fixed support (\"supports\"), not to a "
               "prescribed group");
    f.finish();
    groups.push_back(spec);
  };
  int k = 0;
  for (Fields f : root.objects("supports")) read_group(f, false, "support_" + std::to_string(k++));
  k = 0;
  for (Fields f : root.objects("prescribed"))
    read_group(f, true, "prescribed_" + std::to_string(k++));
  return groups;
}

// Rigid paddles: planes normal to an axis on one side of the body, moving by
// "travel" (m) or by "compression" (a share of the body's extent along the
// axis, towards the body). "position" defaults to touching the body.
std::vector<PaddleSpec> read_paddles(Fields& root) {
  std::vector<PaddleSpec> paddles;
  for (Fields f : root.objects("paddles")) {
    PaddleSpec spec;
    spec.field = f.field();
    model::Paddle& p = spec.paddle;
    p.label = f.string("label", "paddle_" + std::to_string(paddles.size()));
    for (const PaddleSpec& other : paddles)
      if (other.paddle.label == p.label)
        f.fail("label", "\"" + p.label + "\" names another paddle");
    const std::string axis = f.string("axis");
    if (axis.size() != 1 || axis[0] < 'x' || axis[0] > 'z')
      f.fail("axis", "expected one of \"xyz\" (the paddle's normal), got \"" + axis + "\"");
    p.axis = axis[0] - 'x';
    p.above = f.choice("side", "", {"above", "below"}) == "above";
    if (f.has("position")) spec.position = f.number("position");
    if (f.has("travel") == f.has("compression"))
      f.fail("travel",
             "give either travel (m, along the axis) or compression (a share of "
             "the body's extent), one of them");
    if (f.has("travel")) {
      spec.travel = f.number("travel");
    } else {
      spec.compression = f.number("compression");
      if (!(*spec.compression > 0.0 && *spec.compression < 1.0))
        f.fail("compression", "expected a share of the body's extent between 0 and 1");
    }
    p.schedule = read_schedule(f, model::Schedule::Kind::Ramp);
    p.sticking = f.choice("contact", "frictionless", {"frictionless", "sticking"}) == "sticking";
    f.finish();
    paddles.push_back(spec);
  }
  return paddles;
}

solve::NewtonOptions read_newton(Fields f, solve::NewtonOptions o) {
  o.residual_tolerance = f.positive("residual_tolerance", o.residual_tolerance);
  o.increment_tolerance = f.positive("increment_tolerance", o.increment_tolerance);
  o.max_iterations = f.integer("max_iterations", o.max_iterations, 1, 10000);
  o.max_step_cuts = f.integer("max_step_cuts", o.max_step_cuts, 0, 30);
  o.line_search = f.boolean("line_search", o.line_search);
  o.tangent = f.enumeration("tangent", solve::TangentSolver::Auto, solve::kTangentSolverNames);
  o.krylov_tolerance = f.positive("krylov_tolerance", o.krylov_tolerance);
  o.krylov_restart = f.integer("krylov_restart", o.krylov_restart, 1, 1000);
  o.krylov_max_iterations = f.integer("krylov_max_iterations", o.krylov_max_iterations, 1, 100000);
  o.max_contact_rounds = f.integer("max_contact_rounds", o.max_contact_rounds, 1, 1000);
  o.predictor = f.boolean("predictor", o.predictor);
  f.finish();
  return o;
}

solve::SteppingOptions read_stepping(Fields f, solve::SteppingOptions options) {
  options.scheme = f.enumeration("scheme", solve::Scheme::Incremental, solve::kSchemeNames);
  if (f.has("newton") && options.scheme != solve::Scheme::Newton)
    f.fail("newton", "Newton options need \"scheme\": \"newton\"");
  if (options.scheme == solve::Scheme::Newton)
    options.newton = read_newton(f.object_or_empty("newton"), options.newton);
  options.steps = f.integer("steps", options.steps, 1, 100000);
  if (f.has("control")) {
    options.newton.control =
        f.enumeration("control", solve::NewtonOptions::Control::Load, solve::kControlNames);
    if (options.newton.control == solve::NewtonOptions::Control::ArcLength &&
        options.scheme != solve::Scheme::Newton)
      f.fail("control", "arc-length control needs \"scheme\": \"newton\"");
  }
  options.newton.max_arc_steps =
      f.integer("max_arc_steps", options.newton.max_arc_steps, 1, 100000);
  options.rebuild_matrix = f.boolean("rebuild_matrix", options.rebuild_matrix);
  options.update_load_geometry = f.boolean("update_load_geometry", options.update_load_geometry);
  options.boundary_method =
      f.enumeration("boundary_method", options.boundary_method, model::kBoundaryMethodNames);
  options.penalty = f.positive("penalty", options.penalty);
  options.solver = f.enumeration("solver", options.solver, solve::kSolverKindNames);
  options.pcg.tolerance = f.positive("tolerance", options.pcg.tolerance);
  options.pcg.max_iterations = f.integer("max_iterations", options.pcg.max_iterations, 1, 1000000);
  options.max_volume_change = f.positive("max_volume_change", options.max_volume_change);
  options.measure_residual = f.boolean("measure_residual", options.measure_residual);
  options.stop_on_inverted_faces =
      f.boolean("stop_on_inverted_faces", options.stop_on_inverted_faces);
  f.finish();
  return options;
}

void check_tables(const Fields& root, const CaseSpec& c) {
  auto check = [&](const model::Schedule& s, const std::string& what) {
    if (s.kind == model::Schedule::Kind::Table &&
        static_cast<int>(s.values.size()) != c.stepping.steps)
      root.fail(what, "the schedule lists " + std::to_string(s.values.size()) +
                          " factors but stepping.steps is " + std::to_string(c.stepping.steps));
  };
  for (const LoadSpec& l : c.loads) check(l.load.schedule, l.field.path + ".schedule");
  for (const ConstraintSpec& k : c.constraints) check(k.schedule, k.field.path + ".schedule");
  for (const PaddleSpec& p : c.paddles) check(p.paddle.schedule, p.field.path + ".schedule");
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

FiberSpec read_fibers(Fields& root) {
  FiberSpec spec;
  spec.field = {root.file(), root.name("fibers")};
  Fields f = root.object_or_empty("fibers");
  spec.pruning = f.choice("pruning", "auto", {"auto", "off"}) == "auto";
  spec.write = f.choice("write", "none", {"none", "kept", "pruned"});
  const std::string kinematics = f.choice("kinematics", model::VectorSpring::name,
                                          {model::VectorSpring::name, model::CentralFiber::name});
  for (model::FiberKinematics k : model::kAllKinematics)
    if (kinematics == model::kinematics_name(k)) spec.kinematics = k;
  if (f.has("horizon")) {
    spec.horizon = f.number("horizon");
    if (!(spec.horizon > 0.0) || !std::isfinite(spec.horizon))
      f.fail("horizon", "expected a positive length (m), got " + std::to_string(spec.horizon));
  }
  // Central fibers default to the settings under which their response
  // converges as the mesh is refined (model.md, "Parameters that do not move
  // with the mesh"): each vertex's count is the area its fibers reach, and
  // within a horizon the fibers fade out conically. The vector spring keeps
  // the paper's count, so that its figures are reproduced as published.
  const bool central = spec.kinematics == model::FiberKinematics::Central;
  spec.count =
      f.enumeration("connection_count",
                    central ? model::ConnectionCount::Area : model::ConnectionCount::Symmetric,
                    model::kConnectionCountNames);
  const bool fades = central && spec.horizon > 0.0;
  if (f.choice("influence", fades ? "conical" : "constant", {"constant", "conical"}) == "conical") {
    if (!(spec.horizon > 0.0))
      f.fail("influence", "a conical influence (1 - L / horizon) needs a \"horizon\"");
    spec.influence = model::Influence::Kind::Conical;
  }
  if (f.choice("product", "exact", {"exact", "treecode"}) == "treecode") {
    spec.treecode_tolerance = f.number("treecode_tolerance", 1e-6);
    if (!(spec.treecode_tolerance >= 1e-10 && spec.treecode_tolerance <= 1e-2))
      f.fail("treecode_tolerance", "expected a relative error from 1e-10 to 1e-2, got " +
                                       std::to_string(spec.treecode_tolerance));
  } else if (f.has("treecode_tolerance"))
    f.fail("treecode_tolerance", "applies to \"product\": \"treecode\" only");
  if (spec.treecode_tolerance > 0.0 && model::counts_by_area(spec.count))
    f.fail("product",
           "\"treecode\" needs one connection count for every fiber: set "
           "\"connection_count\": \"global\" (the " +
               std::string(model::to_string(spec.count)) +
               " count differs from vertex to vertex) or \"product\": \"exact\"");
  if (spec.treecode_tolerance > 0.0 && spec.horizon > 0.0)
    f.fail("product",
           "\"treecode\" approximates the sum over every pair; with a \"horizon\" most pairs "
           "are not fibers: use \"product\": \"exact\"");
  f.finish();
  return spec;
}

// The treecode's rules are the library's (solve::treecode_problem): the
// reader names the field.
void check_treecode(Fields& root, const CaseSpec& c) {
  model::Model probe;
  probe.material = c.material.material;
  probe.treecode_tolerance = c.fibers.treecode_tolerance;
  const std::string why = solve::treecode_problem(probe, c.stepping);
  if (!why.empty()) root.fail("fibers", "\"product\": \"treecode\": " + why);
}

// The kinematics' rules are the library's (solve::kinematics_problem).
void check_kinematics(Fields& root, const CaseSpec& c) {
  model::Model probe;
  probe.material.kinematics = c.fibers.kinematics;
  const std::string why = solve::kinematics_problem(probe, c.stepping);
  if (!why.empty()) root.fail("fibers", "\"kinematics\": " + why);
}

// Parses one case from a complete simulation document; opens no file.
CaseSpec read_case(Fields& root, const std::filesystem::path& folder,
                   std::vector<std::string>* warnings) {
  CaseSpec c;
  if (root.has("surface")) {
    Fields surface = root.object("surface");
    c.surface = read_surface_spec(surface, folder);
    surface.finish();
  } else {  // the program building the case gives the surface
    c.surface.field = {root.file(), root.name("surface")};
  }
  c.fibers = read_fibers(root);
  c.surface_key = (root.peek("surface") ? root.peek("surface")->dump() : std::string()) + "|" +
                  (root.peek("fibers") ? root.peek("fibers")->dump() : std::string());
  c.material = read_material(root.object("material"));
  if (warnings != nullptr && !root.peek("material")->contains("gamma"))
    warnings->push_back(root.file() + ": " + root.name("material.gamma") +
                        ": not given, so 0 (no surface tension on the mesh edges)");
  c.loads = read_loads(root);
  c.constraints = read_constraints(root);
  c.paddles = read_paddles(root);
  c.paddles_field = {root.file(), root.name("paddles")};
  c.stepping = read_stepping(root.object_or_empty("stepping"), {});
  if (!c.paddles.empty() && c.stepping.scheme != solve::Scheme::Newton)
    root.fail("paddles",
              "paddles need \"stepping\": {\"scheme\": \"newton\"} (contact is "
              "an active set inside the equilibrium iterations)");
  if (!c.material.material.law.is_constant() && c.stepping.scheme == solve::Scheme::Incremental &&
      !c.stepping.rebuild_matrix && warnings != nullptr)
    warnings->push_back(
        "material.law: the incremental scheme without stepping.rebuild_matrix "
        "uses the small-strain modulus Y(0) throughout; set rebuild_matrix or "
        "scheme \"newton\" for the strain-dependent law");
  if (c.fibers.treecode_tolerance > 0.0) check_treecode(root, c);
  check_kinematics(root, c);
  check_tables(root, c);
  root.finish();
  return c;
}

// ------------------------------------------------------------ fit
// A file's length unit ("m", "cm", "mm", "um"; default m) as the factor to m.
double length_units(Fields& f, const std::string& key) {
  const std::string units = f.choice(key, "m", {"m", "cm", "mm", "um"});
  return units == "cm" ? 1e-2 : units == "mm" ? 1e-3 : units == "um" ? 1e-6 : 1.0;
}

// A target of "type": "force": a CSV curve of a paddle's or a support's force.
FitForceSpec read_force_target(Fields& t, const std::filesystem::path& folder) {
  FitForceSpec curve;
  curve.field = t.field();
  curve.file = t.string("file");
  if (curve.file.is_relative()) curve.file = folder / curve.file;
  t.resolve("file", absolute_path(curve.file));
  if (t.has("paddle") == t.has("support"))
    t.fail("paddle",
           "expected the label of a paddle, or a support (\"support\"), whose force "
           "the curve measured: one of them");
  if (t.has("paddle")) {
    curve.paddle = t.string("paddle");
  } else {
    curve.support = t.string("support");
    curve.axis = t.choice("axis", "", {"x", "y", "z"})[0] - 'x';  // the reaction's component
  }
  if (t.has("paddle") && t.has("axis"))
    t.fail("axis", "a paddle's force is along its own axis: give axis only with a support");
  if (t.has("weight")) curve.weight = t.positive("weight", 1.0);
  if (t.has("rows_at")) curve.rows_at = t.choice("rows_at", "", {"travel", "step"});
  curve.travel_scale = length_units(t, "travel_units");
  const std::string force = t.choice("force_units", "N", {"N", "mN", "kN"});
  curve.force_scale = force == "mN" ? 1e-3 : force == "kN" ? 1e3 : 1.0;
  t.finish();
  return curve;
}

// fit.targets: the surfaces and force curves.
void read_fit_targets(Fields& f, const std::filesystem::path& folder, FitSpec& spec) {
  for (Fields t : f.objects("targets")) {
    if (t.choice("type", "surface", {"surface", "force"}) == "force") {
      spec.force_curves.push_back(read_force_target(t, folder));
      continue;
    }
    FitTargetSpec target;
    target.field = t.field();
    target.file = t.string("file");
    if (target.file.is_relative()) target.file = folder / target.file;
    t.resolve("file", absolute_path(target.file));
    target.step = t.integer("step", 0, 1, 100000);
    if (t.has("scale") && t.has("units"))
      t.fail("units", "give the scan's units or its scale, not both");
    if (t.has("units")) target.scale = length_units(t, "units");
    target.scale = t.positive("scale", target.scale);
    t.finish();
    spec.targets.push_back(target);
  }
  if (spec.targets.empty() && spec.force_curves.empty())
    f.fail("targets", "expected at least one target (a surface, or a force curve)");
}

// fit.parameters: each fitted once.
void read_fit_parameters(Fields& f, FitSpec& spec) {
  for (Fields p : f.objects("parameters")) {
    FitParameterSpec parameter;
    parameter.field = p.field();
    parameter.request.name = p.string("name");
    for (const FitParameterSpec& other : spec.parameters)
      if (other.request.name == parameter.request.name)
        p.fail("name", "\"" + parameter.request.name + "\" is fitted twice");
    if (p.has("start")) parameter.request.start = p.number("start");
    if (p.has("lower")) parameter.request.lower = p.number("lower");
    if (p.has("upper")) parameter.request.upper = p.number("upper");
    if (p.has("log_scale")) parameter.request.log_scale = p.boolean("log_scale", false);
    p.finish();
    spec.parameters.push_back(parameter);
  }
  if (spec.parameters.empty()) f.fail("parameters", "expected at least one parameter to fit");
}

// The fit's method and options.
void read_fit_options(Fields& f, FitSpec& spec) {
  // The options' values are checked once, by fit::check_options, for every
  // front end alike (its messages begin with the option's name); here only
  // their types.
  const auto named = [&f](const std::string& key, const InputError& e) {
    const std::string what = e.what();
    const size_t colon = what.find(": ");
    f.fail(key, colon == std::string::npos ? what : what.substr(colon + 2));
  };
  fit::FitOptions& o = spec.options;
  const std::string method = f.string("method", "levenberg-marquardt");
  if (method == "multistart") {  // Levenberg-Marquardt from many starts
    fit::MultistartOptions multistart;
    multistart.starts = f.integer("starts", multistart.starts, 2, 100000);
    multistart.same_optimum = f.number("same_optimum", multistart.same_optimum);
    try {
      fit::check_options(multistart);
    } catch (const InputError& e) {
      named("same_optimum", e);
    }
    spec.multistart = multistart;
  } else {
    try {
      o.method = fit::method_from_string(method);
    } catch (const InputError&) {
      f.fail("method",
             "expected levenberg-marquardt, bobyqa, direct-l, crs2 or multistart, got \"" +
                 method.substr(0, 40) + "\"");
    }
    for (const char* key : {"starts", "same_optimum"})
      if (f.has(key)) f.fail(key, "only with \"method\": \"multistart\"");
    // Every option is honoured by the method it is given with, or refused.
    if (o.method != fit::Method::LevenbergMarquardt)
      for (const char* key : {"max_iterations", "initial_trust_region_radius", "max_step_factor"})
        if (f.has(key))
          f.fail(key, "only with levenberg-marquardt or multistart (" + method +
                          " takes no trust-region steps: max_evaluations bounds its runs)");
  }
  o.finite_differences =
      f.choice("jacobian", "analytic", {"analytic", "finite-differences"}) == "finite-differences";
  o.difference_step = f.number("difference_step", o.difference_step);
  if (f.has("objective")) {
    Fields objective = f.object("objective");
    o.symmetric = objective.boolean("symmetric", false);
    try {
      o.loss = fit::loss_from_string(objective.string("loss", "squared"));
    } catch (const InputError& e) {
      named("objective.loss", e);
    }
    o.loss_scale = objective.number("loss_scale", o.loss_scale);
    if (objective.has("exclude")) {
      Fields exclude = objective.object("exclude");
      spec.exclude = read_selection(exclude);
      exclude.finish();
    }
    objective.finish();
  }
  const int any_min = std::numeric_limits<int>::min(), any_max = std::numeric_limits<int>::max();
  o.max_iterations = f.integer("max_iterations", o.max_iterations, any_min, any_max);
  o.max_evaluations = f.integer("max_evaluations", o.max_evaluations, any_min, any_max);
  o.function_tolerance = f.number("function_tolerance", o.function_tolerance);
  o.parameter_tolerance = f.number("parameter_tolerance", o.parameter_tolerance);
  o.initial_trust_region_radius =
      f.number("initial_trust_region_radius", o.initial_trust_region_radius);
  o.max_step_factor = f.number("max_step_factor", o.max_step_factor);
  o.warm_start = f.boolean("warm_start", o.warm_start);
  o.check_intervals = f.boolean("check_intervals", o.check_intervals);
  try {
    fit::check_options(o);
  } catch (const InputError& e) {
    const std::string what = e.what();
    const std::string option = what.substr(0, what.find(':'));
    named(option == "loss_scale" ? "objective.loss_scale" : option, e);
  }
}

FitSpec read_fit(Fields f, const std::filesystem::path& folder) {
  FitSpec spec;
  spec.field = f.field();
  read_fit_targets(f, folder, spec);
  read_fit_parameters(f, spec);
  spec.mesh_check = f.choice("mesh_check", "none", {"none", "coarser", "finer"});
  if (f.has("start_from")) {
    spec.start_from = f.string("start_from");
    if (spec.start_from->is_relative()) spec.start_from = folder / *spec.start_from;
    f.resolve("start_from", absolute_path(*spec.start_from));
  }
  read_fit_options(f, spec);
  f.finish();
  return spec;
}

// Fields of the experiment that a variant may not patch.
const char* const kExperimentFields[] = {"name",     "description",   "kind",
                                         "variants", "expected",      "output",
                                         "fit",      "fem_reference", "$schema"};

void check_variant_name(const Fields& f, const std::string& name,
                        const std::vector<CaseSpec>& earlier) {
  if (const std::string problem = folder_name_problem(name); !problem.empty())
    f.fail("name", "expected " + problem);
  if (const std::string problem = reserved_name_problem(name); !problem.empty())
    f.fail("name", "expected " + problem);
  for (const CaseSpec& c : earlier)
    if (c.variant == name) f.fail("name", "\"" + name + "\" names another variant already");
}

// A simulation: the base document, or one case per variant, each the base
// with the variant's JSON merge patch (RFC 7386) applied.
void read_simulation(Fields& root, const nlohmann::json& document,
                     const std::filesystem::path& folder, Experiment& ex) {
  json base = document;
  for (const char* field : kExperimentFields) base.erase(field);
  if (!root.has("variants")) {
    json resolved;
    Fields f(base, "", root.file(), &resolved);
    ex.specs.push_back(read_case(f, folder, &ex.warnings));
    ex.resolved.update(resolved);
  } else {
    const json& variants = root.raw("variants");
    if (!variants.is_array() || variants.empty())
      root.fail("variants", "expected a non-empty list of objects");
    json resolved_variants = json::array();
    for (size_t k = 0; k < variants.size(); ++k) {
      Fields v(variants[k], "variants[" + std::to_string(k) + "]", root.file());
      const std::string name = v.string("name");
      check_variant_name(v, name, ex.specs);
      json patch = variants[k];
      patch.erase("name");
      for (const char* field : kExperimentFields)
        if (patch.contains(field))
          v.fail(field, "belongs to the whole experiment; a variant cannot change it");
      json patched = base;
      patched.merge_patch(patch);
      json resolved = {{"name", name}};
      Fields f(patched, "", root.file() + " [variant " + name + "]", &resolved);
      CaseSpec c = read_case(f, folder, &ex.warnings);
      c.variant = name;
      c.patch = patch;
      ex.specs.push_back(std::move(c));
      resolved_variants.push_back(std::move(resolved));
    }
    // Each variant resolved whole: merged onto an empty base, it is its case.
    ex.resolved["variants"] = std::move(resolved_variants);
  }
  Fields output = root.object_or_empty("output");
  ex.output.vtk = output.boolean("vtk", true);
  ex.output.obj = output.boolean("obj", true);
  ex.output.every = output.integer("every", 1, 1, 1000000);
  ex.output.vtk_format = output.choice("vtk_format", "auto", {"auto", "ascii", "compressed"});
  output.finish();
}

// A calibration over several specimens: their experiment files (read when
// the experiment is built) and the parameters they share.
CalibrationSpec read_calibration(Fields& root, const std::filesystem::path& folder) {
  CalibrationSpec spec;
  for (Fields f : root.objects("specimens")) {
    SpecimenSpec specimen;
    specimen.field = f.field();
    specimen.name = f.string("name");
    if (const std::string problem = folder_name_problem(specimen.name); !problem.empty())
      f.fail("name", "expected " + problem);
    if (const std::string problem = reserved_name_problem(specimen.name); !problem.empty())
      f.fail("name", "expected " + problem);
    for (const SpecimenSpec& other : spec.specimens)
      if (other.name == specimen.name)
        f.fail("name", "\"" + specimen.name + "\" names another specimen");
    specimen.file = f.string("experiment");
    if (specimen.file.is_relative()) specimen.file = folder / specimen.file;
    f.resolve("experiment", absolute_path(specimen.file));
    f.finish();
    spec.specimens.push_back(specimen);
  }
  if (spec.specimens.size() < 2)
    root.fail("specimens", "expected two or more specimens (each {\"name\", \"experiment\"})");
  spec.shared = root.names("shared");
  spec.max_iterations = root.integer("max_iterations", spec.max_iterations, 1, 10000);
  return spec;
}

void read_areas(Fields& root, const std::filesystem::path& folder, Experiment& ex) {
  for (Fields f : root.objects("surfaces")) {
    NamedSurfaceSpec named;
    named.name = f.string("name");
    named.surface = read_surface_spec(f, folder);
    f.finish();
    ex.area_specs.push_back(named);
  }
  if (ex.area_specs.empty()) root.fail("surfaces", "expected at least one surface");
}

// Every expected figure names a figure the experiment will have (a fit's
// once its parameters are checked: setup_fit).
void check_expected_names(const Fields& root, const Experiment& ex) {
  for (size_t k = 0; k < ex.expected.size(); ++k) {
    const std::string problem = figure_problem(ex, ex.expected[k].figure, /*fit_figures=*/false);
    if (!problem.empty()) root.fail("expected[" + std::to_string(k) + "].figure", problem);
  }
}

}  // namespace

Experiment read_experiment(const json& document, const std::filesystem::path& folder,
                           const std::string& label) {
  Experiment ex;
  ex.document = document;
  Fields root(document, "", label, &ex.resolved);
  // An editor's pointer to the schema (`fiberfluid schema --help` suggests it): taken, unused.
  if (root.has("$schema")) root.string("$schema");
  ex.name = root.string("name", "experiment");
  if (const std::string problem = folder_name_problem(ex.name); !problem.empty())
    root.fail("name", "expected " + problem);
  ex.description = root.string("description", "");
  ex.kind = root.enumeration("kind", Experiment::Kind::Simulate, kExperimentKindNames);
  ex.expected = read_expected(root);
  if (root.has("fit")) {
    if (ex.kind != Experiment::Kind::Simulate) root.fail("fit", "only a simulation can be fitted");
    if (root.has("variants"))
      root.fail("fit",
                "a fit calibrates one simulation: remove \"variants\" (fit several loads "
                "with several targets, each tied to its step)");
    ex.fit = read_fit(root.object("fit"), folder);
  }
  if (root.has("fem_reference")) {
    if (ex.kind != Experiment::Kind::Simulate)
      root.fail("fem_reference", "only a simulation has a FEM reference");
    if (root.has("variants"))
      root.fail("fem_reference", "a FEM reference solves one simulation: remove \"variants\"");
    Fields f = root.object("fem_reference");
    ex.fem_reference = read_fem_reference(f);
  }
  if (ex.kind == Experiment::Kind::Simulate) {
    read_simulation(root, document, folder, ex);  // each case checks its own fields
  } else if (ex.kind == Experiment::Kind::Benchmark) {
    ex.benchmark = read_benchmark(root);
    root.finish();
  } else if (ex.kind == Experiment::Kind::Calibration) {
    ex.calibration = read_calibration(root, folder);
    root.finish();
  } else {
    read_areas(root, folder, ex);
    root.finish();
  }
  check_expected_names(root, ex);
  return ex;
}

const std::vector<std::string>& experiment_wide_fields() {
  static const std::vector<std::string> fields(std::begin(kExperimentFields),
                                               std::end(kExperimentFields));
  return fields;
}

void require_built(const Experiment& experiment) {
  if (!experiment.built())
    throw std::logic_error("experiment " + experiment.name +
                           " is not built: call build_experiment after read_experiment (or "
                           "parse_experiment, load_experiment)");
}

void build_experiment(Experiment& ex, const geom::Surface* surface) {
  ex.cases.clear();
  ex.area_surfaces.clear();
  ex.specimens.clear();
  if (ex.calibration)  // each specimen's file, read and built; its errors name it
    for (const SpecimenSpec& s : ex.calibration->specimens) {
      // A specimen is a simulation, never a calibration (which could list itself).
      static thread_local bool inside_calibration = false;
      if (inside_calibration)
        throw InputError(s.file.string() +
                         ": a specimen of a calibration is a simulation with "
                         "a \"fit\" section, not a calibration");
      inside_calibration = true;
      Experiment specimen;
      try {
        specimen = load_experiment(s.file);
      } catch (...) {
        inside_calibration = false;
        throw;
      }
      inside_calibration = false;
      if (!specimen.fit)
        s.field.fail("experiment", s.file.string() +
                                       " has no \"fit\" section: a specimen "
                                       "brings its targets and parameters");
      for (const std::string& w : specimen.warnings) ex.warnings.push_back(s.name + ": " + w);
      ex.specimens.push_back(std::move(specimen));
    }
  for (const NamedSurfaceSpec& named : ex.area_specs)
    ex.area_surfaces.push_back({named.name, build_surface(named.surface, &ex.warnings)});
  for (const CaseSpec& spec : ex.specs) {
    const auto same = std::find_if(ex.specs.begin(), ex.specs.end(), [&](const CaseSpec& s) {
      return s.surface_key == spec.surface_key;
    });
    const size_t earlier = static_cast<size_t>(same - ex.specs.begin());
    if (earlier < ex.cases.size())
      ex.cases.push_back(build_case(spec, ex.cases[earlier]));
    else if (surface != nullptr)
      ex.cases.push_back(build_case(spec, *surface, &ex.warnings));
    else
      ex.cases.push_back(build_case(spec, &ex.warnings));
    for (const std::string& note : ex.cases.back().notes)
      ex.warnings.push_back(spec.variant.empty() ? note : spec.variant + ": " + note);
  }
}

Experiment parse_experiment(const json& document, const std::filesystem::path& folder,
                            const std::string& label) {
  Experiment ex = read_experiment(document, folder, label);
  build_experiment(ex);
  return ex;
}

namespace {

template <class Input>
json parse_json_from(Input&& input, const std::string& label) {
  struct TooDeep {};
  struct Duplicate {
    std::string path;
  };
  // A key given twice in one object: nlohmann keeps the last one without a
  // word, so the file would mean what its last line says (issue 43, "a file
  // means one thing"). Each open object's keys, and the key it sits under.
  struct Open {
    std::set<std::string> keys;
    std::string under;
  };
  std::vector<Open> open;
  std::string last_key;
  const json::parser_callback_t guard = [&](int depth, json::parse_event_t event, json& parsed) {
    if ((event == json::parse_event_t::object_start || event == json::parse_event_t::array_start) &&
        depth >= kDeepestJson)
      throw TooDeep{};
    if (event == json::parse_event_t::object_start) open.push_back({{}, last_key});
    if (event == json::parse_event_t::object_end && !open.empty()) open.pop_back();
    if (event == json::parse_event_t::key && !open.empty()) {
      last_key = parsed.is_string() ? parsed.get<std::string>() : std::string();
      if (!open.back().keys.insert(last_key).second) {
        std::string path = last_key;
        for (auto it = open.rbegin(); it != open.rend(); ++it)
          if (!it->under.empty()) path = it->under + "." + path;
        throw Duplicate{path};
      }
    }
    return true;
  };
  try {
    return json::parse(std::forward<Input>(input), guard);
  } catch (const TooDeep&) {
    throw InputError(label + ": nested more than " + std::to_string(kDeepestJson) +
                     " levels deep (an experiment needs a few)");
  } catch (const Duplicate& d) {
    throw InputError(label + ": \"" + d.path.substr(0, 80) +
                     "\" is given twice in one object (expected each key once: which one "
                     "would count?)");
  } catch (const json::exception& e) {  // a syntax error, or a number a double cannot hold (1e999)
    // The parser quotes the token it last read, which may be a whole line: cut it short.
    std::string what = e.what();
    if (what.size() > 200) what = what.substr(0, 200) + "...";
    throw InputError(label + ": not valid JSON: " + what);
  }
}

}  // namespace

json parse_json(std::istream& in, const std::string& label) { return parse_json_from(in, label); }
json parse_json(const std::string& text, const std::string& label) {
  return parse_json_from(text, label);
}

Experiment load_experiment(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string() + ": cannot open the experiment file");
  json document = parse_json(in, path.string());
  if (document.is_object() && !document.contains("name"))
    document["name"] = folder_name_from(path.stem().string());
  Experiment ex = parse_experiment(document, path.parent_path(), path.string());
  ex.source = path;
  return ex;
}

}  // namespace fiberfluid::experiment
