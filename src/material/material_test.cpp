// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/material/material_test.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>

#include "fiberfluid/util/error.hpp"

namespace fiberfluid::material {
namespace {

std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, ',')) {
    while (!field.empty() && (field.back() == '\r' || field.back() == ' ')) field.pop_back();
    while (!field.empty() && field.front() == ' ') field.erase(field.begin());
    fields.push_back(field);
  }
  return fields;
}

double number_at(const std::string& text, const std::string& where) {
  size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || !std::isfinite(value))
    throw InputError(where + ": expected a finite number, got \"" + text + "\"");
  return value;
}

}  // namespace

std::vector<TestPoint> read_material_test(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError(path + ": cannot open the material test");
  std::ostringstream text;
  text << file.rdbuf();
  return read_material_test_text(text.str(), path);
}

std::vector<TestPoint> read_material_test_text(const std::string& text, const std::string& path) {
  std::istringstream in(text);
  std::string line;
  int number = 0, test_column = -1, stretch_column = -1, stress_column = -1;
  double unit = 0.0;
  std::vector<TestPoint> points;
  bool header = false;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#' || line.find_first_not_of(" \r") == std::string::npos)
      continue;
    const std::vector<std::string> fields = split_csv(line);
    const std::string where = path + ":" + std::to_string(number);
    if (!header) {
      header = true;
      for (size_t k = 0; k < fields.size(); ++k) {
        const int c = static_cast<int>(k);
        if (fields[k] == "test") test_column = c;
        if (fields[k] == "stretch") stretch_column = c;
        const double scale = fields[k] == "nominal_stress_Pa"    ? 1.0
                             : fields[k] == "nominal_stress_kPa" ? 1e3
                             : fields[k] == "nominal_stress_MPa" ? 1e6
                                                                 : 0.0;
        if (scale > 0.0 && stress_column < 0) stress_column = c, unit = scale;
      }
      if (test_column < 0 || stretch_column < 0 || stress_column < 0)
        throw InputError(where +
                         ": expected a header with the columns test, stretch and one of "
                         "nominal_stress_Pa, nominal_stress_kPa, nominal_stress_MPa");
      continue;
    }
    const size_t needed =
        static_cast<size_t>(std::max({test_column, stretch_column, stress_column}));
    if (fields.size() <= needed)
      throw InputError(where + ": expected " + std::to_string(needed + 1) + " columns, got " +
                       std::to_string(fields.size()));
    TestPoint p;
    try {
      p.test = homogeneous_test(fields[static_cast<size_t>(test_column)]);
    } catch (const InputError& e) {
      throw InputError(where + ": " + e.what());
    }
    p.stretch = number_at(fields[static_cast<size_t>(stretch_column)], where + ", stretch");
    if (!(p.stretch >= kLeastStretch && p.stretch <= kMostStretch))
      throw InputError(where +
                       ": expected a stretch from 0.001 to 1000 (a length's ratio to its "
                       "unloaded length), got " +
                       fields[static_cast<size_t>(stretch_column)]);
    p.nominal_stress =
        unit * number_at(fields[static_cast<size_t>(stress_column)], where + ", stress");
    points.push_back(p);
  }
  if (points.empty()) throw InputError(path + ": no test points (expected a header, then rows)");
  return points;
}

std::vector<TestPoint> loaded_points(const std::vector<TestPoint>& points) {
  std::vector<TestPoint> loaded;
  std::copy_if(points.begin(), points.end(), std::back_inserter(loaded), is_loaded);
  return loaded;
}

std::vector<double> relative_misfits(const StressResponse& stress,
                                     const std::vector<TestPoint>& points) {
  std::vector<double> misfits;
  for (const TestPoint& p : points)
    if (is_loaded(p))
      misfits.push_back((stress(p.test, p.stretch) - p.nominal_stress) / p.nominal_stress);
  return misfits;
}

std::vector<double> relative_misfits(const HyperelasticLaw& law,
                                     const std::vector<TestPoint>& points) {
  return relative_misfits(
      [&](HomogeneousTest test, double l) { return nominal_stress(law, test, l); }, points);
}

double rms_relative_misfit(const HyperelasticLaw& law, const std::vector<TestPoint>& points) {
  return rms_relative_misfit(
      [&](HomogeneousTest test, double l) { return nominal_stress(law, test, l); }, points);
}

double rms_relative_misfit(const StressResponse& stress, const std::vector<TestPoint>& points) {
  const std::vector<double> m = relative_misfits(stress, points);
  double sum = 0.0;
  for (double r : m) sum += r * r;
  return m.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(m.size()));
}

}  // namespace fiberfluid::material
