#pragma once
// The extended model: what the controller and a replay predict with once the discrepancy analysis
// has added the causes it found. Eq. (8) coefficients per object type, the nozzle's response
// (models/nozzle_response.h) and the extensions (models/model_extensions.h); the field table stays
// the one the analysis ran with (`table`: a file, or empty for the built-in table).
//
// File: extended_model.json (docs/data_formats.md), written by `airtwin discrepancy`, read by
// `airtwin run --model`:
//   {"format": "airtwin-extended-model", "version": 1,
//    "objects": {"tracer": {"xi1": .., "xi2": .., "xi3": ..}, ...},
//    "nozzle_response": {"max_speed_radps": .., "max_acceleration_radps2": .., "transit_delay_s":
//    ..}, "extensions": {"field_scale": {"factor": 1.2}, ...},   (active ones only, typed units)
//    "table": "", "source": "data.csv"}

#include <map>
#include <string>

#include "models/field_table.h"
#include "models/model_extensions.h"
#include "models/nozzle_response.h"
#include "models/object_dynamics.h"

namespace airtwin {

struct ExtendedModel {
  std::map<std::string, ObjectDynamics> objects;
  NozzleResponseParameters nozzle;
  ModelExtensions extensions;
  std::string table;   ///< the field table file; empty: the built-in table
  std::string source;  ///< the data the extensions were found in
};

/// The JSON text (2-space indented, keys in the documented order, ends with a newline).
std::string extended_model_json(const ExtendedModel& model);
/// Whether `text` is JSON with "format": "airtwin-extended-model" (to tell it from model.json).
bool looks_like_extended_model(const std::string& text);
/// Whether the file at `path` reads as one (false when it cannot be read: its reader says why).
bool is_extended_model_file(const std::string& path);
/// Reads the file back; every problem is an InputError naming the source and the key.
ExtendedModel parse_extended_model_json(const std::string& text, const std::string& source);
ExtendedModel read_extended_model(const std::string& path);

/// The field table with every profile's air speed times `factor` (eq. (3) is linear in b1): the
/// field_scale extension for planners that take a field model only. Throws InputError unless
/// factor is finite and > 0.
FieldTable scaled_field_table(const FieldTable& table, double factor);

}  // namespace airtwin
