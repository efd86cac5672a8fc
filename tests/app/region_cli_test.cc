// `airtwin region` end to end: the files it writes, region.json's counts against a tally of
// region.csv's rows (a second count of the same verdicts), the picture's panels, and one clear
// line for bad input. (The region's geometry and verdicts are tested in tests/runs.)

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "common/csv.h"
#include "tests/app/cli_runner.h"

namespace airtwin {
namespace {

using testing::count_lines;
using testing::file_text;
using testing::mirror_flags;
using testing::run_airtwin;
using testing::scratch_dir;

const std::string kSmall = " --extent 0.4 --step 0.4 --directions 4 --quiet ";

// moved / of per class and in all, and the agreement, counted from region.csv's rows.
struct Tally {
  std::array<int, 3> moved{}, of{};
  int all_moved = 0, all_of = 0;
};

TEST(RegionCli, MirrorTwinCountsMatchTheRowsAndThePictureHasBothMaps) {
  const std::string d = scratch_dir("region_twin");
  const auto r = run_airtwin("region" + kSmall + "--twin --seed 4" + mirror_flags() +
                             "--trajectories-out " + d + "/trajectories.csv --out " + d);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("9 points x 4 directions, 36 pushes the nozzle can aim"), std::string::npos)
      << r.out;
  const CsvTable csv = CsvTable::read_file(
      d + "/region.csv",
      {"x", "y", "direction_deg", "class", "reachable", "model_along_m", "twin_along_m"},
      {"s_x", "s_y", "pan_deg", "tilt_deg", "model_end_x", "model_end_y", "twin_end_x",
       "twin_end_y"});
  ASSERT_EQ(csv.rows(), 36u);
  const std::array<std::string, 3> classes = {"away", "across", "toward"};
  Tally model, twin;
  int both = 0, model_only = 0, twin_only = 0, neither = 0;
  for (size_t i = 0; i < csv.rows(); ++i) {
    ASSERT_EQ(csv.text(i, "reachable"), "1");
    const size_t c = static_cast<size_t>(
        std::find(classes.begin(), classes.end(), csv.text(i, "class")) - classes.begin());
    ASSERT_LT(c, 3u) << csv.text(i, "class");
    const bool m = csv.number(i, "model_along_m") >= 0.01;
    const bool t = csv.number(i, "twin_along_m") >= 0.01;
    for (auto [tally, moved] : {std::pair{&model, m}, std::pair{&twin, t}}) {
      ++tally->of[c];
      ++tally->all_of;
      tally->moved[c] += moved ? 1 : 0;
      tally->all_moved += moved ? 1 : 0;
    }
    (m ? (t ? both : model_only) : (t ? twin_only : neither))++;
  }
  const auto j = nlohmann::json::parse(file_text(d + "/region.json"));
  EXPECT_EQ(j["format"], "airtwin-region 1");
  EXPECT_EQ(j["points"], 9);
  EXPECT_EQ(j["reachable"], 36);
  for (const auto& [name, tally] : {std::pair{"model", model}, std::pair{"twin", twin}}) {
    EXPECT_EQ(j[name]["moved"], tally.all_moved) << name;
    EXPECT_EQ(j[name]["of"], tally.all_of) << name;
    for (size_t c = 0; c < 3; ++c) {
      EXPECT_EQ(j[name]["by_class"][classes[c]]["moved"], tally.moved[c]) << name << classes[c];
      EXPECT_EQ(j[name]["by_class"][classes[c]]["of"], tally.of[c]) << name << classes[c];
    }
  }
  EXPECT_EQ(j["agreement"]["both"], both);
  EXPECT_EQ(j["agreement"]["model_only"], model_only);
  EXPECT_EQ(j["agreement"]["twin_only"], twin_only);
  EXPECT_EQ(j["agreement"]["neither"], neither);
  EXPECT_GT(both, 0);
  EXPECT_GT(neither, 0);
  EXPECT_EQ(cv::imread(d + "/region.png", cv::IMREAD_COLOR).cols, 1240);
  // The pushes' records: one trajectory per push, id its row, released at t = 0 where the row
  // says, ending where the row's twin end is, 1.5 s at 40 Hz.
  const CsvTable tr = CsvTable::read_file(d + "/trajectories.csv",
                                          {"traj", "object", "t", "x", "y", "pan_deg", "tilt_deg"});
  ASSERT_EQ(tr.rows(), 36u * 61u);
  for (size_t k = 0; k < 36; ++k) {
    const size_t first = 61 * k, last = first + 60;
    EXPECT_EQ(tr.text(first, "traj"), std::to_string(k));
    EXPECT_EQ(tr.number(first, "t"), 0.0);
    EXPECT_NEAR(tr.number(last, "t"), 1.5, 1e-9);
    EXPECT_NEAR(tr.number(first, "x"), csv.number(k, "x"), 2e-3);  // placed, then settled
    EXPECT_NEAR(tr.number(first, "y"), csv.number(k, "y"), 2e-3);
    EXPECT_NEAR(tr.number(last, "x"), csv.number(k, "twin_end_x"), 1e-6);
    EXPECT_NEAR(tr.number(last, "y"), csv.number(k, "twin_end_y"), 1e-6);
    EXPECT_NEAR(tr.number(first, "tilt_deg"), csv.number(k, "tilt_deg"), 1e-6);
  }
  // A rerun writes the same bytes.
  const std::string d2 = scratch_dir("region_twin_again");
  ASSERT_EQ(
      run_airtwin("region" + kSmall + "--twin --seed 4" + mirror_flags() + "--out " + d2).exit_code,
      0);
  EXPECT_EQ(file_text(d + "/region.csv"), file_text(d2 + "/region.csv"));
}

TEST(RegionCli, WithoutTheTwinOnlyTheModelJudges) {
  const std::string d = scratch_dir("region_model");
  const auto r = run_airtwin("region" + kSmall + "--out " + d);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(file_text(d + "/region.json"));
  EXPECT_TRUE(j["twin"].is_null());
  EXPECT_TRUE(j["agreement"].is_null());
  EXPECT_EQ(j["model"]["of"], 36);
  EXPECT_EQ(cv::imread(d + "/region.png", cv::IMREAD_COLOR).cols, 620);
  EXPECT_EQ(r.out.find("twin "), std::string::npos) << r.out;
}

// A scenario's controller gives D and Delta T and its first object the type, unless the flags
// say otherwise.
TEST(RegionCli, ScenarioSetsTheDistanceHorizonAndObject) {
  const std::string scenes = std::string(AIRTWIN_SOURCE_DIR) + "/scenes/";
  const std::string d = scratch_dir("region_scenario");
  ASSERT_EQ(run_airtwin("region" + kSmall + "--scenario " + scenes + "aggregation.yaml --out " + d)
                .exit_code,
            0);
  auto j = nlohmann::json::parse(file_text(d + "/region.json"));
  EXPECT_EQ(j["distance_m"], 0.30);  // the file's mean0_m
  EXPECT_EQ(j["horizon_s"], 1.5);
  EXPECT_EQ(j["object"], "tracer");
  ASSERT_EQ(run_airtwin("region" + kSmall + "--scenario " + scenes +
                        "aggregation.yaml --distance 0.2 --horizon 1 --out " + d)
                .exit_code,
            0);
  j = nlohmann::json::parse(file_text(d + "/region.json"));
  EXPECT_EQ(j["distance_m"], 0.2);
  EXPECT_EQ(j["horizon_s"], 1.0);
  // The sorting's plane search has no distance: D stays the default, the object its first.
  ASSERT_EQ(
      run_airtwin("region" + kSmall + "--scenario " + scenes + "sorting.yaml --out " + d).exit_code,
      0);
  j = nlohmann::json::parse(file_text(d + "/region.json"));
  EXPECT_EQ(j["distance_m"], 0.418);
  const auto bad = run_airtwin("region --scenario " + scenes + "nosuch.yaml --out " + d);
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_EQ(count_lines(bad.err), 1) << bad.err;
  EXPECT_NE(bad.err.find("nosuch.yaml"), std::string::npos) << bad.err;
}

TEST(RegionCli, BadInputIsOneClearLine) {
  const std::string d = scratch_dir("region_bad");
  for (const auto& [args, code, needle] : std::vector<std::tuple<std::string, int, std::string>>{
           {"--step 0", 2, "--step: expected a spacing"},
           {"--directions 0", 2, "--directions: expected a count in [1, 64]"},
           {"--object brick", 2, "--object: expected tracer or cotton, got 'brick'"},
           {"--distance -1", 2, "--distance: expected a distance in (0.1, 2] m"},
           {"--distance 0.05", 2, "delta_min forbids the push"},
           {"--extent 2", 2, "--extent: expected a half-width in (0, 1.9] m"},
           {"--model /nonexistent/model.json", 1, "/nonexistent/model.json"},
           {"--twin --effect nosuch", 2, "--effect: effect 'nosuch': unknown effect"},
           {"--effect stiction", 2, "--effect needs --twin"},
           {"--object-physics tracer:cd=0.4", 2, "--object-physics needs --twin"},
           {"--seed 3", 2, "--seed needs --twin"},
           {"--trajectories-out x.csv", 2, "--trajectories-out needs --twin"},
       }) {
    const auto r = run_airtwin("region " + args + " --out " + d);
    EXPECT_EQ(r.exit_code, code) << args << "\nstderr: " << r.err;
    EXPECT_EQ(count_lines(r.err), 1) << args << "\nstderr: " << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << args << "\nstderr: " << r.err;
  }
  EXPECT_EQ(run_airtwin("region").exit_code, 2);  // --out is required
}

}  // namespace
}  // namespace airtwin
