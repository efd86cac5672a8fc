#include "runs/scenario_run.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "models/trajectory_data.h"
#include "sim/object_physics.h"
#include "sim/physics_variation.h"
#include "tests/support/physical_twin.h"

namespace airtwin {
namespace {

std::string scene(const std::string& name) {
  return std::string(AIRTWIN_SOURCE_DIR) + "/scenes/" + name + ".yaml";
}

// One tracer along the 52 cm line: a run takes well under a second of wall time.
TEST(ScenarioRun, LineSucceedsAndTheLogIsTheTruth) {
  const Scenario sc = read_scenario(scene("line"));
  const AirFieldModel field = AirFieldModel::with_constructed_table();
  ScenarioRunOptions options;
  options.seed = 3;
  const ScenarioRunResult r = run_scenario(sc, field, options);
  ASSERT_TRUE(r.loop.success);
  EXPECT_TRUE(r.success);
  ASSERT_TRUE(r.loop.completion_time_s.has_value());
  EXPECT_LE(*r.loop.completion_time_s, sc.task.time_limit_s);
  // One row per camera frame (40 Hz) from t = 0 to the end, nozzle commands included.
  ASSERT_EQ(r.log.trajectories.size(), 1u);
  const auto& samples = r.log.trajectories[0].samples;
  EXPECT_EQ(samples.size(), static_cast<size_t>(std::llround(r.loop.end_time_s * 40.0)) + 1);
  // The end of the log is within the switch distance of the path's end (the task's own test).
  EXPECT_LT((samples.back().p_W - sc.task.path_W.back()).norm(), sc.task.switch_distance_m);
  EXPECT_EQ(r.objects_in_zone, 1);
  EXPECT_EQ(r.loop.objects_seen_at_end, 1);
  // Path error: recomputed from the log.
  double max_e = 0.0;
  for (const auto& s : samples) max_e = std::max(max_e, distance_to_path(sc.task.path_W, s.p_W));
  EXPECT_NEAR(r.path_error_m.max, max_e, 1e-12);
  // The decisions' commands are in the log.
  EXPECT_NEAR(samples.back().nozzle.pan_rad, r.loop.decisions.back().plan.orientation.pan_rad,
              1e-12);
}

// The summary's verdict is the run's, not the controller's: a controller that saw the task done
// while the truth disagrees (a detection on a zone's edge) is a failed run with no completion
// time, and says so in controller_done.
TEST(ScenarioRun, TheSummarySuccessIsTheTruthsVerdict) {
  // The verdict: zone tasks need the truth's agreement; a path task is the controller's (its
  // objects_in_zone counts objects near the last reference, not the task's criterion).
  EXPECT_TRUE(run_verdict(TaskKind::kSorting, true, 6, 6));
  EXPECT_FALSE(run_verdict(TaskKind::kSorting, true, 5, 6));
  EXPECT_FALSE(run_verdict(TaskKind::kAggregation, true, 24, 25));
  EXPECT_FALSE(run_verdict(TaskKind::kSorting, false, 6, 6));
  EXPECT_TRUE(run_verdict(TaskKind::kPath, true, 3, 4));
  EXPECT_FALSE(run_verdict(TaskKind::kPath, false, 4, 4));
  ScenarioRunResult r;
  r.scenario = "sorting";
  r.n_objects = 6;
  r.objects_in_zone = 5;
  r.loop.success = true;
  r.loop.completion_time_s = 37.8;
  r.loop.end_time_s = 37.8;
  r.success = false;
  const std::string json = run_summary_json(r, 60.0);
  EXPECT_NE(json.find("\"success\": false"), std::string::npos) << json;
  EXPECT_NE(json.find("\"completion_time_s\": null"), std::string::npos) << json;
  EXPECT_NE(json.find("\"controller_done\": true"), std::string::npos) << json;
  r.success = true;
  const std::string done = run_summary_json(r, 60.0);
  EXPECT_NE(done.find("\"success\": true"), std::string::npos) << done;
  EXPECT_NE(done.find("\"completion_time_s\": 37.8"), std::string::npos) << done;
}

// Stalled: failed, and still over the last kStalledSpan_s (5 s) of the run, bounds included.
TEST(ScenarioRun, AStalledRunFailedStillForItsLastFiveSeconds) {
  EXPECT_TRUE(run_stalled(false, 60.0, 21.775));
  EXPECT_TRUE(run_stalled(false, 60.0, 55.0));
  EXPECT_FALSE(run_stalled(false, 60.0, 55.025));
  EXPECT_FALSE(run_stalled(true, 60.0, 21.775));  // done: still in its zones, not stalled
}

// The models planned with by default follow the twin: the physical one's own fitted models, the
// Lagrangian-time twin's own, none (the paper's eq. (8)) elsewhere; and each named file reads.
TEST(ScenarioRun, TheDefaultModelsAreTheTwinsOwn) {
  EXPECT_TRUE(default_controller_models(false, true).empty());
  EXPECT_TRUE(default_controller_models(true, false).empty());
  EXPECT_TRUE(default_controller_models(false, false, false).empty());
  const std::vector<std::string> physical = default_controller_models(true, true);
  const std::vector<std::string> lagrangian = default_controller_models(true, true, false);
  ASSERT_EQ(physical.size(), 1u);
  ASSERT_EQ(lagrangian.size(), 1u);
  EXPECT_EQ(physical, default_controller_models(true, true, true));
  EXPECT_NE(physical[0].find("/twin/extended_model.json"), std::string::npos);
  EXPECT_NE(lagrangian[0].find("/twin_lagrangian/extended_model.json"), std::string::npos);
  // Each is an extended model (the pressure push near s) whose tracer is not the paper's.
  const AirFieldModel field = AirFieldModel::with_constructed_table();
  for (const std::vector<std::string>& files : {physical, lagrangian}) {
    ScenarioRunOptions options;
    plan_with_model_files(files, field, &options);
    EXPECT_TRUE(options.planning_extensions.has_value()) << files[0];
    EXPECT_NE(options.dynamics.at("tracer").xi1, kTracerDynamics.xi1) << files[0];
  }
}

TEST(ScenarioRun, SameSeedSameBytesOtherSeedOtherRun) {
  const Scenario sc = read_scenario(scene("line"));
  const AirFieldModel field = AirFieldModel::with_constructed_table();
  ScenarioRunOptions options;
  options.seed = 5;
  const std::string a = trajectory_csv(run_scenario(sc, field, options).log);
  const std::string b = trajectory_csv(run_scenario(sc, field, options).log);
  options.seed = 6;
  const std::string c = trajectory_csv(run_scenario(sc, field, options).log);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
}

// Objects that differ (sim/physics_variation.h), in the physical twin: each object's drawn
// physics is the run's, listed in its record as drawn from the seed; the run repeats bit for bit
// and differs from the run of the type's own objects, whose record lists none.
TEST(ScenarioRun, VariedObjectsAreRecordedAndTheRunRepeats) {
  const Scenario sc = read_scenario(scene("line"));
  const AirFieldModel field = testing::cfd_fitted_field();
  ScenarioRunOptions options = testing::physical_twin_run_options(field);
  options.seed = 5;
  const ScenarioRunResult plain = run_scenario(sc, field, options);
  options.physics_variation = PhysicsVariation::parse("0.2");
  const ScenarioRunResult a = run_scenario(sc, field, options);
  const ScenarioRunResult b = run_scenario(sc, field, options);
  EXPECT_TRUE(trajectory_csv(a.log) == trajectory_csv(b.log)) << "a rerun differs";
  EXPECT_FALSE(trajectory_csv(a.log) == trajectory_csv(plain.log)) << "the variation did nothing";
  EXPECT_EQ(a.physics_variation, "0.2");
  ASSERT_EQ(a.object_physics.size(), sc.scene.objects.size());
  EXPECT_EQ(a.object_physics[0].id, sc.scene.objects[0].id);
  EXPECT_EQ(
      a.object_physics[0].physics,
      object_physics_to_string(draw_object_physics(options.physics_variation, ObjectType::kTracer,
                                                   options.twin.scene.tracer, 5, 0),
                               ObjectType::kTracer));
  const std::string summary = run_summary_json(a, sc.task.time_limit_s);
  EXPECT_NE(summary.find("\"physics_variation\": \"0.2\""), std::string::npos) << summary;
  EXPECT_NE(summary.find(a.object_physics[0].physics), std::string::npos) << summary;
  EXPECT_EQ(run_summary_json(plain, sc.task.time_limit_s).find("object_physics"),
            std::string::npos);
}

}  // namespace
}  // namespace airtwin
