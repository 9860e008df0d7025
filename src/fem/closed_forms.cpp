// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fem/closed_forms.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <functional>

#include "fiberfluid/util/error.hpp"

namespace fiberfluid::fem {
namespace {

constexpr double kOnSurface = 1e-9;  // relative to the tube's size

// A point's distance from the z axis (a tube's) or from the origin (a
// sphere's centre), and the unit vector away from it.
enum class Centre { Axis, Point };
Eigen::Vector3d outward(const Eigen::Vector3d& x, Centre centre) {
  return centre == Centre::Axis ? Eigen::Vector3d(x.x(), x.y(), 0.0) : x;
}
bool on_radius(const Mesh& mesh, int v, double radius, Centre centre = Centre::Axis) {
  return std::abs(outward(mesh.nodes.row(v).transpose(), centre).norm() - radius) <=
         kOnSurface * radius;
}

// On the tube's end z = 0 or z = length.
bool on_end(const Mesh& mesh, int v, double length) {
  return mesh.nodes(v, 2) <= kOnSurface * length || mesh.nodes(v, 2) >= (1.0 - kOnSurface) * length;
}

// What an inflation measures: the inner surface's outward reactions summed
// (the pressure times the deformed area), and the outer surface's mean
// deformed radius.
struct Inflated {
  double pushing = 0.0, outer_radius = 0.0;
};
Inflated measure_inflation(const Mesh& mesh, const HyperelasticSolution& solution, double inner,
                           double outer, Centre centre) {
  Inflated out;
  int outer_nodes = 0;
  for (int v = 0; v < mesh.num_nodes(); ++v) {
    const Eigen::Vector3d X = mesh.nodes.row(v).transpose();
    if (on_radius(mesh, v, inner, centre))
      out.pushing += outward(X, centre).normalized().dot(solution.forces.segment<3>(3 * v));
    if (on_radius(mesh, v, outer, centre)) {
      out.outer_radius += outward(X + solution.u.segment<3>(3 * v), centre).norm();
      ++outer_nodes;
    }
  }
  out.outer_radius /= outer_nodes;
  return out;
}

// Each node's prescribed displacement (where `held` says so, per axis) at
// load factor s, as a load path of `steps` steps with no forces.
using Prescribed = std::function<Eigen::Vector3d(const Eigen::Vector3d& rest, double s)>;
using HeldAxes = std::function<Eigen::Vector3i(int node)>;

HyperelasticSolution solve_prescribed(const Mesh& mesh, const HyperelasticMaterial& material,
                                      const HeldAxes& held, const Prescribed& motion,
                                      const HyperelasticOptions& options,
                                      const std::string& problem) {
  const int steps = options.steps;
  const LoadPath path = [&](int step) {
    LoadState state;
    state.forces = Eigen::VectorXd::Zero(mesh.num_dofs());
    const double s = static_cast<double>(step) / steps;
    for (int v = 0; v < mesh.num_nodes(); ++v) {
      const Eigen::Vector3i axes = held(v);
      if (axes.sum() == 0) continue;
      const Eigen::Vector3d u = motion(mesh.nodes.row(v).transpose(), s);
      for (int a = 0; a < 3; ++a)
        if (axes[a]) state.held.hold(3 * v + a, u[a]);
    }
    return state;
  };
  HyperelasticSolution solution;
  const linalg::Status status = solve_hyperelastic(mesh, material, path, options, &solution);
  if (!status.ok) throw InputError(problem + ": " + status.message);
  return solution;
}

ClosedFormRun run_of(const Mesh& mesh, const HyperelasticSolution& solution) {
  ClosedFormRun run;
  run.nodes = mesh.num_nodes();
  run.elements = static_cast<int>(mesh.elements.rows());
  run.newton_iterations = solution.newton_iterations;
  return run;
}

}  // namespace

ClosedFormRun tube_torsion(const TubeMeshSpec& tube, const HyperelasticMaterial& material,
                           double twist, const HyperelasticOptions& options) {
  const Mesh mesh = tube_mesh(tube);
  const double A = tube.inner_radius, B = tube.outer_radius, L = tube.length;
  const HeldAxes held = [&](int v) -> Eigen::Vector3i {
    return on_end(mesh, v, L) || on_radius(mesh, v, A) ? Eigen::Vector3i::Ones()
                                                       : Eigen::Vector3i::Zero();
  };
  const Prescribed torsion = [&](const Eigen::Vector3d& X, double s) -> Eigen::Vector3d {
    return Eigen::AngleAxisd(s * twist * X.z(), Eigen::Vector3d::UnitZ()) * X - X;
  };
  const HyperelasticSolution solution =
      solve_prescribed(mesh, material, held, torsion, options, "torsion");
  // The reactions on the top end: the internal forces of its held nodes.
  const Eigen::VectorXd& f = solution.forces;
  double torque = 0.0, axial = 0.0;
  for (int v = 0; v < mesh.num_nodes(); ++v) {
    if (mesh.nodes(v, 2) < (1.0 - kOnSurface) * L) continue;
    const Eigen::Vector3d x = mesh.nodes.row(v).transpose() + solution.u.segment<3>(3 * v);
    torque += x.x() * f[3 * v + 1] - x.y() * f[3 * v];
    axial += f[3 * v + 2];
  }
  const double mu = material.shear_modulus(), b4a4 = std::pow(B, 4) - std::pow(A, 4);
  ClosedFormRun run = run_of(mesh, solution);
  run.figures = {
      {"torque", torque, M_PI / 2.0 * mu * twist * b4a4},
      {"axial_force", axial, -M_PI / 4.0 * mu * twist * twist * std::pow(B * B - A * A, 2)}};
  return run;
}

ClosedFormRun tube_inflation(const TubeMeshSpec& tube, const HyperelasticMaterial& material,
                             double inner_stretch, const HyperelasticOptions& options) {
  const Mesh mesh = tube_mesh(tube);
  const double A = tube.inner_radius, B = tube.outer_radius, L = tube.length;
  const double a = inner_stretch * A;
  const HeldAxes held = [&](int v) -> Eigen::Vector3i {
    const int inner = on_radius(mesh, v, A) ? 1 : 0;
    return {inner, inner, on_end(mesh, v, L) ? 1 : 0};
  };
  const Prescribed push = [&](const Eigen::Vector3d& X, double s) -> Eigen::Vector3d {
    return {s * (inner_stretch - 1.0) * X.x(), s * (inner_stretch - 1.0) * X.y(), 0.0};
  };
  const HyperelasticSolution solution =
      solve_prescribed(mesh, material, held, push, options, "inflation");
  // The pressure: the inner surface's outward reactions over its deformed
  // area; the outer radius: the mean over the outer surface's nodes.
  const Inflated inflated = measure_inflation(mesh, solution, A, B, Centre::Axis);
  const double b = std::sqrt(B * B + a * a - A * A), mu = material.shear_modulus();
  ClosedFormRun run = run_of(mesh, solution);
  run.figures = {
      {"pressure", inflated.pushing / (2.0 * M_PI * a * L),
       mu * (std::log(a * B / (A * b)) + 0.5 * (a * a - A * A) * (1.0 / (a * a) - 1.0 / (b * b)))},
      {"outer_radius", inflated.outer_radius, b}};
  return run;
}

ClosedFormRun sphere_inflation(const ShellMeshSpec& shell, const HyperelasticMaterial& material,
                               double inner_stretch, const HyperelasticOptions& options) {
  const Mesh mesh = shell_octant_mesh(shell);
  const double A = shell.inner_radius, B = shell.outer_radius, a = inner_stretch * A;
  // The symmetry planes hold their normal displacement; the inner surface
  // is pushed out along its radii.
  const HeldAxes held = [&](int v) -> Eigen::Vector3i {
    if (on_radius(mesh, v, A, Centre::Point)) return Eigen::Vector3i::Ones();
    Eigen::Vector3i axes;
    for (int k = 0; k < 3; ++k) axes[k] = std::abs(mesh.nodes(v, k)) <= kOnSurface * B ? 1 : 0;
    return axes;
  };
  const Prescribed push = [&](const Eigen::Vector3d& X, double s) -> Eigen::Vector3d {
    return s * (inner_stretch - 1.0) * X;
  };
  const HyperelasticSolution solution =
      solve_prescribed(mesh, material, held, push, options, "sphere inflation");
  const Inflated inflated = measure_inflation(mesh, solution, A, B, Centre::Point);
  const double b = std::cbrt(B * B * B + a * a * a - A * A * A), mu = material.shear_modulus();
  const double la = a / A, lb = b / B;
  ClosedFormRun run = run_of(mesh, solution);
  run.figures = {{"pressure", inflated.pushing / (M_PI * a * a / 2.0),  // an octant's 4 pi a^2
                  mu * (2.0 / lb + 0.5 / std::pow(lb, 4) - 2.0 / la - 0.5 / std::pow(la, 4))},
                 {"outer_radius", inflated.outer_radius, b}};
  return run;
}

}  // namespace fiberfluid::fem
