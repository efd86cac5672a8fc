#include "runs/scenario_run.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "common/errors.h"
#include "common/units.h"
#include "rigs/twin_rig.h"

namespace airtwin {

namespace {

// How long an object the perception misses stays in the plan (controller/closed_loop.h).
constexpr double kForgetAfter = 3.0;

// The observation a rig would give before anything moved: the scenario's start positions.
Observation start_observation(const Scenario& scenario) {
  Observation o;
  for (const ObjectSpec& spec : scenario.scene.objects) {
    ObservedObject obj;
    obj.id = spec.id;
    obj.type = spec.type;
    obj.p_W = spec.p_W;
    o.objects.push_back(obj);
  }
  return o;
}

}  // namespace

ScenarioRunResult run_scenario(const Scenario& scenario, const AirFieldModel& field_model,
                               const ScenarioRunOptions& options) {
  ScenarioRunResult result;
  result.scenario = scenario.name;
  result.seed = options.seed;
  result.n_objects = static_cast<int>(scenario.scene.objects.size());
  if (scenario.scene.objects.empty()) {
    throw InputError(scenario.source + ": the scenario has no objects");
  }
  // The field the controller plans with: the twin's, or the one the options give.
  const AirFieldModel& planning = options.planning_field ? *options.planning_field : field_model;

  // The nozzle starts where the controller would first aim, the jet running: the rig is ready
  // when the run begins (a plan from the start positions, with its own random stream).
  TwinParameters params = options.twin;
  {
    Controller first(planning, scenario.controller, scenario.task, options.dynamics,
                     options.seed ^ 0x5EEDF00Dull, kForgetAfter, options.planning_extensions);
    first.observe(start_observation(scenario));
    params.initial_orientation = first.decide(0.0).plan.orientation;
  }
  params.jet_on_at_start = true;
  Twin twin(scenario.scene, params, field_model, options.seed);
  twin.settle_jet();

  TruthPerception truth;
  std::unique_ptr<VisionPerception> vision;
  Perception* perception = &truth;
  if (options.vision_camera) {
    VisionPerceptionOptions vo = options.vision;
    vo.seed = options.seed;
    vision = std::make_unique<VisionPerception>(*options.vision_camera, vo);
    perception = vision.get();
    result.perception = "vision";
  }
  TwinRig rig(twin, *perception);
  RunMetrics metrics(scenario.task);
  Controller controller(planning, scenario.controller, scenario.task, options.dynamics,
                        options.seed, kForgetAfter, options.planning_extensions);
  controller.assume_nozzle(params.initial_orientation);

  // The log: one trajectory per object, a row per camera frame, the commanded orientation.
  result.log.has_group = true;
  for (size_t i = 0; i < twin.object_count(); ++i) {
    Trajectory t;
    t.id = twin.object(i).id;
    t.object = object_type_name(twin.object(i).type);
    t.group = scenario.name;
    result.log.trajectories.push_back(std::move(t));
  }
  std::vector<std::string> types;
  for (size_t i = 0; i < twin.object_count(); ++i) {
    types.push_back(object_type_name(twin.object(i).type));
  }
  std::vector<DecisionRecord> decisions_so_far;  // for the frame callback, during the run
  rig.add_frame_observer([&](const Twin& tw, int64_t frame) {
    const std::vector<ObjectMotion> motion = tw.object_states();
    std::vector<Eigen::Vector2d> p(motion.size());
    for (size_t i = 0; i < motion.size(); ++i) {
      p[i] = motion[i].p_W;
      TrajectorySample s;
      s.t_s = tw.time();
      s.p_W = p[i];
      s.nozzle = tw.commanded_orientation();
      result.log.trajectories[i].samples.push_back(s);
    }
    metrics.add_frame(p, types);
    if (options.on_frame) options.on_frame(tw, frame, decisions_so_far);
  });

  // The nozzle log: the start command, then each decision's as it is sent.
  record_command(&result.nozzle_log, twin.time(), twin.commanded_orientation());

  LoopOptions loop_options;
  loop_options.hold_s = scenario.controller.horizon_s + scenario.loop.settle_s;
  loop_options.time_limit_s = scenario.task.time_limit_s;
  result.loop = run_closed_loop(rig, controller, loop_options, [&](const DecisionRecord& d) {
    record_command(&result.nozzle_log, rig.time(), twin.commanded_orientation());
    if (options.on_frame) decisions_so_far.push_back(d);
    if (options.on_progress) options.on_progress(rig.time(), loop_options.time_limit_s);
  });

  if (vision) {
    result.vision_frames = vision->frames_processed();
    result.vision_frame_ms = vision->mean_frame_ms();
    result.vision_counters = vision->counters();
    result.vision_duplicates = vision->duplicates();
    result.vision_detections_csv = vision->detections_csv();
  }
  result.path_error_m = metrics.path_error();
  result.max_pairwise_distance_m = metrics.max_pairwise_distance_m();
  result.objects_in_zone = metrics.objects_in_zone();
  result.success = run_verdict(scenario.task.kind, result.loop.success, result.objects_in_zone,
                               result.n_objects);
  double sum = 0.0;
  for (const auto& d : result.loop.decisions) {
    sum += d.decision_ms;
    result.decision_ms_max = std::max(result.decision_ms_max, d.decision_ms);
  }
  if (!result.loop.decisions.empty()) {
    result.decision_ms_mean = sum / static_cast<double>(result.loop.decisions.size());
  }
  return result;
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

bool run_verdict(TaskKind kind, bool controller_done, int objects_in_zone, int n_objects) {
  return controller_done && (kind == TaskKind::kPath || objects_in_zone == n_objects);
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
  j["perception"] = r.perception;
  j["controller_done"] = r.loop.success;
  j["objects_seen_at_end"] = r.loop.objects_seen_at_end;
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
      "t,reference_index,ref_x,ref_y,s_x,s_y,pan_deg,tilt_deg,cost,iterations,converged,"
      "n_observed,decision_ms\n";
  char line[512];
  for (const auto& d : r.loop.decisions) {
    std::snprintf(line, sizeof line, "%.6f,%zu,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%d,%d,%d,%.3f\n",
                  d.t_s, d.reference_index, d.reference_W.x(), d.reference_W.y(),
                  d.plan.stagnation_W.x(), d.plan.stagnation_W.y(),
                  rad_to_deg(d.plan.orientation.pan_rad), rad_to_deg(d.plan.orientation.tilt_rad),
                  d.plan.cost, d.plan.iterations, d.plan.converged ? 1 : 0, d.n_observed,
                  d.decision_ms);
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
