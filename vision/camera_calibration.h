#pragma once
// Camera calibration from frames of a checkerboard target, the procedure people follow on the rig
// (docs/camera_calibration.md), and the one the twin's renders go through too (the renderer's
// ground truth is never read here):
//  1. corners: cv::findChessboardCorners + cv::cornerSubPix on every frame of the folder, in the
//     board's own order (origin corner first, see below);
//  2. intrinsics: cv::calibrateCamera with the simplest model the corners support (lens:
//     pinhole, then OpenCV's k1, k2, p1, p2[, k3]; square pixels or not; least Bayesian
//     information criterion, compared on at most 16 views), then every view's board pose by
//     cv::solvePnP; a view whose reprojection error stands out is rejected;
//  3. world pose: cv::solvePnP on the reference frame, in which the board lies flat on the floor
//     where target.yaml says (origin corner x, y and yaw, as measured on the rig);
//  4. joint fit (bundle adjustment) of the intrinsics, the world pose and every board's pose to
//     every corner, the boards found lying flat on the floor (their plane is the reference
//     board's) constrained to it: one board shows the floor's tilt only over its own patch of
//     the image, boards all over the floor show it everywhere;
//  5. quality: RMS reprojection errors, and the corners of the boards on the floor mapped back
//     onto the board's plane against where they are (the floor error).
//
// The board's origin: OpenCV finds a checkerboard's corners up to the board's symmetries. The
// order is made the board's own: z = x cross y must point at the camera (the printed face is what
// the camera sees), and the square between inner corners 0, 1, cols and cols + 1 must be black.
// That needs an asymmetric board, i.e. an odd number of squares along exactly one side (inner
// corners cols + rows odd, e.g. 10 x 7); target.yaml is refused otherwise.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "vision/calibrated_camera.h"

namespace airtwin {

/// The calibration target as target.yaml describes it (docs/data_formats.md).
struct CalibrationTarget {
  int inner_corners_cols = 0;  ///< inner corners along the board's x axis (its long side)
  int inner_corners_rows = 0;  ///< along its y axis
  double square_size_m = 0.0;
  double thickness_m = 0.0;     ///< printed surface above the floor when the board lies on it (m)
  std::string reference_frame;  ///< file name (in the folder) of the view of the board on the floor
  /// The reference view's board pose: origin corner on the floor (m, world) and the angle of the
  /// board's x axis from the world's x axis, counter-clockwise seen from above (rad).
  Eigen::Vector2d origin_W = Eigen::Vector2d::Zero();
  double yaw_rad = 0.0;

  /// World position (m) of inner corner (i, j) of the board in the reference view.
  Eigen::Vector3d reference_corner_W(int i, int j) const;

  /// Reads a target.yaml (YAML as cv::FileStorage reads it; the %YAML:1.0 directive it wants is
  /// supplied when the file has none). Throws InputError naming the file and the key: missing,
  /// not a number, out of range (corners >= 3 and cols + rows odd, square size > 0, thickness
  /// >= 0, finite pose, a plain file name for the frame).
  static CalibrationTarget read(const std::string& path);
};

/// Lens models, simplest first: which of OpenCV's distortion terms are fitted (the rest are 0).
enum class LensModel {
  kPinhole = 0,            ///< no distortion
  kRadial1 = 1,            ///< k1
  kRadial2 = 2,            ///< k1, k2
  kRadial2Tangential = 3,  ///< k1, k2, p1, p2 (OpenCV's usual model without k3)
  kRadial3Tangential = 4,  ///< k1, k2, p1, p2, k3 (wide-angle lenses)
};

/// "pinhole", "k1", "k1 k2", "k1 k2 p1 p2", "k1 k2 p1 p2 k3".
const char* lens_model_name(LensModel lens);

struct CameraCalibrationOptions {
  /// The richest lens model tried.
  LensModel max_lens_model = LensModel::kRadial2Tangential;
  /// Keep the simplest model that the corners support (least BIC): lens models up to
  /// max_lens_model, square pixels (fx = fy) or not. Terms fitted to noise bend the model where
  /// no board was seen (the image's corners). Off: fit max_lens_model with fx and fy free.
  bool select_model = true;
  /// A view whose reprojection RMS exceeds max(this, 3 x the median view's) is rejected (px).
  double max_view_rms_px = 1.0;
};

/// What happened to one frame of the folder.
struct CalibrationViewReport {
  std::string frame;      ///< file name in the folder
  bool used = false;      ///< in the final fit
  bool on_floor = false;  ///< its board lies flat on the floor (it pins the world pose)
  std::string reason;     ///< why not, when not used
  double rms_px = 0.0;    ///< its reprojection RMS in the final fit (used views)
};

struct CameraCalibrationResult {
  CalibratedCamera camera;
  LensModel lens_model = LensModel::kPinhole;  ///< the lens model fitted
  bool square_pixels = false;                  ///< whether fx = fy was imposed
  std::vector<CalibrationViewReport> views;    ///< every image file of the folder, by name
  /// RMS distance (m) between the detected corners of the boards on the floor mapped onto the
  /// board's plane (z = thickness) by `camera` and the corners where the fit puts those boards
  /// (the reference where target.yaml does): the floor error of the calibration where the boards
  /// lay.
  double floor_rms_m = 0.0;
  /// Size of one pixel on the floor at the image centre (m/px).
  double floor_m_per_px = 0.0;
};

/// Calibrates the camera from the folder `dir`: its image files (png, jpg, jpeg, bmp, tif, tiff;
/// any other file is ignored) and target.yaml. Views without a findable board are reported and
/// skipped. Throws InputError naming the folder or file: no folder, no or bad target.yaml, no
/// image, no view with a detectable board, fewer than 3 usable views, the reference frame missing
/// or without a board, a calibration that does not converge.
CameraCalibrationResult calibrate_camera(const std::string& dir,
                                         const CameraCalibrationOptions& options = {});

}  // namespace airtwin
