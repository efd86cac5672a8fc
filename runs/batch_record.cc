#include "runs/batch_record.h"

#include <limits>
#include <nlohmann/json.hpp>

#include "common/errors.h"

namespace airtwin {

using nlohmann::ordered_json;

std::string record_json(const ScenarioRunResult& result, double time_limit_s, double wall_s) {
  // The summary exactly as `airtwin run` writes it, with the run's wall time after it.
  ordered_json j = ordered_json::parse(run_summary_json(result, time_limit_s));
  j["wall_s"] = wall_s;
  return j.dump(2) + "\n";
}

std::string failed_record_json(const RunKey& key, int n_objects, double time_limit_s,
                               const std::string& perception, const std::string& message,
                               double wall_s) {
  ordered_json j;
  j["scenario"] = key.scenario;
  j["seed"] = key.seed;
  j["success"] = false;
  j["completion_time_s"] = nullptr;
  j["path_error_cm"] = nullptr;
  j["max_pairwise_distance_cm"] = 0.0;
  j["objects_in_zone"] = 0;
  j["n_objects"] = n_objects;
  j["decisions"] = 0;
  j["decision_ms"] = {{"mean", 0.0}, {"max", 0.0}};
  j["end_time_s"] = 0.0;
  j["time_limit_s"] = time_limit_s;
  j["still_since_s"] = nullptr;
  j["perception"] = perception;
  j["controller_done"] = false;
  j["objects_seen_at_end"] = 0;
  j["lost_every_object"] = false;
  j["error"] = message;
  j["wall_s"] = wall_s;
  return j.dump(2) + "\n";
}

RunRecord parse_record(const std::string& text, const std::string& source) {
  const ordered_json j = ordered_json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) {
    throw InputError(source + ": not a run record (expected a JSON object)");
  }
  // Typed access with the key named in the message.
  std::string key;
  try {
    const auto number = [&](const ordered_json& parent, const char* name) {
      key = name;
      const ordered_json& v = parent.at(name);
      if (!v.is_number()) throw InputError(source + ": '" + key + "' must be a number");
      return v.get<double>();
    };
    const auto optional_number = [&](const ordered_json& parent,
                                     const char* name) -> std::optional<double> {
      key = name;
      if (parent.at(name).is_null()) return std::nullopt;
      return number(parent, name);
    };
    const auto count = [&](const ordered_json& parent, const char* name, int64_t max) {
      key = name;
      const ordered_json& v = parent.at(name);
      if (!v.is_number_integer() || v.get<int64_t>() < 0 || v.get<int64_t>() > max) {
        throw InputError(source + ": '" + key + "' must be a whole number in [0, " +
                         std::to_string(max) + "]");
      }
      return v.get<int64_t>();
    };
    constexpr int64_t kIntMax = std::numeric_limits<int>::max();
    constexpr int64_t kInt64Max = std::numeric_limits<int64_t>::max();
    RunRecord r;
    key = "scenario";
    r.key.scenario = j.at("scenario").get<std::string>();
    key = "seed";
    if (!j.at("seed").is_number_unsigned()) {
      throw InputError(source + ": 'seed' must be a whole number >= 0");
    }
    r.key.seed = j.at("seed").get<uint64_t>();
    key = "success";
    r.success = j.at("success").get<bool>();
    r.completion_time_s = optional_number(j, "completion_time_s");
    key = "path_error_cm";
    if (!j.at("path_error_cm").is_null()) {
      const ordered_json& e = j.at("path_error_cm");
      r.path_error_mean_cm = number(e, "mean");
      r.path_error_std_cm = number(e, "std");
      r.path_error_max_cm = number(e, "max");
    }
    r.max_pairwise_distance_cm = number(j, "max_pairwise_distance_cm");
    r.objects_in_zone = static_cast<int>(count(j, "objects_in_zone", kIntMax));
    r.n_objects = static_cast<int>(count(j, "n_objects", kIntMax));
    r.decisions = count(j, "decisions", kInt64Max);
    r.decision_ms_mean = number(j.at("decision_ms"), "mean");
    r.decision_ms_max = number(j.at("decision_ms"), "max");
    r.end_time_s = number(j, "end_time_s");
    r.time_limit_s = number(j, "time_limit_s");
    // Optional: a batch resumed from records of an earlier airtwin has them without it.
    if (j.contains("still_since_s")) r.still_since_s = optional_number(j, "still_since_s");
    key = "perception";
    r.perception = j.at("perception").get<std::string>();
    if (j.contains("vision")) {
      const ordered_json& v = j.at("vision");
      r.vision_frames = count(v, "frames", kInt64Max);
      r.vision_frame_ms = number(v, "frame_ms");
      r.vision_detections = count(v, "detections", kInt64Max);
      r.vision_tracks = count(v, "tracks", kInt64Max);
      r.vision_missed = count(v, "missed", kInt64Max);
      r.vision_merged = count(v, "merged", kInt64Max);
      r.vision_lost = count(v, "lost", kInt64Max);
      r.vision_left_view = count(v, "left_view", kInt64Max);
    }
    key = "error";
    if (j.contains("error")) r.error = j.at("error").get<std::string>();
    key = "physics_variation";
    if (j.contains("physics_variation")) {
      r.physics_variation = j.at("physics_variation").get<std::string>();
      key = "object_physics";
      for (const auto& [id, physics] : j.at("object_physics").items()) {
        r.object_physics.push_back({id, physics.get<std::string>()});
      }
    }
    r.wall_s = number(j, "wall_s");
    return r;
  } catch (const nlohmann::json::exception&) {
    throw InputError(source + ": run record: '" + key + "' is missing or of the wrong type");
  }
}

}  // namespace airtwin
