// A run's record: summary.json's fields and the wall time, read back exactly; a twin failure's
// record; refusal of what is no record.

#include "runs/batch_record.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "common/errors.h"

namespace airtwin {
namespace {

TEST(BatchRecord, HoldsTheRunSummaryAndReadsBackExactly) {
  const Scenario sc = read_scenario(std::string(AIRTWIN_SOURCE_DIR) + "/scenes/line.yaml");
  ScenarioRunOptions options;
  options.seed = 2;
  const ScenarioRunResult r = run_scenario(sc, AirFieldModel::with_constructed_table(), options);
  const std::string json = record_json(r, sc.task.time_limit_s, 0.25);
  // The summary's keys in its order, then the wall time.
  const auto j = nlohmann::ordered_json::parse(json);
  const auto summary = nlohmann::ordered_json::parse(run_summary_json(r, sc.task.time_limit_s));
  auto it = j.begin();
  for (auto s = summary.begin(); s != summary.end(); ++s, ++it) {
    EXPECT_EQ(it.key(), s.key());
    EXPECT_EQ(it.value(), s.value());
  }
  EXPECT_EQ(it.key(), "wall_s");

  const RunRecord rec = parse_record(json, "r.json");
  EXPECT_EQ(rec.key, (RunKey{"line", 2}));
  EXPECT_EQ(rec.success, r.loop.success);
  ASSERT_TRUE(rec.completion_time_s.has_value());
  EXPECT_EQ(*rec.completion_time_s, *r.loop.completion_time_s);  // bit for bit
  EXPECT_EQ(*rec.path_error_mean_cm, 100.0 * r.path_error_m.mean);
  EXPECT_EQ(*rec.path_error_max_cm, 100.0 * r.path_error_m.max);
  EXPECT_EQ(rec.decisions, static_cast<int64_t>(r.loop.decisions.size()));
  EXPECT_EQ(rec.end_time_s, r.loop.end_time_s);
  EXPECT_EQ(rec.time_limit_s, sc.task.time_limit_s);
  ASSERT_TRUE(rec.still_since_s.has_value());
  EXPECT_EQ(*rec.still_since_s, r.still_since_s);
  EXPECT_EQ(rec.perception, "truth");
  EXPECT_EQ(rec.wall_s, 0.25);
  EXPECT_TRUE(rec.error.empty());
  // The still time from the log itself: the last sample at which an object was more than 1 cm
  // from where it was at the previous such sample (a second implementation over the log).
  double since = 0.0;
  std::vector<Eigen::Vector2d> from;
  const auto& trajectories = r.log.trajectories;
  for (size_t k = 0; k < trajectories[0].samples.size(); ++k) {
    bool moved = from.empty();
    for (size_t i = 0; i < trajectories.size() && !from.empty(); ++i) {
      moved = moved || (trajectories[i].samples[k].p_W - from[i]).norm() > 0.01;
    }
    if (!moved) continue;
    from.clear();
    for (const auto& t : trajectories) from.push_back(t.samples[k].p_W);
    since = trajectories[0].samples[k].t_s;
  }
  EXPECT_EQ(r.still_since_s, since);
  EXPECT_GT(since, 0.0);
  EXPECT_LE(since, r.loop.end_time_s);
}

// A run of objects that differ: its record keeps the variation and each object's physics.
TEST(BatchRecord, KeepsTheObjectsDrawnPhysics) {
  ScenarioRunResult r;
  r.scenario = "pair";
  r.seed = 4;
  r.n_objects = 2;
  r.physics_variation = "0.1";
  r.object_physics = {{"b", "tracer:mass_g=0.15,mu_s_ratio=1.1"},
                      {"a", "cotton:mass_g=0.23,mu_s_ratio=1.2"}};
  const RunRecord rec = parse_record(record_json(r, 60.0, 1.0), "r.json");
  EXPECT_EQ(rec.physics_variation, "0.1");
  ASSERT_EQ(rec.object_physics.size(), 2u);
  EXPECT_EQ(rec.object_physics[0].id, "b");  // the run's order
  EXPECT_EQ(rec.object_physics[0].physics, r.object_physics[0].physics);
  EXPECT_EQ(rec.object_physics[1].physics, r.object_physics[1].physics);
  // A record without them (no variation) has none.
  r.physics_variation.clear();
  r.object_physics.clear();
  EXPECT_TRUE(parse_record(record_json(r, 60.0, 1.0), "r.json").object_physics.empty());
}

// Records of an earlier airtwin (a batch resumed across versions) have no still_since_s.
TEST(BatchRecord, ReadsRecordsWrittenBeforeTheStillTime) {
  std::string json = failed_record_json({"line", 1}, 1, 120.0, "truth", "x", 1.0);
  const auto at = json.find("  \"still_since_s\": null,\n");
  ASSERT_NE(at, std::string::npos);
  json.erase(at, std::string("  \"still_since_s\": null,\n").size());
  EXPECT_FALSE(parse_record(json, "r.json").still_since_s.has_value());
}

TEST(BatchRecord, ATwinFailureIsAFailedRunWithItsMessage) {
  const std::string json =
      failed_record_json({"octagon", 9}, 4, 400.0, "truth", "object t2: NaN at t = 3.1 s", 1.5);
  const RunRecord rec = parse_record(json, "r.json");
  EXPECT_EQ(rec.key, (RunKey{"octagon", 9}));
  EXPECT_FALSE(rec.success);
  EXPECT_FALSE(rec.completion_time_s.has_value());
  EXPECT_FALSE(rec.path_error_mean_cm.has_value());
  EXPECT_EQ(rec.n_objects, 4);
  EXPECT_EQ(rec.error, "object t2: NaN at t = 3.1 s");
}

TEST(BatchRecord, RefusesWhatIsNoRecordNamingTheKey) {
  EXPECT_THROW(parse_record("{\"scenario\": \"li", "r.json"), InputError);
  EXPECT_THROW(parse_record("[1, 2]", "r.json"), InputError);
  std::string json = failed_record_json({"line", 1}, 1, 120.0, "truth", "x", 1.0);
  json.replace(json.find("\"wall_s\""), 8, "\"wall\"");
  try {
    parse_record(json, "r.json");
    FAIL() << "accepted a record without wall_s";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("r.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("wall_s"), std::string::npos) << e.what();
  }
}

// A seed or a count outside its type is refused, not cast: a seed past 2^64 was read as a double
// and cast, undefined behaviour (fuzz/batch_record_fuzz.cc, docs/fuzzing.md).
TEST(BatchRecord, RefusesSeedsAndCountsOutOfRange) {
  const std::string good = failed_record_json({"line", 1}, 1, 120.0, "truth", "x", 1.0);
  const std::vector<std::pair<std::string, std::string>> edits = {
      {"\"seed\": 1", "\"seed\": 18446744073709551616"},
      {"\"seed\": 1", "\"seed\": -1"},
      {"\"n_objects\": 1", "\"n_objects\": 1e300"},
      {"\"decisions\": 0", "\"decisions\": -1"}};
  for (const auto& [from, to] : edits) {
    std::string json = good;
    json.replace(json.find(from), from.size(), to);
    EXPECT_THROW(parse_record(json, "r.json"), InputError) << to;
  }
}

}  // namespace
}  // namespace airtwin
