#pragma once
// One closed-loop run of a scenario in the twin: the scenario's objects in a twin seeded with
// `seed`, the CEM controller (controller/closed_loop.h) planning on the field model and the
// identified dynamics, the twin rig in between, and the judge's figures from the twin's truth
// (controller/run_metrics.h). What `airtwin run` writes, and what a batch runs many times: a run
// depends on its scenario, options and seed only (not on the thread it runs in).

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "controller/closed_loop.h"
#include "controller/run_metrics.h"
#include "models/air_field.h"
#include "models/extended_model.h"
#include "models/nozzle_log.h"
#include "models/object_dynamics.h"
#include "models/trajectory_data.h"
#include "rigs/vision_perception.h"
#include "scenes/scenario.h"
#include "sim/physics_variation.h"
#include "sim/twin.h"
#include "vision/calibrated_camera.h"

namespace airtwin {

struct ScenarioRunOptions {
  uint64_t seed = 0;
  /// The twin's fixed physics (defaults: the calibrated twin of docs/twin.md).
  TwinParameters twin;
  /// Active: each object gets its own physics drawn from `seed` (sim/physics_variation.h)
  /// around or instead of its type's in `twin.scene`.
  PhysicsVariation physics_variation;
  /// eq. (8) coefficients the controller plans with, per object type (defaults: the paper's).
  std::map<std::string, ObjectDynamics> dynamics = {{"tracer", kTracerDynamics},
                                                    {"cotton", kCottonDynamics}};
  /// Set: the controller plans with this field instead of the twin's (an extended model's
  /// field_scale, models/extended_model.h); unset: with the twin's field model.
  std::shared_ptr<const AirFieldModel> planning_field;
  /// Set: the controller predicts with an extended model's extensions and nozzle response
  /// (controller/cem_planner.h) on the planning field.
  std::optional<ExtendedPlanning> planning_extensions;
  /// Threads that predict each decision's candidates (CemPlanner::set_threads): the same
  /// decisions for any number, in less wall-clock time on a machine with the cores.
  int planner_threads = 1;
  /// Set: the controller sees through the detection pipeline with this calibrated camera
  /// (`--vision`); unset: the twin's truth (fast mode).
  std::optional<CalibratedCamera> vision_camera;
  VisionPerceptionOptions vision;
  /// Called every camera frame (after the observers below), e.g. for a video.
  std::function<void(const Twin&, int64_t frame, const std::vector<DecisionRecord>& decisions)>
      on_frame;
  /// Called after each decision with the rig time and the time limit (progress display).
  std::function<void(double t_s, double limit_s)> on_progress;
};

struct ScenarioRunResult {
  std::string scenario;
  uint64_t seed = 0;
  LoopResult loop;
  /// The run's verdict, run_verdict() below. With --vision the controller judges from what it
  /// detects, and that can disagree with the truth.
  bool success = false;
  ErrorStats path_error_m;
  double max_pairwise_distance_m = 0.0;
  int objects_in_zone = 0;
  int n_objects = 0;
  /// With ScenarioRunOptions::physics_variation active: its text, and each object's id and the
  /// physics it was given ("tracer:mass_g=...,cd=...", sim/object_physics.h); empty otherwise.
  std::string physics_variation;
  struct ObjectPhysicsRecord {
    std::string id;
    std::string physics;
  };
  std::vector<ObjectPhysicsRecord> object_physics;
  /// From this time (s) to the run's end no object moved more than 1 cm (RunMetrics).
  double still_since_s = 0.0;
  double decision_ms_mean = 0.0, decision_ms_max = 0.0;
  /// "truth" or "vision"; for vision, the pipeline's figures.
  std::string perception = "truth";
  int64_t vision_frames = 0;
  double vision_frame_ms = 0.0;
  TrackerCounters vision_counters;
  int64_t vision_duplicates = 0;  ///< tracks withheld as duplicates (rigs/vision_perception.h)
  /// With vision: the detections of every processed frame, as `detect` writes them
  /// (VisionPerception::detections_csv); empty otherwise.
  std::string vision_detections_csv;
  /// Every object's true position every camera frame, with the commanded nozzle orientation:
  /// the trajectory CSV of docs/data_formats.md (group = scenario name).
  TrajectorySet log;
  /// The commands sent to the twin's nozzle: the start orientation at the first frame's time,
  /// then every decision's command at its time, as it changed (models/nozzle_log.h). The frame at
  /// a decision's time was taken before the command was sent: log's row there holds the previous
  /// command, the nozzle log's reading (in force from its time) the new one.
  std::vector<NozzleCommand> nozzle_log;
};

/// The controller of `options` plans with an extended model (extended_model.json from the
/// discrepancy analysis): its eq. (8) coefficients per object type, and its extensions. A
/// field_scale alone keeps the fast predictor on `field`'s table with the air speeds scaled; any
/// other extension makes the controller predict with the extended model and its nozzle response
/// (controller/cem_planner.h). Replaces what an earlier extended model set.
void plan_with_extended_model(const ExtendedModel& model, const AirFieldModel& field,
                              ScenarioRunOptions* options);

/// The controller of `options` plans with the model files `paths`, in order, on `field`: a
/// model.json from `airtwin identify` sets its object type's eq. (8) coefficients; an
/// extended_model.json from `airtwin discrepancy` is plan_with_extended_model's. Throws
/// InputError for an unreadable model or one that names no object type.
void plan_with_model_files(const std::vector<std::string>& paths, const AirFieldModel& field,
                           ScenarioRunOptions* options);

/// The model files the controller plans with unless its user names others: in the physical twin
/// (the CFD's air and physical drag) the models fitted to it the way a rig's user fits theirs
/// (models/data/twin/extended_model.json, scripts/fit_twin_models.sh; docs/twin.md), with the
/// turbulence's Lagrangian time alone (AirForceParameters::turbulence_swept false) those fitted
/// to that twin (models/data/twin_lagrangian/); in any other twin none, i.e. the paper's eq. (8).
/// The CLI and the Python module share this rule.
std::vector<std::string> default_controller_models(bool cfd_air, bool physical_drag,
                                                   bool turbulence_swept = true);

/// A run succeeded when the controller saw its task done and, for a zone task (aggregation,
/// sorting), the twin's truth agrees at that moment: all n_objects in their zones.
bool run_verdict(TaskKind kind, bool controller_done, int objects_in_zone, int n_objects);

/// A failed run whose objects moved no more than 1 cm over its last this many seconds
/// (ScenarioRunResult::still_since_s) stalled: the controller's pushes moved nothing, rather than
/// time running out while they progressed. Three decisions' holds (1.8 s each) less a frame.
inline constexpr double kStalledSpan_s = 5.0;

/// The run failed and its objects had been still (RunMetrics) for kStalledSpan_s at its end.
bool run_stalled(bool success, double end_time_s, double still_since_s);

/// Runs `scenario` in the twin under `field_model`. Throws InputError for unusable inputs,
/// SimulationError when the twin fails.
ScenarioRunResult run_scenario(const Scenario& scenario, const AirFieldModel& field_model,
                               const ScenarioRunOptions& options);

/// summary.json: scenario, seed, success, completion_time_s (null when not done),
/// path_error_cm {mean, std, max} (null for zone tasks), max_pairwise_distance_cm,
/// objects_in_zone, n_objects, decisions, decision_ms {mean, max}, then end_time_s,
/// time_limit_s, perception and controller_done (the controller's own verdict; `success` also
/// asks the truth, see ScenarioRunResult); with varied objects, physics_variation and
/// object_physics (id -> "type:key=value,..."). 2-space indented.
std::string run_summary_json(const ScenarioRunResult& result, double time_limit_s);

/// decisions.csv: t,reference_index,ref_x,ref_y,s_x,s_y,pan_deg,tilt_deg,cost,iterations,
/// converged,sweep,rescue,n_observed,decision_ms.
std::string decisions_csv(const ScenarioRunResult& result);

/// plans.csv: what each decision planned with and predicted, a row per object per decision:
/// t,id,type,seen,x,y,vx,vy,end_x,end_y. (x, y), (vx, vy): the object as the controller knew it
/// (perceived; seen 0: remembered at its last position, at rest); (end_x, end_y): where eq. (8)-
/// (9) put it after Delta T under the chosen s. Beside log.csv (the truth) it shows what the
/// perception and the model got wrong.
std::string plans_csv(const ScenarioRunResult& result);

}  // namespace airtwin
