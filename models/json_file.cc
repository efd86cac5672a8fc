#include "models/json_file.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include "common/errors.h"

namespace airtwin {

nlohmann::json read_json_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open");
  std::ostringstream text;
  text << in.rdbuf();
  try {
    return nlohmann::json::parse(text.str());
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path + ": not JSON (" + e.what() + ")");
  }
}

const nlohmann::json& json_member(const nlohmann::json& j, const std::string& key,
                                  const std::string& where) {
  if (!j.is_object() || !j.contains(key)) throw InputError(where + ": missing field '" + key + "'");
  return j[key];
}

double json_number(const nlohmann::json& j, const std::string& key, const std::string& where) {
  const nlohmann::json& v = json_member(j, key, where);
  if (!v.is_number() || !std::isfinite(v.get<double>())) {
    throw InputError(where + ": field '" + key + "' must be a finite number");
  }
  return v.get<double>();
}

}  // namespace airtwin
