#include "models/extended_model.h"

#include <array>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/errors.h"

namespace airtwin {
namespace {

using Json = nlohmann::ordered_json;
constexpr const char* kFormat = "airtwin-extended-model";

double number_at(const Json& j, const std::string& key, const std::string& where) {
  if (!j.is_object() || !j.contains(key)) throw InputError(where + ": missing key '" + key + "'");
  const Json& v = j.at(key);
  if (!v.is_number()) throw InputError(where + "." + key + ": expected a number");
  const double x = v.get<double>();
  if (!std::isfinite(x)) throw InputError(where + "." + key + ": not finite");
  return x;
}

}  // namespace

std::string extended_model_json(const ExtendedModel& m) {
  Json j;
  j["format"] = kFormat;
  j["version"] = 1;
  Json objects = Json::object();
  for (const auto& [name, d] : m.objects) {
    objects[name] = {{"xi1", d.xi1}, {"xi2", d.xi2}, {"xi3", d.xi3}};
  }
  j["objects"] = objects;
  j["nozzle_response"] = {{"max_speed_radps", m.nozzle.max_speed_radps},
                          {"max_acceleration_radps2", m.nozzle.max_acceleration_radps2},
                          {"transit_delay_s", m.nozzle.transit_delay_s}};
  Json ext = Json::object();
  for (const std::string& name : active_extensions(m.extensions)) {
    const EffectSpec& spec = find_effect(name);
    const std::vector<double> v = extension_values(m.extensions, name);
    Json params = Json::object();
    for (size_t i = 0; i < v.size(); ++i) params[spec.params[i].key] = v[i];
    ext[name] = params;
  }
  j["extensions"] = ext;
  j["table"] = m.table;
  j["source"] = m.source;
  return j.dump(2) + "\n";
}

bool looks_like_extended_model(const std::string& text) {
  const Json j = Json::parse(text, nullptr, /*allow_exceptions=*/false);
  return j.is_object() && j.contains("format") && j["format"] == kFormat;
}

bool is_extended_model_file(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return in && looks_like_extended_model(text.str());
}

ExtendedModel parse_extended_model_json(const std::string& text, const std::string& source) {
  Json j;
  try {
    j = Json::parse(text);
  } catch (const Json::exception& e) {
    throw InputError(source + ": not JSON (" + e.what() + ")");
  }
  if (!j.is_object() || !j.contains("format") || j["format"] != kFormat) {
    throw InputError(source + ": not an extended model (expected \"format\": \"" + kFormat + "\")");
  }
  if (!j.contains("version") || j["version"] != 1) {
    throw InputError(source + ": version: expected 1");
  }
  ExtendedModel m;
  if (!j.contains("objects") || !j["objects"].is_object() || j["objects"].empty()) {
    throw InputError(source + ": objects: expected an object with at least one type");
  }
  for (const auto& [name, d] : j["objects"].items()) {
    const std::string where = source + ": objects." + name;
    ObjectDynamics xi{number_at(d, "xi1", where), number_at(d, "xi2", where),
                      number_at(d, "xi3", where)};
    xi.validate(where);
    m.objects[name] = xi;
  }
  const std::string nr = source + ": nozzle_response";
  if (!j.contains("nozzle_response")) throw InputError(nr + ": missing");
  m.nozzle.max_speed_radps = number_at(j["nozzle_response"], "max_speed_radps", nr);
  m.nozzle.max_acceleration_radps2 = number_at(j["nozzle_response"], "max_acceleration_radps2", nr);
  m.nozzle.transit_delay_s = number_at(j["nozzle_response"], "transit_delay_s", nr);
  try {
    m.nozzle.validate();
  } catch (const InputError& e) {
    throw InputError(source + ": " + e.what());
  }
  if (!j.contains("extensions") || !j["extensions"].is_object()) {
    throw InputError(source + ": extensions: expected an object (may be empty)");
  }
  for (const auto& [name, params] : j["extensions"].items()) {
    const std::string where = source + ": extensions." + name;
    const EffectSpec* spec = nullptr;
    try {
      spec = &find_effect(name);
    } catch (const InputError& e) {
      throw InputError(where + ": " + e.what());
    }
    const std::string type = effect_object_type(name);
    if (!type.empty() && m.objects.find(type) == m.objects.end()) {
      throw InputError(where + ": no object type '" + type + "' in objects");
    }
    if (!params.is_object()) throw InputError(where + ": expected an object of parameters");
    for (const auto& [key, value] : params.items()) {
      bool known = false;
      for (const EffectParameter& p : spec->params) known = known || key == p.key;
      if (!known) throw InputError(where + ": unknown parameter '" + key + "'");
    }
    std::vector<double> v;
    for (const EffectParameter& p : spec->params) v.push_back(number_at(params, p.key, where));
    try {
      set_extension_values(&m.extensions, name, v);
    } catch (const InputError& e) {
      throw InputError(source + ": " + e.what());
    }
  }
  if (j.contains("table")) {
    if (!j["table"].is_string()) throw InputError(source + ": table: expected a string");
    m.table = j["table"].get<std::string>();
  }
  if (j.contains("source") && j["source"].is_string()) m.source = j["source"].get<std::string>();
  return m;
}

ExtendedModel read_extended_model(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_extended_model_json(text.str(), path);
}

FieldTable scaled_field_table(const FieldTable& table, double factor) {
  if (!(std::isfinite(factor) && factor > 0.0)) {
    throw InputError("field scale must be finite and > 0");
  }
  std::vector<std::array<FieldCoefficients, FieldTable::kAlphaBins>> c(table.n_tilts());
  for (size_t i = 0; i < table.n_tilts(); ++i) {
    for (int a = 0; a < FieldTable::kAlphaBins; ++a) {
      c[i][static_cast<size_t>(a)] = table.at(i, a);
      c[i][static_cast<size_t>(a)].b1 *= factor;
    }
  }
  return FieldTable(table.tilts_rad(), std::move(c));
}

}  // namespace airtwin
