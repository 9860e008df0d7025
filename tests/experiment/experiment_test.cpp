// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/experiment.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <fstream>
#include <nlohmann/json.hpp>

#include "fiberfluid/experiment/run/case_builder.hpp"
#include "fiberfluid/experiment/run/runner.hpp"
#include "fiberfluid/experiment/write/csv_tables.hpp"
#include "fiberfluid/experiment/write/outputs.hpp"
#include "fiberfluid/experiment/write/summary_json.hpp"
#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/geom/mesh_io.hpp"
#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/util/error.hpp"
#include "test_support.hpp"

namespace fiberfluid::experiment {
namespace {

using testing::ScratchDir;

// Every experiment file carries its expected figures; each is a regression test.
class ExperimentFile : public ::testing::TestWithParam<const char*> {};

TEST_P(ExperimentFile, RunsAndMeetsItsExpectedFigures) {
  const Experiment ex = load_experiment(testing::experiment_file(GetParam()));
  const ExperimentResult result = run_experiment(ex);
  EXPECT_TRUE(result.runs_succeeded());
  EXPECT_FALSE(result.checks.empty()) << GetParam() << " expects nothing";
  for (const FigureCheck& c : result.checks) EXPECT_TRUE(c.passed) << c.Describe();
}

INSTANTIATE_TEST_SUITE_P(
    Experiments, ExperimentFile,
    ::testing::Values("rectangle.json", "areas.json", "sphere.json", "round_trip.json",
                      "liver_gravity.json", "bunny_gravity.json", "liver_sweep.json",
                      "nonlinear_round_trip.json", "liver_paddles.json", "stress_strain.json",
                      "benchmark_block_mp1.json", "benchmark_block_mp2.json", "benchmark_rod.json",
                      "benchmark_rod_converged.json", "liver_fem_reference.json",
                      "bar_bending.json", "cantilever_large.json", "compression_large.json",
                      "liver_interactive.json", "cylinder_mesh_study.json",
                      "dome_mesh_study.json"));

// A minimal valid experiment, edited by each bad-config case.
nlohmann::json base_config() {
  return nlohmann::json::parse(R"({
    "name": "tiny",
    "surface": {"generator": "icosphere", "subdivisions": 1, "radius": 1.0},
    "material": {"Y": 100000, "gamma": 10},
    "supports": [{"where": "z >= 0.5"}],
    "loads": [{"type": "gravity", "acceleration": [0, 0, -9.81]}],
    "stepping": {"steps": 2}
  })");
}

std::filesystem::path write_config(const ScratchDir& dir, const nlohmann::json& config) {
  return dir.write("experiment.json", config.dump(2));
}

void expect_config_error(const ScratchDir& dir, const nlohmann::json& config,
                         const std::string& part) {
  const auto file = write_config(dir, config);
  try {
    load_experiment(file);
    ADD_FAILURE() << "no error, expected one mentioning '" << part << "'";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(part), std::string::npos) << message;
    EXPECT_EQ(message.rfind(file.string(), 0), 0u) << "must name the file: " << message;
  }
}

TEST(ExperimentConfig, BaseConfigIsValid) {
  ScratchDir dir;
  const Experiment ex = load_experiment(write_config(dir, base_config()));
  ASSERT_EQ(ex.simulation().cases.size(), 1u);
  const Case& c = ex.simulation().cases[0];
  EXPECT_EQ(c.model.num_vertices(), 42);
  EXPECT_FALSE(ex.sweeps());
  EXPECT_EQ(c.stepping.steps, 2);
  EXPECT_EQ(c.model.loads[0].density, 1000.0);  // the default
  EXPECT_FALSE(c.model.constraints.empty());
  EXPECT_EQ(c.model.constraint_groups, std::vector<std::string>{"support_0"});
}

TEST(ExperimentConfig, BadFieldsAreNamed) {
  ScratchDir dir;
  nlohmann::json c = base_config();
  c["material"]["Yx"] = 3;
  expect_config_error(dir, c, "material.Yx: unknown field");

  c = base_config();
  c["stepping"]["steps"] = "ten";
  expect_config_error(dir, c, "stepping.steps: expected a whole number");

  c = base_config();
  c["material"]["Y"] = -1;
  expect_config_error(dir, c, "material.Y: expected a number >= 0");

  c = base_config();
  c.erase("material");
  expect_config_error(dir, c, "material: missing");

  c = base_config();
  c["surface"] = {{"file", "no_such_mesh.obj"}};
  expect_config_error(dir, c, "no_such_mesh.obj: cannot open");

  c = base_config();
  c["supports"][0]["where"] = "z >= 5";
  expect_config_error(dir, c, "supports[0].where: \"z >= 5\" selects no vertex");

  c = base_config();
  c["fibers"] = {{"influence", "conical"}};
  expect_config_error(dir, c, "fibers.influence: a conical influence (1 - L / horizon) needs a");
  c = base_config();
  c["stepping"]["control"] = "arc_length";
  expect_config_error(dir, c, "stepping.control: arc-length control needs \"scheme\"");
  c = base_config();
  c["stepping"] = {{"scheme", "newton"}, {"control", "arc_length"}};
  c["paddles"] = {{{"axis", "z"}, {"side", "above"}, {"travel", -0.01}}};
  expect_config_error(dir, c, "stepping.control: arc length follows the loads' factor");
  c = base_config();
  c["fem_reference"] = {{"E", 1000}, {"nu", 0.3}, {"material", "mooney"}};
  expect_config_error(dir, c, "fem_reference.material: ");
  c = base_config();
  c["fem_reference"] = {{"E", 1000}, {"nu", 0.3}, {"order", 3}};
  expect_config_error(dir, c, "fem_reference.order: ");

  // Found from outside (issue 11): each aborted, read out of bounds, or
  // silently did something else.
  c = base_config();
  c["supports"][0]["where"] = "z >= 1e999";
  expect_config_error(
      dir, c, "supports[0].where: 'z >= 1e999': the threshold 1e999 is beyond a double's range");
  c = base_config();
  c["supports"][0] = {{"vertices", {2147483648LL}}};
  expect_config_error(
      dir, c, "supports[0].vertices: expected vertex indices (whole numbers from 0 to 2147483647)");
  c = base_config();
  c["supports"][0] = {{"vertices", {4294967296ULL}}};
  expect_config_error(dir, c, "supports[0].vertices: expected vertex indices");
  c = base_config();
  c["loads"] = {{{"type", "point"}, {"force", {0, 0, -1}}}};
  expect_config_error(dir, c, "loads[0].vertex: missing (required)");
  c = base_config();
  c["surface"] = {
      {"generator", "box"}, {"min", {0, 0, 0}}, {"max", {1, 1, 1}}, {"segments", {1.9, 2, 2}}};
  expect_config_error(dir, c, "surface.segments: expected a list of 3 whole numbers from 1 to 200");
  c["surface"]["segments"] = {1e300, 2, 2};
  expect_config_error(dir, c, "surface.segments: expected a list of 3 whole numbers");
  c = base_config();
  c["surface"]["scale"] = 1e308;
  expect_config_error(dir, c, "surface.scale: scaled by 1e+308 the surface is inf m across");
  c["surface"]["scale"] = 1e-300;
  expect_config_error(dir, c, "surface.scale: scaled by 1e-300");
  c = base_config();
  c["stepping"]["steps"] = 0;  // unsigned in JSON: still below the range
  expect_config_error(dir, c, "stepping.steps: expected a whole number from 1");
  c["stepping"]["steps"] = 18446744073709551615ULL;
  expect_config_error(dir, c, "stepping.steps: expected a whole number from 1");
  // A number a double cannot hold, anywhere in the file: not a crash.
  const auto overflow = dir.write("overflow.json", R"({"name": "x", "material": {"Y": 1e999}})");
  try {
    load_experiment(overflow);
    ADD_FAILURE() << "no error for 1e999";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("overflow.json: not valid JSON"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("1e999"), std::string::npos) << e.what();
  }

  c = base_config();
  c["supports"][0]["where"] = "height > 1";
  expect_config_error(dir, c, "is not a half-space");

  c = base_config();
  c["supports"][0]["axes"] = "xw";
  expect_config_error(dir, c, "supports[0].axes");

  c = base_config();
  c["loads"][0] = {{"type", "point"}, {"vertex", 99}, {"force", {1, 0, 0}}};
  expect_config_error(dir, c, "loads[0].vertex: vertex 99 does not exist (the mesh has 42");

  c = base_config();
  c["loads"][0]["acceleration"] = {0, -9.81};
  expect_config_error(dir, c, "loads[0].acceleration: expected a list of 3 numbers");

  c = base_config();
  c["loads"][0]["schedule"] = {0.5, 1.0, 1.5};
  expect_config_error(dir, c, "the schedule lists 3 factors but stepping.steps is 2");

  c = base_config();
  c["loads"][0]["type"] = "wind";
  expect_config_error(dir, c, "loads[0].type: expected one of gravity, point");

  c = base_config();
  c["stepping"]["boundary_method"] = "lagrange";
  expect_config_error(dir, c, "stepping.boundary_method");

  expect_config_error(dir, nlohmann::json::array(), "expected an object");
  const auto broken = dir.write("broken.json", "{\"name\": ");
  EXPECT_THROW(load_experiment(broken), InputError);
}

// Central fibers default to the settings under which they converge with the
// mesh (the area count; the conical influence within a horizon); the vector
// spring keeps the paper's; either may be named.
TEST(ExperimentConfig, CentralFibersDefaultToTheAreaCountAndAConicalInfluence) {
  const auto model_of = [](const nlohmann::json& fibers) {
    nlohmann::json c = base_config();
    c["fibers"] = fibers;
    c["stepping"] = {{"scheme", "newton"}, {"steps", 1}};
    return parse_experiment(c, ".", "doc").simulation().cases.at(0).model;
  };
  model::Model m = model_of({{"kinematics", "central"}, {"horizon", 1.5}});
  EXPECT_EQ(m.connection_count, model::ConnectionCount::Area);
  EXPECT_EQ(m.influence.kind, model::Influence::Kind::Conical);
  EXPECT_EQ(m.influence.horizon, 1.5);
  m = model_of({{"kinematics", "central"}});  // every pair: nothing to fade
  EXPECT_EQ(m.connection_count, model::ConnectionCount::Area);
  EXPECT_EQ(m.influence.kind, model::Influence::Kind::Constant);
  m = model_of(nlohmann::json::object());
  EXPECT_EQ(m.connection_count, model::ConnectionCount::Symmetric);
  EXPECT_EQ(m.influence.kind, model::Influence::Kind::Constant);
  m = model_of({{"kinematics", "central"},
                {"horizon", 1.5},
                {"connection_count", "symmetric"},
                {"influence", "constant"}});
  EXPECT_EQ(m.connection_count, model::ConnectionCount::Symmetric);
  EXPECT_EQ(m.influence.kind, model::Influence::Kind::Constant);
  m = model_of({{"connection_count", "area"}});
  EXPECT_EQ(m.connection_count, model::ConnectionCount::Area);

  testing::ScratchDir dir;
  nlohmann::json c = base_config();
  c["fibers"] = {{"connection_count", "area"}, {"product", "treecode"}};
  expect_config_error(dir, c, "fibers.product: \"treecode\" needs one connection count");
  c["fibers"] = {{"connection_count", "by_area"}};
  expect_config_error(dir, c, "fibers.connection_count");

  // The line measure: no count, and no fading unless asked for.
  m = model_of({{"kinematics", "central"}, {"weights", "lines"}, {"horizon", 1.5}});
  EXPECT_EQ(m.fiber_weights, model::FiberWeights::Lines);
  EXPECT_EQ(m.influence.kind, model::Influence::Kind::Constant);
  m = model_of({{"kinematics", "central"}});
  EXPECT_EQ(m.fiber_weights, model::FiberWeights::Paper);
  c["fibers"] = {{"weights", "lines"}, {"connection_count", "area"}};
  expect_config_error(dir, c, "fibers.connection_count: \"weights\": \"lines\" weighs each fiber");
  c["fibers"] = {{"weights", "sideways"}};
  expect_config_error(dir, c, "fibers.weights");
}

// Issue 43, "a case is built from its own spec alone": in a sweep, a
// variant that shares the surface and fibers with an earlier one reused its
// model but copied only some of its settings: "influence": "conical" was
// lost (two identical variants, 0.0784189 and 0.0800808 m).
TEST(ACaseIsBuiltFromItsOwnSpecAlone, AReusedCaseEqualsOneBuiltAfreshFieldByField) {
  nlohmann::json c = base_config();
  c["surface"] = {
      {"generator", "cylinder"}, {"radius", 0.02}, {"length", 0.1}, {"segments", {12, 8}}};
  c["fibers"] = {{"kinematics", "central"},
                 {"horizon", 0.03},
                 {"influence", "conical"},
                 {"connection_count", "global"}};
  c["stepping"] = {{"scheme", "newton"}, {"steps", 2}};
  c["material"]["Y"] = 1e6;
  c["supports"][0]["where"] = "x <= 0";
  c["supports"][0]["layer"] = "mirror";
  c["variants"] = {{{"name", "a"}}, {{"name", "b"}}, {{"name", "c"}, {"material", {{"Y", 5e5}}}}};
  const Experiment ex = parse_experiment(c, ".", "doc");
  ASSERT_EQ(ex.simulation().cases.size(), 3u);
  for (size_t k = 1; k < 3; ++k) {
    const Case& reused = ex.simulation().cases[k];
    const Case fresh = build_case(ex.simulation().specs[k]);
    const model::Model &r = reused.model, &f = fresh.model;
    EXPECT_EQ(reused.variant, fresh.variant);
    EXPECT_EQ(reused.patch, fresh.patch);
    EXPECT_EQ(reused.model_to_input, fresh.model_to_input);
    EXPECT_EQ(reused.input_surface.V, fresh.input_surface.V);
    EXPECT_EQ(r.surface.V, f.surface.V);
    EXPECT_EQ(r.surface.F, f.surface.F);
    EXPECT_EQ(r.influence.kind, f.influence.kind) << k;
    EXPECT_EQ(r.influence.kind, model::Influence::Kind::Conical);
    EXPECT_EQ(r.influence.horizon, f.influence.horizon);
    EXPECT_EQ(r.connection_count, f.connection_count);
    EXPECT_EQ(r.fiber_weights, f.fiber_weights);
    EXPECT_EQ(r.treecode_tolerance, f.treecode_tolerance);
    EXPECT_EQ(r.material.kinematics, f.material.kinematics);
    for (const std::string& name : f.material.parameter_names())
      EXPECT_EQ(r.material.parameter(name), f.material.parameter(name)) << name;
    ASSERT_TRUE(r.fibers && f.fibers);
    EXPECT_EQ(r.fibers->num_kept(), f.fibers->num_kept());
    EXPECT_EQ(r.fibers->kept_per_vertex(), f.fibers->kept_per_vertex());
    EXPECT_EQ(r.loads.size(), f.loads.size());
    EXPECT_EQ(r.constraints.size(), f.constraints.size());
    EXPECT_EQ(r.constraint_groups, f.constraint_groups);
    ASSERT_EQ(r.mirror_layers.size(), f.mirror_layers.size());
    EXPECT_EQ(r.mirror_layers[0].depth, f.mirror_layers[0].depth);
    EXPECT_EQ(r.paddles.size(), f.paddles.size());
    EXPECT_EQ(reused.stepping.steps, fresh.stepping.steps);
    EXPECT_EQ(reused.fibers.kept, fresh.fibers.kept);
  }
  // And what counts: the identical variants give identical bits, and the
  // answer of the experiment run without a sweep (to rounding: a sweep's runs
  // share the threads, and sum in another order).
  const ExperimentResult result = run_experiment(ex);
  for (const RunResult& run : result.runs) ASSERT_TRUE(run.summary.success) << run.summary.message;
  EXPECT_EQ(result.runs[0].summary.unknowns, result.runs[1].summary.unknowns);
  nlohmann::json single = c;
  single.erase("variants");
  const ExperimentResult alone = run_experiment(parse_experiment(single, ".", "doc"));
  ASSERT_TRUE(alone.runs_succeeded());
  const Eigen::VectorXd& u = alone.runs[0].summary.unknowns;
  EXPECT_LT((u - result.runs[1].summary.unknowns).norm(), 1e-9 * u.norm());
  EXPECT_GT(result.runs[2].summary.steps.back().max_displacement,  // Y halved
            1.5 * result.runs[1].summary.steps.back().max_displacement);
}

// Issue 43, "the schema refuses what the reader refuses": `schema --help`
// suggests a "$schema" key, which the reader refused; it is taken now (and
// tests/python/test_schema.py checks the schema side with jsonschema).
TEST(TheSchemaRefusesWhatTheReaderRefuses, TheReaderTakesTheSchemaKeyAnEditorAdds) {
  nlohmann::json c = base_config();
  c["$schema"] = "fiberfluid.schema.json";
  EXPECT_NO_THROW(parse_experiment(c, ".", "doc"));
  c["$schema"] = 5;
  EXPECT_THROW(parse_experiment(c, ".", "doc"), InputError);
  // And the reader still refuses a mirror layer on a prescribed group, as the schema does.
  nlohmann::json p = base_config();
  p["prescribed"] = {{{"where", "z <= -0.5"}, {"displacement", {0, 0, 0.01}}, {"layer", "mirror"}}};
  EXPECT_THROW(parse_experiment(p, ".", "doc"), InputError);
}

TEST(AFileMeansOneThing, AnExperimentKeyGivenTwiceIsRefused) {
  testing::ScratchDir dir;
  // Issue 43, "a file means one thing": a key given twice in one object
  // (JSON leaves it open; the parser kept the last) is refused, naming it.
  for (const auto& [text, path] : std::vector<std::pair<std::string, std::string>>{
           {R"({"name": "x", "material": {"Y": 1000, "gamma": 1, "Y": 2000}})", "material.Y"},
           {R"({"name": "x", "name": "y"})", "name"},
           {R"({"name": "x", "supports": [{"where": "z < 0", "where": "z > 0"}]})",
            "supports.where"}}) {
    const auto twice = dir.write("twice.json", text);
    try {
      load_experiment(twice);
      ADD_FAILURE() << "no error for " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("twice.json: \"" + path + "\" is given twice"),
                std::string::npos)
          << e.what();
    }
  }
  // The same key in two objects is two keys.
  EXPECT_NO_THROW(parse_json(
      std::string(R"({"a": {"Y": 1}, "b": {"Y": 2}, "c": [{"Y": 3}, {"Y": 4}]})"), "ok"));
}

TEST(ExperimentConfig, ASurfaceIsRemeshedToTheCountAsked) {
  ScratchDir dir;
  nlohmann::json c = base_config();
  c["surface"]["subdivisions"] = 3;
  c["surface"]["remesh_vertices"] = 300;  // from the icosphere's 642
  const Experiment ex = load_experiment(write_config(dir, c));
  const int n = ex.simulation().cases[0].model.num_vertices();
  EXPECT_NEAR(n, 300, 6);
  EXPECT_EQ(ex.simulation().cases[0].input_surface.num_vertices(), n);
  bool told = false;
  for (const std::string& w : ex.warnings)
    told = told || w.find("surface.remesh_vertices: remeshed from 642 to " + std::to_string(n) +
                          " vertices (asked 300)") != std::string::npos;
  EXPECT_TRUE(told);
  c["surface"]["remesh_vertices"] = 3;
  expect_config_error(dir, c, "surface.remesh_vertices");
  c["surface"] = {
      {"generator", "rectangle"}, {"min", {0, 0}}, {"max", {1, 1}}, {"remesh_vertices", 100}};
  c["supports"] = {{{"where", "y <= 0"}}};
  c["loads"] = nlohmann::json::array();
  expect_config_error(dir, c, "surface.remesh_vertices: only a 3D surface can be remeshed");
}

TEST(ExperimentConfig, LawsPaddlesAndNewtonOptionsAreRead) {
  ScratchDir dir;
  nlohmann::json c = base_config();
  c["material"] = {{"law", {{"type", "exponential"}, {"Y0", 5000}, {"beta", 4}}},
                   {"axis_factors", {1, 1, 0.5}},
                   {"gamma", 3}};
  c["paddles"] = {{{"label", "press"},
                   {"axis", "z"},
                   {"side", "below"},
                   {"compression", 0.2},
                   {"contact", "sticking"}}};
  c["stepping"] = {{"steps", 4},
                   {"scheme", "newton"},
                   {"newton", {{"tangent", "krylov"}, {"max_step_cuts", 3}}}};
  const Experiment ex = load_experiment(write_config(dir, c));
  const model::Model& m = ex.simulation().cases[0].model;
  EXPECT_EQ(m.material.law.name(), "exponential");
  EXPECT_EQ(m.material.law.parameter("beta"), 4.0);
  EXPECT_EQ(m.material.axis_factors.z(), 0.5);
  ASSERT_EQ(m.paddles.size(), 1u);
  EXPECT_EQ(m.paddles[0].axis, 2);
  EXPECT_FALSE(m.paddles[0].above);
  EXPECT_TRUE(m.paddles[0].sticking());
  const double bottom = m.surface.V.col(2).minCoeff(), top = m.surface.V.col(2).maxCoeff();
  EXPECT_EQ(m.paddles[0].position, bottom);                       // touching by default
  EXPECT_NEAR(m.paddles[0].travel, 0.2 * (top - bottom), 1e-15);  // upwards, into the body
  EXPECT_EQ(ex.simulation().cases[0].stepping.scheme, solve::Scheme::Newton);
  EXPECT_EQ(ex.simulation().cases[0].stepping.newton.tangent, solve::TangentSolver::Krylov);
  EXPECT_EQ(ex.simulation().cases[0].stepping.newton.max_step_cuts, 3);
}

// Coulomb contact: "contact": "coulomb" on a paddle, the coefficient on the
// material, its tolerance in newton; a coefficient nothing would feel, a
// negative one or a bad tolerance refused by name.
TEST(ExperimentConfig, CoulombPaddlesAndTheirFrictionAreRead) {
  ScratchDir dir;
  nlohmann::json c = base_config();
  c["material"]["friction"] = 0.4;
  c["paddles"] = {{{"label", "press"},
                   {"axis", "z"},
                   {"side", "above"},
                   {"travel", -0.1},
                   {"contact", "coulomb"}}};
  c["stepping"] = {{"steps", 2}, {"scheme", "newton"}, {"newton", {{"friction_tolerance", 1e-5}}}};
  const Experiment ex = load_experiment(write_config(dir, c));
  const Case& read = ex.simulation().cases[0];
  EXPECT_EQ(read.model.paddles[0].contact, model::Paddle::Contact::Coulomb);
  EXPECT_EQ(read.model.material.friction, 0.4);
  EXPECT_EQ(read.stepping.newton.friction_tolerance, 1e-5);
  EXPECT_EQ(read.model.material.parameter("friction"), 0.4);

  nlohmann::json unfelt = c;
  unfelt["paddles"][0]["contact"] = "sticking";
  expect_config_error(dir, unfelt,
                      "a friction coefficient acts at paddles with \"contact\": "
                      "\"coulomb\", and this experiment has none");
  nlohmann::json negative = c;
  negative["material"]["friction"] = -0.1;
  expect_config_error(dir, negative, "friction");
  nlohmann::json tolerance = c;
  tolerance["stepping"]["newton"]["friction_tolerance"] = 0;
  expect_config_error(dir, tolerance, "friction_tolerance");
  nlohmann::json contact = c;
  contact["paddles"][0]["contact"] = "rough";
  expect_config_error(dir, contact, "coulomb");
}

// Every name a reader offers for an enum reads as the value it names (an
// enum read through a chain of comparisons once turned a name the chain
// lacked into its default): each name through the file, compared with the
// value the enum's one list gives it.
TEST(ExperimentConfig, EveryNamedChoiceReadsAsTheValueItNames) {
  ScratchDir dir;
  for (const auto& entry : solve::kTangentSolverNames.entries()) {
    nlohmann::json c = base_config();
    c["stepping"] = {{"scheme", "newton"}, {"newton", {{"tangent", entry.name}}}};
    EXPECT_EQ(load_experiment(write_config(dir, c)).simulation().cases[0].stepping.newton.tangent,
              entry.value)
        << entry.name;
  }
  for (const auto& entry : solve::kSolverKindNames.entries()) {
    nlohmann::json c = base_config();
    c["stepping"]["solver"] = entry.name;
    EXPECT_EQ(load_experiment(write_config(dir, c)).simulation().cases[0].stepping.solver,
              entry.value)
        << entry.name;
  }
  for (const auto& entry : model::kBoundaryMethodNames.entries()) {
    nlohmann::json c = base_config();
    c["stepping"]["boundary_method"] = entry.name;
    EXPECT_EQ(load_experiment(write_config(dir, c)).simulation().cases[0].stepping.boundary_method,
              entry.value)
        << entry.name;
  }
  for (const auto& entry : model::kConnectionCountNames.entries()) {
    nlohmann::json c = base_config();
    c["fibers"] = {{"connection_count", entry.name}};
    EXPECT_EQ(load_experiment(write_config(dir, c)).simulation().cases[0].model.connection_count,
              entry.value)
        << entry.name;
  }
  for (const auto& entry : solve::kSchemeNames.entries()) {
    nlohmann::json c = base_config();
    c["stepping"]["scheme"] = entry.name;
    EXPECT_EQ(load_experiment(write_config(dir, c)).simulation().cases[0].stepping.scheme,
              entry.value)
        << entry.name;
  }
}

TEST(ExperimentConfig, BadLawsAndPaddlesAreNamed) {
  ScratchDir dir;
  nlohmann::json c = base_config();
  c["material"]["law"] = {{"type", "exponential"}, {"Y0", 5000}, {"beta", 2}};
  expect_config_error(dir, c, "material.Y: give either Y");

  c = base_config();
  c["material"] = {{"law", {{"type", "exponential"}, {"beta", 2}}}};
  expect_config_error(dir, c, "material.law.Y0: missing");

  c = base_config();
  c["material"] = {
      {"law", {{"type", "tabulated"}, {"strain", {0, 0.1, 0.2}}, {"stress", {0, 200, 150}}}}};
  expect_config_error(dir, c, "material.law.stress: the stresses must be strictly increasing");

  c = base_config();
  c["material"] = {{"law", {{"type", "tabulated"}, {"strain", {0, 0.1}}, {"stress", {0}}}}};
  expect_config_error(dir, c, "material.law.stress: expected as many stresses as strains");

  c = base_config();
  c["material"] = {{"law", {{"type", "exponential"}, {"Y0", 1}, {"beta", 900}}}};
  expect_config_error(dir, c, "check beta");

  // The spline law: its knots, its rises and its rest tension, each by name.
  const nlohmann::json spline = {
      {"type", "spline"}, {"stretches", {0.5, 1.5, 3}}, {"rises", {1e3, 2e3, 4e3}}, {"T1", 0}};
  c = base_config();
  c["material"] = {{"law", spline}};
  const model::FiberLaw read =
      load_experiment(write_config(dir, c)).simulation().cases[0].model.material.law;
  EXPECT_EQ(read.name(), "spline");
  EXPECT_EQ(read.parameter("rise3"), 4e3);
  c["material"]["law"]["rises"] = {1e3, 2e3};
  expect_config_error(dir, c, "material.law.rises: expected one rise per stretch (3), got 2");
  c["material"]["law"] = spline;
  c["material"]["law"]["rises"] = {1e3, -2e3, 4e3};
  expect_config_error(dir, c, "material.law.rises: rise2 must be a number >= 0");
  c["material"]["law"] = spline;
  c["material"]["law"]["stretches"] = {1.1, 1.5, 3};
  expect_config_error(dir, c, "material.law.stretches: the stretches must span the rest stretch");
  c["material"]["law"] = spline;
  c["material"]["law"]["T1"] = -1;
  expect_config_error(dir, c, "material.law.T1");

  c = base_config();
  c["material"] = {{"law", {{"type", "hyperelastic"}}}};
  expect_config_error(dir, c, "material.law.type: expected one of");

  nlohmann::json paddle = {{"axis", "z"}, {"side", "above"}, {"travel", -0.2}};
  c = base_config();
  c["paddles"] = {paddle};
  expect_config_error(dir, c, "paddles: paddles need \"stepping\": {\"scheme\": \"newton\"}");

  c = base_config();
  c["stepping"]["scheme"] = "newton";
  c["paddles"] = {paddle};
  c["paddles"][0]["axis"] = "n";
  expect_config_error(dir, c, "paddles[0].axis: expected one of \"xyz\"");

  c["paddles"] = {paddle};
  c["paddles"][0]["position"] = 0.5;
  expect_config_error(dir, c, "paddles[0].position: the paddle starts inside the body");

  c["paddles"] = {paddle};
  c["paddles"][0]["compression"] = 0.3;
  expect_config_error(dir, c, "paddles[0].travel: give either travel");

  c["paddles"] = {paddle, {{"label", "floor"}, {"axis", "z"}, {"side", "below"}, {"travel", 2.0}}};
  expect_config_error(dir, c, "paddles: paddles paddle_0 and floor meet or pass each other");

  c = base_config();
  c["stepping"]["newton"] = {{"max_iterations", 5}};
  expect_config_error(dir, c, "stepping.newton: Newton options need");

  c = base_config();
  c["stepping"] = {{"scheme", "newton"}, {"newton", {{"tangent", "cg"}}}};
  expect_config_error(dir, c, "stepping.newton.tangent: expected one of auto, dense, krylov");
}

TEST(ExperimentConfig, TreecodeProductIsReadCheckedAndAgreesWithTheExactRun) {
  ScratchDir dir;
  nlohmann::json c = base_config();
  c["surface"]["subdivisions"] = 4;  // 2,562 vertices: proxies in play
  c["fibers"] = {{"product", "treecode"}, {"treecode_tolerance", 1e-6}};
  const Experiment approximate = load_experiment(write_config(dir, c));
  EXPECT_EQ(approximate.simulation().cases[0].model.treecode_tolerance, 1e-6);
  c.erase("fibers");
  c["stepping"]["solver"] = "pcg";
  const Experiment exact = load_experiment(write_config(dir, c));
  const ExperimentResult a = run_experiment(approximate), e = run_experiment(exact);
  ASSERT_TRUE(a.runs_succeeded() && e.runs_succeeded());
  EXPECT_EQ(a.runs[0].summary.solver, solve::SolverKind::PCG);  // auto: the matrix-free backend
  const Eigen::VectorXd& ua = a.runs[0].summary.unknowns;
  const Eigen::VectorXd& ue = e.runs[0].summary.unknowns;
  EXPECT_LT((ua - ue).norm(), 1e-6 * ue.norm());
  EXPECT_GT((ua - ue).norm(), 0.0);  // it did approximate

  // Variants share the surface and its fibers, and the product with them.
  c["fibers"] = {{"product", "treecode"}, {"treecode_tolerance", 1e-4}};
  c["stepping"] = {{"steps", 1}};
  c["variants"] = {{{"name", "soft"}, {"material", {{"Y", 50000}}}},
                   {{"name", "stiff"}, {"material", {{"Y", 200000}}}}};
  const Experiment sweep = load_experiment(write_config(dir, c));
  ASSERT_EQ(sweep.simulation().cases.size(), 2u);
  for (const Case& variant : sweep.simulation().cases)
    EXPECT_EQ(variant.model.treecode_tolerance, 1e-4);
  c.erase("variants");

  c = base_config();
  c["fibers"] = {{"treecode_tolerance", 1e-6}};
  expect_config_error(dir, c,
                      "fibers.treecode_tolerance: applies to \"product\": \"treecode\" only");
  c["fibers"] = {{"product", "treecode"}, {"treecode_tolerance", 0.5}};
  expect_config_error(dir, c,
                      "fibers.treecode_tolerance: expected a relative error from 1e-10 to 1e-2");
  c["fibers"] = {{"product", "treecode"}};
  c["stepping"]["solver"] = "dense-lu";
  expect_config_error(dir, c,
                      "fibers: \"product\": \"treecode\": the treecode product "
                      "(treecode_tolerance) is matrix-free");
  c["stepping"] = {{"scheme", "newton"}};
  expect_config_error(dir, c, "Newton's tangent is exact");
  // A concave body pruned with the symmetric count has no single pair factor.
  c = base_config();
  c["surface"] = {{"generator", "torus"}, {"segments", {16, 8}}};
  c["supports"][0] = {{"where", "z >= 0.5"}};
  c["fibers"] = {{"product", "treecode"}};
  expect_config_error(dir, c, "fibers.product: \"treecode\" needs one connection count");
  c["fibers"]["connection_count"] = "global";
  EXPECT_GT(load_experiment(write_config(dir, c)).simulation().cases[0].fibers.pairs,
            load_experiment(write_config(dir, c)).simulation().cases[0].fibers.kept);
}

// fibers.kinematics: the paper's vector spring by default, central fibers
// with the Newton scheme; the run's summary says which.
TEST(ExperimentConfig, FiberKinematicsIsReadAndChecked) {
  ScratchDir dir;
  nlohmann::json c = base_config();
  EXPECT_EQ(load_experiment(write_config(dir, c)).simulation().cases[0].model.material.kinematics,
            model::FiberKinematics::VectorSpring);
  c["fibers"] = {{"kinematics", "central"}};
  expect_config_error(dir, c,
                      "fibers: \"kinematics\": the central fiber kinematics needs the Newton "
                      "scheme");
  c["stepping"]["scheme"] = "newton";
  const Experiment ex = load_experiment(write_config(dir, c));
  EXPECT_EQ(ex.simulation().cases[0].model.material.kinematics, model::FiberKinematics::Central);
  const ExperimentResult r = run_experiment(ex);
  ASSERT_TRUE(r.runs_succeeded()) << r.runs[0].summary.message;
  EXPECT_GT(r.figures.at("max_displacement"), 0.0);
  c["fibers"]["kinematics"] = "bent";
  expect_config_error(dir, c, "fibers.kinematics");
}

// An expected figure is checked against the experiment's own figures when
// the file is read: a misspelt name fails before the run, listing the names.
TEST(ExperimentConfig, AnUnknownExpectedFigureIsAnErrorWhenTheFileIsRead) {
  ScratchDir dir;
  nlohmann::json c = base_config();
  c["expected"] = {{{"figure", "max_displacement"}, {"at_most", 1.0}},
                   {{"figure", "position.3.z"}, {"at_most", 1.0}},
                   {{"figure", "fibers.kept"}, {"at_least", 1.0}}};
  EXPECT_NO_THROW(load_experiment(write_config(dir, c)));
  c["expected"][0]["figure"] = "max_displacment";
  expect_config_error(dir, c,
                      "expected[0].figure: no figure \"max_displacment\" in this experiment "
                      "(expected one of fibers.in_all, fibers.kept, fibers.pruned, "
                      "max_displacement, final_pressure");
  c["expected"][0]["figure"] = "position.3.q";
  expect_config_error(dir, c, "expected[0].figure: no figure \"position.3.q\"");
  c["expected"][0]["figure"] = "position.I.x";  // the form the message shows, not a figure
  expect_config_error(dir, c, "expected[0].figure: no figure \"position.I.x\"");
  c["expected"][0]["figure"] = "paddle_force.top";  // no such paddle
  expect_config_error(dir, c, "expected[0].figure: no figure \"paddle_force.top\"");
  c["expected"][0]["figure"] = "fit.Y";  // no fit section
  expect_config_error(dir, c, "expected[0].figure: no figure \"fit.Y\"");
  // A sweep's figures carry their variant's name.
  c["variants"] = {{{"name", "soft"}, {"material", {{"Y", 50000}}}},
                   {{"name", "stiff"}, {"material", {{"Y", 200000}}}}};
  c["expected"] = {{{"figure", "stiff.max_displacement"}, {"at_most", 1.0}}};
  EXPECT_NO_THROW(load_experiment(write_config(dir, c)));
  c["expected"][0]["figure"] = "max_displacement";  // which variant?
  expect_config_error(dir, c, "soft.max_displacement, soft.final_pressure");
  c["expected"][0]["figure"] = "hard.max_displacement";
  expect_config_error(dir, c, "expected[0].figure: no figure \"hard.max_displacement\"");
}

// A material without gamma has no surface tension, and the reader says so.
TEST(ExperimentConfig, AMissingGammaIsAWarningNamingItsDefault) {
  ScratchDir dir;
  nlohmann::json c = base_config();
  EXPECT_TRUE(load_experiment(write_config(dir, c)).warnings.empty());
  c["material"].erase("gamma");
  const Experiment ex = load_experiment(write_config(dir, c));
  ASSERT_EQ(ex.warnings.size(), 1u);
  EXPECT_NE(ex.warnings[0].find("material.gamma: not given, so 0 (no surface tension"),
            std::string::npos)
      << ex.warnings[0];
  EXPECT_EQ(ex.simulation().cases[0].model.material.surface_tension, 0.0);
}

// supports[].layer: "mirror" gives a clamp on a plane the fibers that reach
// across it (model::MirrorLayer), as deep as the horizon; a clamp it cannot
// mirror is named.
TEST(ExperimentConfig, AClampsMirrorLayerIsReadAndChecked) {
  ScratchDir dir;
  nlohmann::json c = base_config();
  c["surface"] = {{"generator", "box"},
                  {"min", {0, 0, 0}},
                  {"max", {0.06, 0.02, 0.02}},
                  {"segments", {6, 2, 2}}};
  c["supports"] = {{{"label", "clamp"}, {"where", "x <= 0"}, {"layer", "mirror"}}};
  c["fibers"] = {{"kinematics", "central"}, {"horizon", 0.025}};
  c["stepping"]["scheme"] = "newton";
  const Experiment ex = load_experiment(write_config(dir, c));
  const model::Model& m = ex.simulation().cases[0].model;
  ASSERT_EQ(m.mirror_layers.size(), 1u);
  EXPECT_LT((m.mirror_layers[0].normal - Eigen::Vector3d::UnitX()).norm(), 1e-12);
  EXPECT_EQ(m.mirror_layers[0].depth, 0.025);
  const ExperimentResult r = run_experiment(ex);
  ASSERT_TRUE(r.runs_succeeded()) << r.runs[0].summary.message;
  const nlohmann::json layers = summary_json(ex, r)["fibers"]["mirror_layers"];
  ASSERT_EQ(layers.size(), 1u);
  EXPECT_EQ(layers[0]["support"], "clamp");
  EXPECT_EQ(layers[0]["depth"], 0.025);
  EXPECT_EQ(layers[0]["normal"], nlohmann::json({1.0, 0.0, 0.0}));

  nlohmann::json bad = c;
  bad["supports"][0]["layer"] = "odd";
  expect_config_error(dir, bad, "supports[0].layer");
  bad = c;
  bad["fibers"].erase("horizon");
  expect_config_error(dir, bad,
                      "supports[0].layer: a mirror layer is as deep as the fibers' horizon");
  bad = c;
  bad["supports"][0]["axes"] = "z";
  expect_config_error(dir, bad, "supports[0].layer: a mirror layer clamps every axis");
  bad = c;
  bad["supports"][0]["where"] = "x <= 0.011";
  expect_config_error(dir, bad,
                      "supports[0].layer: the support has no clamp plane: its vertices are not "
                      "on one plane");
  bad = c;
  bad["fibers"]["kinematics"] = "vector";
  bad["stepping"]["scheme"] = "incremental";
  expect_config_error(dir, bad,
                      "supports[0].layer: a support's mirror layer needs the Newton scheme");
  bad = c;
  bad["prescribed"] = {
      {{"where", "x >= 0.06"}, {"displacement", {0, 0, 0.001}}, {"layer", "mirror"}}};
  expect_config_error(dir, bad, "prescribed[0].layer: a mirror layer belongs to a fixed clamp");
}

// A support's split edge ("edge": "split", held_edge.hpp) and the mean
// connection count: read, reported, run, and refused where they cannot act.
TEST(ExperimentConfig, ASupportsSplitEdgeAndTheMeanCountAreReadAndChecked) {
  ScratchDir dir;
  nlohmann::json c = base_config();
  c["surface"] = {{"generator", "box"},
                  {"min", {0, 0, 0}},
                  {"max", {0.06, 0.02, 0.02}},
                  {"segments", {6, 2, 2}}};
  c["supports"] = {
      {{"label", "clamp"}, {"where", "x <= 0"}, {"layer", "mirror"}, {"edge", "split"}}};
  c["fibers"] = {{"kinematics", "central"}, {"horizon", 0.025}, {"connection_count", "mean"}};
  c["stepping"]["scheme"] = "newton";
  const Experiment ex = load_experiment(write_config(dir, c));
  const model::Model& m = ex.simulation().cases[0].model;
  ASSERT_EQ(m.held_edges.size(), 1u);
  EXPECT_EQ(m.held_edges[0].held.size(), 9u);  // the end face's 3 x 3 grid
  EXPECT_EQ(m.connection_count, model::ConnectionCount::Mean);
  const ExperimentResult r = run_experiment(ex);
  ASSERT_TRUE(r.runs_succeeded()) << r.runs[0].summary.message;
  const nlohmann::json fibers = summary_json(ex, r)["fibers"];
  ASSERT_EQ(fibers["split_edges"].size(), 1u);
  EXPECT_EQ(fibers["split_edges"][0]["support"], "clamp");
  EXPECT_EQ(fibers["split_edges"][0]["edge_vertices"], 8);

  nlohmann::json bad = c;
  bad["supports"][0]["edge"] = "cut";
  expect_config_error(dir, bad, "supports[0].edge");
  bad = c;
  bad["supports"][0].erase("layer");
  bad["supports"][0]["axes"] = "xy";
  expect_config_error(dir, bad, "supports[0].edge: a split edge holds every axis");
  bad = c;
  bad["supports"][0].erase("layer");
  bad["fibers"] = {{"kinematics", "vector"}};
  bad["stepping"]["scheme"] = "incremental";
  expect_config_error(dir, bad, "supports[0].edge: a support's split edge needs the Newton scheme");
  bad = c;
  bad["prescribed"] = {
      {{"where", "x >= 0.06"}, {"displacement", {0, 0, 0.001}}, {"edge", "split"}}};
  expect_config_error(dir, bad, "prescribed[0].edge: a split edge belongs to a fixed support");
  bad = c;
  bad["fibers"]["product"] = "treecode";
  bad["fibers"].erase("horizon");
  bad["supports"][0].erase("layer");
  expect_config_error(dir, bad, "fibers.product: \"treecode\" needs one connection count");
}

// A prescribed group may turn rigidly: "rotation" (axis, angle in degrees,
// centre) with an optional translation, along its schedule.
// A cylinder of central fibers pressed between two frictionless paddles and
// held only at the centre of its base (the compression of issue 42, small):
// nothing holds the spin about the paddles' axis, which the loads do not
// drive, so a gauge holds it, says so, and carries no force; the contact set
// settles at first touch in a few rounds instead of rocking the body from
// one paddle to the other. With a load that turns the body about that axis
// there is no equilibrium: refused, naming the rotation.
TEST(ExperimentConfig, AFreeRotationIsHeldByAGaugeOrRefused) {
  ScratchDir dir;
  nlohmann::json c = base_config();
  c["surface"] = {
      {"generator", "cylinder"}, {"radius", 0.025}, {"length", 0.03}, {"segments", {4, 16}}};
  c["material"] = {{"Y", 100000}, {"gamma", 0.001}};
  c["fibers"] = {{"kinematics", "central"}, {"horizon", 0.03}};
  c["loads"] = nlohmann::json::array();
  c["supports"] = {{{"label", "centre"},
                    {"box", {{"min", {-1e-7, -1e-7, -1e-7}}, {"max", {1e-7, 1e-7, 1e-7}}}}}};
  c["paddles"] = {{{"label", "lower"}, {"axis", "x"}, {"side", "below"}, {"travel", 0}},
                  {{"label", "upper"}, {"axis", "x"}, {"side", "above"}, {"travel", -0.006}}};
  c["stepping"] = {{"scheme", "newton"}, {"steps", 3}};
  const Experiment ex = load_experiment(write_config(dir, c));
  ASSERT_EQ(ex.warnings.size(), 1u);
  EXPECT_NE(ex.warnings[0].find("rotation about the axis x through (0.015, 0, 0) free"),
            std::string::npos)
      << ex.warnings[0];
  EXPECT_NE(ex.warnings[0].find("as a gauge"), std::string::npos) << ex.warnings[0];
  const model::Model& m = ex.simulation().cases[0].model;
  ASSERT_EQ(m.constraint_groups.back(), "gauge");
  const ExperimentResult r = run_experiment(ex);
  ASSERT_TRUE(r.runs_succeeded()) << r.runs[0].summary.message;
  const solve::SteppingSummary& s = r.runs[0].summary;
  EXPECT_LE(s.steps[0].contact_rounds, 4);
  // The platens touch the end faces at the start: in contact from the first iterate.
  EXPECT_GT(s.steps[0].paddles[0].contacts, 0);
  EXPECT_GT(s.steps[0].paddles[1].contacts, 0);
  const solve::StepRecord& last = s.steps.back();
  const double pressing = std::abs(last.paddles[1].force.x());
  EXPECT_GT(pressing, 0.1);
  EXPECT_LT(last.reactions.back().norm(), 1e-9 * pressing);  // the gauge carries nothing
  Eigen::Vector3d total = last.paddles[0].force + last.paddles[1].force;
  for (const Eigen::Vector3d& reaction : last.reactions) total += reaction;
  EXPECT_LT(total.norm(), 1e-8 * pressing);  // paddles and supports balance

  nlohmann::json turned = c;  // a push across the axis at the rim turns the body
  turned["loads"] = {{{"type", "point"}, {"vertex", 1}, {"force", {0, 0.01, 0.01}}}};
  expect_config_error(dir, turned,
                      "supports[0]: the supports leave the rotation about the axis x through "
                      "(0.015, 0, 0) free, and the loads turn the body about it");
}

// A body resting on a floor: no support holds it along the floor's axis,
// the floor it touches at its start does, and carries its weight.
TEST(ExperimentConfig, ABodyRestingOnAFloorPaddleIsHeldByIt) {
  ScratchDir dir;
  nlohmann::json c = base_config();
  c["surface"] = {
      {"generator", "cylinder"}, {"radius", 0.025}, {"length", 0.03}, {"segments", {4, 16}}};
  c["material"] = {{"Y", 100000}, {"gamma", 0.001}};
  c["supports"] = {{{"label", "centre"},
                    {"axes", "yz"},
                    {"box", {{"min", {-1e-7, -1e-7, -1e-7}}, {"max", {1e-7, 1e-7, 1e-7}}}}}};
  c["loads"] = {{{"type", "gravity"}, {"acceleration", {-9.81, 0, 0}}, {"density", 1000}}};
  c["paddles"] = {{{"label", "floor"}, {"axis", "x"}, {"side", "below"}, {"travel", 0}}};
  c["stepping"] = {{"scheme", "newton"}, {"steps", 2}};
  const ExperimentResult r = run_experiment(load_experiment(write_config(dir, c)));
  ASSERT_TRUE(r.runs_succeeded()) << r.runs[0].summary.message;
  const solve::StepRecord& last = r.runs[0].summary.steps.back();
  const double weight = -last.applied_force.x();
  EXPECT_GT(weight, 0.1);
  EXPECT_NEAR(last.paddles[0].force.x(), weight, 1e-8 * weight);  // the floor's push on the body
  EXPECT_GT(last.paddles[0].contacts, 0);

  nlohmann::json clear = c;  // a floor below the body holds nothing at the start
  clear["paddles"][0]["position"] = -0.001;
  const ExperimentResult falls = run_experiment(load_experiment(write_config(dir, clear)));
  ASSERT_FALSE(falls.runs_succeeded());
  EXPECT_NE(falls.runs[0].summary.message.find("no support along x"), std::string::npos)
      << falls.runs[0].summary.message;
}

TEST(ExperimentConfig, APrescribedRotationIsReadAndChecked) {
  ScratchDir dir;
  nlohmann::json c = base_config();
  c["prescribed"] = {
      {{"where", "z <= -0.8"},
       {"rotation", {{"axis", {0, 1, 0}}, {"angle_degrees", 30}, {"centre", {0, 0, -1}}}},
       {"displacement", {0.1, 0, 0}}}};
  const Experiment ex = load_experiment(write_config(dir, c));
  const model::Model& m = ex.simulation().cases[0].model;
  ASSERT_EQ(m.motions.size(), 1u);
  EXPECT_NEAR(m.motions[0].angle, M_PI / 6.0, 1e-15);
  EXPECT_EQ(m.motions[0].translation, Eigen::Vector3d(0.1, 0.0, 0.0));
  int turning = 0;
  for (const model::Constraint& k : m.constraints) turning += k.motion == 0;
  EXPECT_GT(turning, 0);
  // The held value at full load is the rigid motion's: a vertex at s moves to
  // R (s - c) + c + t.
  for (const model::Constraint& k : m.constraints) {
    if (k.motion != 0) continue;
    const Eigen::Vector3d s = m.surface.V.row(k.vertex).transpose(), centre(0, 0, -1);
    const Eigen::Vector3d moved =
        Eigen::AngleAxisd(M_PI / 6.0, Eigen::Vector3d::UnitY()) * (s - centre) + centre +
        Eigen::Vector3d(0.1, 0.0, 0.0);
    EXPECT_NEAR(model::held_value(m, k, 2, 2), (moved - s)[k.axis], 1e-14);
  }
  c["prescribed"][0]["rotation"]["axis"] = {0, 0, 0};
  expect_config_error(dir, c, "prescribed[0].rotation.axis: expected a nonzero axis");
  c["prescribed"][0]["rotation"].erase("axis");
  expect_config_error(dir, c, "prescribed[0].rotation.axis");
  c["prescribed"][0]["rotation"] = {{"axis", {0, 1, 0}}, {"centre", {0, 0, -1}}};
  expect_config_error(dir, c, "prescribed[0].rotation.angle_degrees");
}

// loads[].integration: the paper's vertex form by default, or exact.
TEST(ExperimentConfig, TheHydrostaticLoadsIntegrationIsRead) {
  ScratchDir dir;
  nlohmann::json c = base_config();
  EXPECT_EQ(load_experiment(write_config(dir, c)).simulation().cases[0].model.loads[0].integration,
            model::Load::Integration::Vertex);
  c["loads"][0]["integration"] = "exact";
  EXPECT_EQ(load_experiment(write_config(dir, c)).simulation().cases[0].model.loads[0].integration,
            model::Load::Integration::Exact);
  c["loads"][0]["integration"] = "consistent";
  expect_config_error(dir, c, "loads[0].integration: expected one of");
}

TEST(ExperimentConfig, TorusGeneratorIsReadAndChecked) {
  ScratchDir dir;
  nlohmann::json c = base_config();
  c["surface"] = {
      {"generator", "torus"}, {"major_radius", 2.0}, {"minor_radius", 0.5}, {"segments", {24, 12}}};
  c["supports"][0] = {{"where", "z >= 0.4"}};
  const Experiment ex = load_experiment(write_config(dir, c));
  EXPECT_EQ(ex.simulation().cases[0].model.num_vertices(), 24 * 12);
  EXPECT_FALSE(ex.simulation().cases[0].fibers.convex);
  c["surface"]["minor_radius"] = 2.5;
  expect_config_error(dir, c, "surface.minor_radius: must be below major_radius");
  c["surface"]["minor_radius"] = 0.5;
  c["surface"]["segments"] = {2, 12};
  expect_config_error(dir, c,
                      "surface.segments: expected a list of 2 whole numbers from 3 to 1000");
}

// A horizon that keeps few pairs is stored as neighbour lists; its kept
// fibers are written from them, one VTK line each.
TEST(ExperimentConfig, AHorizonsKeptFibersAreWrittenFromItsLists) {
  ScratchDir dir;
  nlohmann::json c = base_config();
  c["surface"]["subdivisions"] = 3;  // 642 vertices
  c["fibers"] = {{"horizon", 0.2}, {"write", "kept"}};
  const Experiment ex = load_experiment(write_config(dir, c));
  ASSERT_TRUE(ex.simulation().cases[0].model.fibers &&
              ex.simulation().cases[0].model.fibers->sparse());
  const long long kept = ex.simulation().cases[0].fibers.kept;
  EXPECT_GT(kept, 642);
  OutputWriter writer(ex, dir.path() / "out");
  writer.begin();
  writer.finish(run_experiment(ex));
  for (const char* name : {"fibers.vtu", "fibers_final.vtu"}) {
    std::ifstream vtu(dir.path() / "out" / name);
    const std::string text((std::istreambuf_iterator<char>(vtu)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("NumberOfCells=\"" + std::to_string(kept) + "\""), std::string::npos)
        << name << ": " << text.substr(0, 300);
    for (const char* field : {"rest_length", "strain", "tension", "force"})
      EXPECT_EQ(text.find(std::string("Name=\"") + field + "\"") != std::string::npos,
                (std::string(name) == "fibers.vtu") == (std::string(field) == "rest_length"))
          << name << " " << field;
  }
}

TEST(ExperimentConfig, FibersArePrunedForConcaveBodiesAndWrittenOnRequest) {
  ScratchDir dir;
  nlohmann::json c = base_config();
  EXPECT_TRUE(
      load_experiment(write_config(dir, c)).simulation().cases[0].fibers.convex);  // an icosphere

  // The paper's 2D L: three pairs see each other across the re-entrant corner.
  c["surface"] = {{"generator", "polygon"},
                  {"points", {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}}}};
  c["supports"][0] = {{"where", "y <= 0"}};
  c["loads"][0]["acceleration"] = {0, -9.81};
  c["fibers"] = {{"write", "pruned"}, {"connection_count", "global"}};
  const Experiment ex = load_experiment(write_config(dir, c));
  const Case& l_case = ex.simulation().cases[0];
  EXPECT_FALSE(l_case.fibers.convex);
  EXPECT_EQ(l_case.fibers.pairs, 15);
  EXPECT_EQ(l_case.fibers.kept, 12);
  EXPECT_EQ(l_case.model.connection_count, model::ConnectionCount::Global);
  ASSERT_TRUE(l_case.model.fibers);

  OutputWriter writer(ex, dir.path() / "out");
  writer.begin();
  const ExperimentResult result = run_experiment(ex);
  writer.finish(result);
  EXPECT_TRUE(result.runs_succeeded());
  EXPECT_EQ(result.figures.at("fibers.pruned"), 3.0);
  std::ifstream vtu(dir.path() / "out" / "fibers.vtu");
  const std::string text((std::istreambuf_iterator<char>(vtu)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("NumberOfCells=\"3\""), std::string::npos) << text.substr(0, 300);
  std::ifstream summary_file(dir.path() / "out" / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  EXPECT_EQ(summary["fibers"]["pruned"], 3);
  EXPECT_EQ(summary["fibers"]["connection_count"], "global");

  c["fibers"] = {{"pruning", "off"}};
  const Experiment unpruned = load_experiment(write_config(dir, c));
  EXPECT_FALSE(unpruned.simulation().cases[0].model.fibers);
  EXPECT_EQ(unpruned.simulation().cases[0].fibers.kept, 15);

  c["fibers"] = {{"pruning", "sometimes"}};
  expect_config_error(dir, c, "fibers.pruning: expected one of auto, off");
  c["fibers"] = {{"colour", "green"}};
  expect_config_error(dir, c, "fibers.colour: unknown field");
}

TEST(ExperimentConfig, InvertedMeshNeedsFlip) {
  ScratchDir dir;
  geom::Surface inward = geom::read_surface(testing::data_mesh("icosahedron.obj")).surface;
  geom::flip_orientation(inward);
  geom::write_obj(dir.path() / "inward.obj", inward);
  nlohmann::json c = base_config();
  c["surface"] = {{"file", "inward.obj"}};
  c["supports"][0]["where"] = "z >= 0.8";
  expect_config_error(dir, c, "inverted");
  c["surface"]["flip"] = true;
  EXPECT_NO_THROW(load_experiment(write_config(dir, c)));
}

TEST(ExperimentConfig, VertexIndicesAreInputIndicesAndOutputsKeepTheInputOrder) {
  ScratchDir dir;
  nlohmann::json c = base_config();
  c["surface"] = {{"file", testing::data_mesh("liver.obj").string()}, {"scale", 0.04}};
  c["supports"][0] = {{"vertices", {0, 1, 2, 3, 4, 5}}};  // liver's vertices 0..5 are used
  c["loads"][0]["acceleration"] = {0, -9.81, 0};
  c["output"] = {{"vtk", true}, {"every", 1}};
  const Experiment ex = load_experiment(write_config(dir, c));
  const Case& liver = ex.simulation().cases[0];
  EXPECT_EQ(liver.input_surface.num_vertices(), 181);
  EXPECT_EQ(liver.model.num_vertices(), 139);

  OutputWriter writer(ex, dir.path() / "out");
  writer.begin();
  const ExperimentResult result =
      run_experiment(ex, [&](size_t run, const solve::StepRecord& r, const Eigen::VectorXd& x) {
        writer.on_step(run, r, x);
      });
  writer.finish(result);
  ASSERT_TRUE(result.runs_succeeded());

  const geom::Surface final_surface = geom::read_surface(dir.path() / "out" / "final.obj").surface;
  EXPECT_EQ(final_surface.num_vertices(), 181);
  EXPECT_EQ(final_surface.F, liver.input_surface.F);
  for (int i = 0; i < 181; ++i) {
    if (liver.input_surface.F.cwiseEqual(i).any()) continue;  // unused vertices stay in place
    EXPECT_NEAR((final_surface.V.row(i) - liver.input_surface.V.row(i)).norm(), 0.0, 1e-12);
  }
  for (const char* file : {"summary.json", "series.pvd", "vtk/step_0000.vtu", "vtk/step_0002.vtu"})
    EXPECT_TRUE(std::filesystem::exists(dir.path() / "out" / file)) << file;

  std::ifstream summary_file(dir.path() / "out" / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  ASSERT_EQ(summary["runs"].size(), 1u);
  const auto& steps = summary["runs"][0]["steps"];
  ASSERT_EQ(steps.size(), 2u);
  for (const char* key : {"pressure", "volume", "max_displacement", "seconds", "load_factors"})
    EXPECT_TRUE(steps[1].contains(key)) << key;
  EXPECT_DOUBLE_EQ(steps[1]["max_displacement"].get<double>(),
                   summary["figures"]["max_displacement"].get<double>());

  std::ifstream vtu(dir.path() / "out" / "vtk" / "step_0002.vtu");
  const std::string text((std::istreambuf_iterator<char>(vtu)), std::istreambuf_iterator<char>());
  for (const char* part : {"NumberOfPoints=\"181\"", "Name=\"displacement\"",
                           "Name=\"displacement_magnitude\"", "Name=\"area_vector\""})
    EXPECT_NE(text.find(part), std::string::npos) << part;
}

}  // namespace
// Parsing opens no file and builds nothing; building loads, prunes and resolves.
TEST(ExperimentPhases, ReadingOpensNoFileAndBuildingNamesTheField) {
  nlohmann::json c = base_config();
  c["surface"] = {{"file", "no_such_mesh.obj"}};
  Experiment ex = read_experiment(c, "/nonexistent_folder", "doc");
  ASSERT_EQ(ex.simulation().specs.size(), 1u);
  EXPECT_TRUE(ex.simulation().cases.empty());
  EXPECT_EQ(ex.simulation().specs[0].surface.file,
            std::filesystem::path("/nonexistent_folder/no_such_mesh.obj"));
  try {
    build_experiment(ex);
    ADD_FAILURE() << "built a case on a missing mesh";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("doc: surface.file: ", 0), 0u) << e.what();
  }

  // What only the mesh reveals: a list with one entry per axis of a 2D surface.
  c = base_config();
  c["surface"] = {{"generator", "rectangle"}, {"min", {0, 0}}, {"max", {2, 1}}};
  c["supports"][0]["where"] = "y <= 0";
  ex = read_experiment(c, ".", "doc");  // 3 numbers are fine before the surface is known
  try {
    build_experiment(ex);
    ADD_FAILURE() << "a 3D acceleration on a 2D surface";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("doc: loads[0].acceleration: expected a list of 2 "
                                         "numbers"),
              std::string::npos)
        << e.what();
  }
  c["supports"][0]["where"] = "z <= 0";
  c["loads"][0]["acceleration"] = {0, -9.81};
  ex = read_experiment(c, ".", "doc");
  EXPECT_THROW(build_experiment(ex), InputError);  // no z axis in 2D
}

// A program builds a model on its own surface, without a mesh file, and gets
// the very model the file-based experiment builds.
TEST(ExperimentPhases, AProgramGivesTheSurface) {
  const nlohmann::json with_generator = base_config();
  const Experiment from_generator = parse_experiment(with_generator, ".", "doc");

  nlohmann::json without_surface = base_config();
  without_surface.erase("surface");
  Experiment ex = read_experiment(without_surface, ".", "doc");
  const geom::Surface sphere = geom::icosphere(1, 1.0);
  build_experiment(ex, &sphere);
  ASSERT_EQ(ex.simulation().cases.size(), 1u);
  const model::Model& a = from_generator.simulation().cases[0].model;
  const model::Model& b = ex.simulation().cases[0].model;
  EXPECT_EQ(b.surface.V, a.surface.V);
  ASSERT_EQ(b.constraints.size(), a.constraints.size());
  for (size_t k = 0; k < a.constraints.size(); ++k)
    EXPECT_EQ(b.constraints[k].vertex, a.constraints[k].vertex);
  const ExperimentResult ra = run_experiment(from_generator), rb = run_experiment(ex);
  ASSERT_TRUE(ra.runs_succeeded() && rb.runs_succeeded());
  EXPECT_EQ(rb.runs[0].summary.unknowns, ra.runs[0].summary.unknowns);

  // One spec builds on any surface: a concave one is pruned on the way.
  Experiment on_cube = read_experiment(without_surface, ".", "doc");
  geom::Surface dented = geom::icosphere(2, 1.0);
  for (int i = 0; i < dented.num_vertices(); ++i)
    if (dented.V(i, 0) > 0.9) dented.V(i, 0) -= 0.5;  // push a cap inward
  build_experiment(on_cube, &dented);
  EXPECT_FALSE(on_cube.simulation().cases[0].fibers.convex);
  EXPECT_LT(on_cube.simulation().cases[0].fibers.kept, on_cube.simulation().cases[0].fibers.pairs);

  // Neither the document nor the program gives a surface, or both do.
  Experiment nothing = read_experiment(without_surface, ".", "doc");
  try {
    build_experiment(nothing);
    ADD_FAILURE() << "built without a surface";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("doc: surface: missing", 0), 0u) << e.what();
  }
  Experiment both = read_experiment(with_generator, ".", "doc");
  EXPECT_THROW(build_experiment(both, &sphere), InputError);
  // A surface the program gives is checked like a mesh file.
  geom::Surface open = sphere;
  open.F.conservativeResize(open.F.rows() - 1, 3);
  Experiment on_open = read_experiment(without_surface, ".", "doc");
  try {
    build_experiment(on_open, &open);
    ADD_FAILURE() << "built on an open surface";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("the given surface"), std::string::npos) << e.what();
  }
}

}  // namespace fiberfluid::experiment

namespace fiberfluid::experiment {
namespace {

// Issue 59, class 4: MPI ranks compare this digest before they work. It
// covers the bytes of every file the experiment names, not only its text and
// mesh: a rank with another target.obj or force curve would decide a fit.
TEST(ExperimentDigest, CoversEveryFileTheExperimentReads) {
  testing::ScratchDir dir;
  const auto octahedron = [](double x) {
    return "v " + std::to_string(x) +
           " 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n"
           "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";
  };
  dir.write("target.obj", octahedron(1.0));
  dir.write("stress.csv", "test,stretch,nominal_stress_Pa\nuniaxial,1.5,100000\n");
  const auto config = dir.write("fit.json", R"({"name": "digest",
    "surface": {"generator": "icosphere", "subdivisions": 1},
    "material": {"law": {"type": "neo_hookean", "mu": 1000}},
    "supports": [{"where": "z >= 0.9"}],
    "loads": [{"type": "gravity", "acceleration": [0, 0, -9.81], "density": 10}],
    "fit": {"targets": [{"type": "surface", "file": "target.obj"},
                        {"type": "material_test", "file": "stress.csv"}],
            "parameters": [{"name": "mu"}]}})");
  const std::string first = experiment_digest(load_experiment(config));
  EXPECT_EQ(experiment_digest(load_experiment(config)), first);  // the same files: the same
  dir.write("target.obj", octahedron(1.001));                    // the scan, a vertex moved
  const std::string moved = experiment_digest(load_experiment(config));
  EXPECT_NE(moved, first);
  dir.write("stress.csv", "test,stretch,nominal_stress_Pa\nuniaxial,1.5,100001\n");
  EXPECT_NE(experiment_digest(load_experiment(config)), moved);  // a material test's stress
}

}  // namespace
}  // namespace fiberfluid::experiment

namespace fiberfluid::experiment {
namespace {

// Issue 59, class 7: GMRES tangents (reused, krylov) on a poor preconditioner
// stall where the exact tangent runs on. A cantilever of a table stiffening
// 400 times past 1% strain under its weight: the reused tangent no longer
// converges at step 1, its steps halved to the end, where the dense tangent
// runs all 4. Now the exact tangent takes over a piece before its step is
// cut (then hands back); the answer is the dense run's, and the summary says
// which stalled, where and why.
TEST(TangentFallback, AStalledGmresTangentGivesWayToTheExactOne) {
  const double Y = 1e5, r = 400.0;
  const nlohmann::json stress = {-(0.01 + 0.49 * r) * Y, -0.01 * Y, 0.0, 0.01 * Y,
                                 (0.01 + 0.49 * r) * Y};
  nlohmann::json document = {
      {"name", "stiffening_cantilever"},
      {"surface",
       {{"generator", "cylinder"}, {"radius", 0.01}, {"length", 0.1}, {"segments", {6, 16}}}},
      {"material",
       {{"law",
         {{"type", "tabulated"}, {"strain", {-0.5, -0.01, 0, 0.01, 0.5}}, {"stress", stress}}},
        {"gamma", 0}}},
      {"fibers", {{"kinematics", "central"}}},
      {"supports", {{{"where", "x <= 0"}}}},
      {"loads", {{{"type", "gravity"}, {"acceleration", {0, 0, -9.81}}, {"density", 8000}}}},
      {"stepping", {{"scheme", "newton"}, {"steps", 4}}}};
  const auto run = [&](const char* tangent) {
    nlohmann::json d = document;
    d["stepping"]["newton"] = {{"tangent", tangent}};
    return run_experiment(parse_experiment(d, ".", "cantilever.json")).runs.front().summary;
  };
  const solve::SteppingSummary dense = run("dense");
  ASSERT_TRUE(dense.success) << dense.message;
  EXPECT_TRUE(dense.tangent_fallback.empty());
  const solve::SteppingSummary reused = run("reused");
  ASSERT_TRUE(reused.success) << reused.message;
  EXPECT_EQ(reused.tangent, solve::TangentSolver::Reused);
  EXPECT_EQ(reused.tangent_fallback.rfind("the exact dense tangent took ", 0), 0u)
      << reused.tangent_fallback;
  EXPECT_NE(reused.tangent_fallback.find("where the reused one stalled, first at step 1: newton: "),
            std::string::npos)
      << reused.tangent_fallback;
  EXPECT_NE(reused.BriefReport().find(reused.tangent_fallback), std::string::npos);
  EXPECT_LT((reused.unknowns - dense.unknowns).norm(), 1e-7 * dense.unknowns.norm());
}

}  // namespace
}  // namespace fiberfluid::experiment
