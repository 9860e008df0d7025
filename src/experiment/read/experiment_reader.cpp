// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/read/experiment_reader.hpp"

#include <algorithm>
#include <filesystem>
#include <istream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "fiberfluid/experiment/read/json_fields.hpp"
#include "fiberfluid/experiment/read/readers.hpp"
#include "fiberfluid/experiment/spec/figures.hpp"
#include "fiberfluid/experiment/write/file_names.hpp"
#include "fiberfluid/experiment/write/output_folder.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::experiment {
namespace {

using nlohmann::json;

std::vector<ExpectedFigure> read_expected(Fields& root) {
  std::vector<ExpectedFigure> expected;
  for (Fields f : root.objects("expected")) {
    ExpectedFigure e;
    e.figure = f.string("figure");
    e.note = f.string("note", "");
    if (f.has("value") && f.raw("value").is_array()) {
      const json& rows = f.raw("value");
      e.matrix.resize(static_cast<Eigen::Index>(rows.size()),
                      rows.empty() ? 0 : static_cast<Eigen::Index>(rows[0].size()));
      for (size_t r = 0; r < rows.size(); ++r) {
        if (!rows[r].is_array() || rows[r].size() != static_cast<size_t>(e.matrix.cols()))
          f.fail("value", "expected a number or a matrix (a list of equal-length rows)");
        for (size_t c = 0; c < rows[r].size(); ++c) {
          if (!rows[r][c].is_number()) f.fail("value", "expected numbers in the matrix");
          e.matrix(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) =
              rows[r][c].get<double>();
        }
      }
    } else if (f.has("value")) {
      e.value = f.number("value");
    }
    e.tolerance = f.non_negative("tolerance", 0.0);
    if (f.has("at_most")) e.at_most = f.number("at_most");
    if (f.has("at_least")) e.at_least = f.number("at_least");
    if (!e.value && e.matrix.size() == 0 && !e.at_most && !e.at_least)
      f.fail("", "expected \"value\", \"at_most\" or \"at_least\"");
    f.finish();
    expected.push_back(e);
  }
  return expected;
}

// Fields of the experiment that a variant may not patch.
const char* const kExperimentFields[] = {"name",     "description",   "kind",
                                         "variants", "expected",      "output",
                                         "fit",      "fem_reference", "$schema"};

void check_variant_name(const Fields& f, const std::string& name,
                        const std::vector<CaseSpec>& earlier) {
  if (const Status problem = check_folder_name(name); !problem.ok)
    f.fail("name", "expected " + problem.message);
  if (const Status problem = check_not_reserved(name); !problem.ok)
    f.fail("name", "expected " + problem.message);
  for (const CaseSpec& c : earlier)
    if (c.variant == name) f.fail("name", "\"" + name + "\" names another variant already");
}

// A simulation: the base document, or one case per variant, each the base
// with the variant's JSON merge patch (RFC 7386) applied.
void read_simulation(Fields& root, const nlohmann::json& document,
                     const std::filesystem::path& folder, Experiment& ex) {
  Simulation& simulation = ex.content.emplace<Simulation>();
  if (root.has("fit")) {
    if (root.has("variants"))
      root.fail("fit",
                "a fit calibrates one simulation: remove \"variants\" (fit several loads "
                "with several targets, each tied to its step)");
    simulation.fit = read_fit(root.object("fit"), folder);
  }
  if (root.has("fem_reference")) {
    if (root.has("variants"))
      root.fail("fem_reference", "a FEM reference solves one simulation: remove \"variants\"");
    Fields f = root.object("fem_reference");
    simulation.fem_reference = read_fem_reference(f);
  }
  json base = document;
  for (const char* field : kExperimentFields) base.erase(field);
  if (!root.has("variants")) {
    json resolved;
    Fields f(base, "", root.file(), &resolved);
    simulation.specs.push_back(read_case(f, folder, &ex.warnings));
    ex.resolved.update(resolved);
  } else {
    const json& variants = root.raw("variants");
    if (!variants.is_array() || variants.empty())
      root.fail("variants", "expected a non-empty list of objects");
    json resolved_variants = json::array();
    for (size_t k = 0; k < variants.size(); ++k) {
      Fields v(variants[k], "variants[" + std::to_string(k) + "]", root.file());
      const std::string name = v.string("name");
      check_variant_name(v, name, simulation.specs);
      json patch = variants[k];
      patch.erase("name");
      for (const char* field : kExperimentFields)
        if (patch.contains(field))
          v.fail(field, "belongs to the whole experiment; a variant cannot change it");
      json patched = base;
      patched.merge_patch(patch);
      json resolved = {{"name", name}};
      Fields f(patched, "", root.file() + " [variant " + name + "]", &resolved);
      CaseSpec c = read_case(f, folder, &ex.warnings);
      c.variant = name;
      c.patch = patch;
      simulation.specs.push_back(std::move(c));
      resolved_variants.push_back(std::move(resolved));
    }
    // Each variant resolved whole: merged onto an empty base, it is its case.
    ex.resolved["variants"] = std::move(resolved_variants);
  }
  Fields output = root.object_or_empty("output");
  simulation.output.vtk = output.boolean("vtk", true);
  simulation.output.obj = output.boolean("obj", true);
  simulation.output.every = output.integer("every", 1, 1, 1000000);
  simulation.output.vtk_format =
      output.choice("vtk_format", "auto", {"auto", "ascii", "compressed"});
  output.finish();
}

// A calibration over several specimens: their experiment files (read when
// the experiment is built) and the parameters they share.
CalibrationSpec read_calibration(Fields& root, const std::filesystem::path& folder) {
  CalibrationSpec spec;
  for (Fields f : root.objects("specimens")) {
    SpecimenSpec specimen;
    specimen.field = f.field();
    specimen.name = f.string("name");
    if (const Status problem = check_folder_name(specimen.name); !problem.ok)
      f.fail("name", "expected " + problem.message);
    if (const Status problem = check_not_reserved(specimen.name); !problem.ok)
      f.fail("name", "expected " + problem.message);
    for (const SpecimenSpec& other : spec.specimens)
      if (other.name == specimen.name)
        f.fail("name", "\"" + specimen.name + "\" names another specimen");
    specimen.file = f.string("experiment");
    if (specimen.file.is_relative()) specimen.file = folder / specimen.file;
    f.resolve("experiment", absolute_path(specimen.file));
    f.finish();
    spec.specimens.push_back(specimen);
  }
  if (spec.specimens.size() < 2)
    root.fail("specimens", "expected two or more specimens (each {\"name\", \"experiment\"})");
  spec.shared = root.names("shared");
  spec.max_iterations = root.integer("max_iterations", spec.max_iterations, 1, 10000);
  return spec;
}

void read_areas(Fields& root, const std::filesystem::path& folder, Experiment& ex) {
  AreaStudy& areas = ex.content.emplace<AreaStudy>();
  for (Fields f : root.objects("surfaces")) {
    NamedSurfaceSpec named;
    named.name = f.string("name");
    named.surface = read_surface_spec(f, folder);
    f.finish();
    areas.specs.push_back(named);
  }
  if (areas.specs.empty()) root.fail("surfaces", "expected at least one surface");
}

// Every expected figure names a figure the experiment will have (a fit's
// once its parameters are checked: setup_fit).
void check_expected_names(const Fields& root, const Experiment& ex) {
  for (size_t k = 0; k < ex.expected.size(); ++k) {
    if (const Status figure = check_figure(ex, ex.expected[k].figure, /*fit_figures=*/false);
        !figure.ok)
      root.fail("expected[" + std::to_string(k) + "].figure", figure.message);
  }
}

}  // namespace

Experiment read_experiment(const json& document, const std::filesystem::path& folder,
                           const std::string& label) {
  Experiment ex;
  ex.document = document;
  Fields root(document, "", label, &ex.resolved);
  // An editor's pointer to the schema (`fiberfluid schema --help` suggests it): taken, unused.
  if (root.has("$schema")) root.string("$schema");
  ex.name = root.string("name", "experiment");
  if (const Status problem = check_folder_name(ex.name); !problem.ok)
    root.fail("name", "expected " + problem.message);
  ex.description = root.string("description", "");
  const Experiment::Kind kind =
      root.enumeration("kind", Experiment::Kind::Simulate, kExperimentKindNames);
  ex.expected = read_expected(root);
  if (kind != Experiment::Kind::Simulate && root.has("fit"))
    root.fail("fit", "only a simulation can be fitted");
  if (kind != Experiment::Kind::Simulate && root.has("fem_reference"))
    root.fail("fem_reference", "only a simulation has a FEM reference");
  switch (kind) {
    case Experiment::Kind::Simulate:
      read_simulation(root, document, folder, ex);  // each case checks its own fields
      break;
    case Experiment::Kind::Benchmark:
      ex.content = read_benchmark(root);
      root.finish();
      break;
    case Experiment::Kind::Calibration:
      ex.content = CalibrationStudy{read_calibration(root, folder), {}};
      root.finish();
      break;
    case Experiment::Kind::Areas:
      read_areas(root, folder, ex);
      root.finish();
      break;
  }
  check_expected_names(root, ex);
  return ex;
}

const std::vector<std::string>& experiment_wide_fields() {
  static const std::vector<std::string> fields(std::begin(kExperimentFields),
                                               std::end(kExperimentFields));
  return fields;
}

namespace {

template <class Input>
json parse_json_from(Input&& input, const std::string& label) {
  struct TooDeep {};
  struct Duplicate {
    std::string path;
  };
  // A key given twice in one object: nlohmann keeps the last one without a
  // word, so the file would mean what its last line says (issue 43, "a file
  // means one thing"). Each open object's keys, and the key it sits under.
  struct Open {
    std::set<std::string> keys;
    std::string under;
  };
  std::vector<Open> open;
  std::string last_key;
  const json::parser_callback_t guard = [&](int depth, json::parse_event_t event, json& parsed) {
    if ((event == json::parse_event_t::object_start || event == json::parse_event_t::array_start) &&
        depth >= kDeepestJson)
      throw TooDeep{};
    if (event == json::parse_event_t::object_start) open.push_back({{}, last_key});
    if (event == json::parse_event_t::object_end && !open.empty()) open.pop_back();
    if (event == json::parse_event_t::key && !open.empty()) {
      last_key = parsed.is_string() ? parsed.get<std::string>() : std::string();
      if (!open.back().keys.insert(last_key).second) {
        std::string path = last_key;
        for (auto it = open.rbegin(); it != open.rend(); ++it)
          if (!it->under.empty()) path = it->under + "." + path;
        throw Duplicate{path};
      }
    }
    return true;
  };
  try {
    return json::parse(std::forward<Input>(input), guard);
  } catch (const TooDeep&) {
    throw InputError(label + ": nested more than " + std::to_string(kDeepestJson) +
                     " levels deep (an experiment needs a few)");
  } catch (const Duplicate& d) {
    throw InputError(label + ": \"" + d.path.substr(0, 80) +
                     "\" is given twice in one object (expected each key once: which one "
                     "would count?)");
  } catch (const json::exception& e) {  // a syntax error, or a number a double cannot hold (1e999)
    // The parser quotes the token it last read, which may be a whole line: cut it short.
    std::string what = e.what();
    if (what.size() > 200) what = what.substr(0, 200) + "...";
    throw InputError(label + ": not valid JSON: " + what);
  }
}

}  // namespace

json parse_json(std::istream& in, const std::string& label) { return parse_json_from(in, label); }
json parse_json(const std::string& text, const std::string& label) {
  return parse_json_from(text, label);
}

}  // namespace fiberfluid::experiment
