#pragma once
// The record of one finished run of a batch: what `airtwin run` writes as summary.json (the
// summary fields of runs/scenario_run.h), plus the run's wall-clock time, or for a run whose twin
// failed (SimulationError) the error instead of the figures. One JSON file per run in the batch's
// runs/ folder (runs/batch_store.h); runs.csv and the report are made from these.
//
// Two kinds of fields. The result (success, times, errors, counts) depends on the scenario, the
// options and the seed only; the timing (wall_s, decision_ms, vision frame_ms) is wall-clock time
// of the machine that ran it and is kept apart wherever results are compared.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "runs/batch_plan.h"
#include "runs/scenario_run.h"

namespace airtwin {

struct RunRecord {
  RunKey key;
  // ---- result --------------------------------------------------------------------------------
  bool success = false;
  std::optional<double> completion_time_s;  ///< rig time when done; unset when not done
  /// Distance of the objects to the reference path over the run (cm); unset for zone tasks.
  std::optional<double> path_error_mean_cm, path_error_std_cm, path_error_max_cm;
  double max_pairwise_distance_cm = 0.0;
  int objects_in_zone = 0;
  int n_objects = 0;
  int64_t decisions = 0;
  double end_time_s = 0.0;    ///< rig time when the loop stopped (s)
  double time_limit_s = 0.0;  ///< the scenario's (s)
  /// From this time (s) to end_time_s no object moved more than 1 cm (RunMetrics); unset for a
  /// run whose twin failed, and in records written before the field existed.
  std::optional<double> still_since_s;
  std::string perception = "truth";  ///< "truth" | "vision"
  /// --vision: the tracker's counters over the run (zero otherwise).
  int64_t vision_frames = 0, vision_detections = 0, vision_tracks = 0, vision_missed = 0,
          vision_merged = 0, vision_lost = 0, vision_left_view = 0;
  /// The twin failed (the SimulationError's message); empty for a run that ended normally.
  std::string error;
  /// With objects that differ (--vary-physics): the variation, and each object's id and drawn
  /// physics ("type:key=value,...", sim/object_physics.h); empty otherwise.
  std::string physics_variation;
  std::vector<ScenarioRunResult::ObjectPhysicsRecord> object_physics;
  // ---- timing (wall clock, machine dependent) ----------------------------------------------
  double wall_s = 0.0;  ///< the whole run (s)
  double decision_ms_mean = 0.0, decision_ms_max = 0.0;
  double vision_frame_ms = 0.0;  ///< --vision: mean render + detection + tracking per frame
};

/// The record file of a finished run: run_summary_json's fields in its order, then "wall_s".
std::string record_json(const ScenarioRunResult& result, double time_limit_s, double wall_s);

/// The record file of a run whose twin failed: the same keys (success false, figures null or 0)
/// and "error": `message`.
std::string failed_record_json(const RunKey& key, int n_objects, double time_limit_s,
                               const std::string& perception, const std::string& message,
                               double wall_s);

/// Reads a record file's text. Throws InputError naming `source` and the key when the text is not
/// such a record (not JSON, a key missing or of the wrong type).
RunRecord parse_record(const std::string& text, const std::string& source);

}  // namespace airtwin
