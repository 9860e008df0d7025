// SPDX-License-Identifier: GPL-3.0-or-later
// An enum's values and their names, listed once. The name of a value, the
// value of a name (an unknown name is refused, listing the names), and the
// names a reader offers all come from the one list, so that a value cannot
// be read under one name and written under another, nor an unlisted name
// read as some default.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "fiberfluid/util/error.hpp"

namespace fiberfluid {

// One value and its name.
template <class Enum>
struct Named {
  Enum value;
  const char* name;
};

template <class Enum, std::size_t N>
class Names {
 public:
  constexpr explicit Names(std::array<Named<Enum>, N> entries) : entries_(entries) {}

  // "?" for a value the list lacks (a defect: every value is listed).
  constexpr const char* name(Enum value) const {
    for (const Named<Enum>& entry : entries_)
      if (entry.value == value) return entry.name;
    return "?";
  }
  std::optional<Enum> find(const std::string& name) const {
    for (const Named<Enum>& entry : entries_)
      if (name == entry.name) return entry.value;
    return std::nullopt;
  }
  // The value named `name`; InputError "what: expected a, b or c, got ..." else.
  Enum parse(const std::string& name, const std::string& what) const {
    if (const std::optional<Enum> value = find(name)) return *value;
    throw InputError(what + ": expected " + listed() + ", got \"" + name.substr(0, 40) + "\"");
  }
  std::vector<std::string> all() const {
    std::vector<std::string> names;
    for (const auto& entry : entries_) names.emplace_back(entry.name);
    return names;
  }
  // "a, b or c".
  std::string listed() const {
    std::string text;
    for (std::size_t i = 0; i < N; ++i)
      text += (i == 0 ? "" : i + 1 == N ? " or " : ", ") + std::string(entries_[i].name);
    return text;
  }
  const std::array<Named<Enum>, N>& entries() const { return entries_; }

 private:
  std::array<Named<Enum>, N> entries_;
};

// Names<Enum, N> from a braced list of {value, name} pairs: names_of<Enum>({{...}, ...}).
template <class Enum, std::size_t N>
constexpr Names<Enum, N> names_of(const Named<Enum> (&entries)[N]) {
  std::array<Named<Enum>, N> a{};
  for (std::size_t i = 0; i < N; ++i) a[i] = entries[i];
  return Names<Enum, N>(a);
}

}  // namespace fiberfluid
