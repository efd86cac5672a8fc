#pragma once
// Reading the project's JSON files with one clear error per fault: the file, the field and what
// was expected (InputError).

#include <nlohmann/json.hpp>
#include <string>

namespace airtwin {

/// The parsed file. InputError "<path>: cannot open" or "<path>: not JSON (...)".
nlohmann::json read_json_file(const std::string& path);
/// j[key]. InputError "<where>: missing field '<key>'" when j is not an object or lacks it.
const nlohmann::json& json_member(const nlohmann::json& j, const std::string& key,
                                  const std::string& where);
/// j[key] as a finite number. InputError naming `where` and the field otherwise.
double json_number(const nlohmann::json& j, const std::string& key, const std::string& where);

}  // namespace airtwin
