#include "runs/batch_manifest.h"

#include <limits>

#include "common/errors.h"

namespace airtwin {

using nlohmann::ordered_json;

namespace {

// The manifest's format name; a later incompatible layout gets a new one.
constexpr const char* kFormat = "airtwin batch 1";

// `j` without the "file" keys, at any depth: what comparisons look at.
ordered_json without_files(const ordered_json& j) {
  if (j.is_object()) {
    ordered_json out = ordered_json::object();
    for (auto it = j.begin(); it != j.end(); ++it) {
      if (it.key() != "file") out[it.key()] = without_files(it.value());
    }
    return out;
  }
  if (j.is_array()) {
    ordered_json out = ordered_json::array();
    for (const ordered_json& v : j) out.push_back(without_files(v));
    return out;
  }
  return j;
}

ordered_json manifest_json(const BatchManifest& m, bool with_shard) {
  ordered_json j;
  j["format"] = kFormat;
  j["scenarios"] = ordered_json::array();
  for (const BatchManifest::Entry& e : m.scenarios) {
    j["scenarios"].push_back(
        {{"name", e.name}, {"file", e.file}, {"content_hash", e.content_hash}});
  }
  j["seeds"] = {{"first", m.first_seed}, {"count", m.seed_count}};
  if (with_shard) j["shard"] = {{"index", m.shard.index}, {"count", m.shard.count}};
  j["settings"] = m.settings;
  return j;
}

std::vector<std::string> names_of(const BatchManifest& m) {
  std::vector<std::string> names;
  for (const BatchManifest::Entry& e : m.scenarios) names.push_back(e.name);
  return names;
}

}  // namespace

BatchManifest BatchManifest::of_plan(const BatchPlan& plan, ordered_json settings) {
  BatchManifest m;
  for (const BatchScenario& s : plan.scenarios) {
    m.scenarios.push_back({s.scenario.name, s.file, s.content_hash});
  }
  m.first_seed = plan.first_seed;
  m.seed_count = plan.seed_count;
  m.shard = plan.shard;
  m.settings = std::move(settings);
  return m;
}

std::vector<RunKey> BatchManifest::all_runs() const {
  return plan_runs(names_of(*this), first_seed, seed_count, Shard{});
}

std::vector<RunKey> BatchManifest::shard_runs() const {
  return plan_runs(names_of(*this), first_seed, seed_count, shard);
}

std::string BatchManifest::to_json() const { return manifest_json(*this, true).dump(2) + "\n"; }

BatchManifest BatchManifest::parse(const std::string& text, const std::string& source) {
  const ordered_json j = ordered_json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) {
    throw InputError(source + ": not a batch manifest (expected a JSON object)");
  }
  if (!j.contains("format") || j["format"] != kFormat) {
    throw InputError(source + ": not a batch manifest of this airtwin (expected format '" +
                     std::string(kFormat) + "')");
  }
  try {
    BatchManifest m;
    for (const ordered_json& e : j.at("scenarios")) {
      m.scenarios.push_back({e.at("name").get<std::string>(), e.at("file").get<std::string>(),
                             e.at("content_hash").get<std::string>()});
    }
    const auto whole = [&](const char* section, const char* name, uint64_t max) {
      const ordered_json& v = j.at(section).at(name);
      if (!v.is_number_unsigned() || v.get<uint64_t>() > max) {
        throw InputError(source + ": batch manifest: " + section + "." + name +
                         " must be a whole number in [0, " + std::to_string(max) + "]");
      }
      return v.get<uint64_t>();
    };
    constexpr uint64_t kIntMax = std::numeric_limits<int>::max();
    m.first_seed = whole("seeds", "first", std::numeric_limits<uint64_t>::max());
    m.seed_count = static_cast<int>(whole("seeds", "count", kIntMax));
    m.shard.index = static_cast<int>(whole("shard", "index", kIntMax));
    m.shard.count = static_cast<int>(whole("shard", "count", kIntMax));
    m.settings = j.at("settings");
    if (m.seed_count < 1 || m.shard.count < 1 || m.shard.index < 0 ||
        m.shard.index >= m.shard.count) {
      throw InputError(source + ": batch manifest: seeds or shard out of range");
    }
    return m;
  } catch (const nlohmann::json::exception& e) {
    throw InputError(source + ": batch manifest: a key is missing or of the wrong type (" +
                     std::string(e.what()) + ")");
  }
}

ordered_json BatchManifest::identity(bool with_shard) const {
  return without_files(manifest_json(*this, with_shard));
}

std::string BatchManifest::difference(const BatchManifest& other, bool ignore_shard) const {
  const ordered_json a = identity(!ignore_shard);
  const ordered_json b = other.identity(!ignore_shard);
  if (a == b) return "";
  // The first change of a JSON patch from a to b names the key; show both values there.
  const ordered_json patch = ordered_json::diff(a, b);
  const std::string path = patch.at(0).at("path").get<std::string>();
  const ordered_json::json_pointer pointer(path);
  const auto value_at = [&](const ordered_json& j) -> std::string {
    try {
      return j.at(pointer).dump();
    } catch (const nlohmann::json::exception&) {
      return "(none)";
    }
  };
  return path + ": " + value_at(a) + " vs " + value_at(b);
}

}  // namespace airtwin
