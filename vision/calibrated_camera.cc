#include "vision/calibrated_camera.h"

#include <Eigen/Dense>
#include <cmath>
#include <filesystem>
#include <opencv2/core.hpp>

#include "common/atomic_file.h"
#include "common/csv.h"
#include "common/errors.h"
#include "vision/yaml_fields.h"

namespace airtwin {
namespace {

// OpenCV's lens model (k1, k2, p1, p2, k3) on normalised coordinates x = (X/Z, Y/Z).
Eigen::Vector2d distort(const Eigen::Matrix<double, 5, 1>& k, const Eigen::Vector2d& x) {
  const double r2 = x.squaredNorm();
  const double radial = 1.0 + r2 * (k[0] + r2 * (k[1] + r2 * k[4]));
  const double xy = x.x() * x.y();
  return {x.x() * radial + 2.0 * k[2] * xy + k[3] * (r2 + 2.0 * x.x() * x.x()),
          x.y() * radial + k[2] * (r2 + 2.0 * x.y() * x.y()) + 2.0 * k[3] * xy};
}

// Inverts distort() by Newton's method from the distorted point itself (the lens moves points by
// a few per cent at most); a finite-difference Jacobian is exact enough for a 2 x 2 solve.
// nullopt when it does not converge, i.e. the pixel lies outside the lens model's valid domain.
std::optional<Eigen::Vector2d> undistort(const Eigen::Matrix<double, 5, 1>& k,
                                         const Eigen::Vector2d& m) {
  if (k.isZero()) return m;
  Eigen::Vector2d x = m;
  for (int iteration = 0; iteration < 50; ++iteration) {
    const Eigen::Vector2d residual = distort(k, x) - m;
    if (residual.norm() < 1e-14) return x;
    constexpr double kStep = 1e-7;
    Eigen::Matrix2d J;
    J.col(0) =
        (distort(k, x + Eigen::Vector2d(kStep, 0)) - distort(k, x - Eigen::Vector2d(kStep, 0))) /
        (2 * kStep);
    J.col(1) =
        (distort(k, x + Eigen::Vector2d(0, kStep)) - distort(k, x - Eigen::Vector2d(0, kStep))) /
        (2 * kStep);
    if (!std::isfinite(J.determinant()) || std::abs(J.determinant()) < 1e-9) return std::nullopt;
    x -= J.lu().solve(residual);
    if (!x.allFinite()) return std::nullopt;
  }
  return (distort(k, x) - m).norm() < 1e-10 ? std::optional<Eigen::Vector2d>(x) : std::nullopt;
}

// cv::Mat <-> Eigen for the YAML file (cv::FileStorage stores matrices as opencv-matrix nodes).
template <int Rows, int Cols>
cv::Mat to_mat(const Eigen::Matrix<double, Rows, Cols>& e) {
  cv::Mat m(Rows, Cols, CV_64F);
  for (int r = 0; r < Rows; ++r) {
    for (int c = 0; c < Cols; ++c) m.at<double>(r, c) = e(r, c);
  }
  return m;
}

}  // namespace

std::optional<Eigen::Vector2d> CalibratedCamera::project(const Eigen::Vector3d& p_W) const {
  // Into the camera frame; behind (or in) the image plane has no pixel.
  const Eigen::Vector3d p_C = R_CW * p_W + t_C;
  if (!(p_C.z() > 0)) return std::nullopt;
  // Normalise, apply the lens, then the intrinsics.
  const Eigen::Vector2d xd = distort(distortion, p_C.head<2>() / p_C.z());
  return Eigen::Vector2d(K(0, 0) * xd.x() + K(0, 1) * xd.y() + K(0, 2), K(1, 1) * xd.y() + K(1, 2));
}

std::optional<Eigen::Vector3d> CalibratedCamera::point_at_height(const Eigen::Vector2d& uv_px,
                                                                 double z_m) const {
  // Pixel -> distorted normalised coordinates (K is upper triangular) -> the lens removed.
  const double yd = (uv_px.y() - K(1, 2)) / K(1, 1);
  const double xd = (uv_px.x() - K(0, 2) - K(0, 1) * yd) / K(0, 0);
  const std::optional<Eigen::Vector2d> x = undistort(distortion, {xd, yd});
  if (!x) return std::nullopt;
  // The viewing ray in the world, from the camera centre; meet the plane z = z_m in front.
  const Eigen::Vector3d d_W = R_CW.transpose() * Eigen::Vector3d(x->x(), x->y(), 1.0);
  const Eigen::Vector3d c_W = centre_W();
  if (std::abs(d_W.z()) < 1e-12) return std::nullopt;
  const double s = (z_m - c_W.z()) / d_W.z();
  if (!(s > 0) || !std::isfinite(s)) return std::nullopt;
  return c_W + s * d_W;
}

Eigen::Vector3d CalibratedCamera::centre_W() const { return -R_CW.transpose() * t_C; }

void CalibratedCamera::write(const std::string& path) const {
  // Composed in memory, then written whole or not at all (common/atomic_file.h).
  cv::FileStorage fs(
      ".yaml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  fs.writeComment(
      "airtwin calibrated camera: pinhole + OpenCV distortion (k1 k2 p1 p2 k3); p_C = R_CW p_W + "
      "t_C, world in m (floor z = 0), pixels (u right, v down); docs/camera_calibration.md");
  fs << "width_px" << width_px << "height_px" << height_px;
  fs << "K" << to_mat(K) << "distortion" << to_mat(distortion);
  fs << "R_CW" << to_mat(R_CW) << "t_C" << to_mat(t_C);
  fs << "rms_reprojection_px" << rms_reprojection_px << "pose_rms_px" << pose_rms_px;
  fs << "n_views" << n_views;
  write_file_atomically(path, fs.releaseAndGetString());
}

CalibratedCamera CalibratedCamera::read(const std::string& path) {
  // Open: a missing file and a file that is not YAML both name the file (checked before OpenCV
  // tries, which would log a second line of its own).
  if (!std::filesystem::is_regular_file(path)) {
    throw InputError(path + ": no such camera calibration file");
  }
  cv::FileStorage fs;
  open_yaml(read_text_file(path), path, "camera calibration file", &fs);
  const YamlFields in(path, fs);

  // The image size and the intrinsics: positive focal lengths, the bottom row (0 0 1).
  CalibratedCamera c;
  c.width_px = in.integer("width_px");
  c.height_px = in.integer("height_px");
  if (c.width_px <= 0) in.fail("width_px", "must be > 0");
  if (c.height_px <= 0) in.fail("height_px", "must be > 0");
  c.K = in.matrix<3, 3>("K");
  if (!(c.K(0, 0) > 0) || !(c.K(1, 1) > 0) || c.K(1, 0) != 0 || c.K(2, 0) != 0 || c.K(2, 1) != 0 ||
      c.K(2, 2) != 1) {
    in.fail("K", "must be [fx s cx; 0 fy cy; 0 0 1] with fx, fy > 0");
  }
  c.distortion = in.matrix<5, 1>("distortion");

  // The world pose: R_CW a proper rotation (orthonormal to 1e-6, determinant +1).
  c.R_CW = in.matrix<3, 3>("R_CW");
  if ((c.R_CW.transpose() * c.R_CW - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 ||
      c.R_CW.determinant() < 0) {
    in.fail("R_CW", "must be a rotation matrix (orthonormal, determinant +1)");
  }
  c.t_C = in.matrix<3, 1>("t_C");

  // Quality figures.
  c.rms_reprojection_px = in.real("rms_reprojection_px");
  c.pose_rms_px = in.real("pose_rms_px");
  c.n_views = in.integer("n_views");
  if (c.rms_reprojection_px < 0) in.fail("rms_reprojection_px", "must be >= 0");
  if (c.pose_rms_px < 0) in.fail("pose_rms_px", "must be >= 0");
  if (c.n_views < 0) in.fail("n_views", "must be >= 0");
  return c;
}

}  // namespace airtwin
