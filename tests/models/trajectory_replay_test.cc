// Replaying trajectories: data made by eqs. (8)-(9) replay with ~0 error under the true model, a
// wrong model shows its error, and the recorded schedule (commands changing mid-trajectory) is
// followed exactly as the predictor would.

#include "models/trajectory_replay.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iterator>
#include <string>

#include "common/units.h"
#include "models/cvode_predictor.h"
#include "models/fast_predictor.h"
#include "models/nozzle_geometry.h"
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

TEST(TrajectoryReplay, SectorsFollowTheBearingFromSAgainstThePan) {
  EXPECT_EQ(placement_sector(0.0), PlacementSector::kDownstream);
  EXPECT_EQ(placement_sector(59.999), PlacementSector::kDownstream);
  EXPECT_EQ(placement_sector(60.0), PlacementSector::kSide);
  EXPECT_EQ(placement_sector(119.999), PlacementSector::kSide);
  EXPECT_EQ(placement_sector(120.0), PlacementSector::kUpstream);
  EXPECT_EQ(placement_sector(180.0), PlacementSector::kUpstream);

  // Starts at known bearings beta around s (either side of the pan direction), each travelling
  // 20 cm radially; one start on s itself.
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  const NozzleOrientation o{deg_to_rad(30), deg_to_rad(22.5)};
  const Eigen::Vector2d s = stagnation_point(model.geometry(), o);
  const double betas[] = {10, -45, 90, -100, 150, -180, 175};
  TrajectorySet set;
  for (double beta : betas) {
    const double a = o.pan_rad + deg_to_rad(beta);
    const Eigen::Vector2d e(std::cos(a), std::sin(a));
    Trajectory tr;
    tr.id = std::to_string(beta);
    for (int k = 0; k < 40; ++k) tr.samples.push_back({0.025 * k, s + 0.3 * e, o});
    tr.samples.back().p_W = s + 0.5 * e;
    set.trajectories.push_back(tr);
  }
  Trajectory on_s;
  on_s.id = "on s";
  for (int k = 0; k < 40; ++k) on_s.samples.push_back({0.025 * k, s, o});
  on_s.samples.back().p_W = s + Eigen::Vector2d(0.0, 0.2);
  set.trajectories.push_back(on_s);

  // Twice: with the tracer's model, and with a friction no air overcomes (all predicted at rest).
  for (const ObjectDynamics& d : {kTracerDynamics, ObjectDynamics{-2.66, 4.26, -100.0}}) {
    const ReplayReport r = replay_trajectories(set, model, d, FastPredictor());
    ASSERT_EQ(r.trajectories.size(), std::size(betas) + 1);
    for (size_t i = 0; i < std::size(betas); ++i) {
      EXPECT_NEAR(r.trajectories[i].bearing_deg, std::abs(betas[i]), 1e-9) << betas[i];
    }
    EXPECT_EQ(r.trajectories.back().bearing_deg, 0.0);

    // Each sector's figures are its trajectories' own, gathered here a second way.
    ASSERT_EQ(r.by_tilt_sector.size(), 1u);
    const auto& sectors = r.by_tilt_sector.at(22.5);
    for (const PlacementSectorInfo& info : kPlacementSectorCatalogue) {
      size_t n = 0, rest = 0;
      double sum = 0.0;
      for (const ReplayedTrajectory& t : r.trajectories) {
        if (!t.used || placement_sector(t.bearing_deg) != info.sector) continue;
        ++n;
        sum += t.error_pct;
        if ((t.predicted_end_W - t.start_W).norm() < 0.01) ++rest;
      }
      const SectorFigures& f = sectors[static_cast<size_t>(info.sector)];
      EXPECT_EQ(f.n, n) << info.name;
      EXPECT_EQ(f.n_predicted_rest, rest) << info.name;
      EXPECT_NEAR(f.mape_pct, sum / n, 1e-9) << info.name;
    }
    EXPECT_EQ(sectors[0].n, 3u);  // 10, -45 and the start on s
    EXPECT_EQ(sectors[1].n, 2u);  // 90, -100
    EXPECT_EQ(sectors[2].n, 3u);  // 150, -180, 175
  }
  // With the friction no air overcomes, nothing is predicted to move: every error is the whole
  // travel.
  const ReplayReport stuck =
      replay_trajectories(set, model, ObjectDynamics{-2.66, 4.26, -100.0}, FastPredictor());
  for (const SectorFigures& f : stuck.by_tilt_sector.at(22.5)) {
    EXPECT_EQ(f.n_predicted_rest, f.n);
    EXPECT_NEAR(f.mape_pct, 100.0, 1e-9);
  }
}

}  // namespace
}  // namespace airtwin
