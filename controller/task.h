#pragma once
// The manipulation tasks of section V: what the objects should do, and the bookkeeping that turns
// observed positions into the reference point r_j of each object in the cost of eq. (10).
//
//  - path (sections V-B and V-C): the reference path is a polyline. One object: the path is split
//    into points reference_spacing_m apart (10 cm) and the reference moves on when the object is
//    within switch_distance_m (4 cm). Several objects (the octagon): the path's vertices are the
//    references, shared by all objects, and the reference moves on when the objects' mean distance
//    to it is below switch_distance_m (6.3 cm). Done when the last reference is reached.
//  - aggregation: every object's reference is the zone's centre; done when all are in the zone.
//  - sorting: each object's reference is the centre of the zone of its type; done when every
//    object is in its zone. Optionally in stages (not in the paper): one type after the other,
//    the objects that need the strongest air first. While a type's objects are not all in their
//    zone, the types after it are deferred: their terms of eq. (10) weigh deferred_weight and
//    they should stay within reach_m of the point below the nozzle (controller/cem_planner.h).
//    Why: a push strong enough to move tracers (2.0 m/s of air to start, eq. 8) moves cotton
//    (1.19 m/s) out to about a metre from s, so tracers cannot be moved without moving the cotton
//    already placed; cotton can be moved with s far enough from the tracers' zone that their air
//    stays below 2.0 m/s. docs/controller.md has the measurements.
//
// A task is never done while the perception reports objects out of its view
// (Observation::out_of_view): the ones still seen being in their zones says nothing of one blown
// off the camera's floor. An object hidden in a merge of touching objects is not out of view: a
// packed group in the zone is done even when the camera resolves only some of it.
//
// Plain data (TaskSpec, Zone) plus one stateful tracker per run (TaskProgress); no dependence on
// how positions were obtained.

#include <Eigen/Core>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace airtwin {

/// A circular zone on the floor (m, world frame).
struct Zone {
  Eigen::Vector2d centre_W = Eigen::Vector2d::Zero();
  double radius_m = 0.0;
  bool contains(const Eigen::Vector2d& p_W) const { return (p_W - centre_W).norm() <= radius_m; }
};

enum class TaskKind { kPath, kAggregation, kSorting };

struct TaskSpec {
  TaskKind kind = TaskKind::kPath;

  // --- path ---
  /// The reference path, a polyline (m, world frame), at least 2 vertices.
  std::vector<Eigen::Vector2d> path_W;
  /// true: the references are the path's vertices after the first (the octagon's corners);
  /// false: points every reference_spacing_m along the path (the last vertex always included).
  bool vertices_as_references = false;
  double reference_spacing_m = 0.10;
  /// A reference counts as reached when the mean distance of the objects to it is below this.
  double switch_distance_m = 0.04;

  // --- aggregation ---
  Zone zone;

  // --- sorting ---
  /// The zone of each object type ("tracer", "cotton").
  std::map<std::string, Zone> zones_by_type;
  /// Sorting in stages (see above). stages_auto (the default): the controller orders the types
  /// by their eq. (8) threshold air speed, highest first (resolve_sorting_stages). Otherwise the
  /// types in the order they are sorted; empty: all at once, as the paper does.
  bool stages_auto = true;
  std::vector<std::string> stages;
  /// The weight in eq. (10) of a deferred object, in (0, 1].
  double deferred_weight = 0.1;
  /// How far (m) from the point below the nozzle a deferred object should stay: the nozzle must
  /// still be able to put s beyond it to bring it back (s reaches 1.65 m at 60 deg of tilt).
  double reach_m = 1.0;

  /// The run fails when the task is not done by then (s of simulated or rig time).
  double time_limit_s = 300.0;

  /// Throws InputError naming `source` and the field when the spec cannot be run (too few path
  /// vertices, non-finite or non-positive sizes, a sorting task without zones).
  void validate(const std::string& source) const;
};

/// A sorting task's stages made explicit: with stages_auto, the zones' types ordered by
/// threshold air speed (ObjectDynamics::threshold_air_speed, highest first; ties by name), given
/// each type's threshold; otherwise `spec` unchanged. Throws InputError when a zone's type has no
/// threshold.
TaskSpec resolve_sorting_stages(const TaskSpec& spec,
                                const std::map<std::string, double>& threshold_air_speed_mps);

/// The weights and reaches of eq. (10) for one decision (controller/cem_planner.h).
struct CostShaping {
  std::vector<double> weights;  ///< empty: all 1
  std::vector<double> reach_m;  ///< empty: no limit
};

/// The references along a path task: every reference_spacing_m along the polyline (or its
/// vertices after the first), the last vertex always included.
std::vector<Eigen::Vector2d> path_references(const TaskSpec& spec);

/// Distance (m) from p_W to the polyline path_W.
double distance_to_path(const std::vector<Eigen::Vector2d>& path_W, const Eigen::Vector2d& p_W);

/// The task's state over one run.
class TaskProgress {
 public:
  /// Throws InputError when the spec is invalid.
  explicit TaskProgress(const TaskSpec& spec);

  /// Takes the objects' current positions and types (object j: p_W[j], types[j]; the set may
  /// change between calls when a camera loses or finds objects): advances the path reference
  /// while it is reached (one reference per call at most for vertex references, as many as are
  /// within reach otherwise), and updates done(): never done while `out_of_view` > 0 (objects
  /// the perception saw leave its view). Returns true when the task is done. Throws
  /// InputError for a sorting task and a type without a zone.
  bool update(const std::vector<Eigen::Vector2d>& p_W, const std::vector<std::string>& types,
              double t_s, int out_of_view = 0);

  bool done() const { return done_time_s_.has_value(); }
  /// Time (s) at which update() first found the task done.
  std::optional<double> done_time_s() const { return done_time_s_; }

  /// The reference point r_j of each object (of type types[j]) for the next decision (eq. 10).
  std::vector<Eigen::Vector2d> references(const std::vector<std::string>& types) const;
  /// The weights and reaches of eq. (10) for objects at p_W of types `types`: empty for
  /// every task but sorting in stages.
  CostShaping cost_shaping(const std::vector<Eigen::Vector2d>& p_W,
                           const std::vector<std::string>& types) const;
  /// Sorting in stages: the type being sorted now (the first in the order with an object out of
  /// its zone; the last when all are in), else "".
  std::string active_stage(const std::vector<Eigen::Vector2d>& p_W,
                           const std::vector<std::string>& types) const;
  /// Index of the current path reference and their count (0 / 0 for zone tasks).
  size_t reference_index() const { return reference_index_; }
  size_t reference_count() const { return references_.size(); }
  const std::vector<Eigen::Vector2d>& path_reference_points() const { return references_; }

  /// Objects inside their zone now (zone tasks), or within switch distance of the last
  /// reference (path).
  int objects_in_zone(const std::vector<Eigen::Vector2d>& p_W,
                      const std::vector<std::string>& types) const;

  const TaskSpec& spec() const { return spec_; }

 private:
  const Zone& zone_of(const std::string& type) const;

  TaskSpec spec_;
  std::vector<Eigen::Vector2d> references_;
  size_t reference_index_ = 0;
  std::optional<double> done_time_s_;
};

/// The largest distance (m) between two of the points: a group's span, by which the octagon's
/// four tracers are judged (section V-C: at most 26.1 cm). 0 for fewer than two points.
double max_pairwise_distance(std::span<const Eigen::Vector2d> points);

}  // namespace airtwin
