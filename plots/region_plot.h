#pragma once
// The feasible manipulation region as a picture (runs/manipulation_region.h): a map of the floor
// per judge (the controller's model, the twin), at each grid point one short arrow per push
// direction, green where the push moved the object, grey where it did not, none where the nozzle
// cannot put s; the point below the nozzle marked. Free of OpenCV in its interface.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace airtwin::plots {

/// What one judge found of each push.
enum class PushVerdict : std::uint8_t { kUnreachable, kStill, kMoved };

struct RegionPanel {
  std::string title;                  ///< e.g. "model: 120 of 200 pushes move"
  std::vector<PushVerdict> verdicts;  ///< per push, in the plot's push order
};

/// A circle drawn over the maps (a task's zone).
struct RegionCircle {
  Eigen::Vector2d centre_W = Eigen::Vector2d::Zero();
  double radius_m = 0.0;
};

struct RegionPlot {
  double extent_m = 0.8;                  ///< the map covers [-extent, extent]^2 plus half a step
  double step_m = 0.1;                    ///< grid spacing: arrows are scaled to it
  std::vector<Eigen::Vector2d> points_W;  ///< per push: the object's position (m)
  std::vector<Eigen::Vector2d> directions_W;  ///< per push: the push's direction (unit)
  std::vector<RegionPanel> panels;            ///< 1 or 2, side by side
  std::vector<std::string> caption;           ///< lines under the maps
  /// Drawn over every map in blue, for a scenario's task: its path (a polyline), its zones and
  /// its objects' start positions (dots).
  std::vector<Eigen::Vector2d> path_W;
  std::vector<RegionCircle> zones;
  std::vector<Eigen::Vector2d> objects_W;
};

/// Writes the picture (PNG, 620 px wide per panel, 720 px high; in panel k the map spans columns
/// 620 k + 80 .. 620 k + 579 and rows 60 .. 559 for [-extent - step / 2, extent + step / 2] on both
/// axes, y up). The same input gives the same bytes. Throws InputError naming the culprit when
/// sizes disagree, there is no or more than two panels, a value is not finite (a zone's radius not
/// > 0), or the file cannot be written.
void write_region_png(const RegionPlot& plot, const std::string& path);

}  // namespace airtwin::plots
