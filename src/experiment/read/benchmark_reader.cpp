// SPDX-License-Identifier: GPL-3.0-or-later
// The benchmark fields of an experiment document ("kind": "benchmark").
#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fiberfluid/experiment/read/json_fields.hpp"
#include "fiberfluid/experiment/read/readers.hpp"

namespace fiberfluid::experiment {
namespace {

using json = nlohmann::json;
using fem::Integrator;

const std::vector<std::pair<std::string, Integrator>>& integrator_names() {
  static const std::vector<std::pair<std::string, Integrator>> names = {
      {"implicit-newmark", Integrator::ImplicitNewmark},
      {"explicit", Integrator::ExplicitConsistent},
      {"explicit-lumped", Integrator::ExplicitLumped},
      {"implicit-lumped", Integrator::ImplicitLumped},
      {"quasi-static", Integrator::QuasiStatic}};
  return names;
}

std::vector<Integrator> read_solvers(Fields& f, const std::string& key, bool with_reference) {
  std::vector<Integrator> out;
  const json& list = f.raw(key);
  std::vector<std::string> allowed;
  for (const auto& [name, kind] : integrator_names())
    if (with_reference || kind != Integrator::ImplicitNewmark) allowed.push_back(name);
  std::string expected;
  for (const std::string& a : allowed) expected += (expected.empty() ? "" : ", ") + a;
  if (!list.is_array() || list.empty())
    f.fail(key, "expected a non-empty list of solvers (" + expected + ")");
  for (const json& item : list) {
    const std::string name = item.is_string() ? item.get<std::string>() : excerpt(item);
    if (std::find(allowed.begin(), allowed.end(), name) == allowed.end())
      f.fail(key, "unknown solver \"" + name + "\" (expected " + expected + ")");
    for (const auto& [known, kind] : integrator_names())
      if (known == name) {
        if (std::find(out.begin(), out.end(), kind) != out.end())
          f.fail(key, "\"" + name + "\" is listed twice");
        out.push_back(kind);
      }
  }
  return out;
}

// "MP1" (a preset) or {"E", "nu", "density", "alpha", "beta"}.
fem::MaterialPreset read_material(Fields& f, const std::string& key, std::string* label) {
  const json* given = f.peek(key);
  if (given == nullptr || given->is_string()) {  // missing: the string's message names the key
    const std::string name = f.string(key);
    if (name != "MP1" && name != "MP2" && name != "MP3")
      f.fail(key,
             "expected a preset (MP1, MP2, MP3) or an object {E, nu, density, alpha, beta}, "
             "got \"" +
                 name + "\"");
    *label = name;
    return fem::material_preset(name);
  }
  Fields m = f.object(key);
  fem::MaterialPreset p;
  p.material.young = m.positive("E", 1.0);
  p.material.poisson = m.number("nu");
  if (!(p.material.poisson > -1.0 && p.material.poisson < 0.5))
    m.fail("nu", "expected a Poisson ratio between -1 and 0.5");
  p.material.density = m.positive("density", 1000.0);
  p.alpha = m.non_negative("alpha", 1.0);
  p.beta = m.non_negative("beta", 0.1);
  m.finish();
  *label = "custom";
  return p;
}

// "mesh": the cells per axis, the elements and (the block) the plane model.
void read_scene_mesh(Fields& root, BenchmarkSpec& spec) {
  const bool block = spec.scene == BenchmarkSpec::Scene::BlockNeedle;
  const int dim = block ? 2 : 3;
  Fields m = root.object("mesh");
  if (m.has("cells")) {
    const Eigen::VectorXd cells = m.vector("cells", dim);
    for (Eigen::Index a = 0; a < dim; ++a)
      if (cells[a] != std::floor(cells[a]) || cells[a] < 1 || cells[a] > 200)
        m.fail("cells", "expected whole numbers of cells from 1 to 200 per axis");
    if (block) {
      spec.block.cells = cells.cast<int>();
      if (spec.block.cells[1] % 2 != 0)
        m.fail("cells",
               "expected an even number of cells along y (the needle sits on the "
               "node in the middle of the right side)");
    } else {
      spec.rod.cells = cells.cast<int>();
    }
  }
  const std::string elements =
      m.choice("elements", block ? "quadrilateral" : "hexahedron",
               block ? std::vector<std::string>{"quadrilateral", "triangle"}
                     : std::vector<std::string>{"hexahedron", "tetrahedron"});
  (block ? spec.block.simplices : spec.rod.simplices) =
      elements == "triangle" || elements == "tetrahedron";
  if (block) {
    spec.block.material.material.plane =
        m.choice("plane", "strain", {"strain", "stress"}) == "stress" ? fem::PlaneModel::Stress
                                                                      : fem::PlaneModel::Strain;
  }
  m.finish();
}

// "static_reference": the rod's static state on finer grids.
void read_static_reference(Fields& root, BenchmarkSpec& spec) {
  Fields r = root.object("static_reference");
  spec.static_reference.levels = r.integer("levels", 3, 1, 5);
  spec.static_reference.ratio = r.integer("ratio", 2, 2, 4);
  r.finish();
  const double finest = std::pow(spec.static_reference.ratio, spec.static_reference.levels);
  const Eigen::Vector3d cells = spec.rod.cells.cast<double>() * finest;
  // A sparse Cholesky of the finest grid: 3 unknowns per node, fill ~ n^(4/3).
  if ((cells.array() + 1.0).prod() > 150000.0)
    root.fail("static_reference",
              "the finest grid (cells x " + std::to_string(static_cast<long long>(finest)) +
                  ") has over 150,000 nodes; give fewer levels or a smaller ratio");
}

// "fiber_model": the fibers-and-fluid model on the scene's surface.
void read_fiber_model(Fields& root, BenchmarkSpec& spec) {
  const bool block = spec.scene == BenchmarkSpec::Scene::BlockNeedle;
  Fields f = root.object("fiber_model");
  spec.fiber.enabled = true;
  spec.fiber.fit = f.boolean("fit", !f.has("Y"));
  if (!spec.fiber.fit) {
    spec.fiber.Y = f.positive("Y", 1.0);
    spec.fiber.gamma = f.non_negative("gamma", 0.0);
  } else if (f.has("Y") || f.has("gamma")) {
    f.fail("fit", "give Y and gamma, or fit them, not both");
  }
  spec.fiber.steps = f.integer("steps", spec.fiber.steps, 1, 10000);
  spec.fiber.central = f.choice("kinematics", "vector", {"vector", "central"}) == "central";
  spec.fiber.newton = f.choice("scheme", spec.fiber.central ? "newton" : "incremental",
                               {"incremental", "newton"}) == "newton";
  if (spec.fiber.central && !spec.fiber.newton)
    f.fail("scheme", "central fibers run with the Newton scheme only");
  if (f.has("horizon")) {
    if (!spec.fiber.central) f.fail("horizon", "only central fibers have a horizon");
    spec.fiber.horizon = f.positive("horizon", 1.0);
  }
  if (f.has("mirror_layer")) {
    if (block) f.fail("mirror_layer", "only the bending-rod scene has a clamp to mirror");
    if (!(spec.fiber.horizon > 0.0))
      f.fail("mirror_layer", "a mirror layer is as deep as the fibers' horizon: set horizon");
  }
  spec.fiber.mirror_layer = spec.fiber.horizon > 0.0 && !block && f.boolean("mirror_layer", true);
  f.finish();
}

}  // namespace

BenchmarkSpec read_benchmark(Fields& root) {
  BenchmarkSpec spec;
  const bool block = root.choice("scene", "", {"block-needle", "bending-rod"}) == "block-needle";
  spec.scene = block ? BenchmarkSpec::Scene::BlockNeedle : BenchmarkSpec::Scene::BendingRod;
  fem::MaterialPreset material = fem::material_preset(block ? "MP1" : "MP3");
  spec.material_label = block ? "MP1" : "MP3";
  if (root.has("material")) material = read_material(root, "material", &spec.material_label);
  (block ? spec.block.material : spec.rod.material) = material;

  if (root.has("mesh")) read_scene_mesh(root, spec);
  if (root.has("needle")) {
    if (!block) root.fail("needle", "only the block-needle scene has a needle");
    Fields n = root.object("needle");
    spec.block.needle_speed = n.positive("speed", spec.block.needle_speed);
    spec.block.push_time = n.positive("push_time", spec.block.push_time);
    n.finish();
  }
  if (root.has("gravity")) {
    if (block) root.fail("gravity", "only the bending-rod scene has gravity");
    spec.rod.gravity = root.positive("gravity", spec.rod.gravity);
  }
  if (root.has("static_reference")) {
    if (block)
      root.fail("static_reference",
                "only the bending-rod scene has a static reference on finer grids");
    read_static_reference(root, spec);
  }
  if (root.has("time")) {
    Fields t = root.object("time");
    spec.step = t.positive("step", spec.step);
    spec.duration = t.positive("duration", spec.duration);
    if (spec.duration / spec.step > 1e6) t.fail("duration", "more than a million steps");
    if (spec.duration < spec.step) t.fail("duration", "shorter than one step");
    t.finish();
  }
  spec.metrics_every = root.integer("metrics_every", 1, 1, 1000000);
  spec.solvers =
      root.has("solvers")
          ? read_solvers(root, "solvers", false)
          : std::vector<Integrator>{Integrator::ExplicitConsistent, Integrator::ExplicitLumped,
                                    Integrator::ImplicitLumped, Integrator::QuasiStatic};
  if (root.has("linear_solver")) {
    Fields l = root.object("linear_solver");
    spec.linear.linear =
        l.choice("method", "cholesky", {"cholesky", "gauss-seidel"}) == "gauss-seidel"
            ? fem::LinearMethod::GaussSeidel
            : fem::LinearMethod::Cholesky;
    spec.linear.tolerance = l.positive("tolerance", spec.linear.tolerance);
    spec.linear.max_sweeps = l.integer("max_sweeps", spec.linear.max_sweeps, 1, 100000000);
    l.finish();
  }
  for (Fields o : root.objects("compare_materials")) {
    BenchmarkSpec::OtherMaterial other;
    std::string preset_label;
    other.material = read_material(o, "material", &preset_label);
    other.label = o.string("label", preset_label);
    if (other.label.empty() || other.label.find(',') != std::string::npos)
      o.fail("label", "expected a name without commas");
    other.solvers = read_solvers(o, "solvers", true);
    if (block) other.material.material.plane = spec.block.material.material.plane;
    o.finish();
    spec.other_materials.push_back(other);
  }
  if (root.has("fiber_model")) read_fiber_model(root, spec);
  return spec;
}

}  // namespace fiberfluid::experiment
