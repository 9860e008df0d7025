// SPDX-License-Identifier: GPL-3.0-or-later
// "type": "material_test": a measured material test (nominal stress against
// stretch in uniaxial, equibiaxial or pure-shear tension: Treloar's rubber,
// a coupon's tensile test), fitted as w (P - P_measured) / P_measured at each
// loaded point, P the body's fiber law's network stress at material level
// (model/material_response.hpp), with no body. Fitted beside a body's
// targets it holds the law to the material while the body holds it to the
// shape and the force; its Jacobian is the law's, by central differences
// (fit::material_misfits), in the law's parameters alone (gamma and the
// alignment do not move a material test).
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "fiberfluid/experiment/read/json_fields.hpp"
#include "fiberfluid/experiment/read/readers.hpp"
#include "fiberfluid/experiment/targets/target_kinds.hpp"
#include "fiberfluid/fit/material_fit.hpp"
#include "fiberfluid/fit/residuals/residual_block.hpp"
#include "fiberfluid/material/material_test.hpp"

namespace fiberfluid::experiment {
namespace {

std::string csv_number(double x) {
  std::ostringstream out;
  out.precision(12);
  out << x;
  return out.str();
}

struct MaterialTestSpec {
  std::string label;  // the target's "label", or the file's name
  std::filesystem::path file;
  double weight = 1.0;
};

// A row per point: `points` are the file's loaded ones (material::loaded_points).
class MaterialTestMisfits : public fit::ResidualBlock {
 public:
  MaterialTestMisfits(MaterialTestSpec spec, std::vector<material::TestPoint> points)
      : spec_(std::move(spec)),
        points_(std::move(points)),
        rows_(static_cast<int>(points_.size())) {}

  int rows() const override { return rows_; }
  std::vector<int> steps() const override { return {}; }  // no body state

  std::string evaluate(const fit::ForwardRun& run, const std::map<int, fit::StepReadings>&,
                       Eigen::Index row, fit::Evaluation& e) const override {
    const model::FiberLaw& law = run.model.material.law;
    const fit::MaterialModel model = fit::material_model(law);
    Eigen::VectorXd misfits;
    Eigen::MatrixXd by_law;
    const Eigen::VectorXd p = Eigen::Map<const Eigen::VectorXd>(
        law.parameters().data(), static_cast<Eigen::Index>(law.parameters().size()));
    const std::string why =
        fit::material_misfits(model, p, points_, &misfits, run.with_jacobian ? &by_law : nullptr);
    if (!why.empty()) return "the material test " + spec_.label + ": " + why;
    e.residuals.segment(row, rows_) = spec_.weight * misfits;
    if (!run.with_jacobian) return "";
    const std::vector<fit::Parameter>& fitted = run.map.parameters();
    const std::vector<std::string>& names = law.parameter_names();
    for (size_t j = 0; j < fitted.size(); ++j) {
      const auto it = std::find(names.begin(), names.end(), fitted[j].name);
      if (it == names.end()) continue;  // gamma, an axis factor, the alignment
      const Eigen::Index k = it - names.begin();
      e.jacobian.block(row, static_cast<Eigen::Index>(j), rows_, 1) =
          spec_.weight * run.dvalue[static_cast<Eigen::Index>(j)] * by_law.col(k);
    }
    return "";
  }

  void describe(const fit::Evaluation& e, Eigen::Index row, fit::FitResult& result) const override {
    const Eigen::VectorXd misfits = e.residuals.segment(row, rows_) / spec_.weight;
    fit::TargetReport report;
    report.kind = "material_test";
    report.label = spec_.label;
    report.figures = {{"points", static_cast<double>(rows_)},
                      {"rms_relative_misfit", std::sqrt(misfits.squaredNorm() / rows_)},
                      {"largest_relative_misfit", misfits.cwiseAbs().maxCoeff()}};
    // Per test kind held, its own rms (Treloar's uniaxial and equibiaxial),
    // and the points with the law's stress beside them (fit_other_K.csv).
    std::map<std::string, std::pair<double, int>> by_test;
    report.columns = {"test", "stretch", "measured_Pa", "fitted_Pa", "relative_misfit"};
    for (Eigen::Index r = 0; r < rows_; ++r) {
      const material::TestPoint& point = points_[static_cast<size_t>(r)];
      auto& [sum, count] = by_test[material::to_string(point.test)];
      sum += misfits[r] * misfits[r], ++count;
      report.rows.push_back({material::to_string(point.test), csv_number(point.stretch),
                             csv_number(point.nominal_stress),
                             csv_number(point.nominal_stress * (1.0 + misfits[r])),
                             csv_number(misfits[r])});
    }
    for (const auto& [test, sum_count] : by_test)
      report.figures["rms_relative_misfit_" + test] = std::sqrt(sum_count.first / sum_count.second);
    result.other_targets.push_back(std::move(report));
  }

 private:
  MaterialTestSpec spec_;
  std::vector<material::TestPoint> points_;
  int rows_ = 0;
};

}  // namespace

FitKindTargetSpec read_material_test_target(Fields& t, const std::filesystem::path& folder) {
  MaterialTestSpec m;
  const FieldName field = t.field();
  m.file = folder / t.string("file");
  t.resolve("file", absolute_path(m.file));  // absolute, as every file a reader reads
  m.weight = t.positive("weight", 1.0);
  m.label = t.string("label", m.file.filename().string());
  t.finish();
  FitKindTargetSpec spec;
  spec.field = field;
  spec.kind = "material_test";
  spec.bind = [m, field](const Case&, size_t) -> fit::BlockMaker {
    std::vector<material::TestPoint> points;
    try {
      points = material::loaded_points(material::read_material_test(m.file.string()));
    } catch (const InputError& e) {
      field.fail("file", e.what());
    }
    if (points.empty())
      field.fail("file", m.file.string() + " holds no loaded point (every stress is 0)");
    return [m, points](const fit::BlockContext&) {
      return std::make_unique<MaterialTestMisfits>(m, points);
    };
  };
  return spec;
}

}  // namespace fiberfluid::experiment
