// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "fiberfluid/experiment/read/schema_recorder.hpp"
#include "fiberfluid/experiment/spec/case_spec.hpp"
#include "fiberfluid/util/error.hpp"
#include "fiberfluid/util/names.hpp"

namespace fiberfluid::experiment {

// A value as a message quotes it: its JSON text, cut to a short excerpt (a
// bad value may be a whole document).
inline std::string excerpt(const nlohmann::json& value) {
  constexpr size_t kLongest = 80;
  std::string text = value.dump();
  if (text.size() > kLongest)
    text = text.substr(0, kLongest) + "... (" + std::to_string(text.size()) + " characters)";
  return text;
}

// Reads the fields of one JSON object, naming "file: path.to.field" in every
// error, and rejects fields nobody asked for. With a `resolved` document it
// also writes there every value it returns, defaults included: the object as
// the reader understood it (an experiment's experiment.resolved.json).
class Fields {
 public:
  Fields(const nlohmann::json& object, std::string path, std::string file,
         nlohmann::json* resolved = nullptr)
      : object_(object), path_(std::move(path)), file_(std::move(file)), resolved_(resolved) {
    if (!object_.is_object()) fail("", "expected an object");
    if (resolved_ != nullptr && !resolved_->is_object()) *resolved_ = nlohmann::json::object();
  }

  // Replaces what the resolved document says of `key` (e.g. a file's path,
  // made absolute).
  void resolve(const std::string& key, const nlohmann::json& value) {
    if (resolved_ != nullptr) (*resolved_)[key] = value;
  }

  // A field the reader refuses where it is: the schema refuses it too.
  [[noreturn]] void refuse(const std::string& key, const std::string& what) const {
    note(key, [] { return nlohmann::json{{"not", nlohmann::json::object()}}; });
    fail(key, what);
  }
  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw InputError(file_ + ": " + name(key) + (name(key).empty() ? "" : ": ") + what);
  }
  std::string name(const std::string& key) const {
    if (key.empty()) return path_;
    return path_.empty() ? key : path_ + "." + key;
  }
  bool has(const std::string& key) const {
    note(key, [] { return nlohmann::json(); });  // asked for: its type, if any, comes with its read
    const bool given = object_.contains(key);
    if (SchemaRecorder* recorder = active_schema_recorder(); recorder != nullptr && !given)
      recorder->asked(path_, key);
    return given;
  }

  // A value as given (recorded as given unless a typed read records it).
  const nlohmann::json& raw(const std::string& key) {
    note(key, [] { return nlohmann::json::object(); });  // any value: the caller checks it
    return value_of(key);
  }
  // A value to look at, if given, without reading it (nothing is recorded).
  const nlohmann::json* peek(const std::string& key) const {
    return object_.contains(key) ? &object_.at(key) : nullptr;
  }
  Fields object(const std::string& key) {
    note(key, [] { return nlohmann::json{{"type", "object"}}; });
    const nlohmann::json& v = value_of(key);
    return Fields(v, name(key), file_, resolved_child(key, nlohmann::json::object()));
  }

  // An optional section: the object, or an empty one whose defaults are then
  // read (and resolved) like the given fields.
  Fields object_or_empty(const std::string& key) {
    static const nlohmann::json kEmpty = nlohmann::json::object();
    note(key, [] { return nlohmann::json{{"type", "object"}}; });
    if (has(key)) return object(key);
    seen_.insert(key);
    return Fields(kEmpty, name(key), file_, resolved_child(key, nlohmann::json::object()));
  }

  double number(const std::string& key) {
    note(key, [] { return nlohmann::json{{"type", "number"}}; });
    const nlohmann::json& v = value_of(key);
    if (!v.is_number()) fail(key, "expected a number, got " + excerpt(v));
    const double x = v.get<double>();
    if (!std::isfinite(x)) fail(key, "expected a finite number");
    return x;
  }
  double number(const std::string& key, double fallback) {
    note(key, [] { return nlohmann::json{{"type", "number"}}; });
    return has(key) ? number(key) : (seen_.insert(key), record(key, fallback));
  }
  double positive(const std::string& key, double fallback) {
    note(key, [] { return nlohmann::json{{"type", "number"}, {"exclusiveMinimum", 0}}; });
    const double x = muted([&] { return number(key, fallback); });
    if (!(x > 0.0)) fail(key, "expected a positive number, got " + std::to_string(x));
    return x;
  }
  double non_negative(const std::string& key, double fallback) {
    note(key, [] { return nlohmann::json{{"type", "number"}, {"minimum", 0}}; });
    const double x = muted([&] { return number(key, fallback); });
    if (x < 0.0) fail(key, "expected a number >= 0, got " + std::to_string(x));
    return x;
  }
  int integer(const std::string& key, int fallback, int min, int max) {
    note(key, [&] {
      return nlohmann::json{{"type", "integer"}, {"minimum", min}, {"maximum", max}};
    });
    // A fallback outside [min, max] stands for "not given" (step 0: the last): not written out.
    if (!has(key))
      return seen_.insert(key), fallback < min || fallback > max ? fallback : record(key, fallback);
    const nlohmann::json& v = value_of(key);
    const std::string range =
        "a whole number from " + std::to_string(min) + " to " + std::to_string(max);
    if (!v.is_number_integer() || !fits(v, min, max))
      fail(key, "expected " + range + ", got " + excerpt(v));
    return static_cast<int>(v.get<long long>());
  }
  bool boolean(const std::string& key, bool fallback) {
    note(key, [] { return nlohmann::json{{"type", "boolean"}}; });
    if (!has(key)) return seen_.insert(key), record(key, fallback);
    const nlohmann::json& v = value_of(key);
    if (!v.is_boolean()) fail(key, "expected true or false, got " + excerpt(v));
    return v.get<bool>();
  }
  std::string string(const std::string& key) {
    note(key, [] { return nlohmann::json{{"type", "string"}}; });
    const nlohmann::json& v = value_of(key);
    if (!v.is_string()) fail(key, "expected a string, got " + excerpt(v));
    return v.get<std::string>();
  }
  std::string string(const std::string& key, const std::string& fallback) {
    return has(key) ? string(key) : (seen_.insert(key), record(key, fallback));
  }
  std::string choice(const std::string& key, const std::string& fallback,
                     const std::vector<std::string>& allowed) {
    if (SchemaRecorder* recorder = active_schema_recorder()) recorder->choice(path_, key, allowed);
    const std::string s = muted([&] { return string(key, fallback); });
    if (std::find(allowed.begin(), allowed.end(), s) == allowed.end())
      fail(key, "expected one of " + join(allowed) + ", got " + excerpt(s));
    return s;
  }
  // A choice among an enum's names (util/names.hpp), as its value: the names
  // offered, the default's name and the value read are the one list's.
  template <class Enum, std::size_t N>
  Enum enumeration(const std::string& key, Enum fallback, const Names<Enum, N>& names) {
    return *names.find(choice(key, names.name(fallback), names.all()));
  }
  // A list of `size` numbers (any size when size < 0).
  Eigen::VectorXd vector(const std::string& key, int size) {
    note(key, [&] {
      nlohmann::json list = {{"type", "array"}, {"items", {{"type", "number"}}}};
      if (size >= 0) list["minItems"] = list["maxItems"] = size;
      return list;
    });
    const nlohmann::json& v = value_of(key);
    const std::string want =
        size < 0 ? "a list of numbers" : "a list of " + std::to_string(size) + " numbers";
    if (!v.is_array() || (size >= 0 && static_cast<int>(v.size()) != size))
      fail(key, "expected " + want + ", got " + excerpt(v));
    Eigen::VectorXd out(static_cast<Eigen::Index>(v.size()));
    for (size_t k = 0; k < v.size(); ++k) {
      if (!v[k].is_number() || !std::isfinite(v[k].get<double>()))
        fail(key, "expected " + want + ", got " + excerpt(v));
      out[static_cast<Eigen::Index>(k)] = v[k].get<double>();
    }
    return out;
  }
  // A list of `size` whole numbers from min to max (counts such as segments).
  Eigen::VectorXi counts(const std::string& key, int size, int min, int max) {
    note(key, [&] {
      return nlohmann::json{{"type", "array"},
                            {"items", {{"type", "integer"}, {"minimum", min}, {"maximum", max}}},
                            {"minItems", size},
                            {"maxItems", size}};
    });
    const nlohmann::json& v = value_of(key);
    const std::string want = "a list of " + std::to_string(size) + " whole numbers from " +
                             std::to_string(min) + " to " + std::to_string(max);
    if (!v.is_array() || static_cast<int>(v.size()) != size)
      fail(key, "expected " + want + ", got " + excerpt(v));
    Eigen::VectorXi out(size);
    for (int k = 0; k < size; ++k) {
      const nlohmann::json& item = v[static_cast<size_t>(k)];
      if (!item.is_number_integer() || !fits(item, min, max))
        fail(key, "expected " + want + ", got " + excerpt(v));
      out[k] = static_cast<int>(item.get<long long>());
    }
    return out;
  }
  std::vector<int> indices(const std::string& key) {
    note(key, [] {
      return nlohmann::json{
          {"type", "array"}, {"items", {{"type", "integer"}, {"minimum", 0}}}, {"minItems", 1}};
    });
    const nlohmann::json& v = value_of(key);
    if (!v.is_array() || v.empty()) fail(key, "expected a non-empty list of vertex indices");
    std::vector<int> out;
    for (const nlohmann::json& item : v) {
      if (!item.is_number_integer() || !fits(item, 0, std::numeric_limits<int>::max()))
        fail(key, "expected vertex indices (whole numbers from 0 to " +
                      std::to_string(std::numeric_limits<int>::max()) + "), got " + excerpt(item));
      out.push_back(static_cast<int>(item.get<long long>()));
    }
    return out;
  }
  // A non-empty list of distinct names.
  std::vector<std::string> names(const std::string& key) {
    note(key, [] {
      return nlohmann::json{{"type", "array"},
                            {"items", {{"type", "string"}, {"minLength", 1}}},
                            {"minItems", 1},
                            {"uniqueItems", true}};
    });
    const nlohmann::json& v = value_of(key);
    if (!v.is_array() || v.empty()) fail(key, "expected a non-empty list of names");
    std::vector<std::string> out;
    for (const nlohmann::json& item : v) {
      if (!item.is_string() || item.get<std::string>().empty())
        fail(key, "expected names (strings), got " + excerpt(item));
      if (std::find(out.begin(), out.end(), item.get<std::string>()) != out.end())
        fail(key, "\"" + item.get<std::string>() + "\" is named twice");
      out.push_back(item.get<std::string>());
    }
    return out;
  }
  std::vector<Fields> objects(const std::string& key) {
    note(key, [] { return nlohmann::json{{"type", "array"}, {"items", {{"type", "object"}}}}; });
    std::vector<Fields> out;
    if (!has(key)) return seen_.insert(key), record(key, nlohmann::json::array()), out;
    const nlohmann::json& v = value_of(key);
    if (!v.is_array()) fail(key, "expected a list of objects");
    // Sized first: its elements' addresses then stay put.
    nlohmann::json* list = resolved_child(
        key, nlohmann::json(std::vector<nlohmann::json>(v.size(), nlohmann::json::object())));
    for (size_t k = 0; k < v.size(); ++k)
      out.emplace_back(v[k], name(key) + "[" + std::to_string(k) + "]", file_,
                       list != nullptr ? &(*list)[k] : nullptr);
    return out;
  }

  // Every field of the object must have been read.
  void finish() const {
    for (auto it = object_.begin(); it != object_.end(); ++it)
      if (!seen_.count(it.key()))
        fail(it.key(), "unknown field (expected one of " + join(known()) + ")");
  }

  const std::string& file() const { return file_; }
  // This object's name, kept with what was read from it for errors found later.
  FieldName field() const { return {file_, path_}; }

 private:
  // The value of a field that must be given (recorded as given unless a
  // typed read records it).
  const nlohmann::json& value_of(const std::string& key) {
    seen_.insert(key);
    if (!object_.contains(key)) {
      if (SchemaRecorder* recorder = active_schema_recorder()) recorder->missing(path_, key);
      fail(key, "missing (required)");
    }
    if (resolved_ != nullptr && !resolved_->contains(key)) (*resolved_)[key] = object_.at(key);
    return object_.at(key);
  }
  // Tells an active schema recorder (experiment_schema) how `key` is read;
  // the fragment is made only then.
  template <class MakeFragment>
  void note(const std::string& key, const MakeFragment& fragment) const {
    if (SchemaRecorder* recorder = active_schema_recorder(); recorder != nullptr && !muted_)
      recorder->note(path_, key, fragment());
  }
  // Runs a read whose own notes would be less exact than the caller's
  // (positive reads a number; a choice, a string).
  template <class Read>
  auto muted(const Read& read) -> decltype(read()) {
    const bool was = muted_;
    muted_ = true;
    struct Restore {
      bool& flag;
      bool value;
      ~Restore() { flag = value; }
    } restore{muted_, was};
    return read();
  }
  // Whether a JSON integer lies in [min, max] (an unsigned one may exceed long long).
  static bool fits(const nlohmann::json& v, long long min, long long max) {
    if (v.is_number_unsigned()) {
      const unsigned long long u = v.get<unsigned long long>();
      return (min <= 0 || u >= static_cast<unsigned long long>(min)) && max >= 0 &&
             u <= static_cast<unsigned long long>(max);
    }
    const long long x = v.get<long long>();
    return x >= min && x <= max;
  }
  std::vector<std::string> known() const { return {seen_.begin(), seen_.end()}; }
  // Where the resolved form of a nested object or list goes, set to
  // `initial`; null when nothing is recorded.
  nlohmann::json* resolved_child(const std::string& key, nlohmann::json initial) {
    if (resolved_ == nullptr) return nullptr;
    nlohmann::json* child = &(*resolved_)[key];
    *child = std::move(initial);
    return child;
  }
  // Writes a default into the resolved document; returns it.
  template <class T>
  T record(const std::string& key, T value) {
    if (resolved_ != nullptr) (*resolved_)[key] = value;
    return value;
  }
  static std::string join(const std::vector<std::string>& words) {
    std::string out;
    for (const auto& w : words) out += (out.empty() ? "" : ", ") + w;
    return out;
  }

  const nlohmann::json& object_;
  std::string path_, file_;
  std::set<std::string> seen_;
  bool muted_ = false;                  // the schema recorder hears the caller, not this read
  nlohmann::json* resolved_ = nullptr;  // not owned; null: nothing recorded
};

}  // namespace fiberfluid::experiment
