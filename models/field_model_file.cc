#include "models/field_model_file.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/atomic_file.h"
#include "common/errors.h"
#include "models/field_table.h"
#include "models/json_file.h"

namespace airtwin {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

constexpr const char* kFormat = "airtwin-field-model 1";

double coefficient(const Json& eq2, const char* key, const std::string& path) {
  if (!eq2.is_object() || !eq2.contains(key) || !eq2[key].is_number() ||
      !std::isfinite(eq2[key].get<double>())) {
    throw InputError(path + ": eq2." + key + ": expected a finite number");
  }
  return eq2[key].get<double>();
}

}  // namespace

bool is_field_model_file(const std::string& path) { return fs::path(path).extension() == ".json"; }

AirFieldModel read_air_field_model(const std::string& path) {
  if (!is_field_model_file(path))
    return AirFieldModel(NozzleGeometry{}, FieldTable::load_csv(path));
  const Json j = read_json_file(path);
  if (!j.is_object() || !j.contains("format") || j["format"] != kFormat) {
    throw InputError(path + ": format: expected \"" + std::string(kFormat) + "\"");
  }
  if (!j.contains("eq2")) throw InputError(path + ": missing field 'eq2'");
  NozzleGeometry geometry;
  geometry.a1 = coefficient(j["eq2"], "a1", path);
  geometry.a2 = coefficient(j["eq2"], "a2", path);
  try {
    geometry.validate();
  } catch (const InputError& e) {
    throw InputError(path + ": eq2: " + e.what());
  }
  if (!j.contains("table") || !j["table"].is_string() || j["table"].get<std::string>().empty()) {
    throw InputError(path + ": table: expected the coefficient table's file name");
  }
  const fs::path table = fs::path(path).parent_path() / j["table"].get<std::string>();
  return AirFieldModel(geometry, FieldTable::load_csv(table.string()));
}

AirFieldModel field_model_or_default(const std::string& path) {
  return path.empty() ? AirFieldModel::fitted_to_cfd() : read_air_field_model(path);
}

void write_air_field_model(const std::string& path, const NozzleGeometry& geometry,
                           const std::string& table_file) {
  const Json j = {{"format", kFormat},
                  {"eq2", {{"a1", geometry.a1}, {"a2", geometry.a2}}},
                  {"table", table_file}};
  write_file_atomically(path, j.dump(2) + "\n");
}

}  // namespace airtwin
