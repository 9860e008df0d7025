// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/write/prediction_files.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "fiberfluid/experiment/write/file_names.hpp"
#include "fiberfluid/geom/mesh_io.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::experiment {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

// The cells of one CSV line (quoted cells as csv_tables writes them).
std::vector<std::string> split_cells(const std::string& line) {
  std::vector<std::string> cells(1);
  bool quoted = false;
  for (size_t k = 0; k < line.size(); ++k) {
    const char ch = line[k];
    if (quoted && ch == '"' && k + 1 < line.size() && line[k + 1] == '"') {
      cells.back() += "\"\"";
      ++k;
    } else if (ch == '"') {
      quoted = !quoted;
      cells.back() += ch;
    } else if (ch == ',' && !quoted) {
      cells.emplace_back();
    } else {
      cells.back() += ch;
    }
  }
  return cells;
}

std::string unquoted(const std::string& cell) {
  if (cell.size() < 2 || cell.front() != '"') return cell;
  std::string out;
  for (size_t k = 1; k + 1 < cell.size(); ++k) {
    out += cell[k];
    if (cell[k] == '"') ++k;  // "" inside a quoted cell
  }
  return out;
}

std::string quoted(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string out = "\"";
  for (char ch : text) out += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return out + "\"";
}

std::string number_text(double x) {
  std::ostringstream out;
  out << std::setprecision(17) << x;
  return out.str();
}

json number(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

json band_json(const Band& b) {
  return {{"value", number(b.value)},
          {"sd", number(b.sd)},
          {"lower95", number(b.lower95())},
          {"upper95", number(b.upper95())}};
}

}  // namespace

std::string with_band_columns(const std::string& steps_csv, const RunBands& bands) {
  std::istringstream in(steps_csv);
  std::string line;
  std::vector<std::vector<std::string>> rows;
  while (std::getline(in, line)) rows.push_back(split_cells(line));
  if (rows.empty()) return steps_csv;
  const std::vector<std::string> header = rows.front();
  std::vector<bool> banded(header.size(), false);
  for (size_t c = 0; c < header.size(); ++c)
    for (const std::map<std::string, Band>& step : bands.steps)
      if (step.count(unquoted(header[c]))) banded[c] = true;
  std::ostringstream out;
  for (size_t r = 0; r < rows.size(); ++r) {
    const std::map<std::string, Band>* step =
        r >= 1 && r - 1 < bands.steps.size() ? &bands.steps[r - 1] : nullptr;
    std::vector<std::string> cells;
    for (size_t c = 0; c < rows[r].size(); ++c) {
      cells.push_back(rows[r][c]);
      if (c >= header.size() || !banded[c]) continue;
      const std::string name = unquoted(header[c]);
      if (r == 0) {
        cells.push_back(quoted(name + "_lower95"));
        cells.push_back(quoted(name + "_upper95"));
        continue;
      }
      Band b;
      if (step)
        if (const auto found = step->find(name); found != step->end()) b = found->second;
      cells.push_back(number_text(b.lower95()));
      cells.push_back(number_text(b.upper95()));
    }
    for (size_t c = 0; c < cells.size(); ++c) out << (c ? "," : "") << cells[c];
    out << "\n";
  }
  return out.str();
}

json prediction_json(const Experiment& experiment, const FittedEstimate& estimate,
                     const std::vector<RunBands>& bands) {
  json parameters = json::array();
  for (size_t k = 0; k < estimate.names.size(); ++k) {
    const auto at = std::find(estimate.banded.begin(), estimate.banded.end(), estimate.names[k]);
    json p = {{"name", estimate.names[k]},
              {"value", estimate.values[static_cast<Eigen::Index>(k)]},
              {"banded", at != estimate.banded.end()}};
    if (at != estimate.banded.end()) {
      const auto b = static_cast<Eigen::Index>(at - estimate.banded.begin());
      p["sd_of_fitted_variable"] = number(std::sqrt(estimate.covariance(b, b)));
      p["fitted_variable"] = estimate.banded_log_scale[static_cast<size_t>(b)]
                                 ? "log of the parameter"
                                 : "the parameter";
    }
    parameters.push_back(p);
  }
  json runs = json::array();
  for (size_t r = 0; r < bands.size(); ++r) {
    json figures = json::object();
    for (const auto& [name, band] : bands[r].figures) figures[name] = band_json(band);
    runs.push_back({{"variant", experiment.simulation().cases[r].variant}, {"figures", figures}});
  }
  return {{"fit", estimate.source.string()},
          {"fit_experiment", estimate.experiment},
          {"fit_status", estimate.status},
          {"parameters", parameters},
          {"held", estimate.held},
          {"bands_are",
           "95%, first order: the fit's covariance carried through the run's Newton "
           "sensitivities (var f = g^T C g, g = df/dphi, phi the fitted variables); value +- "
           "1.96 sd. They hold the parameters' uncertainty, not the model's own error"},
          {"runs", runs}};
}

void write_prediction(const fs::path& folder, const Experiment& experiment,
                      const FittedEstimate& estimate, const std::vector<RunBands>& bands) {
  const Simulation& simulation = experiment.simulation();
  for (size_t r = 0; r < bands.size() && r < simulation.cases.size(); ++r) {
    const std::string& variant = simulation.cases[r].variant;
    const fs::path steps = (variant.empty() ? folder : folder / variant) / output_files::kSteps;
    std::ifstream in(steps);
    if (!in) throw InputError(steps.string() + ": not written: cannot add the bands");
    std::stringstream text;
    text << in.rdbuf();
    in.close();
    geom::write_text_file(steps, with_band_columns(text.str(), bands[r]));
  }
  const fs::path summary = folder / output_files::kSummary;
  std::ifstream in(summary);
  json doc = json::parse(in);
  in.close();
  doc["prediction"] = prediction_json(experiment, estimate, bands);
  geom::write_text_file(summary, doc.dump(2) + "\n");
}

}  // namespace fiberfluid::experiment
