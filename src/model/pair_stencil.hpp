// SPDX-License-Identifier: GPL-3.0-or-later
// The fiber stencils: the one place where a fiber's weight, strain, force,
// tangent and parameter derivative are written. Every pair loop (the tiled
// kernels of bulk_pairs.cpp and deformed_pairs.cpp, FiberSystem's rows, Equilibrium's dense
// tangent and dR/dtheta, the stored-coefficient tangent operator, the
// treecode's pruned corrections) calls these; they are scalar and inline so
// that the loops around them vectorise.
//
// How a bulk fiber's force follows its two ends is a policy (the fiber
// kinematics, below): a second kinematics is one new policy struct and one
// case in with_kinematics(), not an edit of every loop.
#pragma once

#include <cmath>
#include <stdexcept>

namespace fiberfluid::model {

// ---- Weights (the reference configuration) --------------------------------

// Bulk fiber weight (paper Eq. 6): a_ij = h_ij (|S_i| + |S_j|) / L_ij, with
// h_ij = 1 / (2 (N-1)), or the pruned connection factor below.
inline double bulk_weight(double h, double area_i, double area_j, double length) {
  return h * (area_i + area_j) / length;
}

// The connection factor of a pair from its ends' connection counts c_i, c_j
// (model.md section 5, PairFactors): h_ij = m_ij / (c_i + c_j), m_ij = 1 for a
// kept fiber and 0 for a pruned one.
inline double connection_factor(double kept, double count_i, double count_j) {
  return kept / (count_i + count_j);
}

// The mean count's factor (ConnectionCount::Mean): with M_i = c_i |S_i| the
// area the fibers at i reach, w_ij = 2 kept |S_i| |S_j| / ((M_i + M_j) L),
// that is h_ij = 2 kept |S_i| |S_j| / ((|S_i| + |S_j|) (M_i + M_j)).
inline double mean_connection_factor(double kept, double area_i, double area_j, double count_i,
                                     double count_j) {
  return 2.0 * kept * area_i * area_j / ((area_i + area_j) * (count_i * area_i + count_j * area_j));
}

// bulk_weight(connection_factor(kept, c_i, c_j), ...) written with one
// division instead of two: the form the tiled kernels use. With `mean`, the
// mean count's weight 2 kept |S_i| |S_j| / ((c_i |S_i| + c_j |S_j|) L)
// (a select, not a branch, so that the loops still vectorise).
inline double counted_bulk_weight(double kept, double area_i, double area_j, double count_i,
                                  double count_j, double length, bool mean = false) {
  const double reached = mean ? count_i * area_i + count_j * area_j : count_i + count_j;
  const double areas = mean ? 2.0 * area_i * area_j : area_i + area_j;
  return kept * areas / (reached * length);
}

// The line measure of a fiber (FiberWeights::Lines). Straight lines through
// a body, rho of them per unit area across them and per steradian, cross a
// surface patch S_i in direction n as rho |n . S_i| per steradian, and the
// patch S_j at distance L in that direction subtends |n . S_j| / L^2
// steradians (the measure of lines joining two patches: Santalo, "Integral
// Geometry and Geometric Probability", 1976, ch. 12; radiosity's form
// factor). A fiber standing for those lines, each a fiber of stress T, pulls
// i by rho |n . S_i| |n . S_j| T / L^2 where a fiber gives a Y(e) e L:
//   a_ij = rho |d . S_i| |d . S_j| / L^5,   d = s_j - s_i.
// Under an affine deformation every line is strained alike by its direction,
// so a vertex's force is the network's stress times its area vector: the
// patch test. rho = 5 / (2 pi) makes that stress the material-level
// response's (material_response.hpp: 5 <T d d>; the mean over the sphere is
// 1/(2 pi) times the integral over the half of it that undirected lines span).
inline constexpr double kLineDensity = 2.5 / 3.14159265358979323846;
// The multiplier m_ij of the weight a_ij = m_ij / L (the counts being the
// areas, PairFactors): rho |d . S_i| |d . S_j| / L^4. A fiber along the
// surface (d . S = 0) stands for no line.
inline double line_measure(double d_dot_si, double d_dot_sj, double length) {
  const double squared = length * length;
  return kLineDensity * std::abs(d_dot_si * d_dot_sj) / (squared * squared);
}

// Surface fiber weight (paper Eq. 7): (|S_i| + |S_k|) / (2 |s_i - s_k|^2).
inline double surface_weight(double area_i, double area_k, double length_squared) {
  return (area_i + area_k) / (2.0 * length_squared);
}

// ---- A pair's state at a deformed configuration ---------------------------

// |(d0, d1, d2)|: a fiber's length from the difference of its ends.
inline double pair_length(double d0, double d1, double d2) {
  return std::sqrt(d0 * d0 + d1 * d1 + d2 * d2);
}

// A fiber's strain from its current and reference lengths: e = r / L - 1.
// Every pair loop takes the strain from here (the secant modulus Y(e), the
// tangent's slope Y'(e), a law parameter's derivative dY/dtheta(e)).
inline double fiber_strain(double current, double length) { return current / length - 1.0; }

// The two coefficients of a pair's force and tangent (see the policies).
struct PairCoefficients {
  double c1, c2;
};

// ---- Fiber kinematics (policies) -------------------------------------------
//
// For a pair (i, j) with reference length L, current length r, weight a, the
// law's secant modulus Y = Y(e), slope Y' = Y'(e), b = x_i - x_j (current) and
// d = u_i - u_j (displacements), a policy gives
//   - along(b_a, d_a): the component of the vector g the force lies along;
//   - coefficients(a, Y, Y', r, L) -> (c1, c2), with which
//       the force on i          f   = c1 g,
//       the tangent on w        T w = c1 (w_i - w_j) + c2 (b . (w_i - w_j)) g,
//       (df_a / dx_i,b = -df_a / dx_j,b = c1 delta_ab + c2 g_a b_b);
//   - parameter_coefficient(a, dY/dtheta, r, L) -> p, with df/dtheta = p g.
// The axis factors multiply each component afterwards (Material).

// The paper's vector spring (model.md section 7): f = a Y(e) (u_i - u_j).
// It resists every relative displacement alike, across the fiber as much as
// along it, so a body of them shears but cannot bend; with Y constant it is
// the paper's linear model exactly.
// (A rest tension has no meaning for it: check_fiber_weights refuses one.)
struct VectorSpring {
  static constexpr const char* name = "vector";
  static double along(double /*b*/, double d) { return d; }
  static PairCoefficients coefficients(double a, double Y, double Yp, double r, double L,
                                       double /*T0*/ = 0.0) {
    return {a * Y, a * Yp / (r * L)};  // d(a Y(e) d)/dx_i = a Y I + a Y' d (de/dx_i)^T
  }
  static double parameter_coefficient(double a, double dY, double /*r*/, double /*L*/,
                                      double /*dT0*/ = 0.0) {
    return a * dY;
  }
};

// A central fiber (a bond of bond-based peridynamics, Silling 2000): the
// force lies along the current fiber and follows its change of length,
//   f = a Y(e) (r - L) b / r,
// so a body of them bends, and a rigid rotation leaves every fiber unstrained
// (zero force). Same weight a as the vector spring: a stretch along a fiber
// gives the same force in both. Its tangent has the material part (Y') and
// the geometric part (the force turning with the fiber):
//   df/dx_i = a Y (1 - L/r) I + a (Y' (r - L) / (r^2 L) + Y L / r^3) b b^T.
// With a rest tension T0 (the law's, times the fiber's own factor) the
// force gains a T0 L b / r, a constant tension along the fiber: c1 gains
// a T0 L / r and c2 loses a T0 L / r^3 (the tension turning with the fiber).
struct CentralFiber {
  static constexpr const char* name = "central";
  static double along(double b, double /*d*/) { return b; }
  static PairCoefficients coefficients(double a, double Y, double Yp, double r, double L,
                                       double T0 = 0.0) {
    const double stretch = 1.0 - L / r;  // (r - L) / r
    const double rest = a * T0 * L / r;
    return {a * Y * stretch + rest,
            a * (Yp * stretch / (r * L) + Y * L / (r * r * r)) - rest / (r * r)};
  }
  static double parameter_coefficient(double a, double dY, double r, double L, double dT0 = 0.0) {
    return a * dY * (1.0 - L / r) + a * dT0 * L / r;
  }
};

// The kinematics a material's bulk fibers use (Material::kinematics).
enum class FiberKinematics {
  VectorSpring,  // "vector": the paper's, the default
  Central,       // "central"
};

inline const char* kinematics_name(FiberKinematics k) {
  switch (k) {
    case FiberKinematics::VectorSpring:
      return VectorSpring::name;
    case FiberKinematics::Central:
      return CentralFiber::name;
  }
  return "?";
}

// Every kinematics, in the order of the enum (for readers and tests).
inline constexpr FiberKinematics kAllKinematics[] = {FiberKinematics::VectorSpring,
                                                     FiberKinematics::Central};

// Calls body(Policy{}) with the policy of `k`: the one switch over the kinematics.
template <class Body>
decltype(auto) with_kinematics(FiberKinematics k, Body&& body) {
  switch (k) {
    case FiberKinematics::VectorSpring:
      return body(VectorSpring{});
    case FiberKinematics::Central:
      return body(CentralFiber{});
  }
  throw std::logic_error("unknown fiber kinematics");
}

// ---- The pair's contributions, for any policy ----------------------------

// The component a of the force on i: c1 g_a.
template <class K>
inline double pair_force(const PairCoefficients& c, double b, double d) {
  return c.c1 * K::along(b, d);
}

// The component a of the tangent applied to v = w_i - w_j, given
// b_dot_v = b . v: c1 v_a + c2 (b . v) g_a.
template <class K>
inline double pair_tangent(const PairCoefficients& c, double v, double b_dot_v, double b,
                           double d) {
  return c.c1 * v + c.c2 * b_dot_v * K::along(b, d);
}

// The entry (a, b) of the 3x3 tangent block df_a/dx_i,b: c1 delta_ab + c2 g_a b_b.
template <class K>
inline double pair_tangent_entry(const PairCoefficients& c, bool same_axis, double b_a, double d_a,
                                 double b_b) {
  return c.c1 * (same_axis ? 1.0 : 0.0) + c.c2 * K::along(b_a, d_a) * b_b;
}

// The component a of df/dtheta for a law parameter theta: p g_a.
template <class K>
inline double pair_parameter_force(double a, double dY, double r, double L, double b, double d,
                                   double dT0 = 0.0) {
  return K::parameter_coefficient(a, dY, r, L, dT0) * K::along(b, d);
}

}  // namespace fiberfluid::model
