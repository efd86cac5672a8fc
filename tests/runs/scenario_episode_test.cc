#include "runs/scenario_episode.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "common/errors.h"
#include "models/trajectory_data.h"

namespace airtwin {
namespace {

std::string scene(const std::string& name) {
  return std::string(AIRTWIN_SOURCE_DIR) + "/scenes/" + name + ".yaml";
}

// The caller's commands at the controller's stagnation points take the episode through the
// controller's run, frame by frame: the episode aims as the planner aims.
TEST(ScenarioEpisode, TheControllersPointsAsCallersCommandsGiveTheSameRun) {
  const Scenario sc = read_scenario(scene("octagon"));
  const AirFieldModel field = AirFieldModel::with_constructed_table();
  ScenarioRunOptions options;
  options.seed = 4;
  ScenarioEpisode controlled(sc, field, options), replayed(sc, field, options);
  for (int k = 0; k < 6; ++k) {
    DecisionRecord d = controlled.decide();
    const Eigen::Vector2d s_W = d.plan.stagnation_W;
    controlled.step(std::move(d));
    replayed.step_at(s_W);
    EXPECT_EQ(replayed.last_cost(), controlled.last_cost());
  }
  EXPECT_EQ(trajectory_csv(replayed.result().log), trajectory_csv(controlled.result().log));
  EXPECT_EQ(controlled.result().loop.decisions.size(), 6u);
  EXPECT_TRUE(replayed.result().loop.decisions.empty());
}

// last_cost is eq. (10) on the truth: the objects' distances to the turn's references, or J_P
// for an s within delta_min of an object.
TEST(ScenarioEpisode, TheLastCostIsEq10OnWhereTheObjectsGot) {
  const Scenario sc = read_scenario(scene("octagon"));
  const AirFieldModel field = AirFieldModel::with_constructed_table();
  ScenarioRunOptions options;
  options.seed = 2;
  ScenarioEpisode episode(sc, field, options);
  const DecisionInputs before = episode.controller().inputs();
  episode.step(NozzleOrientation{0.5, 0.4});
  double sum = 0.0;
  for (size_t j = 0; j < before.ids.size(); ++j) {
    sum += (episode.controller().known().at(before.ids[j]).p_W - before.references_W[j]).norm();
  }
  EXPECT_NEAR(episode.last_cost(), sum, 1e-12);
  episode.step_at(episode.controller().inputs().positions_W[0]);
  EXPECT_EQ(episode.last_cost(), sc.controller.penalty);
  EXPECT_THROW(episode.step_at({std::nan(""), 0.0}), InputError);
}

// A finished episode takes no more turns; its result is run_scenario's.
TEST(ScenarioEpisode, AFinishedEpisodeRefusesTurns) {
  Scenario sc = read_scenario(scene("line"));
  sc.task.time_limit_s = 3.0;
  const AirFieldModel field = AirFieldModel::with_constructed_table();
  ScenarioRunOptions options;
  options.seed = 1;
  ScenarioEpisode episode(sc, field, options);
  while (!episode.finished()) episode.step(episode.decide());
  EXPECT_DOUBLE_EQ(episode.time(), 3.0);
  EXPECT_THROW(episode.step(NozzleOrientation{0.0, 0.3}), InputError);
  EXPECT_THROW(episode.decide(), InputError);
  EXPECT_EQ(trajectory_csv(episode.result().log),
            trajectory_csv(run_scenario(sc, field, options).log));
}

// The file's loop latency reaches the twin: each turn aims that long after its observation, so
// a turn takes latency + horizon + settle of rig time.
TEST(ScenarioEpisode, TheFilesLatencyDelaysEachAim) {
  Scenario sc = read_scenario(scene("line"));
  sc.loop.latency_s = 0.5;
  const AirFieldModel field = AirFieldModel::with_constructed_table();
  ScenarioRunOptions options;
  options.seed = 1;
  ScenarioEpisode episode(sc, field, options);
  const double turn = 0.5 + sc.controller.horizon_s + sc.loop.settle_s;
  for (int k = 1; k <= 2; ++k) {
    episode.step(episode.decide());
    EXPECT_NEAR(episode.time(), k * turn, 1e-9);
  }
  const auto& decisions = episode.result().loop.decisions;
  ASSERT_EQ(decisions.size(), 2u);
  EXPECT_NEAR(decisions[1].t_s, turn, 1e-9);
}

}  // namespace
}  // namespace airtwin
