#include "renders/calibration_target.h"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <sstream>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "common/errors.h"
#include "common/random_stream.h"
#include "common/text.h"
#include "common/units.h"
#include "renders/camera_model.h"
#include "renders/frame_renderer.h"
#include "renders/png.h"
#include "sim/mujoco_runtime.h"
#include "sim/scene_builder.h"

namespace airtwin {
namespace {

// The board (see the header): inner corners, square size, white margin beyond the outer squares,
// total thickness, and the height of the black squares above the white (their tops are the
// printed surface, z = 0 of the board frame).
constexpr int kCols = 10;
constexpr int kRows = 7;
constexpr double kSquare = 0.08;
constexpr double kMargin = 0.04;
constexpr double kThickness = 0.003;
constexpr double kInkHeight = 0.0003;

// Poses: propped views lean 15-35 deg; every other view (the reference first) lies flat.
constexpr double kMinLean = deg_to_rad(15.0);
constexpr double kMaxLean = deg_to_rad(35.0);
// Board centres between these fractions of the camera's half view from the image centre (up to
// the picture's corners, where the lens model needs corners as much as anywhere).
constexpr double kMinReach = 0.25;
constexpr double kMaxReach = 1.4;
// Every corner of the board at least this far inside the image (px), and the board this far
// (m, at the rig's height) from the nozzle rig's axis: the servos, brackets and hose hang there.
constexpr double kImageMarginPx = 8.0;
constexpr double kRigClearance = 0.08;
constexpr double kRigTop = 0.12;  // hose end above the nozzle exit (m), sim/scene_builder.cc
constexpr int kMaxAttempts = 500;
// Multisampled frames: the edges of the squares are area-averaged as a camera's pixels do
// (llvmpipe gives 4 samples at most; asking 8 or 16 renders the same bytes).
constexpr int kMultisamples = 4;

constexpr const char* kTargetFile = "target.yaml";

std::string frame_name(int view) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "view_%02d.png", view);
  return buffer;
}

// A rigid pose of the board frame B in the world: p_W = R_WB p_B + p_WB.
struct BoardPose {
  Eigen::Matrix3d R_WB = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_WB = Eigen::Vector3d::Zero();
};

// The board's outer box in B: x, y extents of the white board, z from the floor side to the ink.
constexpr double kMinX = -kSquare - kMargin, kMaxX = kCols * kSquare + kMargin;
constexpr double kMinY = -kSquare - kMargin, kMaxY = kRows * kSquare + kMargin;

std::vector<Eigen::Vector3d> box_corners_B() {
  std::vector<Eigen::Vector3d> corners;
  for (double x : {kMinX, kMaxX}) {
    for (double y : {kMinY, kMaxY}) {
      for (double z : {-kThickness, 0.0}) corners.emplace_back(x, y, z);
    }
  }
  return corners;
}

// The MJCF of the target: materials for the assets and a mocap body (at B) for the world body.
std::string target_assets() {
  return "  <material name=\"calib_white\" rgba=\"0.93 0.93 0.93 1\" specular=\"0\""
         " shininess=\"0\" reflectance=\"0\"/>\n"
         "  <material name=\"calib_black\" rgba=\"0.04 0.04 0.04 1\" specular=\"0\""
         " shininess=\"0\" reflectance=\"0\"/>\n";
}

std::string target_body() {
  std::ostringstream s;
  s << "  <body name=\"calibration_target\" mocap=\"true\" pos=\"0 0 -1\">\n";
  // Its geoms are massless visuals; MuJoCo still wants a body with mass (a 2 kg board).
  s << "    <inertial pos=\"0 0 0\" mass=\"2\" diaginertia=\"0.1 0.1 0.1\"/>\n";
  // The white board: from the floor side up to just below the ink.
  s << "    <geom name=\"calib_board\" class=\"visual\" type=\"box\" material=\"calib_white\" "
       "pos=\""
    << format_number(0.5 * (kMinX + kMaxX)) << ' ' << format_number(0.5 * (kMinY + kMaxY)) << ' '
    << format_number(-0.5 * (kThickness + kInkHeight)) << "\" size=\""
    << format_number(0.5 * (kMaxX - kMinX)) << ' ' << format_number(0.5 * (kMaxY - kMinY)) << ' '
    << format_number(0.5 * (kThickness - kInkHeight)) << "\"/>\n";
  // The black squares: square (a, b), a in [-1, cols), b in [-1, rows), spans [a, a + 1] x
  // [b, b + 1] squares from the origin corner; black when a + b is even (so the corner squares
  // at the origin's end are black, those at the far end white); their tops, the printed surface,
  // stand kInkHeight above the white.
  for (int a = -1; a < kCols; ++a) {
    for (int b = -1; b < kRows; ++b) {
      if ((a + b) % 2 != 0) continue;
      s << "    <geom class=\"visual\" type=\"box\" material=\"calib_black\" pos=\""
        << format_number((a + 0.5) * kSquare) << ' ' << format_number((b + 0.5) * kSquare) << ' '
        << format_number(-kInkHeight) << "\" size=\"" << format_number(0.5 * kSquare) << ' '
        << format_number(0.5 * kSquare) << ' ' << format_number(kInkHeight) << "\"/>\n";
    }
  }
  s << "  </body>\n";
  return s.str();
}

// The twin's scene (no objects) with the target inserted before </asset> and </worldbody>.
std::string scene_with_target(const SceneParameters& params, uint64_t seed) {
  SceneSpec empty;
  empty.source = "calibration target scene";
  std::string xml = scene_xml(empty, params, seed);
  const size_t assets_end = xml.rfind("</asset>");
  AIRTWIN_DEMAND(assets_end != std::string::npos);
  xml.insert(assets_end, target_assets());
  const size_t world_end = xml.rfind("</worldbody>");
  AIRTWIN_DEMAND(world_end != std::string::npos);
  xml.insert(world_end, target_body());
  return xml;
}

// Whether the board at `pose` is whole in the image and clear of the rig. The rig's outline is a
// disc around the projection of the nozzle, of kRigClearance at the height of the hose's end.
bool board_fits(const BoardPose& pose, const GroundTruthCamera& camera,
                const SceneParameters& params) {
  std::vector<cv::Point2f> hull_in;
  for (const Eigen::Vector3d& c_B : box_corners_B()) {
    const std::optional<Eigen::Vector2d> uv = camera.project(pose.R_WB * c_B + pose.p_WB);
    if (!uv) return false;
    if (uv->x() < kImageMarginPx || uv->y() < kImageMarginPx ||
        uv->x() > camera.width_px() - 1 - kImageMarginPx ||
        uv->y() > camera.height_px() - 1 - kImageMarginPx) {
      return false;
    }
    hull_in.emplace_back(static_cast<float>(uv->x()), static_cast<float>(uv->y()));
  }
  const std::optional<Eigen::Vector2d> rig_uv = camera.project({0.0, 0.0, params.nozzle_height_m});
  if (!rig_uv) return true;  // the rig is out of the picture
  const double rig_depth = camera.p_WC().z() - (params.nozzle_height_m + kRigTop);
  const double clearance_px =
      rig_depth > 0 ? camera.focal_px() * kRigClearance / rig_depth : camera.width_px();
  std::vector<cv::Point2f> hull;
  cv::convexHull(hull_in, hull);
  // pointPolygonTest: signed distance, positive inside the outline.
  const double inside = cv::pointPolygonTest(
      hull, cv::Point2f(static_cast<float>(rig_uv->x()), static_cast<float>(rig_uv->y())), true);
  return inside < -clearance_px;
}

// How one view is posed: flat, or propped about an edge running at `axis_rad` from the world's x
// axis. The propped views' axes are spread over half a turn: a board leaning about one direction
// shows the focal length along the other image axis best.
struct ViewPlan {
  bool lean = false;
  double axis_rad = 0.0;
};

// Draws the pose of view `view` of `views`: the board's centre in the view's sector of directions
// around the origin (so that the views together cover the picture), flat on the floor at any yaw
// or propped on one of its four bottom edges, that edge along the plan's axis (+- half the spacing
// of the axes). Retries until the board fits.
BoardPose draw_pose(int view, int views, const ViewPlan& plan, double axis_spread_rad,
                    uint64_t seed, const GroundTruthCamera& camera, const SceneParameters& params) {
  RandomStream rng(seed, RandomPurpose::kScenario, static_cast<uint64_t>(view));
  const Eigen::Vector3d centre_B(0.5 * (kMinX + kMaxX), 0.5 * (kMinY + kMaxY), 0.0);
  for (int attempt = 0; attempt < kMaxAttempts; ++attempt) {
    // Where the board goes, which edge it may lean on, how far, and its yaw: free when flat, else
    // such that the edge runs along the plan's axis (edges 0, 1 are along the board's y axis,
    // 2, 3 along its x axis), either way round.
    const double direction = 2.0 * kPi * (view + rng.uniform()) / views;
    const double reach = params.camera_half_view_m * rng.uniform(kMinReach, kMaxReach);
    const int edge = static_cast<int>(rng.uniform(0.0, 4.0));
    const double lean_angle = rng.uniform(kMinLean, kMaxLean);
    const double flip = rng.uniform() < 0.5 ? 0.0 : kPi;
    const double axis = plan.axis_rad + axis_spread_rad * (rng.uniform() - 0.5);
    const double yaw =
        plan.lean ? axis - (edge < 2 ? 0.5 * kPi : 0.0) + flip : rng.uniform(-kPi, kPi);
    // Flat: yaw about z, the board's printed surface kThickness above the floor.
    BoardPose pose;
    pose.R_WB = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Vector3d centre_W(reach * std::cos(direction), reach * std::sin(direction),
                                   kThickness);
    pose.p_WB = centre_W - pose.R_WB * centre_B;
    if (plan.lean) {
      // Propped: turn the flat board about one of its bottom edges (which stays on the floor),
      // the way that lifts the board's centre.
      const Eigen::Vector3d edge_point_B(edge == 1 ? kMaxX : kMinX, edge == 3 ? kMaxY : kMinY,
                                         -kThickness);
      const Eigen::Vector3d edge_axis_B =
          edge < 2 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitX();
      const Eigen::Vector3d q_W = pose.R_WB * edge_point_B + pose.p_WB;
      const Eigen::Vector3d axis_W = pose.R_WB * edge_axis_B;
      Eigen::Matrix3d turn = Eigen::AngleAxisd(lean_angle, axis_W).toRotationMatrix();
      if ((turn * (centre_W - q_W)).z() < 0) {
        turn = Eigen::AngleAxisd(-lean_angle, axis_W).toRotationMatrix();
      }
      pose.R_WB = turn * pose.R_WB;
      pose.p_WB = q_W + turn * (pose.p_WB - q_W);
    }
    if (board_fits(pose, camera, params)) return pose;
  }
  std::string message = "calibration target: cannot place the board (";
  message += format_number(kMaxX - kMinX);
  message += " m x ";
  message += format_number(kMaxY - kMinY);
  message += " m) whole in the camera's view, clear of the nozzle rig, for view ";
  message += std::to_string(view);
  message += " (camera_half_view_m = ";
  message += format_number(params.camera_half_view_m);
  message += ")";
  throw InputError(message);
}

void validate(const CalibrationDatasetOptions& o) {
  if (o.views < 3 || o.views > 100) {
    throw InputError("calibration dataset: views must be in [3, 100], got " +
                     std::to_string(o.views));
  }
  if (!(std::isfinite(o.noise_sigma_grey) && o.noise_sigma_grey >= 0)) {
    throw InputError("calibration dataset: noise_sigma_grey must be finite and >= 0, got " +
                     format_number(o.noise_sigma_grey));
  }
  if (!(std::isfinite(o.blur_sigma_px) && o.blur_sigma_px >= 0)) {
    throw InputError("calibration dataset: blur_sigma_px must be finite and >= 0, got " +
                     format_number(o.blur_sigma_px));
  }
}

// target.yaml: the board and the reference view's measured pose (docs/data_formats.md).
void write_target_file(const std::string& path, const BoardPose& reference) {
  const Eigen::Vector3d x_axis_W = reference.R_WB.col(0);
  cv::FileStorage fs;
  bool opened = false;
  try {
    opened = fs.open(path, cv::FileStorage::WRITE | cv::FileStorage::FORMAT_YAML);
  } catch (const cv::Exception&) {
    opened = false;
  }
  if (!opened) throw InputError(path + ": cannot open for writing");
  fs.writeComment(
      "airtwin calibration target (docs/camera_calibration.md). Board: inner corners cols x rows, "
      "square size and thickness in m. Reference: the frame in which the board lies flat on the "
      "floor, its origin corner at (origin_x_m, origin_y_m) and its x axis at yaw_deg from the "
      "world's x axis.");
  fs << "board"
     << "{";
  fs << "inner_corners_cols" << kCols << "inner_corners_rows" << kRows;
  fs << "square_size_m" << kSquare << "thickness_m" << kThickness;
  fs << "}";
  fs << "reference"
     << "{";
  fs << "frame" << frame_name(0);
  fs << "origin_x_m" << reference.p_WB.x() << "origin_y_m" << reference.p_WB.y();
  fs << "yaw_deg" << rad_to_deg(std::atan2(x_axis_W.y(), x_axis_W.x()));
  fs << "}";
  fs.release();
}

}  // namespace

int write_calibration_dataset(const std::string& dir, const SceneParameters& params,
                              const CalibrationDatasetOptions& options) {
  validate(options);
  // The twin's scene with the board, and the camera that sees it.
  const std::string xml = scene_with_target(params, options.seed);
  const ModelPtr model = load_model_from_xml(xml, "calibration target scene");
  const mjModel* m = model.get();
  const DataPtr data = make_data(m);
  const GroundTruthCamera camera = GroundTruthCamera::from_model(m, "top");
  const int body = mj_name2id(m, mjOBJ_BODY, "calibration_target");
  AIRTWIN_DEMAND(body > 0 && m->body_mocapid[body] >= 0);
  const int mocap = m->body_mocapid[body];

  // Every pose first: a board that cannot be placed fails before any file is written.
  // The plan: the reference and every other view flat (boards on the floor all over the picture
  // pin the floor's image), the others propped with their axes spread evenly over half a turn.
  std::vector<ViewPlan> plans(static_cast<size_t>(options.views));
  int n_lean = 0;
  for (int view = 0; view < options.views; ++view) n_lean += view % 2 != 0;
  for (int view = 0, lean = 0; view < options.views; ++view) {
    if (view % 2 == 0) continue;
    plans[static_cast<size_t>(view)] = ViewPlan{true, kPi * (lean + 0.5) / n_lean};
    ++lean;
  }
  std::vector<BoardPose> poses;
  for (int view = 0; view < options.views; ++view) {
    poses.push_back(draw_pose(view, options.views, plans[static_cast<size_t>(view)], kPi / n_lean,
                              options.seed, camera, params));
  }

  // The folder, then one frame per pose.
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error || !std::filesystem::is_directory(dir)) {
    throw InputError(dir + ": cannot create the calibration folder");
  }
  RenderOptions render_options;
  render_options.multisamples = kMultisamples;
  render_options.noise_sigma_grey = options.noise_sigma_grey;
  render_options.blur_sigma_px = options.blur_sigma_px;
  render_options.seed = options.seed;
  FrameRenderer renderer(m, render_options, "top");
  mjData* d = data.get();
  for (int view = 0; view < options.views; ++view) {
    // The board's pose as the mocap body's, then the kinematics the renderer reads.
    const BoardPose& pose = poses[static_cast<size_t>(view)];
    const Eigen::Quaterniond q(pose.R_WB);
    for (int k = 0; k < 3; ++k) d->mocap_pos[3 * mocap + k] = pose.p_WB[k];
    d->mocap_quat[4 * mocap + 0] = q.w();
    d->mocap_quat[4 * mocap + 1] = q.x();
    d->mocap_quat[4 * mocap + 2] = q.y();
    d->mocap_quat[4 * mocap + 3] = q.z();
    mj_forward(m, d);
    const cv::Mat frame = renderer.render(d, view);
    write_png((std::filesystem::path(dir) / frame_name(view)).string(), frame);
  }
  write_target_file((std::filesystem::path(dir) / kTargetFile).string(), poses.front());
  return options.views;
}

}  // namespace airtwin
