// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// The two benchmark scenes of Alterovitz and Goldberg (the benchmarks
// paper, docs: benchmarks.md), built as finite-element systems, with what a
// surface model needs to pose the same problem: the held nodes, the moving
// needle, the gravity.
//
// Choices the paper leaves open (benchmarks.md), as defaults:
//  - the block is a slab in plane strain (a block of tissue, not a sheet);
//  - meshes of 8 x 8 quadrilaterals (block) and 4 x 2 x 2 hexahedra (rod):
//    small enough for a test, refined through the options;
//  - the rod lies along x, clamped at x = 0, gravity along -z.

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "fiberfluid/fem/dynamics.hpp"
#include "fiberfluid/fem/fem.hpp"
#include "fiberfluid/fem/mesh_tools.hpp"

namespace fiberfluid::fem {

// The paper's materials (benchmarks.md): MP1 (soft), MP2 (human prostate),
// MP3 (the rod), each with Rayleigh damping alpha = 1.0, beta = 0.1.
struct MaterialPreset {
  Material material;
  double alpha = 1.0, beta = 0.1;
};
// Throws InputError for a name other than MP1, MP2, MP3.
MaterialPreset material_preset(const std::string& name);

struct Scene {
  std::string name;  // "block-needle" or "bending-rod"
  Mesh mesh;
  Material material;
  Dynamics dynamics;  // matrices, damping, loads, held unknowns and their path
  // The same problem for a surface model:
  std::vector<int> fixed_nodes;  // held in every axis
  int needle = -1;               // the block's needle node
  double needle_travel = 0.0;    // its displacement along -x at the end of the push
  double push_time = 0.0;        // s
  Eigen::VectorXd gravity;       // the rod's acceleration (m/s^2); empty for the block
  // Where each scene's load reaches its final value: the quasi-static path.
  double load_factor(double t) const;
};

// A 1 m x 1 m block, its top, bottom and left sides held, a needle at the
// middle of the right side moving left at `needle_speed` for `push_time`,
// then stopping (a prescribed displacement of that node).
struct BlockOptions {
  Eigen::Vector2i cells{8, 8};  // cells along y must be even: the needle sits on a node
  MaterialPreset material = material_preset("MP1");
  double needle_speed = 0.08;  // m/s
  double push_time = 2.0;      // s
  bool simplices = false;      // triangles instead of quadrilaterals
};
Scene needle_block(const BlockOptions& options);

// A rod of 0.25 m x 0.25 m cross-section, 0.5 m long, clamped at one end,
// under gravity switched on at t = 0 (the damping is the viscous medium).
struct RodOptions {
  Eigen::Vector3i cells{4, 2, 2};  // along the rod, then across it
  MaterialPreset material = material_preset("MP3");
  double gravity = 0.05;   // m/s^2, along -z
  bool simplices = false;  // tetrahedra instead of hexahedra
};
Scene bending_rod(const RodOptions& options);

// The scene's static state under the full load (the late-time limit of its
// dynamics). Throws InputError when the held nodes leave it singular.
Eigen::VectorXd static_state(const Scene& scene);

// The rows of a per-node matrix (#nodes x k) at the boundary's nodes, in its
// vertex order.
Eigen::MatrixXd boundary_rows(const Boundary& b, const Eigen::MatrixXd& node_rows);

// The rod's static displacement on the grid of `options` (a refinement of a
// coarser rod over the same box) at `nodes`, nodes of the coarser grid
// (#nodes x 3): the refined grid keeps them.
Eigen::MatrixXd rod_statics_at(const RodOptions& options, const Eigen::MatrixXd& nodes);

}  // namespace fiberfluid::fem
