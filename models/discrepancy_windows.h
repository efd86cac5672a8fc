#pragma once
// The discrepancy analysis's data (models/discrepancy.h, step 1): each trajectory cut into windows
// of at most window_s, each window predicted from its first observed state under the recorded
// command history, its residual samples and its error scale. Internal to the analysis.

#include <Eigen/Core>
#include <cstddef>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "models/discrepancy.h"
#include "models/extended_predictor.h"
#include "models/nozzle_response.h"
#include "models/object_dynamics.h"
#include "models/trajectory_data.h"

namespace airtwin::discrepancy_detail {

constexpr double kMinScale_m = 0.05;  // a window's error scale is at least 5 cm
// Two models whose RMS path errors on a window differ by less than this (m) fit it equally well:
// below half a camera pixel on the floor (2.64 mm/px, docs/vision.md).
constexpr double kResolvedDifference_m = 0.001;

struct Window {
  size_t trajectory = 0;
  const ObjectDynamics* xi = nullptr;
  const std::string* type = nullptr;  // the object's type (the coefficients' key)
  const NozzleTimeline* timeline = nullptr;
  WindowStart start;
  std::vector<double> times;              // residual samples (absolute s)
  std::vector<Eigen::Vector2d> measured;  // positions there
  std::vector<double> since_change_s;     // since the command last changed
  double path_m = 0.0;                    // measured path length
  double scale_m = kMinScale_m;
  bool train = true;
  bool command_changes = false;  // the nominal field orientation changes inside the window
};

struct WindowSet {
  std::vector<std::unique_ptr<NozzleTimeline>> timelines;
  std::vector<Window> windows;
  size_t n_short = 0;  // windows (or trajectories) too short to use
  std::set<double> tilts_deg;
};

// The windows of `set` under `o`; InputError naming the trajectory whose object type has no
// coefficients in `objects`.
WindowSet make_windows(const TrajectorySet& set,
                       const std::map<std::string, ObjectDynamics>& objects,
                       const DiscrepancyOptions& o);

}  // namespace airtwin::discrepancy_detail
