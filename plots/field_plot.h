#pragma once
// Pictures for people (not for the detector): the air field as a colour map of speed with arrows,
// the stagnation point s and the projection point c marked, in the manner of the paper's Fig. 3.

#include <Eigen/Core>
#include <string>

namespace airtwin::plots {

/// A field sampled on a rectilinear grid: x (nx, ascending, m), y (ny, ascending, m) and per-node
/// values stored row = y index, column = x index (ny x nx), in m/s.
struct VectorFieldGrid {
  Eigen::VectorXd x;
  Eigen::VectorXd y;
  Eigen::MatrixXd vx;
  Eigen::MatrixXd vy;
  Eigen::MatrixXd speed;
};

/// What to mark on the picture.
struct FieldMarks {
  Eigen::Vector2d stagnation_W = Eigen::Vector2d::Zero();  ///< s, metres
  Eigen::Vector2d projection_W = Eigen::Vector2d::Zero();  ///< c, metres
  std::string title;                                       ///< e.g. "pan 90 deg, tilt 22.5 deg"
  /// Top of the colour bar in m/s, to put several pictures on one scale; 0 (the default): the
  /// largest speed on the grid. Faster nodes get the top colour.
  double speed_max_mps = 0.0;
};

/// Size of every picture write_field_png writes.
inline constexpr int kFieldPngWidth_px = 1000;
inline constexpr int kFieldPngHeight_px = 900;

/// Where the map sits in the picture: image columns left_px .. left_px + width_px - 1 and rows
/// top_px .. top_px + height_px - 1.
struct FieldPlotArea {
  int left_px = 0;
  int top_px = 0;
  int width_px = 0;
  int height_px = 0;
};

/// Writes a kFieldPngWidth_px x kFieldPngHeight_px PNG to `path` (always PNG, whatever the
/// extension; the directory must exist): the speed as a viridis colour map, bilinearly
/// interpolated between nodes, from min(0, lowest speed) to the highest speed (or
/// marks.speed_max_mps) with a labelled colour bar in m/s; arrows along the local air direction
/// (vx, vy) on a subsampled grid (about 18 per side), length proportional to speed, none shorter
/// than 5 px (below about 1/7 of the fastest arrow's speed); axes in metres (x right, y up); s (red
/// disc) and c (magenta cross) marked and labelled, or, when outside the grid, shown by a pointer
/// at the edge of the map towards them; their coordinates in a legend. The same input gives the
/// same bytes. Throws InputError naming the culprit when the grid is malformed (sizes disagree,
/// fewer than 2 nodes per axis, coordinates not strictly ascending, a value not finite), a mark is
/// not finite, marks.speed_max_mps is negative, or the file cannot be written.
void write_field_png(const VectorFieldGrid& grid, const FieldMarks& marks, const std::string& path);

/// Where write_field_png draws the map of `grid` (only grid.x and grid.y are used): x.front() at
/// column left_px, x.back() at column left_px + width_px - 1, y.back() at row top_px and y.front()
/// at row top_px + height_px - 1, linear in between (pixel centres at integer coordinates). The
/// same metres per pixel on both axes unless one side of the grid is more than 4 times the other.
/// Throws InputError when x or y is malformed, as write_field_png does.
FieldPlotArea field_plot_area(const VectorFieldGrid& grid);

}  // namespace airtwin::plots
