#include "controller/run_metrics.h"

#include <gtest/gtest.h>

#include <cmath>

namespace airtwin {
namespace {

TEST(RunMetrics, PathErrorStatisticsAndPairwiseDistance) {
  TaskSpec t;
  t.kind = TaskKind::kPath;
  t.path_W = {{0.0, 0.0}, {1.0, 0.0}};
  RunMetrics m(t);
  const std::vector<std::string> types(2, "tracer");
  // Distances to the x axis: frame 1: 0.01, 0.03; frame 2: 0.02, 0.00 (the second pair 0.5 m apart
  // in x).
  m.add_frame(0.0, {{0.1, 0.01}, {0.2, -0.03}}, types);
  m.add_frame(0.025, {{0.3, 0.02}, {0.8, 0.0}}, types);
  const ErrorStats e = m.path_error();
  EXPECT_EQ(e.count, 4);
  EXPECT_NEAR(e.mean, 0.015, 1e-12);
  // Sample standard deviation of {0.01, 0.03, 0.02, 0}.
  EXPECT_NEAR(e.std, std::sqrt((0.005 * 0.005 + 0.015 * 0.015 + 0.005 * 0.005 + 0.015 * 0.015) / 3),
              1e-12);
  EXPECT_NEAR(e.max, 0.03, 1e-12);
  EXPECT_NEAR(m.max_pairwise_distance_m(), std::hypot(0.5, 0.02), 1e-12);
  // The last frame: the second object is 0.2 m from the end (1, 0), outside 4 cm.
  EXPECT_EQ(m.objects_in_zone(), 0);
  m.add_frame(0.05, {{0.99, 0.0}, {0.5, 0.0}}, types);
  EXPECT_EQ(m.objects_in_zone(), 1);
  EXPECT_EQ(m.frames(), 3);
}

TEST(RunMetrics, ZoneTasksHaveNoPathError) {
  TaskSpec t;
  t.kind = TaskKind::kAggregation;
  t.zone = Zone{{0, 0}, 0.185};
  RunMetrics m(t);
  m.add_frame(0.0, {{0.1, 0.0}, {0.3, 0.0}}, {"tracer", "tracer"});
  EXPECT_EQ(m.path_error().count, 0);
  EXPECT_EQ(m.objects_in_zone(), 1);
}

TEST(RunMetrics, StillSinceTheLastMoveOfMoreThanOneCentimetre) {
  TaskSpec t;
  t.kind = TaskKind::kAggregation;
  t.zone = Zone{{0, 0}, 0.185};
  RunMetrics m(t);
  const std::vector<std::string> types(2, "tracer");
  EXPECT_EQ(m.still_since_s(), 0.0);
  m.add_frame(1.0, {{0.5, 0.0}, {0.0, 0.5}}, types);
  EXPECT_EQ(m.still_since_s(), 1.0);  // the first frame starts the stretch
  // Creeping: each frame under 1 cm from the last, but the second object 1.2 cm from where it
  // was at 1.0 s by the third frame; the stretch restarts there, not at every small step.
  m.add_frame(2.0, {{0.5, 0.0}, {0.0, 0.506}}, types);
  EXPECT_EQ(m.still_since_s(), 1.0);
  m.add_frame(3.0, {{0.5, 0.0}, {0.0, 0.512}}, types);
  EXPECT_EQ(m.still_since_s(), 3.0);
  // Jitter within 1 cm of the positions at 3.0 s, in both objects: still since 3.0 s.
  m.add_frame(4.0, {{0.509, 0.0}, {0.0, 0.503}}, types);
  m.add_frame(9.0, {{0.5, 0.004}, {0.0, 0.518}}, types);
  EXPECT_EQ(m.still_since_s(), 3.0);
  // One object out by just over 1 cm restarts it.
  m.add_frame(9.5, {{0.5, 0.0}, {0.0, 0.5221}}, types);
  EXPECT_EQ(m.still_since_s(), 9.5);
  // A change in the number of objects restarts it too.
  m.add_frame(10.0, {{0.5, 0.0}}, {"tracer"});
  EXPECT_EQ(m.still_since_s(), 10.0);
}

}  // namespace
}  // namespace airtwin
