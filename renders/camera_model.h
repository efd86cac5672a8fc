#pragma once
// The TRUE pinhole model of a fixed camera of the twin (normally `top`), computed from the
// compiled mjModel: what MuJoCo's renderer actually does, with no calibration error. It is the
// ground truth of synthetic datasets (truth.csv's x_px, y_px) and of the renderer's tests. The
// vision pipeline must NOT use it: it calibrates its own model from images of a calibration target,
// as it would on the rig, and is scored against this one.
//
// Conventions (docs/rendering.md):
//  - Pixel coordinates (u, v) in px of the saved image: u to the right, v down, the centre of the
//    top-left pixel at (0, 0) (OpenCV's convention), so the principal point of a centred camera is
//    ((W - 1) / 2, (H - 1) / 2).
//  - Camera frame C as in MuJoCo: x to the image's right, y to the image's top, looking along -z.
//    For the twin's `top` camera (xyaxes="1 0 0 0 1 0"): world +x is image right (+u) and world
//    +y is image up (-v).
//  - Square pixels: MuJoCo derives the horizontal field of view from the vertical one (cam_fovy)
//    and the image's aspect ratio, so fx = fy = (H / 2) / tan(fovy / 2).

#include <Eigen/Core>
#include <optional>
#include <string>

#include <mujoco/mujoco.h>

namespace airtwin {

class GroundTruthCamera {
 public:
  /// The model's camera `name`, image size from <visual><global offwidth offheight>. The camera
  /// must be fixed to the world body (its pose is then the model's, independent of any mjData).
  /// Throws InputError naming the camera when it does not exist, is attached to a moving body or
  /// tracks one, or the offscreen size is not > 0.
  static GroundTruthCamera from_model(const mjModel* m, const std::string& name = "top");

  /// Pixel (u, v) in px of the world point p_W (m). Points at or behind the camera's plane have
  /// no image: returns std::nullopt.
  std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& p_W) const;

  /// The floor point (z = 0, m, world frame) seen at pixel (u, v) in px: the viewing ray
  /// intersected with the floor plane. std::nullopt when the ray does not reach the floor in
  /// front of the camera (parallel to it, or pointing away).
  std::optional<Eigen::Vector3d> floor_point(const Eigen::Vector2d& uv_px) const;

  /// Intrinsic matrix [fx 0 cx; 0 fy cy; 0 0 1] in px for the (u right, v down) convention.
  Eigen::Matrix3d intrinsics() const;

  int width_px() const { return width_px_; }
  int height_px() const { return height_px_; }
  double focal_px() const { return focal_px_; }          ///< fx = fy (px)
  const Eigen::Vector3d& p_WC() const { return p_WC_; }  ///< camera centre in world (m)
  /// Orientation: columns are the camera frame's axes (x right, y up, z backwards) in world.
  const Eigen::Matrix3d& R_WC() const { return R_WC_; }

 private:
  GroundTruthCamera() = default;
  int width_px_ = 0, height_px_ = 0;
  double focal_px_ = 0.0, fovy_rad_ = 0.0;
  Eigen::Vector3d p_WC_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_WC_ = Eigen::Matrix3d::Identity();
};

}  // namespace airtwin
