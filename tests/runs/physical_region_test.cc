// The manipulation region of the physical twin (docs/controller.md, "Where the line search's
// pushes move an object"): the controller's shipped models judged against the twin over the
// floor, and the figures the documentation rests on. Label calibration: a physics change that
// leaves the controller's models stale or moves these figures fails here (~10 s on two cores).

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "models/air_field.h"
#include "runs/manipulation_region.h"
#include "runs/scenario_run.h"
#include "tests/support/physical_twin.h"

namespace airtwin {
namespace {

using testing::physical_twin;

// The grid +-0.8 m at 0.2 m, 8 directions (648 pushes), judged by the model of each file and,
// once, by the twin (the pushes' s and orientations are the field model's, whatever the model).
std::vector<RegionSummary> region_of(const std::vector<std::string>& model_files,
                                     double distance_m) {
  const AirFieldModel field = AirFieldModel::fitted_to_cfd();
  RegionOptions o;
  o.step_m = 0.2;
  o.distance_m = distance_m;
  std::vector<RegionSummary> out;
  std::vector<RegionPush> twin;
  for (const std::string& file : model_files) {
    ScenarioRunOptions run;
    plan_with_model_files({file}, field, &run);
    std::vector<RegionPush> pushes = model_region(o, field, run);
    if (twin.empty()) {
      run_region_in_twin(&pushes, o, physical_twin(), field);
      twin = pushes;
    }
    for (size_t i = 0; i < pushes.size(); ++i) pushes[i].twin_end_W = twin[i].twin_end_W;
    out.push_back(summarize_region(pushes, o));
  }
  return out;
}

const std::string kExtended = AIRTWIN_SOURCE_DIR "/models/data/twin/extended_model.json";
const std::string kIdentified = AIRTWIN_SOURCE_DIR "/models/data/twin/tracer_identified.json";

int moved(const RegionJudgement& j, PushClass c) {
  return j.by_class[static_cast<size_t>(c)].moved;
}

// At the paper's mu0: the extended model the controller plans with by default agrees with the
// twin on 95 % of the pushes or more (measured 98.1 % on this grid, 2026-11-29) and
// is seldom deluded; the identified eq. (8) of the paper's pipeline is blind more often and never
// deluded more; no push toward the point below the nozzle moves a tracer, by any of them.
TEST(PhysicalTwinRegion, ShippedModelsAgainstTheTwinAtThePapersDistance) {
  const std::vector<RegionSummary> r = region_of({kExtended, kIdentified}, 0.418);
  const RegionSummary& ext = r[0];
  const RegionSummary& ident = r[1];
  ASSERT_TRUE(ext.model && ext.twin);
  EXPECT_EQ(ext.reachable, 648);
  EXPECT_GE(ext.both + ext.neither, 0.95 * ext.reachable);
  EXPECT_LE(ext.model_only, 0.01 * ext.reachable);
  EXPECT_EQ(moved(*ext.model, PushClass::kToward), 0);
  EXPECT_EQ(moved(*ext.twin, PushClass::kToward), 0);
  EXPECT_GE(moved(*ext.twin, PushClass::kAway), 150);  // of 156
  EXPECT_EQ(ext.twin->region_points, 0);

  ASSERT_TRUE(ident.model && ident.twin);
  EXPECT_EQ(moved(*ident.model, PushClass::kToward), 0);
  EXPECT_GT(ident.twin_only, ext.twin_only);
  EXPECT_LE(ident.model_only, 0.01 * ident.reachable);
}

// Nearer s, pushes toward the point below the nozzle start to move the tracer, and the region of
// every direction appears (at 20 cm on the 0.1 m grid: 258 of 568 toward, 124 of 289 points).
TEST(PhysicalTwinRegion, NearerPushesReachTowardTheNozzle) {
  const RegionSummary r = region_of({kExtended}, 0.2).front();
  ASSERT_TRUE(r.twin);
  EXPECT_GT(moved(*r.twin, PushClass::kToward), 0.2 * 156);
  EXPECT_GT(r.twin->region_points, 10);
  EXPECT_GE(r.both + r.neither, 0.9 * r.reachable);
}

}  // namespace
}  // namespace airtwin
