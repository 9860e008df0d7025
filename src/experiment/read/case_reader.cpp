// SPDX-License-Identifier: GPL-3.0-or-later
// One case of a simulation: its surface, fibers, material, loads, supports,
// paddles and stepping, read from a complete document (a variant already
// patched in).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fiberfluid/experiment/read/json_fields.hpp"
#include "fiberfluid/experiment/read/readers.hpp"
#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::experiment {
namespace {

using nlohmann::json;

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

// The field a law's refusal names: a table's stresses, a spline's knots or
// rises (the message names the parameter), else the law itself.
std::string failed_law_field(const std::string& type, const std::string& message) {
  if (type == "tabulated") return "stress";
  if (type != "spline") return "";
  if (message.find("stretches") != std::string::npos) return "stretches";
  return message.rfind("T1", 0) == 0 ? "T1" : "rises";
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
  } else if (type == "neo_hookean") {
    law = model::FiberLaw::neo_hookean(required_positive(f, "mu"));
  } else if (type == "bilinear") {
    const double Y_t = required_positive(f, "Y_t"), Y_c = required_positive(f, "Y_c");
    law = model::FiberLaw::bilinear(Y_t, Y_c, f.non_negative("transition", 0.005));
  } else if (type == "spline") {
    const Eigen::VectorXd stretches = f.vector("stretches", -1), rises = f.vector("rises", -1);
    const double rest_tension = f.non_negative("T1", 0.0);
    if (stretches.size() < 2)
      f.fail("stretches", "expected at least two stretches (the spline's knots), got " +
                              std::to_string(stretches.size()));
    if (rises.size() != stretches.size())
      f.fail("rises", "expected one rise per stretch (" + std::to_string(stretches.size()) +
                          "), got " + std::to_string(rises.size()));
    law = model::FiberLaw::spline({stretches.data(), stretches.data() + stretches.size()},
                                  rest_tension, {rises.data(), rises.data() + rises.size()});
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
  if (const Status usable = law.check(); !usable.ok)
    f.fail(failed_law_field(type, usable.message), usable.message);
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
  m.friction = f.non_negative("friction", 0.0);
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
    const std::string contact =
        f.choice("contact", "frictionless", {"frictionless", "sticking", "coulomb"});
    p.contact = contact == "sticking"  ? model::Paddle::Contact::Sticking
                : contact == "coulomb" ? model::Paddle::Contact::Coulomb
                                       : model::Paddle::Contact::Frictionless;
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
  o.friction_tolerance = f.positive("friction_tolerance", o.friction_tolerance);
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
  spec.weights = f.enumeration("weights", model::FiberWeights::Paper, model::kFiberWeightsNames);
  const bool lines = spec.weights == model::FiberWeights::Lines;
  // The line measure is a fiber's whole weight: no count divides it, and no
  // influence fades it unless asked for.
  if (lines && f.has("connection_count"))
    f.fail("connection_count",
           "\"weights\": \"lines\" weighs each fiber by the lines it stands for, not by a "
           "count: leave \"connection_count\" out");
  // Not read under the line measure: the resolved file records what is read.
  spec.count = lines ? model::ConnectionCount::Symmetric
                     : f.enumeration("connection_count",
                                     central ? model::ConnectionCount::Area
                                             : model::ConnectionCount::Symmetric,
                                     model::kConnectionCountNames);
  const bool fades = central && spec.horizon > 0.0 && !lines;
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

// The treecode's rules are the library's (solve::check_treecode): the
// reader names the field.
void check_treecode(Fields& root, const CaseSpec& c) {
  model::Model probe;
  probe.material = c.material.material;
  probe.treecode_tolerance = c.fibers.treecode_tolerance;
  if (const Status usable = solve::check_treecode(probe, c.stepping); !usable.ok)
    root.fail("fibers", "\"product\": \"treecode\": " + usable.message);
}

// The kinematics' rules are the library's (solve::check_kinematics).
void check_kinematics(Fields& root, const CaseSpec& c) {
  model::Model probe;
  probe.material.kinematics = c.fibers.kinematics;
  if (const Status usable = solve::check_kinematics(probe, c.stepping); !usable.ok)
    root.fail("fibers", "\"kinematics\": " + usable.message);
}

}  // namespace

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
  // Refused here, not at the run's start (issue 59, class 5).
  if (!c.paddles.empty() && c.stepping.newton.control == solve::NewtonOptions::Control::ArcLength)
    root.fail("stepping.control",
              "arc length follows the loads' factor, and paddles move the body by "
              "displacement, which load control already follows: use \"control\": \"load\"");
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

}  // namespace fiberfluid::experiment
