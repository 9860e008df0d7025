// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The experiment file's JSON Schema, generated from the reader itself:
// experiment_schema() runs the reader (with a SchemaRecorder active,
// schema_recorder.hpp) over a document that has every section and then over
// every alternative of every choice it met, so that each branch's fields are
// read, and turns what was recorded into a schema (draft 2020-12). The schema
// is therefore as strict as the reader (unknown fields are refused) and
// cannot fall behind it.

#include <nlohmann/json.hpp>

namespace fiberfluid::experiment {

// The experiment file's JSON Schema (what `fiberfluid schema` prints).
nlohmann::json experiment_schema();

}  // namespace fiberfluid::experiment
