#pragma once
// Replaying measured trajectories with the model: each trajectory is predicted from its first
// sample under the nozzle commands it recorded, and the predicted end position is compared with
// the measured one, in percent of the distance the object travelled (section IV-B: "the MAPEs
// between the experimental and predicted end-of-trajectory positions").
//
// Start state: position and velocity at the first sample from the least-squares quadratic in
// time through the first 5 frames (0.1 s at 40 Hz): exact for uniformly accelerated motion, so an
// object released at rest starts at ~0 speed as in Appendix D, and it averages detection noise
// (1 mm of noise leaves ~1 mm and ~40 mm/s, where a one-sided difference leaves ~100 mm/s).
// Schedule: the command of the first sample, then a change at every sample whose command differs
// from the previous one. Travelled distance: the straight distance from the (fitted) start to the
// last measured position (the motion of eq. 9 is radial under a fixed orientation, so it equals
// the path length there, and it does not grow with detection noise as a summed path would).
// Trajectories with fewer than 3 samples, or that travelled less than `min_travel_m` (no
// meaningful percentage), are excluded and counted.
//
// Where the model errs, by placement: each trajectory under one command is put in a sector by its
// start's bearing from the model's s, measured from the nozzle's pan direction (0 deg: beyond s,
// away from the point below the nozzle, where an oblique jet's wall jet is strongest; 180 deg:
// between s and that point, where it is weakest). Appendix D places objects in every direction
// around s; an oblique jet's upstream air lies near the start threshold of motion, where a model
// that predicts rest and an object that slides a few cm differ by 100 %.

#include <array>
#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "models/air_field.h"
#include "models/object_dynamics.h"
#include "models/trajectory_data.h"
#include "models/trajectory_predictor.h"

namespace airtwin {

/// The placement sectors, by bearing from s against the pan direction (see the top of this file).
enum class PlacementSector { kDownstream, kSide, kUpstream };
inline constexpr size_t kPlacementSectors = 3;
struct PlacementSectorInfo {
  PlacementSector sector;
  const char* name;
  double max_bearing_deg;  ///< the sector holds bearings up to this (from the previous sector's)
};
inline constexpr std::array<PlacementSectorInfo, kPlacementSectors> kPlacementSectorCatalogue{{
    {PlacementSector::kDownstream, "downstream", 60.0},
    {PlacementSector::kSide, "side", 120.0},
    {PlacementSector::kUpstream, "upstream", 180.0},
}};
/// A start closer than this to s (m) has no bearing worth the name: it counts as 0 deg.
inline constexpr double kOnStagnationPoint_m = 1e-3;
/// The sector of a bearing in [0, 180] deg: downstream below 60, side below 120, upstream above.
PlacementSector placement_sector(double bearing_deg);

/// One sector's figures over the used trajectories under one command.
struct SectorFigures {
  size_t n = 0;                 ///< trajectories
  double mape_pct = 0.0;        ///< mean error_pct; NaN when n is 0
  size_t n_predicted_rest = 0;  ///< of them, predicted to move less than min_travel_m
};

struct ReplayOptions {
  double min_travel_m = 0.01;  ///< trajectories that moved less are excluded from the MAPE
};

struct ReplayedTrajectory {
  std::string id;
  bool used = false;              ///< false: fewer than 3 samples or moved less than min_travel_m
  bool constant_command = false;  ///< one nozzle command throughout
  double tilt_deg = 0.0;          ///< the first sample's tilt (deg, for grouping)
  Eigen::Vector2d start_W = Eigen::Vector2d::Zero();  ///< fitted start position
  Eigen::Vector2d measured_end_W = Eigen::Vector2d::Zero();
  Eigen::Vector2d predicted_end_W = Eigen::Vector2d::Zero();
  double travel_m = 0.0;
  double error_m = 0.0;
  double error_pct = 0.0;  ///< 100 error / travel
  /// The start's bearing from the model's s at the first command, from the pan direction (deg,
  /// [0, 180]; placement_sector gives its sector); 0 within kOnStagnationPoint_m of s.
  double bearing_deg = 0.0;
};

struct ReplayReport {
  std::vector<ReplayedTrajectory> trajectories;  ///< in the set's order
  size_t n_used = 0;
  size_t n_excluded = 0;
  double mape_pct = 0.0;  ///< mean of error_pct over the used trajectories; NaN when none
  /// MAPE per tilt (deg, rounded to 1e-3) over used trajectories with a constant command.
  std::map<double, double> mape_by_tilt_pct;
  /// The same per tilt and placement sector (indexed by PlacementSector).
  std::map<double, std::array<SectorFigures, kPlacementSectors>> by_tilt_sector;
};

/// Frames used for the start state.
inline constexpr size_t kStartFrames = 5;
/// Position and velocity at samples[first] from the least-squares quadratic in time through
/// samples[first .. first + kStartFrames) (fewer at the end; at least 3).
struct StartFit {
  Eigen::Vector2d p_W = Eigen::Vector2d::Zero();  ///< m
  Eigen::Vector2d v_W = Eigen::Vector2d::Zero();  ///< m/s
};
StartFit fit_start(const std::vector<TrajectorySample>& samples, size_t first = 0);
/// The start state of a trajectory of at least 3 samples (see above): fit_start's position and
/// the length of its velocity.
ObjectState start_state(const std::vector<TrajectorySample>& samples);

/// Replays every trajectory of `set` with `dynamics` in `field` using `predictor`.
/// Throws InputError when a trajectory's tilt is beyond the field model's fold, IntegrationError
/// when the predictor fails.
ReplayReport replay_trajectories(const TrajectorySet& set, const AirFieldModel& field,
                                 const ObjectDynamics& dynamics,
                                 const TrajectoryPredictor& predictor,
                                 const ReplayOptions& options = {});

}  // namespace airtwin
