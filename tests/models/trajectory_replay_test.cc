// Replaying trajectories: data made by eqs. (8)-(9) replay with ~0 error under the true model, a
// wrong model shows its error, and the recorded schedule (commands changing mid-trajectory) is
// followed exactly as the predictor would.

#include "models/trajectory_replay.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/units.h"
#include "models/cvode_predictor.h"
#include "models/fast_predictor.h"
#include "tests/support/synthetic_trajectories.h"

namespace airtwin {
namespace {

TEST(TrajectoryReplay, TheTrueModelReplaysItsOwnDataWithinAFractionOfAPercent) {
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  const TrajectorySet set =
      testing::make_ray_trajectories(model, -2.66, 4.26, -8.53, 40, 3, "tracer");
  const ReplayReport r = replay_trajectories(set, model, kTracerDynamics, FastPredictor());
  // Some starts lie where the air cannot overcome friction: they do not move and are excluded.
  EXPECT_EQ(r.n_used + r.n_excluded, 40u);
  EXPECT_GE(r.n_used, 30u);
  // The data start at rest and are integrated at 0.25 ms; the start speed estimate is exact for
  // uniform acceleration, so only the first frame's jerk (~1e-5 m) separates the two.
  EXPECT_LT(r.mape_pct, 0.2);
  ASSERT_EQ(r.mape_by_tilt_pct.size(), 2u);
  EXPECT_TRUE(r.mape_by_tilt_pct.count(0.0));
  EXPECT_TRUE(r.mape_by_tilt_pct.count(22.5));
  for (const ReplayedTrajectory& t : r.trajectories) {
    EXPECT_TRUE(t.constant_command);
    EXPECT_EQ(t.used, t.travel_m >= 0.01);
  }
  // A model with 20% more friction stops the objects early: a clearly larger error.
  const ObjectDynamics wrong{-2.66, 4.26, -8.53 * 1.2};
  EXPECT_GT(replay_trajectories(set, model, wrong, FastPredictor()).mape_pct, 5.0);
}

TEST(TrajectoryReplay, FollowsTheRecordedScheduleLikeThePredictor) {
  // One trajectory whose command changes twice; its replay must equal a direct prediction under
  // the same schedule by a second implementation (CVODE), started from the same state.
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  Trajectory tr;
  tr.id = "a";
  tr.object = "tracer";
  const NozzleOrientation o1{0.0, deg_to_rad(10)}, o2{deg_to_rad(40), deg_to_rad(20)},
      o3{deg_to_rad(-30), 0.0};
  for (int k = 0; k <= 60; ++k) {
    const NozzleOrientation& o = k < 20 ? o1 : (k < 45 ? o2 : o3);
    // Positions only matter at the first three frames (start state) and the last (the end).
    tr.samples.push_back({1.0 + 0.025 * k, Eigen::Vector2d(0.3 + 0.001 * k * k * 0.0, 0.2), o});
  }
  tr.samples.back().p_W = {0.9, 0.4};
  TrajectorySet set;
  set.trajectories.push_back(tr);
  const ReplayReport r = replay_trajectories(set, model, kTracerDynamics, FastPredictor());
  ASSERT_EQ(r.trajectories.size(), 1u);
  EXPECT_FALSE(r.trajectories[0].constant_command);
  EXPECT_TRUE(r.mape_by_tilt_pct.empty());  // per-tilt figures only for constant commands

  const OrientationSchedule schedule{{0.0, o1}, {0.5, o2}, {1.125, o3}};
  const ObjectState start{{0.3, 0.2}, 0.0};
  PredictionOptions po;
  po.horizon_s = 1.5;
  const Prediction p = CvodePredictor().predict(model, schedule, std::span(&kTracerDynamics, 1),
                                                std::span(&start, 1), po);
  EXPECT_LT((p.end[0].p_W - r.trajectories[0].predicted_end_W).norm(), 1e-3);
  const double travel = (Eigen::Vector2d(0.9, 0.4) - Eigen::Vector2d(0.3, 0.2)).norm();
  EXPECT_NEAR(r.trajectories[0].travel_m, travel, 1e-12);
  EXPECT_NEAR(r.mape_pct,
              100 * (r.trajectories[0].predicted_end_W - Eigen::Vector2d(0.9, 0.4)).norm() / travel,
              1e-9);
}

TEST(TrajectoryReplay, TooShortOrMotionlessTrajectoriesAreCountedNotUsed) {
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  TrajectorySet set;
  Trajectory still, two;
  still.id = "still";
  two.id = "two";
  for (int k = 0; k < 10; ++k) still.samples.push_back({0.025 * k, {1.2, 1.2}, {0.0, 0.0}});
  for (int k = 0; k < 2; ++k) two.samples.push_back({0.025 * k, {0.3, 0.0}, {0.0, 0.0}});
  set.trajectories = {still, two};
  const ReplayReport r = replay_trajectories(set, model, kTracerDynamics, FastPredictor());
  EXPECT_EQ(r.n_used, 0u);
  EXPECT_EQ(r.n_excluded, 2u);
  EXPECT_TRUE(std::isnan(r.mape_pct));
}

}  // namespace
}  // namespace airtwin
