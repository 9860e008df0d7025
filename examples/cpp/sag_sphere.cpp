// SPDX-License-Identifier: GPL-3.0-or-later
// Uses fiberfluid as a library: a soft sphere hanging from its cap, with the
// experiment built in code rather than read from a file, swept over Y, and
// the cap's reaction read back. Prints one line per variant.
#include <fiberfluid/experiment/experiment.hpp>
#include <fiberfluid/experiment/run/runner.hpp>
#include <fiberfluid/geom/area_vectors.hpp>

#include <cstdio>
#include <nlohmann/json.hpp>

int main() {
  using nlohmann::json;
  const json document = {
      {"name", "sag_sphere"},
      {"surface", {{"generator", "icosphere"}, {"subdivisions", 2}, {"radius", 0.05}}},
      {"material", {{"Y", 20000.0}, {"gamma", 1.0}}},
      {"supports", {{{"where", "z >= 0.04"}, {"label", "cap"}}}},
      {"loads", {{{"type", "gravity"}, {"acceleration", {0.0, 0.0, -9.81}}, {"density", 1000.0}}}},
      {"stepping", {{"steps", 5}}},
      {"variants",
       {{{"name", "soft"}, {"material", {{"Y", 10000.0}}}},
        {{"name", "stiff"}, {"material", {{"Y", 40000.0}}}}}}};
  const fiberfluid::experiment::Experiment ex =
      fiberfluid::experiment::parse_experiment(document, ".", "in code");
  const fiberfluid::experiment::ExperimentResult result =
      fiberfluid::experiment::run_experiment(ex);
  for (size_t r = 0; r < result.runs.size(); ++r) {
    const auto& summary = result.runs[r].summary;
    if (!summary.success) {
      std::fprintf(stderr, "%s: %s\n", result.runs[r].variant.c_str(), summary.message.c_str());
      return 1;
    }
    const auto& surface = ex.simulation().cases[r].model.surface;
    std::printf("%s: largest displacement %.6g m, cap reaction z %.6g N, volume %.6g m^3\n",
                result.runs[r].variant.c_str(),
                result.figures.at(result.runs[r].variant + ".max_displacement"),
                summary.steps.back().reactions.at(0).z(),
                fiberfluid::geom::enclosed_volume(surface.V, surface.F));
  }
  return 0;
}
