#pragma once
// Air-speed samples on the floor, each taken with a known nozzle orientation: the hot-wire grids
// of Appendix A and the CFD fields of Appendix B, the input of the field fit (models/field_fit.h).
//
// File format (docs/field_fitting.md): CSV with header `pan_deg,tilt_deg,x,y,speed` for a
// measured grid, plus `vx,vy` for a CFD grid (columns in any order). Every row carries its own
// orientation, so one file may mix pans and tilts. Units: degrees, metres (world frame W, the
// floor point of the sample), m/s. `speed` is the air speed magnitude that eq. (3) models; `vx,vy`
// are the in-plane components of the CFD velocity, used only for their direction.

#include <Eigen/Core>
#include <string>
#include <string_view>
#include <vector>

#include "models/nozzle_geometry.h"

namespace airtwin {

/// Which kind of data a grid holds: measured speeds only, or CFD speeds with velocity components.
enum class GridKind { kMeasured, kSimulated };

/// One sample: air speed (and for CFD the in-plane velocity) at a floor point.
struct FieldSample {
  NozzleOrientation orientation;                  ///< rad
  Eigen::Vector2d p_W = Eigen::Vector2d::Zero();  ///< m, floor point in the world frame
  double speed_mps = 0.0;                         ///< air speed magnitude, m/s, >= 0
  Eigen::Vector2d v_W = Eigen::Vector2d::Zero();  ///< m/s, in-plane velocity (simulated grids)
  size_t line = 0;  ///< 1-based line in the source file; 0 for samples not read from a file
};

/// The samples of one file.
struct FieldGrid {
  std::string source;  ///< file name (or any label), used in every error message
  GridKind kind = GridKind::kMeasured;
  std::vector<FieldSample> samples;
};

/// Limits of a plausible sample: |x|, |y| <= kMaxCoordinateM (m), speed in [0, kMaxSpeedMps]
/// (the choked jet's exit speed is ~313 m/s), |pan| <= 360 deg, tilt in [0, 90) deg.
inline constexpr double kMaxCoordinateM = 100.0;
inline constexpr double kMaxSpeedMps = 1000.0;

/// Reads a grid file (see the format above). Throws InputError naming file, line and column for
/// an unreadable, empty, binary or header-only file, a missing, unknown or duplicated column
/// (a simulated grid must have vx and vy), a non-numeric or non-finite cell, a value outside the
/// limits above, or a duplicated sample (same pan, tilt, x, y).
FieldGrid load_field_grid(const std::string& path, GridKind kind);

/// Same as load_field_grid, from text in memory; `source` names it in messages.
FieldGrid parse_field_grid(std::string_view text, const std::string& source, GridKind kind);

/// Checks samples built in code with the same rules as the reader (limits, duplicates, a finite
/// velocity for simulated grids). Throws InputError naming grid.source and the sample's line
/// (or its index when line is 0).
void validate_field_grid(const FieldGrid& grid);

/// The CSV text of a grid, readable by parse_field_grid (deterministic, 12 significant digits).
std::string field_grid_to_csv(const FieldGrid& grid);

}  // namespace airtwin
