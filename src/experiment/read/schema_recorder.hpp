// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// What the reader reads, recorded: while a SchemaRecorder is active on a
// thread, every Fields accessor (json_fields.hpp) reports the field it reads
// (its name, type, range, allowed values). read/schema.hpp turns a recording
// of the whole reader into the experiment file's JSON Schema.

#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

namespace fiberfluid::experiment {

class SchemaRecorder {
 public:
  // A field `key` of the object at `path` ("fit.targets[1]"), read as
  // `fragment` (a JSON Schema for its value; {} for any value).
  void note(const std::string& path, const std::string& key, const nlohmann::json& fragment);
  // A field with a fixed set of values: recorded, and kept for exploring.
  void choice(const std::string& path, const std::string& key,
              const std::vector<std::string>& allowed);

  // A required field that was not given: the explorer gives it a value.
  void missing(const std::string& path, const std::string& key);
  // The field missing in the last read, if any (path, key), and what it was read as.
  bool take_missing(std::string* path, std::string* key, nlohmann::json* fragment);

  struct Choice {
    std::string path, key;
    std::vector<std::string> allowed;
  };
  // The choices met since the last call.
  std::vector<Choice> take_choices();

  // An optional field the reader asked for (has) and the document lacks:
  // the explorer gives it one, so that its typed read is recorded too (issue
  // 43: fields read only when given came out as any value).
  void asked(const std::string& path, const std::string& key);
  std::vector<Choice> take_asked();

  // The schema of everything recorded: objects closed to unknown fields.
  nlohmann::json schema() const;

 private:
  // Per object path pattern ("fit.targets[]"), per field: its schema.
  std::map<std::string, std::map<std::string, nlohmann::json>> fields_;
  std::vector<Choice> choices_;
  std::vector<Choice> asked_;
  std::string missing_path_, missing_key_;
  bool missing_ = false;
};

// The recorder Fields reports to on this thread, or null (the usual case).
SchemaRecorder*& active_schema_recorder();

// "fit.targets[1].x" -> "fit.targets[].x": the one schema of every element.
std::string schema_path_pattern(const std::string& path);

}  // namespace fiberfluid::experiment
