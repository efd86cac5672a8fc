#pragma once
// The camera model the vision pipeline uses: a pinhole camera with lens distortion, CALIBRATED from
// images of a calibration target (vision/camera_calibration.h), never taken from the renderer.
// It maps pixels to the floor and back, for points on the floor or at a given height above it
// (an object's visible top is ~1-2 cm up: at 1 m from the image centre, ignoring it moves the
// answer by ~5 mm for a camera 3.2 m up).
//
// Conventions: pixels (u, v) = (column, row) of pixel centres, u right, v down, as OpenCV; the
// camera frame is OpenCV's (x right, y down, z forward); the world frame W is the floor's (origin
// below the nozzle, z up), metres. Saved as YAML by cv::FileStorage (docs/data_formats.md).

#include <Eigen/Core>
#include <optional>
#include <string>

namespace airtwin {

struct CalibratedCamera {
  int width_px = 0;
  int height_px = 0;
  /// Intrinsics [fx 0 cx; 0 fy cy; 0 0 1] (px).
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  /// OpenCV's distortion (k1, k2, p1, p2, k3).
  Eigen::Matrix<double, 5, 1> distortion = Eigen::Matrix<double, 5, 1>::Zero();
  /// World -> camera: p_C = R_CW p_W + t_C.
  Eigen::Matrix3d R_CW = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t_C = Eigen::Vector3d::Zero();
  /// Calibration quality: RMS reprojection error (px) of the intrinsic fit and of the world pose.
  double rms_reprojection_px = 0.0;
  double pose_rms_px = 0.0;
  int n_views = 0;  ///< target views used

  /// Pixel of a world point; nullopt when it is not in front of the camera.
  std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& p_W) const;
  /// The world point at height z_m (m above the floor) seen at pixel uv (distortion removed);
  /// nullopt when the ray does not meet that plane in front of the camera.
  std::optional<Eigen::Vector3d> point_at_height(const Eigen::Vector2d& uv_px, double z_m) const;
  /// Camera centre in the world (m).
  Eigen::Vector3d centre_W() const;

  /// Writes / reads the YAML file. read() throws InputError naming the file and the missing or
  /// malformed key (sizes, a non-finite number, a non-rotation R_CW).
  void write(const std::string& path) const;
  static CalibratedCamera read(const std::string& path);
};

}  // namespace airtwin
