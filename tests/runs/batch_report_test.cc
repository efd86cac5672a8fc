// The batch report: distributions with their worst seed, success rates with Wilson intervals,
// runs.csv in (scenario, seed) order whatever the input order, and the files it writes.

#include "runs/batch_report.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <random>

#include "common/csv.h"
#include "common/errors.h"
#include "tests/support/scratch_dir.h"

namespace airtwin {
namespace {

namespace fs = std::filesystem;

RunRecord path_run(const std::string& scenario, uint64_t seed, bool success, double time_s,
                   double error_cm) {
  RunRecord r;
  r.key = {scenario, seed};
  r.success = success;
  if (success) r.completion_time_s = time_s;
  r.path_error_mean_cm = error_cm;
  r.path_error_std_cm = 0.5 * error_cm;
  r.path_error_max_cm = 3.0 * error_cm;
  r.n_objects = 1;
  r.objects_in_zone = success ? 1 : 0;
  r.decisions = 10 + static_cast<int64_t>(seed);
  r.end_time_s = success ? time_s : 120.0;
  r.time_limit_s = 120.0;
  r.wall_s = 0.1 * static_cast<double>(seed);
  return r;
}

TEST(BatchReport, DistributionHasMedianP90AndTheWorstSeed) {
  const Distribution d = distribution({3, 1, 4, 1, 5}, {10, 11, 12, 13, 14});
  EXPECT_EQ(d.count, 5);
  EXPECT_DOUBLE_EQ(d.mean, 2.8);
  EXPECT_DOUBLE_EQ(d.median, 3.0);
  EXPECT_DOUBLE_EQ(d.p90, 4.6);  // numpy.quantile([1, 1, 3, 4, 5], 0.9)
  EXPECT_EQ(d.worst, 5.0);
  EXPECT_EQ(d.worst_seed, 14u);
  // Ties go to the smallest seed; where higher is better the smallest value is the worst.
  EXPECT_EQ(distribution({2, 7, 7}, {5, 9, 8}).worst_seed, 8u);
  const Distribution zone = distribution({1.0, 0.5, 0.5}, {1, 3, 2}, /*higher_is_better=*/true);
  EXPECT_EQ(zone.worst, 0.5);
  EXPECT_EQ(zone.worst_seed, 2u);
  EXPECT_EQ(distribution({}, {}).count, 0);
}

TEST(BatchReport, StatsPerScenarioWithFailuresAndWilsonIntervals) {
  std::vector<RunRecord> records;
  for (uint64_t s = 1; s <= 10; ++s) {
    records.push_back(path_run("line", s, s != 4 && s != 7, 30.0 + s, 0.1 * s));
  }
  RunRecord diverged = path_run("zeta", 1, false, 0, 0);
  diverged.error = "diverged";
  diverged.path_error_mean_cm.reset();
  diverged.path_error_std_cm.reset();
  diverged.path_error_max_cm.reset();
  records.push_back(diverged);
  const std::vector<ScenarioStats> stats = scenario_stats(records);
  ASSERT_EQ(stats.size(), 2u);
  const ScenarioStats& line = stats[0];
  EXPECT_EQ(line.scenario, "line");
  EXPECT_EQ(line.runs, 10);
  EXPECT_EQ(line.successes, 8);
  EXPECT_DOUBLE_EQ(line.success_rate, 0.8);
  // Wilson 95% for 8/10: 0.490 .. 0.943.
  EXPECT_NEAR(line.success_ci95_low, 0.4902, 1e-3);
  EXPECT_NEAR(line.success_ci95_high, 0.9433, 1e-3);
  EXPECT_EQ(line.failed_seeds, (std::vector<uint64_t>{4, 7}));
  // Times over the 8 successes, errors over all 10 runs.
  EXPECT_EQ(line.completion_time_s.count, 8);
  EXPECT_EQ(line.completion_time_s.worst_seed, 10u);
  ASSERT_TRUE(line.path_error_max_cm.has_value());
  EXPECT_EQ(line.path_error_max_cm->count, 10);
  EXPECT_DOUBLE_EQ(line.path_error_max_cm->worst, 3.0);
  EXPECT_EQ(line.decisions.worst_seed, 10u);
  // Seed 4 failed with its objects still for the last 6 s, seed 7 for the last 4 s: only 4
  // stalled (kStalledSpan_s 5 s); a success still at its end never stalls.
  EXPECT_TRUE(line.stalled_seeds.empty());  // no still times given
  records[3].still_since_s = 114.0;
  records[6].still_since_s = 116.0;
  records[0].still_since_s = 0.0;
  EXPECT_EQ(scenario_stats(records)[0].stalled_seeds, (std::vector<uint64_t>{4}));
  const ScenarioStats& zeta = stats[1];
  EXPECT_EQ(zeta.twin_failure_seeds, (std::vector<uint64_t>{1}));
  EXPECT_EQ(zeta.failed_seeds, (std::vector<uint64_t>{1}));
  EXPECT_EQ(zeta.max_pairwise_distance_cm.count, 0);
}

// Objects that differ: each drawn parameter's values split by the runs' verdicts, recounted by
// hand; the keys that did not vary, twin failures and records without object physics left out.
TEST(BatchReport, PhysicsSensitivitySplitsEachDrawnValueByTheRunsVerdict) {
  std::vector<RunRecord> records;
  const double mu[4] = {0.30, 0.36, 0.44, 0.48};
  for (uint64_t s = 1; s <= 4; ++s) {
    RunRecord r = path_run("square", s, s >= 3, 100.0, 1.0);
    r.physics_variation = "documented";
    r.object_physics = {{"t1", "tracer:mass_g=0.16,cd=0.35,area_cm2=3.5,mu_k=" +
                                   std::to_string(mu[s - 1]) + ",mu_s_ratio=1.4,cl=0.2"}};
    records.push_back(r);
  }
  RunRecord diverged = records[0];
  diverged.key.seed = 5;
  diverged.error = "the twin diverged";
  diverged.object_physics[0].physics = "tracer:mass_g=0.16,mu_k=0.9";
  records.push_back(diverged);
  records.push_back(path_run("line", 1, true, 30.0, 0.1));  // nothing varied
  const std::vector<PhysicsSensitivity> table = physics_sensitivity(records);
  ASSERT_EQ(table.size(), 1u);  // only mu_k varied
  EXPECT_EQ(table[0].scenario, "square");
  EXPECT_EQ(table[0].type, "tracer");
  EXPECT_EQ(table[0].key, "mu_k");
  EXPECT_EQ(table[0].successes.count, 2);
  EXPECT_NEAR(table[0].successes.median, 0.46, 1e-12);
  EXPECT_EQ(table[0].failures.count, 2);
  EXPECT_NEAR(table[0].failures.median, 0.33, 1e-12);
  EXPECT_EQ(table[0].failures.worst_seed, 2u);
  // A record whose physics cannot be read names its run and the object.
  records[1].object_physics[0].physics = "tracer:mu_k=nine";
  try {
    physics_sensitivity(records);
    ADD_FAILURE() << "an unreadable record was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'t1'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("square"), std::string::npos) << e.what();
  }
}

TEST(BatchReport, RunsCsvIsInScenarioSeedOrderWhateverTheInputOrder) {
  std::vector<RunRecord> records;
  for (const char* name : {"square", "line"}) {
    for (uint64_t s = 1; s <= 12; ++s) records.push_back(path_run(name, s, s % 5 != 0, 40.0, 0.3));
  }
  const std::string sorted = runs_csv(records);
  std::mt19937 shuffle(7);
  std::shuffle(records.begin(), records.end(), shuffle);
  EXPECT_EQ(runs_csv(records), sorted);
  // Read back with the project's strict CSV reader: one row per run, line seed 1 first, 10 after 9.
  const CsvTable t = CsvTable::parse(
      sorted, "runs.csv",
      {"scenario", "seed", "success", "completion_time_s", "path_error_mean_cm", "error"},
      {"path_error_std_cm", "path_error_max_cm", "max_pairwise_distance_cm", "objects_in_zone",
       "n_objects", "decisions", "end_time_s", "time_limit_s", "still_since_s", "perception",
       "vision_frames", "vision_detections", "vision_tracks", "vision_missed", "vision_merged",
       "vision_lost", "vision_left_view"});
  ASSERT_EQ(t.rows(), 24u);
  EXPECT_EQ(t.text(0, "scenario"), "line");
  EXPECT_EQ(t.text(9, "seed"), "10");
  EXPECT_EQ(t.text(4, "completion_time_s"), "");  // seed 5 failed
  EXPECT_EQ(t.text(12, "scenario"), "square");
}

TEST(BatchReport, WritesEveryFileAndTimingApartFromResults) {
  const std::string dir = testing::fresh_scratch_dir("report");
  BatchManifest m;
  m.scenarios = {{"line", "line.yaml", "01"}};
  m.seed_count = 6;
  m.settings = {{"perception", "truth"}};
  std::vector<RunRecord> records;
  for (uint64_t s = 1; s <= 6; ++s) records.push_back(path_run("line", s, s != 3, 20.0 + s, 0.2));
  write_batch_report(dir, m, records);
  for (const char* f :
       {"runs.csv", "timings.csv", "report.json", "report.md", "plots/completion_time.png",
        "plots/path_error_mean.png", "plots/path_error_max.png", "plots/line.png"}) {
    EXPECT_TRUE(fs::is_regular_file(dir + "/" + f)) << f;
  }
  auto j = nlohmann::json::parse(read_text_file(dir + "/report.json"));
  EXPECT_EQ(j["scenarios"][0]["successes"], 5);
  EXPECT_EQ(j["scenarios"][0]["completion_time_s"]["worst_seed"], 6);
  EXPECT_EQ(j["batch"]["seeds"]["count"], 6);
  EXPECT_FALSE(j["batch"]["scenarios"][0].contains("file"));
  // Wall-clock figures only under "timing" and in timings.csv.
  const std::string md = read_text_file(dir + "/report.md");
  EXPECT_NE(md.find("## Timing"), std::string::npos);
  for (RunRecord& r : records) r.wall_s *= 3.0;
  const std::string before = read_text_file(dir + "/runs.csv");
  write_batch_report(dir, m, records);
  EXPECT_EQ(read_text_file(dir + "/runs.csv"), before);
  auto k = nlohmann::json::parse(read_text_file(dir + "/report.json"));
  k.erase("timing");
  j.erase("timing");
  EXPECT_EQ(k, j);
  const std::string md2 = read_text_file(dir + "/report.md");
  EXPECT_EQ(md2.substr(0, md2.find("## Timing")), md.substr(0, md.find("## Timing")));
  EXPECT_NE(md2, md);
}

}  // namespace
}  // namespace airtwin
