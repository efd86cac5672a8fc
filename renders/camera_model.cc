#include "renders/camera_model.h"

#include <cmath>

#include "common/errors.h"
#include "common/units.h"

namespace airtwin {

GroundTruthCamera GroundTruthCamera::from_model(const mjModel* m, const std::string& name) {
  AIRTWIN_DEMAND(m != nullptr);
  // The camera: present, on the world body, not tracking anything.
  const int id = mj_name2id(m, mjOBJ_CAMERA, name.c_str());
  if (id < 0) throw InputError("model: no camera named '" + name + "'");
  if (m->cam_bodyid[id] != 0 || m->cam_mode[id] != mjCAMLIGHT_FIXED) {
    throw InputError("model: camera '" + name +
                     "' must be fixed to the world body for a ground-truth model");
  }
  if (m->vis.global.offwidth <= 0 || m->vis.global.offheight <= 0) {
    throw InputError("model: <visual><global offwidth offheight> must be > 0");
  }

  GroundTruthCamera c;
  c.width_px_ = m->vis.global.offwidth;
  c.height_px_ = m->vis.global.offheight;
  // Pose: on the world body, the camera's position and quaternion are already in world.
  c.p_WC_ = Eigen::Vector3d(m->cam_pos[3 * id], m->cam_pos[3 * id + 1], m->cam_pos[3 * id + 2]);
  mjtNum mat[9];
  mju_quat2Mat(mat, m->cam_quat + 4 * id);
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) c.R_WC_(r, k) = mat[3 * r + k];
  }
  // Focal length: the vertical field of view spans the image height (MuJoCo's frustum).
  c.fovy_rad_ = deg_to_rad(m->cam_fovy[id]);
  c.focal_px_ = 0.5 * c.height_px_ / std::tan(0.5 * c.fovy_rad_);
  return c;
}

std::optional<Eigen::Vector2d> GroundTruthCamera::project(const Eigen::Vector3d& p_W) const {
  // Into the camera frame; the camera looks along its -z, so depth = -z_C.
  const Eigen::Vector3d p_C = R_WC_.transpose() * (p_W - p_WC_);
  const double depth = -p_C.z();
  if (!(depth > 0)) return std::nullopt;
  // Perspective division; v grows downwards while y_C grows upwards.
  const double cx = 0.5 * (width_px_ - 1), cy = 0.5 * (height_px_ - 1);
  return Eigen::Vector2d(cx + focal_px_ * p_C.x() / depth, cy - focal_px_ * p_C.y() / depth);
}

std::optional<Eigen::Vector3d> GroundTruthCamera::floor_point(const Eigen::Vector2d& uv_px) const {
  // The viewing ray through the pixel, in the camera frame (depth 1), then in world.
  const double cx = 0.5 * (width_px_ - 1), cy = 0.5 * (height_px_ - 1);
  const Eigen::Vector3d ray_C((uv_px.x() - cx) / focal_px_, -(uv_px.y() - cy) / focal_px_, -1.0);
  const Eigen::Vector3d ray_W = R_WC_ * ray_C;
  // Intersection with z = 0 in front of the camera.
  if (!(std::abs(ray_W.z()) > 1e-12)) return std::nullopt;
  const double s = -p_WC_.z() / ray_W.z();
  if (!(s > 0)) return std::nullopt;
  Eigen::Vector3d p_W = p_WC_ + s * ray_W;
  p_W.z() = 0.0;
  return p_W;
}

Eigen::Matrix3d GroundTruthCamera::intrinsics() const {
  Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
  k(0, 0) = focal_px_;
  k(1, 1) = focal_px_;
  k(0, 2) = 0.5 * (width_px_ - 1);
  k(1, 2) = 0.5 * (height_px_ - 1);
  return k;
}

}  // namespace airtwin
