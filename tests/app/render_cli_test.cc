// `airtwin render` end to end: the dataset it writes (frames, truth.csv, nozzle.csv, calibration
// views, video and its sidecar), the same seed giving the same bytes, overlays kept off the frames
// vision reads, and one clear line for a bad scenario or bad flags. (The renderer, overlay and
// video writer themselves are tested in tests/renders.)

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/csv.h"
#include "tests/app/cli_runner.h"

namespace airtwin {
namespace {

using testing::count_lines;
using testing::run_airtwin;
using testing::scratch_dir;

const std::string kScenes = std::string(AIRTWIN_SOURCE_DIR) + "/scenes/";

std::vector<std::string> split(const std::string& line, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string item;
  while (std::getline(ss, item, sep)) out.push_back(item);
  return out;
}

TEST(RenderCli, WritesFramesTruthAndCalibrationSameSeedSameBytes) {
  const std::string d = scratch_dir("render");
  const std::string quick =
      "render " + kScenes + "sorting.yaml --frames 3 --seed 5 --calibration-views 3 --quiet ";
  const auto r = run_airtwin(quick + "--out " + d + "/a");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("rendered 3 frames"), std::string::npos) << r.out;
  EXPECT_EQ(r.err, "");  // --quiet
  for (int k = 0; k < 3; ++k) {
    EXPECT_TRUE(std::filesystem::exists(d + "/a/frames/frame_00000" + std::to_string(k) + ".png"));
  }
  EXPECT_FALSE(std::filesystem::exists(d + "/a/frames/frame_000003.png"));
  EXPECT_TRUE(std::filesystem::exists(d + "/a/calibration/target.yaml"));
  EXPECT_TRUE(std::filesystem::exists(d + "/a/calibration/view_02.png"));
  EXPECT_FALSE(std::filesystem::exists(d + "/a/overlay"));

  // truth.csv: one row per frame and object, at 40 Hz, pixels where the floor geometry puts them
  // (1024 px across 2.7 m, origin at the centre, +y up) within the small parallax of the bodies'
  // height.
  const std::string truth = read_text_file(d + "/a/truth.csv");
  EXPECT_EQ(count_lines(truth), 1 + 3 * 6);
  std::stringstream lines(truth);
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(line, "frame,t,id,object,x,y,x_px,y_px");
  int rows = 0;
  while (std::getline(lines, line)) {
    const auto f = split(line, ',');
    ASSERT_EQ(f.size(), 8u) << line;
    const int frame = std::stoi(f[0]);
    EXPECT_NEAR(std::stod(f[1]), frame / 40.0, 1e-9) << line;
    EXPECT_TRUE(f[3] == "tracer" || f[3] == "cotton") << line;
    const double x = std::stod(f[4]), y = std::stod(f[5]);
    EXPECT_NEAR(std::stod(f[6]), 511.5 + x * 1024 / 2.7, 1.5) << line;
    EXPECT_NEAR(std::stod(f[7]), 511.5 - y * 1024 / 2.7, 1.5) << line;
    // Six decimals everywhere.
    EXPECT_EQ(f[4].size() - f[4].find('.'), 7u) << line;
    // At t = 0 the scenario's first object is where the file puts it (t1 at (-0.07, 0.12)),
    // within the ~1 mm its drop onto the floor may move it.
    if (rows == 0) {
      EXPECT_EQ(f[0] + "," + f[1] + "," + f[2] + "," + f[3], "0,0.000000,t1,tracer");
      EXPECT_NEAR(x, -0.07, 2e-3);
      EXPECT_NEAR(y, 0.12, 2e-3);
    }
    ++rows;
  }
  EXPECT_EQ(rows, 18);
  // nozzle.csv: the one command (the default pan 0, tilt 20 deg), from the first frame on.
  EXPECT_EQ(read_text_file(d + "/a/nozzle.csv"),
            "t,pan_deg,tilt_deg\n0.000000,0.000000,20.000000\n");

  // Again with the same seed: the same bytes, file by file.
  ASSERT_EQ(run_airtwin(quick + "--out " + d + "/b").exit_code, 0);
  for (const auto& entry : std::filesystem::recursive_directory_iterator(d + "/a")) {
    if (!entry.is_regular_file()) continue;
    const std::string rel = std::filesystem::relative(entry.path(), d + "/a").string();
    EXPECT_EQ(read_text_file(entry.path().string()), read_text_file(d + "/b/" + rel)) << rel;
  }
}

TEST(RenderCli, VideoAndOverlayLeaveTheFramesClean) {
  const std::string d = scratch_dir("render_video");
  const std::string common =
      "render " + kScenes + "line.yaml --seed 2 --noise low " + "--calibration-views 0 --quiet ";
  const std::string base = common + "--frames 3 ";
  ASSERT_EQ(run_airtwin(base + "--out " + d + "/plain").exit_code, 0);
  const auto r = run_airtwin(base + "--overlay --video " + d + "/v/run.mp4 --out " + d + "/ov");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("video " + d + "/v/run.mp4: 3 frames"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(d + "/ov/calibration"));
  // The frames vision reads are the same bytes with or without overlays and video.
  for (int k = 0; k < 3; ++k) {
    const std::string name = "/frames/frame_00000" + std::to_string(k) + ".png";
    EXPECT_EQ(read_text_file(d + "/plain" + name), read_text_file(d + "/ov" + name)) << name;
  }
  std::ifstream sidecar(d + "/v/run.mp4.json");
  ASSERT_TRUE(sidecar.good());
  const nlohmann::json j = nlohmann::json::parse(sidecar);
  EXPECT_EQ(j.at("frames").get<int>(), 3);
  EXPECT_EQ(j.at("fps").get<double>(), 40.0);
  EXPECT_DOUBLE_EQ(j.at("sim_seconds").get<double>(), 0.075);
  // The video too is the same bytes for the same run.
  ASSERT_EQ(
      run_airtwin(base + "--overlay --video " + d + "/v/again.mp4 --out " + d + "/ov3").exit_code,
      0);
  EXPECT_EQ(read_text_file(d + "/v/run.mp4"), read_text_file(d + "/v/again.mp4"));
  // Overlays without a video go to their own folder.
  ASSERT_EQ(run_airtwin(common + "--frames 1 --overlay --out " + d + "/ov2").exit_code, 0);
  EXPECT_TRUE(std::filesystem::exists(d + "/ov2/overlay/frame_000000.png"));
  EXPECT_NE(read_text_file(d + "/ov2/overlay/frame_000000.png"),
            read_text_file(d + "/ov2/frames/frame_000000.png"));
  // Another seed, other sensor noise.
  ASSERT_EQ(run_airtwin("render " + kScenes +
                        "line.yaml --frames 1 --seed 3 --noise low --calibration-views 0 --quiet "
                        "--out " +
                        d + "/seed3")
                .exit_code,
            0);
  EXPECT_NE(read_text_file(d + "/plain/frames/frame_000000.png"),
            read_text_file(d + "/seed3/frames/frame_000000.png"));
}

TEST(RenderCli, BadScenarioIsOneLineNamingTheKey) {
  const std::string d = scratch_dir("render_bad");
  {
    std::ofstream out(d + "/bad.yaml");
    out << "objects: [{id: a, type: tracer, x: 0.3, y: 0.3}]\n"
           "task:\n"
           "  kind: aggregation\n"
           "  time_limit_s: 10\n"
           "  zone: {centre: [0, 0], diameter_m: abc}\n";
  }
  const auto r = run_airtwin("render " + d + "/bad.yaml --frames 3 --out " + d + "/o");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(d + "/bad.yaml:5: task.zone.diameter_m: expected a positive number"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(std::filesystem::exists(d + "/o"));

  const auto missing = run_airtwin("render " + d + "/none.yaml --frames 3 --out " + d + "/o");
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_EQ(count_lines(missing.err), 1) << missing.err;
  EXPECT_NE(missing.err.find("none.yaml"), std::string::npos) << missing.err;
}

TEST(RenderCli, TheModelAirIsTheTablesWhenOneIsNamed) {
  // In the model's air the objects follow eqs. (1)-(3) with --table's model: the constructed
  // table's air moves them otherwise than the default model's, and the same table twice gives
  // the same truth.
  const std::string d = scratch_dir("render_table");
  const std::string quick = "render " + kScenes +
                            "octagon.yaml --frames 40 --pan 0 --tilt 8 --seed 2 "
                            "--calibration-views 0 --air model --drag eq8 --quiet ";
  const std::string table = " --table " + testing::constructed_table();
  ASSERT_EQ(run_airtwin(quick + "--out " + d + "/default").exit_code, 0);
  ASSERT_EQ(run_airtwin(quick + table + " --out " + d + "/a").exit_code, 0);
  ASSERT_EQ(run_airtwin(quick + table + " --out " + d + "/b").exit_code, 0);
  EXPECT_EQ(read_text_file(d + "/a/truth.csv"), read_text_file(d + "/b/truth.csv"));
  EXPECT_NE(read_text_file(d + "/a/truth.csv"), read_text_file(d + "/default/truth.csv"));
  // A missing table: one line naming it.
  const auto r = run_airtwin(quick + "--table " + d + "/none.csv --out " + d + "/c");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("none.csv"), std::string::npos) << r.err;
}

TEST(RenderCli, BadFlagsAreUsageErrors) {
  const std::string scenario = kScenes + "line.yaml";
  for (const auto& [flags, fragment] :
       std::vector<std::pair<std::string, std::string>>{{"--frames 0", "--frames"},
                                                        {"--frames 3 --noise medium", "--noise"},
                                                        {"--frames 3 --tilt 75", "--tilt"},
                                                        {"--frames 3 --pan 200", "--pan"},
                                                        {"--frames 3 --stride 0", "--stride"},
                                                        {"--frames 3 --table t.csv", "--table"},
                                                        {"", "--frames"}}) {
    const auto r = run_airtwin("render " + scenario + " " + flags + " --out /tmp/x");
    EXPECT_EQ(r.exit_code, 2) << flags << "\n" << r.err;
    EXPECT_EQ(count_lines(r.err), 1) << flags << "\n" << r.err;
    EXPECT_NE(r.err.find(fragment), std::string::npos) << flags << "\n" << r.err;
  }
}

}  // namespace
}  // namespace airtwin
