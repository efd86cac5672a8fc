// A batch's folder: the manifest guards it, finished runs are exactly the readable records, and
// what a killed batch leaves (a temporary, a damaged record) never counts as finished.

#include "runs/batch_store.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "common/csv.h"
#include "common/errors.h"
#include "tests/support/scratch_dir.h"

namespace airtwin {
namespace {

namespace fs = std::filesystem;

using testing::fresh_scratch_dir;

BatchManifest manifest(int seeds) {
  BatchManifest m;
  m.scenarios = {{"line", "scenes/line.yaml", "00ff"}};
  m.seed_count = seeds;
  m.settings = {{"perception", "truth"}};
  return m;
}

std::string record(uint64_t seed) {
  return failed_record_json({"line", seed}, 1, 120.0, "truth", "diverged", 0.5);
}

TEST(BatchStore, ANewFolderGetsTheManifestAndTheSameBatchReopens) {
  const std::string dir = fresh_scratch_dir("new");
  { BatchStore store(dir, manifest(3)); }
  EXPECT_EQ(
      BatchManifest::parse(read_text_file(dir + "/batch.json"), "b").difference(manifest(3), false),
      "");
  BatchStore again(dir, manifest(3));
  EXPECT_EQ(BatchStore::open_existing(dir).manifest().seed_count, 3);
}

TEST(BatchStore, OtherArgumentsOrAForeignFolderAreRefused) {
  const std::string dir = fresh_scratch_dir("refuse");
  { BatchStore store(dir, manifest(3)); }
  try {
    BatchStore other(dir, manifest(5));
    FAIL() << "resumed with other seeds";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("batch.json"), std::string::npos) << m;
    EXPECT_NE(m.find("/seeds/count: 3 vs 5"), std::string::npos) << m;
  }
  // A folder with files but no batch.json is not taken over.
  const std::string foreign = fresh_scratch_dir("foreign");
  fs::create_directories(foreign);
  std::ofstream(foreign + "/notes.txt") << "mine";
  EXPECT_THROW(BatchStore(foreign, manifest(3)), InputError);
  EXPECT_THROW(BatchStore::open_existing(foreign), InputError);
}

TEST(BatchStore, FinishedRunsAreTheReadableRecords) {
  const std::string dir = fresh_scratch_dir("records");
  const BatchStore store(dir, manifest(3));
  EXPECT_FALSE(store.load({"line", 1}).has_value());
  RunLogs logs{"t,x\n", "t,ref\n", "t,id\n", "t,pan,tilt\n", "frame,t,id\n"};
  store.commit({"line", 1}, record(1), &logs);
  store.commit({"line", 2}, record(2), nullptr);
  ASSERT_TRUE(store.load({"line", 1}).has_value());
  EXPECT_EQ(store.load({"line", 1})->key, (RunKey{"line", 1}));
  EXPECT_EQ(read_text_file(dir + "/runs/line/seed-1.log.csv"), "t,x\n");
  EXPECT_EQ(read_text_file(dir + "/runs/line/seed-1.nozzle.csv"), "t,pan,tilt\n");
  EXPECT_EQ(read_text_file(dir + "/runs/line/seed-1.detections.csv"), "frame,t,id\n");
  EXPECT_EQ(store.record_path({"line", 2}), dir + "/runs/line/seed-2.json");

  // A damaged record, or one holding another run, is not finished and says why.
  std::ofstream(dir + "/runs/line/seed-3.json") << "{\"scenario\": \"li";
  std::string problem;
  EXPECT_FALSE(store.load({"line", 3}, &problem).has_value());
  EXPECT_NE(problem.find("seed-3.json"), std::string::npos) << problem;
  fs::copy_file(dir + "/runs/line/seed-1.json", dir + "/runs/line/seed-3.json",
                fs::copy_options::overwrite_existing);
  problem.clear();
  EXPECT_FALSE(store.load({"line", 3}, &problem).has_value());
  EXPECT_NE(problem.find("line seed 1"), std::string::npos) << problem;
}

TEST(BatchStore, ReopeningRemovesWhatAKilledWriterLeft) {
  const std::string dir = fresh_scratch_dir("stale");
  { BatchStore store(dir, manifest(2)); }
  fs::create_directories(dir + "/runs/line");
  std::ofstream(dir + "/runs/line/seed-1.json.tmp.4242.7") << "{\"scenario\": \"line\", \"se";
  const BatchStore store(dir, manifest(2));
  EXPECT_FALSE(fs::exists(dir + "/runs/line/seed-1.json.tmp.4242.7"));
  EXPECT_FALSE(store.load({"line", 1}).has_value());
}

TEST(BatchStore, CopiesARunWithItsLogs) {
  const std::string a = fresh_scratch_dir("copy_a"), b = fresh_scratch_dir("copy_b");
  const BatchStore from(a, manifest(2)), to(b, manifest(2));
  RunLogs logs{"log\n", "decisions\n", "plans\n", "nozzle\n", "detections\n"};
  from.commit({"line", 2}, record(2), &logs);
  to.copy_run(from, {"line", 2});
  EXPECT_EQ(read_text_file(b + "/runs/line/seed-2.json"), record(2));
  EXPECT_EQ(read_text_file(b + "/runs/line/seed-2.decisions.csv"), "decisions\n");
  EXPECT_EQ(read_text_file(b + "/runs/line/seed-2.plans.csv"), "plans\n");
  EXPECT_EQ(read_text_file(b + "/runs/line/seed-2.nozzle.csv"), "nozzle\n");
  EXPECT_EQ(read_text_file(b + "/runs/line/seed-2.detections.csv"), "detections\n");
  // A run logged before plans.csv and nozzle.csv existed, without vision, is copied without
  // them.
  RunLogs old_logs{"log\n", "decisions\n", "", "", ""};
  from.commit({"line", 1}, record(1), &old_logs);
  to.copy_run(from, {"line", 1});
  EXPECT_EQ(read_text_file(b + "/runs/line/seed-1.decisions.csv"), "decisions\n");
  EXPECT_FALSE(fs::exists(b + "/runs/line/seed-1.plans.csv"));
  EXPECT_FALSE(fs::exists(b + "/runs/line/seed-1.nozzle.csv"));
  EXPECT_FALSE(fs::exists(b + "/runs/line/seed-1.detections.csv"));
}

}  // namespace
}  // namespace airtwin
