// The paper's whole pipeline on the physical twin, the way it ran on the rig: the twin in the
// CFD's air with physical drag (docs/twin.md; the lag and the wall jet's formation at their
// defaults), the Appendix D collection, eq. (8) identified from it in the controller's
// CFD-fitted field model, then the line of Table I steered with the paper's own CEM settings
// (section V-B) planning with that model. Label `closedloop`.
//
// Nothing here is the model's own output: the air, the drag, the friction and the re-aim's
// transients are the twin's, the model is what identification makes of them. Runs are
// deterministic per seed (collection and run), so a failure is a regression. The many-seed
// figures (line 9/10 and the rest, the aggregation 10/10) are in docs/twin.md, "Closed loop in the
// physical twin".

#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "controller/cem_planner.h"
#include "models/discrepancy.h"
#include "models/extended_model.h"
#include "models/field_model_file.h"
#include "models/identification.h"
#include "models/trajectory_data.h"
#include "runs/scenario_run.h"
#include "scenes/scenario.h"
#include "sim/collection.h"
#include "tests/support/physical_twin.h"

namespace airtwin {
namespace {

using testing::cfd_fitted_field;
using testing::physical_twin;

// Appendix D in the twin (collection seed 202), eq. (8)'s terms identified as the paper found
// them, with identify's other defaults.
IdentifiedModel identified_tracer(const AirFieldModel& field) {
  CollectionOptions collection;
  collection.seed = 202;
  collection.twin = physical_twin();
  collection.threads = 0;
  const TrajectorySet data = run_collection(collection, field);
  IdentificationOptions identification;
  identification.sindy.terms = parse_sindy_terms("1,v,vair");
  return identify_trajectories(data, "tracer", field, identification);
}

TEST(PhysicalTwinClosedLoop, IdentifiedOnTheTwinThePapersControllerFollowsTheLine) {
  const AirFieldModel field = cfd_fitted_field();
  const IdentifiedModel model = identified_tracer(field);
  ASSERT_TRUE(model.is_eq8());
  const ObjectDynamics xi = model.eq8();
  std::printf("identified on the physical twin: dv/dt = %.3f v + %.3f vair %.3f\n", xi.xi1, xi.xi2,
              xi.xi3);
  // Physics, not the paper's numbers by construction: a drag rate, an air gain and a start
  // threshold of the paper's kind (tracer: -2.66, 4.26, -8.53; threshold 2.0 m/s).
  EXPECT_LT(xi.xi1, -1.0);
  EXPECT_GT(xi.xi2, 1.0);
  EXPECT_LT(xi.xi3, 0.0);
  EXPECT_NEAR(-xi.xi3 / xi.xi2, 2.0, 0.5);

  // The line with the paper's single-object CEM (mu0 41.8 cm, Sigma0 20.9 cm^2, 25 samples,
  // 3 elites, 5 iterations), as the scenario file has it.
  const Scenario line = read_scenario(AIRTWIN_SOURCE_DIR "/scenes/line.yaml");
  // Two seeds pin the pipeline's regressions; scripts/acceptance.sh holds the ten-seed floor.
  // Seeds 1-10 succeed six times (1, 2, 5, 8, 9, 10; docs/twin.md): seeds 5 and 8, in 91.8 s and
  // 34.2 s.
  for (const uint64_t seed : {5, 8}) {
    ScenarioRunOptions options;
    options.seed = seed;
    options.twin = physical_twin();
    options.dynamics["tracer"] = xi;
    const ScenarioRunResult r = run_scenario(line, field, options);
    std::printf(
        "line, seed %d: %s in %.1f s, path error %.2f / %.2f cm (Table I: 38 s, 0.67 / "
        "2.52 cm)\n",
        static_cast<int>(seed), r.success ? "success" : "FAILED",
        r.loop.completion_time_s.value_or(r.loop.end_time_s), 100 * r.path_error_m.mean,
        100 * r.path_error_m.max);
    EXPECT_TRUE(r.success) << "seed " << seed;
    // Within 3x of Table I's time (seed 5 takes 2.4x); errors within 5x (seed 5's mean 3.9x: the
    // physical twin is harder than the rig for the identified model, docs/twin.md).
    EXPECT_LT(r.loop.completion_time_s.value_or(1e9), 3 * 38.0) << "seed " << seed;
    EXPECT_LT(r.path_error_m.mean, 5 * 0.0067) << "seed " << seed;
  }
}

// What a rig's user does when the identified model's plans go wrong, on the physical twin: the
// closed-loop logs of a few runs (the line, the square and the letter A at calibration seeds 101
// and 102, the paper's CEM planning with the identified model) go to the discrepancy analysis
// (`airtwin discrepancy`'s library, its defaults), and the extended model it makes steers the
// line at seeds the analysis never saw, where the identified model alone fails. The error it
// meets is the twin's own, none hidden for it: near its start threshold, where the CEM's pushes
// land, the identified model under-predicts a tracer's travel 2-3x (docs/twin.md). The line's
// seeds 1-10: the identified model fails 3, 4, 6 and 7, and the extended model of these logs
// succeeds at all four (in 14-40 s, mean path error at most 0.12 cm).
TEST(PhysicalTwinClosedLoop, ClosedLoopLogsExtendTheModelAndTheLineIsFollowed) {
  const AirFieldModel field = cfd_fitted_field();
  const IdentifiedModel model = identified_tracer(field);
  ASSERT_TRUE(model.is_eq8());
  std::map<std::string, ObjectDynamics> objects = {{"tracer", model.eq8()},
                                                   {"cotton", kCottonDynamics}};
  auto scenario_file = [](const char* name) {
    return read_scenario(std::string(AIRTWIN_SOURCE_DIR "/scenes/") + name + ".yaml");
  };
  const Scenario line = scenario_file("line");

  std::vector<TrajectorySet> logs;
  for (const char* name : {"line", "square", "letter_A"}) {
    const Scenario scenario = scenario_file(name);
    for (const uint64_t seed : {101, 102}) {
      ScenarioRunOptions options;
      options.seed = seed;
      options.twin = physical_twin();
      options.dynamics = objects;
      logs.push_back(run_scenario(scenario, field, options).log);
    }
  }
  const DiscrepancyReport report =
      analyse_discrepancy(merge_trajectory_sets(std::move(logs)), field, objects, {});
  std::string found;
  for (const std::string& f : report.found) found += f + " ";
  std::printf("found in 6 closed-loop logs: %sheld-out end MAPE %.1f -> %.1f %%\n", found.c_str(),
              report.baseline_end_mape, report.extended_end_mape);
  ASSERT_FALSE(report.found.empty());
  EXPECT_LT(report.extended_end_mape, 0.7 * report.baseline_end_mape);

  ExtendedModel extended;
  extended.objects = objects;
  extended.extensions = report.extensions;
  for (const uint64_t seed : {3, 4}) {
    ScenarioRunOptions options;
    options.seed = seed;
    options.twin = physical_twin();
    options.dynamics = objects;
    const ScenarioRunResult nominal = run_scenario(line, field, options);
    plan_with_extended_model(extended, field, &options);
    const ScenarioRunResult r = run_scenario(line, field, options);
    std::printf("line, seed %d: nominal %s, extended %s in %.1f s, path error %.2f / %.2f cm\n",
                static_cast<int>(seed), nominal.success ? "success" : "FAILED",
                r.success ? "success" : "FAILED",
                r.loop.completion_time_s.value_or(r.loop.end_time_s), 100 * r.path_error_m.mean,
                100 * r.path_error_m.max);
    EXPECT_FALSE(nominal.success) << "seed " << seed << ": the gain is no longer shown here";
    EXPECT_TRUE(r.success) << "seed " << seed;
    // Table I: 38 s, 0.67 / 2.52 cm; within 2x of each.
    EXPECT_LT(r.loop.completion_time_s.value_or(1e9), 2 * 38.0) << "seed " << seed;
    EXPECT_LT(r.path_error_m.mean, 2 * 0.0067) << "seed " << seed;
    EXPECT_LT(r.path_error_m.max, 2 * 0.0252) << "seed " << seed;
  }
}

// The 25-tracer aggregation planned with the model identified above, from the nearer, wider start
// that model needs (the line search with mu0 25 cm, Sigma0 60 cm^2). The file's mu0 of 30 cm
// suits the extended model the twin plans with by default; the identified eq. (8) sees no push
// toward the point below the nozzle move a tracer from 30 cm (docs/controller.md, the region),
// and moves nothing there in 150 s (0 of seeds 1-10). From this start: every tracer in the zone,
// in a time of the paper's kind (105 s). Seeds 1-10 with the script's identified model
// (scripts/physical_twin_closed_loop.sh --multi, 2026-11-29, the tracer set before): 10/10,
// median 95.4 s, worst 133.2 s; here seed 1 takes 75.6 s.
TEST(PhysicalTwinClosedLoop, TheAggregationFromANearerWiderStartCollectsEveryTracer) {
  const AirFieldModel field = cfd_fitted_field();
  const IdentifiedModel model = identified_tracer(field);
  ASSERT_TRUE(model.is_eq8());
  Scenario aggregation = read_scenario(AIRTWIN_SOURCE_DIR "/scenes/aggregation.yaml");
  aggregation.controller.mean0_m = 0.25;
  aggregation.controller.variance0_m2 = 60e-4;
  ScenarioRunOptions options;
  options.seed = 1;
  options.twin = physical_twin();
  options.dynamics["tracer"] = model.eq8();
  const ScenarioRunResult r = run_scenario(aggregation, field, options);
  std::printf("aggregation, seed 1: %s in %.1f s, %d of %d in the zone (the paper: 105 s)\n",
              r.success ? "success" : "FAILED",
              r.loop.completion_time_s.value_or(r.loop.end_time_s), r.objects_in_zone, r.n_objects);
  EXPECT_TRUE(r.success);
  EXPECT_EQ(r.objects_in_zone, 25);
  // Within the 0.67-1.5x of the paper's time.
  const double t = r.loop.completion_time_s.value_or(1e9);
  EXPECT_GT(t, 0.67 * 105.0);
  EXPECT_LT(t, 1.5 * 105.0);
}

}  // namespace
}  // namespace airtwin
