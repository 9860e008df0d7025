// SPDX-License-Identifier: GPL-3.0-or-later
// "type": "marker": a tracked marker's measured displacement at a load step
// (a fiducial bead or an ink dot on the tissue, followed by a camera or a
// tracker), fitted as w (u_i(step) - u_measured) in m over the axes, u_i
// the displacement of the model vertex at the marker. Its Jacobian is the
// vertex's row of the Newton sensitivities du/dtheta (central differences of
// whole runs where the scheme has none), as the scan distances use it.
#include <Eigen/Core>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "fiberfluid/experiment/read/json_fields.hpp"
#include "fiberfluid/experiment/read/readers.hpp"
#include "fiberfluid/experiment/targets/target_kinds.hpp"
#include "fiberfluid/fit/residuals/residual_block.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::experiment {
namespace {

// What the file says of the marker.
struct MarkerSpec {
  std::string label;                  // the target's "label", or "marker K"
  int input_vertex = -1;              // "vertex": an input vertex index
  std::optional<Eigen::Vector3d> at;  // "at": the marker's rest position (m), its nearest vertex
  int step = 0;                       // the load step it was measured at; 0: the last
  Eigen::Vector3d displacement = Eigen::Vector3d::Zero();  // m
  double weight = 1.0;  // the rows' weight (1: a misfit in m, as a distance)
};

class MarkerDisplacement : public fit::ResidualBlock {
 public:
  MarkerDisplacement(MarkerSpec spec, int vertex, int step, size_t index)
      : spec_(std::move(spec)), vertex_(vertex), step_(step), index_(index) {}

  int rows() const override { return 3; }
  std::vector<int> steps() const override { return {step_}; }

  std::string evaluate(const fit::ForwardRun& run, const std::map<int, fit::StepReadings>&,
                       Eigen::Index row, fit::Evaluation& e) const override {
    const Eigen::VectorXd& x = run.states.at(step_);
    const Eigen::MatrixXd U = model::displacements(run.model, x);
    const Eigen::Vector3d u = U.row(vertex_).transpose();
    e.residuals.segment<3>(row) = spec_.weight * (u - spec_.displacement);
    if (!run.with_jacobian) return "";
    const auto S = run.sensitivities.find(step_);
    if (S != run.sensitivities.end())
      e.jacobian.middleRows<3>(row) += spec_.weight * run.vertex_sensitivity(S->second, vertex_);
    return "";
  }

  void describe(const fit::Evaluation& e, Eigen::Index row, fit::FitResult& result) const override {
    const Eigen::Vector3d misfit = e.residuals.segment<3>(row) / spec_.weight;
    fit::TargetReport report;
    report.kind = "marker";
    report.label = spec_.label;
    report.figures = {{"vertex", static_cast<double>(vertex_)},
                      {"step", static_cast<double>(step_)},
                      {"misfit", misfit.norm()},
                      {"measured", spec_.displacement.norm()}};
    for (int a = 0; a < 3; ++a) {
      const std::string axis(1, "xyz"[a]);
      report.figures["misfit_" + axis] = misfit[a];
      report.figures["simulated_" + axis] = misfit[a] + spec_.displacement[a];
    }
    (void)index_;
    result.other_targets.push_back(std::move(report));
  }

 private:
  MarkerSpec spec_;
  int vertex_, step_;
  size_t index_;
};

// The model vertex the marker sits on: the input vertex's, or the vertex
// nearest its rest position.
int marker_vertex(const MarkerSpec& spec, const Case& c, const FieldName& field) {
  if (spec.at) {
    Eigen::Index nearest = 0;
    (c.model.surface.V.rowwise() - spec.at->transpose()).rowwise().squaredNorm().minCoeff(&nearest);
    return static_cast<int>(nearest);
  }
  for (size_t k = 0; k < c.model_to_input.size(); ++k)
    if (c.model_to_input[k] == spec.input_vertex) return static_cast<int>(k);
  field.fail("vertex", "input vertex " + std::to_string(spec.input_vertex) +
                           " is not a vertex of the body (the mesh has " +
                           std::to_string(c.input_surface.num_vertices()) +
                           " vertices; one in no face is not modelled)");
}

}  // namespace

FitKindTargetSpec read_marker_target(Fields& t, const std::filesystem::path&) {
  MarkerSpec m;
  const FieldName field = t.field();
  // The fields every marker has first, so that the schema's explorer reads
  // them all (it follows the reader until its first refusal).
  const double scale = length_units(t, "units");
  m.displacement = t.vector("displacement", 3) * scale;
  m.step = t.integer("step", 0, 1, 100000);
  m.weight = t.positive("weight", 1.0);
  m.label = t.string("label", "marker");
  if (t.has("vertex") == t.has("at"))
    t.fail("vertex",
           "expected the marker's \"vertex\" (an input vertex index) or its rest "
           "position \"at\": one of them");
  if (t.has("vertex")) m.input_vertex = t.integer("vertex", 0, 0, std::numeric_limits<int>::max());
  if (t.has("at")) m.at = Eigen::Vector3d(t.vector("at", 3) * scale);
  t.finish();
  FitKindTargetSpec spec;
  spec.field = field;
  spec.kind = "marker";
  spec.bind = [m, field](const Case& c, size_t index) -> fit::BlockMaker {
    const int vertex = marker_vertex(m, c, field);
    const int steps = c.stepping.steps;
    if (m.step > steps)
      field.fail("step", "step " + std::to_string(m.step) + " of a run of " +
                             std::to_string(steps) + " load steps");
    const int step = m.step == 0 ? steps : m.step;
    return [m, vertex, step, index](const fit::BlockContext&) {
      return std::make_unique<MarkerDisplacement>(m, vertex, step, index);
    };
  };
  return spec;
}

}  // namespace fiberfluid::experiment
