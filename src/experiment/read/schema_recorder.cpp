// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/read/schema_recorder.hpp"

#include <algorithm>
#include <functional>

namespace fiberfluid::experiment {
namespace {

using nlohmann::json;

// The path of field `key` of the object at `path`.
std::string child(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

}  // namespace

// "fit.targets[1].x" -> "fit.targets[].x": one schema for every element.
std::string schema_path_pattern(const std::string& path) {
  std::string out;
  for (size_t i = 0; i < path.size(); ++i) {
    out += path[i];
    if (path[i] == '[')
      while (i + 1 < path.size() && std::isdigit(static_cast<unsigned char>(path[i + 1]))) ++i;
  }
  return out;
}

SchemaRecorder*& active_schema_recorder() {
  thread_local SchemaRecorder* recorder = nullptr;
  return recorder;
}

void SchemaRecorder::note(const std::string& path, const std::string& key, const json& fragment) {
  json& known = fields_[schema_path_pattern(path)][key];
  if (known.is_null()) known = json::array();
  if (std::find(known.begin(), known.end(), fragment) == known.end()) known.push_back(fragment);
}

void SchemaRecorder::choice(const std::string& path, const std::string& key,
                            const std::vector<std::string>& allowed) {
  note(path, key, {{"enum", allowed}});
  choices_.push_back({path, key, allowed});
}

void SchemaRecorder::missing(const std::string& path, const std::string& key) {
  missing_ = true;
  missing_path_ = path;
  missing_key_ = key;
}

bool SchemaRecorder::take_missing(std::string* path, std::string* key, json* fragment) {
  if (!missing_) return false;
  missing_ = false;
  *path = missing_path_;
  *key = missing_key_;
  *fragment = json::object();
  for (const json& f : fields_[schema_path_pattern(missing_path_)][missing_key_])
    if (!f.is_null() && !f.empty()) *fragment = f;
  return true;
}

void SchemaRecorder::asked(const std::string& path, const std::string& key) {
  asked_.push_back({path, key, {}});
}

std::vector<SchemaRecorder::Choice> SchemaRecorder::take_asked() {
  std::vector<Choice> out;
  out.swap(asked_);
  return out;
}

std::vector<SchemaRecorder::Choice> SchemaRecorder::take_choices() {
  std::vector<Choice> out;
  out.swap(choices_);
  return out;
}

json SchemaRecorder::schema() const {
  // The object read at `path`: its fields, each the union of how it was read.
  std::function<json(const std::string&)> object = [&](const std::string& path) {
    json properties = json::object();
    const auto found = fields_.find(path);
    if (found != fields_.end())
      for (const auto& [key, fragments] : found->second) {
        json kinds = json::array();
        bool any = false;
        for (json fragment : fragments) {
          if (fragment.is_null()) continue;  // asked for (has): typed where it is read, if at all
          if (fragment.empty()) any = true;  // read as it is (raw): the reader checks its form
          const std::string name = child(path, key);
          if (fragment.value("type", "") == "object" && fields_.count(name))
            fragment = object(name);
          if (fragment.value("type", "") == "array" && fields_.count(name + "[]"))
            fragment["items"] = object(name + "[]");
          if (std::find(kinds.begin(), kinds.end(), fragment) == kinds.end())
            kinds.push_back(fragment);
        }
        // A string read of a field that a choice read too is the same value
        // read again: the choice's names bound it ("generator": "box2").
        bool named = false;
        for (const json& kind : kinds) named |= kind.contains("enum");
        if (named) {
          json narrowed = json::array();
          for (const json& kind : kinds)
            if (kind != json{{"type", "string"}}) narrowed.push_back(kind);
          kinds = narrowed;
        }
        properties[key] = any || kinds.empty() ? json::object()
                          : kinds.size() == 1  ? kinds[0]
                                               : json{{"anyOf", kinds}};
      }
    return json{{"type", "object"}, {"properties", properties}, {"additionalProperties", false}};
  };
  json root = object("");
  return root;
}

}  // namespace fiberfluid::experiment
