// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/read/schema.hpp"

#include <algorithm>
#include <cctype>
#include <deque>
#include <set>

#include "fiberfluid/experiment/read/experiment_reader.hpp"
#include "fiberfluid/experiment/read/schema_recorder.hpp"
#include "fiberfluid/experiment/write/file_names.hpp"
#include "fiberfluid/experiment/write/output_folder.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::experiment {
namespace {

using nlohmann::json;

// "fit.targets[1]" and "type" -> the JSON pointer /fit/targets/1/type.
json::json_pointer pointer(const std::string& path, const std::string& key) {
  std::string p;
  std::string part;
  for (const char c : path + ".") {
    if (c == '.' || c == '[' || c == ']') {
      if (!part.empty()) p += "/" + part;
      part.clear();
    } else {
      part += c;
    }
  }
  return json::json_pointer(p + "/" + key);
}

// Every value may also be null in a variant: a JSON merge patch (RFC 7386)
// removes a field with null.
json nullable(const json& schema) {
  if (schema.empty()) return schema;  // any value already
  json out = schema;
  if (out.contains("properties"))
    for (auto& [key, value] : out["properties"].items()) value = nullable(value);
  if (out.contains("anyOf")) {
    for (json& kind : out["anyOf"]) kind = nullable(kind);
    return out;
  }
  return {{"anyOf", {out, {{"type", "null"}}}}};
}

// A value of the kind a fragment describes, for a required field the
// explorer must give to read on.
json placeholder(const json& fragment) {
  if (fragment.contains("enum")) return fragment["enum"][0];
  const std::string type = fragment.value("type", "");
  if (type == "integer") return std::max(1, fragment.value("minimum", 1));
  if (type == "boolean") return false;
  if (type == "string") return "x";
  if (type == "object") return json::object();
  if (type == "array") {
    const json item = placeholder(fragment.value("items", json::object()));
    return json(
        std::vector<json>(static_cast<size_t>(std::max(1, fragment.value("minItems", 1))), item));
  }
  return 1.0;  // a number, or anything
}

// The recorded fields, and what the experiment adds to them: a variant (a
// patch of the simulation's fields with a name) and a specimen's name, each
// making a folder beside the result's own files, so not one of their names.
json experiment_fields_schema(const SchemaRecorder& recorder) {
  json root = recorder.schema();
  json not_reserved = {{"type", "string"},
                       {"not",
                        {{"anyOf",
                          {{{"enum", reserved_result_names()}},
                           {{"pattern", "^fit_(force_.+[.]csv|target_.+[.](vtu|obj))$"}}}}}}};
  json variant = {{"type", "object"},
                  {"properties", {{"name", not_reserved}}},
                  {"required", {"name"}},
                  {"additionalProperties", false}};
  for (const auto& [key, value] : root["properties"].items()) {
    const std::vector<std::string>& wide = experiment_wide_fields();
    if (std::find(wide.begin(), wide.end(), key) == wide.end())
      variant["properties"][key] = nullable(value);
  }
  root["properties"]["variants"] = {{"type", "array"}, {"minItems", 1}, {"items", variant}};
  json& specimen = root["properties"]["specimens"]["items"];
  if (specimen.is_object() && specimen.contains("properties"))
    specimen["properties"]["name"] = not_reserved;
  return root;
}

// Documents that between them have every section; each choice's other
// values are then tried from them.
const char* const kSeeds[] = {
    // The forms a choice of one field excludes: a mesh file, supports by vertex.
    R"({"name": "f", "surface": {"file": "x.obj", "flip": false},
        "material": {"Y": 1, "gamma": 0}, "supports": [{"vertices": [0, 1]}]})",
    R"({"name": "s", "description": "", "kind": "simulate",
        "surface": {"generator": "icosphere", "subdivisions": 1, "scale": 1},
        "material": {"law": {"type": "exponential", "Y0": 1000, "beta": 1}, "gamma": 1,
                     "axis_factors": [1, 1, 1]},
        "supports": [{"label": "held", "where": "z >= 0.5", "axes": "xyz", "layer": "none",
                      "edge": "held"}],
        "prescribed": [{"label": "moved", "box": {"min": [-2, -2, -2], "max": [2, 2, -0.9]},
                        "displacement": [0, 0, 0.01], "schedule": "ramp"},
                       {"label": "turned", "vertices": [3], "displacement": [0, 0, 0],
                        "rotation": {"axis": [0, 0, 1], "angle_degrees": 5,
                                     "centre": [0, 0, 0]}}],
        "loads": [{"type": "gravity", "label": "g", "acceleration": [0, 0, -1], "density": 1,
                   "schedule": "ramp", "integration": "vertex"},
                  {"type": "point", "label": "push", "vertex": 0, "force": [0, 0, 1],
                   "schedule": "final"},
                  {"type": "point", "label": "table", "vertex": 1, "force": [0, 0, 1],
                   "schedule": [0.5, 1]}],
        "paddles": [{"label": "upper", "axis": "z", "side": "above", "compression": 0.1,
                     "contact": "frictionless", "schedule": "ramp"},
                    {"label": "lower", "axis": "z", "side": "below", "travel": 0,
                     "position": -1.5}],
        "stepping": {"steps": 2, "scheme": "newton", "rebuild_matrix": false,
                     "update_load_geometry": false, "newton": {}},
        "fibers": {"pruning": "auto", "horizon": 1.5},
        "output": {"vtk": true},
        "fem_reference": {"material": "linear", "E": 1000, "nu": 0.3},
        "fit": {"targets": [{"type": "surface", "file": "a.obj", "step": 1, "units": "mm"},
                            {"type": "force", "file": "f.csv", "paddle": "upper",
                             "weight": 1, "rows_at": "travel"},
                            {"type": "force", "file": "f.csv", "support": "held", "axis": "z"}],
                "parameters": [{"name": "Y0", "start": 1, "lower": 0.1, "upper": 10,
                                "log_scale": true}],
                "objective": {"symmetric": true, "loss": "huber", "loss_scale": 0.001,
                              "exclude": {"where": "z > 0"}},
                "start_from": "fit.json", "method": "multistart", "starts": 4,
                "same_optimum": 0.001},
        "expected": [{"figure": "steps", "value": 2, "tolerance": 0, "note": ""},
                     {"figure": "steps", "at_most": 3, "at_least": 1}]})",
    R"({"name": "v", "surface": {"generator": "icosphere"}, "material": {"Y": [1, 1, 1]},
        "supports": [{"where": "z > 0"}], "loads": [{"type": "gravity", "acceleration": [0, 0, -1]}],
        "variants": [{"name": "a", "stepping": {"steps": 1}}]})",
    R"({"name": "c", "surface": {"generator": "icosphere"}, "material": {"Y": 1, "gamma": 0},
        "supports": [{"where": "z > 0"}]})",
    R"({"name": "j", "kind": "calibration", "shared": ["Y0"], "max_iterations": 10,
        "specimens": [{"name": "a", "experiment": "a.json"}, {"name": "b", "experiment": "b.json"}]})",
    R"({"name": "a", "kind": "areas", "surfaces": [{"name": "o", "generator": "octahedron"},
        {"name": "f", "file": "x.obj", "flip": false}]})",
    R"({"name": "b", "kind": "benchmark", "scene": "block-needle", "material": "MP1",
        "mesh": {"cells": [2, 2], "elements": "quadrilateral", "plane": "strain"},
        "time": {"step": 0.1, "duration": 1}, "solvers": ["explicit"],
        "fiber_model": {"fit": true}})",
    R"({"name": "b", "kind": "benchmark", "scene": "bending-rod",
        "material": {"E": 1, "nu": 0.3, "density": 1, "alpha": 0, "beta": 0},
        "mesh": {"cells": [2, 1, 1], "elements": "hexahedron"}, "gravity": 0.05,
        "time": {"step": 0.1, "duration": 1}, "solvers": ["explicit"],
        "fiber_model": {"fit": true, "steps": 2, "scheme": "newton"}})",
};

}  // namespace

json experiment_schema() {
  SchemaRecorder recorder;
  SchemaRecorder*& active = active_schema_recorder();
  SchemaRecorder* const before = active;
  active = &recorder;
  std::deque<json> queue;
  for (const char* seed : kSeeds) queue.push_back(json::parse(seed));
  std::set<std::string> tried;
  constexpr int kMostReads = 5000;  // a bound, far above what the reader's choices need
  for (int reads = 0; !queue.empty() && reads < kMostReads; ++reads) {
    const json document = std::move(queue.front());
    queue.pop_front();
    try {
      read_experiment(document, ".", "schema");
    } catch (const std::exception&) {
      // A changed choice may leave the rest of the document wrong: what the
      // reader read before the error is recorded all the same. A required
      // field it missed is given a value of its kind, and the reading tried again.
      std::string path, key;
      json fragment;
      if (recorder.take_missing(&path, &key, &fragment)) {
        const json::json_pointer at = pointer(path, key);
        if (tried.insert("given " + at.to_string() + " " + document.dump()).second) {
          json given = document;
          try {
            given[at] = placeholder(fragment);
            queue.push_front(std::move(given));
          } catch (const json::exception&) {
          }
        }
      }
    }
    // An optional field the document lacks, given an empty object: its typed
    // read (a section's, or a value's before its check fails) is recorded.
    for (const SchemaRecorder::Choice& a : recorder.take_asked()) {
      // Once per field and the object around it (a cylinder's segments
      // are read as two counts, a box's as three).
      const json::json_pointer at = pointer(a.path, a.key);
      json given = document;
      try {
        const std::string around = document.at(at.parent_pointer()).dump();
        if (!tried.insert("asked " + schema_path_pattern(a.path) + "." + a.key + " in " + around)
                 .second)
          continue;
        given[at] = json::object();
      } catch (const json::exception&) {
        continue;
      }
      queue.push_back(std::move(given));
    }
    for (const SchemaRecorder::Choice& c : recorder.take_choices())
      for (const std::string& value : c.allowed) {
        const json::json_pointer at = pointer(c.path, c.key);
        if (!tried.insert(at.to_string() + "=" + value).second) continue;
        json changed = document;
        try {
          changed[at] = value;
        } catch (const json::exception&) {
          continue;  // a path the document does not have (a case read from a merged variant)
        }
        queue.push_back(std::move(changed));
      }
  }
  active = before;
  json schema = experiment_fields_schema(recorder);
  schema["$schema"] = "https://json-schema.org/draft/2020-12/schema";
  schema["title"] = "fiberfluid experiment";
  schema["description"] =
      "An experiment file of fiberfluid (README: Experiment files). Generated by `fiberfluid "
      "schema` from the reader's own fields: every field it reads, with its type, range and "
      "allowed values; unknown fields are refused as the reader refuses them. Which fields go "
      "together (a law's parameters, one of file and generator) the reader checks.";
  return schema;
}

}  // namespace fiberfluid::experiment
