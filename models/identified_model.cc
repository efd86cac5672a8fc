#include "models/identified_model.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "common/csv.h"
#include "common/errors.h"

namespace airtwin {
namespace {

using json = nlohmann::ordered_json;

json coefficient_array(const IdentifiedModel::Coefficients& c) {
  json a = json::array();
  for (int j = 0; j < kSindyTerms; ++j) a.push_back(c[j]);
  return a;
}

json optional_number(const std::optional<double>& v) {
  if (v && std::isfinite(*v)) return *v;
  return nullptr;
}

// A tilt as a JSON key: "0", "22.5".
std::string tilt_key(double tilt_deg) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", tilt_deg);
  return buf;
}

}  // namespace

bool IdentifiedModel::is_eq8() const {
  for (int j = 0; j < kSindyTerms; ++j)
    if (j != kTermConstant && j != kTermV && j != kTermVair && coefficients[j] != 0.0) return false;
  return true;
}

std::string IdentifiedModel::eq8_note() const {
  if (is_eq8()) return "";
  std::string extra;
  for (int j = 3; j < kSindyTerms; ++j)
    if (coefficients[j] != 0.0) extra += std::string(extra.empty() ? "" : ", ") + kTermNames[j];
  return "the identified model has terms beyond eq. (8) (" + extra +
         "); the predictors use eq. (8): dv/dt = xi1 v + xi2 vair + xi3";
}

ObjectDynamics IdentifiedModel::eq8() const {
  if (!is_eq8()) throw InputError(eq8_note());
  return {coefficients[kTermV], coefficients[kTermVair], coefficients[kTermConstant]};
}

std::string identified_model_json(const IdentifiedModel& m) {
  json j;
  j["object"] = m.object.empty() ? json(nullptr) : json(m.object);
  j["method"] = m.method;
  j["terms"] = json::array();
  for (const char* name : kTermNames) j["terms"].push_back(name);
  j["coefficients"] = coefficient_array(m.coefficients);
  j["discrete_coefficients"] = coefficient_array(m.discrete);
  j["inclusion_probability"] = coefficient_array(m.inclusion);
  j["r2"] = m.r2;
  j["end_position_mape"] = optional_number(m.end_position_mape_pct);
  j["n_samples"] = m.n_samples;
  j["n_dropped"] = m.n_dropped;
  if (m.is_eq8()) {
    j["eq8"] = {{"xi1", m.coefficients[kTermV]},
                {"xi2", m.coefficients[kTermVair]},
                {"xi3", m.coefficients[kTermConstant]}};
  } else {
    j["eq8"] = nullptr;
  }
  j["r2_change"] = m.r2_change;
  json by_tilt = json::object();
  for (const auto& [tilt, mape] : m.end_position_mape_by_tilt_pct) by_tilt[tilt_key(tilt)] = mape;
  j["end_position_mape_by_tilt"] = by_tilt;
  json by_sector = json::object();
  for (const auto& [tilt, sectors] : m.end_position_by_sector) {
    json per = json::object();
    for (const PlacementSectorInfo& info : kPlacementSectorCatalogue) {
      const SectorFigures& f = sectors[static_cast<size_t>(info.sector)];
      per[info.name] = {{"n", f.n},
                        {"mape", f.n ? json(f.mape_pct) : json(nullptr)},
                        {"predicted_rest", f.n_predicted_rest}};
    }
    by_sector[tilt_key(tilt)] = per;
  }
  j["end_position_by_sector"] = by_sector;
  j["n_mape_trajectories"] = m.n_mape_trajectories;
  j["n_mape_excluded"] = m.n_mape_excluded;
  json moved = json::object();
  for (const auto& [tilt, counts] : m.moved_by_tilt)
    moved[tilt_key(tilt)] = {counts.first, counts.second};
  j["moved_by_tilt"] = moved;
  j["n_pairs"] = m.n_pairs;
  j["n_trajectories"] = m.n_trajectories;
  j["n_glitches_repaired"] = m.n_glitches_repaired;
  j["n_short_trajectories"] = m.n_short_trajectories;
  j["n_off_radial"] = m.n_off_radial;
  j["n_transient"] = m.n_transient;
  j["transient_s"] = m.transient_s;
  j["dt_s"] = m.dt_s;
  j["lambda"] = m.lambda;
  j["library"] = m.library;
  j["bootstraps"] = m.bootstraps;
  j["seed"] = m.seed;
  j["smoothing_half_window"] = m.smoothing_half_window;
  j["position_noise_m"] = m.position_noise_m;
  j["positions_smoothed"] = m.positions_smoothed;
  j["stationary_speed_mps"] = m.stationary_speed_mps;
  j["speed_noise_mps"] = m.speed_noise_mps;
  j["n_negative_speeds"] = m.n_negative_speeds;
  j["source"] = m.source;
  return j.dump(2) + "\n";
}

IdentifiedModel read_identified_model(const std::string& path) {
  return parse_identified_model_json(read_text_file(path), path);
}

IdentifiedModel parse_identified_model_json(const std::string& text, const std::string& source) {
  const json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) {
    throw InputError(source + ": not a JSON object (expected a model.json of airtwin identify)");
  }
  auto need = [&](const char* key) -> const json& {
    if (!j.contains(key)) throw InputError(source + ": key '" + key + "' is missing");
    return j.at(key);
  };
  auto number = [&](const json& v, const std::string& key) {
    if (!v.is_number() || !std::isfinite(v.get<double>())) {
      throw InputError(source + ": key '" + key + "': expected a finite number");
    }
    return v.get<double>();
  };
  auto count = [&](const char* key) -> size_t {
    if (!j.contains(key)) return 0;
    if (!j.at(key).is_number_unsigned()) {
      throw InputError(source + ": key '" + key + "': expected a non-negative integer");
    }
    return j.at(key).get<size_t>();
  };
  auto coefficients = [&](const char* key) {
    const json& a = need(key);
    if (!a.is_array() || a.size() != kSindyTerms) {
      throw InputError(source + ": key '" + key + "': expected an array of " +
                       std::to_string(kSindyTerms) + " numbers");
    }
    IdentifiedModel::Coefficients c;
    for (int i = 0; i < kSindyTerms; ++i)
      c[i] = number(a[i], std::string(key) + "[" + std::to_string(i) + "]");
    return c;
  };

  IdentifiedModel m;
  const json& terms = need("terms");
  if (!terms.is_array() || terms.size() != kSindyTerms) {
    throw InputError(source + ": key 'terms': expected the " + std::to_string(kSindyTerms) +
                     " library terms");
  }
  for (int i = 0; i < kSindyTerms; ++i) {
    if (!terms[i].is_string() || terms[i].get<std::string>() != kTermNames[i]) {
      throw InputError(source + ": key 'terms'[" + std::to_string(i) + "]: expected '" +
                       kTermNames[i] + "'");
    }
  }
  m.coefficients = coefficients("coefficients");
  if (j.contains("discrete_coefficients")) m.discrete = coefficients("discrete_coefficients");
  if (j.contains("inclusion_probability")) m.inclusion = coefficients("inclusion_probability");
  const json& object = need("object");
  if (!object.is_null() && !object.is_string()) {
    throw InputError(source + ": key 'object': expected a string or null");
  }
  if (object.is_string()) m.object = object.get<std::string>();
  if (j.contains("method") && j.at("method").is_string()) m.method = j.at("method");
  if (j.contains("r2")) m.r2 = number(j.at("r2"), "r2");
  if (j.contains("r2_change")) m.r2_change = number(j.at("r2_change"), "r2_change");
  if (j.contains("end_position_mape") && !j.at("end_position_mape").is_null()) {
    m.end_position_mape_pct = number(j.at("end_position_mape"), "end_position_mape");
  }
  m.n_samples = count("n_samples");
  m.n_dropped = count("n_dropped");
  m.n_pairs = count("n_pairs");
  m.n_trajectories = count("n_trajectories");
  m.n_glitches_repaired = count("n_glitches_repaired");
  m.n_short_trajectories = count("n_short_trajectories");
  m.n_off_radial = count("n_off_radial");
  m.n_transient = count("n_transient");
  m.n_mape_trajectories = count("n_mape_trajectories");
  m.n_mape_excluded = count("n_mape_excluded");
  if (j.contains("dt_s")) m.dt_s = number(j.at("dt_s"), "dt_s");
  if (j.contains("lambda")) m.lambda = number(j.at("lambda"), "lambda");
  // Files written before the key existed used the whole library.
  m.library.assign(kTermNames.begin(), kTermNames.end());
  if (j.contains("library")) {
    const auto& lib = j.at("library");
    bool ok = lib.is_array() && !lib.empty();
    std::vector<std::string> names;
    for (const auto& t : lib) {
      if (!t.is_string() || std::find(kTermNames.begin(), kTermNames.end(), t.get<std::string>()) ==
                                kTermNames.end()) {
        ok = false;
        break;
      }
      names.push_back(t.get<std::string>());
    }
    if (!ok) throw InputError(source + ": key 'library': expected a list of library term names");
    m.library = names;
  }
  if (j.contains("source") && j.at("source").is_string()) m.source = j.at("source");
  return m;
}

}  // namespace airtwin
