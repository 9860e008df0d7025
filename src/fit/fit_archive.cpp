// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fit/fit_archive.hpp"

#include <stdexcept>

#include "fiberfluid/solve/summary_fields.hpp"
#include "fiberfluid/util/byte_archive.hpp"

namespace fiberfluid::fit {

// The fields of each type, once, for both directions. A field added to one
// of these structs goes here too.
template <class A>
void fields(A& a, IterationRecord& r) {
  a(r.iteration, r.cost, r.accepted, r.trial_cost, r.trial_failure, r.values, r.forward_runs,
    r.seconds);
}
template <class A>
void fields(A& a, FailedRun& f) {
  a(f.values, f.message);
}
template <class A>
void fields(A& a, DistanceStatistics& d) {
  a(d.count, d.mean, d.rms, d.standard_deviation, d.largest, d.length);
}
template <class A>
void fields(A& a, ForceMisfit& m) {
  a(m.simulated, m.rms, m.largest, m.scale, m.weight, m.relative, m.rms_relative, m.scatter, m.runs,
    m.runs_expected, m.runs_z, m.systematic, m.verdict);
}
template <class A>
void fields(A& a, TargetReport& t) {
  a(t.kind, t.label, t.figures, t.columns, t.rows);
}
template <class A>
void fields(A& a, FitResult& r) {
  a(r.status, r.success, r.message, r.status_detail, r.start_note, r.warm_started_runs,
    r.warm_start_note, r.at_bounds, r.unseen, r.method, r.analytic_jacobian, r.names, r.initial,
    r.values, r.covariance_ok, r.standard_errors, r.lower_95, r.upper_95, r.interval_notes,
    r.interval_runs, r.correlation, r.iterations, r.initial_cost, r.final_cost, r.forward_runs,
    r.sensitivity_solves, r.failed_runs, r.failures_by_cause, r.failed_examples, r.seconds,
    r.summary, r.positions, r.vertex_distances, r.statistics, r.overall, r.force_misfits,
    r.other_targets);
}
template <class A>
void fields(A& a, Evaluation& e) {
  a(e.ok, e.message, e.residuals, e.jacobian, e.summary, e.positions, e.forces, e.forward_runs,
    e.sensitivity_solves, e.warm_started_runs);
}

namespace {

template <class T>
std::string pack(const T& value) {
  ByteWriter out;
  out(value);
  return out.take();
}

template <class T>
T unpack(const std::string& bytes, const char* what) {
  T value;
  ByteReader in(bytes);
  in(value);
  if (!in.finished()) throw std::runtime_error(std::string(what) + " has bytes left over");
  return value;
}

}  // namespace

std::string pack_fit_result(const FitResult& result) { return pack(result); }
FitResult unpack_fit_result(const std::string& bytes) {
  return unpack<FitResult>(bytes, "a fit's result");
}
std::string pack_evaluation(const Evaluation& evaluation) { return pack(evaluation); }
Evaluation unpack_evaluation(const std::string& bytes) {
  return unpack<Evaluation>(bytes, "an evaluation");
}

}  // namespace fiberfluid::fit
