// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The accuracy benchmarks of Alterovitz and Goldberg (docs: benchmarks.md)
// as experiments ("kind": "benchmark"): a scene (the block and needle, or
// the bending rod), finite-element solvers run on it and compared with the
// implicit Newmark reference at the same mesh and step, time step by time
// step (E_n, E_s, E_i); optionally the same scene with other materials
// against that reference (the paper's Fig. 11), and the fibers-and-fluid
// model on the scene's surface with the same supports and loads.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fiberfluid/fem/dynamics.hpp"
#include "fiberfluid/fem/scenes.hpp"

namespace fiberfluid::experiment {

struct BenchmarkSpec {
  enum class Scene { BlockNeedle, BendingRod };
  Scene scene = Scene::BlockNeedle;
  fem::BlockOptions block;
  fem::RodOptions rod;
  std::string material_label = "MP1";    // the preset's name, or "custom"
  double step = 1.0 / 30.0;              // s, the paper's h
  double duration = 10.0;                // s
  int metrics_every = 1;                 // compute E_s every k-th step (E_n, E_i every step)
  std::vector<fem::Integrator> solvers;  // against the implicit Newmark reference
  fem::IntegrationOptions linear;        // Cholesky, or the paper's Gauss-Seidel
  // The same scene with another material, each solver against the reference.
  struct OtherMaterial {
    std::string label;
    fem::MaterialPreset material;
    std::vector<fem::Integrator> solvers;
  };
  std::vector<OtherMaterial> other_materials;
  // The fibers-and-fluid model on the scene's boundary (quasi-static).
  struct FiberModel {
    bool enabled = false;
    bool fit = true;  // Y and gamma fitted to the FEM's static shape; else given
    double Y = 0.0, gamma = 0.0;
    int steps = 10;  // load steps of the rod's gravity (the block: one per time step of the push)
    bool newton = false;  // the Newton scheme instead of the paper's incremental one
    // Central fibers (they bend; Newton only) instead of the paper's vector
    // spring, within a horizon (m; 0: every pair), with the rod's clamp as a
    // mirror layer as deep as the horizon.
    bool central = false;
    double horizon = 0.0;
    bool mirror_layer = false;
  };
  FiberModel fiber;
  // The rod's static state again on finer grids, each cell split ratio^k
  // times per axis (k = 1..levels), sampled at this mesh's nodes (a refined
  // grid keeps them): how far the benchmark's mesh is from a converged static
  // shape, with the observed order; the fiber model is then fitted to the
  // finest. levels = 0: none.
  struct StaticReference {
    int levels = 0;
    int ratio = 2;
  };
  StaticReference static_reference;
};

}  // namespace fiberfluid::experiment
