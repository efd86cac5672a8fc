#include "controller/task.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/errors.h"
#include "models/object_dynamics.h"

namespace airtwin {
namespace {

TaskSpec line_task() {
  TaskSpec t;
  t.kind = TaskKind::kPath;
  t.path_W = {{-0.26, 0.25}, {0.26, 0.25}};
  t.reference_spacing_m = 0.10;
  t.switch_distance_m = 0.04;
  return t;
}

TEST(PathReferences, SpacedAlongTheArcWithTheEndIncluded) {
  const auto refs = path_references(line_task());
  // 52 cm: points at 10, 20, 30, 40, 50 cm and the end at 52 cm.
  ASSERT_EQ(refs.size(), 6u);
  for (size_t i = 0; i < 5; ++i) {
    EXPECT_NEAR(refs[i].x(), -0.26 + 0.1 * static_cast<double>(i + 1), 1e-12);
    EXPECT_NEAR(refs[i].y(), 0.25, 1e-12);
  }
  EXPECT_NEAR(refs[5].x(), 0.26, 1e-12);
}

TEST(PathReferences, SpacingCarriesAroundCorners) {
  TaskSpec t = line_task();
  t.path_W = {{0, 0}, {0.15, 0}, {0.15, 0.15}};
  const auto refs = path_references(t);
  // Arc lengths 0.1 (first leg), 0.2 (0.05 up the second leg), 0.3 = end.
  ASSERT_EQ(refs.size(), 3u);
  EXPECT_TRUE(refs[0].isApprox(Eigen::Vector2d(0.1, 0.0)));
  EXPECT_NEAR((refs[1] - Eigen::Vector2d(0.15, 0.05)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((refs[2] - Eigen::Vector2d(0.15, 0.15)).norm(), 0.0, 1e-12);
}

TEST(PathReferences, VerticesAfterTheFirst) {
  TaskSpec t = line_task();
  t.vertices_as_references = true;
  t.path_W = {{0.3, 0}, {0, 0.3}, {-0.3, 0}, {0.3, 0}};
  const auto refs = path_references(t);
  ASSERT_EQ(refs.size(), 3u);
  EXPECT_EQ(refs[0], t.path_W[1]);
  EXPECT_EQ(refs[2], t.path_W[3]);
}

TEST(DistanceToPath, MatchesDenseSampling) {
  const std::vector<Eigen::Vector2d> path = {{0, 0}, {0.3, 0.1}, {0.2, 0.5}, {-0.4, 0.2}};
  // Independent check: the closest of 1e5 points sampled along the polyline.
  std::vector<Eigen::Vector2d> dense;
  for (size_t i = 1; i < path.size(); ++i) {
    for (int k = 0; k <= 30000; ++k) {
      dense.push_back(path[i - 1] + (path[i] - path[i - 1]) * (k / 30000.0));
    }
  }
  for (const Eigen::Vector2d& q : {Eigen::Vector2d(0.1, 0.3), Eigen::Vector2d(-0.5, -0.1),
                                   Eigen::Vector2d(0.25, 0.3), Eigen::Vector2d(0.0, 0.0)}) {
    double best = 1e9;
    for (const auto& d : dense) best = std::min(best, (q - d).norm());
    EXPECT_NEAR(distance_to_path(path, q), best, 2e-5) << q.transpose();
  }
}

TEST(TaskProgress, OneObjectPassesSeveralPointsAtOnce) {
  TaskProgress progress(line_task());
  const std::vector<std::string> types = {"tracer"};
  EXPECT_FALSE(progress.update({{-0.26, 0.25}}, types, 0.0));
  EXPECT_EQ(progress.reference_index(), 0u);
  // Near the 30 cm point but 19 cm from the current (10 cm) one: the index stays.
  EXPECT_FALSE(progress.update({{0.03, 0.25}}, types, 1.0));
  EXPECT_EQ(progress.reference_index(), 0u);
  EXPECT_FALSE(progress.update({{-0.17, 0.25}}, types, 2.0));
  EXPECT_EQ(progress.reference_index(), 1u);
  EXPECT_TRUE(progress.references(types)[0].isApprox(Eigen::Vector2d(-0.06, 0.25)));
  for (double x : {-0.06, 0.04, 0.14}) progress.update({{x, 0.25}}, types, 3.0);
  EXPECT_FALSE(progress.done());
  EXPECT_EQ(progress.reference_index(), 4u);
  // 1 cm from both the 50 cm point and the end: both are passed in one update.
  EXPECT_TRUE(progress.update({{0.25, 0.25}}, types, 4.5));
  EXPECT_EQ(progress.done_time_s(), 4.5);
}

TEST(TaskProgress, GroupMovesOnOneCornerPerUpdateOnTheMeanDistance) {
  TaskSpec t = line_task();
  t.vertices_as_references = true;
  t.switch_distance_m = 0.063;
  t.path_W = {{0.3, 0}, {0, 0.3}, {0, 0.31}};
  TaskProgress progress(t);
  const std::vector<std::string> types(2, "tracer");
  // Mean distance 0.07 > 0.063: stays; 0.05: moves on, but only one corner although the next is
  // also near.
  progress.update({{0.0, 0.23}, {0.0, 0.37}}, types, 0.0);
  EXPECT_EQ(progress.reference_index(), 0u);
  progress.update({{0.0, 0.25}, {0.0, 0.35}}, types, 1.0);
  EXPECT_EQ(progress.reference_index(), 1u);
  EXPECT_TRUE(progress.update({{0.0, 0.28}, {0.0, 0.33}}, types, 2.0));
}

TEST(TaskProgress, ZonesPerTypeAndAggregation) {
  TaskSpec sort;
  sort.kind = TaskKind::kSorting;
  sort.zones_by_type = {{"tracer", Zone{{-0.6, 0}, 0.105}}, {"cotton", Zone{{0.6, 0}, 0.105}}};
  TaskProgress progress(sort);
  const std::vector<std::string> types = {"tracer", "cotton"};
  EXPECT_EQ(progress.objects_in_zone({{-0.6, 0.1}, {0.0, 0.0}}, types), 1);
  EXPECT_FALSE(progress.update({{-0.6, 0.1}, {0.6, 0.2}}, types, 1.0));
  EXPECT_TRUE(progress.update({{-0.6, 0.1}, {0.65, 0.05}}, types, 2.0));
  EXPECT_THROW(progress.references({"glass"}), InputError);

  TaskSpec agg;
  agg.kind = TaskKind::kAggregation;
  agg.zone = Zone{{0, 0}, 0.185};
  TaskProgress a(agg);
  const auto r = a.references({"tracer", "cotton"});
  EXPECT_EQ(r[0], Eigen::Vector2d::Zero());
  EXPECT_EQ(r[1], Eigen::Vector2d::Zero());
}

// An object the perception saw leave its view keeps the task open: the ones still seen being in
// their zones says nothing of it (zone tasks and paths alike).
TEST(TaskProgress, NeverDoneWhileAnObjectIsOutOfView) {
  TaskSpec sort;
  sort.kind = TaskKind::kSorting;
  sort.zones_by_type = {{"tracer", Zone{{-0.6, 0}, 0.105}}, {"cotton", Zone{{0.6, 0}, 0.105}}};
  TaskProgress progress(sort);
  const std::vector<Eigen::Vector2d> in = {{-0.6, 0.0}, {0.6, 0.0}};
  EXPECT_FALSE(progress.update(in, {"tracer", "cotton"}, 1.0, /*out_of_view=*/1));
  EXPECT_FALSE(progress.done());
  EXPECT_TRUE(progress.update(in, {"tracer", "cotton"}, 2.0, /*out_of_view=*/0));
  EXPECT_DOUBLE_EQ(*progress.done_time_s(), 2.0);

  // A path task past its last reference waits too.
  TaskProgress path(line_task());
  double t = 0.0;
  for (const Eigen::Vector2d& r : path.path_reference_points()) {
    EXPECT_FALSE(path.update({r}, {"tracer"}, t += 1.0, 1));
  }
  EXPECT_EQ(path.reference_index(), path.reference_count());
  EXPECT_TRUE(path.update({line_task().path_W.back()}, {"tracer"}, t += 1.0, 0));
}

// Sorting in stages: the type that needs the strongest air first (tracer 2.0 m/s against cotton
// 1.19 m/s with the paper's coefficients); while a tracer is out of its zone the cottons are
// deferred (weight, reach); once all tracers are in, every object weighs 1 again.
TEST(TaskProgress, SortingInStagesDefersTheTypesAfterTheActiveOne) {
  TaskSpec sort;
  sort.kind = TaskKind::kSorting;
  sort.zones_by_type = {{"tracer", Zone{{-0.6, 0}, 0.105}}, {"cotton", Zone{{0.6, 0}, 0.105}}};
  sort.deferred_weight = 0.2;
  sort.reach_m = 0.9;
  ASSERT_TRUE(sort.stages_auto);  // the default
  const TaskSpec resolved =
      resolve_sorting_stages(sort, {{"tracer", kTracerDynamics.threshold_air_speed()},
                                    {"cotton", kCottonDynamics.threshold_air_speed()}});
  EXPECT_FALSE(resolved.stages_auto);
  EXPECT_EQ(resolved.stages, (std::vector<std::string>{"tracer", "cotton"}));
  // Reversed thresholds, reversed order.
  EXPECT_EQ(resolve_sorting_stages(sort, {{"tracer", 1.0}, {"cotton", 2.0}}).stages,
            (std::vector<std::string>{"cotton", "tracer"}));
  EXPECT_THROW(resolve_sorting_stages(sort, {{"tracer", 1.0}}), InputError);

  TaskProgress progress(resolved);
  const std::vector<std::string> types = {"tracer", "cotton", "tracer"};
  const std::vector<Eigen::Vector2d> one_out = {{-0.6, 0.0}, {0.0, 0.0}, {0.0, 0.3}};
  EXPECT_EQ(progress.active_stage(one_out, types), "tracer");
  CostShaping c = progress.cost_shaping(one_out, types);
  EXPECT_EQ(c.weights, (std::vector<double>{1.0, 0.2, 1.0}));
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(c.reach_m, (std::vector<double>{inf, 0.9, inf}));
  // All tracers in: the cottons' stage; nothing deferred.
  const std::vector<Eigen::Vector2d> tracers_in = {{-0.6, 0.0}, {0.0, 0.0}, {-0.55, 0.05}};
  EXPECT_EQ(progress.active_stage(tracers_in, types), "cotton");
  c = progress.cost_shaping(tracers_in, types);
  EXPECT_EQ(c.weights, (std::vector<double>(3, 1.0)));
  EXPECT_EQ(c.reach_m, (std::vector<double>(3, inf)));

  // `stages: none` (an empty explicit order) is the paper's: no shaping at all.
  TaskSpec all_at_once = sort;
  all_at_once.stages_auto = false;
  const TaskProgress plain(resolve_sorting_stages(all_at_once, {}));
  EXPECT_TRUE(plain.cost_shaping(one_out, types).weights.empty());
  EXPECT_EQ(plain.active_stage(one_out, types), "");
  // An explicit order naming a type without a zone, or twice, is refused.
  all_at_once.stages = {"tracer", "glass"};
  EXPECT_THROW(all_at_once.validate("x.yaml"), InputError);
  all_at_once.stages = {"tracer", "tracer"};
  EXPECT_THROW(all_at_once.validate("x.yaml"), InputError);
  all_at_once.stages = {"cotton"};
  all_at_once.deferred_weight = 0.0;
  EXPECT_THROW(all_at_once.validate("x.yaml"), InputError);
}

TEST(TaskSpec, ValidateNamesTheField) {
  TaskSpec t = line_task();
  t.path_W.resize(1);
  try {
    t.validate("x.yaml");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("task.path"), std::string::npos);
  }
  t = line_task();
  t.time_limit_s = std::nan("");
  EXPECT_THROW(t.validate("x.yaml"), InputError);
  TaskSpec s;
  s.kind = TaskKind::kSorting;
  EXPECT_THROW(s.validate("x.yaml"), InputError);
}

TEST(MaxPairwiseDistance, IsTheLongestSideOfTheGroup) {
  // A 3-4-5 right triangle: the hypotenuse, whatever the order.
  std::vector<Eigen::Vector2d> p = {{0.0, 0.0}, {0.3, 0.0}, {0.0, 0.4}};
  EXPECT_DOUBLE_EQ(max_pairwise_distance(p), 0.5);
  std::swap(p[0], p[2]);
  EXPECT_DOUBLE_EQ(max_pairwise_distance(p), 0.5);
  EXPECT_EQ(max_pairwise_distance(std::vector<Eigen::Vector2d>{{1.0, 2.0}}), 0.0);
  EXPECT_EQ(max_pairwise_distance(std::vector<Eigen::Vector2d>{}), 0.0);
}

}  // namespace
}  // namespace airtwin
