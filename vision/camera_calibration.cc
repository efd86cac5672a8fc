#include "vision/camera_calibration.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/errors.h"
#include "common/text.h"
#include "common/units.h"
#include "vision/frame_source.h"
#include "vision/yaml_fields.h"

namespace airtwin {
namespace {

namespace fs = std::filesystem;

constexpr const char* kTargetFile = "target.yaml";
// At least this many views with a board: fewer leave the intrinsics poorly determined.
constexpr int kMinViews = 3;
// The lens models are compared on at most this many views.
constexpr size_t kModelViews = 16;
// A board whose plane is within this angle (rad) and this fraction of the camera's distance of
// the reference board's plane lies on the floor too (propped boards lean 15 deg or more).
constexpr double kFloorAngle = deg_to_rad(2.0);
constexpr double kFloorOffset = 0.01;

// Mean grey level of a small patch around `centre` (px), clipped to the image.
double patch_mean(const cv::Mat& grey, const cv::Point2f& centre, int half) {
  const int u = static_cast<int>(std::lround(centre.x)),
            v = static_cast<int>(std::lround(centre.y));
  const cv::Rect patch = cv::Rect(u - half, v - half, 2 * half + 1, 2 * half + 1) &
                         cv::Rect(0, 0, grey.cols, grey.rows);
  if (patch.area() == 0) return 0.0;
  return cv::mean(grey(patch))[0];
}

// Puts the corners of one view in the board's own order (see the header): first mirror the rows
// if z = x cross y points away from the camera, then turn the grid by 180 deg if square (0, 0) is
// the lighter of squares (0, 0) and (1, 0).
void order_like_the_board(const cv::Mat& grey, int cols, int rows,
                          std::vector<cv::Point2f>& corners) {
  auto at = [&](int i, int j) -> cv::Point2f& {
    return corners[static_cast<size_t>(j * cols + i)];
  };
  // Handedness: in (u right, v down) pixels, a board seen from its printed side has
  // (x direction) cross (y direction) < 0.
  const cv::Point2f x = at(1, 0) - at(0, 0), y = at(0, 1) - at(0, 0);
  if (x.x * y.y - x.y * y.x > 0) {
    for (int j = 0; j < rows; ++j) {
      std::reverse(corners.begin() + j * cols, corners.begin() + (j + 1) * cols);
    }
  }
  // Parity: the centres of squares (0, 0) and (1, 0) from their four corners.
  const cv::Point2f square00 = 0.25f * (at(0, 0) + at(1, 0) + at(0, 1) + at(1, 1));
  const cv::Point2f square10 = 0.25f * (at(1, 0) + at(2, 0) + at(1, 1) + at(2, 1));
  const double side = std::min(cv::norm(at(1, 0) - at(0, 0)), cv::norm(at(0, 1) - at(0, 0)));
  const int half = std::max(1, static_cast<int>(0.15 * side));
  if (patch_mean(grey, square00, half) > patch_mean(grey, square10, half)) {
    std::reverse(corners.begin(), corners.end());
  }
}

// The smallest distance (px) between neighbouring corners of the grid.
double smallest_spacing(const std::vector<cv::Point2f>& corners, int cols, int rows) {
  double spacing = 1e9;
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < cols; ++i) {
      const cv::Point2f& p = corners[static_cast<size_t>(j * cols + i)];
      if (i + 1 < cols) spacing = std::min(spacing, cv::norm(corners[j * cols + i + 1] - p));
      if (j + 1 < rows) spacing = std::min(spacing, cv::norm(corners[(j + 1) * cols + i] - p));
    }
  }
  return spacing;
}

// One frame: the board's corners in the board's order, or the reason there are none.
struct Detection {
  std::vector<cv::Point2f> corners;
  std::string failure;
};

Detection detect_board(const cv::Mat& grey, const CalibrationTarget& t) {
  Detection d;
  const cv::Size pattern(t.inner_corners_cols, t.inner_corners_rows);
  const bool found = cv::findChessboardCorners(
      grey, pattern, d.corners,
      cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK);
  if (!found || d.corners.size() != static_cast<size_t>(pattern.area())) {
    d.corners.clear();
    d.failure = "no board of " + std::to_string(pattern.width) + " x " +
                std::to_string(pattern.height) + " inner corners found";
    return d;
  }
  // Sub-pixel corners: a search window of ~0.4 of the smallest square seen, so that it holds
  // the corner's own four edges and no neighbouring corner.
  const double spacing = smallest_spacing(d.corners, pattern.width, pattern.height);
  if (spacing < 8.0) {
    d.corners.clear();
    d.failure =
        "board too small in the image (squares of " + format_short(spacing) + " px, need >= 8)";
    return d;
  }
  const int half = std::clamp(static_cast<int>(0.4 * spacing), 3, 15);
  cv::cornerSubPix(grey, d.corners, cv::Size(half, half), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 1e-4));
  order_like_the_board(grey, pattern.width, pattern.height, d.corners);
  return d;
}

Eigen::Matrix3d to_eigen3(const cv::Mat& m) {
  Eigen::Matrix3d e;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) e(r, c) = m.at<double>(r, c);
  }
  return e;
}

cv::Mat to_mat(const Eigen::Matrix3d& e) {
  cv::Mat m(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m.at<double>(r, c) = e(r, c);
  }
  return m;
}

// The intrinsic fit over the views `used` (indices into detections): K, distortion, per-view
// board poses and per-view RMS. InputError when OpenCV gives up.
struct IntrinsicFit {
  cv::Mat K, distortion;
  std::vector<cv::Mat> rvecs, tvecs;
  std::vector<double> view_rms_px;
  double rms_px = 0.0;
};

// OpenCV's flags that leave exactly the distortion terms of `lens` free (the others stay 0).
int lens_flags(LensModel lens) {
  switch (lens) {
    case LensModel::kPinhole:
      return cv::CALIB_FIX_K1 | cv::CALIB_FIX_K2 | cv::CALIB_FIX_K3 | cv::CALIB_ZERO_TANGENT_DIST;
    case LensModel::kRadial1:
      return cv::CALIB_FIX_K2 | cv::CALIB_FIX_K3 | cv::CALIB_ZERO_TANGENT_DIST;
    case LensModel::kRadial2:
      return cv::CALIB_FIX_K3 | cv::CALIB_ZERO_TANGENT_DIST;
    case LensModel::kRadial2Tangential:
      return cv::CALIB_FIX_K3;
    case LensModel::kRadial3Tangential:
      return 0;
  }
  AIRTWIN_DEMAND(false);
  return 0;
}

int lens_terms(LensModel lens) {
  constexpr int kTerms[] = {0, 1, 2, 4, 5};
  return kTerms[static_cast<int>(lens)];
}

// A model of the intrinsic fit: the lens terms, and whether fx = fy.
struct IntrinsicModel {
  LensModel lens = LensModel::kPinhole;
  bool square_pixels = true;
};

IntrinsicFit fit_intrinsics(const std::vector<std::vector<cv::Point2f>>& image_points,
                            const CalibrationTarget& t, cv::Size image_size,
                            const IntrinsicModel& model, const std::string& dir) {
  // The board's corners in its own frame (z = 0), the same for every view.
  std::vector<cv::Point3f> board;
  for (int j = 0; j < t.inner_corners_rows; ++j) {
    for (int i = 0; i < t.inner_corners_cols; ++i) {
      board.emplace_back(static_cast<float>(i * t.square_size_m),
                         static_cast<float>(j * t.square_size_m), 0.0f);
    }
  }
  const std::vector<std::vector<cv::Point3f>> object_points(image_points.size(), board);
  IntrinsicFit fit;
  // Square pixels: OpenCV keeps the ratio fx / fy of the matrix passed in (1).
  const int flags = lens_flags(model.lens) | (model.square_pixels ? cv::CALIB_FIX_ASPECT_RATIO : 0);
  fit.K = cv::Mat::eye(3, 3, CV_64F);
  cv::Mat std_intrinsics, std_extrinsics, view_errors;
  try {
    fit.rms_px = cv::calibrateCamera(
        object_points, image_points, image_size, fit.K, fit.distortion, fit.rvecs, fit.tvecs,
        std_intrinsics, std_extrinsics, view_errors, flags,
        cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200, 1e-15));
  } catch (const cv::Exception& e) {
    throw InputError(dir + ": cv::calibrateCamera failed: " + e.err);
  }
  if (!std::isfinite(fit.rms_px) || !cv::checkRange(fit.K) || !cv::checkRange(fit.distortion)) {
    throw InputError(dir + ": the calibration did not converge (non-finite result)");
  }
  fit.distortion = fit.distortion.reshape(1, 1);
  for (int k = 0; k < view_errors.rows; ++k) fit.view_rms_px.push_back(view_errors.at<double>(k));
  return fit;
}

// A board lying flat on the floor: its origin corner (x, y) in m and the yaw of its x axis (rad).
struct FloorPose {
  double x = 0.0, y = 0.0, yaw = 0.0;
};

Eigen::Vector3d floor_corner_W(const CalibrationTarget& t, const FloorPose& b, int i, int j) {
  const Eigen::Vector3d x_W(std::cos(b.yaw), std::sin(b.yaw), 0.0);
  const Eigen::Vector3d y_W(-std::sin(b.yaw), std::cos(b.yaw), 0.0);
  return Eigen::Vector3d(b.x, b.y, t.thickness_m) + t.square_size_m * (i * x_W + j * y_W);
}

// The rotation exp([w]x) of a rotation vector w (rad).
Eigen::Matrix3d rotation(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  return angle > 0 ? Eigen::AngleAxisd(angle, w / angle).toRotationMatrix()
                   : Eigen::Matrix3d::Identity();
}

// One view of the joint fit: the reference board (where target.yaml puts it), a board lying on
// the floor (x, y, yaw fitted) or a board anywhere (its pose in the camera frame fitted).
enum class BoardKind { kReference, kFloor, kFree };
struct JointView {
  const std::vector<cv::Point2f>* corners = nullptr;
  BoardKind kind = BoardKind::kFree;
  FloorPose floor;                                     // kReference, kFloor
  Eigen::Matrix3d R_CB = Eigen::Matrix3d::Identity();  // kFree
  Eigen::Vector3d t_CB = Eigen::Vector3d::Zero();      // kFree
};

// The joint fit of everything to every corner (a bundle adjustment): the intrinsics and lens
// terms of the model, the camera's world pose, the floor poses of the boards on the floor and the
// poses of the others. cv::calibrateCamera knows nothing of the floor; here the boards on the
// floor share its plane, so that they pin the floor's image (the homography that the floor error
// depends on) wherever they lie, not just at the reference board, and the principal point and
// the camera's tilt, nearly interchangeable for a camera looking straight down, stop trading
// errors that grow towards the image's corners. Levenberg-Marquardt on the reprojection errors
// (px) with central-difference Jacobians, assembled view by view (a view depends on the shared
// parameters and its own only, so the cost grows with the views, not their square); rotations
// are updated as exp(w) R.
class JointFit {
 public:
  JointFit(const CalibrationTarget& t, const IntrinsicModel& model, const CalibratedCamera& camera,
           std::vector<JointView> views)
      : t_(&t), model_(model), camera_(camera), views_(std::move(views)) {
    // Parameter layout: intrinsics (f or fx, fy; cx, cy), lens terms, the camera's rotation
    // increment and t_C (the shared block), then per view (x, y, yaw) on the floor or a rotation
    // increment and t_CB.
    static const std::vector<int> kLensIndices[] = {{}, {0}, {0, 1}, {0, 1, 2, 3}, {0, 1, 2, 3, 4}};
    lens_indices_ = kLensIndices[static_cast<int>(model.lens)];
    intrinsics_ = (model.square_pixels ? 3 : 4) + static_cast<int>(lens_indices_.size());
    Eigen::Index offset = intrinsics_ + 6;
    for (const JointView& v : views_) {
      offset_.push_back(offset);
      offset += v.kind == BoardKind::kFloor ? 3 : v.kind == BoardKind::kFree ? 6 : 0;
    }
    size_ = offset;
  }

  void run() {
    Eigen::VectorXd p = pack();
    double cost = cost_at(p), lambda = 1e-3;
    for (int iteration = 0; iteration < 100; ++iteration) {
      // Normal equations J^T J, J^T r, assembled view by view: a view's corners depend on the
      // intrinsics, the camera pose (boards on the floor) and the view's own parameters only.
      Eigen::MatrixXd JtJ = Eigen::MatrixXd::Zero(size_, size_);
      Eigen::VectorXd g = Eigen::VectorXd::Zero(size_);
      const CalibratedCamera camera = camera_at(p);
      for (size_t v = 0; v < views_.size(); ++v) {
        accumulate_view(p, camera, v, JtJ, g);
      }
      // Damped steps; one that lowers the cost is taken and the damping eased.
      bool improved = false, converged = false;
      for (int tries = 0; tries < 12 && !improved; ++tries) {
        Eigen::MatrixXd A = JtJ;
        A.diagonal() += lambda * JtJ.diagonal().cwiseMax(1e-12);
        const Eigen::VectorXd trial = p + A.ldlt().solve(-g);
        const double trial_cost = cost_at(trial);
        if (std::isfinite(trial_cost) && trial_cost < cost) {
          converged = cost - trial_cost < 1e-12 * cost;
          p = trial;
          cost = trial_cost;
          lambda = std::max(lambda / 10, 1e-12);
          improved = true;
        } else {
          lambda *= 10;
        }
      }
      if (!improved || converged) break;
    }
    // Bake the fitted parameters in.
    const CalibratedCamera camera = camera_at(p);
    for (size_t v = 0; v < views_.size(); ++v) views_[v] = view_at(p, v);
    camera_ = camera;
  }

  const CalibratedCamera& camera() const { return camera_; }
  const JointView& view(size_t v) const { return views_[v]; }

  // RMS reprojection error (px) of view v, and of all views, at the fitted parameters.
  double view_rms_px(size_t v) const {
    const Eigen::VectorXd r = view_residuals(camera_, views_[v]);
    return std::sqrt(r.squaredNorm() / (0.5 * static_cast<double>(r.size())));
  }
  double rms_px() const {
    double sum = 0.0;
    for (const JointView& v : views_) sum += view_residuals(camera_, v).squaredNorm();
    const double corners =
        static_cast<double>(views_.size()) * t_->inner_corners_cols * t_->inner_corners_rows;
    return std::sqrt(sum / corners);
  }

 private:
  Eigen::VectorXd pack() const {
    Eigen::VectorXd p = Eigen::VectorXd::Zero(size_);
    Eigen::Index i = 0;
    p[i++] = camera_.K(0, 0);
    if (!model_.square_pixels) p[i++] = camera_.K(1, 1);
    p[i++] = camera_.K(0, 2);
    p[i++] = camera_.K(1, 2);
    for (int k : lens_indices_) p[i++] = camera_.distortion[k];
    p.segment<3>(i + 3) = camera_.t_C;  // the rotation increment starts at 0
    for (size_t v = 0; v < views_.size(); ++v) {
      const JointView& view = views_[v];
      if (view.kind == BoardKind::kFloor) {
        p.segment<3>(offset_[v]) << view.floor.x, view.floor.y, view.floor.yaw;
      } else if (view.kind == BoardKind::kFree) {
        p.segment<3>(offset_[v] + 3) = view.t_CB;
      }
    }
    return p;
  }

  // The camera (intrinsics, lens, world pose) and view v at parameters p.
  CalibratedCamera camera_at(const Eigen::VectorXd& p) const {
    CalibratedCamera c = camera_;
    Eigen::Index i = 0;
    c.K(0, 0) = p[i++];
    c.K(1, 1) = model_.square_pixels ? c.K(0, 0) : p[i++];
    c.K(0, 2) = p[i++];
    c.K(1, 2) = p[i++];
    for (int k : lens_indices_) c.distortion[k] = p[i++];
    c.R_CW = rotation(p.segment<3>(i)) * camera_.R_CW;
    c.t_C = p.segment<3>(i + 3);
    return c;
  }

  JointView view_at(const Eigen::VectorXd& p, size_t v) const {
    JointView view = views_[v];
    const Eigen::Index i = offset_[v];
    if (view.kind == BoardKind::kFloor) {
      view.floor = FloorPose{p[i], p[i + 1], p[i + 2]};
    } else if (view.kind == BoardKind::kFree) {
      view.R_CB = rotation(p.segment<3>(i)) * views_[v].R_CB;
      view.t_CB = p.segment<3>(i + 3);
    }
    return view;
  }

  double cost_at(const Eigen::VectorXd& p) const {
    const CalibratedCamera camera = camera_at(p);
    double cost = 0.0;
    for (size_t v = 0; v < views_.size(); ++v) {
      cost += view_residuals(camera, view_at(p, v)).squaredNorm();
    }
    return cost;
  }

  // Adds view v's share of J^T J and J^T r: central differences over the parameters it depends
  // on, steps relative to each parameter's size.
  void accumulate_view(const Eigen::VectorXd& p, const CalibratedCamera& camera, size_t v,
                       Eigen::MatrixXd& JtJ, Eigen::VectorXd& g) const {
    const JointView& base = views_[v];
    std::vector<Eigen::Index> depends;
    for (Eigen::Index k = 0; k < intrinsics_; ++k) depends.push_back(k);
    if (base.kind != BoardKind::kFree) {
      for (Eigen::Index k = intrinsics_; k < intrinsics_ + 6; ++k) depends.push_back(k);
    }
    const Eigen::Index own = base.kind == BoardKind::kFloor  ? 3
                             : base.kind == BoardKind::kFree ? 6
                                                             : 0;
    for (Eigen::Index k = 0; k < own; ++k) depends.push_back(offset_[v] + k);

    const JointView view = view_at(p, v);
    const Eigen::VectorXd r = view_residuals(camera, view);
    Eigen::MatrixXd J(r.size(), static_cast<Eigen::Index>(depends.size()));
    Eigen::VectorXd q = p;
    for (size_t c = 0; c < depends.size(); ++c) {
      const Eigen::Index k = depends[c];
      const double h = 1e-6 * std::max(1.0, std::abs(p[k]));
      const bool shared = k < intrinsics_ + 6;
      q[k] = p[k] + h;
      const Eigen::VectorXd plus =
          shared ? view_residuals(camera_at(q), view) : view_residuals(camera, view_at(q, v));
      q[k] = p[k] - h;
      const Eigen::VectorXd minus =
          shared ? view_residuals(camera_at(q), view) : view_residuals(camera, view_at(q, v));
      q[k] = p[k];
      J.col(static_cast<Eigen::Index>(c)) = (plus - minus) / (2 * h);
    }
    const Eigen::MatrixXd JtJ_v = J.transpose() * J;
    const Eigen::VectorXd g_v = J.transpose() * r;
    for (size_t a = 0; a < depends.size(); ++a) {
      g[depends[a]] += g_v[static_cast<Eigen::Index>(a)];
      for (size_t b = 0; b < depends.size(); ++b) {
        JtJ(depends[a], depends[b]) +=
            JtJ_v(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b));
      }
    }
  }

  // Reprojection errors (px) of one view's corners through camera c.
  Eigen::VectorXd view_residuals(const CalibratedCamera& c, const JointView& v) const {
    // A board anywhere is projected through the camera placed at the board's frame.
    CalibratedCamera through = c;
    if (v.kind == BoardKind::kFree) {
      through.R_CW = v.R_CB;
      through.t_C = v.t_CB;
    }
    const std::vector<cv::Point2f>& seen = *v.corners;
    Eigen::VectorXd r(2 * seen.size());
    for (int j = 0; j < t_->inner_corners_rows; ++j) {
      for (int i = 0; i < t_->inner_corners_cols; ++i) {
        const size_t k = static_cast<size_t>(j * t_->inner_corners_cols + i);
        const Eigen::Vector3d p =
            v.kind == BoardKind::kFree
                ? Eigen::Vector3d(i * t_->square_size_m, j * t_->square_size_m, 0.0)
                : floor_corner_W(*t_, v.floor, i, j);
        const std::optional<Eigen::Vector2d> uv = through.project(p);
        // A corner behind the camera: a large penalty rather than no residual.
        r.segment<2>(2 * static_cast<Eigen::Index>(k)) =
            uv ? Eigen::Vector2d(*uv - Eigen::Vector2d(seen[k].x, seen[k].y))
               : Eigen::Vector2d(1e4, 1e4);
      }
    }
    return r;
  }

  const CalibrationTarget* t_;
  IntrinsicModel model_;
  CalibratedCamera camera_;       // also the base of the rotation increments
  std::vector<JointView> views_;  // also the bases of their rotation increments
  std::vector<int> lens_indices_;
  Eigen::Index intrinsics_ = 0;       // intrinsic and lens parameters
  std::vector<Eigen::Index> offset_;  // of each view's own parameters
  Eigen::Index size_ = 0;
};

}  // namespace

Eigen::Vector3d CalibrationTarget::reference_corner_W(int i, int j) const {
  return floor_corner_W(*this, FloorPose{origin_W.x(), origin_W.y(), yaw_rad}, i, j);
}

CalibrationTarget CalibrationTarget::read(const std::string& path) {
  // Open: missing and unparsable files both name the file.
  if (!fs::is_regular_file(path)) {
    throw InputError(path +
                     ": no calibration target file (board geometry and reference pose, "
                     "docs/camera_calibration.md)");
  }
  // People write this file by hand: cv::FileStorage wants a %YAML directive first, so one is
  // supplied when the file has none.
  std::ifstream file(path, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  if (!file) throw InputError(path + ": cannot read the calibration target file");
  if (text.rfind("%YAML", 0) != 0) text.insert(0, "%YAML:1.0\n---\n");
  cv::FileStorage storage;
  open_yaml(text, path, "calibration target file", &storage);
  const YamlFields in(path, storage);

  // The board: an asymmetric pattern of at least 3 x 3 inner corners.
  CalibrationTarget t;
  t.inner_corners_cols = in.integer("board.inner_corners_cols");
  t.inner_corners_rows = in.integer("board.inner_corners_rows");
  if (t.inner_corners_cols < 3) in.fail("board.inner_corners_cols", "must be >= 3");
  if (t.inner_corners_rows < 3) in.fail("board.inner_corners_rows", "must be >= 3");
  if ((t.inner_corners_cols + t.inner_corners_rows) % 2 == 0) {
    in.fail("board.inner_corners_rows",
            "must differ from inner_corners_cols in parity (an odd number of squares along one "
            "side only), or the board's origin cannot be told from the opposite corner, got " +
                std::to_string(t.inner_corners_cols) + " x " +
                std::to_string(t.inner_corners_rows));
  }
  t.square_size_m = in.real("board.square_size_m");
  if (!(t.square_size_m > 0)) in.fail("board.square_size_m", "must be > 0");
  t.thickness_m = in.real("board.thickness_m");
  if (!(t.thickness_m >= 0)) in.fail("board.thickness_m", "must be >= 0");

  // The reference view: a file name of the folder and the board's measured pose in it.
  t.reference_frame = in.text("reference.frame");
  if (t.reference_frame.empty() || fs::path(t.reference_frame).filename() != t.reference_frame) {
    in.fail("reference.frame",
            "must be the file name of a frame in the folder, got '" + t.reference_frame + "'");
  }
  t.origin_W = {in.real("reference.origin_x_m"), in.real("reference.origin_y_m")};
  t.yaw_rad = deg_to_rad(in.real("reference.yaw_deg"));
  return t;
}

const char* lens_model_name(LensModel lens) {
  switch (lens) {
    case LensModel::kPinhole:
      return "pinhole";
    case LensModel::kRadial1:
      return "k1";
    case LensModel::kRadial2:
      return "k1 k2";
    case LensModel::kRadial2Tangential:
      return "k1 k2 p1 p2";
    case LensModel::kRadial3Tangential:
      return "k1 k2 p1 p2 k3";
  }
  return "?";
}

CameraCalibrationResult calibrate_camera(const std::string& dir,
                                         const CameraCalibrationOptions& options) {
  if (!(std::isfinite(options.max_view_rms_px) && options.max_view_rms_px > 0)) {
    throw InputError("camera calibration: max_view_rms_px must be > 0, got " +
                     format_short(options.max_view_rms_px));
  }
  if (static_cast<int>(options.max_lens_model) < 0 ||
      options.max_lens_model > LensModel::kRadial3Tangential) {
    throw InputError("camera calibration: max_lens_model is not a lens model");
  }
  // The folder, its target file and its images (by name).
  if (!fs::is_directory(dir)) throw InputError(dir + ": no such calibration folder");
  const CalibrationTarget target = CalibrationTarget::read((fs::path(dir) / kTargetFile).string());
  std::vector<std::string> frames;
  for (const std::string& file : list_image_files(dir)) {
    frames.push_back(fs::path(file).filename().string());
  }
  if (std::find(frames.begin(), frames.end(), target.reference_frame) == frames.end()) {
    std::string message = (fs::path(dir) / kTargetFile).string();
    message += ": reference.frame '";
    message += target.reference_frame;
    message += "' is not an image file of the folder";
    throw InputError(message);
  }

  // Corners of every frame; frames without a board (or of another size) are reported.
  CameraCalibrationResult result;
  std::vector<std::vector<cv::Point2f>> corners;  // per candidate view
  std::vector<size_t> candidate;                  // index into result.views
  cv::Size image_size;
  for (const std::string& frame : frames) {
    CalibrationViewReport report;
    report.frame = frame;
    const std::string path = (fs::path(dir) / frame).string();
    cv::Mat grey;
    try {
      grey = cv::imread(path, cv::IMREAD_GRAYSCALE);
    } catch (const cv::Exception&) {
      grey.release();
    }
    if (grey.empty()) {
      report.reason = "cannot read the image";
    } else if (!image_size.empty() && grey.size() != image_size) {
      report.reason = "image size " + std::to_string(grey.cols) + " x " +
                      std::to_string(grey.rows) + " differs from the first frame's " +
                      std::to_string(image_size.width) + " x " + std::to_string(image_size.height);
    } else {
      if (image_size.empty()) image_size = grey.size();
      Detection d = detect_board(grey, target);
      if (d.corners.empty()) {
        report.reason = d.failure;
      } else {
        corners.push_back(std::move(d.corners));
        candidate.push_back(result.views.size());
      }
    }
    result.views.push_back(report);
  }
  if (candidate.empty()) {
    throw InputError(dir + ": no view has a detectable board of " +
                     std::to_string(target.inner_corners_cols) + " x " +
                     std::to_string(target.inner_corners_rows) + " inner corners (" +
                     std::to_string(frames.size()) + " images)");
  }
  auto reference_of = [&]() -> std::optional<size_t> {
    for (size_t k = 0; k < candidate.size(); ++k) {
      if (result.views[candidate[k]].frame == target.reference_frame) return k;
    }
    return std::nullopt;
  };
  if (!reference_of()) {
    std::string message = (fs::path(dir) / target.reference_frame).string();
    message += ": the reference frame has no detectable board (";
    for (const CalibrationViewReport& v : result.views) {
      if (v.frame == target.reference_frame) message += v.reason;
    }
    message += ")";
    throw InputError(message);
  }
  if (static_cast<int>(candidate.size()) < kMinViews) {
    throw InputError(dir + ": only " + std::to_string(candidate.size()) +
                     " views with a detectable board, need at least " + std::to_string(kMinViews));
  }

  // Intrinsics, with the simplest model the corners support: every lens model up to the richest
  // allowed, with square pixels (fx = fy) or not, is fitted and the one of least Bayesian
  // information criterion kept, BIC = n ln(RSS / n) + p ln n over the n corner coordinates, p
  // the fitted parameters (3 or 4 intrinsics, the lens terms, 6 per view). A term that only fits
  // noise lowers the RSS by ~1/n and costs ln n; a real lens or a real aspect ratio lowers it by
  // far more. Terms fitted to noise bend the model where boards were seen least (the corners
  // of the image) and a free aspect ratio tilts the floor's scale. The models are compared on at
  // most kModelViews views spread over the folder, the reference among them (cv::calibrateCamera
  // costs ~1 s at 50 views, ~10 s at 100); the joint fit below uses every view.
  size_t ref = *reference_of();
  std::vector<std::vector<cv::Point2f>> sample;
  const size_t n_sample = std::min(candidate.size(), kModelViews);
  for (size_t s = 0; s < n_sample; ++s) {
    const size_t k = s * candidate.size() / n_sample;
    sample.push_back(corners[s + 1 == n_sample && ref > k ? ref : k]);
  }
  const double n_residuals = 2.0 * static_cast<double>(sample.size()) * target.inner_corners_cols *
                             target.inner_corners_rows;
  auto bic = [&](const IntrinsicFit& f, const IntrinsicModel& model) {
    const double rss = f.rms_px * f.rms_px * 0.5 * n_residuals;
    const double p = (model.square_pixels ? 3.0 : 4.0) + lens_terms(model.lens) +
                     6.0 * static_cast<double>(sample.size());
    return n_residuals * std::log(std::max(rss, 1e-300) / n_residuals) + p * std::log(n_residuals);
  };
  IntrinsicModel model{options.max_lens_model, false};
  IntrinsicFit fit = fit_intrinsics(sample, target, image_size, model, dir);
  if (options.select_model) {
    double best = bic(fit, model);
    for (int m = 0; m <= static_cast<int>(options.max_lens_model); ++m) {
      for (bool square : {true, false}) {
        const IntrinsicModel simpler{static_cast<LensModel>(m), square};
        if (simpler.lens == options.max_lens_model && !square) continue;  // fitted above
        IntrinsicFit trial = fit_intrinsics(sample, target, image_size, simpler, dir);
        const double score = bic(trial, simpler);
        if (score < best) {
          best = score;
          model = simpler;
          fit = std::move(trial);
        }
      }
    }
  }
  result.lens_model = model.lens;
  result.square_pixels = model.square_pixels;

  // Every view's board pose with those intrinsics (cv::solvePnP, IPPE for a plane, then refined)
  // and its reprojection RMS.
  std::vector<cv::Point3d> board;
  for (int j = 0; j < target.inner_corners_rows; ++j) {
    for (int i = 0; i < target.inner_corners_cols; ++i) {
      board.emplace_back(i * target.square_size_m, j * target.square_size_m, 0.0);
    }
  }
  std::vector<Eigen::Matrix3d> R_CB;
  std::vector<Eigen::Vector3d> t_CB;
  std::vector<double> view_rms;
  for (size_t k = 0; k < candidate.size(); ++k) {
    cv::Mat rvec, tvec, R;
    std::vector<cv::Point2d> back;
    try {
      cv::solvePnP(board, corners[k], fit.K, fit.distortion, rvec, tvec, false, cv::SOLVEPNP_IPPE);
      cv::solvePnPRefineLM(board, corners[k], fit.K, fit.distortion, rvec, tvec);
      cv::projectPoints(board, rvec, tvec, fit.K, fit.distortion, back);
    } catch (const cv::Exception& e) {
      throw InputError(dir + "/" + result.views[candidate[k]].frame +
                       ": cv::solvePnP failed: " + e.err);
    }
    double sum2 = 0.0;
    for (size_t c = 0; c < back.size(); ++c) {
      const cv::Point2d d = back[c] - cv::Point2d(corners[k][c].x, corners[k][c].y);
      sum2 += d.dot(d);
    }
    view_rms.push_back(std::sqrt(sum2 / static_cast<double>(back.size())));
    cv::Rodrigues(rvec, R);
    R_CB.push_back(to_eigen3(R));
    t_CB.emplace_back(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
  }

  // Views whose reprojection error stands out are dropped (the joint fit below refines the
  // intrinsics with the rest).
  std::vector<double> sorted = view_rms;
  std::sort(sorted.begin(), sorted.end());
  const double limit = std::max(options.max_view_rms_px, 3.0 * sorted[sorted.size() / 2]);
  size_t kept = 0;
  for (size_t k = 0; k < candidate.size(); ++k) {
    if (view_rms[k] > limit && k != ref) {
      result.views[candidate[k]].reason = "reprojection RMS " + format_short(view_rms[k]) +
                                          " px, above the limit " + format_short(limit) + " px";
      continue;
    }
    if (k == ref) ref = kept;
    if (kept != k) {
      corners[kept] = std::move(corners[k]);
      candidate[kept] = candidate[k];
      R_CB[kept] = R_CB[k];
      t_CB[kept] = t_CB[k];
      view_rms[kept] = view_rms[k];
    }
    ++kept;
  }
  if (static_cast<int>(kept) < kMinViews) {
    throw InputError(dir + ": only " + std::to_string(kept) +
                     " views fit a common camera, need at least " + std::to_string(kMinViews));
  }
  corners.resize(kept);
  candidate.resize(kept);
  R_CB.resize(kept);
  t_CB.resize(kept);
  view_rms.resize(kept);
  for (size_t k : candidate) result.views[k].used = true;

  // World pose from the reference view: the board's corners where target.yaml puts them. Start
  // from the reference board's pose carried into the world, then solvePnP on world points.
  std::vector<cv::Point3d> world;
  for (int j = 0; j < target.inner_corners_rows; ++j) {
    for (int i = 0; i < target.inner_corners_cols; ++i) {
      const Eigen::Vector3d p = target.reference_corner_W(i, j);
      world.emplace_back(p.x(), p.y(), p.z());
    }
  }
  const Eigen::Matrix3d R_WB =
      Eigen::AngleAxisd(target.yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d p_WB = target.reference_corner_W(0, 0);
  const Eigen::Matrix3d R_CW_guess = R_CB[ref] * R_WB.transpose();
  const Eigen::Vector3d t_C_guess = t_CB[ref] - R_CW_guess * p_WB;
  cv::Mat rvec, tvec = (cv::Mat_<double>(3, 1) << t_C_guess.x(), t_C_guess.y(), t_C_guess.z());
  cv::Rodrigues(to_mat(R_CW_guess), rvec);
  try {
    cv::solvePnP(world, corners[ref], fit.K, fit.distortion, rvec, tvec, true,
                 cv::SOLVEPNP_ITERATIVE);
  } catch (const cv::Exception& e) {
    throw InputError(dir + ": cv::solvePnP failed on the reference frame: " + e.err);
  }

  // The calibrated camera, posed by the reference view alone for now.
  CalibratedCamera camera;
  camera.width_px = image_size.width;
  camera.height_px = image_size.height;
  camera.K = to_eigen3(fit.K);
  for (int k = 0; k < 5; ++k) camera.distortion[k] = fit.distortion.at<double>(k);
  cv::Mat R_CW_cv;
  cv::Rodrigues(rvec, R_CW_cv);
  camera.R_CW = to_eigen3(R_CW_cv);
  camera.t_C = Eigen::Vector3d(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
  camera.rms_reprojection_px = fit.rms_px;
  camera.n_views = static_cast<int>(candidate.size());
  if (!camera.K.allFinite() || !camera.R_CW.allFinite() || !camera.t_C.allFinite()) {
    throw InputError(dir + ": the calibration did not converge (non-finite pose)");
  }
  if (!(camera.centre_W().z() > target.thickness_m)) {
    throw InputError(dir + ": the reference pose puts the camera below the floor; check " +
                     (fs::path(dir) / kTargetFile).string() + " (reference origin and yaw)");
  }

  // The views for the joint fit: the reference; the other boards lying on the floor, whose plane
  // (in the camera frame, from the intrinsic fit) is the reference board's within kFloorAngle and
  // kFloorOffset, their floor poses starting from their board poses carried into the world; and
  // the boards anywhere else, from their board poses.
  const Eigen::Vector3d n_ref = R_CB[ref].col(2);
  const double d_ref = n_ref.dot(t_CB[ref]);
  std::vector<JointView> joint(candidate.size());
  for (size_t k = 0; k < candidate.size(); ++k) {
    JointView& v = joint[k];
    v.corners = &corners[k];
    v.R_CB = R_CB[k];
    v.t_CB = t_CB[k];
    const Eigen::Vector3d n = R_CB[k].col(2);
    if (k == ref) {
      v.kind = BoardKind::kReference;
      v.floor = FloorPose{target.origin_W.x(), target.origin_W.y(), target.yaw_rad};
    } else if (n.dot(n_ref) >= std::cos(kFloorAngle) &&
               std::abs(n.dot(t_CB[k]) - d_ref) <= kFloorOffset * std::abs(d_ref)) {
      const Eigen::Vector3d origin_W = camera.R_CW.transpose() * (t_CB[k] - camera.t_C);
      const Eigen::Vector3d x_W = camera.R_CW.transpose() * R_CB[k].col(0);
      v.kind = BoardKind::kFloor;
      v.floor = FloorPose{origin_W.x(), origin_W.y(), std::atan2(x_W.y(), x_W.x())};
    } else {
      v.kind = BoardKind::kFree;
    }
  }

  // The joint fit; a board taken for lying on the floor that does not fit there (held a little
  // above it, say) is let free and the fit repeated.
  auto run_joint = [&]() {
    JointFit f(target, model, camera, joint);
    f.run();
    return f;
  };
  JointFit joint_fit = run_joint();
  bool moved = false;
  for (size_t k = 0; k < candidate.size(); ++k) {
    if (joint[k].kind == BoardKind::kFloor &&
        joint_fit.view_rms_px(k) > std::max(3.0 * view_rms[k], view_rms[k] + 0.1)) {
      joint[k].kind = BoardKind::kFree;
      moved = true;
    }
  }
  if (moved) joint_fit = run_joint();
  result.camera = joint_fit.camera();
  result.camera.rms_reprojection_px = joint_fit.rms_px();
  for (size_t k = 0; k < candidate.size(); ++k) {
    result.views[candidate[k]].rms_px = joint_fit.view_rms_px(k);
    result.views[candidate[k]].on_floor = joint_fit.view(k).kind != BoardKind::kFree;
  }

  // Quality: the reference's reprojection at the final pose, and the floor error: the detected
  // corners of the boards on the floor mapped back onto the board's plane, against the corners.
  CalibratedCamera& final_camera = result.camera;
  double pose_sum2 = 0.0, floor_sum2 = 0.0;
  size_t floor_count = 0;
  for (size_t k = 0; k < candidate.size(); ++k) {
    const JointView& v = joint_fit.view(k);
    if (v.kind == BoardKind::kFree) continue;
    const std::vector<cv::Point2f>& seen = corners[k];
    for (int j = 0; j < target.inner_corners_rows; ++j) {
      for (int i = 0; i < target.inner_corners_cols; ++i) {
        const Eigen::Vector3d p_W = floor_corner_W(target, v.floor, i, j);
        const cv::Point2f& s = seen[static_cast<size_t>(j * target.inner_corners_cols + i)];
        const std::optional<Eigen::Vector2d> uv = final_camera.project(p_W);
        const std::optional<Eigen::Vector3d> back =
            final_camera.point_at_height({s.x, s.y}, target.thickness_m);
        if (!uv || !back) {
          throw InputError(dir +
                           ": the calibrated camera does not see the boards on the floor; "
                           "check " +
                           (fs::path(dir) / kTargetFile).string());
        }
        if (v.kind == BoardKind::kReference) {
          pose_sum2 += (*uv - Eigen::Vector2d(s.x, s.y)).squaredNorm();
        }
        floor_sum2 += (*back - p_W).squaredNorm();
        ++floor_count;
      }
    }
  }
  const double corners_per_view = target.inner_corners_cols * target.inner_corners_rows;
  final_camera.pose_rms_px = std::sqrt(pose_sum2 / corners_per_view);
  result.floor_rms_m = std::sqrt(floor_sum2 / static_cast<double>(floor_count));
  const Eigen::Vector2d centre(0.5 * (final_camera.width_px - 1),
                               0.5 * (final_camera.height_px - 1));
  const std::optional<Eigen::Vector3d> a = final_camera.point_at_height(centre, 0.0);
  const std::optional<Eigen::Vector3d> b =
      final_camera.point_at_height(centre + Eigen::Vector2d(1.0, 0.0), 0.0);
  result.floor_m_per_px = a && b ? (*b - *a).norm() : 0.0;
  return result;
}

}  // namespace airtwin
