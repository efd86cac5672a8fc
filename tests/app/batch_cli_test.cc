// `airtwin batch` and `airtwin batch-merge` end to end: the same runs.csv bytes for any --jobs,
// resumption after kill -9 that loses and duplicates nothing, shards merged into the report of
// the unsharded batch, a refused restart with other arguments, and one clear line for bad input.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "common/csv.h"
#include "tests/app/cli_runner.h"

namespace airtwin {
namespace {

namespace fs = std::filesystem;
using testing::count_lines;
using testing::run_airtwin;
using testing::scratch_dir;

const std::string kScenes = std::string(AIRTWIN_SOURCE_DIR) + "/scenes/";
// Two cheap scenarios (about 0.2 and 0.9 s of CPU per run).
const std::string kBatch = "batch " + kScenes + "line.yaml " + kScenes + "square.yaml ";

// Records (finished runs) in DIR/runs.
int records_in(const std::string& dir) {
  int n = 0;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir + "/runs", ec);
       !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    const std::string name = it->path().filename().string();
    n += name.size() > 5 && name.substr(name.size() - 5) == ".json";
  }
  return n;
}

// report.json without its wall-clock part, and report.md before its timing section.
nlohmann::json results_of(const std::string& dir) {
  nlohmann::json j = nlohmann::json::parse(read_text_file(dir + "/report.json"));
  j.erase("timing");
  return j;
}
std::string md_results_of(const std::string& dir) {
  const std::string md = read_text_file(dir + "/report.md");
  return md.substr(0, md.find("## Timing"));
}

// Starts airtwin with `args` in the background; its stderr (the progress lines) is readable from
// *stderr_fd, so that the caller waits on the batch's own output instead of sleeping.
pid_t start_airtwin(const std::vector<std::string>& args, int* stderr_fd) {
  int fds[2];
  if (::pipe(fds) != 0) return -1;
  const pid_t pid = fork();
  if (pid == 0) {
    std::vector<char*> argv;
    std::string binary = AIRTWIN_BINARY;
    argv.push_back(binary.data());
    std::vector<std::string> copy = args;
    for (std::string& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    const int null = ::open("/dev/null", O_RDWR);
    dup2(null, 0);
    dup2(null, 1);
    dup2(fds[1], 2);
    ::close(fds[0]);
    execv(AIRTWIN_BINARY, argv.data());
    _exit(127);
  }
  ::close(fds[1]);
  *stderr_fd = fds[0];
  return pid;
}

std::vector<std::string> words(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

TEST(BatchCli, RunsCsvIsTheSameForAnyJobCount) {
  const std::string d = scratch_dir("batch_jobs");
  const auto one = run_airtwin(kBatch + "--seeds 3 --jobs 1 --out " + d + "/one");
  ASSERT_EQ(one.exit_code, 0) << one.err;
  const auto two = run_airtwin(kBatch + "--seeds 3 --jobs 2 --out " + d + "/two");
  ASSERT_EQ(two.exit_code, 0) << two.err;
  const std::string csv = read_text_file(d + "/one/runs.csv");
  EXPECT_EQ(count_lines(csv), 1 + 6);
  EXPECT_EQ(csv, read_text_file(d + "/two/runs.csv"));
  EXPECT_EQ(results_of(d + "/one"), results_of(d + "/two"));
  EXPECT_EQ(md_results_of(d + "/one"), md_results_of(d + "/two"));
  EXPECT_EQ(read_text_file(d + "/one/plots/completion_time.png"),
            read_text_file(d + "/two/plots/completion_time.png"));
  // A batch run's record is `airtwin run`'s summary.json plus its wall time.
  const auto run = run_airtwin("run " + kScenes + "line.yaml --seed 2 --quiet --out " + d + "/r");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  auto summary = nlohmann::json::parse(read_text_file(d + "/r/summary.json"));
  auto record = nlohmann::json::parse(read_text_file(d + "/one/runs/line/seed-2.json"));
  for (auto* j : {&summary, &record}) j->erase("decision_ms");
  record.erase("wall_s");
  EXPECT_EQ(summary, record);
  // Plain progress lines when stderr is not a terminal, and the summary on stdout.
  EXPECT_NE(one.err.find("batch 6/6 runs"), std::string::npos) << one.err;
  EXPECT_EQ(one.err.find('\r'), std::string::npos);
  EXPECT_NE(one.out.find("line: 3/3 succeeded"), std::string::npos) << one.out;
}

TEST(BatchCli, KilledAnyTimeItResumesWithoutLossOrDuplicates) {
  const std::string d = scratch_dir("batch_kill");
  // Progress lines on (stderr is a pipe: one plain line per tenth of the runs, each written after
  // the records it counts), so the test waits on them.
  const std::string args = kBatch + "--seeds 6 --jobs 2 --out ";
  const auto whole = run_airtwin(args + d + "/whole");
  ASSERT_EQ(whole.exit_code, 0) << whole.err;

  // Killed twice with SIGKILL while runs are under way, then left to finish.
  int killed_at = 0;
  for (int round = 0; round < 2; ++round) {
    int progress_fd = -1;
    const pid_t pid = start_airtwin(words(args + d + "/killed"), &progress_fd);
    ASSERT_GT(pid, 0);
    // Blocks on the batch's progress output until two more runs are recorded (or it ends).
    char buffer[256];
    while (records_in(d + "/killed") < killed_at + 2 &&
           ::read(progress_fd, buffer, sizeof(buffer)) > 0) {
    }
    ::kill(pid, SIGKILL);
    ::close(progress_fd);
    int status = 0;
    ::waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status)) << "the batch ended before it was killed";
    const int finished = records_in(d + "/killed");
    ASSERT_GE(finished, killed_at + 2);
    ASSERT_LT(finished, 12) << "the batch finished before it was killed";
    killed_at = finished;
  }
  const auto resumed = run_airtwin(args + d + "/killed");
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_NE(resumed.out.find(std::to_string(killed_at) + " finished before, " +
                             std::to_string(12 - killed_at) + " to run"),
            std::string::npos)
      << resumed.out;
  // Every run exactly once, with the results of the batch that was never interrupted, and no
  // temporary file left.
  const std::string csv = read_text_file(d + "/killed/runs.csv");
  EXPECT_EQ(csv, read_text_file(d + "/whole/runs.csv"));
  const CsvTable t =
      CsvTable::parse(csv, "runs.csv", {"scenario", "seed"},
                      {"success",           "completion_time_s", "path_error_mean_cm",
                       "path_error_std_cm", "path_error_max_cm", "max_pairwise_distance_cm",
                       "objects_in_zone",   "n_objects",         "decisions",
                       "end_time_s",        "time_limit_s",      "still_since_s",
                       "perception",        "vision_frames",     "vision_detections",
                       "vision_tracks",     "vision_missed",     "vision_merged",
                       "vision_lost",       "vision_left_view",  "error"});
  std::set<std::string> keys;
  for (size_t r = 0; r < t.rows(); ++r) keys.insert(t.text(r, "scenario") + t.text(r, "seed"));
  EXPECT_EQ(t.rows(), 12u);
  EXPECT_EQ(keys.size(), 12u);
  EXPECT_EQ(records_in(d + "/killed"), 12);
  for (const auto& e : fs::recursive_directory_iterator(d + "/killed")) {
    EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << e.path();
  }
  EXPECT_EQ(results_of(d + "/killed"), results_of(d + "/whole"));
}

TEST(BatchCli, ShardsMergeIntoTheReportOfTheWholeBatch) {
  const std::string d = scratch_dir("batch_shards");
  const std::string args = kBatch + "--seeds 3 --quiet ";
  ASSERT_EQ(run_airtwin(args + "--jobs 2 --out " + d + "/whole").exit_code, 0);
  for (int i = 0; i < 3; ++i) {
    const auto r = run_airtwin(args + "--jobs 1 --shard " + std::to_string(i) + "/3 --out " + d +
                               "/s" + std::to_string(i));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(count_lines(read_text_file(d + "/s" + std::to_string(i) + "/runs.csv")), 1 + 2);
  }
  // Every shard is needed, once.
  const auto partial = run_airtwin("batch-merge " + d + "/s0 " + d + "/s2 --out " + d + "/m");
  EXPECT_EQ(partial.exit_code, 1);
  EXPECT_EQ(count_lines(partial.err), 1) << partial.err;
  EXPECT_NE(partial.err.find("shard 1/3 is missing"), std::string::npos) << partial.err;
  const auto twice =
      run_airtwin("batch-merge " + d + "/s0 " + d + "/s0 " + d + "/s1 --out " + d + "/m");
  EXPECT_EQ(twice.exit_code, 1);
  const auto merged =
      run_airtwin("batch-merge " + d + "/s2 " + d + "/s0 " + d + "/s1 --out " + d + "/merged");
  ASSERT_EQ(merged.exit_code, 0) << merged.err;
  EXPECT_EQ(read_text_file(d + "/merged/runs.csv"), read_text_file(d + "/whole/runs.csv"));
  EXPECT_EQ(results_of(d + "/merged"), results_of(d + "/whole"));
  EXPECT_EQ(md_results_of(d + "/merged"), md_results_of(d + "/whole"));
  EXPECT_EQ(read_text_file(d + "/merged/plots/square.png"),
            read_text_file(d + "/whole/plots/square.png"));
  // The merged folder is the whole batch: `batch` with its arguments finds nothing to do.
  const auto again = run_airtwin(args + "--out " + d + "/merged");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_NE(again.out.find("6 finished before, 0 to run"), std::string::npos) << again.out;
  // Shards of another batch are refused.
  ASSERT_EQ(run_airtwin(kBatch + "--seeds 4 --quiet --shard 1/3 --out " + d + "/x1").exit_code, 0);
  const auto mixed =
      run_airtwin("batch-merge " + d + "/s0 " + d + "/x1 " + d + "/s2 --out " + d + "/m2");
  EXPECT_EQ(mixed.exit_code, 1);
  EXPECT_NE(mixed.err.find("/seeds/count"), std::string::npos) << mixed.err;
}

TEST(BatchCli, VisionBatchCalibratesOnceAndResumesWithThatCamera) {
  // scenes/line.yaml cut to 5 s: a few seconds of rendering per run.
  const std::string d = scratch_dir("batch_vision");
  std::string text = read_text_file(kScenes + "line.yaml");
  text.replace(text.find("name: line"), 10, "name: line_short");
  text.replace(text.find("time_limit_s: 120"), 17, "time_limit_s: 5");
  std::ofstream(d + "/line_short.yaml") << text;
  const std::string args = "batch " + d + "/line_short.yaml --seeds 2 --vision --quiet --out ";
  const auto first = run_airtwin(args + d + "/b");
  ASSERT_EQ(first.exit_code, 0) << first.err;
  EXPECT_TRUE(fs::is_regular_file(d + "/b/calib.yaml"));
  EXPECT_TRUE(fs::is_directory(d + "/b/calibration"));
  const std::string csv = read_text_file(d + "/b/runs.csv");
  EXPECT_NE(csv.find(",vision,"), std::string::npos) << csv;
  // A lost run is redone with the saved camera: the same record.
  fs::remove(d + "/b/runs/line_short/seed-2.json");
  const auto again = run_airtwin(args + d + "/b");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_NE(again.out.find("1 finished before, 1 to run"), std::string::npos) << again.out;
  EXPECT_EQ(read_text_file(d + "/b/runs.csv"), csv);
  // `airtwin run --vision` with that camera gives the batch's record.
  const auto run = run_airtwin("run " + d + "/line_short.yaml --seed 2 --vision --calib " + d +
                               "/b/calib.yaml --quiet --out " + d + "/r");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  auto summary = nlohmann::json::parse(read_text_file(d + "/r/summary.json"));
  auto record = nlohmann::json::parse(read_text_file(d + "/b/runs/line_short/seed-2.json"));
  for (auto* j : {&summary, &record}) {
    j->erase("decision_ms");
    (*j)["vision"].erase("frame_ms");
  }
  record.erase("wall_s");
  EXPECT_EQ(summary, record);
}

TEST(BatchCli, RestartWithOtherArgumentsIsRefused) {
  const std::string d = scratch_dir("batch_args");
  ASSERT_EQ(
      run_airtwin("batch " + kScenes + "line.yaml --seeds 2 --quiet --out " + d + "/b").exit_code,
      0);
  for (const std::string other :
       {"--seeds 3", "--seeds 2 --first-seed 2", "--seeds 2 --shard 0/2",
        "--seeds 2 --effect field_scale:factor=1.1", "--seeds 2 --vary-physics 0.1"}) {
    const auto r =
        run_airtwin("batch " + kScenes + "line.yaml " + other + " --quiet --out " + d + "/b");
    EXPECT_EQ(r.exit_code, 1) << other;
    EXPECT_EQ(count_lines(r.err), 1) << other << ": " << r.err;
    EXPECT_NE(r.err.find("other arguments"), std::string::npos) << r.err;
  }
  // The same arguments, spelled with another path to the same file, continue it.
  const auto same = run_airtwin("batch " + kScenes +
                                "../scenes/line.yaml --seeds 2 --jobs 1 "
                                "--quiet --out " +
                                d + "/b");
  EXPECT_EQ(same.exit_code, 0) << same.err;
}

// Objects that differ: the report splits each drawn parameter by the runs' verdicts, and the
// batch's settings name the variation.
TEST(BatchCli, VariedObjectsGetTheirSectionInTheReport) {
  const std::string d = scratch_dir("batch_vary");
  {
    std::ifstream in(kScenes + "line.yaml");
    std::stringstream text;
    text << in.rdbuf();
    std::string yaml = text.str();
    yaml.replace(yaml.find("time_limit_s: 120"), 17, "time_limit_s: 6");
    std::ofstream(d + "/short.yaml") << yaml;
  }
  const auto r = run_airtwin("batch " + d + "/short.yaml --seeds 2 --vary-physics documented " +
                             "--quiet --out " + d + "/b");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream md(d + "/b/report.md");
  std::stringstream report;
  report << md.rdbuf();
  EXPECT_NE(report.str().find("## Objects that differ (`--vary-physics documented`)"),
            std::string::npos);
  EXPECT_NE(report.str().find("| line | tracer | mu_k |"), std::string::npos) << report.str();
  const auto json = nlohmann::json::parse(std::ifstream(d + "/b/report.json"));
  EXPECT_EQ(json.at("physics_variation"), "documented");
  EXPECT_EQ(json.at("object_physics").size(), 5u);  // mass, C_D, mu_k, mu_s/mu_k, C_L: not the area
  const auto batch = nlohmann::json::parse(std::ifstream(d + "/b/batch.json"));
  EXPECT_EQ(batch.at("settings").at("physics_variation"), "documented");
}

TEST(BatchCli, BadInputIsOneClearLine) {
  const std::string d = scratch_dir("batch_bad");
  const std::string line = "batch " + kScenes + "line.yaml --out " + d + "/o ";
  for (const std::string flags :
       {"", "--seeds 0", "--seeds 2 --jobs -1", "--seeds 2 --shard 2/2", "--seeds 2 --shard x",
        "--seeds 2 --noise low", "--seeds 2 --vision --vision-rate 7", "--seeds 2 --bogus"}) {
    const auto r = run_airtwin(line + flags);
    EXPECT_EQ(r.exit_code, 2) << flags << ": " << r.err;
    EXPECT_EQ(count_lines(r.err), 1) << flags << ": " << r.err;
  }
  EXPECT_FALSE(fs::exists(d + "/o"));  // flags are checked before anything is written
  const auto missing = run_airtwin("batch " + d + "/none.yaml --seeds 2 --out " + d + "/o");
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_EQ(count_lines(missing.err), 1) << missing.err;
  EXPECT_NE(missing.err.find("none.yaml"), std::string::npos);
  const auto twice = run_airtwin("batch " + kScenes + "line.yaml " + kScenes +
                                 "line.yaml --seeds 2 --out " + d + "/o");
  EXPECT_EQ(twice.exit_code, 1);
  EXPECT_EQ(count_lines(twice.err), 1) << twice.err;
  // An output folder that holds other things is not taken over.
  fs::create_directories(d + "/full");
  std::ofstream(d + "/full/notes.txt") << "x";
  const auto full = run_airtwin("batch " + kScenes + "line.yaml --seeds 1 --out " + d + "/full");
  EXPECT_EQ(full.exit_code, 1);
  EXPECT_NE(full.err.find("not empty"), std::string::npos) << full.err;
  // batch-merge: no batch folder, no --out.
  const auto merge = run_airtwin("batch-merge " + d + " --out " + d + "/m");
  EXPECT_EQ(merge.exit_code, 1);
  EXPECT_EQ(count_lines(merge.err), 1) << merge.err;
  EXPECT_EQ(run_airtwin("batch-merge " + d).exit_code, 2);
  // --help documents the shard convention.
  const auto help = run_airtwin("batch --help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("0-based"), std::string::npos);
}

}  // namespace
}  // namespace airtwin
