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
};

/// Writes a PNG: speed colour map with a labelled colour bar (m/s), arrows along the local air
/// direction, axes in metres, s and c marked and labelled. Throws InputError when the grid is
/// malformed (sizes disagree, fewer than 2 nodes per axis) or the file cannot be written.
void write_field_png(const VectorFieldGrid& grid, const FieldMarks& marks, const std::string& path);

}  // namespace airtwin::plots
