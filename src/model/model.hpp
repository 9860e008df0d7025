// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "fiberfluid/geom/fiber_mask.hpp"
#include "fiberfluid/geom/surface.hpp"
#include "fiberfluid/model/fiber_law.hpp"
#include "fiberfluid/model/pair_stencil.hpp"
#include "fiberfluid/util/names.hpp"

namespace fiberfluid::model {

// A material parameter resolved from its name once (Material::resolve), so
// that loops over pairs or fit evaluations never compare strings.
struct MaterialParameter {
  enum class Kind {
    Law,             // the law's parameter `index` ("Y", "Y0", "beta", ...)
    SurfaceTension,  // "gamma"
    AxisFactor,      // "factor_x", "factor_y", "factor_z": axis `index`
    Friction,        // "friction": the Coulomb coefficient against paddles
  };
  Kind kind = Kind::Law;
  int index = 0;
};

// The material: the bulk fibers' law Y(e) (force per area, Pa), the paper's
// per-axis moduli as multipliers of the law (the x block uses
// axis_factors.x() Y(e), and so on), and a constant surface tension on mesh
// edges. The paper's linear model is the constant law.
struct Material {
  FiberLaw law = FiberLaw::constant(1.0);
  Eigen::Vector3d axis_factors = Eigen::Vector3d::Ones();
  double surface_tension = 0.0;  // gamma, force per length (N/m)
  // The Coulomb coefficient between the body's surface and the paddles whose
  // contact is "coulomb": a sliding vertex feels friction * its normal force.
  double friction = 0.0;
  // How a bulk fiber's force follows its ends (pair_stencil.hpp).
  FiberKinematics kinematics = FiberKinematics::VectorSpring;

  // The small-strain modulus per axis, axis_factors Y(0): what the linear model uses.
  Eigen::Vector3d young_modulus() const { return law.modulus(0.0) * axis_factors; }
  // The paper's linear material: one Y per axis (as the constant law 1 and
  // the moduli as factors, so that Y_a is exact) or one Y for all.
  static Material linear(const Eigen::Vector3d& Y, double gamma = 0.0) {
    return {FiberLaw::constant(1.0), Y, gamma};
  }
  static Material linear(double Y, double gamma = 0.0) {
    return {FiberLaw::constant(Y), Eigen::Vector3d::Ones(), gamma};
  }

  // The parameters by name, the one list every front end and the fitter use:
  // the law's, "gamma", then "factor_x" ... (one per axis of a dim-D model),
  // then "friction".
  std::vector<std::string> parameter_names(int dim = 3) const;
  // Throws std::invalid_argument for a name not in parameter_names(dim),
  // listing them.
  MaterialParameter resolve(const std::string& name, int dim = 3) const;
  bool has_parameter(const std::string& name, int dim = 3) const;
  double parameter(const MaterialParameter& p) const;
  double parameter(const std::string& name) const { return parameter(resolve(name)); }
  void set_parameter(const MaterialParameter& p, double value);
  void set_parameter(const std::string& name, double value) { set_parameter(resolve(name), value); }
  // Whether the parameter is positive by nature (a modulus, gamma, a
  // factor), so that a fit may vary it in log scale; false for an exponent
  // and for friction (0, frictionless, is one of its values).
  bool is_positive_parameter(const std::string& name) const;
};

// How a load or a prescribed displacement grows over the load steps: the
// factor f(k) multiplying its full value after step k of n (f(0) = 0).
struct Schedule {
  enum class Kind {
    Ramp,    // k / n
    Final,   // 0 until the last step, then 1 (the sphere's point force)
    UpDown,  // up to 1 at step n/2, back to 0 at step n (load then unload)
    Table,   // values[k - 1], one per step
  };
  Kind kind = Kind::Ramp;
  std::vector<double> values;  // Table only

  double factor(int step, int steps) const;
};
// The schedules named in an experiment file (a table is given as a list).
inline constexpr auto kScheduleNames =
    names_of<Schedule::Kind>({{Schedule::Kind::Ramp, "ramp"},
                              {Schedule::Kind::Final, "final"},
                              {Schedule::Kind::UpDown, "up_down"}});

struct Load {
  enum class Kind {
    Point,        // a force on one vertex
    Hydrostatic,  // rho a h_i S_i: the fluid's weight under an acceleration
  };
  Kind kind = Kind::Point;
  std::string label;
  int vertex = -1;                                         // Point: the vertex (model index)
  Eigen::Vector3d force = Eigen::Vector3d::Zero();         // Point: force at full load (N)
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();  // Hydrostatic, at full load (m/s^2)
  double density = 0.0;                                    // Hydrostatic: fluid density (kg/m^3)
  // Hydrostatic: how the pressure becomes vertex forces (loads.hpp).
  enum class Integration {
    Vertex,  // the paper's q_i S_i: sums to 3 C0 times the weight, near but not exactly it
    Exact,   // q linear over each face against the linear shape functions: exactly rho a V
  };
  Integration integration = Integration::Vertex;
  Schedule schedule;
};
inline constexpr auto kIntegrationNames = names_of<Load::Integration>(
    {{Load::Integration::Vertex, "vertex"}, {Load::Integration::Exact, "exact"}});

// One degree of freedom held at a displacement (0 for a support).
struct Constraint {
  int vertex = -1;     // model index
  int axis = 0;        // 0, 1, 2 = x, y, z
  double value = 0.0;  // displacement at full load
  Schedule schedule;   // how the displacement is reached
  int group = 0;       // index into Model::constraint_groups: whose reaction this adds to
  // Index into Model::motions: the vertex follows that rigid motion (its
  // component `axis`) and `value` is unused; -1: the value above.
  int motion = -1;
};

// A rigid motion of a prescribed group: a rotation by `angle` (radians)
// about `axis` (a unit vector; z in 2D) through `centre`, and a translation,
// both reached along the group's schedule: at factor f the vertex at s is at
// R(f angle) (s - centre) + centre + f translation.
struct RigidMotion {
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  double angle = 0.0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Vector3d displacement(const Eigen::Vector3d& s, double factor) const;
};

// A rigid paddle (the paper's liver validation): a plane normal to a
// coordinate axis, on one side of the body, moving along the axis. Contact is
// an active set in the Newton scheme (model.md section 7).
struct Paddle {
  std::string label;
  int axis = 2;           // 0, 1, 2 = x, y, z: the plane's normal
  bool above = true;      // on the high side of the body (it keeps x_axis <= plane), or below
  double position = 0.0;  // the plane's coordinate before the first step (m)
  double travel = 0.0;    // its displacement along the axis at full schedule (m)
  Schedule schedule;
  enum class Contact {
    Frictionless,  // the normal component of a vertex in contact held
    Sticking,      // every component held where the vertex touched
    Coulomb,       // held where it touched while |tangential force| <= friction * normal force,
                   // else sliding against friction * normal force (Material::friction)
  };
  Contact contact = Contact::Frictionless;
  bool sticking() const { return contact == Contact::Sticking; }
  bool coulomb() const { return contact == Contact::Coulomb; }
  // Whether the contact can depend on the way there (where a vertex stuck).
  bool holds_where_touched() const { return contact != Contact::Frictionless; }

  double plane(double factor) const { return position + factor * travel; }
  // How far a coordinate is past the plane (> 0: penetrating).
  double penetration(double coordinate, double plane_position) const {
    return above ? coordinate - plane_position : plane_position - coordinate;
  }
};

// How the bulk fibers are normalised once some are pruned: the paper divides
// by N-1, "the number of effective connections" for a concave body.
enum class ConnectionCount {
  Symmetric,  // (n_i + n_j) / 2 for the pair, n_i = kept fibers at i (default)
  Global,     // one count for all pairs: the mean of n_i (the paper's reading)
  // The area the fibers at i reach, in units of i's own: c_i = sum_j kept_ij
  // omega(L_ij) |S_j| / |S_i|. On a uniform mesh it is n_i; on any mesh the
  // force on i becomes |S_i| times the area-weighted mean of Y e over what
  // its fibers reach, so that the response converges as the mesh is refined
  // (the default for central fibers: model.md).
  Area,
  // The area count's c_i, mixed by the plain mean of the reached areas
  // M_i = c_i |S_i|: w_ij = 2 kept omega |S_i| |S_j| / ((M_i + M_j) L). The
  // area count mixes M_i and M_j weighted by the ends' areas, so a vertex
  // whose neighbours are larger than it (the octahedron's poles) reads its
  // neighbours' reach and dips below its rings (model.md, "A sphere under
  // gravity"); the mean does not.
  Mean,
};
inline constexpr auto kConnectionCountNames =
    names_of<ConnectionCount>({{ConnectionCount::Symmetric, "symmetric"},
                               {ConnectionCount::Global, "global"},
                               {ConnectionCount::Area, "area"},
                               {ConnectionCount::Mean, "mean"}});
inline const char* to_string(ConnectionCount count) { return kConnectionCountNames.name(count); }
// Whether a count weighs the fibers by the areas they reach (Area, Mean).
inline bool counts_by_area(ConnectionCount count) {
  return count == ConnectionCount::Area || count == ConnectionCount::Mean;
}

// What a bulk fiber's weight stands for.
enum class FiberWeights {
  // The paper's Eq. 6: a_ij = h_ij (|S_i| + |S_j|) / L_ij, h_ij from the
  // connection count (the default; the paper's figures need it).
  Paper,
  // The line measure (pair_stencil.hpp, line_measure): a fiber stands for the
  // straight lines through the body that cross the surface at its two ends'
  // patches, so that a homogeneous deformation of any body is an equilibrium
  // whose stress is the fiber network's material-level response
  // (material_response.hpp): the body of fibers is a material (issue 57's
  // patch test). Counts, and an influence, do not enter it.
  Lines,
};
inline constexpr auto kFiberWeightsNames =
    names_of<FiberWeights>({{FiberWeights::Paper, "paper"}, {FiberWeights::Lines, "lines"}});
inline const char* to_string(FiberWeights weights) { return kFiberWeightsNames.name(weights); }

// How a bulk fiber's weight falls off with its reference length L within the
// horizon delta: the influence function of peridynamics (Seleson and Parks
// 2011, "On the role of the influence function in the peridynamic theory").
// Constant (1: every fiber alike, the paper's) or conical (1 - L / delta).
struct Influence {
  enum class Kind { Constant, Conical };
  Kind kind = Kind::Constant;
  double horizon = 0.0;  // delta (m), for Conical
  bool weighs() const { return kind == Kind::Conical; }
  double operator()(double length) const {
    return kind == Kind::Constant ? 1.0 : std::max(0.0, 1.0 - length / horizon);
  }
};

// A clamped support's mirror layer (Prudhomme and Diehl 2020, "On the
// treatment of boundary conditions for bond-based peridynamic models"): a
// fiber body held on a plane misses the fibers that would reach across it, so
// it hinges at the clamp. The layer restores them as fibers from each vertex
// i to the odd reflection of each vertex j through the plane, at
// 2 q_j - x_j (q_j the foot of j's reference position on the plane): the
// displacement field extended as an odd function, zero on the plane.
struct MirrorLayer {
  int group = 0;  // the support group (Model::constraint_groups) whose reaction it adds to
  Eigen::Vector3d point = Eigen::Vector3d::Zero();    // on the clamp plane
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();  // unit, into the body
  double depth = 0.0;  // the horizon: only pairs with |s_i - mirror(s_j)| < depth are fibers
  // The vertices the group holds on the plane: a layer acts only across the
  // part of the plane they hold (mirror_layer.hpp).
  std::vector<int> held;
};

// A held group whose edge is split (supports[].edge: "split", held_edge.hpp):
// its edge vertices' free share of area moves with the free side.
struct HeldEdge {
  int group = 0;
  std::vector<int> held;  // the vertices the group holds in every axis
};

// Everything the equations need: the reference surface (every vertex used by
// a face), the material, the loads and the constraints.
struct Model {
  geom::Surface surface;
  Material material;
  std::vector<Load> loads;
  std::vector<Constraint> constraints;
  std::vector<Paddle> paddles;
  std::vector<RigidMotion> motions;        // of prescribed groups (Constraint::motion)
  std::vector<MirrorLayer> mirror_layers;  // of clamped supports (Newton scheme)
  std::vector<HeldEdge> held_edges;        // of supports whose edge is split (Newton scheme)
  // Names of the support and prescribed groups (one per experiment entry), for
  // reporting the reaction force of each; constraints refer to them by index.
  std::vector<std::string> constraint_groups;
  // The bulk fibers that exist: null means every pair (a convex body).
  std::shared_ptr<const geom::FiberMask> fibers;
  Influence influence;  // each fiber's weight by its reference length
  FiberWeights fiber_weights = FiberWeights::Paper;
  ConnectionCount connection_count = ConnectionCount::Symmetric;
  // Above 0: the linear bulk product and diagonal come from a treecode with
  // this relative error (bulk_treecode.hpp) instead of the exact pair sums.
  // It needs one connection count for every fiber and a constant law.
  double treecode_tolerance = 0.0;

  int dim() const { return surface.dim; }
  int num_vertices() const { return surface.num_vertices(); }
  // Unknowns of the paper's layout: all x displacements, all y, (all z), P.
  int num_unknowns() const { return dim() * num_vertices() + 1; }
  int dof(int vertex, int axis) const { return axis * num_vertices() + vertex; }
  int pressure_dof() const { return dim() * num_vertices(); }
  // Whether a paddle has Coulomb contact (Material::friction acts).
  bool has_coulomb_paddle() const {
    for (const Paddle& paddle : paddles)
      if (paddle.coulomb()) return true;
    return false;
  }
};

}  // namespace fiberfluid::model
