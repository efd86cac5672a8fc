// Section IV end to end on trajectories made by eqs. (8)-(9): the identified coefficients, the
// counts and the end-position MAPE of the replay.

#include "models/identification.h"

#include <gtest/gtest.h>

#include "common/errors.h"
#include "tests/support/synthetic_trajectories.h"

namespace airtwin {
namespace {

TEST(Identification, TracerTrajectoriesGiveTheTracerModelAndASmallMape) {
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  TrajectorySet set = testing::make_ray_trajectories(model, -2.66, 4.26, -8.53, 60, 11, "tracer");
  // Cotton trajectories in the same file are left alone.
  const TrajectorySet cotton =
      testing::make_ray_trajectories(model, -4.25, 3.46, -4.12, 5, 12, "cotton");
  for (Trajectory tr : cotton.trajectories) {
    tr.id = "c" + tr.id;
    set.trajectories.push_back(tr);
  }
  const IdentifiedModel m = identify_trajectories(set, "tracer", model, IdentificationOptions{});
  EXPECT_EQ(m.object, "tracer");
  EXPECT_EQ(m.method, "robust-esindy");
  EXPECT_EQ(m.n_trajectories, 60u);
  ASSERT_TRUE(m.is_eq8());
  const ObjectDynamics d = m.eq8();
  EXPECT_NEAR(d.xi1, -2.66, 0.005 * 2.66);
  EXPECT_NEAR(d.xi2, 4.26, 0.005 * 4.26);
  EXPECT_NEAR(d.xi3, -8.53, 0.005 * 8.53);
  EXPECT_EQ(m.n_samples, 60u * 79u);  // interior frames
  EXPECT_GT(m.n_dropped, 0u);
  ASSERT_TRUE(m.end_position_mape_pct.has_value());
  EXPECT_LT(*m.end_position_mape_pct, 1.0);
  EXPECT_EQ(m.n_mape_trajectories + m.n_mape_excluded, 60u);  // some never move
  EXPECT_GE(m.n_mape_trajectories, 45u);
  EXPECT_EQ(m.end_position_mape_by_tilt_pct.size(), 2u);
  // Which placements moved, per tilt: every trajectory counted once, and the moving ones are
  // those the replay kept (it drops the ones that travelled under 1 cm from their fitted start).
  ASSERT_EQ(m.moved_by_tilt.size(), 2u);
  size_t moved = 0, all = 0;
  for (const auto& [tilt, counts] : m.moved_by_tilt) {
    EXPECT_LE(counts.first, counts.second) << tilt;
    moved += counts.first;
    all += counts.second;
  }
  EXPECT_EQ(all, 60u);
  EXPECT_EQ(moved, m.n_mape_trajectories);
  EXPECT_NE(identified_model_json(m).find("\"moved_by_tilt\""), std::string::npos);
  EXPECT_EQ(m.bootstraps, 15);
  EXPECT_EQ(m.smoothing_half_window, 4);

  EXPECT_THROW(identify_trajectories(set, "pebble", model, IdentificationOptions{}), InputError);
}

}  // namespace
}  // namespace airtwin
