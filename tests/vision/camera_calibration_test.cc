// Camera calibration from rendered frames of the calibration target, scored against the
// renderer's ground-truth camera (which vision/ never sees): every pixel of the view maps to the
// floor where the true camera says, the focal length and principal point match, with clean and
// with noisy, blurred frames. Plus the refusals: no folder, no or bad target file, no board,
// a reference frame without a board.

#include "vision/camera_calibration.h"

#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <map>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/errors.h"
#include "renders/calibration_target.h"
#include "renders/camera_model.h"
#include "sim/mujoco_runtime.h"
#include "sim/scene_builder.h"
#include "tests/support/scratch_dir.h"

namespace airtwin {
namespace {

namespace fs = std::filesystem;

fs::path test_dir(const std::string& name) {
  return fs::path(testing::scratch_root()) / "camera_calibration" / name;
}

// A dataset rendered once per test program (rendering is the slow part).
const fs::path& dataset(const std::string& name, double noise_sigma_grey, double blur_sigma_px,
                        uint64_t seed) {
  static std::map<std::string, fs::path> made;
  auto it = made.find(name);
  if (it != made.end()) return it->second;
  const fs::path dir = test_dir(name);
  fs::remove_all(dir);
  CalibrationDatasetOptions options;
  options.seed = seed;
  options.noise_sigma_grey = noise_sigma_grey;
  options.blur_sigma_px = blur_sigma_px;
  write_calibration_dataset(dir.string(), SceneParameters{}, options);
  return made.emplace(name, dir).first->second;
}

GroundTruthCamera true_camera() {
  const ModelPtr m = load_model_from_xml(scene_xml(SceneSpec{}, SceneParameters{}, 0), "test");
  return GroundTruthCamera::from_model(m.get());
}

// Largest floor distance (m) between the calibrated and the true camera's floor points, over a
// 33 x 33 grid of pixels covering the whole image, corners included.
double worst_floor_error_m(const CalibratedCamera& camera, const GroundTruthCamera& truth) {
  double worst = 0.0;
  for (int a = 0; a <= 32; ++a) {
    for (int b = 0; b <= 32; ++b) {
      const Eigen::Vector2d uv((truth.width_px() - 1) * a / 32.0,
                               (truth.height_px() - 1) * b / 32.0);
      const std::optional<Eigen::Vector3d> mine = camera.point_at_height(uv, 0.0);
      const std::optional<Eigen::Vector3d> real = truth.floor_point(uv);
      if (!mine || !real) return 1e9;
      worst = std::max(worst, (*mine - *real).norm());
    }
  }
  return worst;
}

struct Score {
  double floor_worst_m, focal_error, principal_error_px, centre_error_m;
};

Score score(const CameraCalibrationResult& r, const GroundTruthCamera& truth) {
  const CalibratedCamera& c = r.camera;
  Score s;
  s.floor_worst_m = worst_floor_error_m(c, truth);
  s.focal_error = std::max(std::abs(c.K(0, 0) / truth.focal_px() - 1.0),
                           std::abs(c.K(1, 1) / truth.focal_px() - 1.0));
  s.principal_error_px =
      (Eigen::Vector2d(c.K(0, 2), c.K(1, 2)) - truth.intrinsics().col(2).head<2>()).norm();
  s.centre_error_m = (c.centre_W() - truth.p_WC()).norm();
  std::printf(
      "views %d, rms %.4f px, pose rms %.4f px, floor rms at the board %.3f mm | truth: worst "
      "floor %.3f mm, focal %.4f %%, principal point %.3f px, centre %.2f mm\n",
      c.n_views, c.rms_reprojection_px, c.pose_rms_px, 1e3 * r.floor_rms_m, 1e3 * s.floor_worst_m,
      100 * s.focal_error, s.principal_error_px, 1e3 * s.centre_error_m);
  return s;
}

TEST(CameraCalibration, CleanFramesMapEveryPixelToTheFloorWithinAMillimetre) {
  const fs::path& dir = dataset("clean", 0.0, 0.0, 1);
  const auto start = std::chrono::steady_clock::now();
  const CameraCalibrationResult r = calibrate_camera(dir.string());
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("calibration took %.2f s\n", seconds);
  ASSERT_EQ(r.views.size(), 8u);
  for (const CalibrationViewReport& v : r.views) EXPECT_TRUE(v.used) << v.frame << ": " << v.reason;
  const Score s = score(r, true_camera());
  EXPECT_LT(s.floor_worst_m, 1e-3);
  EXPECT_LT(s.focal_error, 0.005);
  EXPECT_LT(s.principal_error_px, 3.0);
  EXPECT_LT(r.camera.rms_reprojection_px, 0.2);
  EXPECT_LT(r.floor_rms_m, 1e-3);
  EXPECT_NEAR(r.floor_m_per_px, 2.7 / 1024, 2e-5);
  // The renderer is a perfect pinhole with square pixels: nothing more is supported.
  EXPECT_EQ(r.lens_model, LensModel::kPinhole);
  int on_floor = 0;
  for (const CalibrationViewReport& v : r.views) on_floor += v.on_floor;
  EXPECT_EQ(on_floor, 4);  // views 0, 2, 4 and 6 lie flat
  RecordProperty("floor_worst_mm", std::to_string(1e3 * s.floor_worst_m));
  RecordProperty("focal_error_percent", std::to_string(100 * s.focal_error));
  RecordProperty("calibration_s", std::to_string(seconds));
}

TEST(CameraCalibration, NoisyBlurredFramesStayWithinAFewMillimetres) {
  const fs::path& dir = dataset("noisy", 6.0, 1.0, 2);
  const CameraCalibrationResult r = calibrate_camera(dir.string());
  int used = 0;
  for (const CalibrationViewReport& v : r.views) used += v.used;
  EXPECT_GE(used, 7);
  const Score s = score(r, true_camera());
  EXPECT_LT(s.floor_worst_m, 2e-3);
  EXPECT_LT(s.focal_error, 0.005);
  RecordProperty("floor_worst_mm", std::to_string(1e3 * s.floor_worst_m));
  RecordProperty("focal_error_percent", std::to_string(100 * s.focal_error));
}

TEST(CameraCalibration, WrittenCameraReadsBackAndMapsTheSame) {
  const fs::path& dir = dataset("clean", 0.0, 0.0, 1);
  const CameraCalibrationResult r = calibrate_camera(dir.string());
  const std::string path = (test_dir("out") / "calib.yaml").string();
  fs::create_directories(test_dir("out"));
  r.camera.write(path);
  const CalibratedCamera back = CalibratedCamera::read(path);
  const Eigen::Vector2d uv(100.0, 900.0);
  EXPECT_LT((*back.point_at_height(uv, 0.0) - *r.camera.point_at_height(uv, 0.0)).norm(), 1e-9);
}

// A lens the renderer does not have: the clean frames resampled through OpenCV's barrel
// distortion (k1 = -0.08: ~18 px at the image's corners). The true camera
// is then the ground truth's pinhole with that lens in front: a pixel's floor point is that of
// its undistorted pixel (cv::undistortPoints, independent of the code under test).
TEST(CameraCalibration, RecoversALensTheRendererDoesNotHave) {
  const fs::path& clean = dataset("clean", 0.0, 0.0, 1);
  const GroundTruthCamera truth = true_camera();
  cv::Mat K(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) K.at<double>(r, c) = truth.intrinsics()(r, c);
  }
  const cv::Mat lens = (cv::Mat_<double>(1, 5) << -0.08, 0.0, 0.0, 0.0, 0.0);
  auto ideal_pixels = [&](const std::vector<cv::Point2f>& distorted) {
    std::vector<cv::Point2f> ideal;
    cv::undistortPoints(
        distorted, ideal, K, lens, cv::noArray(), K,
        cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 50, 1e-9));
    return ideal;
  };

  // Each output pixel samples the clean frame at its undistorted position.
  const int w = truth.width_px(), h = truth.height_px();
  std::vector<cv::Point2f> grid;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) grid.emplace_back(static_cast<float>(u), static_cast<float>(v));
  }
  const cv::Mat map = cv::Mat(ideal_pixels(grid), true).reshape(2, h);
  const fs::path dir = test_dir("lens");
  fs::remove_all(dir);
  fs::create_directories(dir);
  fs::copy_file(clean / "target.yaml", dir / "target.yaml");
  for (const fs::directory_entry& e : fs::directory_iterator(clean)) {
    if (e.path().extension() != ".png") continue;
    cv::Mat distorted;
    cv::remap(cv::imread(e.path().string()), distorted, map, cv::noArray(), cv::INTER_LINEAR,
              cv::BORDER_REPLICATE);
    cv::imwrite((dir / e.path().filename()).string(), distorted);
  }

  const CameraCalibrationResult r = calibrate_camera(dir.string());
  EXPECT_GE(r.lens_model, LensModel::kRadial1);
  double worst = 0.0;
  std::vector<cv::Point2f> probes;
  for (int a = 0; a <= 32; ++a) {
    for (int b = 0; b <= 32; ++b) {
      probes.emplace_back(static_cast<float>((w - 1) * a / 32.0),
                          static_cast<float>((h - 1) * b / 32.0));
    }
  }
  const std::vector<cv::Point2f> ideal = ideal_pixels(probes);
  for (size_t k = 0; k < probes.size(); ++k) {
    const Eigen::Vector3d mine = *r.camera.point_at_height({probes[k].x, probes[k].y}, 0.0);
    const Eigen::Vector3d real = *truth.floor_point({ideal[k].x, ideal[k].y});
    worst = std::max(worst, (mine - real).norm());
  }
  std::printf("lens %s: k %.4f %.4f %.5f %.5f %.4f, worst floor %.3f mm, rms %.4f px\n",
              lens_model_name(r.lens_model), r.camera.distortion[0], r.camera.distortion[1],
              r.camera.distortion[2], r.camera.distortion[3], r.camera.distortion[4], 1e3 * worst,
              r.camera.rms_reprojection_px);
  EXPECT_LT(worst, 1e-3);
  RecordProperty("floor_worst_mm", std::to_string(1e3 * worst));
}

// A copy of the clean dataset in `name`, to be spoiled by a test.
fs::path copy_of_clean(const std::string& name) {
  const fs::path& clean = dataset("clean", 0.0, 0.0, 1);
  const fs::path dir = test_dir(name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const fs::directory_entry& e : fs::directory_iterator(clean)) {
    fs::copy_file(e.path(), dir / e.path().filename());
  }
  return dir;
}

std::string error_of(const fs::path& dir) {
  try {
    calibrate_camera(dir.string());
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

TEST(CameraCalibration, SkipsAndReportsFramesWithoutABoard) {
  // An unreadable file and a blank frame among the views: reported, the rest calibrates.
  const fs::path dir = copy_of_clean("spoiled_views");
  write_text(dir / "view_03.png", "not a png");
  cv::imwrite((dir / "view_05.png").string(), cv::Mat(1024, 1024, CV_8UC3, cv::Scalar(90, 90, 90)));
  write_text(dir / "notes.txt", "ignored");
  const CameraCalibrationResult r = calibrate_camera(dir.string());
  ASSERT_EQ(r.views.size(), 8u);
  EXPECT_FALSE(r.views[3].used);
  EXPECT_EQ(r.views[3].reason, "cannot read the image");
  EXPECT_FALSE(r.views[5].used);
  EXPECT_NE(r.views[5].reason.find("no board of 10 x 7 inner corners"), std::string::npos);
  EXPECT_EQ(r.camera.n_views, 6);
}

// A target file that OpenCV's YAML parser chokes on is one InputError naming the file
// (fuzz/calibration_target_fuzz.cc): a key starting with ':' (std::length_error inside OpenCV),
// an indented top level followed by more text (the parser then loops forever).
TEST(CameraCalibration, TargetFilesOpenCvCannotParseAreOneError) {
  fs::create_directories(test_dir("unparsable_target"));
  const fs::path path = test_dir("unparsable_target") / "target.yaml";
  for (const std::string text : {"board:\n   b: 3\n   :c 1\n", " board: 3\n!x\n-"}) {
    std::ofstream(path) << text;
    try {
      CalibrationTarget::read(path.string());
      ADD_FAILURE() << "accepted " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
    }
  }
}

TEST(CameraCalibration, RefusesUnusableFolders) {
  // No folder.
  const fs::path missing = test_dir("does_not_exist");
  EXPECT_NE(error_of(missing).find("no such calibration folder"), std::string::npos);

  // No target file.
  fs::path dir = copy_of_clean("no_target");
  fs::remove(dir / "target.yaml");
  std::string message = error_of(dir);
  EXPECT_NE(message.find((dir / "target.yaml").string()), std::string::npos) << message;

  // A target file with a key missing, a symmetric board, a reference that is no frame.
  struct Case {
    std::string from, to, expected;
  };
  const std::vector<Case> cases = {
      {"   square_size_m:", "   square_size:", "board.square_size_m is missing"},
      {"inner_corners_rows: 7", "inner_corners_rows: 8", "must differ from inner_corners_cols"},
      {"frame: \"view_00.png\"", "frame: \"view_99.png\"", "'view_99.png' is not an image file"},
      {"frame: \"view_00.png\"", "frame: \"../view_00.png\"", "reference.frame must be the file"},
      {"yaw_deg:", "yaw_deg: .nan\n   old_yaw:", "reference.yaw_deg must be finite"},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    dir = copy_of_clean("bad_target");
    std::ifstream in(dir / "target.yaml");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const size_t at = text.find(cases[i].from);
    ASSERT_NE(at, std::string::npos) << cases[i].from;
    text.replace(at, cases[i].from.size(), cases[i].to);
    write_text(dir / "target.yaml", text);
    message = error_of(dir);
    EXPECT_NE(message.find(cases[i].expected), std::string::npos) << i << ": " << message;
    EXPECT_NE(message.find("target.yaml"), std::string::npos) << i << ": " << message;
  }

  // No image with a board at all; then only the reference without one.
  dir = copy_of_clean("no_board");
  const cv::Mat blank(1024, 1024, CV_8UC3, cv::Scalar(90, 90, 90));
  for (int k = 0; k < 8; ++k) {
    char name[32];
    std::snprintf(name, sizeof(name), "view_%02d.png", k);
    cv::imwrite((dir / name).string(), blank);
  }
  message = error_of(dir);
  EXPECT_NE(message.find("no view has a detectable board"), std::string::npos) << message;
  dir = copy_of_clean("no_reference_board");
  cv::imwrite((dir / "view_00.png").string(), blank);
  message = error_of(dir);
  EXPECT_NE(message.find("view_00.png: the reference frame has no detectable board"),
            std::string::npos)
      << message;
}

}  // namespace
}  // namespace airtwin
