#include "controller/task.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/errors.h"

namespace airtwin {

namespace {

bool finite(const Eigen::Vector2d& p) { return std::isfinite(p.x()) && std::isfinite(p.y()); }

void check_zone(const Zone& zone, const std::string& source, const std::string& field) {
  if (!finite(zone.centre_W)) {
    throw InputError(source + ": " + field + ".centre must be finite");
  }
  if (!(std::isfinite(zone.radius_m) && zone.radius_m > 0.0)) {
    throw InputError(source + ": " + field + ": the diameter must be a positive number");
  }
}

}  // namespace

void TaskSpec::validate(const std::string& source) const {
  if (!(std::isfinite(time_limit_s) && time_limit_s > 0.0)) {
    throw InputError(source + ": task.time_limit_s must be a positive number");
  }
  switch (kind) {
    case TaskKind::kPath: {
      if (path_W.size() < 2) {
        throw InputError(source + ": task.path needs at least 2 points");
      }
      for (size_t i = 0; i < path_W.size(); ++i) {
        if (!finite(path_W[i])) {
          throw InputError(source + ": task.path[" + std::to_string(i) + "] is not finite");
        }
      }
      if (!(std::isfinite(reference_spacing_m) && reference_spacing_m > 0.0)) {
        throw InputError(source + ": task.spacing_m must be a positive number");
      }
      if (!(std::isfinite(switch_distance_m) && switch_distance_m > 0.0)) {
        throw InputError(source + ": task.switch_distance_m must be a positive number");
      }
      double length = 0.0;
      for (size_t i = 1; i < path_W.size(); ++i) length += (path_W[i] - path_W[i - 1]).norm();
      if (!(length > 0.0)) {
        throw InputError(source + ": task.path has zero length");
      }
      break;
    }
    case TaskKind::kAggregation:
      check_zone(zone, source, "task.zone");
      break;
    case TaskKind::kSorting:
      if (zones_by_type.empty()) {
        throw InputError(source + ": task.zones: a sorting task needs a zone per object type");
      }
      for (const auto& [type, z] : zones_by_type) check_zone(z, source, "task.zones." + type);
      for (size_t i = 0; i < stages.size(); ++i) {
        if (!zones_by_type.count(stages[i])) {
          throw InputError(source + ": task.stages names '" + stages[i] + "', which has no zone");
        }
        if (std::find(stages.begin(), stages.begin() + i, stages[i]) != stages.begin() + i) {
          throw InputError(source + ": task.stages names '" + stages[i] + "' twice");
        }
      }
      if (!(std::isfinite(deferred_weight) && deferred_weight > 0.0 && deferred_weight <= 1.0)) {
        throw InputError(source + ": task.deferred_weight must be in (0, 1]");
      }
      if (!(std::isfinite(reach_m) && reach_m > 0.0)) {
        throw InputError(source + ": task.reach_m must be a positive number");
      }
      break;
  }
}

TaskSpec resolve_sorting_stages(const TaskSpec& spec,
                                const std::map<std::string, double>& threshold_air_speed_mps) {
  if (spec.kind != TaskKind::kSorting || !spec.stages_auto) return spec;
  TaskSpec out = spec;
  out.stages_auto = false;
  out.stages.clear();
  for (const auto& [type, zone] : spec.zones_by_type) {
    if (!threshold_air_speed_mps.count(type)) {
      throw InputError("task.stages: no dynamics to order object type '" + type + "' by");
    }
    out.stages.push_back(type);
  }
  // Highest threshold first; the map's name order breaks ties (stable sort).
  std::stable_sort(out.stages.begin(), out.stages.end(),
                   [&](const std::string& a, const std::string& b) {
                     return threshold_air_speed_mps.at(a) > threshold_air_speed_mps.at(b);
                   });
  return out;
}

std::vector<Eigen::Vector2d> path_references(const TaskSpec& spec) {
  std::vector<Eigen::Vector2d> out;
  const auto& path = spec.path_W;
  if (path.size() < 2) return out;
  if (spec.vertices_as_references) {
    out.assign(path.begin() + 1, path.end());
    return out;
  }
  // Walk the polyline and drop a point every `spacing` of arc length (section V-B: "each reference
  // path was divided into reference points with a spacing of 10 cm").
  const double spacing = spec.reference_spacing_m;
  double next = spacing;  // arc length of the next reference
  double walked = 0.0;
  for (size_t i = 1; i < path.size(); ++i) {
    const Eigen::Vector2d a = path[i - 1];
    const Eigen::Vector2d b = path[i];
    const double len = (b - a).norm();
    while (len > 0.0 && next <= walked + len + 1e-12) {
      const double f = std::min(1.0, (next - walked) / len);
      out.push_back(a + f * (b - a));
      next += spacing;
    }
    walked += len;
  }
  // The last vertex always ends the list; a spaced point within 1 mm of it is the same point.
  if (out.empty() || (out.back() - path.back()).norm() > 1e-3) {
    out.push_back(path.back());
  } else {
    out.back() = path.back();
  }
  return out;
}

double distance_to_path(const std::vector<Eigen::Vector2d>& path_W, const Eigen::Vector2d& p_W) {
  if (path_W.empty()) return std::numeric_limits<double>::infinity();
  if (path_W.size() == 1) return (p_W - path_W[0]).norm();
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 1; i < path_W.size(); ++i) {
    const Eigen::Vector2d a = path_W[i - 1];
    const Eigen::Vector2d ab = path_W[i] - a;
    const double len2 = ab.squaredNorm();
    const double f = len2 > 0.0 ? std::clamp((p_W - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    best = std::min(best, (p_W - (a + f * ab)).norm());
  }
  return best;
}

TaskProgress::TaskProgress(const TaskSpec& spec) : spec_(spec) {
  spec_.validate("task");
  if (spec_.kind == TaskKind::kPath) references_ = path_references(spec_);
}

const Zone& TaskProgress::zone_of(const std::string& type) const {
  const auto it = spec_.zones_by_type.find(type);
  if (it == spec_.zones_by_type.end()) {
    throw InputError("task.zones: no zone for object type '" + type + "'");
  }
  return it->second;
}

bool TaskProgress::update(const std::vector<Eigen::Vector2d>& p_W,
                          const std::vector<std::string>& types, double t_s, int out_of_view) {
  if (done()) return true;
  AIRTWIN_DEMAND(p_W.size() == types.size());
  if (p_W.empty()) return false;
  const bool all_in_view = out_of_view <= 0;
  switch (spec_.kind) {
    case TaskKind::kPath: {
      auto mean_distance = [&](const Eigen::Vector2d& r) {
        double sum = 0.0;
        for (const auto& p : p_W) sum += (p - r).norm();
        return sum / static_cast<double>(p_W.size());
      };
      // One object may pass several 10 cm points within one decision; a group moves on one
      // corner at a time (section V-C: the reference switches when the mean distance falls
      // below 6.3 cm).
      const bool one_at_a_time = spec_.vertices_as_references;
      while (reference_index_ < references_.size() &&
             mean_distance(references_[reference_index_]) < spec_.switch_distance_m) {
        ++reference_index_;
        if (one_at_a_time) break;
      }
      if (reference_index_ >= references_.size() && all_in_view) {
        done_time_s_ = t_s;
      }
      break;
    }
    case TaskKind::kAggregation:
    case TaskKind::kSorting:
      if (objects_in_zone(p_W, types) == static_cast<int>(p_W.size()) && all_in_view) {
        done_time_s_ = t_s;
      }
      break;
  }
  return done();
}

std::vector<Eigen::Vector2d> TaskProgress::references(const std::vector<std::string>& types) const {
  std::vector<Eigen::Vector2d> out(types.size());
  for (size_t j = 0; j < types.size(); ++j) {
    switch (spec_.kind) {
      case TaskKind::kPath:
        out[j] = references_[std::min(reference_index_, references_.size() - 1)];
        break;
      case TaskKind::kAggregation:
        out[j] = spec_.zone.centre_W;
        break;
      case TaskKind::kSorting:
        out[j] = zone_of(types[j]).centre_W;
        break;
    }
  }
  return out;
}

int TaskProgress::objects_in_zone(const std::vector<Eigen::Vector2d>& p_W,
                                  const std::vector<std::string>& types) const {
  AIRTWIN_DEMAND(p_W.size() == types.size());
  int n = 0;
  for (size_t j = 0; j < p_W.size(); ++j) {
    switch (spec_.kind) {
      case TaskKind::kPath:
        n += (p_W[j] - references_.back()).norm() < spec_.switch_distance_m ? 1 : 0;
        break;
      case TaskKind::kAggregation:
        n += spec_.zone.contains(p_W[j]) ? 1 : 0;
        break;
      case TaskKind::kSorting:
        n += zone_of(types[j]).contains(p_W[j]) ? 1 : 0;
        break;
    }
  }
  return n;
}

std::string TaskProgress::active_stage(const std::vector<Eigen::Vector2d>& p_W,
                                       const std::vector<std::string>& types) const {
  AIRTWIN_DEMAND(p_W.size() == types.size());
  if (spec_.kind != TaskKind::kSorting || spec_.stages.empty()) return "";
  for (const std::string& stage : spec_.stages) {
    for (size_t j = 0; j < p_W.size(); ++j) {
      if (types[j] == stage && !zone_of(types[j]).contains(p_W[j])) return stage;
    }
  }
  return spec_.stages.back();
}

CostShaping TaskProgress::cost_shaping(const std::vector<Eigen::Vector2d>& p_W,
                                       const std::vector<std::string>& types) const {
  CostShaping out;
  const std::string active = active_stage(p_W, types);
  if (active.empty()) return out;
  const auto rank = [&](const std::string& type) {
    const auto it = std::find(spec_.stages.begin(), spec_.stages.end(), type);
    // A type outside the order is sorted with the active stage.
    return it == spec_.stages.end() ? -1 : static_cast<int>(it - spec_.stages.begin());
  };
  const int active_rank = rank(active);
  out.weights.assign(p_W.size(), 1.0);
  out.reach_m.assign(p_W.size(), std::numeric_limits<double>::infinity());
  for (size_t j = 0; j < p_W.size(); ++j) {
    if (rank(types[j]) > active_rank) {
      out.weights[j] = spec_.deferred_weight;
      out.reach_m[j] = spec_.reach_m;
    }
  }
  return out;
}

double max_pairwise_distance(std::span<const Eigen::Vector2d> points) {
  double widest = 0.0;
  for (size_t a = 0; a < points.size(); ++a) {
    for (size_t b = a + 1; b < points.size(); ++b) {
      widest = std::max(widest, (points[a] - points[b]).norm());
    }
  }
  return widest;
}

}  // namespace airtwin
