#pragma once
// The controller's air model as a file: eq. (3)'s coefficient table alone (a CSV, with eq. (2)'s
// a1, a2 the paper's), or a field-model JSON that adds eq. (2)'s coefficients to a table, for a
// model fitted to another jet than the paper's (docs/data_formats.md):
//
//   {"format": "airtwin-field-model 1",
//    "eq2": {"a1": 0.181, "a2": 1.334},
//    "table": "cfd_fitted_field_table.csv"}      (a path relative to the JSON file)
//
// Every command that takes --table reads either through read_air_field_model.

#include <string>

#include "models/air_field.h"
#include "models/nozzle_geometry.h"

namespace airtwin {

/// True when `path` names a field-model JSON (by its extension) rather than a table CSV.
bool is_field_model_file(const std::string& path);

/// The model a file describes: a table CSV with the paper's geometry, or a field-model JSON.
/// InputError naming the file and the field: not JSON, a wrong format, a1 or a2 missing or out of
/// range (NozzleGeometry::validate), a table that cannot be read.
AirFieldModel read_air_field_model(const std::string& path);

/// The model `path` names (read_air_field_model), or when it is empty the default one,
/// AirFieldModel::fitted_to_cfd(): what every command's --table means.
AirFieldModel field_model_or_default(const std::string& path);

/// Writes a field-model JSON at `path` naming `table_file` (written beside it by the caller) with
/// eq. (2)'s a1, a2 of `geometry`. InputError when the file cannot be written.
void write_air_field_model(const std::string& path, const NozzleGeometry& geometry,
                           const std::string& table_file);

}  // namespace airtwin
