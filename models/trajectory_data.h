#pragma once
// Measured (or simulated) object trajectories: the trajectory CSV every data command of airtwin
// reads and writes (docs/data_formats.md).
//
// Header `traj,object,t,x,y,pan_deg,tilt_deg` plus an optional `group`: one row per camera frame
// per object; `traj` an id per object trajectory, `object` the object type (e.g. tracer, cotton),
// `t` in s, `x,y` in m in the world frame (origin below the nozzle), `pan_deg,tilt_deg` the nozzle
// command in force at that time. Rows of different trajectories may interleave (a multi-object
// log has one row per object per frame); within a trajectory, time must increase.

#include <Eigen/Core>
#include <set>
#include <string>
#include <vector>

#include "models/nozzle_geometry.h"

namespace airtwin {

struct TrajectorySample {
  double t_s = 0.0;
  Eigen::Vector2d p_W = Eigen::Vector2d::Zero();  ///< metres
  NozzleOrientation nozzle;                       ///< command in force at t (radians)
};

struct Trajectory {
  std::string id;
  std::string object;
  std::string group;  ///< empty when the file has no group column
  std::vector<TrajectorySample> samples;
};

struct TrajectorySet {
  std::vector<Trajectory> trajectories;  ///< in order of first appearance in the file
  bool has_group = false;
};

/// The object types the project knows unless told otherwise.
const std::set<std::string>& default_object_types();

/// A nozzle tilt as data are grouped by it (per-tilt figures, JSON keys): degrees rounded to
/// 1e-3, so that a command read back from CSV falls in the tilt it was written as.
double tilt_group_deg(double tilt_rad);

/// Reads and validates a trajectory CSV: header, finite numbers, tilt in [0, 90) deg, known object
/// types, one object type per trajectory, time strictly increasing within a trajectory, at least
/// one row. Every problem is an InputError naming the file, the line and the column.
TrajectorySet read_trajectory_csv(
    const std::string& path, const std::set<std::string>& known_objects = default_object_types());
/// Same, from text in memory; `source` names it in messages.
TrajectorySet parse_trajectory_csv(
    const std::string& text, const std::string& source,
    const std::set<std::string>& known_objects = default_object_types());

/// The CSV text of a set, rows grouped by trajectory (deterministic: same set, same bytes).
std::string trajectory_csv(const TrajectorySet& set);

/// Several files' sets as one, in order. With more than one set every trajectory id becomes
/// "<k>:<id>", k the set's 1-based position, so that logs written alike (each closed-loop run calls
/// its tracer t1) stay apart; one set is returned as it is. has_group if any set has groups.
TrajectorySet merge_trajectory_sets(std::vector<TrajectorySet> sets);

}  // namespace airtwin
