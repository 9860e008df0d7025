// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// The fields of a run's records, once, for util/byte_archive.hpp (both
// directions): how a run made on another MPI rank comes back. A field added
// to StepRecord or SteppingSummary (other than a live object: the factored
// system, the final tangent, which stay where they were made) goes here too.

#include "fiberfluid/solve/stepping.hpp"

namespace fiberfluid::model {
template <class A>
void fields(A& a, PairPasses& p) {
  a(p.computed, p.stored);
}
}  // namespace fiberfluid::model

namespace fiberfluid::solve {
template <class A>
void fields(A& a, StepRecord::HeldForce& h) {
  a(h.vertex, h.paddle, h.force);
}
template <class A>
void fields(A& a, StepRecord::PaddleState& p) {
  a(p.plane, p.travel, p.force, p.contacts, p.sliding);
}
template <class A>
void fields(A& a, StepSensitivities& s) {
  a(s.state, s.paddle_forces, s.reactions);
}
template <class A>
void fields(A& a, StepRecord& r) {
  a(r.step, r.load_factors, r.pressure, r.volume, r.max_displacement, r.residual, r.seconds,
    r.reactions, r.applied_force, r.held_forces, r.newton_iterations, r.residual_norms,
    r.line_search_halvings, r.krylov_iterations, r.pair_passes, r.step_cuts, r.pieces,
    r.volume_drift, r.contact_rounds, r.contacts_added, r.contacts_released, r.friction_updates,
    r.paddles, r.sensitivities);
}
template <class A>
void fields(A& a, SolverStatistics& s) {
  a(s.factorization_flops, s.factorization_kernel_seconds, s.iterations, s.solves);
}
template <class A>
void fields(A& a, SteppingSummary& s) {
  a(s.success, s.message, s.steps, s.unknowns, s.reaction_forces, s.scheme, s.solver, s.tangent,
    s.newton_iterations, s.warm_started, s.limit_load_factor, s.krylov_iterations,
    s.solver_statistics, s.factorizations, s.single_precision_factorizations, s.assemble_seconds,
    s.factorize_seconds, s.solve_seconds, s.total_seconds);
}
}  // namespace fiberfluid::solve
