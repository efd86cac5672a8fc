// Closed-loop success of every shipped scenario in the twin `airtwin run` builds by default: the
// physical twin (the CFD's air with its turbulence swept past the objects, physical drag), the
// controller planning with the models fitted to
// it (models/data/twin/, scripts/fit_twin_models.sh; fast mode: it sees the twin's truth),
// against the paper's section V and Table I, and the octagon with vision. Label `closedloop`,
// Release. In CI each scenario runs seeds 1-3; the acceptance tier (scripts/acceptance.sh) runs
// seeds 1-10. Runs are deterministic per seed, so a CI failure is a regression. The bounds are
// Table I's where the twin meets them and the measured figures (docs/twin.md, "The physical twin
// by default") where it does not: the twin is easier than the rig on path error and time.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "runs/scenario_run.h"
#include "tests/support/physical_twin.h"
#include "tests/support/test_run.h"

namespace airtwin {
namespace {

// Success count over the seeds; figures over the successful runs: the median run's (Table I
// reports one run per task) and the worst pairwise distance.
struct Tally {
  int success = 0;
  double median_time_s = 0.0, worst_time_s = 0.0;
  double median_mean_error_m = 0.0, median_max_error_m = 0.0, worst_pairwise_m = 0.0;
  int success_within_30cm = 0;  ///< successful runs whose group never spread beyond 30 cm
};

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Seeds 1..n of the tier: 3 in CI, 10 in the acceptance tier.
int seed_count() { return testing::acceptance_tier() ? 10 : 3; }
// Successes required: all in CI; 9 of 10 in the acceptance tier.
int required_successes(int seeds) { return seeds >= 10 ? seeds - 1 : seeds; }

// The twin a run is in: the physical one by default, or the mirror of the controller's model
// (the model's air, eq. (8) drag, the built-in table and the paper's eq. (8)).
enum class TwinKind { kPhysical, kMirror };

Tally run_seeds(const std::string& name, int seeds, TwinKind twin = TwinKind::kPhysical) {
  const Scenario sc = read_scenario(std::string(AIRTWIN_SOURCE_DIR) + "/scenes/" + name + ".yaml");
  const AirFieldModel field = twin == TwinKind::kPhysical ? testing::cfd_fitted_field()
                                                          : AirFieldModel::with_constructed_table();
  Tally t;
  std::vector<double> times, means, maxes;
  for (int seed = 1; seed <= seeds; ++seed) {
    ScenarioRunOptions options = twin == TwinKind::kPhysical
                                     ? testing::physical_twin_run_options(field)
                                     : ScenarioRunOptions{};
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
    if (r.max_pairwise_distance_m <= 0.30) ++t.success_within_30cm;
  }
  t.median_time_s = median(times);
  t.median_mean_error_m = median(means);
  t.median_max_error_m = median(maxes);
  return t;
}

TEST(ClosedLoopAcceptance, OctagonFourTracers) {
  const int n = seed_count();
  const Tally t = run_seeds("octagon", n);
  EXPECT_GE(t.success, required_successes(n));
  // Table I row 4: mean 5.65 cm, max 20.32 cm, 205 s.
  EXPECT_LE(t.median_mean_error_m, 2.0 * 0.0565);
  EXPECT_LE(t.median_max_error_m, 2.0 * 0.2032);
  EXPECT_LE(t.median_time_s, 1.5 * 205.0);
  // The group within 30 cm (the issue): 10 of seeds 1-10 in the physical twin (the widest
  // 19.3 cm), since a blind search's rescue may not spread the group (7 of 10 before, 5 without
  // the sweep clearance): every CI seed, 9 of 10 in the acceptance tier.
  EXPECT_GE(t.success_within_30cm, required_successes(n))
      << "worst pairwise " << t.worst_pairwise_m << " m";
  EXPECT_LE(t.worst_pairwise_m, 0.75);
}

// The paper's line search with mu0 30 cm (scenes/aggregation.yaml): every tracer in the zone
// within the file's 150 s, the median run within the 0.67-1.5x of the paper's 105 s
// (seeds 1-10: 64.8-97.2 s, median 78.3 s; the tracer set before 2026-11-29: 77-108 s, median
// 90.9 s, seeds 11-30 median 92.7 s, worst 118.8 s).
TEST(ClosedLoopAcceptance, AggregationTwentyFiveTracers) {
  const int n = seed_count();
  const Tally t = run_seeds("aggregation", n);
  EXPECT_GE(t.success, required_successes(n));
  EXPECT_LE(t.worst_time_s, 150.0);  // every successful run
  EXPECT_GE(t.median_time_s, 0.67 * 105.0);
  EXPECT_LE(t.median_time_s, 1.5 * 105.0);
}

// Sorting three tracers and three cotton wads in stages (scenes/sorting.yaml): the issue asks
// for 9 of 10, all six in their zones within 60 s (paper: 40 s). With the paper's Sigma0 the
// physical twin sorts 10 of seeds 1-10, median 39.6 s (the tracer set before 2026-11-29: 55 in 60
// over seeds 1-60). Every CI seed. The median run within 0.67-1.5x the paper's time.
TEST(ClosedLoopAcceptance, SortingByTypeInStages) {
  const int n = seed_count();
  const Tally t = run_seeds("sorting", n);
  EXPECT_GE(t.success, required_successes(n));
  EXPECT_GE(t.median_time_s, 0.67 * 40.0);
  EXPECT_LE(t.median_time_s, 1.5 * 40.0);
  EXPECT_LE(t.worst_time_s, 60.0);
}

// Table I: line 0.67 / 2.52 cm in 38 s, square 1.24 / 4.40 in 154 s, letter A 0.82 / 3.29 in
// 108 s (mean / max error, completion time).
struct PathRow {
  const char* name;
  double mean_m, max_m, time_s;
};
const PathRow kTableI[] = {{"line", 0.0067, 0.0252, 38.0},
                           {"square", 0.0124, 0.0440, 154.0},
                           {"letter_A", 0.0082, 0.0329, 108.0}};

// One failure allowed per scenario, in CI as in the acceptance tier; seeds 1-10 succeed 10 of 10
// in each. (Before the cheapest candidate the letter A failed seed 3: a re-aim's s passed the
// tracer 10.2 cm away, just outside the sweep clearance, and threw it 50 cm out to where only the
// weak air upstream of an oblique jet's s would push it back; docs/controller.md.)
TEST(ClosedLoopAcceptance, SingleTracerPathsAsTableI) {
  const int n = seed_count();
  for (const PathRow& p : kTableI) {
    const Tally t = run_seeds(p.name, n);
    EXPECT_GE(t.success, n - 1) << p.name;
    EXPECT_LE(t.median_mean_error_m, 2.0 * p.mean_m) << p.name;
    EXPECT_LE(t.median_max_error_m, 2.0 * p.max_m) << p.name;
    EXPECT_LE(t.median_time_s, 1.5 * p.time_s) << p.name;
  }
}

// The mirror twin (the controller's own air and eq. (8) as the objects' physics), kept for
// comparison: the paper's settings of the path files succeed there too, 30 of 30 over seeds 1-10
// (29 before the cheapest candidate: the letter A's seed 3 blown out where only the weak air
// upstream of an oblique jet's s would push it back). One failure allowed per scenario, in CI as
// in the acceptance tier.
TEST(ClosedLoopAcceptance, SingleTracerPathsInTheMirrorTwin) {
  const int n = seed_count();
  for (const PathRow& p : kTableI) {
    const Tally t = run_seeds(p.name, n, TwinKind::kMirror);
    EXPECT_GE(t.success, n - 1) << p.name;
    EXPECT_LE(t.median_mean_error_m, 2.0 * p.mean_m) << p.name;
    EXPECT_LE(t.median_max_error_m, 2.0 * p.max_m) << p.name;
  }
}

// The octagon in the mirror twin keeps its group within 30 cm in every CI seed and 9 of 10 in
// the acceptance tier (docs/controller.md; 10 of 10 measured, the widest 15.8 cm). Without the
// blind search's rescue two of ten stall there to the time limit: the model's own air upstream
// of an oblique jet's s cannot start a tracer left beyond a corner.
TEST(ClosedLoopAcceptance, OctagonInTheMirrorTwinKeepsTheGroupTogether) {
  const int n = seed_count();
  const Tally t = run_seeds("octagon", n, TwinKind::kMirror);
  EXPECT_GE(t.success, required_successes(n));
  EXPECT_GE(t.success_within_30cm, required_successes(n))
      << "worst pairwise " << t.worst_pairwise_m << " m";
}

// With --vision: the controller sees through the calibrated camera, detection and tracking on
// rendered frames (with the "low" sensor noise). One seed of the octagon: success, and the errors
// still within 2x of Table I. (The group's spread is not asserted here: with noise this seed's
// maximum pairwise distance reached 39 cm, against 18 cm in fast mode; docs/controller.md.)
TEST(ClosedLoopAcceptance, OctagonWithVision) {
  const Scenario sc = read_scenario(std::string(AIRTWIN_SOURCE_DIR) + "/scenes/octagon.yaml");
  const AirFieldModel field = testing::cfd_fitted_field();
  ScenarioRunOptions options = testing::physical_twin_run_options(field);
  options.seed = 1;
  const std::string dir =
      (std::filesystem::temp_directory_path() / "airtwin_vision_octagon_calibration").string();
  std::filesystem::remove_all(dir);
  options.vision.noise_sigma_grey = 3.0;
  options.vision.blur_sigma_px = 0.7;
  options.vision_camera = calibrate_twin_camera(dir, options.twin.scene, 1, 3.0, 0.7);
  std::filesystem::remove_all(dir);
  const ScenarioRunResult r = run_scenario(sc, field, options);
  EXPECT_EQ(r.perception, "vision");
  EXPECT_TRUE(r.loop.success);
  EXPECT_LE(r.path_error_m.mean, 2.0 * 0.0565);
  EXPECT_LE(r.path_error_m.max, 2.0 * 0.2032);
  // Four objects, four tracks: no object was lost for good.
  EXPECT_EQ(r.vision_counters.new_tracks, 4);
}

}  // namespace
}  // namespace airtwin
