#include "runs/scenario_run.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "common/errors.h"
#include "common/units.h"
#include "models/identified_model.h"
#include "runs/scenario_episode.h"

namespace airtwin {

ScenarioRunResult run_scenario(const Scenario& scenario, const AirFieldModel& field_model,
                               const ScenarioRunOptions& options) {
  // The episode with every command the controller's.
  ScenarioEpisode episode(scenario, field_model, options);
  while (!episode.finished()) episode.step(episode.decide());
  return episode.result();
}

void plan_with_extended_model(const ExtendedModel& model, const AirFieldModel& field,
                              ScenarioRunOptions* options) {
  for (const auto& [name, xi] : model.objects) options->dynamics[name] = xi;
  bool beyond_scale = false;
  for (const std::string& name : active_extensions(model.extensions)) {
    beyond_scale = beyond_scale || find_effect(name).id != EffectId::kFieldScale;
  }
  options->planning_field.reset();
  options->planning_extensions.reset();
  if (beyond_scale) {
    ExtendedPlanning planning;
    planning.extensions = model.extensions;
    planning.response = model.nozzle;
    options->planning_extensions = planning;
  } else if (model.extensions.field_scale != 1.0) {
    options->planning_field = std::make_shared<const AirFieldModel>(
        field.geometry(), scaled_field_table(field.table(), model.extensions.field_scale));
  }
}

void plan_with_model_files(const std::vector<std::string>& paths, const AirFieldModel& field,
                           ScenarioRunOptions* options) {
  for (const std::string& path : paths) {
    if (is_extended_model_file(path)) {
      plan_with_extended_model(read_extended_model(path), field, options);
      continue;
    }
    const IdentifiedModel model = read_identified_model(path);
    if (model.object.empty()) {
      throw InputError(path + ": the model names no object type (identify it with --object)");
    }
    options->dynamics[model.object] = model.eq8();
  }
}

std::vector<std::string> default_controller_models(bool cfd_air, bool physical_drag,
                                                   bool turbulence_swept) {
  if (!(cfd_air && physical_drag)) return {};
  if (!turbulence_swept) return {AIRTWIN_MODEL_DATA_DIR "/twin_lagrangian/extended_model.json"};
  return {AIRTWIN_MODEL_DATA_DIR "/twin/extended_model.json"};
}

bool run_verdict(TaskKind kind, bool controller_done, int objects_in_zone, int n_objects) {
  return controller_done && (kind == TaskKind::kPath || objects_in_zone == n_objects);
}

bool run_stalled(bool success, double end_time_s, double still_since_s) {
  return !success && end_time_s - still_since_s >= kStalledSpan_s;
}

std::string run_summary_json(const ScenarioRunResult& r, double time_limit_s) {
  using nlohmann::ordered_json;
  ordered_json j;
  j["scenario"] = r.scenario;
  j["seed"] = r.seed;
  j["success"] = r.success;
  j["completion_time_s"] = r.success && r.loop.completion_time_s
                               ? ordered_json(*r.loop.completion_time_s)
                               : ordered_json(nullptr);
  if (r.path_error_m.count > 0) {
    j["path_error_cm"] = {{"mean", 100.0 * r.path_error_m.mean},
                          {"std", 100.0 * r.path_error_m.std},
                          {"max", 100.0 * r.path_error_m.max}};
  } else {
    j["path_error_cm"] = nullptr;
  }
  j["max_pairwise_distance_cm"] = 100.0 * r.max_pairwise_distance_m;
  j["objects_in_zone"] = r.objects_in_zone;
  j["n_objects"] = r.n_objects;
  j["decisions"] = r.loop.decisions.size();
  j["decision_ms"] = {{"mean", r.decision_ms_mean}, {"max", r.decision_ms_max}};
  j["end_time_s"] = r.loop.end_time_s;
  j["time_limit_s"] = time_limit_s;
  j["still_since_s"] = r.still_since_s;
  j["perception"] = r.perception;
  j["controller_done"] = r.loop.success;
  j["objects_seen_at_end"] = r.loop.objects_seen_at_end;
  j["lost_every_object"] = r.loop.lost_every_object;
  if (!r.physics_variation.empty()) {
    j["physics_variation"] = r.physics_variation;
    ordered_json objects = ordered_json::object();
    for (const auto& o : r.object_physics) objects[o.id] = o.physics;
    j["object_physics"] = objects;
  }
  if (r.perception == "vision") {
    const TrackerCounters& c = r.vision_counters;
    j["vision"] = {{"frames", r.vision_frames},
                   {"frame_ms", r.vision_frame_ms},
                   {"detections", c.detections},
                   {"tracks", c.new_tracks},
                   {"missed", c.missed},
                   {"merged", c.merged},
                   {"lost", c.lost},
                   {"left_view", c.left_view},
                   {"entered_view", c.entered_view},
                   {"duplicates", r.vision_duplicates}};
  }
  return j.dump(2) + "\n";
}

std::string decisions_csv(const ScenarioRunResult& r) {
  std::string out =
      "t,reference_index,ref_x,ref_y,s_x,s_y,pan_deg,tilt_deg,cost,iterations,converged,sweep,"
      "rescue,n_observed,decision_ms\n";
  char line[512];
  for (const auto& d : r.loop.decisions) {
    // sweep: 1 when the sweep clearance blocked every push and the decision is the paper's
    // (controller/cem_planner.h), else 0.
    // rescue: 1 when the line search was blind and the floor was scanned for a push that does
    // not spread the objects (controller/cem_planner.h), else 0.
    const int sweep = d.plan.sweep_blocked ? 1 : 0;
    const int rescue = d.plan.blind_scan ? 1 : 0;
    std::snprintf(line, sizeof line,
                  "%.6f,%zu,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%d,%d,%d,%d,%d,%.3f\n", d.t_s,
                  d.reference_index, d.reference_W.x(), d.reference_W.y(), d.plan.stagnation_W.x(),
                  d.plan.stagnation_W.y(), rad_to_deg(d.plan.orientation.pan_rad),
                  rad_to_deg(d.plan.orientation.tilt_rad), d.plan.cost, d.plan.iterations,
                  d.plan.converged ? 1 : 0, sweep, rescue, d.n_observed, d.decision_ms);
    out += line;
  }
  return out;
}

std::string plans_csv(const ScenarioRunResult& r) {
  std::string out = "t,id,type,seen,x,y,vx,vy,end_x,end_y\n";
  char line[512];
  for (const auto& d : r.loop.decisions) {
    for (size_t j = 0; j < d.objects.size(); ++j) {
      const ObservedObject& o = d.objects[j];
      const Eigen::Vector2d end =
          j < d.plan.predicted_end_W.size() ? d.plan.predicted_end_W[j] : o.p_W;
      std::snprintf(line, sizeof line, "%.6f,", d.t_s);
      out += line;
      out += o.id;
      out += ',';
      out += o.type;
      std::snprintf(line, sizeof line, ",%d,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f\n",
                    j < d.seen.size() ? static_cast<int>(d.seen[j]) : 1, o.p_W.x(), o.p_W.y(),
                    o.v_W.x(), o.v_W.y(), end.x(), end.y());
      out += line;
    }
  }
  return out;
}

}  // namespace airtwin
