// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/model/fiber_system.hpp"
#include "fiberfluid/model/model.hpp"
#include "fiberfluid/model/pair_kernels.hpp"
#include "fiberfluid/solve/linear_solver.hpp"
#include "fiberfluid/util/names.hpp"
#include "fiberfluid/util/status.hpp"

namespace fiberfluid::solve {

enum class Scheme {
  // The paper's (model.md section 6): at step k,
  //   A(x_{k-1}) dx_k = B(x_{k-1}, f_k) - B(x_{k-1}, f_{k-1}),
  // a forward-Euler walk along the load path.
  Incremental,
  // Equilibrium R(x; lambda_k) = 0 at every step (model.md section 7), with
  // rigid paddles in contact as an active set.
  Newton,
};
inline constexpr auto kSchemeNames =
    names_of<Scheme>({{Scheme::Incremental, "incremental"}, {Scheme::Newton, "newton"}});
inline const char* to_string(Scheme scheme) { return kSchemeNames.name(scheme); }

// How each Newton step's linear system with the tangent is solved.
enum class TangentSolver {
  Auto,    // dense up to 600 unknowns (about 200 vertices), then krylov for the vector
           // spring; for central fibers up to 50,000 unknowns: within a horizon stored
           // as lists sparse up to 4,000 then reused, else reused; above, krylov
  Dense,   // LU of the dense tangent (LAPACK) at every iteration
  Krylov,  // matrix-free GMRES, preconditioned by the structured secant solve
  Sparse,  // LU of the sparse tangent (UMFPACK): N times the neighbours entries
  Reused,  // GMRES on the exact tangent, preconditioned by the LU of an earlier one
           // (dense; sparse for a horizon's lists), reused across iterations and steps
           // while GMRES needs few iterations
};
inline constexpr auto kTangentSolverNames =
    names_of<TangentSolver>({{TangentSolver::Auto, "auto"},
                             {TangentSolver::Dense, "dense"},
                             {TangentSolver::Krylov, "krylov"},
                             {TangentSolver::Sparse, "sparse"},
                             {TangentSolver::Reused, "reused"}});
inline const char* to_string(TangentSolver solver) { return kTangentSolverNames.name(solver); }
// choose_tangent (what Auto means for a run) is in solve/tangent/tangent_solve.hpp.

struct NewtonOptions {
  // Converged when the relative residual (force rows over the largest of the
  // loads and reactions seen, the volume row over dim C0 V0) is at most
  // residual_tolerance; or when it has stalled at rounding level (at most
  // 1000 times that) while the last correction moved no coordinate by more
  // than increment_tolerance times the body's bounding-box diagonal.
  double residual_tolerance = 1e-10;
  double increment_tolerance = 1e-12;
  int max_iterations = 25;  // per load step (or cut piece of one)
  int max_step_cuts = 6;    // halvings of a failing step before giving up
  bool line_search = true;  // backtracking on the residual norm
  TangentSolver tangent = TangentSolver::Auto;
  // GMRES stops at a relative residual of max(krylov_tolerance, min(0.1,
  // max(0.1 r, 0.5 residual_tolerance / r))) for a Newton residual r (inexact
  // Newton: quadratic, and no sharper than the tolerance needs).
  double krylov_tolerance = 1e-10;
  int krylov_restart = 50;
  int krylov_max_iterations = 500;
  int max_contact_rounds = 30;  // active-set updates per step
  // Coulomb paddles: the active set is settled when no friction force changed
  // by more than this share of the largest friction bound between solutions
  // (1e-4: the cylinder's rolled-over ring settles in 3-5 rounds a step).
  double friction_tolerance = 1e-4;
  // Start each step from the solution extrapolated along the load path
  // (quadratic in the last three converged points) rather than from the last
  // solution: fewer iterations on a smooth path.
  bool predictor = true;
  // How the load path is followed: by the load (each step's load factor is
  // set, as the paper steps) or by arc length (Crisfield's cylindrical
  // constraint on the displacements: the load factor is an unknown, so the
  // path is traced through a limit point where the load peaks).
  enum class Control { Load, ArcLength } control = Control::Load;
  int max_arc_steps = 200;  // arc length: steps before giving up on reaching the final load

  bool IsValid(std::string* why) const;
};
inline constexpr auto kControlNames = names_of<NewtonOptions::Control>(
    {{NewtonOptions::Control::Load, "load"}, {NewtonOptions::Control::ArcLength, "arc_length"}});

struct SteppingOptions {
  Scheme scheme = Scheme::Incremental;
  NewtonOptions newton;
  int steps = 1;                     // number of load steps n
  bool rebuild_matrix = false;       // rebuild A (lengths, area vectors) from x_{k-1} each step
  bool update_load_geometry = true;  // loads from x_{k-1} (the paper) or from the reference
  model::BoundaryMethod boundary_method = model::BoundaryMethod::Elimination;
  double penalty = 1e9;                  // the paper's diagonal value, for BoundaryMethod::Penalty
  SolverKind solver = SolverKind::Auto;  // the linear backend; Auto: automatic_solver()
  PcgOptions pcg;                        // for SolverKind::PCG
  // Runaway guards: a step that changes the enclosed volume by more than this
  // fraction of the reference volume, or turns a face over, ends the run.
  double max_volume_change = 0.5;
  bool stop_on_inverted_faces = true;
  // Incremental: measure each step's equilibrium residual (StepRecord::residual),
  // one O(N^2) pass over the fibers per step.
  bool measure_residual = true;
  // Newton: keep the tangent solve prepared at the solution in the summary
  // (final_tangent), for sensitivities. It holds O(N^2) memory.
  bool keep_final_tangent = false;
  // Newton: the sensitivities du/dtheta of the solution to material
  // parameters (named as for model::Equilibrium::parameter_derivatives) at
  // chosen steps, each one solve with the step's last tangent (calibration).
  struct Sensitivities {
    std::vector<std::string> parameters;
    std::vector<int> steps;  // 1..steps
  } sensitivities;
  // Newton: unknowns [u.. P] near the solution at the path's end, from a
  // nearby problem already solved (a fit's previous trial point). The final
  // load point is solved from them in one piece, and the summary holds that
  // step alone (SteppingSummary::warm_started); where the piece fails, the
  // path is walked from the unloaded start as usual. Only where the end of
  // the path does not depend on the way there: load control, no sticking
  // paddle (check_warm_start). Empty: walk the path.
  Eigen::VectorXd warm_start;

  bool IsValid(std::string* why) const;
};

// A field added to StepRecord or SteppingSummary (other than a live object)
// goes into solve/summary_fields.hpp's lists too: it is how a run made on
// another MPI rank comes back.
// The derivatives of a step's state and forces by the parameters that
// SteppingOptions::sensitivities names (Newton only), one column per
// parameter: what a fit's Jacobian is made of.
struct StepSensitivities {
  Eigen::MatrixXd state;  // du/dtheta, full layout (zero at held unknowns)
  // Per paddle (Model::paddles): d force / d theta, 3 x parameters.
  std::vector<Eigen::MatrixXd> paddle_forces;
  // Per support group: d reaction / d theta (3 x parameters; NaN for a group
  // with a mirror layer, whose fibers' share is not differentiated).
  std::vector<Eigen::MatrixXd> reactions;
};

struct StepRecord {
  int step = 0;                      // 1..n
  std::vector<double> load_factors;  // one per load, after this step
  double pressure = 0.0;             // P after this step
  double volume = 0.0;               // enclosed volume (area in 2D) after this step
  double max_displacement = 0.0;     // max_i |u_i|
  // How far the state reached is from equilibrium: the relative |R| of
  // model.md section 7 (Equilibrium::relative_norm). Newton drives it below
  // its tolerance; the incremental scheme leaves what its linearisation
  // misses (with SteppingOptions::measure_residual).
  double residual = 0.0;
  double seconds = 0.0;  // wall time of this step
  // Force that each constraint group (Model::constraint_groups) exerts on the
  // body, and the sum of the external loads; they sum to zero at equilibrium.
  std::vector<Eigen::Vector3d> reactions;
  Eigen::Vector3d applied_force = Eigen::Vector3d::Zero();
  // The force on each vertex a support or a paddle holds (the reactions and
  // paddle forces above, vertex by vertex; a clamp's mirror layer's fibers
  // are not in it). Only held vertices are listed.
  struct HeldForce {
    int vertex = -1;  // model index
    int paddle = -1;  // the paddle (Model::paddles) in contact; -1: a support
    Eigen::Vector3d force = Eigen::Vector3d::Zero();
  };
  std::vector<HeldForce> held_forces;

  // Newton scheme only.
  int newton_iterations = 0;           // over the step's pieces
  std::vector<double> residual_norms;  // relative, at every iteration (before its correction)
  int line_search_halvings = 0;
  int krylov_iterations = 0;
  model::PairPasses pair_passes;  // over every fiber pair, in the step (its solves, its checks)
  int step_cuts = 0;              // halvings of this step
  int pieces = 0;                 // the converged pieces it was walked in (1: uncut)
  double volume_drift = 0.0;      // (V - V0) / V0 after the step
  // Paddles: the active-set rounds of the step (over its pieces), and the
  // vertices that joined and left the contact set in them.
  int contact_rounds = 0, contacts_added = 0, contacts_released = 0;
  // Coulomb paddles: the vertices that changed between sticking and sliding
  // at the rounds' solutions.
  int friction_updates = 0;
  struct PaddleState {
    double plane = 0.0;                               // the plane's coordinate
    double travel = 0.0;                              // how far it has moved
    Eigen::Vector3d force = Eigen::Vector3d::Zero();  // on the body
    int contacts = 0;                                 // vertices held on it
    int sliding = 0;                                  // of them, sliding (Coulomb)
  };
  std::vector<PaddleState> paddles;  // one per Model::paddles
  // What a fit asks of the step (SteppingOptions::sensitivities): empty
  // except at the steps it lists.
  StepSensitivities sensitivities;
};

struct SteppingSummary {
  bool success = false;
  std::string message;  // why it failed, or "" on success
  std::vector<StepRecord> steps;
  Eigen::VectorXd unknowns;         // final [u_x.. u_y.. (u_z..) P]
  Eigen::MatrixXd reaction_forces;  // #V by dim: the support force on each vertex at the end
  Scheme scheme = Scheme::Incremental;
  SolverKind solver = SolverKind::Auto;  // the backend that ran (newton: the preconditioner's)
  TangentSolver tangent = TangentSolver::Auto;  // newton: how the tangent was solved
  // Newton: "" or, when the tangent chosen stalled on pieces of steps that
  // the exact one then solved, how many, and where and why it first stalled.
  std::string tangent_fallback;
  int newton_iterations = 0;  // newton: over all steps
  // Newton: the final step was solved from SteppingOptions::warm_start alone
  // (steps holds step n only); false when there was none or it failed and
  // the path was walked.
  bool warm_started = false;
  // Arc length: the largest load reached before the path turned back, as a
  // share of the final load (the limit load), or NaN when it never turned.
  double limit_load_factor = std::numeric_limits<double>::quiet_NaN();
  int krylov_iterations = 0;  // newton with krylov: over all solves
  // The bordered system the backend factored last (reduced, boundary
  // conditions applied): what was actually solved.
  std::shared_ptr<const model::FiberSystem> system;
  // Incremental: the backend holding that system's factorisation, ready to
  // solve more right-hand sides with it (the matrix of the last step).
  std::shared_ptr<LinearSolver> factorization;
  // Newton with keep_final_tangent: solves with dR/dx at the solution
  // (du/dtheta = -final_tangent->solve_full(dR/dtheta)); refers to the model.
  std::shared_ptr<class TangentSolve> final_tangent;
  SolverStatistics solver_statistics;
  int factorizations = 0;
  // Newton's reused dense tangent LU: the factorisations whose factors were
  // rounded to single precision for GMRES's preconditioner solves.
  int single_precision_factorizations = 0;
  double assemble_seconds = 0.0;
  double factorize_seconds = 0.0;
  double solve_seconds = 0.0;
  double total_seconds = 0.0;

  std::string BriefReport() const;
};

// Called after each step with its record and the unknowns reached.
using StepObserver = std::function<void(const StepRecord&, const Eigen::VectorXd&)>;

// Runs the load steps. Expected numerical failures (a singular setup, a
// singular matrix, a runaway: non-finite values, a face turned over, a volume
// change beyond max_volume_change) come back as success = false with a
// message naming the step and the cause.
SteppingSummary solve_load_steps(const model::Model& model, const SteppingOptions& options,
                                 const StepObserver& observer = {});

// Whether the model's treecode product (Model::treecode_tolerance) can run
// with these options, else why not: it approximates the incremental scheme's
// linear product, needs the constant law and the matrix-free pcg solver.
// solve_load_steps checks it, so every entry point (JSON, C++, Python) gets
// the same message.
Status check_treecode(const model::Model& model, const SteppingOptions& options);

// Whether the material's fiber kinematics can run with these options, else
// why not: every kinematics but the paper's vector spring needs the Newton
// scheme (the incremental scheme's matrix is the vector spring's).
Status check_kinematics(const model::Model& model, const SteppingOptions& options);

// Whether the model's support terms (mirror layers, model::MirrorLayer, and
// split edges, model::HeldEdge) can run with these options, else why not:
// they need the Newton scheme.
Status check_support_terms(const model::Model& model, const SteppingOptions& options);

// Whether the model's fiber weights can run with these options, else why
// not: the line measure (model::FiberWeights::Lines) is 3D, weighs each pair
// differently (no treecode), has no mirror layer, and is a reference measure
// (no matrix rebuilt from the deformed geometry); a law with a rest tension
// (model::FiberLaw::rest_tension) needs central fibers, the Newton scheme and
// the line measure, which balances it at rest.
Status check_fiber_weights(const model::Model& model, const SteppingOptions& options);

// The backend SolverKind::Auto runs: pcg with the treecode, else
// choose_solver's rule by size (the largest axis block, the distinct factors).
SolverKind automatic_solver(const model::Model& model, double largest_block, int factors,
                            double budget_bytes);

// The paper's scheme (what solve_load_steps runs for Scheme::Incremental).
// The Newton scheme's own entry point and checks: solve/newton/newton.hpp.
SteppingSummary solve_incremental_steps(const model::Model& model, const SteppingOptions& options,
                                        const StepObserver& observer = {});

}  // namespace fiberfluid::solve
