// The plan of a batch: scenario x seed in a fixed order, stable keys, shards that split the runs
// without loss or overlap, and clear refusals.

#include "runs/batch_plan.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <set>

#include "common/errors.h"
#include "tests/support/scratch_dir.h"

namespace airtwin {
namespace {

namespace fs = std::filesystem;

const std::string kScenes = std::string(AIRTWIN_SOURCE_DIR) + "/scenes/";

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(BatchPlan, ParsesShardsZeroBased) {
  EXPECT_EQ(parse_shard("0/1"), (Shard{0, 1}));
  EXPECT_EQ(parse_shard("3/4"), (Shard{3, 4}));
  for (const char* bad : {"4/4", "1", "-1/4", "a/4", "1/0", "1/4x", "", "/", "1/200000"}) {
    EXPECT_THROW(parse_shard(bad), FieldError) << bad;
    EXPECT_NE(message_of([&] { parse_shard(bad); }).find("batch.shard"), std::string::npos) << bad;
  }
}

TEST(BatchPlan, RunsInScenarioThenSeedOrderWithStableKeys) {
  // Files in any order; the plan sorts the scenarios by name.
  const BatchPlan plan =
      make_batch_plan({kScenes + "square.yaml", kScenes + "line.yaml"}, 5, 3, Shard{});
  ASSERT_EQ(plan.scenarios.size(), 2u);
  EXPECT_EQ(plan.scenarios[0].scenario.name, "line");
  const std::vector<RunKey> runs = plan.all_runs();
  ASSERT_EQ(runs.size(), 6u);
  EXPECT_EQ(runs[0], (RunKey{"line", 5}));
  EXPECT_EQ(runs[2], (RunKey{"line", 7}));
  EXPECT_EQ(runs[3], (RunKey{"square", 5}));
  EXPECT_TRUE(std::is_sorted(runs.begin(), runs.end()));
  EXPECT_EQ(runs[1].stem(), "line/seed-6");
  EXPECT_EQ(runs[1].label(), "line seed 6");
  EXPECT_EQ(plan.shard_runs(), runs);
  EXPECT_EQ(plan.scenario("square").file, kScenes + "square.yaml");
}

TEST(BatchPlan, ShardsPartitionTheRunsAndShareEveryScenario) {
  const std::vector<std::string> files = {kScenes + "line.yaml", kScenes + "square.yaml",
                                          kScenes + "octagon.yaml"};
  const std::vector<RunKey> all = make_batch_plan(files, 1, 7, Shard{}).all_runs();
  for (int n : {1, 2, 3, 4, 21, 25}) {
    std::multiset<RunKey> seen;
    for (int i = 0; i < n; ++i) {
      const std::vector<RunKey> mine = make_batch_plan(files, 1, 7, Shard{i, n}).shard_runs();
      EXPECT_TRUE(std::is_sorted(mine.begin(), mine.end()));
      // Shard sizes differ by one at most.
      EXPECT_LE(std::abs(static_cast<int>(mine.size()) * n - static_cast<int>(all.size())), n);
      seen.insert(mine.begin(), mine.end());
    }
    EXPECT_EQ(std::vector<RunKey>(seen.begin(), seen.end()), all) << n << " shards";
  }
  // Two shards of 3 scenarios x 7 seeds: each gets runs of every scenario.
  const std::vector<RunKey> half = make_batch_plan(files, 1, 7, Shard{1, 2}).shard_runs();
  std::set<std::string> names;
  for (const RunKey& k : half) names.insert(k.scenario);
  EXPECT_EQ(names.size(), 3u);
}

TEST(BatchPlan, RefusesDuplicateNamesBadNamesAndBadSeedCounts) {
  const std::string dir = testing::fresh_scratch_dir("plan");
  fs::copy_file(kScenes + "line.yaml", dir + "/line.yaml", fs::copy_options::overwrite_existing);
  // The copy names itself "line" too.
  const std::string dup = message_of([&] {
    make_batch_plan({kScenes + "line.yaml", dir + "/line.yaml"}, 1, 2, {});
  });
  EXPECT_NE(dup.find("'line'"), std::string::npos) << dup;
  // A name that cannot be a folder.
  const std::string text =
      "name: \"a/b\"\nobjects:\n  - {id: t1, type: tracer, x: 0.1, y: 0.2}\n"
      "task: {kind: aggregation, zone: {centre: [0, 0], diameter_m: 0.3}, "
      "time_limit_s: 10}\n";
  std::ofstream(dir + "/slash.yaml") << text;
  const std::string bad_name =
      message_of([&] { make_batch_plan({dir + "/slash.yaml"}, 1, 1, {}); });
  EXPECT_NE(bad_name.find("slash.yaml"), std::string::npos) << bad_name;
  // Seeds and files.
  EXPECT_NE(message_of([&] {
              make_batch_plan({kScenes + "line.yaml"}, 1, 0, {});
            }).find("batch.seed_count"),
            std::string::npos);
  EXPECT_NE(message_of([&] {
              make_batch_plan({kScenes + "line.yaml"}, ~0ull, 2, {});
            }).find("batch.first_seed"),
            std::string::npos);
  EXPECT_NE(message_of([&] { make_batch_plan({}, 1, 2, {}); }).find("batch.scenarios"),
            std::string::npos);
  const std::string missing = message_of([&] { make_batch_plan({dir + "/none.yaml"}, 1, 1, {}); });
  EXPECT_NE(missing.find("none.yaml"), std::string::npos) << missing;
}

TEST(BatchPlan, ContentHashIsFnv1a64) {
  // The FNV-1a reference values of "" and "a".
  EXPECT_EQ(content_hash(""), "cbf29ce484222325");
  EXPECT_EQ(content_hash("a"), "af63dc4c8601ec8c");
  EXPECT_NE(content_hash("line: 1"), content_hash("line: 2"));
}

}  // namespace
}  // namespace airtwin
