// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Reading an experiment document: JSON text parsed (refusing what nlohmann
// would take silently), then every field checked that needs no mesh; no file
// is opened. One reader per section (read/readers.hpp) fills the spec.

#include <filesystem>
#include <istream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fiberfluid/experiment/spec/experiment.hpp"

namespace fiberfluid::experiment {

// The fields of an experiment file that belong to the whole experiment
// (name, variants, fit, ...): a variant cannot change them.
const std::vector<std::string>& experiment_wide_fields();

// The deepest nesting of arrays and objects a JSON document may have: an
// experiment needs a handful; a deeper one is refused while it is parsed,
// before anything copies it (copies recurse).
constexpr int kDeepestJson = 64;
// Parses JSON text, refusing documents nested deeper than kDeepestJson and
// syntax errors with an InputError naming `label`.
nlohmann::json parse_json(std::istream& in, const std::string& label);
nlohmann::json parse_json(const std::string& text, const std::string& label);

// The first phase of parse_experiment (experiment.hpp): checks every field
// that needs no mesh and opens no file; the cases stay unbuilt until
// build_experiment.
Experiment read_experiment(const nlohmann::json& document, const std::filesystem::path& folder,
                           const std::string& label);

}  // namespace fiberfluid::experiment
