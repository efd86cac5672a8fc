// The calibration dataset against independent truths: the frames show a checkerboard whose
// corners OpenCV finds where the ground-truth camera projects the board of target.yaml (reference
// view), every view has a findable board, the same seed gives the same bytes, another seed other
// poses, and bad options are refused before anything is written.

#include "renders/calibration_target.h"

#include <unistd.h>

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "common/errors.h"
#include "common/units.h"
#include "renders/camera_model.h"
#include "renders/png.h"
#include "sim/mujoco_runtime.h"
#include "sim/scene_builder.h"
#include "tests/support/scratch_dir.h"

namespace airtwin {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::path(testing::scratch_root()) / "calibration_target" / name;
  fs::remove_all(dir);
  return dir;
}

std::string file_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The twin's own top camera (the same scene parameters the dataset was rendered with).
GroundTruthCamera twin_camera() {
  const ModelPtr m = load_model_from_xml(scene_xml(SceneSpec{}, SceneParameters{}, 0), "test");
  return GroundTruthCamera::from_model(m.get());
}

// The target file as a test reads it (independently of vision/'s reader).
struct TargetFile {
  int cols = 0, rows = 0;
  double square_m = 0, thickness_m = 0, x_m = 0, y_m = 0, yaw_deg = 0;
  std::string frame;
};
TargetFile read_target(const fs::path& path) {
  cv::FileStorage in(path.string(), cv::FileStorage::READ);
  TargetFile t;
  t.cols = static_cast<int>(in["board"]["inner_corners_cols"]);
  t.rows = static_cast<int>(in["board"]["inner_corners_rows"]);
  t.square_m = static_cast<double>(in["board"]["square_size_m"]);
  t.thickness_m = static_cast<double>(in["board"]["thickness_m"]);
  t.frame = static_cast<std::string>(in["reference"]["frame"]);
  t.x_m = static_cast<double>(in["reference"]["origin_x_m"]);
  t.y_m = static_cast<double>(in["reference"]["origin_y_m"]);
  t.yaw_deg = static_cast<double>(in["reference"]["yaw_deg"]);
  return t;
}

TEST(CalibrationTarget, ReferenceCornersAreWhereTheTrueCameraProjectsTheBoard) {
  const fs::path dir = fresh_dir("reference");
  CalibrationDatasetOptions options;
  options.views = 3;
  options.seed = 5;
  EXPECT_EQ(write_calibration_dataset(dir.string(), SceneParameters{}, options), 3);
  const TargetFile t = read_target(dir / "target.yaml");
  ASSERT_EQ(t.cols, 10);
  ASSERT_EQ(t.rows, 7);
  EXPECT_EQ(t.frame, "view_00.png");

  // OpenCV's corners of the reference frame.
  cv::Mat grey;
  cv::cvtColor(read_png((dir / t.frame).string()), grey, cv::COLOR_BGR2GRAY);
  std::vector<cv::Point2f> found;
  ASSERT_TRUE(
      cv::findChessboardCorners(grey, cv::Size(t.cols, t.rows), found,
                                cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE));
  cv::cornerSubPix(grey, found, cv::Size(7, 7), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-4));

  // The board's corners from target.yaml through the true camera: each detection near one.
  const GroundTruthCamera camera = twin_camera();
  const double yaw = deg_to_rad(t.yaw_deg);
  const Eigen::Vector3d x_W(std::cos(yaw), std::sin(yaw), 0), y_W(-std::sin(yaw), std::cos(yaw), 0);
  double worst = 0, sum2 = 0;
  for (int j = 0; j < t.rows; ++j) {
    for (int i = 0; i < t.cols; ++i) {
      const Eigen::Vector3d p_W =
          Eigen::Vector3d(t.x_m, t.y_m, t.thickness_m) + t.square_m * (i * x_W + j * y_W);
      const Eigen::Vector2d truth = *camera.project(p_W);
      double best = 1e9;
      for (const cv::Point2f& f : found) {
        best = std::min(best, (Eigen::Vector2d(f.x, f.y) - truth).norm());
      }
      worst = std::max(worst, best);
      sum2 += best * best;
    }
  }
  const double rms = std::sqrt(sum2 / (t.cols * t.rows));
  RecordProperty("worst_px", std::to_string(worst));
  RecordProperty("rms_px", std::to_string(rms));
  std::printf("reference corners vs truth: rms %.4f px, worst %.4f px\n", rms, worst);
  EXPECT_LT(worst, 0.25);
}

TEST(CalibrationTarget, EveryViewShowsAWholeBoardAndHalfOfThemLieFlat) {
  const fs::path dir = fresh_dir("views");
  CalibrationDatasetOptions options;
  options.seed = 11;
  ASSERT_EQ(write_calibration_dataset(dir.string(), SceneParameters{}, options), 8);
  int flat = 0;
  for (int k = 0; k < 8; ++k) {
    char name[32];
    std::snprintf(name, sizeof(name), "view_%02d.png", k);
    cv::Mat grey;
    cv::cvtColor(read_png((dir / name).string()), grey, cv::COLOR_BGR2GRAY);
    std::vector<cv::Point2f> found;
    ASSERT_TRUE(cv::findChessboardCorners(
        grey, cv::Size(10, 7), found, cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE))
        << name;
    // A flat board's squares all look alike (a camera straight above); a propped one's shrink
    // across the board. Compare the corner spacing along the first and last rows and columns.
    auto spacing = [&](int a, int b) { return cv::norm(found[a] - found[b]); };
    const double rows = spacing(0, 9) / spacing(60, 69);
    const double cols = spacing(0, 60) / spacing(9, 69);
    if (std::abs(rows - 1.0) < 0.01 && std::abs(cols - 1.0) < 0.01) ++flat;
  }
  EXPECT_EQ(flat, 4);
}

TEST(CalibrationTarget, SameSeedSameBytesOtherSeedOtherPoses) {
  CalibrationDatasetOptions options;
  options.views = 3;
  options.seed = 21;
  options.noise_sigma_grey = 3.0;
  options.blur_sigma_px = 0.7;
  const fs::path a = fresh_dir("a"), b = fresh_dir("b"), c = fresh_dir("c");
  write_calibration_dataset(a.string(), SceneParameters{}, options);
  write_calibration_dataset(b.string(), SceneParameters{}, options);
  options.seed = 22;
  write_calibration_dataset(c.string(), SceneParameters{}, options);
  for (const std::string name : {"target.yaml", "view_00.png", "view_01.png", "view_02.png"}) {
    const std::string bytes = file_bytes(a / name);
    EXPECT_FALSE(bytes.empty()) << name;
    EXPECT_EQ(bytes, file_bytes(b / name)) << name;
    EXPECT_NE(bytes, file_bytes(c / name)) << name;
  }
}

TEST(CalibrationTarget, RefusesBadOptionsBeforeWritingAnything) {
  const fs::path dir = fresh_dir("refused");
  auto message = [&](const CalibrationDatasetOptions& o) -> std::string {
    try {
      write_calibration_dataset(dir.string(), SceneParameters{}, o);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  CalibrationDatasetOptions o;
  o.views = 2;
  EXPECT_NE(message(o).find("views must be in [3, 100], got 2"), std::string::npos);
  o = {};
  o.noise_sigma_grey = -1;
  EXPECT_NE(message(o).find("noise_sigma_grey must be finite and >= 0"), std::string::npos);
  o = {};
  o.blur_sigma_px = std::nan("");
  EXPECT_NE(message(o).find("blur_sigma_px must be finite and >= 0"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir));
  // A camera that sees too little floor for the board.
  SceneParameters narrow;
  narrow.camera_half_view_m = 0.4;
  o = {};
  try {
    write_calibration_dataset(dir.string(), narrow, o);
    ADD_FAILURE() << "a 0.8 m view cannot hold the board";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot place the board"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir));
}

}  // namespace
}  // namespace airtwin
