// A batch's manifest: what its results depend on, compared without file paths, with or without
// the shard.

#include "runs/batch_manifest.h"

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "common/errors.h"

namespace airtwin {
namespace {

BatchManifest example() {
  BatchManifest m;
  m.scenarios = {{"line", "scenes/line.yaml", "00ff"}, {"square", "scenes/square.yaml", "0a0b"}};
  m.first_seed = 3;
  m.seed_count = 4;
  m.shard = {1, 3};
  m.settings = {{"perception", "truth"}, {"table", {{"file", "t.csv"}, {"content_hash", "77"}}}};
  return m;
}

TEST(BatchManifest, RoundTripsThroughItsJson) {
  const BatchManifest m = example();
  const BatchManifest back = BatchManifest::parse(m.to_json(), "batch.json");
  EXPECT_EQ(back.to_json(), m.to_json());
  EXPECT_EQ(back.difference(m, false), "");
  EXPECT_EQ(back.shard_runs(), m.shard_runs());
  ASSERT_EQ(m.all_runs().size(), 8u);
  EXPECT_EQ(m.all_runs().front(), (RunKey{"line", 3}));
}

TEST(BatchManifest, ComparesContentNotPaths) {
  const BatchManifest a = example();
  BatchManifest b = a;
  b.scenarios[0].file = "/elsewhere/line.yaml";
  b.settings["table"]["file"] = "/cluster/t.csv";
  EXPECT_EQ(a.difference(b, false), "");
  b.scenarios[0].content_hash = "00fe";
  EXPECT_EQ(a.difference(b, false), "/scenarios/0/content_hash: \"00ff\" vs \"00fe\"");
  BatchManifest c = a;
  c.seed_count = 5;
  EXPECT_EQ(a.difference(c, false), "/seeds/count: 4 vs 5");
  BatchManifest d = a;
  d.settings["perception"] = "vision";
  EXPECT_NE(a.difference(d, false).find("/settings/perception"), std::string::npos);
  BatchManifest e = a;
  e.scenarios.pop_back();
  EXPECT_NE(a.difference(e, false).find("/scenarios/1"), std::string::npos);
}

TEST(BatchManifest, ShardsOfOneBatchDifferOnlyInTheShard) {
  const BatchManifest a = example();
  BatchManifest other = a;
  other.shard = {2, 3};
  EXPECT_EQ(a.difference(other, true), "");
  EXPECT_EQ(a.difference(other, false), "/shard/index: 1 vs 2");
  EXPECT_FALSE(a.identity(false).contains("shard"));
  EXPECT_FALSE(a.identity(true)["scenarios"][0].contains("file"));
}

TEST(BatchManifest, RefusesWhatIsNoManifest) {
  EXPECT_THROW(BatchManifest::parse("not json", "b.json"), InputError);
  EXPECT_THROW(BatchManifest::parse("{\"format\": \"other\"}", "b.json"), InputError);
  std::string text = example().to_json();
  text.replace(text.find("\"count\": 3"), 10, "\"count\": 0");  // the shard's count
  try {
    BatchManifest::parse(text, "b.json");
    FAIL() << "accepted a shard count of 0";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("b.json"), std::string::npos);
  }
}

// Seeds and shards outside their type are refused, not cast: a count of 6.7e21 was read as a
// double and cast to int, undefined behaviour (fuzz/batch_manifest_fuzz.cc, docs/fuzzing.md).
TEST(BatchManifest, RefusesSeedsAndShardsOutOfRange) {
  const std::string good = example().to_json();
  const std::vector<std::pair<std::string, std::string>> edits = {
      {"\"count\": 4", "\"count\": 6.7e21"},
      {"\"count\": 4", "\"count\": 2147483648"},
      {"\"first\": 3", "\"first\": -3"},
      {"\"index\": 1", "\"index\": 1.5"}};
  for (const auto& [from, to] : edits) {
    std::string text = good;
    text.replace(text.find(from), from.size(), to);
    EXPECT_THROW(BatchManifest::parse(text, "b.json"), InputError) << to;
  }
}

}  // namespace
}  // namespace airtwin
