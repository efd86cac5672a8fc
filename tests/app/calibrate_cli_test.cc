// `airtwin calibrate` end to end: a rendered calibration folder gives a camera file that reads
// back and a JSON summary; an unusable folder or flag is one clear line and the right exit status.
// (The calibration itself is tested in tests/vision/camera_calibration_test.cc.)

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "renders/calibration_target.h"
#include "tests/app/cli_runner.h"
#include "vision/calibrated_camera.h"

namespace airtwin {
namespace {

namespace fs = std::filesystem;
using testing::count_lines;
using testing::run_airtwin;
using testing::scratch_dir;

void expect_one_line_error(const std::string& args, int status, const std::string& fragment) {
  const auto r = run_airtwin(args);
  EXPECT_EQ(r.exit_code, status) << args << "\nstderr: " << r.err;
  EXPECT_EQ(count_lines(r.err), 1) << args << "\nstderr: " << r.err;
  EXPECT_NE(r.err.find(fragment), std::string::npos) << args << "\nstderr: " << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

TEST(CalibrateCli, WritesTheCameraAndSummarises) {
  const std::string d = scratch_dir("calibrate");
  CalibrationDatasetOptions options;
  options.seed = 3;
  write_calibration_dataset(d + "/calibration", SceneParameters{}, options);
  const auto r = run_airtwin("calibrate " + d + "/calibration --out " + d + "/out/calib.yaml");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["views"], 8);
  EXPECT_EQ(j["views_used"], 8);
  EXPECT_EQ(j["views_on_floor"], 4);
  EXPECT_TRUE(j["rejected"].empty());
  EXPECT_LT(j["rms_px"].get<double>(), 0.2);
  EXPECT_LT(j["floor_rms_mm"].get<double>(), 1.0);
  EXPECT_NEAR(j["camera_centre_m"][2].get<double>(), 3.2, 0.03);
  const CalibratedCamera c = CalibratedCamera::read(d + "/out/calib.yaml");
  EXPECT_EQ(c.n_views, 8);
  EXPECT_DOUBLE_EQ(c.K(0, 0), j["focal_px"][0].get<double>());

  // A frame without a board is named in the summary, the rest still calibrates.
  std::ofstream(d + "/calibration/view_07.png") << "not an image";
  const auto spoiled = run_airtwin("calibrate " + d + "/calibration --out " + d + "/c2.yaml");
  ASSERT_EQ(spoiled.exit_code, 0) << spoiled.err;
  const nlohmann::json k = nlohmann::json::parse(spoiled.out);
  EXPECT_EQ(k["views_used"], 7);
  ASSERT_EQ(k["rejected"].size(), 1u);
  EXPECT_EQ(k["rejected"][0]["frame"], "view_07.png");
}

TEST(CalibrateCli, UnusableFoldersAndFlagsAreOneClearLine) {
  const std::string d = scratch_dir("calibrate_errors");
  expect_one_line_error("calibrate " + d + "/missing --out " + d + "/c.yaml", 1,
                        d + "/missing: no such calibration folder");
  expect_one_line_error("calibrate " + d + " --out " + d + "/c.yaml", 1,
                        d + "/target.yaml: no calibration target file");
  std::ofstream(d + "/target.yaml") << "board: {inner_corners_cols: 10}\n";
  expect_one_line_error("calibrate " + d + " --out " + d + "/c.yaml", 1,
                        "target.yaml: board.inner_corners_rows is missing");
  expect_one_line_error("calibrate " + d, 2, "--out");
  expect_one_line_error("calibrate --out " + d + "/c.yaml", 2, "DIR");
  expect_one_line_error("calibrate " + d + " --lens fisheye --out c.yaml", 2, "--lens");
  expect_one_line_error("calibrate " + d + " --max-view-rms 0 --out c.yaml", 2, "--max-view-rms");
  EXPECT_FALSE(fs::exists(d + "/c.yaml"));
}

}  // namespace
}  // namespace airtwin
