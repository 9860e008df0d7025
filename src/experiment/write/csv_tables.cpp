// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/write/csv_tables.hpp"

#include <iomanip>
#include <map>
#include <set>
#include <sstream>
#include <utility>

#include "fiberfluid/experiment/run/runner.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/report_names.hpp"

namespace fiberfluid::experiment {
namespace {

using model::axis_name;
using model::constraint_group_name;

// A CSV field: quoted when it holds a comma, a quote or a line break.
std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string out = "\"";
  for (char ch : text) out += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return out + "\"";
}

std::string number_text(double value) {
  std::ostringstream out;
  out << std::setprecision(17) << value;
  return out.str();
}

// Rows of cells joined by commas, numbers with 17 significant digits. Given a
// prediction's bands (one map per data row, by column name), every column
// they name is followed by COLUMN_lower95 and COLUMN_upper95 ("nan" in a row
// without that band).
class CsvTable {
 public:
  CsvTable() = default;
  explicit CsvTable(const RunBands& bands) : bands_(&bands) {
    for (const std::map<std::string, Band>& row : bands.steps)
      for (const auto& [name, band] : row) banded_.insert(name);
  }

  void header(const std::string& name) {
    cells_.push_back(csv_field(name));
    const bool banded = banded_.count(name) > 0;
    columns_.push_back(banded ? name : std::string());
    if (!banded) return;
    cells_.push_back(csv_field(name + "_lower95"));
    cells_.push_back(csv_field(name + "_upper95"));
  }
  void text(const std::string& value) { add(csv_field(value)); }
  void number(double value) { add(number_text(value)); }
  void end_row() {
    for (size_t k = 0; k < cells_.size(); ++k) out_ << (k ? "," : "") << cells_[k];
    out_ << "\n";
    cells_.clear();
    column_ = 0;
    ++row_;
  }
  std::string str() const { return out_.str(); }

 private:
  // A data cell, and after it its row's band when its column has one.
  void add(std::string cell) {
    cells_.push_back(std::move(cell));
    const size_t column = column_++;
    if (column >= columns_.size() || columns_[column].empty()) return;
    Band band;
    if (row_ >= 1 && row_ - 1 < bands_->steps.size()) {
      const std::map<std::string, Band>& row = bands_->steps[row_ - 1];
      if (const auto found = row.find(columns_[column]); found != row.end()) band = found->second;
    }
    cells_.push_back(number_text(band.lower95()));
    cells_.push_back(number_text(band.upper95()));
  }

  const RunBands* bands_ = nullptr;
  std::set<std::string> banded_;      // every column name a step's bands hold
  std::vector<std::string> columns_;  // the header's names, empty where unbanded
  size_t column_ = 0, row_ = 0;       // the row's next data column; rows so far
  std::vector<std::string> cells_;
  std::ostringstream out_;
};

}  // namespace

// Per paddle: its travel and the force on the body along its axis (all
// components and the contact count when `full`).
void paddle_headers(CsvTable& t, const model::Paddle& p, int dim, bool full) {
  t.header("paddle_" + p.label + "_travel_m");
  if (full) {
    t.header("paddle_" + p.label + "_plane_m");
    for (int a = 0; a < dim; ++a) t.header("paddle_" + p.label + "_force_" + axis_name(a) + "_N");
    t.header("paddle_" + p.label + "_contacts");
  } else {
    t.header("paddle_" + p.label + "_force_N");
  }
}

void paddle_numbers(CsvTable& t, const model::Model& m, const solve::StepRecord& r, int dim,
                    bool full) {
  for (size_t p = 0; p < m.paddles.size(); ++p) {
    const solve::StepRecord::PaddleState s =
        p < r.paddles.size() ? r.paddles[p] : solve::StepRecord::PaddleState{};
    t.number(s.travel);
    if (full) {
      t.number(s.plane);
      for (int a = 0; a < dim; ++a) t.number(s.force[a]);
      t.number(s.contacts);
    } else {
      t.number(s.force[m.paddles[p].axis]);
    }
  }
}

std::string steps_csv(const Case& c, const RunResult& run) {
  const model::Model& m = c.model;
  const int dim = m.dim();
  const size_t groups = std::max<size_t>(1, m.constraint_groups.size());
  CsvTable t(run.bands);
  t.header("step");
  for (const model::Load& load : m.loads) t.header("load_factor_" + load.label);
  t.header("pressure_Pa");
  t.header(dim == 3 ? "volume_m3" : "area_m2");
  t.header("max_displacement_m");
  for (int a = 0; a < dim; ++a) t.header(std::string("applied_force_") + axis_name(a) + "_N");
  for (size_t g = 0; g < groups; ++g)
    for (int a = 0; a < dim; ++a)
      t.header("reaction_" + constraint_group_name(m, g) + "_" + axis_name(a) + "_N");
  for (const model::Paddle& p : m.paddles) paddle_headers(t, p, dim, true);
  const bool newton = run.summary.scheme == solve::Scheme::Newton;
  if (newton)
    for (const char* h : {"newton_iterations", "line_search_halvings", "krylov_iterations",
                          "step_cuts", "volume_drift"})
      t.header(h);
  t.header("equilibrium_residual");
  t.header("seconds");
  t.end_row();
  for (const solve::StepRecord& r : run.summary.steps) {
    t.number(r.step);
    for (double f : r.load_factors) t.number(f);
    t.number(r.pressure);
    t.number(r.volume);
    t.number(r.max_displacement);
    for (int a = 0; a < dim; ++a) t.number(r.applied_force[a]);
    for (size_t g = 0; g < groups; ++g)
      for (int a = 0; a < dim; ++a) t.number(g < r.reactions.size() ? r.reactions[g][a] : 0.0);
    paddle_numbers(t, m, r, dim, true);
    if (newton) {
      t.number(r.newton_iterations);
      t.number(r.line_search_halvings);
      t.number(r.krylov_iterations);
      t.number(r.step_cuts);
      t.number(r.volume_drift);
    }
    t.number(r.residual);
    t.number(r.seconds);
    t.end_row();
  }
  return t.str();
}

std::string load_displacement_csv(const Case& c, const RunResult& run) {
  const model::Model& m = c.model;
  const int dim = m.dim();
  CsvTable t;
  t.header("step");
  for (const model::Load& load : m.loads) t.header("load_factor_" + load.label);
  for (const model::Paddle& p : m.paddles) paddle_headers(t, p, dim, false);
  t.header("max_displacement_m");
  t.header("pressure_Pa");
  t.header(dim == 3 ? "volume_m3" : "area_m2");
  t.end_row();
  for (const solve::StepRecord& r : run.summary.steps) {
    t.number(r.step);
    for (double f : r.load_factors) t.number(f);
    paddle_numbers(t, m, r, dim, false);
    t.number(r.max_displacement);
    t.number(r.pressure);
    t.number(r.volume);
    t.end_row();
  }
  return t.str();
}

std::string vertices_csv(const Case& c, const RunResult& run) {
  const int dim = c.input_surface.dim;
  const Eigen::MatrixXd& S = c.input_surface.V;
  const Eigen::MatrixXd U = input_positions(c, run.summary.unknowns) - S;
  Eigen::MatrixXd reactions = Eigen::MatrixXd::Zero(S.rows(), dim);
  if (run.summary.reaction_forces.rows() == c.model.num_vertices())
    for (size_t m = 0; m < c.model_to_input.size(); ++m)
      reactions.row(c.model_to_input[m]) =
          run.summary.reaction_forces.row(static_cast<Eigen::Index>(m));
  CsvTable t;
  t.header("vertex");
  for (int a = 0; a < dim; ++a) t.header(std::string(1, axis_name(a)) + "_m");
  for (int a = 0; a < dim; ++a) t.header(std::string("u") + axis_name(a) + "_m");
  t.header("u_magnitude_m");
  for (int a = 0; a < dim; ++a) t.header(std::string("reaction_") + axis_name(a) + "_N");
  t.end_row();
  for (Eigen::Index i = 0; i < S.rows(); ++i) {
    t.number(static_cast<double>(i));
    for (int a = 0; a < dim; ++a) t.number(S(i, a));
    for (int a = 0; a < dim; ++a) t.number(U(i, a));
    t.number(U.row(i).norm());
    for (int a = 0; a < dim; ++a) t.number(reactions(i, a));
    t.end_row();
  }
  return t.str();
}

std::string comparison_csv(const Experiment& ex, const ExperimentResult& result) {
  const char* figures[] = {"max_displacement", "final_pressure", "final_volume",
                           "volume_change_relative"};
  const char* headers[] = {"max_displacement_m", "final_pressure_Pa", "final_volume_m3",
                           "volume_change_relative"};
  CsvTable t;
  t.header("variant");
  t.header("success");
  t.header("steps");
  for (const char* h : headers) t.header(h);
  // Reactions at the end, per group of the first case (variants may differ).
  const model::Model& first = ex.simulation().cases.front().model;
  const size_t groups = first.constraint_groups.size();
  for (size_t g = 0; g < groups; ++g)
    for (int a = 0; a < first.dim(); ++a)
      t.header("reaction_" + constraint_group_name(first, g) + "_" + axis_name(a) + "_N");
  // Paddles at the end (those of the first case, by label): force along the axis, contacts.
  for (const model::Paddle& p : first.paddles) {
    t.header("paddle_" + p.label + "_force_N");
    t.header("paddle_" + p.label + "_contacts");
  }
  t.header("seconds");
  t.header("rank");  // the MPI rank that ran it (0 in a one-process run)
  t.header("message");
  t.header("patch");
  t.end_row();
  for (size_t r = 0; r < result.runs.size(); ++r) {
    const RunResult& run = result.runs[r];
    const solve::SteppingSummary& s = run.summary;
    t.text(run.variant);
    t.text(s.success ? "true" : "false");
    t.number(static_cast<double>(s.steps.size()));
    for (const char* f : figures) {  // as the runner computed them; none for a failed run
      const auto value = result.figures.find(run.variant + "." + f);
      if (value != result.figures.end())
        t.number(value->second);
      else
        t.text("");
    }
    const bool same_groups =
        ex.simulation().cases[r].model.constraint_groups == first.constraint_groups;
    for (size_t g = 0; g < groups; ++g)
      for (int a = 0; a < first.dim(); ++a) {
        if (s.success && same_groups && !s.steps.empty())
          t.number(s.steps.back().reactions[g][a]);
        else
          t.text("");
      }
    for (const model::Paddle& p : first.paddles)
      for (const std::string what : {"paddle_force.", "paddle_contacts."}) {
        const auto value = result.figures.find(run.variant + "." + what + p.label);
        if (value != result.figures.end())
          t.number(value->second);
        else
          t.text("");
      }
    t.number(s.total_seconds);
    t.number(run.rank);
    t.text(s.message);
    t.text(ex.simulation().cases[r].patch.is_null() ? "" : ex.simulation().cases[r].patch.dump());
    t.end_row();
  }
  return t.str();
}

}  // namespace fiberfluid::experiment
