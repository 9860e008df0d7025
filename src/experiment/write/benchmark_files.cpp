// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/write/benchmark_files.hpp"

#include <cmath>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>

#include "fiberfluid/geom/mesh_io.hpp"

namespace fiberfluid::experiment {

using json = nlohmann::json;

std::string benchmark_report(const BenchmarkResult& result) {
  std::ostringstream out;
  out << "  E_n / E_s / E_i against implicit Newmark (" << result.reference_seconds << " s):\n";
  for (const MetricSeries& s : result.series) {
    out << "  " << s.label << ":";
    for (const char* when : {"at_1s", "at_2s", "at_5s", "final"}) {
      const auto figure = [&](const char* metric) {
        const auto it = result.figures.find(s.label + "." + metric + "." + when);
        return it == result.figures.end()
                   ? std::string("-")
                   : (std::ostringstream() << std::setprecision(3) << it->second).str();
      };
      out << " " << (std::string(when) == "final" ? "end" : std::string(when).substr(3)) << " "
          << figure("E_n") << " / " << figure("E_s") << " / " << figure("E_i") << ";";
    }
    out << " " << std::setprecision(3) << s.seconds << " s";
    if (!s.ok) out << "; stopped: " << s.message;
    out << "\n";
  }
  const auto figure = [&](const std::string& name) {
    const auto it = result.figures.find(name);
    return it == result.figures.end()
               ? std::string("-")
               : (std::ostringstream() << std::setprecision(4) << it->second).str();
  };
  if (result.figures.count("reference.static_E_n_to_converged") != 0) {
    out << "  static shape, largest displacement by grid:";
    for (int refine = 1; refine <= 1024; ++refine)
      if (const auto it =
              result.figures.find("static.refine_" + std::to_string(refine) + ".max_displacement");
          it != result.figures.end())
        out << " x" << refine << " " << std::setprecision(5) << it->second;
    out << " m; order " << figure("static.order") << ", extrapolated "
        << figure("static.extrapolated_max_displacement") << " m; this mesh's static E_n against "
        << "the finest " << figure("reference.static_E_n_to_converged") << "\n";
  }
  if (result.fiber)
    out << "  fiber model: Y = " << result.fiber->Y << ", gamma = " << result.fiber->gamma << " ("
        << result.fiber->how << "; static shape of " << result.fiber->target << ", E_n "
        << result.fiber->static_energy_norm << ")\n";
  return out.str();
}

std::string benchmark_csv(const BenchmarkResult& result) {
  std::ostringstream out;
  out.precision(10);
  out << "time_s,series,E_n,E_s,E_i\n";
  auto cell = [](double v) {
    return std::isfinite(v) ? (std::ostringstream() << std::setprecision(10) << v).str()
                            : std::string();
  };
  for (const MetricSeries& s : result.series)
    for (size_t k = 0; k < s.times.size(); ++k)
      out << s.times[k] << "," << s.label << "," << cell(s.energy_norm[k]) << ","
          << cell(s.surface[k]) << "," << cell(s.interior[k]) << "\n";
  return out.str();
}

std::string benchmark_json(const BenchmarkSpec& spec, const BenchmarkResult& result) {
  const fem::Scene& scene = result.scene;
  json series = json::array();
  for (const MetricSeries& s : result.series)
    series.push_back({{"label", s.label},
                      {"ok", s.ok},
                      {"message", s.message},
                      {"seconds", s.seconds},
                      {"gauss_seidel_sweeps", s.sweeps},
                      {"steps", s.times.size()},
                      {"interior_weights", s.interior_weights}});
  json doc = {{"scene", scene.name},
              {"material",
               {{"label", spec.material_label},
                {"E", scene.material.young},
                {"nu", scene.material.poisson},
                {"density", scene.material.density},
                {"alpha", scene.dynamics.alpha},
                {"beta", scene.dynamics.beta}}},
              {"mesh",
               {{"nodes", scene.mesh.num_nodes()},
                {"elements", scene.mesh.elements.rows()},
                {"nodes_per_element", scene.mesh.elements.cols()},
                {"plane", scene.mesh.dim == 3                               ? "3D"
                          : scene.material.plane == fem::PlaneModel::Strain ? "strain"
                                                                            : "stress"}}},
              {"time", {{"step", spec.step}, {"duration", spec.duration}}},
              {"linear_solver", fem::to_string(spec.linear.linear)},
              {"reference",
               {{"solver", "implicit-newmark"},
                {"seconds", result.reference_seconds},
                {"gauss_seidel_sweeps", result.reference_sweeps}}},
              {"series", series}};
  if (result.fiber)
    doc["fiber_model"] = {{"Y", result.fiber->Y},
                          {"gamma", result.fiber->gamma},
                          {"how", result.fiber->how},
                          {"vertices", result.fiber->vertices},
                          {"static_E_n", result.fiber->static_energy_norm},
                          {"static_target", result.fiber->target}};
  return doc.dump(2) + "\n";
}

void write_benchmark_files(const std::filesystem::path& folder, const BenchmarkSpec& spec,
                           const BenchmarkResult& result) {
  using namespace benchmark_files;
  geom::write_text_file(folder / kMetrics, benchmark_csv(result));
  geom::write_text_file(folder / kReport, benchmark_json(spec, result));
  if (result.reference_final.num_vertices() > 0)
    geom::write_obj(folder / kReferenceFinal, result.reference_final);
  if (result.fiber_final.num_vertices() > 0)
    geom::write_obj(folder / kFiberModelFinal, result.fiber_final);
}

}  // namespace fiberfluid::experiment
