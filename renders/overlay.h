#pragma once
// Overlays on camera frames, for people watching a run (videos, figures like the paper's Figs. 6
// and 7): the reference path or zones, the current reference points r_j, the stagnation point s,
// the nozzle's heading, the objects' trails and a time label. Never for the detector: overlays
// are drawn on a copy meant for eyes, never on the frames vision reads.
//
// Everything comes in as plain data in metres (world frame, on the floor) and is projected
// through the ground-truth camera (renders/camera_model.h): the renderer's side of the pipeline
// may know the true camera. The closed-loop runner fills an OverlayData per frame from its task
// and decisions; nothing here depends on the controller.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "renders/camera_model.h"

namespace airtwin {

/// A circular zone on the floor (m, world frame), e.g. a task's reference zone.
struct OverlayZone {
  Eigen::Vector2d centre_W = Eigen::Vector2d::Zero();
  double radius_m = 0.0;
  std::string label;  ///< drawn beside the zone ("tracer", "cotton"); may be empty
};

/// What to draw on one frame; every member is optional (empty: not drawn).
struct OverlayData {
  /// The reference path, a polyline on the floor (m).
  std::vector<Eigen::Vector2d> path_W;
  /// All reference points along the path (small dots, m).
  std::vector<Eigen::Vector2d> path_references_W;
  std::vector<OverlayZone> zones;
  /// The current reference point(s) r_j of eq. (10) (m).
  std::vector<Eigen::Vector2d> current_references_W;
  /// The stagnation point s the nozzle is aimed at now (m).
  std::optional<Eigen::Vector2d> stagnation_W;
  /// The nozzle's pan (rad): an arrow from the floor point below the nozzle toward the pan
  /// direction (the direction the jet is tilted to, eq. 1).
  std::optional<double> nozzle_pan_rad;
  /// The floor point below the nozzle (m): the origin of the twin's world.
  Eigen::Vector2d nozzle_base_W = Eigen::Vector2d::Zero();
  /// Per object, its past positions, oldest first (m).
  std::vector<std::vector<Eigen::Vector2d>> trails_W;
  /// Simulated time (s) shown as "t = 12.35 s" in the top-left corner.
  std::optional<double> time_s;
  /// A second line under the time (scenario name, decision count...).
  std::string caption;
};

/// Colours (BGR) and sizes of the overlay.
struct OverlayStyle {
  cv::Scalar path_bgr{80, 220, 80};
  cv::Scalar reference_dot_bgr{80, 220, 80};
  cv::Scalar zone_bgr{0, 215, 255};
  double zone_fill_alpha = 0.18;  ///< the zone's inside is tinted this much toward zone_bgr
  cv::Scalar current_reference_bgr{255, 0, 255};
  cv::Scalar stagnation_bgr{0, 0, 255};
  cv::Scalar heading_bgr{0, 140, 255};
  double heading_length_m = 0.25;  ///< arrow length on the floor (m)
  cv::Scalar text_bgr{255, 255, 255};
  int line_thickness_px = 2;
  /// Trail colours, cycled over the objects.
  std::vector<cv::Scalar> trail_bgr{{255, 160, 60},  {60, 200, 255},  {200, 120, 255},
                                    {120, 255, 180}, {255, 255, 120}, {140, 140, 255}};
};

/// Draws `data` onto `bgr` (CV_8UC3, the camera's image size) in place, projecting with `camera`.
/// Points the camera cannot see are skipped; shapes are clipped at the image border. Throws
/// InputError when the image is not 8-bit BGR of the camera's size or a value is not finite.
void draw_overlay(cv::Mat& bgr, const GroundTruthCamera& camera, const OverlayData& data,
                  const OverlayStyle& style = {});

/// Past positions of each object for OverlayData::trails_W: push() the current positions once per
/// frame; each trail keeps its last `max_points` positions.
class TrailHistory {
 public:
  explicit TrailHistory(size_t max_points = 400) : max_points_(max_points) {}
  /// Appends one position per object (m); the object count must stay the same between calls
  /// (it is fixed by the first call).
  void push(const std::vector<Eigen::Vector2d>& p_W);
  const std::vector<std::vector<Eigen::Vector2d>>& trails() const { return trails_; }

 private:
  size_t max_points_;
  std::vector<std::vector<Eigen::Vector2d>> trails_;
};

}  // namespace airtwin
