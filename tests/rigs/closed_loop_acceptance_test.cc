// Closed-loop acceptance in the default twin (fast mode: the controller sees the twin's truth),
// 10 seeds per scenario, against the paper's section V and Table I. Label `closedloop`, Release.
// What is asserted is what the twin achieves today; what it does not (sorting) is measured in
// docs/controller.md and left out here.

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "rigs/scenario_run.h"

namespace airtwin {
namespace {

// Success count over the seeds; figures over the successful runs: the median run's (Table I
// reports one run per task) and the worst pairwise distance.
struct Tally {
  int success = 0;
  double median_time_s = 0.0, worst_time_s = 0.0;
  double median_mean_error_m = 0.0, median_max_error_m = 0.0, worst_pairwise_m = 0.0;
};

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

Tally run_seeds(const std::string& name, int seeds) {
  const Scenario sc = read_scenario(std::string(AIRTWIN_SOURCE_DIR) + "/scenes/" + name + ".yaml");
  const AirFieldModel field = AirFieldModel::with_default_table();
  Tally t;
  std::vector<double> times, means, maxes;
  for (int seed = 1; seed <= seeds; ++seed) {
    ScenarioRunOptions options;
    options.seed = static_cast<uint64_t>(seed);
    const ScenarioRunResult r = run_scenario(sc, field, options);
    // The figures of successful runs, as Table I reports a completed path.
    if (!r.loop.success) continue;
    ++t.success;
    times.push_back(*r.loop.completion_time_s);
    means.push_back(r.path_error_m.mean);
    maxes.push_back(r.path_error_m.max);
    t.worst_time_s = std::max(t.worst_time_s, *r.loop.completion_time_s);
    t.worst_pairwise_m = std::max(t.worst_pairwise_m, r.max_pairwise_distance_m);
  }
  t.median_time_s = median(times);
  t.median_mean_error_m = median(means);
  t.median_max_error_m = median(maxes);
  return t;
}

TEST(ClosedLoopAcceptance, OctagonFourTracers) {
  const Tally t = run_seeds("octagon", 10);
  EXPECT_GE(t.success, 9);
  // Table I row 4: mean 5.65 cm, max 20.32 cm, 205 s; pairwise distance <= 30 cm (issue).
  EXPECT_LE(t.median_mean_error_m, 2.0 * 0.0565);
  EXPECT_LE(t.median_max_error_m, 2.0 * 0.2032);
  EXPECT_LE(t.median_time_s, 1.5 * 205.0);
  EXPECT_LE(t.worst_pairwise_m, 0.30);
}

TEST(ClosedLoopAcceptance, AggregationTwentyFiveTracers) {
  const Tally t = run_seeds("aggregation", 10);
  EXPECT_GE(t.success, 9);
  EXPECT_LE(t.worst_time_s, 150.0);  // every successful run (paper: 105 s)
}

TEST(ClosedLoopAcceptance, SingleTracerPathsAsTableI) {
  // Table I: line 0.67 / 2.52 cm in 38 s, square 1.24 / 4.40 in 154 s, letter A 0.82 / 3.29 in
  // 108 s (mean / max error, completion time).
  const struct {
    const char* name;
    double mean_m, max_m, time_s;
  } paths[] = {{"line", 0.0067, 0.0252, 38.0},
               {"square", 0.0124, 0.0440, 154.0},
               {"letter_A", 0.0082, 0.0329, 108.0}};
  for (const auto& p : paths) {
    const Tally t = run_seeds(p.name, 10);
    EXPECT_GE(t.success, 9) << p.name;
    EXPECT_LE(t.median_mean_error_m, 2.0 * p.mean_m) << p.name;
    EXPECT_LE(t.median_max_error_m, 2.0 * p.max_m) << p.name;
    EXPECT_LE(t.median_time_s, 1.5 * p.time_s) << p.name;
  }
}

}  // namespace
}  // namespace airtwin
