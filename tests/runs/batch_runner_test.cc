// The batch runner: results independent of the job count (truth and vision: rendering in several
// threads at once), resumption that runs only what is missing, and a stop on bad input.

#include "runs/batch_runner.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "common/csv.h"
#include "common/errors.h"
#include "models/track_join.h"
#include "runs/batch_report.h"
#include "sim/scene_builder.h"
#include "tests/support/scratch_dir.h"
#include "tests/vision/twin_frames.h"

namespace airtwin {
namespace {

namespace fs = std::filesystem;

const std::string kScenes = std::string(AIRTWIN_SOURCE_DIR) + "/scenes/";

using testing::fresh_scratch_dir;

// scenes/line.yaml cut to `limit_s` of simulated time under another name (a cheap scenario).
std::string short_line(const std::string& dir, double limit_s) {
  std::string text = read_text_file(kScenes + "line.yaml");
  text.replace(text.find("name: line"), 10, "name: line_short");
  text.replace(text.find("time_limit_s: 120"), 17, "time_limit_s: " + std::to_string(limit_s));
  fs::create_directories(dir);
  std::ofstream(dir + "/line_short.yaml") << text;
  return dir + "/line_short.yaml";
}

BatchRunResult run_in(const std::string& dir, const BatchPlan& plan, BatchRunOptions options) {
  const BatchStore store(dir, BatchManifest::of_plan(plan, {{"perception", "test"}}));
  return run_batch(plan, AirFieldModel::with_constructed_table(), store, options);
}

// The batch run with one and with two worker threads, each in a folder of its own under `dir`.
std::pair<BatchRunResult, BatchRunResult> with_one_and_two_jobs(const std::string& dir,
                                                                const BatchPlan& plan,
                                                                BatchRunOptions options) {
  options.jobs = 1;
  BatchRunResult one = run_in(dir + "/one", plan, options);
  options.jobs = 2;
  return {std::move(one), run_in(dir + "/two", plan, options)};
}

TEST(BatchRunner, ResultsDoNotDependOnTheJobCount) {
  const BatchPlan plan =
      make_batch_plan({kScenes + "square.yaml", kScenes + "line.yaml"}, 1, 3, Shard{});
  const auto [a, b] = with_one_and_two_jobs(fresh_scratch_dir("jobs"), plan, {});
  ASSERT_EQ(a.records.size(), 6u);
  EXPECT_EQ(a.ran, 6);
  EXPECT_EQ(a.finished_before, 0);
  // Records in plan order, whatever order they finished in, with equal results.
  for (size_t i = 0; i < a.records.size(); ++i) EXPECT_EQ(a.records[i].key, plan.all_runs()[i]);
  EXPECT_EQ(runs_csv(a.records), runs_csv(b.records));
}

TEST(BatchRunner, ResumesOnlyWhatIsMissing) {
  const std::string dir = fresh_scratch_dir("resume");
  const BatchPlan plan = make_batch_plan({kScenes + "line.yaml"}, 1, 5, Shard{});
  BatchRunOptions options;
  options.jobs = 2;
  const BatchRunResult first = run_in(dir, plan, options);
  // Two runs lost (as if killed before they finished) and one damaged record.
  fs::remove(dir + "/runs/line/seed-2.json");
  fs::remove(dir + "/runs/line/seed-5.json");
  std::ofstream(dir + "/runs/line/seed-3.json", std::ios::trunc) << "{\"scen";
  int redone = 0, started_before = -1, started_to_run = -1;
  options.on_redo = [&](const std::string&) { ++redone; };
  options.on_start = [&](int before, int to_run) {
    started_before = before;
    started_to_run = to_run;
  };
  const BatchRunResult again = run_in(dir, plan, options);
  EXPECT_EQ(redone, 1);
  EXPECT_EQ(started_before, 2);
  EXPECT_EQ(started_to_run, 3);
  EXPECT_EQ(again.finished_before, 2);
  EXPECT_EQ(again.ran, 3);
  EXPECT_EQ(runs_csv(again.records), runs_csv(first.records));
  // A third start has nothing to do.
  const BatchRunResult done = run_in(dir, plan, options);
  EXPECT_EQ(done.ran, 0);
  EXPECT_EQ(runs_csv(done.records), runs_csv(first.records));
}

TEST(BatchRunner, VisionRunsInTwoThreadsGiveTheRecordsOfOne) {
  // Each run renders through its own OSMesa context in its worker thread; two at once must give
  // what one thread gives (tracker counters included).
  const std::string dir = fresh_scratch_dir("vision");
  const BatchPlan plan = make_batch_plan({short_line(dir + "/scenes", 5.0)}, 1, 2, Shard{});
  const ModelPtr m = load_model_from_xml(scene_xml(SceneSpec{}, SceneParameters{}, 0), "test");
  BatchRunOptions options;
  options.run.vision_camera = testing::camera_from_truth(GroundTruthCamera::from_model(m.get()));
  options.keep_logs = true;
  const auto [a, b] = with_one_and_two_jobs(dir, plan, options);
  ASSERT_EQ(a.records.size(), 2u);
  for (const RunRecord& r : a.records) {
    EXPECT_EQ(r.perception, "vision");
    EXPECT_GT(r.vision_detections, 0);
    // The logs keep what the camera detected, as `detect` writes it, one row per detection, the
    // same bytes from either thread count; and the nozzle's log beside it.
    const std::string stem = "/runs/line_short/seed-" + std::to_string(r.key.seed);
    const std::string detections = dir + "/one" + stem + ".detections.csv";
    const DetectionTable table = read_detections_csv(detections);
    EXPECT_EQ(static_cast<int>(table.rows.size()), r.vision_detections);
    EXPECT_EQ(read_text_file(detections), read_text_file(dir + "/two" + stem + ".detections.csv"));
    EXPECT_TRUE(fs::is_regular_file(dir + "/one" + stem + ".nozzle.csv"));
  }
  EXPECT_EQ(runs_csv(a.records), runs_csv(b.records));
}

TEST(BatchRunner, BadInputStopsTheBatchAndKeepsWhatFinished) {
  // No dynamics for tracers: every run fails at its first decision with an InputError.
  const std::string dir = fresh_scratch_dir("stop");
  const BatchPlan plan = make_batch_plan({kScenes + "line.yaml"}, 1, 4, Shard{});
  BatchRunOptions options;
  options.jobs = 2;
  options.run.dynamics.erase("tracer");
  EXPECT_THROW(run_in(dir, plan, options), InputError);
  const BatchStore store = BatchStore::open_existing(dir);
  for (const RunKey& k : plan.all_runs()) EXPECT_FALSE(store.load(k).has_value());
}

}  // namespace
}  // namespace airtwin
