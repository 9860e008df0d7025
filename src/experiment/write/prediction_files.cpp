// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/write/prediction_files.hpp"

#include <algorithm>
#include <cmath>

#include "fiberfluid/experiment/write/summary_json.hpp"

namespace fiberfluid::experiment {
namespace {

using json = nlohmann::json;

json band_json(const Band& b) {
  return {{"value", finite_or_null(b.value)},
          {"sd", finite_or_null(b.sd)},
          {"lower95", finite_or_null(b.lower95())},
          {"upper95", finite_or_null(b.upper95())}};
}

}  // namespace

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
      p["sd_of_fitted_variable"] = finite_or_null(std::sqrt(estimate.covariance(b, b)));
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

}  // namespace fiberfluid::experiment
