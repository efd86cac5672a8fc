#pragma once
// What a batch reports (airtwin batch, batch-merge), from the records of its runs:
//
//   runs.csv     one row per run in (scenario, seed) order: the result fields of the records
//   timings.csv  one row per run: wall-clock figures (machine dependent, so apart from runs.csv)
//   report.json  per scenario: success rate (with a 95% Wilson interval), failed seeds (and of
//                them the stalled: objects still for the last kStalledSpan_s of the run), and the
//                distributions over seeds of completion time, path error, pairwise distance,
//                objects in zone and decisions: count, mean, median, p90, worst value and the
//                worst seed; then the same for the timings under "timing"
//                with objects that differ (--vary-physics), each drawn parameter's values over
//                the successful runs' objects and over the failed runs' (physics_sensitivity)
//   report.md    the same for people, with the plots
//   plots/       completion_time.png, path_error_mean.png, path_error_max.png (box plots over the
//                scenarios), <scenario>.png (histograms of one scenario)
//
// runs.csv, the plots and everything in report.json and report.md but their "timing" part depend
// on the batch's scenarios, seeds and settings only: equal for any job count, any order of
// completion, and for shards merged (docs/batch.md). Quantiles: common/quantile.h. Completion
// times are over the successful runs, the other figures over every run the twin completed (a
// failed run's path error is what the controller did); twin failures are listed apart.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "runs/batch_manifest.h"
#include "runs/batch_record.h"

namespace airtwin {

/// A figure's distribution over the runs of a scenario.
struct Distribution {
  int count = 0;  ///< runs with the figure; the rest is 0 when count is 0
  double mean = 0.0, median = 0.0, p90 = 0.0;
  double worst = 0.0;       ///< the largest value (the smallest where higher is better)
  uint64_t worst_seed = 0;  ///< its seed (the smallest such seed on ties)
};

struct ScenarioStats {
  std::string scenario;
  int runs = 0, successes = 0;
  double success_rate = 0.0;
  double success_ci95_low = 0.0, success_ci95_high = 0.0;  ///< Wilson score interval
  std::vector<uint64_t> failed_seeds;                      ///< not done in time, or the twin failed
  std::vector<uint64_t> twin_failure_seeds;
  std::vector<uint64_t> stalled_seeds;  ///< failed runs that had stalled (stalled())
  Distribution completion_time_s;       ///< successful runs
  /// Path tasks only (unset for zone tasks): per-run mean and max distance to the path (cm).
  std::optional<Distribution> path_error_mean_cm, path_error_max_cm;
  Distribution max_pairwise_distance_cm;
  Distribution objects_in_zone_fraction;  ///< objects_in_zone / n_objects at the end
  Distribution decisions;
};

/// With objects that differ (--vary-physics): one drawn parameter of one object type in one
/// scenario, over the objects of its successful runs and over those of its failed runs (each
/// value's seed its run's). Where the two part, the controller is sensitive to that parameter.
struct PhysicsSensitivity {
  std::string scenario, type, key;  ///< key: sim/object_physics.h's, in its typed unit
  Distribution successes, failures;
};

/// Every (scenario, type, key) whose drawn values differ between the runs of `records`, in
/// scenario, type and catalogue order; none without varied objects. Throws InputError naming the
/// run for a record whose object physics cannot be read.
std::vector<PhysicsSensitivity> physics_sensitivity(const std::vector<RunRecord>& records);

/// The record's run failed and had stalled at its end (run_stalled, runs/scenario_run.h).
bool stalled(const RunRecord& record);

/// The statistics of each scenario of `records` (in the order the scenarios first appear).
std::vector<ScenarioStats> scenario_stats(const std::vector<RunRecord>& records);

/// A figure's distribution: `values` with the seed of each (same length); `higher_is_better`
/// makes the smallest value the worst.
Distribution distribution(const std::vector<double>& values, const std::vector<uint64_t>& seeds,
                          bool higher_is_better = false);

/// runs.csv's text for `records` (sorted by (scenario, seed) here).
std::string runs_csv(std::vector<RunRecord> records);
/// timings.csv's text (same order).
std::string timings_csv(std::vector<RunRecord> records);

/// Writes runs.csv, timings.csv, report.json, report.md and plots/ into `dir` for the runs
/// `records` of the batch `manifest` (the shard's runs, or all). Throws InputError when a file
/// cannot be written.
void write_batch_report(const std::string& dir, const BatchManifest& manifest,
                        const std::vector<RunRecord>& records);

}  // namespace airtwin
