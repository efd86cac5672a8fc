#pragma once
// The feasible manipulation region (Kopitca et al., section V-C after their [11]: the part of the
// floor "where motion control in any direction over the surface is possible"), measured the way
// the paper's line search pushes: an object at rest at p should go in direction d, so s is put a
// distance D behind it (s = p - D d; D the search's start mu0, 41.8 cm in the paper) and the
// nozzle holds that orientation for Delta T. The push moved the object when it went at least
// min_travel along d. Two judges:
//   - the model the controller plans with: its prediction of the push (CemPlanner::cost, the same
//     code and model files as a closed-loop decision), the nozzle already at the orientation;
//   - the twin: the object released at rest into that orientation's steady air (the placed
//     protocol of sim/collection.h), recorded for Delta T.
// A point is in the region when the pushes in every direction are reachable and move the object.
// Where the judges disagree the controller is blind (the twin moves the object, the model says it
// stays) or deluded (the reverse); whether a push runs away from the point below the nozzle,
// across or toward it says whether the object lies downstream of s or upstream, where the wall
// jet is weakest.
//
// Determinism: a push's twin trial is seeded by the options' seed and the push's index only, so
// the result does not depend on the thread count.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "controller/cem_planner.h"
#include "models/air_field.h"
#include "models/nozzle_geometry.h"
#include "models/object_dynamics.h"
#include "models/trajectory_data.h"
#include "runs/scenario_run.h"
#include "sim/twin.h"

namespace airtwin {

/// The most pushes one region may have (memory and time: a twin trial takes ~10 ms).
inline constexpr int kMaxRegionPushes = 1000000;

struct RegionOptions {
  std::string object = "tracer";  ///< "tracer" | "cotton"
  double extent_m = 0.8;          ///< the grid covers [-extent, extent]^2 around the origin
  double step_m = 0.1;            ///< grid spacing
  int directions = 8;             ///< push directions per point, evenly spaced from +x
  double distance_m = 0.418;      ///< D: s this far behind the object (the paper's mu0)
  double horizon_s = 1.5;         ///< Delta T: how long the push is held (section V-A)
  double min_travel_m = 0.01;     ///< moved: at least this far along the direction
  double settle_s = 0.5;          ///< twin: the object rests this long, jet off, before release
  std::uint64_t seed = 1;         ///< twin: each trial's turbulence and shape
  int threads = 0;                ///< twin trials in parallel (0: one per core)
  /// Throws FieldError naming the field ("region.step_m") when a value is out of range.
  void validate() const;
};

/// Where a push sends the object relative to the point below the nozzle (the origin): the angle
/// between d and the outward radial at p within 45 deg (away: the object lies downstream of s),
/// beyond 135 deg (toward: upstream of s), or between (across). At the origin itself: across.
enum class PushClass { kAway, kAcross, kToward };
inline constexpr int kPushClassCount = 3;

struct PushClassInfo {
  PushClass id;
  const char* name;  ///< as written in region.json
};
/// The catalogue, indexed by PushClass.
inline constexpr std::array<PushClassInfo, kPushClassCount> kPushClasses = {{
    {PushClass::kAway, "away"},
    {PushClass::kAcross, "across"},
    {PushClass::kToward, "toward"},
}};

/// The class of a push in direction d_W (unit) of an object at p_W.
PushClass classify_push(const Eigen::Vector2d& p_W, const Eigen::Vector2d& d_W);

struct RegionPush {
  int index = 0;                                           ///< in plan order
  Eigen::Vector2d p_W = Eigen::Vector2d::Zero();           ///< the object at rest (m)
  Eigen::Vector2d direction_W = Eigen::Vector2d::UnitX();  ///< d, unit
  Eigen::Vector2d s_W = Eigen::Vector2d::Zero();           ///< p - D d (m)
  PushClass push_class = PushClass::kAcross;
  /// The orientation that puts s there (eqs. 1-2 inverted); unset when the nozzle cannot.
  std::optional<NozzleOrientation> orientation;
  std::optional<Eigen::Vector2d> model_end_W;  ///< the model's predicted end (m)
  std::optional<Eigen::Vector2d> twin_end_W;   ///< where the twin's object was after Delta T (m)
  bool reachable() const { return orientation.has_value(); }
};

/// The object's travel along the push's direction to `end_W` (m; negative: backwards).
double travel_along(const RegionPush& push, const Eigen::Vector2d& end_W);

/// The pushes: for each grid point (x fastest, from -extent), each direction k at angle
/// 2 pi k / directions; s aimed with `geometry` (the controller's eqs. 1-2 and tilt range).
std::vector<RegionPush> plan_region(const RegionOptions& options, const NozzleGeometry& geometry);

/// Sets model_end_W of every reachable push: `planner`'s prediction for one object of dynamics
/// `xi` and type `type` (which picks its own effects when the planner's model has them per type)
/// at rest at p, the nozzle at the push's orientation for the planner's horizon.
void predict_region(std::vector<RegionPush>* pushes, const CemPlanner& planner,
                    const ObjectDynamics& xi, const std::string& type);

/// The pushes planned and judged by the model a closed-loop run with `run` plans with: its planning
/// field (an extended model's scaled one, else `field`) places s, and its dynamics for the object
/// type, with the extended model's extensions if any, predict over options.horizon_s. Throws
/// InputError when `run` has no dynamics for options.object.
std::vector<RegionPush> model_region(const RegionOptions& options, const AirFieldModel& field,
                                     const ScenarioRunOptions& run);

/// Sets twin_end_W of every reachable push: a twin with `params` (the object placed at p, the
/// nozzle at the orientation, jet off for settle_s, then its steady air for horizon_s).
/// `progress(done, total)` (optional) after each trial, from one thread at a time. With
/// `trajectories`, also every trial's record at 40 Hz from the release, in push order (id = the
/// push's index): data of the pushes the controller makes, for `identify` and `discrepancy`.
/// Throws SimulationError when a twin fails.
void run_region_in_twin(std::vector<RegionPush>* pushes, const RegionOptions& options,
                        const TwinParameters& params, const AirFieldModel& field,
                        const std::function<void(int, int)>& progress = {},
                        TrajectorySet* trajectories = nullptr);

struct RegionTally {
  int moved = 0;
  int of = 0;  ///< reachable pushes judged
};

/// One judge's verdicts.
struct RegionJudgement {
  RegionTally all;
  std::array<RegionTally, kPushClassCount> by_class;  ///< indexed by PushClass
  /// Grid points whose every direction is reachable and moves the object: the region.
  int region_points = 0;
};

struct RegionSummary {
  int points = 0;
  int pushes = 0;
  int reachable = 0;
  std::optional<RegionJudgement> model;  ///< set when some push has a model end
  std::optional<RegionJudgement> twin;   ///< set when some push has a twin end
  /// Pushes judged by both: moved by both, by the model only (deluded), by the twin only
  /// (blind), by neither.
  int both = 0, model_only = 0, twin_only = 0, neither = 0;
};

RegionSummary summarize_region(const std::vector<RegionPush>& pushes, const RegionOptions& options);

/// region.csv: a row per push, `x,y,direction_deg,class,s_x,s_y,pan_deg,tilt_deg,reachable,
/// model_end_x,model_end_y,model_along_m,twin_end_x,twin_end_y,twin_along_m` (empty cells where
/// a judge has no end). docs/data_formats.md.
std::string region_csv(const std::vector<RegionPush>& pushes);

/// region.json: the options and the summary. docs/data_formats.md.
std::string region_json(const RegionSummary& summary, const RegionOptions& options);

/// region.png: a map of the floor per judge that saw the pushes (plots/region_plot.h), with
/// `scenario`'s task over it when given (its path, zones and objects' start positions). Throws
/// InputError when the file cannot be written.
void write_region_png(const std::vector<RegionPush>& pushes, const RegionSummary& summary,
                      const RegionOptions& options, const std::string& path,
                      const Scenario* scenario = nullptr);

}  // namespace airtwin
