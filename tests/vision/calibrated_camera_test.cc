// The calibrated camera model on its own: pixel <-> world maps inverse to each other (with and
// without lens distortion), the camera centre against the pose, the YAML file round trip and the
// reader's errors (each names the file and the key).

#include "vision/calibrated_camera.h"

#include <unistd.h>

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <string>

#include "common/errors.h"
#include "tests/support/scratch_dir.h"

namespace airtwin {
namespace {

namespace fs = std::filesystem;

// A camera like the rig's: 3.2 m above the floor, looking down, slightly tilted and rotated,
// with a mild barrel lens.
CalibratedCamera rig_like_camera() {
  CalibratedCamera c;
  c.width_px = 1024;
  c.height_px = 1024;
  c.K << 1210.0, 0.0, 515.0, 0.0, 1214.0, 508.0, 0.0, 0.0, 1.0;
  c.distortion << -0.08, 0.02, 0.0004, -0.0003, 0.001;
  // Looking down: camera z = -world z, camera x = world x, camera y = -world y; then a small tilt.
  Eigen::Matrix3d down;
  down << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  const Eigen::Matrix3d tilt = (Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitX()) *
                                Eigen::AngleAxisd(-0.015, Eigen::Vector3d::UnitY()) *
                                Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ()))
                                   .toRotationMatrix();
  c.R_CW = tilt * down;
  const Eigen::Vector3d centre_W(0.01, -0.02, 3.2);
  c.t_C = -c.R_CW * centre_W;
  c.rms_reprojection_px = 0.05;
  c.pose_rms_px = 0.07;
  c.n_views = 8;
  return c;
}

std::string temp_path(const std::string& name) {
  const fs::path dir = fs::path(testing::scratch_root()) / "calibrated_camera";
  fs::create_directories(dir);
  return (dir / name).string();
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

TEST(CalibratedCamera, CentreIsWherePoseSaysAndProjectsNothingBehind) {
  const CalibratedCamera c = rig_like_camera();
  EXPECT_LT((c.centre_W() - Eigen::Vector3d(0.01, -0.02, 3.2)).norm(), 1e-12);
  EXPECT_FALSE(c.project({0.0, 0.0, 4.0}).has_value());  // above the camera
  // A ray that never comes down to a plane above the camera.
  EXPECT_FALSE(c.point_at_height({512.0, 512.0}, 5.0).has_value());
}

TEST(CalibratedCamera, PointAtHeightInvertsProjectOverTheWholeImage) {
  for (const bool with_lens : {false, true}) {
    CalibratedCamera c = rig_like_camera();
    if (!with_lens) c.distortion.setZero();
    double worst_px = 0.0, worst_m = 0.0;
    for (double z : {0.0, 0.015, 0.3}) {
      for (double u = 0.0; u <= 1023.0; u += 63.9375) {
        for (double v = 0.0; v <= 1023.0; v += 63.9375) {
          // Pixel -> world point at height z -> back to the same pixel.
          const std::optional<Eigen::Vector3d> p = c.point_at_height({u, v}, z);
          ASSERT_TRUE(p.has_value()) << u << "," << v;
          EXPECT_NEAR(p->z(), z, 1e-12);
          const std::optional<Eigen::Vector2d> uv = c.project(*p);
          ASSERT_TRUE(uv.has_value());
          worst_px = std::max(worst_px, (*uv - Eigen::Vector2d(u, v)).norm());
          // World -> pixel -> world.
          const Eigen::Vector3d q(p->x() * 0.9 + 0.05, p->y() * 0.9 - 0.03, z);
          const std::optional<Eigen::Vector3d> back = c.point_at_height(*c.project(q), z);
          ASSERT_TRUE(back.has_value());
          worst_m = std::max(worst_m, (*back - q).norm());
        }
      }
    }
    EXPECT_LT(worst_px, 1e-8) << "lens " << with_lens;
    EXPECT_LT(worst_m, 1e-10) << "lens " << with_lens;
  }
}

TEST(CalibratedCamera, ProjectMatchesAPlainPinholeWithoutLens) {
  CalibratedCamera c = rig_like_camera();
  c.distortion.setZero();
  const Eigen::Vector3d p_W(0.7, -0.4, 0.02);
  const Eigen::Vector3d h = c.K * (c.R_CW * p_W + c.t_C);
  EXPECT_LT((*c.project(p_W) - h.head<2>() / h.z()).norm(), 1e-10);
}

TEST(CalibratedCamera, WriteThenReadGivesTheSameCamera) {
  const CalibratedCamera c = rig_like_camera();
  const std::string path = temp_path("round_trip.yaml");
  c.write(path);
  const CalibratedCamera r = CalibratedCamera::read(path);
  EXPECT_EQ(r.width_px, c.width_px);
  EXPECT_EQ(r.height_px, c.height_px);
  EXPECT_EQ(r.n_views, c.n_views);
  // cv::FileStorage writes doubles with 16 significant digits.
  EXPECT_LT((r.K - c.K).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((r.distortion - c.distortion).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LT((r.R_CW - c.R_CW).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LT((r.t_C - c.t_C).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_DOUBLE_EQ(r.rms_reprojection_px, c.rms_reprojection_px);
  EXPECT_DOUBLE_EQ(r.pose_rms_px, c.pose_rms_px);
}

// The message of the InputError read() throws, or "" when it does not throw.
std::string read_error(const std::string& path) {
  try {
    CalibratedCamera::read(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// The round-trip file with the line of `key` replaced by `replacement` (may be empty).
std::string edited_file(const std::string& name, const std::string& key,
                        const std::string& replacement) {
  const std::string good = temp_path("good.yaml");
  rig_like_camera().write(good);
  std::ifstream in(good);
  std::string text, line;
  bool skipping = false;
  while (std::getline(in, line)) {
    // A matrix node spans several indented lines after its key.
    if (line.rfind(key + ":", 0) == 0) {
      text += replacement;
      skipping = true;
      continue;
    }
    if (skipping && !line.empty() && line[0] == ' ') continue;
    skipping = false;
    text += line;
    text += "\n";
  }
  const std::string path = temp_path(name);
  write_text(path, text);
  return path;
}

TEST(CalibratedCamera, ReadNamesTheFileAndTheMissingKey) {
  for (const std::string key :
       {"width_px", "K", "distortion", "R_CW", "t_C", "rms_reprojection_px", "n_views"}) {
    std::string name = "missing_";
    name += key;
    name += ".yaml";
    const std::string path = edited_file(name, key, "");
    const std::string message = read_error(path);
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find(key + " is missing"), std::string::npos) << message;
  }
}

TEST(CalibratedCamera, ReadRejectsMalformedValues) {
  struct Case {
    std::string key, replacement, expected;
  };
  const std::vector<Case> cases = {
      {"width_px", "width_px: -4\n", "width_px must be > 0"},
      {"width_px", "width_px: wide\n", "width_px must be an integer"},
      {"rms_reprojection_px", "rms_reprojection_px: .nan\n", "rms_reprojection_px must be finite"},
      {"K", "K: !!opencv-matrix\n   rows: 2\n   cols: 2\n   dt: d\n   data: [ 1., 0., 0., 1. ]\n",
       "K must be a 3 x 3 matrix"},
      {"R_CW",
       "R_CW: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ 1., 0., 0., 0., 2., "
       "0., 0., 0., 1. ]\n",
       "R_CW must be a rotation"},
      {"t_C", "t_C: !!opencv-matrix\n   rows: 3\n   cols: 1\n   dt: d\n   data: [ 1., .inf, 0. ]\n",
       "t_C must hold finite numbers"},
      {"K", "K: 3\n", "K must be"},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    std::string name = "bad_";
    name += std::to_string(i);
    name += ".yaml";
    const std::string path = edited_file(name, cases[i].key, cases[i].replacement);
    const std::string message = read_error(path);
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find(cases[i].expected), std::string::npos)
        << "case " << i << ": " << message;
  }
}

// The size a file states is checked before anything is allocated: 10^10 doubles in name are a
// wrong size, not an allocation (fuzz/calibrated_camera_fuzz.cc, docs/fuzzing.md).
TEST(CalibratedCamera, ReadChecksAMatrixSizeBeforeAllocating) {
  const std::string path = edited_file(
      "huge.yaml", "K",
      "K: !!opencv-matrix\n   rows: 100000\n   cols: 100000\n   dt: d\n   data: [ 1. ]\n");
  const std::string message = read_error(path);
  EXPECT_NE(message.find("K must be a 3 x 3 matrix"), std::string::npos) << message;
}

TEST(CalibratedCamera, ReadNamesAMissingOrUnparsableFile) {
  const std::string missing = temp_path("does_not_exist.yaml");
  EXPECT_NE(read_error(missing).find(missing), std::string::npos);
  const std::string garbage = temp_path("garbage.yaml");
  write_text(garbage, "%YAML:1.0\n---\nK: [1, 2\n  : : ]]\n");
  const std::string message = read_error(garbage);
  EXPECT_NE(message.find(garbage), std::string::npos) << message;
  // OpenCV's YAML parser throws std::length_error on a key that starts with ':'
  // (fuzz/calibrated_camera_fuzz.cc): still one InputError naming the file.
  const std::string colon_key = temp_path("colon_key.yaml");
  write_text(colon_key, "%YAML:1.0\n---\na:\n   b: 3\n   :c 1\n");
  EXPECT_NE(read_error(colon_key).find(colon_key), std::string::npos) << read_error(colon_key);
  // Neither a list at the top level, on which OpenCV asserts at the first key, nor a second
  // document, on which its parser loops forever, is handed to OpenCV.
  for (const std::string text :
       {"%YAML:1.0\n---\n- width_px\n- 1024\n", "%YAML:1.0\n---\n a: 3\n!x\n-"}) {
    const std::string path = temp_path("not_one_map.yaml");
    write_text(path, text);
    EXPECT_NE(read_error(path).find(path + ": not a YAML camera calibration file"),
              std::string::npos)
        << read_error(path);
  }
}

}  // namespace
}  // namespace airtwin
